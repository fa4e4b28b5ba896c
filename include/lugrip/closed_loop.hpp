// lugrip — closed-loop grasp simulation: plant -> two fingertip sensors -> two observers ->
// grasp-force controller -> gripper command (docs/model.md 9.7, 9.8, 10.1), plus the two baseline
// controllers of the experiments (constant force, friction-cone threshold).
//
// Multi-rate (docs/model.md 9.7): the plant steps at PlantConfig::rate (1 kHz); both sensors are
// sampled at sensor.rate (500 Hz) and each sample goes through its finger's Observer and the
// controller at once (no computation delay); the controller issues a command every
// command_ratio samples (50 Hz), which the plant's zero-order hold latches at its command tick
// (the same instant) and passes through the first-order actuator lag.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "lugrip/grasp_controller.hpp"
#include "lugrip/grasp_plant.hpp"
#include "lugrip/observer.hpp"
#include "lugrip/slip_control.hpp"

namespace lugrip {

//! Which law computes the grasp-force command. Stable integer values.
enum class ControllerKind : int {
  //! GraspController (paper eqs. 34-37: slipping avoidance + pivoting), fed by the observers.
  Lugrip = 0,
  //! Baseline: a constant command (ClosedLoopConfig::constant_force) from controller_start on.
  ConstantForce = 1,
  //! Baseline: friction-cone threshold controller, blind to torsion. At each command the
  //! translational utilisation u = max_i |f_t,i| / (mu f_n,i) of the measured forces (mean over
  //! the command period) is compared with cone_margin; the command starts at controller.f_min
  //! (at controller_start) and, when u >= cone_margin, is raised
  //! to max_i |f_t,i| / (mu cone_margin) (never lowered, except by cone_release_rate while
  //! u < cone_margin). Same force range and rate limits as the GraspController settings.
  FrictionCone = 2,
};

//! Mode-schedule actions (the experiment's operator or task logic). Stable integer values.
enum class ModeAction : int {
  Pivot = 0,              //!< GraspController::request_pivoting()
  SlippingAvoidance = 1,  //!< GraspController::request_slipping_avoidance()
  DynamicOn = 2,          //!< GraspController::set_dynamic_enabled(true)
  DynamicOff = 3,         //!< GraspController::set_dynamic_enabled(false)
};

const char* to_string(ControllerKind k) noexcept;
const char* to_string(ModeAction a) noexcept;

//! Injected fault of the simulated sensor or actuator path. Stable integer values. Sensor faults
//! change the wrench the observers and the controller receive (and the logged *_meas columns),
//! never the plant; actuator faults change the command between the controller and the gripper.
enum class FaultKind : int {
  Dropout = 0,       //!< the sensor repeats its last delivered sample (bursts)
  NanBurst = 1,      //!< every channel reads NaN (bursts)
  Spike = 2,         //!< `force` added to f_x and f_y, `torque` to tau, sign alternating per burst
  BiasDrift = 3,     //!< offset growing from 0 at force_rate on f_x, f_y and torque_rate on tau
  Saturation = 4,    //!< f_x, f_y clipped to +-force and tau to +-torque (a saturated range)
  Stuck = 5,         //!< every channel frozen at the last sample delivered before the onset
  Dead = 6,          //!< every channel reads 0 (a sensor without power or signal)
  ContactLoss = 7,   //!< the pad reads no contact (f_n, f_x, f_y, tau = 0), then re-contact
  ActuatorLag = 8,   //!< extra first-order lag `time_constant` between command and gripper
  ActuatorSaturation = 9,  //!< the gripper's command saturates at `force`
};

const char* to_string(FaultKind k) noexcept;

//! One fault, active for t_start <= t < t_start + duration. Within that window it is active on
//! the samples k (counted from the onset) with k mod every < burst (every = 0: every sample).
//!
//! | field | meaning | unit | default |
//! |---|---|---|---|
//! | kind | FaultKind | | Dropout |
//! | finger | sensor faults: 0, 1 or -1 (both) | | -1 |
//! | t_start, duration | active window (t_start <= 1e9) | s | 0, inf |
//! | burst, every | burst length and burst period | samples | 1, 0 |
//! | force | Spike height, Saturation limit, ActuatorSaturation limit | N | 0 |
//! | torque | Spike height, Saturation limit | N m | 0 |
//! | force_rate, torque_rate | BiasDrift slopes | N/s, N m/s | 0 |
//! | time_constant | ActuatorLag | s | 0 |
struct FaultSpec {
  FaultKind kind = FaultKind::Dropout;
  int finger = -1;
  double t_start = 0.0;    //!< [s]
  double duration = 1e300; //!< [s]
  int burst = 1;           //!< [samples] >= 1
  int every = 0;           //!< [samples] 0 or >= burst
  double force = 0.0;      //!< [N]
  double torque = 0.0;     //!< [N m]
  double force_rate = 0.0;   //!< [N/s]
  double torque_rate = 0.0;  //!< [N m/s]
  double time_constant = 0.0;  //!< [s]
};

//! Most faults one closed loop injects.
constexpr int kMaxFaults = 16;

//! Checks every fault (one line per problem, prefixed "faults[i]."). Returns true when valid.
bool validate(const std::vector<FaultSpec>& faults, std::string* message);

//! Applies a list of faults to the wrenches of each sensor sample and to the command sent to the
//! gripper (ClosedLoop uses one; a simulator of its own, e.g. the MuJoCo loop, can too).
//! Lifecycle: construct (validates, copies the list) -> sensors()/actuator() once per sample,
//! in sample order (noexcept, no allocation) -> reset().
class FaultInjector {
 public:
  FaultInjector() = default;
  //! sample_period [s] in [1e-9, 1e3]. Throws std::invalid_argument for an invalid fault list.
  FaultInjector(const std::vector<FaultSpec>& faults, double sample_period);
  //! Back to before the first sample; `command` [N] is the gripper's command before it.
  void reset(double command = 0.0) noexcept;
  //! Sensor faults of sample n (t = n * sample_period) applied to the fingers' wrenches in
  //! place. Returns true when a fault acted.
  bool sensors(int64_t n, std::array<FingerWrench, kMaxFingers>& fingers) noexcept;
  //! Actuator faults of sample n: the command [N] that reaches the gripper; sets `active`
  //! when a fault acted (leaves it unchanged otherwise).
  double actuator(int64_t n, double command, bool& active) noexcept;
  bool empty() const noexcept { return faults_.empty(); }
  const std::vector<FaultSpec>& faults() const noexcept { return faults_; }

