// Closed-loop simulation: configuration and a batch run() that loops in C++ (GIL released) and
// hands the columns over to numpy without copying.
#include <nanobind/nanobind.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>

#include <stdexcept>
#include <string>

#include "common.hpp"
#include "tables.hpp"

namespace lugrip_bind {

using namespace nb::literals;

void bind_closed_loop(nb::module_& m) {
  nb::enum_<ControllerKind>(m, "ControllerKind", "Law computing the grasp-force command.")
      .value("Lugrip", ControllerKind::Lugrip)
      .value("ConstantForce", ControllerKind::ConstantForce)
      .value("FrictionCone", ControllerKind::FrictionCone);
  nb::enum_<ModeAction>(m, "ModeAction", "Scheduled controller action.")
      .value("Pivot", ModeAction::Pivot)
      .value("SlippingAvoidance", ModeAction::SlippingAvoidance)
      .value("DynamicOn", ModeAction::DynamicOn)
      .value("DynamicOff", ModeAction::DynamicOff);
  nb::class_<ModeEvent> event(m, "ModeEvent");
  event.def(nb::init<>());
  def_fields_rw(event);
  nb::class_<ClosedLoopConfig> config(m, "ClosedLoopConfig");
  config.def(nb::init<>())
      .def("clear_schedule", [](ClosedLoopConfig& c) { c.schedule.clear(); })
      .def("add_event", [](ClosedLoopConfig& c, double t, ModeAction a) { c.schedule.push_back(ModeEvent{t, a}); },
           "time"_a, "action"_a)
      .def_prop_ro("n_events", [](const ClosedLoopConfig& c) { return c.schedule.size(); });
  def_fields_rw(config);
  m.def("validate_closed_loop_config", &validation_message<ClosedLoopConfig>, "Empty string when valid, else one line per problem.");

  using Loop = Guarded<ClosedLoop>;
  {
    nb::class_<Loop>(m, "ClosedLoop")
        .def(nb::init<const ClosedLoopConfig&>(), "config"_a)
        .def("reset", [](Loop& c) {
          c.guard.check("ClosedLoop");
          c.reset();
        })
        .def_prop_ro("time", [](const Loop& c) { return c.time(); })
        .def_prop_ro("samples", [](const Loop& c) { return c.samples(); })
        .def_prop_ro("sample_period", [](const Loop& c) { return c.sample_period(); })
        .def_prop_ro("plant_state", [](const Loop& c) { return c.plant().state(); })
        .def_prop_ro("mode", [](const Loop& c) { return static_cast<int>(c.controller().mode()); })
        .def("run", [](Loop& c, int64_t samples) {
          c.guard.check("ClosedLoop");
          if (samples < 0) throw std::invalid_argument("samples must be >= 0");
          auto* log = new ClosedLoopLog();
          try {
            nb::gil_scoped_release release;
            c.run(samples, *log);
          } catch (...) {
            delete log;
            throw;
          }
          // One capsule owns the log; every column is a view into it.
          nb::capsule owner(log, [](void* p) noexcept { delete static_cast<ClosedLoopLog*>(p); });
          nb::dict d;
          auto put = [&](const char* name, auto& v) {
            using T = typename std::decay_t<decltype(v)>::value_type;
            d[name] = nb::ndarray<nb::numpy, T, nb::ndim<1>>(v.data(), {v.size()}, owner);
          };
          put("t", log->t);
          put("command", log->command);
          put("static_force", log->static_force);
          put("dynamic_force", log->dynamic_force);
          put("f_n", log->f_n);
          const char* suffix[] = {"_0", "_1"};
          for (int i = 0; i < 2; ++i) {
            const std::string s = suffix[i];
            put(("f_n_meas" + s).c_str(), log->f_n_meas[i]);
            put(("f_t_meas" + s).c_str(), log->f_t_meas[i]);
            put(("tau_meas" + s).c_str(), log->tau_meas[i]);
            put(("f_t_true" + s).c_str(), log->f_t_true[i]);
            put(("tau_true" + s).c_str(), log->tau_true[i]);
            put(("omega_hat" + s).c_str(), log->omega_hat[i]);
            put(("S" + s).c_str(), log->slippage[i]);
            put(("c_tilde" + s).c_str(), log->c_tilde[i]);
            put(("omega_true" + s).c_str(), log->omega_true[i]);
            put(("c_tilde_true" + s).c_str(), log->c_tilde_true[i]);
            put(("observer_status" + s).c_str(), log->observer_status[i]);
          }
          put("slip_x", log->slip_x);
          put("slip_y", log->slip_y);
          put("slip", log->slip);
          put("rotation", log->rotation);
          put("theta", log->theta);
          put("cog_x", log->cog_x);
          put("cog_y", log->cog_y);
          put("gripper_y", log->gripper_y);
          put("ext_fx", log->ext_fx);
          put("ext_fy", log->ext_fy);
          put("ext_tau", log->ext_tau);
          put("mode", log->mode);
          put("pivot_end", log->pivot_end);
          put("command_issued", log->command_issued);
          put("pivot_finished", log->pivot_finished);
          put("supported", log->supported);
          put("dropped", log->dropped);
          put("finite", log->finite);
          return d;
        }, "samples"_a,
           "Runs `samples` closed-loop samples in C++ from the current state; returns a dict of "
           "arrays (per-finger columns suffixed _0/_1; flags as uint8).");
  }
}

}  // namespace lugrip_bind
