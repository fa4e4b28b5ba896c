// lugrip — sliding-velocity observer (paper eqs. 19-23) and slippage indicator (eq. 37).
#pragma once

#include <cmath>
#include <string>

#include "lugrip/contact.hpp"
#include "lugrip/params.hpp"
#include "lugrip/slider_model.hpp"
#include "lugrip/status.hpp"

namespace lugrip {

//! How the observer gain l is chosen at each sample.
enum class GainMode : int {
  Fixed = 0,      //!< l = ObserverSettings::gain
  //! l = bandwidth / sigma_1 clipped to [gain_min, gain_max]: the sliding convergence rate
  //! l sigma_1 is then the same at every force, CoR and beta_A (docs/model.md 7.4 "scale the gain
  //! with sigma_1"); sigma_1 spans five decades, a fixed l is seconds late when it is small.
  Bandwidth = 1,
};

//! Short name ("fixed", "bandwidth"); never allocates.
const char* to_string(GainMode m) noexcept;

//! Observer settings; every default lives here. The defaults were chosen on synthetic sliding
//! data (plant = SliderModel, sensor = ContactModel::wrench_at + white noise); the figures are in
//! BENCHMARKS.md (section Sliding-velocity observer), and tests/cpp/test_observer.cpp pins the
//! behaviour.
//! The bandwidth is also the one identification uses by default (docs/model.md 7.4, 8.1: the
//! parameters are identified for the observer inside the cost): at 3000/s the Table 1 round
//! trip and the per-object refit recover the parameters within 5 %, at 100/s the observer's lag
//! behind slip ramps is absorbed by sigma0 (x2) and beta_A (-14 %); BENCHMARKS.md, section
//! Identification.
//!
//! Units, ranges and meanings of the fields: the field table, lugrip/settings_fields.hpp (its
//! ranges are what validate() enforces; docs/conventions.md prints it).
//!
//! What the ranges guarantee, with ContactParams inside theirs (sigma0 >= 1e-12 among them):
//! * finite outputs: rho = delta f_n^gamma < max(1, f_n^(1/3)) and |c| <= c_max rho (c_max <=
//!   1e3), so forces <= 1e9 N give rho < 1e3 m, |y| <= |tau| + |c| f_t < 1e16 N m and g < 1e17 N m,
//!   hence |z_hat| <= g / sigma0 < 1e29 rad; |omega_object| <= |omega_hat| <= omega_limit <= 1e6
//!   rad/s keeps v_slip <= |omega_hat| rho (c_max + 1/(2 c_max)) below 1e12 m/s; every other
//!   output is a ratio with a floored denominator. An update that still overflows (a gain of 1e15
//!   times a large sigma_1 over a long step) is the divergence guard's case; a sample whose CoR
//!   or outputs are not finite is rejected like an invalid input (InvalidSample: state untouched).
//! * bounded work: each sample costs at most 8 x max_substeps integrator substeps (the adaptive
//!   schemes retry up to eight times) plus a CoR solve of at most a few hundred limit-surface
//!   evaluations. A substep takes about 0.1 us, so substeps = max_substeps = 5000 costs about
//!   0.5 ms per sample (2 s for a 4000-sample log; 1e8 took minutes), at most 4 ms.
struct ObserverSettings {
  double dt = 0.002;
  Integrator integrator = Integrator::Rosenbrock;
  GainMode gain_mode = GainMode::Bandwidth;
  double gain = 200.0;
  double bandwidth = 3000.0;
  double gain_min = 1.0;
  double gain_max = 1.0e7;
  double g_floor = 1.0e-7;
  double torque_cutoff = 2.0;
  bool filter_force = true;
  double cor_sign_sigmas = 5.0;
  int max_invalid = 10;
  double max_dt_gap = 0.05;
  double torque_noise = 1.0e-5;
  double resolution_max = 0.02;
  double omega_limit = 1.0e3;
  int substeps = 1;
  int max_substeps = 500;
  CorSettings cor;
};

//! Upper bound of ObserverSettings::max_substeps (bounds the work per sample).
constexpr int kMaxObserverSubsteps = 5000;

//! Checks every field (and the nested CorSettings); one line per bad field in *message,
//! naming field and value. Returns true when valid.
bool validate(const ObserverSettings& s, std::string* message);
//! "ObserverSettings(dt=0.002, integrator='rosenbrock', ..., cor=CorSettings(...))" at full
//! precision (for bug reports).
std::string to_string(const ObserverSettings& s);

//! sqrt(x^2 + y^2), within an ulp of std::hypot (which is several times slower), falling back
//! to std::hypot where the squares would overflow or underflow; NaN and Inf as std::hypot.
inline double planar_norm(double x, double y) noexcept {
  const double s = x * x + y * y;
  if (s < 1e300 && s > 1e-300) return std::sqrt(s);
  return std::hypot(x, y);
}

//! One fingertip sample: the wrench the OBJECT exerts on the FINGERTIP, i.e. what a fingertip
//! force/torque sensor reads (docs/model.md 7.2), in a frame with z along the contact normal.
//! With this wrench y = tau - c f_t has the sign of the slip velocity and omega_hat is the
//! object's angular velocity relative to the fingertip about the sensor's z axis. Feeding the
//! opposite wrench (fingertip on object) returns -omega_hat with the same S.
struct ObserverInput {
  double f_n = 0.0;  //!< normal force [N], >= CorSettings::f_n_min in contact
  double f_t = 0.0;  //!< tangential force [N]: in-plane magnitude (>= 0) or a signed component
  double tau = 0.0;  //!< torsional moment about the contact normal [N m], signed
  double dt = 0.0;   //!< time since the previous sample [s]; 0 means the nominal settings.dt

