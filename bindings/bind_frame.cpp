// lugrip::contact_wrench: a fingertip sensor's wrench in the contact frame (one sample, or a
// batch with the GIL released).
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/array.h>

#include <array>
#include <stdexcept>

#include "lugrip/sensor_frame.hpp"

namespace nb = nanobind;

namespace lugrip_bind {

using Rows3 = nb::ndarray<const double, nb::ndim<2>, nb::shape<-1, 3>, nb::c_contig, nb::device::cpu>;
using Rows4 = nb::ndarray<nb::numpy, double, nb::ndim<2>>;

void bind_frame(nb::module_& m) {
  m.def(
      "contact_wrench",
      [](const std::array<double, 3>& force, const std::array<double, 3>& moment, bool flip_normal,
         double contact_offset, double floor) {
        return lugrip::contact_wrench(force, moment, lugrip::SensorFrame{flip_normal, contact_offset}, floor);
      },
      nb::arg("force"), nb::arg("moment"), nb::arg("flip_normal"), nb::arg("contact_offset"), nb::arg("floor"),
      "(f_n, f_x, f_y, tau) of one sensor wrench (lugrip::contact_wrench; contact_offset < 0: none)");
  m.def(
      "contact_wrenches",
      [](const Rows3& force, const Rows3& moment, bool flip_normal, double contact_offset, double floor) {
        const size_t n = force.shape(0);
        if (moment.shape(0) != n) throw std::invalid_argument("force and moment: different numbers of rows");
        double* out = new double[n > 0 ? 4 * n : 1];
        nb::capsule owner(out, [](void* p) noexcept { delete[] static_cast<double*>(p); });
        const double *f = force.data(), *mo = moment.data();
        const lugrip::SensorFrame frame{flip_normal, contact_offset};
        {
          nb::gil_scoped_release release;
          for (size_t i = 0; i < n; ++i) {
            const auto row = lugrip::contact_wrench({f[3 * i], f[3 * i + 1], f[3 * i + 2]},
                                                    {mo[3 * i], mo[3 * i + 1], mo[3 * i + 2]}, frame, floor);
            for (size_t j = 0; j < 4; ++j) out[4 * i + j] = row[j];
          }
        }
        return Rows4(out, {n, 4}, owner);
      },
      nb::arg("force"), nb::arg("moment"), nb::arg("flip_normal"), nb::arg("contact_offset"), nb::arg("floor"),
      "(n, 4) rows (f_n, f_x, f_y, tau) of n sensor wrenches, (n, 3) force and moment");
}

}  // namespace lugrip_bind
