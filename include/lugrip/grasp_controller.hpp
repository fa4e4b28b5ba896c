// lugrip — grasp-force controller: slipping avoidance and pivoting (paper eqs. 34-37, docs/model.md 9)
// and the static grasp force a constant load settles at.
#pragma once

#include <array>
#include <string>

#include "lugrip/contact.hpp"
#include "lugrip/params.hpp"
#include "lugrip/status.hpp"

namespace lugrip {

//! Number of fingertips the controller combines (parallel gripper).
constexpr int kMaxFingers = 2;

//! Settings of GraspController; every default is here. All forces per finger [N] (a parallel
//! gripper applies the same normal force on both fingertips). Fields marked (*) may be changed
//! at run time through GraspController::set_settings() (validated again).
//!
//! The fields come in the groups of the controller's layers (docs/controller.md §1): the
//! gripper (rates, range, rate limits), the regulator (the paper's PI on S), the dynamic part
//! (the paper's C_d), the floors and the ceiling built from the measured load (not in the
//! paper), friction learned online (not in the paper) and pivoting. Every other number of the
//! law is a constant of the code (docs/controller.md names each one and the campaign that
//! showed that its setting did not pay). paper_settings() turns every addition off.
struct GraspControllerSettings {
  // --- gripper: rates, range, rate limits (docs/model.md 9.5) --------------------------------
  double sensor_rate = 500.0;  //!< [Hz] rate of step() calls (tactile/observer rate), > 0
  int command_ratio = 10;      //!< step() calls per force command (500 Hz / 50 Hz), >= 1
  double f_min = 0.1;   //!< [N] minimum force (keeps contact), > 0
  double f_max = 20.0;  //!< [N] maximum force (gripper limit), > f_min
  double max_rate = 200.0;  //!< (*) [N/s] the gripper's slew rate: limit on command changes, > 0 (inf: off)
  //! (*) [s] default 0.03; 0 = off (paper). The gripper's force time constant: when the
  //! feed-forward or the reflex lifts the static part above the force the gripper is estimated to
  //! apply (f_est: the commands through this first-order lag), the command overshoots the target
  //! by the lag's shortfall over one command period, (target - f_est) a / (1 - a),
  //! a = exp(-T / reaction_lag), so the force reaches the target within one period. >= 0, finite.
  double reaction_lag = 0.03;

  // --- regulator: static part in slipping avoidance, PI on e = S - s_ref (docs/model.md 9.4) --
  double s_ref = 0.8;  //!< (*) reference of the slippage indicator S-bar_a, in (0, 1)
  double k_p = 4.0;    //!< (*) [N] proportional gain (e > 0 raises the force), > 0
  double k_i = 16.0;   //!< (*) [N/s] integral gain (paper: 10), > 0
  //! (*) [N] default 6.4; 0 = the paper's constant gains. The loop gain of the PI on S is
  //! k |dS/df_n| = k n S / f_n (S ~ f_n^-n: n = 1 for a translational load, 1 + gamma for a
  //! torsional one), so constant gains limit-cycle at low force. With gain_force > 0 the gains
  //! are k_p f / (n gain_force) and k_i f / (n gain_force) (f: the last command; n from the
  //! contact model for the load of the last command period, in [1, 1 + gamma]): k_p and k_i are
  //! the gains at f = gain_force on a translational load. Gain changes are bumpless. >= 0, finite.
  double gain_force = 6.4;

  // --- dynamic part f_nd = |C_d omega_hat|, C_d(s) = k_cd (s + z_cd)/(s + p_cd) (eqs. 35-36) --
  // (on at construction; GraspController::set_dynamic_enabled() switches it, as the paper's
  // static and dynamic slipping avoidance are two operating modes)
  double k_cd = 10.0;   //!< [N s/rad] high-frequency gain, > 0
  double p_cd = 7.0;    //!< [rad/s] pole, > 0
  double z_cd = 250.0;  //!< [rad/s] zero, > p_cd (lag network, DC gain k_cd z_cd / p_cd)

