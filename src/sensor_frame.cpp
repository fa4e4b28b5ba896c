#include "lugrip/sensor_frame.hpp"

#include <cmath>

namespace lugrip {

ContactWrench contact_wrench(const std::array<double, 3>& force, const std::array<double, 3>& moment,
                             const SensorFrame& frame, double floor) noexcept {
  const double s = frame.flip_normal ? -1.0 : 1.0;  // rotation by pi about x
  const double fx = force[0], fy = s * force[1], fz = s * force[2];
  const double mx = moment[0], my = s * moment[1], mz = s * moment[2];
  double tau = mz;
  const double d = frame.contact_offset;
  if (d >= 0.0 && std::isfinite(fz) && fz > floor) {
    const double x = -(my + d * fx) / fz;
    const double y = (mx - d * fy) / fz;
    tau = mz - x * fy + y * fx;
  }
  return {fz, fx, fy, tau};
}

}  // namespace lugrip
