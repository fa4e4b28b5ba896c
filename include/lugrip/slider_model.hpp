// lugrip — the planar slider about its centre of rotation (paper eqs. 1-2) and the one-step
// integrators shared with the velocity observer (docs/model.md 7.1 and 7.4). The integrators are
// implemented once, templated on the scalar type, in lugrip/detail/rotor_steps.hpp (double here,
// dual numbers in the identification's forward sensitivities).
#pragma once

#include <string>

#include "lugrip/contact.hpp"
#include "lugrip/params.hpp"
#include "lugrip/status.hpp"

namespace lugrip {

//! Discretisation of the two-state LuGre rotor (z, omega) over one sample, inputs held.
enum class Integrator : int {
  //! Exponential-implicit Euler: exact z-update for a frozen decay rate a = sigma0 |omega_n| / g
  //! (z <- E z + h phi omega_{n+1}, E = exp(-a h), phi = (1 - E)/(a h)) and omega implicit
  //! (linear in omega_{n+1}, closed form). A-stable for every gain, force and speed (in stick it
  //! is backward Euler of the linear system), exact steady sliding, one exp() per step; but
  //! first order: its lag is visible when sigma_1 is small and l large.
  Implicit = 0,
  //! The paper's scheme: one classical RK4 step per sample (zero-order-hold inputs). Unstable
  //! when h l (sigma_z + sigma_1) > 2.785 or h sigma0 |omega| / g > 2.785 (docs/model.md 7.4).
  Rk4 = 1,
  //! RK4 with n = ceil(h Lambda / 2) substeps, Lambda = max(k (sigma_z + sigma_1),
  //! sigma0 |omega| / g) at the start of the sample, redone with more substeps when the largest
  //! Lambda seen during the sample violates h Lambda / n <= 2.785; n is capped (docs/model.md 7.4).
  Rk4Adaptive = 2,
  //! Default of the observer and the plant. Linearly implicit 2-stage Rosenbrock method ROS2
  //! (gamma = 1 + 1/sqrt(2)) with the exact 2x2 Jacobian: second order, L-stable (any gain l,
  //! no substeps needed for stability), exact steady states; substeps resolve the bristle
  //! transient and, while sliding, the omega mode, h_sub r <= kRosenbrockRate with
  //! r = rosenbrock_rate (re-checked at the end of the sample like Rk4Adaptive): one step per
  //! sample in stick and hold, a few while sliding.
  Rosenbrock = 3,
};

//! Short name ("implicit", "rk4", "rk4_adaptive"); never allocates.
const char* to_string(Integrator i) noexcept;

//! Frozen coefficients of one step of the rotor
//!   zdot = omega - (sigma0 / g) z |omega|,                                 (eq. 1 / 21)
//!   omegadot = k [u - sigma0 z - sigma_z zdot - sigma_1 omega],            (eq. 2 / 22)
//! with k = 1/J and u = tau_e (plant) or k = l and u = y (observer).
struct RotorCoefficients {
  double sigma0 = 0.0;   //!< bristle stiffness [N m/rad], > 0
  double sigma_z = 0.0;  //!< bristle damping [N m s/rad], >= 0
  double sigma_1 = 0.0;  //!< viscous coefficient about the CoR [N m s/rad], >= 0
  double g = 0.0;        //!< dry torque capacity about the CoR [N m], > 0
  double gain = 0.0;     //!< k: 1/J (plant) or the observer gain l [1/(kg m^2)], > 0
  double drive = 0.0;    //!< u: external torque (plant) or measured y (observer) [N m]
};

namespace detail {
//! Value of a scalar: the identity for double; another scalar type (the identification's dual
//! numbers) provides its own overload, found by argument-dependent lookup.
inline double scalar_value(double x) noexcept { return x; }
//! Eq. 1 for any scalar type (see lugrip/detail/rotor_steps.hpp): the one implementation.
template <class T>
inline T rotor_zdot(const T& z, const T& omega, const T& sigma0, const T& g) noexcept {
  return omega - sigma0 / g * z * (scalar_value(omega) < 0.0 ? -omega : omega);
}
}  // namespace detail

//! Right-hand side zdot of eq. 1 at (z, omega).
inline double lugre_zdot(double z, double omega, double sigma0, double g) noexcept {
  return detail::rotor_zdot(z, omega, sigma0, g);
}

//! One step of length h with the Implicit scheme (see Integrator::Implicit). Not projected.
void rotor_step_implicit(double& z, double& omega, double h, const RotorCoefficients& c) noexcept;
//! One ROS2 step of length h (see Integrator::Rosenbrock). Not projected.
void rotor_step_rosenbrock(double& z, double& omega, double h, const RotorCoefficients& c) noexcept;
//! One classical RK4 step of length h. Not projected.
void rotor_step_rk4(double& z, double& omega, double h, const RotorCoefficients& c) noexcept;
//! Stiffness of the step: Lambda = max(k (sigma_z + sigma_1), sigma0 |omega| / g) [1/s].
double rotor_stiffness(double omega, const RotorCoefficients& c) noexcept;
//! Real-axis stability limit of classical RK4, h |lambda| <= 2.7853.
constexpr double kRk4StabilityLimit = 2.7853;
//! Bristle decay over the sample, h sigma0 |omega| / g, above which one Rosenbrock step resolves
//! the z transient (see rosenbrock_rate).
constexpr double kRosenbrockStiff = 50.0;
//! Rate the Rosenbrock substeps resolve [1/s], for a substep of length h whose stage and end
//! omega keep the sign of its start (a substep that crosses the kink of |omega| is rated at the
//! reversal rate 2 sigma0 |omega|max / g instead, by rotor_advance): the larger of two modes.
//!
//! The bristle transient. With omega of one sign the z equation is linear in z with the decay
//! a = sigma0 |omega| / g; ROS2 is L-stable and one step leaves the error |R(-a h) - e^(-a h)|
//! times the initial distance of z from its sliding steady state sign(omega) g / sigma0 (R: the
//! ROS2 stability function). That factor peaks at 0.17 near a h = 2.6 and falls as 0.8 / (a h)
//! beyond, so this rate is
//!   * a b, b = 1 - sigma0 z sign(omega) / g in [0, 2] the distance in units of g / sigma0: a
//!     saturated z (steady sliding) needs no substeps at any a;
//!   * 0 when a h >= kRosenbrockStiff: the transient is over within 1/50 of the step and one
//!     step lands within 1.6 % of its distance, closer than the substep rule itself guarantees.
//!
//! The omega mode. Once z saturates (sliding) dzdot/domega vanishes and omega relaxes toward its
//! quasi-static value (y - sign(omega) g) / sigma_1 with the rate gain sigma_1 (the observer's
//! bandwidth, 3000/s by default, i.e. 6 per 2 ms sample). Stable at any step, but one ROS2 step
//! at h gain sigma_1 = 6 leaves 12 % of the distance where the exact flow leaves 0.25 %: the
//! observer then lags every slip ramp like one of a third of its bandwidth, and identification
//! fitted through it biases beta_A (-9 % on the Table 2 refit). This rate is
//! (kRosenbrockRate / kRosenbrockOmegaStep) gain sigma_1 min(1, h a), i.e. substeps with
//! h_sub gain sigma_1 <= kRosenbrockOmegaStep while sliding; min(1, h a) is the share of the step
//! in that regime (pre-sliding, h a << 1, keeps one step: there the stiff modes are the
//! bristle spring and damper, which L-stability handles). Not resolved: just short of
//! saturation (z within a few 1e-3 of g / sigma0, e.g. while g grows along a slip ramp) a large
//! sigma_z couples the modes through sigma_z dz/dt, whose rate gain (sigma_1 + sigma_z (1 - u)),
//! u = sigma0 z sign(omega) / g, is several times the bandwidth with Table 1's sigma_z = 2 and
//! Table 2's sigma_1; resolving it would cost tens of substeps per sliding sample.
double rosenbrock_rate(double z, double omega, double h, const RotorCoefficients& c) noexcept;
//! Rosenbrock substeps keep h_sub rosenbrock_rate <= this (redone above twice this).
constexpr double kRosenbrockRate = 2.0;
//! While sliding, Rosenbrock substeps keep h_sub gain sigma_1 <= this (see rosenbrock_rate):
//! n substeps leave R(-6/n)^n of a sample's omega distance at the default bandwidth (n = 6:
//! 1.0 %, against 12 % for one step and 0.25 % for the exact flow).
constexpr double kRosenbrockOmegaStep = 1.0;

//! Integrates one sample of length h with `scheme`, projecting |z| <= g/sigma0 before the
//! sample (g may have dropped since the last one) and after every (sub)step (docs/model.md 7.1).
//! Implicit, Rosenbrock and Rk4 take `n_min` equal substeps; Rk4Adaptive takes
//! max(n_min, ceil(h Lambda / 2)) and re-checks Lambda at the end (at most `max_substeps`).
//! *substeps receives the number used, *capped whether the cap limited an unstable
//! Rk4Adaptive sample (both may be null). Returns whether the projection was active at the end.
bool rotor_advance(double& z, double& omega, double h, const RotorCoefficients& c, Integrator scheme,
                   int n_min, int max_substeps, int* substeps, bool* capped) noexcept;

//! Settings of the plant simulator (defaults in one place).
struct SliderSettings {
  //! Scheme (Rk4 is accepted but only stable for slow, non-stiff cases).
  Integrator integrator = Integrator::Rosenbrock;
  //! [s] every step() takes at least ceil(dt / max_substep) equal substeps (accuracy).
  double max_substep = 2.0e-5;
  int max_substeps = 100000;  //!< cap on substeps per step() (both schemes)
  double g_floor = 1.0e-7;    //!< [N m] lower bound on g (tiny f_n)
};

//! Checks the settings; one line per bad field in *message. Returns true when valid.
bool validate(const SliderSettings& s, std::string* message);
//! "SliderSettings(integrator='rosenbrock', ...)" at full precision (for bug reports).
std::string to_string(const SliderSettings& s);

//! One plant sample. f_n, c_tilde and tau_e are held over [t, t + dt].
struct SliderInput {
  double f_n = 0.0;      //!< normal force [N], > 0
  double c_tilde = 0.0;  //!< CoR of the motion, normalized c/rho [-], signed, finite (not clipped)
  double tau_e = 0.0;    //!< external torque about the CoR axis [N m]
  double dt = 0.0;       //!< step length [s], > 0
};

//! Plant state and friction at the end of the step.
struct SliderOutput {
  double z = 0.0;                //!< bristle state [rad], |z| <= g / sigma0
  double omega = 0.0;            //!< angular velocity about the CoR [rad/s]
  double zdot = 0.0;             //!< eq. 1 at the end state [rad/s]
  double g = 0.0;                //!< dry torque capacity about the CoR [N m] (eq. 18)
  double sigma_1 = 0.0;          //!< viscous coefficient about the CoR [N m s/rad] (eq. 17)
  double dry_torque = 0.0;       //!< sigma0 z + sigma_z zdot [N m]
  //! Friction torque about the CoR, sigma0 z + sigma_z zdot + sigma_1 omega [N m] (eq. 19):
  //! the torque the fingertip exerts on the slider is minus this; a fingertip sensor reads +this
  //! (docs/model.md 7.2), so this is the observer's y for a noiseless sensor.
  double friction_torque = 0.0;
  double slip = 0.0;             //!< sigma0 |z| / g [-] (eq. 37 for the true state)
  int substeps = 0;              //!< internal steps used
  bool projected = false;        //!< |z| was clipped to g / sigma0 at the end of the step
  Status status = Status::NoContact;  //!< Ok, or InvalidSample (state untouched)
};

//! The planar slider of eqs. 1-2 about a given (virtual) CoR, as a plant for simulators and
//! tests: z and omega, inertia J about the CoR axis, g and sigma_1 from the contact model at the
//! current f_n and c~. After every substep z is projected onto |z| <= g / sigma0 (docs/model.md 7.1),
//! so the friction never exceeds the current capacity when g drops.
class SliderModel {
 public:
  //! J: inertia about the CoR axis [kg m^2], finite and > 0. Throws std::invalid_argument.
  SliderModel(const ContactParams& params, double J, const SliderSettings& settings = SliderSettings());
  SliderModel(const ContactModel& model, double J, const SliderSettings& settings = SliderSettings());

  //! Advances by in.dt. Invalid input (non-finite, f_n <= 0, dt <= 0): InvalidSample, state
  //! untouched, out holds the previous output. Never throws or allocates.
  Status step(const SliderInput& in, SliderOutput& out) noexcept;
  //! Sets the state (z is not projected until the next step).
  void reset(double z = 0.0, double omega = 0.0) noexcept;

  double z() const noexcept { return z_; }
  double omega() const noexcept { return omega_; }
  double inertia() const noexcept { return J_; }
  const ContactModel& model() const noexcept { return model_; }
  const SliderSettings& settings() const noexcept { return s_; }

 private:
  ContactModel model_;
  SliderSettings s_;
  double J_;
  double z_ = 0.0, omega_ = 0.0;
  SliderOutput last_;
};

}  // namespace lugrip