  // --- floors and ceiling from the measured load (not in the paper; docs/controller.md) ------
  //! (*) default true; false = paper. The floors of the static part, from the measured load
  //! (the integrator restarts at a floor that lifts it; none while pivoting):
  //! - feed-forward: the static grasp force (StaticForceSolver at S = 0.9) of the load measured
  //!   over the last command period (mean f_t and tau of each valid finger, the larger force),
  //!   or of that load extrapolated 30 ms ahead along its trend when that asks 50 % more (a
  //!   load still rising at the command);
  //! - a reserve learned from the pushes seen (0.6 of the load's excursions below its peak,
  //!   both forgetting over 10 s): the load plus that reserve held at S = 1, as reserve_force;
  //! - slip reflex: when S = max_i S_i is at or above 0.93 on 3 valid samples of one command
  //!   period (anywhere in it: a chattering slide alternates S around the bound), 1.25 x the
  //!   grip the contact slid at (the last static part, or the measured f_n while the force
  //!   lags), whether or not the slip speed is observable (with Coulomb-like pads C_d adds
  //!   nothing).
  bool load_floors = true;
  //! (*) [N] default 0 = off. The task's envelope of pushes per finger: the static part is
  //! floored at the static grasp force at S = 1 of the measured load with reserve_force added
  //! to |f_t| and reserve_torque to |tau| (such a push then keeps the contact at its limit while
  //! the reaction is on its way); where the reserve learned from the pushes (load_floors) is
  //! larger, that one. >= 0, finite.
  double reserve_force = 0.0;
  double reserve_torque = 0.0;  //!< (*) [N m] default 0 = off; the twist to absorb. >= 0, finite.
  //! (*) [-] default 1.7; 0 = off (paper). In slipping avoidance a raise never takes the command
  //! above this factor times the grip the measured load needs at S = 1 (the period-mean load,
  //! the trend's load when the feed-forward uses it, or the load plus the reserve; the largest
  //! over the fingers; that grip also read from S, command x S), nor f_max; lowering is the
  //! PI's. A sticking contact's load is the object's, so reactions that pile up cannot crush a
  //! fragile object; a sliding contact's load is its friction, so the reaction still grows by
  //! this factor per command period. With the ceiling on, C_d adds at most 25 % of the static
  //! part. 0 or in [1, 1000].
  double ceiling_factor = 1.7;

  // --- friction learned online (not in the paper; docs/controller.md §9) ----------------------
  //! (*) [-] default 0 = off (mu as told, the paper's); 0.08 learns mu online. Relative size of
  //! the grip probe: while S is at least 0.5 and not falling, the static part is raised by this
  //! fraction for three command periods; a sliding contact's load follows the grip (elasticity
  //! d ln load / d ln f_n ~ 1), a sticking one's does not. A slip found so lowers the belief to
  //! the friction measured (by at most 30 % per probe, never below half the told mu, never
  //! above it). Off by default: a load rising during the probe reads as a slide
  //! (docs/controller.md §9). Needs each finger's f_n (FingerInput::f_n). In [0, 0.5].
  double mu_probe = 0.0;

