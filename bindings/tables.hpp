// The one description of every struct the Python module exposes: field name, member and a
// short doc with the unit; the settings users set are the core's own tables
// (lugrip/settings_fields.hpp, lugrip/grasp_controller_fields.hpp). The nanobind attributes,
// the `fields` tuples (from which the Python dataclasses, settings conversions and batch outputs
// are built) and the batch columns all come from these tables, so a field added to a table
// appears everywhere at once.
#pragma once

#include <tuple>

#include "fields.hpp"
#include "lugrip/closed_loop.hpp"
#include "lugrip/contact.hpp"
#include "lugrip/grasp_controller.hpp"
#include "lugrip/grasp_controller_fields.hpp"
#include "lugrip/settings_fields.hpp"
#include "lugrip/grasp_plant.hpp"
#include "lugrip/identification.hpp"
#include "lugrip/observer.hpp"
#include "lugrip/params.hpp"
#include "lugrip/slider_model.hpp"
#include "lugrip/slip_control.hpp"

namespace lugrip_bind {

using namespace lugrip;

// --- parameters and settings ----------------------------------------------------------------

template <>
struct Table<ContactParams> : lugrip::FieldTable<ContactParams> {};  // lugrip/settings_fields.hpp

template <>
struct Table<CorSettings> : lugrip::FieldTable<CorSettings> {};  // lugrip/settings_fields.hpp

template <>
struct Table<SliderSettings> : lugrip::FieldTable<SliderSettings> {};  // lugrip/settings_fields.hpp

template <>
struct Table<ObserverSettings> : lugrip::FieldTable<ObserverSettings> {};  // lugrip/settings_fields.hpp

template <>
struct Table<GraspControllerSettings> {
  // described once in the core (the parameter-file loader reads the same table)
  static constexpr auto fields = lugrip::grasp_controller_fields;
};

template <>
struct Table<SlipControlSettings> : lugrip::FieldTable<SlipControlSettings> {};  // lugrip/settings_fields.hpp

template <>
struct Table<IdentificationSettings> : lugrip::FieldTable<IdentificationSettings> {};  // lugrip/settings_fields.hpp

// --- per-sample outputs ---------------------------------------------------------------------

template <>
struct Table<CorOutput> {
  using S = CorOutput;
  static constexpr auto fields = std::make_tuple(
      field("c_tilde", &S::c_tilde, "signed normalized CoR [-], |c~| <= c_max"),
      field("c", &S::c, "signed CoR position [m]"),
      field("ft_tilde", &S::ft_tilde, "f_t / (mu f_n) [-]"),
      field("tau_tilde", &S::tau_tilde, "tau / tau_max [-]"),
      field("sigma", &S::sigma, "eq. 14 ratio [-]"),
      field("rho", &S::rho, "contact radius [m]"),
      field("g", &S::g, "dry torque capacity about the CoR used by the update [N m]; times static_ratio in stick"),
      field("sigma_1", &S::sigma_1, "viscous coefficient about the CoR [N m s/rad]"),
      field("y", &S::y, "friction torque about the CoR [N m]"),
      field("inside", &S::inside, "wrench strictly inside the limit surface"),
      field("saturated", &S::saturated, "|c~| clipped at c_max"),
      field("iterations", &S::iterations, "root-finding iterations"),
      field("status", &S::status, "Status"),
      field("c_tilde_unclipped", &S::c_tilde_unclipped, "normalized CoR before the clip [-]"));
};

template <>
struct Table<SliderOutput> {
  using S = SliderOutput;
  static constexpr auto fields = std::make_tuple(
      field("z", &S::z, "bristle state [rad]"),
      field("omega", &S::omega, "angular velocity about the CoR [rad/s]"),
      field("zdot", &S::zdot, "bristle rate [rad/s]"),
      field("g", &S::g, "dry torque capacity [N m]"),
      field("sigma_1", &S::sigma_1, "viscous coefficient [N m s/rad]"),
      field("dry_torque", &S::dry_torque, "sigma0 z + sigma_z zdot [N m]"),
      field("friction_torque", &S::friction_torque, "total friction torque [N m]"),
      field("slip", &S::slip, "sigma0 |z| / g [-]"),
      field("substeps", &S::substeps, "internal steps used"),
      field("projected", &S::projected, "|z| clipped to g / sigma0"),
      field("status", &S::status, "Status"));
};

template <>
struct Table<ObserverOutput> {
  using S = ObserverOutput;
  static constexpr auto fields = std::make_tuple(
      field("omega_hat", &S::omega_hat, "estimated slip velocity about the clipped CoR [rad/s]; 0 where omega_resolution > 1.5 resolution_max"),
      field("z_hat", &S::z_hat, "estimated bristle state [rad]"),
      field("S", &S::S, "slippage indicator sigma0 |z_hat| / g [-] (eq. 37)"),
      field("c_tilde", &S::c_tilde, "normalized CoR [-]"),
      field("c", &S::c, "CoR position [m]"),
      field("g", &S::g, "dry torque capacity about the CoR used by the update [N m]; times static_ratio in stick"),
      field("sigma_1", &S::sigma_1, "viscous coefficient about the CoR [N m s/rad]"),
      field("y", &S::y, "measured friction torque about the CoR, tau - c f_t [N m]"),
      field("tau_cor", &S::tau_cor, "filtered torque used for the CoR [N m]"),
      field("ft_cor", &S::ft_cor, "tangential force used for the CoR [N]"),
      field("gain", &S::gain, "observer gain l used [1/(kg m^2)]"),
      field("omega_resolution", &S::omega_resolution, "speed resolution torque_noise / sigma_1 [rad/s]"),
      field("speed_observable", &S::speed_observable, "omega_resolution <= resolution_max"),
      field("inside", &S::inside, "CoR wrench strictly inside the limit surface"),
      field("saturated", &S::saturated, "|c~| clipped at c_max"),
      field("projected", &S::projected, "z_hat clipped to +-g/sigma0"),
      field("cor_side_flipped", &S::cor_side_flipped, "the CoR changed side: state mirrored"),
      field("diverged", &S::diverged, "re-initialised by the divergence guard"),
      field("substeps_capped", &S::substeps_capped, "adaptive substeps hit max_substeps"),
      field("substeps", &S::substeps, "integrator substeps on this sample"),
      field("cor_iterations", &S::cor_iterations, "root-finding iterations of the CoR"),
      field("status", &S::status, "Status"),
      field("c_tilde_unclipped", &S::c_tilde_unclipped, "normalized CoR before the clip [-]"),
      field("omega_object", &S::omega_object, "slip velocity about the unclipped CoR [rad/s]; 0 where omega_hat is"),
      field("v_slip", &S::v_slip, "slip speed of the patch centre [m/s]; 0 where omega_hat is"),
      field("omega_state", &S::omega_state, "the observer's slip-velocity state (omega_hat before the resolution gate) [rad/s]"),
      field("kinetic", &S::kinetic, "sliding has started: S judged against kinetic_ratio g (friction ratios not 1)"));
};

template <>
struct Table<GraspControllerOutput> {
  using S = GraspControllerOutput;
  static constexpr auto fields = std::make_tuple(
      field("force", &S::force, "commanded grasp force [N]"),
      field("static_force", &S::static_force, "static part f_ns at the last command [N]"),
      field("dynamic_force", &S::dynamic_force, "dynamic part f_nd at the last command [N]"),
      field("floor", &S::floor, "lower bound applied at the last command [N]"),
      field("slippage", &S::slippage, "combined S = max_i S_i at the last command [-]"),
      field("error", &S::error, "S - S_ref at the last command [-]"),
      field("integrator", &S::integrator, "PI integrator [N]"),
      field("gain_p", &S::gain_p, "k_p used at the last command [N]"),
      field("gain_i", &S::gain_i, "k_i used at the last command [N/s]"),
      field("feedforward_force", &S::feedforward_force, "feed-forward force at the last command [N]"),
      field("reserve_force", &S::reserve_force, "reserve of the last command: the stated or the learned, the larger, per finger [N]"),
      field("reserve_torque", &S::reserve_torque, "the same for the twist [N m]"),
      field("reflex", &S::reflex, "the slip reflex raised the last command"),
      field("peak_slippage", &S::peak_slippage, "peak of max_i S_i over the period before the last command [-]"),
      field("mu_belief", &S::mu_belief, "friction coefficient the controller believes now [-]"),
      field("ceiling", &S::ceiling, "ceiling of the last command (f_max when off) [N]"),
      field("probing", &S::probing, "a grip probe raised the last command"),
      field("probe_slip", &S::probe_slip, "a grip probe found the contact sliding at the last command (mu lowered)"),
      field("dynamic_sample", &S::dynamic_sample, "signed C_d omega_hat per finger at this sample [N]"),
      field("dynamic_peak", &S::dynamic_peak, "peak of max_i |C_d omega_hat_i| since the last command [N]"),
      field("mean_c_tilde", &S::mean_c_tilde, "mean |c~_i| of the valid fingers [-]"),
      field("pivot_time", &S::pivot_time, "time in the current pivoting manoeuvre [s]"),
      field("mode", &S::mode, "ControllerMode after this call"),
      field("pivot_end", &S::pivot_end, "PivotEnd, when pivoting ended in this call"),
      field("pivot_finished", &S::pivot_finished, "pivoting ended in this call"),
      field("command_issued", &S::command_issued, "a new command was computed in this call"),
      field("saturated", &S::saturated, "last command clipped at a limit"),
      field("rate_limited", &S::rate_limited, "last command rate limited"),
      field("held", &S::held, "last command held because of invalid input"),
      field("status", &S::status, "Ok or the worst finger status of this sample"));
};

template <>
struct Table<SlipControlOutput> {
  using S = SlipControlOutput;
  static constexpr auto fields = std::make_tuple(
      field("force", &S::force, "grasp-force command to send [N]"),
      field("status", &S::status, "Ok or the worst status of this cycle (command held otherwise)"),
      field("controller", &S::controller, "controller output (GraspControllerOutput)"));
};

// --- simulator ------------------------------------------------------------------------------

template <>
struct Table<ObjectConfig> {
  using S = ObjectConfig;
  static constexpr auto fields = std::make_tuple(
      field("mass", &S::mass, "[kg]"), field("inertia", &S::inertia, "about the CoG [kg m^2]"),
      field("cog_x", &S::cog_x, "CoG relative to the grasp point [m]"), field("cog_y", &S::cog_y, "[m]"),
      field("theta0", &S::theta0, "initial angle [rad]"));
};

template <>
struct Table<GripperMove> {
  using S = GripperMove;
  static constexpr auto fields = std::make_tuple(
      field("t_start", &S::t_start, "[s]"), field("duration", &S::duration, "[s]"),
      field("dx", &S::dx, "total displacement [m]"), field("dy", &S::dy, "[m]"));
};

template <>
struct Table<Disturbance> {
  using S = Disturbance;
  static constexpr auto fields = std::make_tuple(
      field("t_start", &S::t_start, "[s]"), field("duration", &S::duration, "[s]"),
      field("shape", &S::shape, "PulseShape"), field("force_x", &S::force_x, "peak force [N]"),
      field("force_y", &S::force_y, "[N]"), field("torque", &S::torque, "peak torque [N m]"),
      field("point_x", &S::point_x, "application point relative to the CoG [m]"),
      field("point_y", &S::point_y, "[m]"));
};

template <>
struct Table<ActuatorConfig> {
  using S = ActuatorConfig;
  static constexpr auto fields = std::make_tuple(
      field("f_init", &S::f_init, "force at t = 0 [N]"), field("f_max", &S::f_max, "saturation [N]"),
      field("time_constant", &S::time_constant, "first-order lag [s]"),
      field("rate_limit", &S::rate_limit, "|df/dt| limit [N/s]"),
      field("command_rate", &S::command_rate, "command ZOH rate [Hz]"));
};

template <>
struct Table<SensorConfig> {
  using S = SensorConfig;
  static constexpr auto fields = std::make_tuple(
      field("rate", &S::rate, "sampling rate [Hz]"), field("force_noise", &S::force_noise, "[N]"),
      field("torque_noise", &S::torque_noise, "[N m]"),
      field("force_resolution", &S::force_resolution, "quantisation step [N]"),
      field("torque_resolution", &S::torque_resolution, "quantisation step [N m]"),
      field("filter_time_constant", &S::filter_time_constant, "low-pass before sampling [s]"));
};

template <>
struct Table<PatchSettings> {
  using S = PatchSettings;
  static constexpr auto fields = std::make_tuple(
      field("rings", &S::rings, "rings of cells"),
      field("bristle_stiffness", &S::bristle_stiffness, "[1/m]"),
      field("bristle_damping", &S::bristle_damping, "[s/m]"),
      field("static_ratio", &S::static_ratio, "static / Coulomb friction [-]"),
      field("stribeck_velocity", &S::stribeck_velocity, "[m/s]"));
};

template <>
struct Table<DropConfig> {
  using S = DropConfig;
  static constexpr auto fields = std::make_tuple(
      field("slip_limit", &S::slip_limit, "[m]"), field("rotation_limit", &S::rotation_limit, "[rad]"),
      field("contact_force_min", &S::contact_force_min, "[N]"));
};

template <>
struct Table<PlantConfig> {
  using S = PlantConfig;
  static constexpr auto fields = std::make_tuple(
      field("contact", &S::contact, "ContactParams of both fingertips"), field("model", &S::model, "PlantModel"),
      field("object", &S::object, "ObjectConfig"), field("actuator", &S::actuator, "ActuatorConfig"),
      field("sensor", &S::sensor, "SensorConfig"), field("patch", &S::patch, "PatchSettings"),
      field("drop", &S::drop, "DropConfig"), field("gravity", &S::gravity, "[m/s^2]"),
      field("rate", &S::rate, "plant step rate [Hz]"), field("substeps", &S::substeps, "per plant step"),
      field("support", &S::support, "a support under the object"), field("seed", &S::seed, "noise seed"));
};

template <>
struct Table<FingerSample> {
  using S = FingerSample;
  static constexpr auto fields = std::make_tuple(
      field("index", &S::index, "sample number"), field("t", &S::t, "[s]"), field("f_n", &S::f_n, "[N]"),
      field("f_x", &S::f_x, "[N]"), field("f_y", &S::f_y, "[N]"), field("tau", &S::tau, "[N m]"),
      field("true_f_n", &S::true_f_n, "[N]"), field("true_f_x", &S::true_f_x, "[N]"),
      field("true_f_y", &S::true_f_y, "[N]"), field("true_tau", &S::true_tau, "[N m]"),
      field("slip_x", &S::slip_x, "[m]"), field("slip_y", &S::slip_y, "[m]"),
      field("slip_angle", &S::slip_angle, "[rad]"), field("slip_vx", &S::slip_vx, "[m/s]"),
      field("slip_vy", &S::slip_vy, "[m/s]"), field("omega", &S::omega, "[rad/s]"),
      field("c_tilde", &S::c_tilde, "[-]"), field("rho", &S::rho, "[m]"));
};

template <>
struct Table<PlantState> {
  using S = PlantState;
  static constexpr auto fields = std::make_tuple(
      field("t", &S::t, "[s]"), field("f_cmd", &S::f_cmd, "[N]"), field("f_held", &S::f_held, "[N]"),
      field("f_n", &S::f_n, "[N]"), field("gripper_x", &S::gripper_x, "[m]"),
      field("gripper_y", &S::gripper_y, "[m]"), field("gripper_vx", &S::gripper_vx, "[m/s]"),
      field("gripper_vy", &S::gripper_vy, "[m/s]"), field("x", &S::x, "[m]"), field("y", &S::y, "[m]"),
      field("vx", &S::vx, "[m/s]"), field("vy", &S::vy, "[m/s]"), field("theta", &S::theta, "[rad]"),
      field("omega", &S::omega, "[rad/s]"), field("slip_x", &S::slip_x, "[m]"),
      field("slip_y", &S::slip_y, "[m]"), field("slip_angle", &S::slip_angle, "[rad]"),
      field("max_slip", &S::max_slip, "[m]"), field("max_rotation", &S::max_rotation, "[rad]"),
      field("contact_fx", &S::contact_fx, "[N]"), field("contact_fy", &S::contact_fy, "[N]"),
      field("contact_tau", &S::contact_tau, "[N m]"), field("ext_fx", &S::ext_fx, "[N]"),
      field("ext_fy", &S::ext_fy, "[N]"), field("ext_tau", &S::ext_tau, "[N m]"),
      field("supported", &S::supported, ""), field("dropped", &S::dropped, ""),
      field("drop_time", &S::drop_time, "[s]"), field("drop_reason", &S::drop_reason, "bit mask"),
      field("steps", &S::steps, "plant steps since reset"));
};

template <>
struct Table<ModeEvent> {
  using S = ModeEvent;
  static constexpr auto fields =
      std::make_tuple(field("time", &S::time, "[s]"), field("action", &S::action, "ModeAction"));
};

template <>
struct Table<FaultSpec> {
  using S = FaultSpec;
  static constexpr auto fields = std::make_tuple(
      field("kind", &S::kind, "FaultKind"), field("finger", &S::finger, "0, 1 or -1 (both)"),
      field("t_start", &S::t_start, "[s]"), field("duration", &S::duration, "[s]"),
      field("burst", &S::burst, "[samples]"), field("every", &S::every, "[samples] (0: continuous)"),
      field("force", &S::force, "[N]"), field("torque", &S::torque, "[N m]"),
      field("force_rate", &S::force_rate, "[N/s]"), field("torque_rate", &S::torque_rate, "[N m/s]"),
      field("time_constant", &S::time_constant, "[s]"));
};

template <>
struct Table<ClosedLoopConfig> {
  using S = ClosedLoopConfig;
  static constexpr auto fields = std::make_tuple(
      field("plant", &S::plant, "PlantConfig"), field("observer", &S::observer, "ObserverSettings"),
      field("estimator", &S::estimator, "ContactParams of the estimator side (None: the plant's)"),
      field("controller", &S::controller, "GraspControllerSettings"),
      field("kind", &S::kind, "ControllerKind"),
      field("controller_start", &S::controller_start, "[s]"),
      field("constant_force", &S::constant_force, "[N]"), field("cone_margin", &S::cone_margin, "[-]"),
      field("cone_release_rate", &S::cone_release_rate, "[N/s]"),
      field("stuck_samples", &S::stuck_samples, "exact wrench repeats reported SensorFault [samples] (0: off)"),
      field("healthy_finger_fallback", &S::healthy_finger_fallback, "SlipControlSettings::healthy_finger_fallback"));
};

template <>
struct Table<ClosedLoopSample> {
  using S = ClosedLoopSample;
  static constexpr auto fields = std::make_tuple(
      field("index", &S::index, "sample number"), field("t", &S::t, "[s]"),
      field("command", &S::command, "grasp-force command sent to the gripper [N]"),
      field("static_force", &S::static_force, "f_ns of the last command [N]"),
      field("dynamic_force", &S::dynamic_force, "f_nd of the last command [N]"),
      field("f_n", &S::f_n, "true normal force of each finger [N]"),
      field("f_n_meas", &S::f_n_meas, "measured normal force per finger [N]"),
      field("f_t_meas", &S::f_t_meas, "measured tangential force per finger [N]"),
      field("tau_meas", &S::tau_meas, "measured torque per finger [N m]"),
      field("f_t_true", &S::f_t_true, "true tangential load per finger [N]"),
      field("tau_true", &S::tau_true, "true torque per finger [N m]"),
      field("omega_hat", &S::omega_hat, "estimated slip velocity per finger [rad/s]"),
      field("S", &S::slippage, "slippage indicator per finger [-]"),
      field("c_tilde", &S::c_tilde, "estimated CoR per finger [-]"),
      field("omega_true", &S::omega_true, "true slip velocity per finger [rad/s]"),
      field("c_tilde_true", &S::c_tilde_true, "true CoR per finger [-]"),
      field("observer_status", &S::observer_status, "Status code per finger"),
      field("slip_x", &S::slip_x, "[m]"), field("slip_y", &S::slip_y, "[m]"),
      field("slip", &S::slip, "slip distance (lumped: path length) [m]"),
      field("rotation", &S::rotation, "theta - theta0 [rad]"), field("theta", &S::theta, "[rad]"),
      field("cog_x", &S::cog_x, "CoG relative to the grasp point [m]"), field("cog_y", &S::cog_y, "[m]"),
      field("gripper_y", &S::gripper_y, "grasp-point height [m]"), field("ext_fx", &S::ext_fx, "[N]"),
      field("ext_fy", &S::ext_fy, "[N]"), field("ext_tau", &S::ext_tau, "[N m]"),
      field("mode", &S::mode, "ControllerMode code"),
      field("command_issued", &S::command_issued, "a command was computed at this sample"),
      field("pivot_finished", &S::pivot_finished, "pivoting ended at this sample"),
      field("pivot_end", &S::pivot_end, "PivotEnd code"),
      field("supported", &S::supported, "object resting on the support"),
      field("dropped", &S::dropped, "a drop criterion has been met (latched)"),
      field("finite", &S::finite, "every value of this sample is finite"),
      field("status", &S::status, "Status code of the cycle"),
      field("fault_active", &S::fault_active, "an injected fault acted on this sample"),
      field("actuator_command", &S::actuator_command, "command reaching the gripper after actuator faults [N]"),
      field("mu_belief", &S::mu_belief, "friction coefficient the controller believes [-]"));
};

}  // namespace lugrip_bind
