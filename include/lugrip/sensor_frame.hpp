// A fingertip sensor's wrench in lugrip's contact frame: the transform the log readers
// (lugrip.io.read_log) and the ROS node (lugrip.ros) apply to every sample, in the real-time
// core so that a C++ robot loop applies the same one. No allocation, no exceptions.
#pragma once

#include <array>

namespace lugrip {

//! How a fingertip's force/torque sensor is mounted.
struct SensorFrame {
  //! The sensor's z axis points toward the object (its force z is negative while pressed):
  //! the frame is rotated by pi about x (y and z of force and moment change sign).
  bool flip_normal = false;
  //! [m] The sensor origin lies this far behind the pad surface along the normal; the
  //! torsional moment is moved to the centre of pressure. Negative (default): the wrench is
  //! measured at the contact already and taken as it is.
  double contact_offset = -1.0;
};

//! (f_n, f_x, f_y, tau): one row of SlipControl's input.
using ContactWrench = std::array<double, 4>;

//! The wrench (force [N], moment [N m], in the sensor's frame) in the contact frame. With a
//! contact offset d >= 0 the centre of pressure on the surface z = -d is
//!   x = -(m_y + d f_x) / f_z,  y = (m_x - d f_y) / f_z
//! and tau = m_z - x f_y + y f_x, located only where f_z > floor [N] (elsewhere, or for a
//! non-finite f_z, tau = m_z: no contact to locate). Non-finite inputs give non-finite
//! outputs (the observer reports them InvalidSample).
ContactWrench contact_wrench(const std::array<double, 3>& force, const std::array<double, 3>& moment,
                             const SensorFrame& frame, double floor) noexcept;

}  // namespace lugrip