  // --- pivoting mode (docs/model.md 9.6) -----------------------------------------------------------
  // (the filter's gain is k_p, docs/model.md 9.6; the manoeuvre ends at mean |c~_i| > 1, the paper's)
  double s_pivot = 1.3;      //!< (*) reference S-bar_p, > 1
  double tau_pivot = 2.0;    //!< (*) [s] time constant tau_p of the pivoting filter, > 0
};

//! The paper's law (eqs. 34-37): constant PI gains k_p = 4 N, k_i = 10 N/s, C_d as above, no
//! floor, reflex, lag overshoot, reserve, ceiling or learning. Three implementation choices of lugrip that have no
//! setting apply to it too: the PI's S is the mean over the command period, C_d's input has a
//! dead band of the observer's speed resolution, and the pivot's end test is lugrip's
//! (docs/controller.md §1).
GraspControllerSettings paper_settings() noexcept;

//! Checks every field; one line per bad field ("k_p = -1: must be finite and > 0") in *message
//! (if not null). Returns true when valid.
bool validate(const GraspControllerSettings& s, std::string* message);

//! Python-assignment style dump at full precision.
std::string to_string(const GraspControllerSettings& s);

//! Operating mode. Stable integer values.
enum class ControllerMode : int {
  SlippingAvoidance = 0,  //!< f_nd + PI on S (both parts active)
  Pivoting = 1,           //!< f_nd = 0, first-order filter driving S toward S-bar_p > 1
};

//! Why pivoting ended (reported in the call where it ends). Stable integer values.
enum class PivotEnd : int {
  None = 0,          //!< pivoting did not end in this call
  CorThreshold = 1,  //!< low-passed mean |c~| > 1 on 3 consecutive samples
  Timeout = 2,       //!< 10 s of pivoting elapsed
  Requested = 3,     //!< request_slipping_avoidance() while pivoting
  AtFloor = 4,       //!< the pivoting filter was held at its floor for 1 s
};

const char* to_string(ControllerMode m) noexcept;
const char* to_string(PivotEnd e) noexcept;

//! One fingertip's observer values for one sensor sample (filled from the observer output;
//! the controller does not depend on the observer type).
struct FingerInput {
  double omega_hat = 0.0;  //!< estimated sliding velocity about the CoR [rad/s]
  double slippage = 0.0;   //!< slippage indicator S = sigma0 |z^| / g [-], >= 0 (eq. 37)
  double c_tilde = 0.0;    //!< normalized CoR c / rho [-] (signed or magnitude)
  double f_t = 0.0;        //!< tangential force [N] (magnitude is used; pivoting floor)
  Status status = Status::Ok;  //!< observer status of this sample
  bool present = true;     //!< false: this finger is not used (one-finger operation)
  //! speed resolution of omega_hat [rad/s] (ObserverOutput::omega_resolution), >= 0; C_d sees
  //! omega_hat shrunk by it (a dead band: below it omega_hat is sensor noise); 0: none
  double omega_resolution = 0.0;
  double tau = 0.0;  //!< measured torsional moment [N m] (signed; feed-forward and slope)
  double f_n = 0.0;  //!< measured normal force [N] (grip probe, mu_probe); 0: unknown, no probe
};

//! Input of one step(): the two fingertips at one sensor sample.
//! When the call computes a command. Stable integer values.
enum class CommandTiming : int {
  //! The controller's clock: the first call after construction or reset() and every
  //! command_ratio-th call after it. A command is then computed from the samples up to the
  //! one of that call, i.e. from the first sample of each period onwards.
  Clock = 0,
  //! A command now, from the samples since the last command including this one; the clock
  //! restarts here. A gripper that takes a command after each batch of samples passes Now
  //! with the batch's newest sample (and Hold with the others): the command is not a period
  //! old when it is sent.
  Now = 1,
  Hold = 2,  //!< no command in this call (the samples count toward the next one)
};

struct GraspControllerInput {
  std::array<FingerInput, kMaxFingers> fingers{};
  CommandTiming command = CommandTiming::Clock;  //!< when this call computes a command
};

//! Output of one step() (caller-owned, reused). The command fields are those of the last
//! command issued (zero-order hold between commands); the *_sample fields belong to this call.
struct GraspControllerOutput {
  double force = 0.0;          //!< commanded grasp force f_n [N], in [f_min, f_max], finite
  double static_force = 0.0;   //!< static part f_ns at the last command [N]
  double dynamic_force = 0.0;  //!< dynamic part f_nd at the last command, after clipping [N]
  double floor = 0.0;          //!< lower bound applied at the last command [N]
  double slippage = 0.0;       //!< combined S = max_i S_i used at the last command [-]
  double error = 0.0;          //!< S - S-bar (S-bar_a or S-bar_p) at the last command [-]
  double integrator = 0.0;     //!< PI integrator I after the last command [N]
  double gain_p = 0.0;         //!< k_p used at the last command [N]
  double gain_i = 0.0;         //!< k_i used at the last command [N/s]
  double feedforward_force = 0.0;  //!< feed-forward force at the last command [N] (0: none)
  //! reserve of the last command, per finger, the largest over the fingers: the stated
  //! reserve_force or the pushes learned, the larger (docs/controller.md §8) [N]
  double reserve_force = 0.0;
  double reserve_torque = 0.0;  //!< the same for the twist [N m]
  bool reflex = false;         //!< last command: the slip reflex raised the static part
  double peak_slippage = 0.0;  //!< peak of max_i S_i over the period before the last command [-]
  double mu_belief = 0.0;      //!< friction coefficient the controller believes now [-]
  double ceiling = 0.0;        //!< ceiling of the last command (ceiling_factor; f_max when off) [N]
  bool probing = false;        //!< last command: a grip probe raised the static part
  bool probe_slip = false;     //!< last command: a probe found the contact sliding (mu lowered)
  //! signed C_d omega_hat_i of each finger at this sample [N] (0 for absent fingers)
  std::array<double, kMaxFingers> dynamic_sample{};
  double dynamic_peak = 0.0;   //!< peak of max_i |C_d omega_hat_i| since the last command [N]
  double mean_c_tilde = 0.0;   //!< mean |c~_i| over valid fingers at this sample [-]
  double pivot_time = 0.0;     //!< [s] time spent in the current pivoting manoeuvre
  ControllerMode mode = ControllerMode::SlippingAvoidance;  //!< mode after this call
  PivotEnd pivot_end = PivotEnd::None;  //!< reason, when pivoting ended in this call
  bool pivot_finished = false;  //!< event: pivoting ended in this call
  bool command_issued = false;  //!< a new command was computed in this call
  bool saturated = false;       //!< last command: static part or total clipped at a limit
  bool rate_limited = false;    //!< last command: the rate limit was active
  bool held = false;            //!< last command: safe hold/raise because of invalid input
  //! this sample: Ok, or the worst finger status (SensorFault > InvalidSample > NoContact) when
  //! a present finger is invalid (NaN/Inf/out of range counts as InvalidSample); NoContact when
  //! no finger is present.
  Status status = Status::Ok;
};

//! First-order filter k (s + z)/(s + p) discretised by Tustin (bilinear, no prewarping) at
//! sample time T: y[n] = b0 u[n] + b1 u[n-1] - a1 y[n-1], with K = 2/T,
//! b0 = k (K + z)/(K + p), b1 = k (z - K)/(K + p), a1 = (p - K)/(K + p).
//! DC gain k z / p and gain k at Nyquist are exact; |H(e^{jwT})| = |C(j K tan(wT/2))|.
class LagFilter {
 public:
  LagFilter() = default;
  LagFilter(double k, double z, double p, double sample_time) noexcept;
  double step(double u) noexcept {
    const double y = b0_ * u + b1_ * u_ - a1_ * y_;
    u_ = u;
    y_ = y;
    return y;
  }
  void reset() noexcept { u_ = y_ = 0.0; }  //!< zero state (output starts from 0)
  double b0() const noexcept { return b0_; }
  double b1() const noexcept { return b1_; }
  double a1() const noexcept { return a1_; }
  double output() const noexcept { return y_; }

