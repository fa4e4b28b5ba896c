// Closed-loop simulation: configuration and a batch run() that loops in C++ (GIL released) and
// hands the columns over to numpy without copying.
#include <nanobind/nanobind.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/tuple.h>
#include <nanobind/stl/vector.h>

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
  nb::enum_<FaultKind>(m, "FaultKind", "Injected sensor or actuator fault.")
      .value("Dropout", FaultKind::Dropout)
      .value("NanBurst", FaultKind::NanBurst)
      .value("Spike", FaultKind::Spike)
      .value("BiasDrift", FaultKind::BiasDrift)
      .value("Saturation", FaultKind::Saturation)
      .value("Stuck", FaultKind::Stuck)
      .value("Dead", FaultKind::Dead)
      .value("ContactLoss", FaultKind::ContactLoss)
      .value("ActuatorLag", FaultKind::ActuatorLag)
      .value("ActuatorSaturation", FaultKind::ActuatorSaturation);
  nb::class_<FaultSpec> fault(m, "FaultSpec");
  fault.def(nb::init<>());
  def_fields_rw(fault);
  nb::class_<FaultInjector>(m, "FaultInjector",
                             "Applies a fault list to each sensor sample's wrenches and to the gripper command.")
      .def(nb::init<const std::vector<FaultSpec>&, double>(), "faults"_a, "sample_period"_a)
      .def("reset", &FaultInjector::reset, "command"_a = 0.0)
      .def(
          "sensors",
          [](FaultInjector& f, int64_t n, const std::vector<double>& w) {
            if (w.size() != 8) throw nb::value_error("wrenches: expected 8 values (f_n, f_x, f_y, tau of finger 0, then 1)");
            std::array<FingerWrench, kMaxFingers> fw{};
            for (int i = 0; i < 2; ++i) fw[i] = FingerWrench{w[4 * i], w[4 * i + 1], w[4 * i + 2], w[4 * i + 3]};
            const bool active = f.sensors(n, fw);
            std::vector<double> out(8);
            for (int i = 0; i < 2; ++i) {
              out[4 * i] = fw[i].f_n;
              out[4 * i + 1] = fw[i].f_x;
              out[4 * i + 2] = fw[i].f_y;
              out[4 * i + 3] = fw[i].tau;
            }
            return std::make_tuple(active, out);
          },
          "n"_a, "wrenches"_a,
          "Sample n's wrenches (8 values: f_n, f_x, f_y, tau per finger) -> (fault acted, wrenches received).")
      .def(
          "actuator",
          [](FaultInjector& f, int64_t n, double command) {
            bool active = false;
            const double out = f.actuator(n, command, active);
            return std::make_tuple(out, active);
          },
          "n"_a, "command"_a, "Sample n's command [N] -> (command reaching the gripper [N], fault acted).")
      .def_prop_ro("empty", &FaultInjector::empty);
  nb::class_<ModeEvent> event(m, "ModeEvent");
  event.def(nb::init<>());
  def_fields_rw(event);
  nb::class_<ClosedLoopConfig> config(m, "ClosedLoopConfig");
  config.def(nb::init<>())
      .def("clear_schedule", [](ClosedLoopConfig& c) { c.schedule.clear(); })
      .def("add_event", [](ClosedLoopConfig& c, double t, ModeAction a) { c.schedule.push_back(ModeEvent{t, a}); },
           "time"_a, "action"_a)
      .def("add_fault", [](ClosedLoopConfig& c, const FaultSpec& f) { c.faults.push_back(f); }, "fault"_a)
      .def("clear_faults", [](ClosedLoopConfig& c) { c.faults.clear(); })
      .def_prop_ro("n_faults", [](const ClosedLoopConfig& c) { return c.faults.size(); })
      .def_prop_ro("n_events", [](const ClosedLoopConfig& c) { return c.schedule.size(); });
  def_fields_rw(config);
  nb::class_<ClosedLoopSample> sample(m, "ClosedLoopSample");
  sample.def(nb::init<>());
  def_fields_ro(sample);
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
          const size_t n = static_cast<size_t>(samples);
          Columns<ClosedLoopSample, uint8_t> cols(n);
          {
            nb::gil_scoped_release release;
            ClosedLoopSample s;
            for (size_t k = 0; k < n; ++k) {
              c.step(s);
              cols.set(k, s);
            }
          }
          nb::dict d;
          cols.into(d);
          return d;
        }, "samples"_a,
           "Runs `samples` closed-loop samples in C++ from the current state; returns a dict of "
           "arrays (ClosedLoopSample.fields; per-finger columns suffixed _0/_1; flags as uint8).");
  }
}

}  // namespace lugrip_bind
