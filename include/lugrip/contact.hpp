// lugrip — contact quantities (paper eqs. 3-4, 7-10, 16-18) and CoR estimation (eqs. 13-15).
#pragma once

#include <string>
#include <vector>

#include "lugrip/limit_surface.hpp"
#include "lugrip/params.hpp"
#include "lugrip/status.hpp"

namespace lugrip {

//! Limit surface plus the parameter-dependent maps of one contact. Every method is noexcept and
//! allocation-free. The tables depend on k and gamma only; mu is a factor of every map, so
//! set_mu() is real-time safe.
class ContactModel {
 public:
  //! Validates `params` (throws std::invalid_argument naming every bad field) and builds the
  //! limit-surface tables and the sigma_LS inverse table (a few tens of ms).
  explicit ContactModel(const ContactParams& params);

  const ContactParams& params() const noexcept { return p_; }
  const LimitSurface& limit_surface() const noexcept { return ls_; }
  //! Replaces the friction coefficient (every map scales with it; no table changes). Returns
  //! false and changes nothing unless 0 < mu <= 10 (ContactParams::mu). No allocation.
  bool set_mu(double mu) noexcept;
  double xi() const noexcept { return ls_.xi(); }

  double rho(double f_n) const noexcept;      //!< contact radius delta f_n^gamma [m]
  double ft_max(double f_n) const noexcept;   //!< mu f_n [N] (eq. 3)
  double tau_max(double f_n) const noexcept;  //!< mu xi delta f_n^(gamma+1) [N m] (eq. 4)
  //! Viscous/dry ratio of eqs. 9-10, K = pi delta^3 beta_A f_n^(3 gamma - 1) / mu [s/rad].
  double viscous_ratio(double f_n) const noexcept;
  //! Viscous coefficient about the CoR, pi beta_A rho^4 (c~^2 + 1/2) [N m s/rad] (eq. 17).
  double sigma_1(double f_n, double c_tilde) const noexcept;
  //! Maximum dry friction torque about the CoR, mu f_n rho G(|c~|) [N m] (eq. 18), > 0.
  double g(double f_n, double c_tilde) const noexcept;

  //! |c~| on the limit surface for a given |sigma| (eq. 13, first line); monotone inverse of
  //! sigma_LS, not clipped. Bracketed safeguarded Newton; `iterations` (optional) counts steps.
  double invert_sigma(double sigma_abs, int* iterations = nullptr) const noexcept;
  //! Inverse of the CoR estimation, for simulators and tests: the sensor-convention wrench
  //! (f_t >= 0 [N], tau [N m]) whose estimated CoR has |c~| = |c_tilde| and whose friction
  //! torque about the CoR, tau - c f_t, equals `y` [N m]. The CoR side follows the sign of y
  //! (load-motion inequality: sign(c~) = -sign(y)). |y| <= g gives a point inside the LS on the
  //! sigma-curve of |c~| (virtual CoR, eq. 14); |y| > g gives the LS point plus viscous excess
  //! along (2 xi a, 1) (eqs. 9-10). Exact round trip with CorEstimator for |c~| < c_max.
  void wrench_at(double f_n, double c_tilde, double y, double& f_t, double& tau) const noexcept;

  //! Root of h(a) = f - F(a) - 2 xi a (t - T(a)) on [0, c_max] (eq. 13, second line,
  //! docs/model.md 5.4); returns c_max when h(c_max) > 0.
  //! `guess` (optional, e.g. the inside-LS estimate) starts the iteration.
  //! `point` (optional) receives the LS point (F, T, dF, dT) at the returned a.
  double solve_outside(double ft_abs, double tau_abs, int* iterations = nullptr,
                       double guess = -1.0, LsPoint* point = nullptr) const noexcept;
  //! The same root beyond the clip, for a wrench whose root lies past c_max (h(c_max) > 0):
  //! searched on [c_max, a_limit] by an expanding bracket and safeguarded Newton; returns
  //! a_limit when h(a_limit) > 0 (a torque too small for a finite CoR within the limit).
  double solve_outside_beyond(double ft_abs, double tau_abs, double a_limit,
                              int* iterations = nullptr) const noexcept;

 private:
  ContactParams p_;
  LimitSurface ls_;
  double inv_s0_ = 0.0, inv_s1_ = 0.0;  // log sigma_LS at a = 1e-4 and a = 1e4
  std::vector<double> inv_;  // (kInverseIntervals + 1) x 3: log a, h d(log a)/d(log sigma), a