 private:
  double b0_ = 0.0, b1_ = 0.0, a1_ = 0.0, u_ = 0.0, y_ = 0.0;
};

//! Static utilization and static grasp force for a constant load (docs/model.md 6, 9.4).
//!
//! S_static(f_n) = |tau - c f_t| / g(f_n, c) = (|tau| + |c| f_t) / g(f_n, c), with c~ from the
//! CoR estimator at f_n (same estimator and c_max clip as the closed loop), is what S settles
//! to in stick. (For a torque below the estimator's zero threshold, whose sign the estimator
//! holds from history, the load-motion sign rule is applied instead: at most 1e-4 tau_max.)
//! It decreases with f_n, so the force where the static controller settles, S_static = s_ref,
//! is one root: for a fixed load |c~| does not depend on f_n and S_static(f_n) = A f_n^-(1+gamma)
//! + B f_n^-1, whose constants one evaluation gives (Newton's method on that, checked by a second
//! evaluation); where the check fails, a bracket (doubling) and a safeguarded secant (Illinois)
//! on log f_n.
struct StaticForceResult {
  double force = 0.0;     //!< f_n [N] with S_static(f_n) = s_ref (0 for a zero load, NaN if invalid)
  double c_tilde = 0.0;   //!< |c~| estimated at that force [-]
  double slippage = 0.0;  //!< S_static at that force [-]
  int iterations = 0;     //!< S_static evaluations spent
  bool converged = false; //!< relative tolerance 1e-12 on f_n reached within the bound
};

//! S_static of one load as a function of f_n in closed form, S = a x^pw + b x with x = f0 / f_n
//! and pw = 1 + gamma (one evaluation of the map gives a and b, StaticForceSolver::map): exact
//! for every f_n where the load lies inside the LS or |c~| is at its clip, i.e. wherever S <= 1,
//! up to the estimator's zero thresholds.
struct StaticLoadMap {
  double f0 = 0.0;  //!< [N] force of the evaluation
  double a = 0.0;   //!< torsional term at f0, |tau| / g [-]
  double b = 0.0;   //!< translational term at f0, |c| |f_t| / g [-]
  double pw = 1.0;  //!< 1 + gamma
  bool valid = false;
  //! built by StaticForceSolver::map(): its evaluation lay inside the LS (the load at 80 % of the
  //! diamond |f~_t| + |tau~| <= 1), where |c~| is the load's own
  bool inside = false;
  double slippage(double f_n) const noexcept;  //!< S_static at f_n (NaN unless valid, f_n > 0)
  double root(double s_ref) const noexcept;    //!< f_n [N] with slippage(f_n) = s_ref (Newton)
};

class StaticForceSolver {
 public:
  //! Copies the model's tables into its own CoR estimator (allocates; construction only).
  explicit StaticForceSolver(const ContactModel& model);
  explicit StaticForceSolver(const ContactParams& params);

