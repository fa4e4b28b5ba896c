// SlipControl: fingertip wrenches in, grasp-force command out.
#include <nanobind/nanobind.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/tuple.h>

#include <cmath>

#include "common.hpp"
#include "tables.hpp"

namespace lugrip_bind {

using namespace nb::literals;

namespace {

using Wrenches = nb::ndarray<const double, nb::c_contig, nb::device::cpu>;
using Batch = nb::ndarray<const double, nb::ndim<3>, nb::c_contig, nb::device::cpu>;
using Times = nb::ndarray<const double, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using Requests = nb::ndarray<const int32_t, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using SC = Guarded<SlipControl>;

//! Columns of SlipControl.run_log, in order.
constexpr size_t kLogColumns = 17;
const char* const kLogNames[kLogColumns] = {
    "force", "status", "static_force", "dynamic_force", "mu_belief", "mode", "command_issued",
    "pivot_finished", "pivot_end", "omega_hat_0", "omega_hat_1", "S_0", "S_1", "c_tilde_0",
    "c_tilde_1", "status_0", "status_1"};

// Copies k x 4 wrench values (k = the object's finger count, or 2) into the input.
void load(const SC& sc, const double* w, size_t size, SlipControlInput& in) {
  const size_t k = static_cast<size_t>(sc.fingers());
  if (size != 4 * k && size != 4 * kMaxFingers)
    throw std::invalid_argument("wrenches: expected " + std::to_string(4 * k) +
                                " values (fingers x (f_n, f_x, f_y, tau)), got " + std::to_string(size));
  for (size_t i = 0; i < k; ++i) in.fingers[i] = FingerWrench{w[4 * i], w[4 * i + 1], w[4 * i + 2], w[4 * i + 3]};
}

// Batch row i of (N, k, 4) wrenches into the input, after its request (1 pivoting, 2
// slipping avoidance; pr may be null).
void load_row(SC& sc, const double* pw, size_t k, size_t i, const int32_t* pr, SlipControlInput& in) {
  if (pr && pr[i] == 1) sc.request_pivoting();
  else if (pr && pr[i] == 2) sc.request_slipping_avoidance();
  for (size_t j = 0; j < static_cast<size_t>(sc.fingers()); ++j) {
    const double* x = pw + 4 * (k * i + j);
    in.fingers[j] = FingerWrench{x[0], x[1], x[2], x[3]};
  }
}

}  // namespace

void bind_slip_control(nb::module_& m) {
  nb::class_<SlipControlSettings> settings(m, "SlipControlSettings");
  settings.def(nb::init<>());
  def_fields_rw(settings);
  m.def("validate_slip_control_settings", &validation_message<SlipControlSettings>,
        "Empty string when valid, else one line per problem.");

  {
    nb::list names;
    for (const char* name : kLogNames) names.append(name);
    m.attr("SLIP_CONTROL_LOG_COLUMNS") = nb::tuple(names);
  }
  nb::class_<SlipControlOutput> out(m, "SlipControlOutput");
  out.def(nb::init<>());
  def_fields_ro(out);
  out.def_prop_ro("fingers", [](const SlipControlOutput& o) { return nb::make_tuple(o.fingers[0], o.fingers[1]); },
                  "each finger's ObserverOutput (finger 1 unused with one finger)");
  out.def_prop_ro("pivot_finished", [](const SlipControlOutput& o) { return o.controller.pivot_finished; },
                  "pivoting ended in this cycle (controller.pivot_end says why)");
  out.def_prop_ro("mode", [](const SlipControlOutput& o) { return o.controller.mode; },
                  "ControllerMode after this cycle");

  nb::class_<SC>(m, "SlipControl")
      .def(nb::init<const ContactParams&, const SlipControlSettings&>(), "params"_a,
           "settings"_a = SlipControlSettings())
      .def(nb::init<const ContactModel&, const SlipControlSettings&>(), "model"_a,
           "settings"_a = SlipControlSettings())
      .def("step", [](SC& sc, const Wrenches& w, double dt, int command) {
        sc.guard.check("SlipControl");
        SlipControlInput in;
        load(sc, w.data(), w.size(), in);
        in.dt = dt;
        in.command = static_cast<CommandTiming>(command);
        SlipControlOutput o;
        sc.step(in, o);
        return o;
      }, "wrenches"_a, "dt"_a = 0.0, "command"_a = 0,
         "One cycle: wrenches = fingers x (f_n, f_x, f_y, tau) float64 values (C order); dt [s] since "
         "the previous cycle (0: nominal); command: 0 the clock, 1 a command now, 2 none (CommandTiming).")
      .def("run", [](SC& sc, const Batch& w, const Times& dt, const Requests& req, const Requests& cmd) {
        sc.guard.check("SlipControl");
        const size_t n = w.shape(0), k = w.shape(1);
        if (w.shape(2) != 4 || (k != static_cast<size_t>(sc.fingers()) && k != kMaxFingers))
          throw std::invalid_argument("wrenches: expected shape (N, " + std::to_string(sc.fingers()) + ", 4)");
        if (dt.shape(0) != n && dt.shape(0) != 0) throw std::invalid_argument("dt: expected N values or none");
        if (req.shape(0) != n && req.shape(0) != 0) throw std::invalid_argument("requests: expected N values or none");
        if (cmd.shape(0) != n && cmd.shape(0) != 0) throw std::invalid_argument("commands: expected N values or none");
        Columns<GraspControllerOutput> ctrl(n);
        Columns<ObserverOutput> f0(n, "_0"), f1(n, "_1");
        const double* pw = w.data();
        const double* pd = dt.shape(0) ? dt.data() : nullptr;
        const int32_t* pr = req.shape(0) ? req.data() : nullptr;
        const int32_t* pc = cmd.shape(0) ? cmd.data() : nullptr;
        const bool two = sc.fingers() == 2;
        {
          nb::gil_scoped_release release;
          SlipControlInput in;
          SlipControlOutput o;
          for (size_t i = 0; i < n; ++i) {
            load_row(sc, pw, k, i, pr, in);
            in.dt = pd ? pd[i] : 0.0;
            in.command = pc ? static_cast<CommandTiming>(pc[i]) : CommandTiming::Clock;
            sc.step(in, o);
            ctrl.set(i, o.controller);
            f0.set(i, o.fingers[0]);
            if (two) f1.set(i, o.fingers[1]);
          }
        }
        nb::dict d;
        ctrl.into(d);
        f0.into(d);
        if (two) f1.into(d);
        return d;
      }, "wrenches"_a, "dt"_a, "requests"_a, "commands"_a,
         "Runs step() over (N, fingers, 4) wrenches in one C++ loop (dt: (N,) or empty; requests: (N,) "
         "0 none, 1 pivoting, 2 slipping avoidance, or empty; commands: (N,) CommandTiming codes or "
         "empty for the clock). Returns a dict of (N,) arrays: the "
         "GraspControllerOutput fields and each finger's ObserverOutput fields suffixed _0 / _1.")
      .def("run_log", [](SC& sc, const Batch& w, const Requests& req,
                         nb::ndarray<double, nb::ndim<2>, nb::c_contig, nb::device::cpu> out) {
        sc.guard.check("SlipControl");
        const size_t n = w.shape(0), k = w.shape(1);
        if (w.shape(2) != 4 || (k != static_cast<size_t>(sc.fingers()) && k != kMaxFingers))
          throw std::invalid_argument("wrenches: expected shape (N, " + std::to_string(sc.fingers()) + ", 4)");
        if (req.shape(0) != n && req.shape(0) != 0) throw std::invalid_argument("requests: expected N values or none");
        if (out.shape(0) != n || out.shape(1) != kLogColumns)
          throw std::invalid_argument("out: expected shape (N, " + std::to_string(kLogColumns) + ")");
        const double* pw = w.data();
        const int32_t* pr = req.shape(0) ? req.data() : nullptr;
        double* po = out.data();
        nb::gil_scoped_release release;
        SlipControlInput in;
        SlipControlOutput o;
        for (size_t i = 0; i < n; ++i) {
          load_row(sc, pw, k, i, pr, in);
          sc.step(in, o);
          const GraspControllerOutput& c = o.controller;
          double* r = po + i * kLogColumns;
          r[0] = o.force;
          r[1] = static_cast<double>(static_cast<int>(o.status));
          r[2] = c.static_force;
          r[3] = c.dynamic_force;
          r[4] = c.mu_belief;
          r[5] = static_cast<double>(static_cast<int>(c.mode));
          r[6] = c.command_issued ? 1.0 : 0.0;
          r[7] = c.pivot_finished ? 1.0 : 0.0;
          r[8] = static_cast<double>(static_cast<int>(c.pivot_end));
          for (size_t j = 0; j < 2; ++j) {
            const ObserverOutput& f = o.fingers[j];
            r[9 + j] = f.omega_hat;
            r[11 + j] = f.S;
            r[13 + j] = f.c_tilde;
            r[15 + j] = static_cast<double>(static_cast<int>(f.status));
          }
        }
      }, "wrenches"_a, "requests"_a, "out"_a,
         "step() over (N, fingers, 4) wrenches with the clock's commands (requests: (N,) 0 none, 1 "
         "pivoting, 2 slipping avoidance, or empty), writing the closed-loop log's columns of each "
         "cycle into out (N, 17) float64, named by lugrip._core.SLIP_CONTROL_LOG_COLUMNS "
         "(codes as numbers). A batch without one array per output field.")
      .def("reset", [](SC& sc, double force) {
        sc.guard.check("SlipControl");
        sc.reset(force);
      }, "force"_a)
      .def("request_pivoting", [](SC& sc) {
        sc.guard.check("SlipControl");
        sc.request_pivoting();
      })
      .def("request_slipping_avoidance", [](SC& sc) {
        sc.guard.check("SlipControl");
        sc.request_slipping_avoidance();
      })
      .def("set_dynamic_enabled", [](SC& sc, bool on) {
        sc.guard.check("SlipControl");
        sc.set_dynamic_enabled(on);
      }, "enabled"_a)
      .def("set_mu", [](SC& sc, double mu) {
        sc.guard.check("SlipControl");
        if (!sc.set_mu(mu))
          throw nb::value_error(("mu = " + std::to_string(mu) + ": must be finite, > 0 and <= 10").c_str());
      }, "mu"_a)
      .def("set_controller_settings", [](SC& sc, const GraspControllerSettings& s) {
        sc.guard.check("SlipControl");
        sc.set_controller_settings(s);
      }, "settings"_a)
      .def_prop_ro("command", [](const SC& sc) { return sc.command(); })
      .def_prop_ro("mode", [](const SC& sc) { return sc.mode(); })
      .def_prop_ro("fingers", [](const SC& sc) { return sc.fingers(); })
      .def_prop_ro("params", [](const SC& sc) { return sc.params(); })
      .def_prop_ro("settings", [](const SC& sc) { return sc.settings(); })
      .def_prop_ro("controller_settings", [](const SC& sc) { return sc.controller().settings(); })
      .def_prop_ro("mu", [](const SC& sc) { return sc.controller().mu(); });
}

}  // namespace lugrip_bind