  //! Builds the input from the in-plane force vector (f_t = planar_norm(f_x, f_y)).
  static ObserverInput from_force_vector(double f_n, double f_x, double f_y, double tau,
                                         double dt = 0.0) noexcept {
    return ObserverInput{f_n, planar_norm(f_x, f_y), tau, dt};
  }
};

//! Friction ratios (ContactParams::static_ratio r_s, kinetic_ratio r_k, not both 1; docs/model.md
//! 7.5): the observer starts in stick, where the update and S use the static capacity r_s g; once
//! the friction torque about the CoR reaches kBreakawayLevel r_k g (the level at which a slip,
//! once under way, does not stop) the update uses g and S is judged against r_k g (clipped at 1),
//! until the friction falls below kStickRelease r_k g (stuck again). With r_s = r_k = 1 this is
//! the paper's S.
constexpr double kBreakawayLevel = 0.995;
constexpr double kStickRelease = 0.8;

//! omega_hat, omega_object and v_slip are reported where omega_resolution <= this factor times
//! ObserverSettings::resolution_max and 0 beyond, where the speed is not in the data (noise and
//! model error would set the number). Above 1, so the estimates just past the speed_observable
//! flag, still good to a few resolutions, are kept; below 2, the margin identification gives data
//! without a measurable viscous term (beta_A set so that the resolution is at least twice
//! resolution_max everywhere, docs/model.md 8.3), so those report 0 throughout.
constexpr double kOmegaReportFactor = 1.5;

//! Result for one sample. Always finite. On InvalidSample / SensorFault the previous output is
//! held (with the new status); on NoContact omega_hat = z_hat = S = y = 0 (state reset).
//!
//! Two angular velocities. omega_hat is the observer's state (reported up to kOmegaReportFactor
//! resolution_max, else 0; the state itself is omega_state), the slip about the CoR the
//! dynamics use, i.e. with |c~| clipped at c_max (paper; docs/model.md §5.6); it is what the grasp
//! controller's dynamic part C_d filters (GraspController, FingerInput::omega_hat). On a
//! translation-dominated slide the true CoR lies far beyond the clip, the object turns slowly
//! and omega_hat (about the clipped CoR) is several times the object's angular velocity.
//! omega_object and v_slip re-express the same slip about the unclipped CoR estimate
//! c~u = c_tilde_unclipped: with the viscous stress uniform over the patch (docs/model.md §5.1) the
//! viscous torque about a point at a rho on the CoR line of a slip omega about a_u rho is
//! pi beta_A rho^4 omega (1/2 + a a_u), so the torque omega_hat explains about the clip
//! (sigma_1 = pi beta_A rho^4 (a^2 + 1/2)) is that of
//!   omega_object = omega_hat (a^2 + 1/2) / (a a_u + 1/2)   (a = |c~|, a_u = |c~u| >= a),
//! and the patch centre, at distance a_u rho from that CoR, slides at
//!   v_slip = |omega_object| a_u rho = |omega_hat| rho (a^2 + 1/2) / (a + 1/(2 a_u)).
//! Without the clip (a_u = a) these are omega_hat and |omega_hat c|; a pure translation
//! (a_u -> inf) gives omega_object -> 0 and a finite v_slip.
struct ObserverOutput {
  //! estimated slip velocity about the clipped CoR c [rad/s] (object vs fingertip); drives C_d.
  //! Reported as 0 where omega_resolution > kOmegaReportFactor resolution_max (the speed is not in
  //! the data: 0 is never worse than a number drawn from noise and model error); omega_state is
  //! the observer's state.
  double omega_hat = 0.0;
  double z_hat = 0.0;       //!< estimated bristle state [rad], |sigma0 z_hat| <= g
  double S = 0.0;           //!< slippage indicator sigma0 |z_hat| / g in [0, 1] (eq. 37); / (kinetic_ratio g) when kinetic
  double c_tilde = 0.0;     //!< normalized CoR [-] (sensor frame), |c~| <= c_max
  double c = 0.0;           //!< CoR position [m]
  double g = 0.0;           //!< dry torque capacity about the CoR used by the update [N m] (eq. 18, floored); times static_ratio in stick
  double sigma_1 = 0.0;     //!< viscous coefficient about the CoR [N m s/rad] (eq. 17)
  double y = 0.0;           //!< measured friction torque about the CoR, tau - c f_t [N m] (eq. 20), raw torque
  double tau_cor = 0.0;     //!< filtered torque (with sign hysteresis) used for the CoR [N m]
  double ft_cor = 0.0;      //!< tangential force used for the CoR (filtered when filter_force) [N]
  double gain = 0.0;        //!< observer gain l used on this sample [1/(kg m^2)]
  //! Speed resolution torque_noise / sigma_1 [rad/s]: the slip speed enters the wrench only
  //! through viscous friction (docs/model.md 6, 7.3), so speed changes below this are invisible.
  double omega_resolution = 0.0;
  bool speed_observable = false;  //!< omega_resolution <= settings.resolution_max
  bool inside = true;       //!< CoR wrench strictly inside the limit surface (eq. 15)
  bool saturated = false;   //!< |c~| clipped at c_max
  bool projected = false;   //!< z_hat was clipped to +-g/sigma0 after the update
  bool cor_side_flipped = false;  //!< the CoR changed side this sample: the state was mirrored (z, omega -> -z, -omega)
  bool diverged = false;    //!< the update left the valid range (|omega_hat| > omega_limit or non-finite): re-initialised
  bool substeps_capped = false;  //!< Rk4Adaptive needed more than max_substeps
  int substeps = 0;         //!< integrator (sub)steps on this sample (0 when not integrated)
  int cor_iterations = 0;   //!< root-finding iterations of the CoR estimate
  Status status = Status::NoContact;
  double c_tilde_unclipped = 0.0;  //!< normalized CoR before the clip [-], signed like c_tilde, |c~u| >= |c~|
  double omega_object = 0.0;  //!< slip velocity about the unclipped CoR [rad/s] (= omega_hat where c~u = c~); 0 where omega_hat is
  double v_slip = 0.0;        //!< slip speed of the patch centre [m/s], >= 0; 0 where omega_hat is
  double omega_state = 0.0;   //!< the observer's slip-velocity state (omega_hat before the resolution gate) [rad/s]
  //! sliding has started: g is the fitted capacity and S = sigma0 |z_hat| / (kinetic_ratio g);
  //! false in stick and always false when ContactParams::static_ratio == kinetic_ratio == 1
  bool kinetic = false;
};

//! Nonlinear sliding-velocity observer of the paper (eqs. 21-23, docs/model.md 7), per fingertip:
//!
//!   zhat' = omegahat - (sigma0/g) zhat |omegahat|,
//!   omegahat' = l [y - sigma0 zhat - sigma_1 omegahat - sigma_z zhat'],
//!
//! with y = tau - c f_t. Per sample: (1) CoR estimate (CorEstimator) from f_n and the low-pass
//! filtered torque (and f_t, filter_force) with sign hysteresis; y uses the raw wrench. On
//! translational loads the torque is below the noise and an unfiltered CoR changes side every
//! few samples, which flips the sign of y and drags z_hat across zero;
//! (2) g, sigma_1 and y at the current sample; (3) one update with the chosen integrator over
//! the time since the last integrated sample; (4) projection |zhat| <= g/sigma0, so S <= 1.
//!
//! What is observable: the slip indicator S (how much of the dry capacity is used) always is.
//! The slip SPEED enters the measured wrench only through the viscous term sigma_1 omega: in
//! steady sliding omega_hat converges to (|y| - g)/sigma_1 at rate l sigma_1, and a torque error
//! e maps to a speed error e / sigma_1. With weak viscous friction (paper Table 2, sigma_1 ~ 1e-3)
//! the speed is poorly observable; omega_resolution and speed_observable report this per sample.
//!
//! Initialisation (first valid sample, after reset(), NoContact, SensorFault or a dt gap):
//! omega_hat = 0, z_hat = clip(y/sigma0, +-g/sigma0), status Reinitialized.
class Observer {
 public:
  //! Validates params and settings (std::invalid_argument, one line per bad field).
  explicit Observer(const ContactParams& params, const ObserverSettings& settings = ObserverSettings());
  //! Reuses an existing contact model (copies its tables; no quadrature).
  explicit Observer(const ContactModel& model, const ObserverSettings& settings = ObserverSettings());