  //! S_static at normal force f_n [N] for a load f_t [N] (magnitude used), tau [N m]. Never
  //! allocates. NaN for a non-finite or non-positive f_n.
  double slippage(double f_n, double f_t, double tau, double* c_tilde = nullptr) noexcept;
  //! Per-finger static grasp force for the load (f_t, tau) and reference s_ref in (0, 1].
  StaticForceResult solve(double f_t, double tau, double s_ref = 0.8) noexcept;
  //! The closed form of S_static for the load (f_t, tau) from one evaluation (invalid for no
  //! load or a non-finite one).
  StaticLoadMap map(double f_t, double tau) noexcept;
  //! solve() from that load's map (one evaluation checks the map's root): several references
  //! of one load cost one evaluation each.
  StaticForceResult solve(const StaticLoadMap& map, double f_t, double tau, double s_ref) noexcept;
  //! solve(map, f_t, tau, s_ref).force, the same value, without the checking evaluation where
  //! the check cannot fail: a map from map() whose root and evaluation both lie in the
  //! estimator's general branch (a torque, |f~_t| at or above its zero threshold, forces and
  //! parameters in the ranges where every estimate is finite). There |c~| at the root is the
  //! map's (sigma does not depend on f_n), so the estimator's S there differs from s_ref by its
  //! inversion accuracy (1e-12), far inside the check's 1e-10. Otherwise solve().
  double force(const StaticLoadMap& map, double f_t, double tau, double s_ref) noexcept;
  //! solve(f_t, tau, s_ref).force through map() and force() (the same value).
  double force(double f_t, double tau, double s_ref) noexcept;

  const ContactModel& model() const noexcept { return est_.model(); }
  //! ContactModel::set_mu on the solver's model (no allocation); false: mu out of range.
  bool set_mu(double mu) noexcept { return est_.set_mu(mu); }

