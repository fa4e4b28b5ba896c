// lugrip — one object per control cycle: fingertip wrenches in, grasp-force command out.
// Two (or one) Observers feeding a GraspController, with every status forwarded
// (docs/model.md §9.7, §9.8).
#pragma once

#include <array>
#include <string>

#include "lugrip/contact.hpp"
#include "lugrip/grasp_controller.hpp"
#include "lugrip/observer.hpp"
#include "lugrip/params.hpp"
#include "lugrip/status.hpp"

namespace lugrip {

//! Settings of SlipControl: the observer of every finger, the controller and the finger count.
//! Constraint checked at construction: observer.dt * controller.sensor_rate == 1.
struct SlipControlSettings {
  ObserverSettings observer;            //!< settings of each finger's Observer
  GraspControllerSettings controller;   //!< settings of the GraspController
  int fingers = 2;                      //!< fingertips measured: 1 or 2
  //! A finger with a valid estimate whose four channels repeat bit for bit for this many
  //! consecutive samples is reported SensorFault (a frozen sensor, or a link that repeats its
  //! last sample; a noisy sensor never repeats exactly). 0: off (for a noise-free simulated or
  //! coarsely quantised sensor, which repeats legitimately). Default 25: 50 ms at 500 Hz.
  int stuck_samples = 25;               //!< [samples], >= 0
  //! Two fingers, one without a valid estimate (dead, frozen, no contact, invalid samples):
  //! the other finger alone drives the controller instead of holding the command. The cycle
  //! status still reports the faulty finger. false: hold (the default).
  bool healthy_finger_fallback = false;
};

//! Checks both nested settings, the finger count and the rate consistency; one line per problem
//! in *message ("observer.dt = ...", "controller.k_p = ..."). Returns true when valid.
bool validate(const SlipControlSettings& s, std::string* message);
//! "SlipControlSettings(observer=..., controller=..., fingers=2, ...)" at full precision.
std::string to_string(const SlipControlSettings& s);

//! One fingertip wrench as a force/torque sensor reads it (object on fingertip, z along the
//! contact normal; docs/model.md §7.2).
struct FingerWrench {
  double f_n = 0.0;  //!< normal force [N]
  double f_x = 0.0;  //!< tangential force, sensor x [N]
  double f_y = 0.0;  //!< tangential force, sensor y [N]
  double tau = 0.0;  //!< torsional moment about the normal [N m]
};

//! Input of one cycle. Fingers beyond SlipControlSettings::fingers are ignored.
struct SlipControlInput {
  std::array<FingerWrench, kMaxFingers> fingers{};  //!< per-finger wrench
  double dt = 0.0;  //!< [s] time since the previous cycle; 0: the nominal observer dt
  //! When this cycle computes a command (GraspController's CommandTiming): Clock (every
  //! command_ratio-th cycle from reset), Now (a command from the samples up to this one) or Hold.
  CommandTiming command = CommandTiming::Clock;
};

//! Output of one cycle (caller-owned, reused).
struct SlipControlOutput {
  double force = 0.0;  //!< grasp-force command to send [N], in [f_min, f_max], finite
  //! Ok, or the worst status of this cycle (the controller's combination of the finger
  //! statuses); any status but Ok means the command was held at the last command due, except
  //! under healthy_finger_fallback, where one faulty finger is reported while the other
  //! finger's estimate computes the command.
  Status status = Status::Ok;
  GraspControllerOutput controller;                   //!< full controller output
  std::array<ObserverOutput, kMaxFingers> fingers{};  //!< each finger's observer output
};

//! Slip detection and grasp-force control for one gripper.
//!
//! step() runs each present finger's Observer on its wrench, hands omega_hat, S, c~, f_t, the
//! speed resolution and the observer status to the GraspController and returns its command.
//! The statuses travel inside: when a finger's observer reports anything but a valid estimate
//! (NoContact on contact loss, InvalidSample, SensorFault, an unknown code) the command due in
//! that cycle is held at the last command, never lowered. With
//! stuck_samples > 0 (the default) a finger whose wrench repeats exactly that many times in a row
//! while its observer has a valid estimate is reported SensorFault (its observer keeps running)
//! until the wrench changes; a repeated reading that is already invalid (no contact, NaN) keeps
//! its own status.
//!
//! Lifecycle: construct (validates, allocates the contact tables) -> step() / the run-time
//! calls (noexcept, no allocation; set_mu() included) -> reset().
//! Thread safety: none inside; use one object per thread (or guard it with your own lock).
class SlipControl {
 public:
  //! Validates params and settings (std::invalid_argument, one line per problem).
  explicit SlipControl(const ContactParams& params, const SlipControlSettings& settings = {});
  //! Reuses an existing contact model (copies its tables; no quadrature).
  explicit SlipControl(const ContactModel& model, const SlipControlSettings& settings = {});

  //! One cycle at the sensor rate. Never throws, never allocates; out.force is finite and in
  //! [f_min, f_max]. Returns out.status.
  Status step(const SlipControlInput& in, SlipControlOutput& out) noexcept;
  //! Runs the observers only (fills out.fingers; the controller is not stepped and out.force
  //! keeps its value), e.g. while another law commands the gripper. Returns the worst finger
  //! status (Ok when every present finger carries an estimate).
  Status observe(const SlipControlInput& in, SlipControlOutput& out) noexcept;

  //! Observers forgotten, controller back to slipping avoidance; `force` [N] (clipped to the
  //! range, f_min if not finite) is held until the next step(), which starts from it.
  void reset(double force) noexcept;
  void reset() noexcept { reset(ctrl_.settings().f_min); }

  void request_pivoting() noexcept { ctrl_.request_pivoting(); }                      //!< at the next step()
  void request_slipping_avoidance() noexcept { ctrl_.request_slipping_avoidance(); }  //!< at the next step()
  //! The paper's dynamic (on, after construction) or static slipping avoidance (off).
  void set_dynamic_enabled(bool enabled) noexcept { ctrl_.set_dynamic_enabled(enabled); }

  //! Replaces the told friction coefficient of the observers and the controller (the
  //! per-object refit, docs/model.md §8.1); the controller's learned belief restarts from it.
  //! Real-time safe (mu scales every contact map; no table is rebuilt): noexcept, no
  //! allocation. The observers restart at the next sample; the controller keeps its mode and
  //! its last command. Returns false and changes nothing unless 0 < mu <= 10.
  bool set_mu(double mu) noexcept;

  //! Replaces the controller settings marked (*) in GraspControllerSettings (validated).
  void set_controller_settings(const GraspControllerSettings& settings) {
    ctrl_.set_settings(settings);
    s_.controller = ctrl_.settings();
  }

  double command() const noexcept { return ctrl_.command(); }  //!< last command [N]
  ControllerMode mode() const noexcept { return ctrl_.mode(); }
  int fingers() const noexcept { return s_.fingers; }
  const ContactParams& params() const noexcept { return obs_[0].model().params(); }
  const SlipControlSettings& settings() const noexcept { return s_; }
  const Observer& observer(int finger) const noexcept { return obs_[finger == 1 ? 1 : 0]; }
  const GraspController& controller() const noexcept { return ctrl_; }

 private:
  SlipControlSettings s_;
  std::array<Observer, kMaxFingers> obs_;
  GraspController ctrl_;
  GraspControllerInput cin_{};
  std::array<FingerWrench, kMaxFingers> prev_{};  // previous wrench per finger (stuck check)
  std::array<int, kMaxFingers> repeats_{};        // consecutive exact repeats per finger
};

}  // namespace lugrip