  //! Processes one sample; never throws, never allocates; out is always finite.
  Status step(const ObserverInput& in, ObserverOutput& out) noexcept;
  //! Forgets the state; the next valid sample re-initialises.
  void reset() noexcept;
  //! ContactModel::set_mu on the observer's model (no allocation; the state is kept, reset() to
  //! restart). False: mu out of range, nothing changed.
  bool set_mu(double mu) noexcept { return cor_.set_mu(mu); }

  //! The last reported omega_hat (0 where the speed is not in the data) and the state itself.
  double omega_hat() const noexcept { return last_.omega_hat; }
  double omega_state() const noexcept { return omega_; }
  double z_hat() const noexcept { return z_; }
  const ContactModel& model() const noexcept { return cor_.model(); }
  const ObserverSettings& settings() const noexcept { return s_; }

 private:
  // Holds the state and the previous output for a sample that cannot be used (input invalid
  // or its CoR/outputs not computable); counts toward SensorFault.
  Status reject(double dt, ObserverOutput& out) noexcept;

  CorEstimator cor_;
  ObserverSettings s_;
  double z_ = 0.0, omega_ = 0.0;
  double tau_f_ = 0.0;    // low-pass filtered torque for the CoR
  double ft_f_ = 0.0;     // low-pass filtered tangential force for the CoR (filter_force)
  double cor_sign_ = 1.0; // side of the CoR torque (hysteresis)
  double pending_ = 0.0;  // time of skipped (invalid) samples, added to the next step
  double sign_band_ = 0.0;  // [N m] CoR sign hysteresis (cor_sign_sigmas x filtered noise std)
  double alpha_dt_ = 1.0;   // low-pass coefficient of the CoR inputs at the nominal period
  int invalid_run_ = 0;
  bool need_init_ = true;
  bool kinetic_ = false;  // Stribeck term: the capacity is the kinetic one (sliding has started)
  ObserverOutput last_;
  // The CoR estimate of the sample being processed: a member, so that step() does not
  // zero-initialise a temporary each call (evaluate() writes every field).
  CorOutput co_;
};

}  // namespace lugrip