 private:
  // S_static at f_n (NaN where invalid) with the estimate it came from in o
  double evaluate(double f_n, double f_t, double tau, CorOutput& o) noexcept;
  // The estimator at f_n for the load (|f_t| = ft, tau) takes its general branch with finite
  // outputs (force()'s condition, checked at the map's force and at its root).
  bool general_branch(double f_n, double ft, double tau) const noexcept;
  CorEstimator est_;
  CorOutput scratch_;  // the estimate of map() and solve() (every field written: no per-call zeroing)
};

//! Two-mode grasp-force controller f_n = f_ns + f_nd (eq. 34, docs/model.md 9).
//!
//! * step() runs at the sensor rate. Every call updates one C_d filter per present finger
//!   (Tustin at the sensor rate) and the peak of max_i |C_d omega_hat_i|; every command_ratio-th
//!   call (the first call after construction/reset included) computes a new command, which is
//!   held in between (zero-order hold).
//! * Slipping avoidance: f_ns = k_p e + I, e = S - s_ref, forward-Euler integrator at the command
//!   rate; f_ns clipped to [f_min, f_max] with back-calculation anti-windup; f_nd = the peak of
//!   |C_d omega_hat| over the last command period clipped to [0, f_max - f_ns].
//! * Pivoting: f_nd = 0; tau_p df/dt = -f + k_p (S - s_pivot), exact discretisation at the
//!   command rate, started from the last command; floor max(f_min, 1.1 max_i |f_t,i| / mu)
//!   on the output and the filter state; ends on mean |c~_i| > 1 for
//!   3 consecutive sensor samples (mean |c~_i| low-passed with a 0.2 s time constant; counted
//!   only while the pivoting filter is held at the floor and max_i S_i < 0.99), after 1 s at
//!   the floor, after 10 s, or on request, then returns to
//!   slipping avoidance bumplessly (I = last command - k_p e at the next command, C_d reset).
//! * Two fingers (docs/model.md 9.8): S = max_i S_i, f_nd from max_i |C_d omega_hat_i|, pivot end on
//!   the mean of |c~_i|; absent fingers are ignored.
//! * Rate limits act on the total command after the force range; the floor wins over them.
//! * Invalid input (a present finger with NaN/Inf/out-of-range values or status InvalidSample,
//!   SensorFault, NoContact): its C_d state is held; a command due in such a call holds the last
//!   command, never lower, and the static law restarts bumplessly.
//! * Beyond the paper (each a setting, docs/controller.md): PI gains from the plant's slope
//!   (gain_force), floors on the static part from the static grasp force of the measured load
//!   and a slip reflex (load_floors, reserve), a ceiling from the same load (ceiling_factor) and a grip probe that
//!   learns mu (mu_probe). They act in slipping avoidance only, on the static part, before the
//!   force range and the rate limits.
class GraspController {
 public:
  //! Validates params (uses mu; the feed-forward and the slope use the whole contact model) and
  //! settings; throws std::invalid_argument naming bad fields. Builds the contact tables (a few
  //! tens of ms); the ContactModel overload copies them.
  GraspController(const ContactParams& params, const GraspControllerSettings& settings = {});
  GraspController(const ContactModel& model, const GraspControllerSettings& settings = {});

  //! One sensor sample. Never throws, never allocates; out.force is finite, in [f_min, f_max].
  //! Returns out.status.
  Status step(const GraspControllerInput& in, GraspControllerOutput& out) noexcept;

  //! Back to slipping avoidance with zeroed filters; current_force [N] (clipped to the range,
  //! f_min if not finite) is the command held until the next step(), which issues a command
  //! and starts the PI bumplessly from it.
  void reset(double current_force) noexcept;
  void reset() noexcept { reset(s_.f_min); }

  //! Latched requests, applied at the next step(). Pivoting starts from the last command.
  void request_pivoting() noexcept;
  void request_slipping_avoidance() noexcept;