 private:
  std::vector<FaultSpec> faults_;
  double dt_ = 0.002;
  std::array<FingerWrench, kMaxFingers> last_{};   // last wrench delivered per finger
  std::array<FingerWrench, kMaxFingers> frozen_{}; // Stuck: wrench at the onset per finger
  std::array<bool, kMaxFaults> was_active_{};
  double lag_state_ = 0.0;      // ActuatorLag filter output [N]
  double last_actuator_ = 0.0;  // command that reached the gripper at the last sample [N]
  bool lag_init_ = false;

  bool on(const FaultSpec& f, int64_t n) const noexcept;
  int64_t first_sample(const FaultSpec& f) const noexcept;
};

//! One scheduled action, applied before the first sensor sample with t >= time.
struct ModeEvent {
  double time = 0.0;  //!< [s]
  ModeAction action = ModeAction::Pivot;
};

//! Everything a closed-loop run needs. The observer's dt and the controller's rates must match
//! the plant: observer.dt = 1/sensor.rate, controller.sensor_rate = sensor.rate and
//! controller.command_ratio = sensor.rate / actuator.command_rate (validated).
//!
//! | field | meaning | unit | default |
//! |---|---|---|---|
//! | plant | object, contact, actuator, sensors, moves, disturbances (GraspPlant) | | (required) |
//! | observer | settings of both fingers' Observer | | ObserverSettings() |
//! | estimator | contact parameters the observers and the controller use (what the robot believes); unset: the plant's own | | unset |
//! | controller | GraspController settings (also the range/rate limits of the baselines) | | GraspControllerSettings() |
//! | kind | which law computes the command | | Lugrip |
//! | controller_start | before this time the command stays at plant.actuator.f_init | s | 0 |
//! | constant_force | ConstantForce command | N | 1 |
//! | cone_margin | FrictionCone target utilisation, in (0, 1] | - | 0.8 |
//! | cone_release_rate | FrictionCone decrease rate while below the margin (0: ratchet) | N/s | 0 |
//! | schedule | mode actions (sorted by time at construction) | | {} |
//! | faults | injected sensor/actuator faults (at most kMaxFaults) | | {} |
//! | stuck_samples | SlipControlSettings::stuck_samples of the lugrip law (0: off) | samples | 0 |
//! | healthy_finger_fallback | SlipControlSettings::healthy_finger_fallback | | false |
struct ClosedLoopConfig {
  PlantConfig plant;
  ObserverSettings observer;
  //! Contact parameters of the estimator side (observers, controller). A real fingertip is not
  //! the lumped model: set this to the parameters identified for the simulated fingertip (or to
  //! deliberately wrong ones, to study mismatch). Unset: plant.contact.
  std::optional<ContactParams> estimator;
  GraspControllerSettings controller;
  ControllerKind kind = ControllerKind::Lugrip;
  double controller_start = 0.0;
  double constant_force = 1.0;
  double cone_margin = 0.8;
  double cone_release_rate = 0.0;
  std::vector<ModeEvent> schedule;
  std::vector<FaultSpec> faults;
  int stuck_samples = 0;
  bool healthy_finger_fallback = false;
};

//! Checks the plant config, the observer and controller settings, the rate consistency and the
//! baseline fields; one line per problem in *message. Returns true when valid.
bool validate(const ClosedLoopConfig& c, std::string* message);

//! One closed-loop sample (sensor time t). Measured and estimated values are those the
//! controller used at t; plant values are the true state at t (before the plant advances).
struct ClosedLoopSample {
  int64_t index = 0;   //!< sample number (t = index / sensor.rate)
  double t = 0.0;      //!< [s]
  double command = 0.0;        //!< grasp-force command sent to the gripper (held between commands) [N]
  double static_force = 0.0;   //!< f_ns of the last command (Lugrip; else the command) [N]
  double dynamic_force = 0.0;  //!< f_nd of the last command (Lugrip; else 0) [N]
  double f_n = 0.0;            //!< true normal force of each finger (actuator) [N]
  // per finger: measured (sensor frame) and estimated
  std::array<double, 2> f_n_meas{}, f_t_meas{}, tau_meas{};  //!< [N], [N], [N m]
  std::array<double, 2> f_t_true{}, tau_true{};  //!< true friction load [N], [N m]
  std::array<double, 2> omega_hat{}, slippage{}, c_tilde{};  //!< [rad/s], [-], [-]
  std::array<double, 2> omega_true{}, c_tilde_true{};  //!< true slip velocity [rad/s], CoR [-]
  std::array<int, 2> observer_status{};  //!< Status codes
  // object (ground truth)
  double slip_x = 0.0, slip_y = 0.0;  //!< displacement of the grasped object point [m]
  double slip = 0.0;                   //!< |(slip_x, slip_y)| (patch) or slip length (lumped) [m]
  double rotation = 0.0;               //!< theta - theta0 [rad]
  double theta = 0.0;                  //!< object angle [rad]
  double cog_x = 0.0, cog_y = 0.0;     //!< CoG relative to the grasp point (gripper axes) [m]
  double gripper_y = 0.0;              //!< grasp-point height [m]
  double ext_fx = 0.0, ext_fy = 0.0, ext_tau = 0.0;  //!< disturbance [N], [N m]
  int mode = 0;                 //!< ControllerMode code (Lugrip; else 0)
  bool command_issued = false;  //!< a command was computed at this sample
  bool pivot_finished = false;  //!< pivoting ended at this sample
  int pivot_end = 0;            //!< PivotEnd code when pivot_finished
  bool supported = false;       //!< object resting on the support
  bool dropped = false;         //!< a drop criterion has been met (latched)
  bool finite = true;           //!< every value of this sample is finite (the measured columns
                                //!< excepted while an injected fault acts: a NaN burst reads NaN)
  int status = 0;               //!< Status code of the cycle (what step() returned)
  bool fault_active = false;    //!< an injected fault acted on this sample
  double actuator_command = 0.0;  //!< command reaching the gripper after actuator faults [N]
  double mu_belief = 0.0;  //!< friction coefficient lugrip's controller believes (Lugrip; else the told mu) [-]
};

//! Arrays of a batch run, one entry per sample (columns of ClosedLoopSample).
struct ClosedLoopLog {
  std::vector<double> t, command, static_force, dynamic_force, f_n;
  std::array<std::vector<double>, 2> f_n_meas, f_t_meas, tau_meas, f_t_true, tau_true, omega_hat,
      slippage, c_tilde, omega_true, c_tilde_true;
  std::array<std::vector<int32_t>, 2> observer_status;
  std::vector<double> slip_x, slip_y, slip, rotation, theta, cog_x, cog_y, gripper_y, ext_fx, ext_fy, ext_tau;
  std::vector<int32_t> mode, pivot_end;
  std::vector<uint8_t> command_issued, pivot_finished, supported, dropped, finite;
  std::vector<int32_t> status;
  std::vector<uint8_t> fault_active;
  std::vector<double> actuator_command, mu_belief;

