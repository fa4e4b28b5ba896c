// lugrip._core: the nanobind module. One file per concept (bind_*.cpp); the fields of every
// bound struct are described once in tables.hpp.
#include <nanobind/nanobind.h>

#include "lugrip/version.hpp"

namespace nb = nanobind;

namespace lugrip_bind {
void bind_contact(nb::module_& m);
void bind_observer(nb::module_& m);
void bind_controller(nb::module_& m);
void bind_slip_control(nb::module_& m);
void bind_plant(nb::module_& m);
void bind_closed_loop(nb::module_& m);
void bind_identification(nb::module_& m);
void bind_frame(nb::module_& m);
}  // namespace lugrip_bind

NB_MODULE(_core, m) {
  m.doc() = "lugrip real-time core (C++17): contact model, CoR, observer, controller, SlipControl; simulator; identification";
  m.attr("__version__") = LUGRIP_VERSION;
  // Order matters: types used as default arguments are registered first.
  lugrip_bind::bind_contact(m);
  lugrip_bind::bind_observer(m);
  lugrip_bind::bind_controller(m);
  lugrip_bind::bind_slip_control(m);
  lugrip_bind::bind_plant(m);
  lugrip_bind::bind_closed_loop(m);
  lugrip_bind::bind_identification(m);
  lugrip_bind::bind_frame(m);
}