  //! Switches the dynamic part between the paper's dynamic (on, the state after construction)
  //! and static slipping avoidance; re-enabling resets the C_d states. Kept by reset().
  void set_dynamic_enabled(bool enabled) noexcept;
  bool dynamic_enabled() const noexcept { return dynamic_; }
  //! Replaces the settings marked (*) (rates, C_d and force range must not change); throws
  //! std::invalid_argument when invalid or when a fixed field differs.
  void set_settings(const GraspControllerSettings& settings);
  //! Replaces the told friction coefficient (the one the observers' S is normalised with) and
  //! restarts the belief from it. Real-time safe: no allocation, noexcept; returns false and
  //! changes nothing unless 0 < mu <= 10 (ContactParams::mu).
  bool set_mu(double mu) noexcept;
  //! Replaces the contact model (mu, feed-forward, slope) by a copy of `model`'s (allocates).
  void set_contact_model(const ContactModel& model);

  ControllerMode mode() const noexcept { return mode_; }
  double command() const noexcept { return command_; }
  double command_period() const noexcept { return t_cmd_; }  //!< [s]
  const GraspControllerSettings& settings() const noexcept { return s_; }
  const LagFilter& dynamic_filter(int finger) const noexcept { return cd_[finger]; }
  double mu() const noexcept { return mu0_; }                //!< told mu [-]
  double mu_belief() const noexcept { return mu_; }         //!< believed mu (learned) [-]
  const ContactModel& contact_model() const noexcept { return solver_.model(); }

 private:
  enum class Request { None, Pivot, Avoid };
  void end_pivot(PivotEnd why, GraspControllerOutput& out) noexcept;
  void reset_dynamic() noexcept;
  void issue_command(bool valid, double slip) noexcept;
  double static_floor(double& slope_exponent) noexcept;
  // static_floor() raised by the armed slip reflex; records both in c (feedforward_force, reflex)
  double reaction_floor(double& slope_exponent, GraspControllerOutput& c) noexcept;
  void clear_period() noexcept;
  // The grip probe (mu_probe): probe_evaluate() counts a running probe down and, at its end,
  // compares the period's load with the reference period's (slip lowers mu_); probe_start()
  // takes this period as the reference of a new probe when one is due (true: started).
  void probe_evaluate() noexcept;
  bool probe_start(double slip_mean, bool reacting) noexcept;
  void reset_probe() noexcept;
  static constexpr int kProbeGapMin = 3;  // [commands] at least between two probes
  // One finger's load over one command period (the probe's measurements).
  struct PeriodLoad {
    double fn = 0.0, ft = 0.0, tau = 0.0;  // means [N], [N], [N m]
    double var_ft = 0.0, var_tau = 0.0;    // sample variances [N^2], [N^2 m^2]
    int n = 0;                             // samples (0: none usable)
  };
  PeriodLoad period_load(int finger) const noexcept;

