// lugrip — the fields of GraspControllerSettings, described once (name, member, doc with unit):
// the Python bindings, the parameter-file loader's controller block and the tests read them.
#pragma once

#include "lugrip/detail/field_table.hpp"
#include "lugrip/grasp_controller.hpp"

namespace lugrip {

//! Every field of GraspControllerSettings, in the struct's order.
inline constexpr auto grasp_controller_fields = [] {
  using S = GraspControllerSettings;
  using detail::field;
  return std::make_tuple(
      field("sensor_rate", &S::sensor_rate, "rate of step() calls [Hz]"),
      field("command_ratio", &S::command_ratio, "step() calls per force command"),
      field("f_min", &S::f_min, "minimum force [N]"),
      field("f_max", &S::f_max, "maximum force [N]"),
      field("max_rate", &S::max_rate, "the gripper's slew rate: limit on command changes (inf: off) [N/s]"),
      field("reaction_lag", &S::reaction_lag, "the gripper's force time constant the reactions overshoot for (0: off) [s]"),
      field("s_ref", &S::s_ref, "utilisation the PI holds in stick: lower is more margin against a wrong mu, more force [-]"),
      field("k_p", &S::k_p, "proportional gain (at gain_force on a translational load) [N]"),
      field("k_i", &S::k_i, "integral gain (at gain_force on a translational load) [N/s]"),
      field("gain_force", &S::gain_force, "PI gains scale with command / gain_force and the load's slope (0: constant, paper) [N]"),
      field("k_cd", &S::k_cd, "C_d high-frequency gain [N s/rad]"),
      field("p_cd", &S::p_cd, "C_d pole [rad/s]"),
      field("z_cd", &S::z_cd, "C_d zero [rad/s]"),
      field("load_floors", &S::load_floors, "static part floored by the measured load (feed-forward, pushes learned, slip reflex)"),
      field("reserve_force", &S::reserve_force, "the task's push envelope per finger (0: off) [N]"),
      field("reserve_torque", &S::reserve_torque, "the task's twist envelope per finger (0: off) [N m]"),
      field("ceiling_factor", &S::ceiling_factor, "raises <= this x the grip the measured load needs at S = 1 (0: off) [-]"),
      field("mu_probe", &S::mu_probe, "relative size of the grip probe that learns mu (0: off) [-]"),
      field("s_pivot", &S::s_pivot, "pivoting slippage reference (> 1) [-]"),
      field("tau_pivot", &S::tau_pivot, "pivoting filter time constant [s]"));
}();

}  // namespace lugrip