  void reserve(size_t n);
  void append(const ClosedLoopSample& s);
  size_t size() const noexcept { return t.size(); }
};

//! The closed loop. Lifecycle: construct (validates, allocates) -> step() (noexcept, no
//! allocation) -> reset(). Deterministic: the same config gives the same run.
class ClosedLoop {
 public:
  //! Throws std::invalid_argument (every problem listed) for an invalid config.
  explicit ClosedLoop(const ClosedLoopConfig& config);

  //! Back to t = 0 (plant, observers, controller, schedule).
  void reset() noexcept;
  //! Processes the current sensor sample (schedule, observers, controller, command), records it
  //! in `out`, then advances the plant to the next sample. Returns the status of the cycle
  //! (SlipControl's while the lugrip law runs, else the worst observer status; Ok when valid).
  Status step(ClosedLoopSample& out) noexcept;
  //! Runs `samples` steps, appending to `log` (allocates: not for real-time use).
  void run(int64_t samples, ClosedLoopLog& log);

  const ClosedLoopConfig& config() const noexcept { return cfg_; }
  const GraspPlant& plant() const noexcept { return plant_; }
  const GraspController& controller() const noexcept { return sc_.controller(); }
  const Observer& observer(int finger) const noexcept { return sc_.observer(finger); }
  const SlipControl& slip_control() const noexcept { return sc_; }
  double time() const noexcept { return plant_.time(); }
  double sample_period() const noexcept { return dt_; }
  int64_t samples() const noexcept { return n_; }

 private:
  ClosedLoopConfig cfg_;
  GraspPlant plant_;
  SlipControl sc_;
  double dt_ = 0.002;
  int ratio_ = 10;
  int64_t n_ = 0;
  size_t next_event_ = 0;
  double command_ = 0.0;        // command sent to the plant [N]
  bool started_ = false;        // the controller/baseline is active
  std::array<double, 2> cone_fn_sum_{}, cone_ft_sum_{};  // friction cone: sums this period
  int cone_count_ = 0;
  SlipControlOutput sout_;
  FaultInjector faults_;

  void apply_events(double t) noexcept;
  void cone_command() noexcept;
};

}  // namespace lugrip
