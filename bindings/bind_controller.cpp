// Grasp-force controller, its C_d filter and the static grasp force.
#include <nanobind/nanobind.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/tuple.h>

#include <limits>

#include "common.hpp"
#include "tables.hpp"

namespace lugrip_bind {

using namespace nb::literals;

void bind_controller(nb::module_& m) {
  nb::enum_<ControllerMode>(m, "ControllerMode")
      .value("SlippingAvoidance", ControllerMode::SlippingAvoidance)
      .value("Pivoting", ControllerMode::Pivoting);
  nb::enum_<PivotEnd>(m, "PivotEnd")
      .value("None_", PivotEnd::None)
      .value("CorThreshold", PivotEnd::CorThreshold)
      .value("Timeout", PivotEnd::Timeout)
      .value("Requested", PivotEnd::Requested)
      .value("AtFloor", PivotEnd::AtFloor);

  nb::class_<GraspControllerSettings> settings(m, "GraspControllerSettings");
  settings.def(nb::init<>()).def("__repr__", [](const GraspControllerSettings& s) { return to_string(s); });
  def_fields_rw(settings);
  m.def("paper_settings", &paper_settings,
        "The paper's law (eqs. 34-37): constant PI gains, no floor, reflex, lag overshoot, reserve, ceiling or learning.");
  m.def("validate_controller_settings", &validation_message<GraspControllerSettings>,
        "Empty string when valid, else one line per bad field.");

  nb::class_<GraspControllerOutput> out(m, "GraspControllerOutput");
  out.def(nb::init<>());
  def_fields_ro(out);

  using Lag = Guarded<LagFilter>;
  nb::class_<Lag>(m, "LagFilter")
      .def(nb::init<double, double, double, double>(), "k"_a, "z"_a, "p"_a, "sample_time"_a)
      .def_prop_ro("b0", [](const Lag& f) { return f.b0(); })
      .def_prop_ro("b1", [](const Lag& f) { return f.b1(); })
      .def_prop_ro("a1", [](const Lag& f) { return f.a1(); })
      .def("reset", [](Lag& f) {
        f.guard.check("LagFilter");
        f.reset();
      })
      .def("filter", [](Lag& f, const In1& u) {
        f.guard.check("LagFilter");
        return map1(u, [&](double x) { return f.step(x); });
      }, "u"_a, "Filters a 1-D array sample by sample (state carried over).");

  using Fingers2 = nb::ndarray<const double, nb::shape<-1, 2>, nb::c_contig, nb::device::cpu>;
  using Status2 = nb::ndarray<const int32_t, nb::shape<-1, 2>, nb::c_contig, nb::device::cpu>;
  using Bool2 = nb::ndarray<const bool, nb::shape<-1, 2>, nb::c_contig, nb::device::cpu>;
  using Int1 = nb::ndarray<const int32_t, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
  using Ctrl = Guarded<GraspController>;
  nb::class_<Ctrl>(m, "GraspController")
      .def(nb::init<const ContactParams&, const GraspControllerSettings&>(), "params"_a,
           "settings"_a = GraspControllerSettings())
      .def(nb::init<const ContactModel&, const GraspControllerSettings&>(), "model"_a,
           "settings"_a = GraspControllerSettings())
      .def("reset", [](Ctrl& c, double force) {
        c.guard.check("GraspController");
        c.reset(force);
      }, "current_force"_a)
      .def("request_pivoting", [](Ctrl& c) {
        c.guard.check("GraspController");
        c.request_pivoting();
      })
      .def("request_slipping_avoidance", [](Ctrl& c) {
        c.guard.check("GraspController");
        c.request_slipping_avoidance();
      })
      .def("set_dynamic_enabled", [](Ctrl& c, bool on) {
        c.guard.check("GraspController");
        c.set_dynamic_enabled(on);
      }, "enabled"_a)
      .def("set_settings", [](Ctrl& c, const GraspControllerSettings& s) {
        c.guard.check("GraspController");
        c.set_settings(s);
      }, "settings"_a)
      .def_prop_ro("settings", [](const Ctrl& c) { return c.settings(); })
      .def_prop_ro("mode", [](const Ctrl& c) { return c.mode(); })
      .def_prop_ro("command", [](const Ctrl& c) { return c.command(); })
      .def_prop_ro("command_period", [](const Ctrl& c) { return c.command_period(); })
      .def_prop_ro("mu", [](const Ctrl& c) { return c.mu(); })
      .def_prop_ro("dynamic_filter", [](const Ctrl& c) { return Lag(c.dynamic_filter(0)); })
      .def("step", [](Ctrl& c, double w0, double s0, double c0, double f0, int st0, bool p0,
                      double w1, double s1, double c1, double f1, int st1, bool p1, double r0,
                      double r1, double t0, double t1, double n0, double n1) {
        c.guard.check("GraspController");
        GraspControllerInput in;
        in.fingers[0] = FingerInput{w0, s0, c0, f0, static_cast<Status>(st0), p0, r0, t0, n0};
        in.fingers[1] = FingerInput{w1, s1, c1, f1, static_cast<Status>(st1), p1, r1, t1, n1};
        GraspControllerOutput o;
        c.step(in, o);
        return o;
      }, "Per-finger values of finger 0 then finger 1: omega_hat, S, c_tilde, f_t, status, present; then omega_resolution, tau and f_n of both.")
      .def("run", [](Ctrl& c, const Fingers2& w, const Fingers2& S, const Fingers2& ct,
                     const Fingers2& ft, const Status2& st, const Bool2& present, const Int1& requests,
                     const Fingers2& res, const Fingers2& tau, const Fingers2& fn) {
        c.guard.check("GraspController");
        const size_t n = w.shape(0);
        if (S.shape(0) != n || ct.shape(0) != n || ft.shape(0) != n || st.shape(0) != n ||
            present.shape(0) != n || requests.shape(0) != n || res.shape(0) != n || tau.shape(0) != n ||
            fn.shape(0) != n)
          throw std::invalid_argument("arrays must have the same length");
        Columns<GraspControllerOutput> cols(n);
        const double *pw = w.data(), *ps = S.data(), *pc = ct.data(), *pf = ft.data(), *pr = res.data(),
                     *pt = tau.data(), *pn = fn.data();
        const int32_t *pst = st.data(), *prq = requests.data();
        const bool* pp = present.data();
        {
          nb::gil_scoped_release release;
          GraspControllerInput in;
          GraspControllerOutput o;
          for (size_t i = 0; i < n; ++i) {
            if (prq[i] == 1) c.request_pivoting();
            else if (prq[i] == 2) c.request_slipping_avoidance();
            for (int k = 0; k < 2; ++k) {
              const size_t j = 2 * i + k;
              in.fingers[k] = FingerInput{pw[j], ps[j], pc[j], pf[j], static_cast<Status>(pst[j]), pp[j], pr[j], pt[j], pn[j]};
            }
            c.step(in, o);
            cols.set(i, o);
          }
        }
        nb::dict d;
        cols.into(d);
        return d;
      }, "omega_hat"_a, "S"_a, "c_tilde"_a, "f_t"_a, "status"_a, "present"_a, "requests"_a, "omega_resolution"_a, "tau"_a, "f_n"_a,
         "Runs step() over (N, 2) arrays in C++ (requests: 0 none, 1 pivoting, 2 slipping "
         "avoidance, applied before the sample); returns a dict of (N,) arrays (GraspControllerOutput.fields).");

  using Solver = Guarded<StaticForceSolver>;
  nb::class_<Solver>(m, "StaticForceSolver")
      .def(nb::init<const ContactModel&>(), "model"_a)
      .def("slippage", [](Solver& s, const In1& fn, const In1& ft, const In1& tau) {
        s.guard.check("StaticForceSolver");
        same_size(fn, ft);
        same_size(fn, tau);
        const size_t n = fn.shape(0);
        auto S = new_array<double>(n), c = new_array<double>(n);
        for (size_t i = 0; i < n; ++i) {
          double a = std::numeric_limits<double>::quiet_NaN();
          S.data()[i] = s.slippage(fn.data()[i], ft.data()[i], tau.data()[i], &a);
          c.data()[i] = a;
        }
        return nb::make_tuple(S, c);
      }, "f_n"_a, "f_t"_a, "tau"_a, "S_static and |c~| at each (f_n, f_t, tau).")
      .def("solve", [](Solver& s, const In1& ft, const In1& tau, double s_ref) {
        s.guard.check("StaticForceSolver");
        same_size(ft, tau);
        const size_t n = ft.shape(0);
        auto f = new_array<double>(n), c = new_array<double>(n), S = new_array<double>(n);
        auto it = new_array<int32_t>(n);
        auto conv = new_array<bool>(n);
        {
          nb::gil_scoped_release release;
          for (size_t i = 0; i < n; ++i) {
            const StaticForceResult r = s.solve(ft.data()[i], tau.data()[i], s_ref);
            f.data()[i] = r.force; c.data()[i] = r.c_tilde; S.data()[i] = r.slippage;
            it.data()[i] = r.iterations; conv.data()[i] = r.converged;
          }
        }
        nb::dict d;
        d["force"] = f; d["c_tilde"] = c; d["slippage"] = S; d["iterations"] = it; d["converged"] = conv;
        return d;
      }, "f_t"_a, "tau"_a, "s_ref"_a, "Static grasp force per load; dict of arrays.");
}

}  // namespace lugrip_bind