  GraspControllerSettings s_;
  StaticForceSolver solver_;  // feed-forward force and slope exponent
  double mu_ = 1.0;   // believed mu (the solver's)
  double mu0_ = 1.0;  // told mu (the observers' normalisation of S)
  double gamma_ = 0.25;
  double dt_ = 0.002, t_cmd_ = 0.02, pivot_decay_ = 0.0;
  std::array<LagFilter, kMaxFingers> cd_{};
  ControllerMode mode_ = ControllerMode::SlippingAvoidance;
  Request request_ = Request::None;
  bool dynamic_ = true;       // the dynamic part is active in slipping avoidance
  bool init_static_ = true;   // bumpless (re)start of the static law at the next command
  int phase_ = 0;             // calls since the last command
  double command_ = 0.0;      // last command [N]
  double integrator_ = 0.0;   // PI integrator I [N]
  double pivot_state_ = 0.0;  // pivoting filter state [N]
  double peak_ = 0.0;         // running peak of max_i |C_d omega_i| [N]
  long pivot_samples_ = 0;    // samples since pivoting started
  int pivot_count_ = 0;       // consecutive samples with mean |c~| above the threshold
  bool pivot_at_floor_ = false;  // the last pivoting command wanted to go below the floor
  long pivot_floor_samples_ = 0;  // consecutive samples with the filter held at the floor
  bool pivot_c_init_ = true;     // the low-pass on mean |c~| starts at the next valid sample
  double pivot_c_filtered_ = 0.0;  // low-passed mean |c~| of the pivot end test [-]
  double pivot_c_alpha_ = 1.0;     // its coefficient 1 - exp(-dt / kPivotEndFilter)
  double last_f_t_ = 0.0;     // last valid max_i |f_t,i| [N] (pivot floor)
  double last_kp_ = 0.0;      // k_p of the last command [N] (bumpless gain change)
  double last_e_ = 0.0;       // proportional error of the last command [-]
  std::array<double, kMaxFingers> sum_f_t_{}, sum_tau_{};  // valid samples since the last command
  std::array<int, kMaxFingers> n_load_{};
  std::array<double, kMaxFingers> sum_kf_{}, sum_kt_{};  // sums of k f_t, k tau (k: sample index in the period)
  std::array<double, kMaxFingers> sum_k_{}, sum_kk_{};   // sums of k, k^2 over those samples
  std::array<int, kMaxFingers> k_load_{};                // sample index in the period
  double f_est_ = 0.0;        // gripper force estimated through reaction_lag [N]
  double floor_measured_ = 0.0;  // reaction floor without the trend (mean load, reflex) [N]
  double ceiling_load_ = 0.0;    // grip the period's load needs at S = 1 (ceiling_factor) [N]
  double trend_lift_ = 0.0;      // part of the last restart of the integrator due to the trend [N]
  double trend_force_ = 0.0;     // static part the trend lifted to at the last command [N]
  double peak_s_ = 0.0;       // peak of max_i S_i since the last command
  double sum_s_ = 0.0;        // sum of max_i S_i over the valid samples since the last command
  int n_s_ = 0;
  int count_s_ = 0;            // valid samples with S >= 0.93 since the last command
  bool reflex_armed_ = false;  // such samples reached 3 since the last command
  // grip probe (mu_probe)
  std::array<double, kMaxFingers> sum_f_n_{};  // sum of f_n over the load samples of the period
  std::array<bool, kMaxFingers> fn_ok_{{true, true}};  // every load sample of the period had f_n
  std::array<double, kMaxFingers> sum_ft2_{}, sum_tau2_{};   // sums of squares (variances)
  std::array<PeriodLoad, kMaxFingers> prev_load_{};  // the previous period's
  std::array<PeriodLoad, kMaxFingers> ref_a_{}, ref_b_{};  // the two periods before the probe
  std::array<PeriodLoad, kMaxFingers> probe_a_{};          // the probe's second period
  int probe_left_ = 0;        // commands of the running probe still to issue (0: none)
  int probe_wait_ = 0;        // commands until the next probe may start
  double probe_s_ = 0.0;      // highest S at which a probe found stick (0: none since a slip)
  double probe_ref_s_ = 0.0;  // S of the running probe's reference period
  double probe_f_ = 0.0;      // static part at the start of the last probe that found stick [N]
  bool probe_disturbed_ = false;  // a reaction acted during the running probe
  double prev_s_ = 0.0;       // mean S of the previous command period
  double probe_base_ = 0.0;   // static part when the probe started [N]
  bool probe_slip_ = false;   // the last evaluated probe found slip

  // reserve learned from the pushes (load_floors): per finger, the decaying peak of the
  // period-mean load (|f_t| [N], |tau| [N m]) and the excursion learned from it
  std::array<double, kMaxFingers> peak_ft_{}, peak_tau_{}, learned_ft_{}, learned_tau_{};
  std::array<bool, kMaxFingers> peak_valid_{};
  double reserve_decay_ = 0.0;  // forgetting factor of both per command
  double reserve_force_ = 0.0, reserve_torque_ = 0.0;  // reserve of the last floor (output)
  GraspControllerOutput last_{};  // command fields of the last command
};

//! Convenience: per-finger static grasp force [N] (builds a ContactModel; prefer
//! StaticForceSolver for many loads). Throws std::invalid_argument for invalid params or s_ref,
//! a non-finite load, or a load whose force is outside the solver's range (1e-12 to 1e12 N).
double static_grasp_force(const ContactParams& params, double f_t, double tau, double s_ref = 0.8);

}  // namespace lugrip