 public:
  static constexpr int kInverseIntervals = 2048;
};

//! Largest |c~| the estimator reports before the clip (CorOutput::c_tilde_unclipped) [-]: a
//! translation whose torque is too small to place the CoR closer reads as this.
constexpr double kCTildeUnclippedMax = 1.0e6;

//! Per-sample settings of the CoR estimator (defaults in one place). Every field must be finite
//! and > 0; a sample whose normalisation or CoR quantities overflow (forces near the largest
//! double, mu or delta near 0) is InvalidSample. Inside an Observer the sensor range and the
//! contact threshold are narrower (ObserverSettings). Units, ranges and meanings: the field
//! table, lugrip/settings_fields.hpp (docs/conventions.md prints it).
struct CorSettings {
  double f_n_min = 0.03;         //!< [N] below this normal force: NoContact (paper's code: 0.03)
  double force_limit = 1.0e4;    //!< [N] |f_n| or |f_t| above: InvalidSample (sensor range)
  double torque_limit = 1.0e3;   //!< [N m] |tau| above: InvalidSample
  double zero_force = 1.0e-4;    //!< f~_t below this counts as zero (pure rotation)
  double zero_torque = 1.0e-4;   //!< |tau~| below this counts as zero: |c~| = c_max, sign held
};

//! Largest cor.force_limit [N] and cor.torque_limit [N m] an Observer accepts.
constexpr double kMaxForceLimit = 1.0e9;
//! Smallest cor.f_n_min [N] an Observer accepts (a micronewton: below any force sensor's
//! resolution).
constexpr double kMinContactForce = 1.0e-6;

//! Checks the settings; one line per bad field in *message. Returns true when valid.
bool validate(const CorSettings& s, std::string* message);
//! "CorSettings(f_n_min=0.03, ...)" at full precision (for bug reports).
std::string to_string(const CorSettings& s);

//! One fingertip sample as the sensor gives it.
struct CorInput {
  double f_n = 0.0;  //!< normal force [N], > 0 in contact
  double f_t = 0.0;  //!< tangential force [N]: in-plane magnitude (>= 0) or a signed component
  double tau = 0.0;  //!< torsional moment about the contact normal [N m], signed
};

//! Result for one sample. On NoContact / InvalidSample the previous values are kept.
struct CorOutput {
  double c_tilde = 0.0;    //!< signed normalized CoR c/rho [-], |c~| <= c_max
  double c = 0.0;          //!< signed CoR position [m] (rho at the current f_n)
  double ft_tilde = 0.0;   //!< f_t / (mu f_n) [-] (signed like f_t)
  double tau_tilde = 0.0;  //!< tau / tau_max [-]
  double sigma = 0.0;      //!< eq. 14, sign of tau [-]
  double rho = 0.0;        //!< contact radius [m]
  double g = 0.0;          //!< max dry torque about the CoR [N m] (eq. 18)
  double sigma_1 = 0.0;    //!< viscous coefficient about the CoR [N m s/rad] (eq. 17)
  double y = 0.0;          //!< friction torque about the CoR, tau - c f_t [N m] (eqs. 16, 20)
  bool inside = true;      //!< wrench strictly inside the limit surface (eq. 15)
  bool saturated = false;  //!< |c~| was clipped at c_max
  int iterations = 0;      //!< root-finding iterations spent on this sample
  Status status = Status::NoContact;
  //! signed normalized CoR before the clip [-]: equals c_tilde when |c~| < c_max, otherwise
  //! the root of the same equations past c_max, |c~u| <= kCTildeUnclippedMax
  double c_tilde_unclipped = 0.0;
};

//! CoR estimator (docs/model.md 5.7): virtual CoR inside the LS, viscous-LS CoR outside, sign rule
//! sign(c~) = -sign(f_t) sign(tau), saturation at c_max. Holds the previous estimate for the
//! undefined cases (zero wrench: previous c~; torque below threshold: previous sign).
class CorEstimator {
 public:
  explicit CorEstimator(const ContactParams& params, const CorSettings& settings = CorSettings());
  //! Reuses an existing model (copies its tables; no quadrature).
  explicit CorEstimator(const ContactModel& model, const CorSettings& settings = CorSettings());

  //! Estimate from one sample; never throws, never allocates, outputs always finite.
  //! Same as evaluate() followed by commit().
  Status step(const CorInput& in, CorOutput& out) noexcept;
  //! Estimate from one sample without changing the state (the previous estimate, used for the
  //! undefined cases, stays as it was). On NoContact / InvalidSample `out` is the held estimate.
  Status evaluate(const CorInput& in, CorOutput& out) const noexcept;
  //! Makes `out` (a result of evaluate()) the previous estimate; ignored unless its status
  //! carries an estimate (not NoContact / InvalidSample / SensorFault).
  void commit(const CorOutput& out) noexcept;
  void reset() noexcept;

  const ContactModel& model() const noexcept { return model_; }
  const CorSettings& settings() const noexcept { return s_; }
  //! ContactModel::set_mu on the estimator's model; the held estimate is kept. No allocation.
  bool set_mu(double mu) noexcept { return model_.set_mu(mu); }

 private:
  ContactModel model_;
  CorSettings s_;
  CorOutput last_;
};

}  // namespace lugrip
