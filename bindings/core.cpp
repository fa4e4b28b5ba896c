// The only nanobind file: builds lugrip._core. Thin: structs and step() as they are, plus batch
// loops over 1-D contiguous float64 arrays (shape handling lives in the Python layer).
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/tuple.h>

#include <cstdint>
#include <stdexcept>

#include "lugrip/lugrip.hpp"

namespace nb = nanobind;
using namespace nb::literals;
using namespace lugrip;

namespace {

using In1 = nb::ndarray<const double, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
template <class T>
using Out1 = nb::ndarray<nb::numpy, T, nb::ndim<1>>;

template <class T>
Out1<T> new_array(size_t n) {
  T* data = new T[n > 0 ? n : 1];
  nb::capsule owner(data, [](void* p) noexcept { delete[] static_cast<T*>(p); });
  return Out1<T>(data, {n}, owner);
}

void same_size(const In1& a, const In1& b) {
  if (a.shape(0) != b.shape(0)) throw std::invalid_argument("arrays must have the same length");
}

// Applies fn elementwise over one array.
template <class Fn>
Out1<double> map1(const In1& x, Fn&& fn) {
  const size_t n = x.shape(0);
  auto out = new_array<double>(n);
  const double* px = x.data();
  double* po = out.data();
  {
    nb::gil_scoped_release release;
    for (size_t i = 0; i < n; ++i) po[i] = fn(px[i]);
  }
  return out;
}

template <class Fn>
Out1<double> map2(const In1& x, const In1& y, Fn&& fn) {
  same_size(x, y);
  const size_t n = x.shape(0);
  auto out = new_array<double>(n);
  const double* px = x.data();
  const double* py = y.data();
  double* po = out.data();
  {
    nb::gil_scoped_release release;
    for (size_t i = 0; i < n; ++i) po[i] = fn(px[i], py[i]);
  }
  return out;
}

}  // namespace

NB_MODULE(_core, m) {
  m.doc() = "lugrip real-time core (C++17): limit surface, contact model, CoR estimation";
  m.attr("__version__") = LUGRIP_VERSION;

  nb::enum_<Status>(m, "Status", "Per-sample status (stable integer values).")
      .value("Ok", Status::Ok)
      .value("Saturated", Status::Saturated)
      .value("Degenerate", Status::Degenerate)
      .value("NoContact", Status::NoContact)
      .value("InvalidSample", Status::InvalidSample)
      .value("SensorFault", Status::SensorFault)
      .value("Reinitialized", Status::Reinitialized);
  m.def("status_description", [](int s) { return std::string(to_string(static_cast<Status>(s))); });

  m.def("shape_factor", &shape_factor, "k"_a, "Torsional shape factor xi(k) (tau_max = mu xi rho f_n).");

  nb::class_<ContactParams>(m, "ContactParams")
      .def(nb::init<>())
      .def_rw("mu", &ContactParams::mu)
      .def_rw("beta_a", &ContactParams::beta_a)
      .def_rw("sigma0", &ContactParams::sigma0)
      .def_rw("sigma_z", &ContactParams::sigma_z)
      .def_rw("delta", &ContactParams::delta)
      .def_rw("gamma", &ContactParams::gamma)
      .def_rw("k", &ContactParams::k)
      .def_rw("c_max", &ContactParams::c_max)
      .def("__repr__", [](const ContactParams& p) { return to_string(p); });
  m.def("validate_params", [](const ContactParams& p) {
    std::string msg;
    validate(p, &msg);
    return msg;
  }, "Empty string when valid, else one line per bad field.");
  m.def("table1_params", &table1_params);
  m.def("object_params", &object_params, "name"_a);

  nb::class_<CorSettings>(m, "CorSettings")
      .def(nb::init<>())
      .def_rw("f_n_min", &CorSettings::f_n_min)
      .def_rw("force_limit", &CorSettings::force_limit)
      .def_rw("torque_limit", &CorSettings::torque_limit)
      .def_rw("zero_force", &CorSettings::zero_force)
      .def_rw("zero_torque", &CorSettings::zero_torque);
  m.def("validate_cor_settings", [](const CorSettings& s) {
    std::string msg;
    validate(s, &msg);
    return msg;
  });

  nb::class_<LimitSurface>(m, "LimitSurface")
      .def(nb::init<double, int>(), "k"_a = 4.0, "intervals"_a = 0)
      .def_prop_ro("k", &LimitSurface::k)
      .def_prop_ro("xi", &LimitSurface::xi)
      .def_prop_ro("intervals", &LimitSurface::intervals)
      .def_prop_ro("small_slope", &LimitSurface::small_slope)
      .def_prop_ro("tail_force", &LimitSurface::tail_force)
      .def_prop_ro("tail_torque", &LimitSurface::tail_torque)
      .def("ft_star", [](const LimitSurface& ls, const In1& c) { return map1(c, [&](double x) { return ls.ft_star(x); }); })
      .def("tau_star", [](const LimitSurface& ls, const In1& c) { return map1(c, [&](double x) { return ls.tau_star(x); }); })
      .def("dft_star", [](const LimitSurface& ls, const In1& c) { return map1(c, [&](double x) { return ls.dft_star(x); }); })
      .def("dtau_star", [](const LimitSurface& ls, const In1& c) { return map1(c, [&](double x) { return ls.dtau_star(x); }); })
      .def("G", [](const LimitSurface& ls, const In1& c) { return map1(c, [&](double x) { return ls.G(x); }); })
      .def("sigma_ls", [](const LimitSurface& ls, const In1& a, double gamma) {
        return map1(a, [&](double x) { return ls.sigma_ls(x, gamma); });
      }, "a"_a, "gamma"_a)
      .def("integrate", [](const LimitSurface& ls, double a) {
        const LsPoint p = ls.integrate(a);
        return nb::make_tuple(p.F, p.T, p.dF, p.dT);
      }, "a"_a, "Direct quadrature at one |c~| (slow): (F, T, dF, dT).");

  nb::class_<ContactModel>(m, "ContactModel")
      .def(nb::init<const ContactParams&>(), "params"_a)
      .def_prop_ro("xi", &ContactModel::xi)
      .def("rho", [](const ContactModel& cm, const In1& fn) { return map1(fn, [&](double x) { return cm.rho(x); }); })
      .def("ft_max", [](const ContactModel& cm, const In1& fn) { return map1(fn, [&](double x) { return cm.ft_max(x); }); })
      .def("tau_max", [](const ContactModel& cm, const In1& fn) { return map1(fn, [&](double x) { return cm.tau_max(x); }); })
      .def("viscous_ratio", [](const ContactModel& cm, const In1& fn) { return map1(fn, [&](double x) { return cm.viscous_ratio(x); }); })
      .def("sigma_1", [](const ContactModel& cm, const In1& fn, const In1& c) { return map2(fn, c, [&](double x, double y) { return cm.sigma_1(x, y); }); })
      .def("g", [](const ContactModel& cm, const In1& fn, const In1& c) { return map2(fn, c, [&](double x, double y) { return cm.g(x, y); }); })
      .def("invert_sigma", [](const ContactModel& cm, const In1& s) { return map1(s, [&](double x) { return cm.invert_sigma(x); }); })
      .def("solve_outside", [](const ContactModel& cm, const In1& f, const In1& t) { return map2(f, t, [&](double x, double y) { return cm.solve_outside(x, y); }); })
      .def("wrench_at", [](const ContactModel& cm, const In1& fn, const In1& c, const In1& y) {
        same_size(fn, c);
        same_size(fn, y);
        const size_t n = fn.shape(0);
        auto ft = new_array<double>(n), tau = new_array<double>(n);
        for (size_t i = 0; i < n; ++i) cm.wrench_at(fn.data()[i], c.data()[i], y.data()[i], ft.data()[i], tau.data()[i]);
        return nb::make_tuple(ft, tau);
      }, "f_n"_a, "c_tilde"_a, "y"_a, "Sensor wrench (f_t, tau) with CoR |c~| and torque y about it.");

  nb::class_<CorOutput>(m, "CorOutput")
      .def(nb::init<>())
      .def_ro("c_tilde", &CorOutput::c_tilde)
      .def_ro("c", &CorOutput::c)
      .def_ro("ft_tilde", &CorOutput::ft_tilde)
      .def_ro("tau_tilde", &CorOutput::tau_tilde)
      .def_ro("sigma", &CorOutput::sigma)
      .def_ro("rho", &CorOutput::rho)
      .def_ro("g", &CorOutput::g)
      .def_ro("sigma_1", &CorOutput::sigma_1)
      .def_ro("y", &CorOutput::y)
      .def_ro("inside", &CorOutput::inside)
      .def_ro("saturated", &CorOutput::saturated)
      .def_ro("iterations", &CorOutput::iterations)
      .def_ro("status", &CorOutput::status)
      .def_ro("c_tilde_unclipped", &CorOutput::c_tilde_unclipped);

  nb::class_<CorEstimator>(m, "CorEstimator")
      .def(nb::init<const ContactParams&, const CorSettings&>(), "params"_a, "settings"_a = CorSettings())
      .def(nb::init<const ContactModel&, const CorSettings&>(), "model"_a, "settings"_a = CorSettings())
      .def("reset", &CorEstimator::reset)
      .def("step", [](CorEstimator& e, double f_n, double f_t, double tau) {
        CorOutput out;
        e.step(CorInput{f_n, f_t, tau}, out);
        return out;
      }, "f_n"_a, "f_t"_a, "tau"_a)
      .def("run", [](CorEstimator& e, const In1& fn, const In1& ft, const In1& tau) {
        same_size(fn, ft);
        same_size(fn, tau);
        const size_t n = fn.shape(0);
        auto c_tilde = new_array<double>(n), c = new_array<double>(n), ft_t = new_array<double>(n),
             tau_t = new_array<double>(n), sigma = new_array<double>(n), rho = new_array<double>(n),
             g = new_array<double>(n), s1 = new_array<double>(n), y = new_array<double>(n);
        auto inside = new_array<bool>(n), sat = new_array<bool>(n);
        auto iters = new_array<int32_t>(n), status = new_array<int32_t>(n);
        auto c_free = new_array<double>(n);
        const double *pf = fn.data(), *pt = ft.data(), *pq = tau.data();
        {
          nb::gil_scoped_release release;
          CorOutput o;
          for (size_t i = 0; i < n; ++i) {
            e.step(CorInput{pf[i], pt[i], pq[i]}, o);
            c_tilde.data()[i] = o.c_tilde;
            c.data()[i] = o.c;
            ft_t.data()[i] = o.ft_tilde;
            tau_t.data()[i] = o.tau_tilde;
            sigma.data()[i] = o.sigma;
            rho.data()[i] = o.rho;
            g.data()[i] = o.g;
            s1.data()[i] = o.sigma_1;
            y.data()[i] = o.y;
            inside.data()[i] = o.inside;
            sat.data()[i] = o.saturated;
            iters.data()[i] = o.iterations;
            status.data()[i] = static_cast<int32_t>(o.status);
            c_free.data()[i] = o.c_tilde_unclipped;
          }
        }
        nb::dict d;
        d["c_tilde_unclipped"] = c_free;
        d["c_tilde"] = c_tilde; d["c"] = c; d["ft_tilde"] = ft_t; d["tau_tilde"] = tau_t;
        d["sigma"] = sigma; d["rho"] = rho; d["g"] = g; d["sigma_1"] = s1; d["y"] = y;
        d["inside"] = inside; d["saturated"] = sat; d["iterations"] = iters; d["status"] = status;
        return d;
      }, "f_n"_a, "f_t"_a, "tau"_a, "Runs step() over 1-D arrays in C++; returns a dict of arrays.");

  // --- controller --------------------------------------------------------------------------
  // GraspController, C_d filter and static grasp force (include/lugrip/grasp_controller.hpp).
  nb::enum_<ControllerMode>(m, "ControllerMode")
      .value("SlippingAvoidance", ControllerMode::SlippingAvoidance)
      .value("Pivoting", ControllerMode::Pivoting);
  nb::enum_<PivotEnd>(m, "PivotEnd")
      .value("None_", PivotEnd::None)
      .value("CorThreshold", PivotEnd::CorThreshold)
      .value("Timeout", PivotEnd::Timeout)
      .value("Requested", PivotEnd::Requested);

  nb::class_<GraspControllerSettings>(m, "GraspControllerSettings")
      .def(nb::init<>())
      .def_rw("sensor_rate", &GraspControllerSettings::sensor_rate)
      .def_rw("command_ratio", &GraspControllerSettings::command_ratio)
      .def_rw("k_cd", &GraspControllerSettings::k_cd)
      .def_rw("p_cd", &GraspControllerSettings::p_cd)
      .def_rw("z_cd", &GraspControllerSettings::z_cd)
      .def_rw("dynamic_enabled", &GraspControllerSettings::dynamic_enabled)
      .def_rw("s_ref", &GraspControllerSettings::s_ref)
      .def_rw("k_p", &GraspControllerSettings::k_p)
      .def_rw("k_i", &GraspControllerSettings::k_i)
      .def_rw("anti_windup", &GraspControllerSettings::anti_windup)
      .def_rw("gain_schedule_force", &GraspControllerSettings::gain_schedule_force)
      .def_rw("omega_deadband", &GraspControllerSettings::omega_deadband)
      .def_rw("static_equivalent_slippage", &GraspControllerSettings::static_equivalent_slippage)
      .def_rw("f_min", &GraspControllerSettings::f_min)
      .def_rw("f_max", &GraspControllerSettings::f_max)
      .def_rw("max_rate_up", &GraspControllerSettings::max_rate_up)
      .def_rw("max_rate_down", &GraspControllerSettings::max_rate_down)
      .def_rw("invalid_raise_step", &GraspControllerSettings::invalid_raise_step)
      .def_rw("s_pivot", &GraspControllerSettings::s_pivot)
      .def_rw("tau_pivot", &GraspControllerSettings::tau_pivot)
      .def_rw("k_f", &GraspControllerSettings::k_f)
      .def_rw("pivot_floor_factor", &GraspControllerSettings::pivot_floor_factor)
      .def_rw("pivot_end_c_tilde", &GraspControllerSettings::pivot_end_c_tilde)
      .def_rw("pivot_end_samples", &GraspControllerSettings::pivot_end_samples)
      .def_rw("pivot_timeout", &GraspControllerSettings::pivot_timeout)
      .def("__repr__", [](const GraspControllerSettings& s) { return to_string(s); });
  m.def("validate_controller_settings", [](const GraspControllerSettings& s) {
    std::string msg;
    validate(s, &msg);
    return msg;
  }, "Empty string when valid, else one line per bad field.");

  nb::class_<GraspControllerOutput>(m, "GraspControllerOutput")
      .def(nb::init<>())
      .def_ro("force", &GraspControllerOutput::force)
      .def_ro("static_force", &GraspControllerOutput::static_force)
      .def_ro("dynamic_force", &GraspControllerOutput::dynamic_force)
      .def_ro("floor", &GraspControllerOutput::floor)
      .def_ro("slippage", &GraspControllerOutput::slippage)
      .def_ro("error", &GraspControllerOutput::error)
      .def_ro("integrator", &GraspControllerOutput::integrator)
      .def_prop_ro("dynamic_sample", [](const GraspControllerOutput& o) {
        return nb::make_tuple(o.dynamic_sample[0], o.dynamic_sample[1]);
      })
      .def_ro("dynamic_peak", &GraspControllerOutput::dynamic_peak)
      .def_ro("mean_c_tilde", &GraspControllerOutput::mean_c_tilde)
      .def_ro("pivot_time", &GraspControllerOutput::pivot_time)
      .def_ro("mode", &GraspControllerOutput::mode)
      .def_ro("pivot_end", &GraspControllerOutput::pivot_end)
      .def_ro("pivot_finished", &GraspControllerOutput::pivot_finished)
      .def_ro("command_issued", &GraspControllerOutput::command_issued)
      .def_ro("saturated", &GraspControllerOutput::saturated)
      .def_ro("rate_limited", &GraspControllerOutput::rate_limited)
      .def_ro("held", &GraspControllerOutput::held)
      .def_ro("status", &GraspControllerOutput::status);

  nb::class_<LagFilter>(m, "LagFilter")
      .def(nb::init<double, double, double, double>(), "k"_a, "z"_a, "p"_a, "sample_time"_a)
      .def_prop_ro("b0", &LagFilter::b0)
      .def_prop_ro("b1", &LagFilter::b1)
      .def_prop_ro("a1", &LagFilter::a1)
      .def("reset", &LagFilter::reset)
      .def("filter", [](LagFilter& f, const In1& u) { return map1(u, [&](double x) { return f.step(x); }); },
           "u"_a, "Filters a 1-D array sample by sample (state carried over).");

  using Fingers2 = nb::ndarray<const double, nb::shape<-1, 2>, nb::c_contig, nb::device::cpu>;
  using Status2 = nb::ndarray<const int32_t, nb::shape<-1, 2>, nb::c_contig, nb::device::cpu>;
  using Bool2 = nb::ndarray<const bool, nb::shape<-1, 2>, nb::c_contig, nb::device::cpu>;
  using Int1 = nb::ndarray<const int32_t, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
  nb::class_<GraspController>(m, "GraspController")
      .def(nb::init<const ContactParams&, const GraspControllerSettings&>(), "params"_a,
           "settings"_a = GraspControllerSettings())
      .def("reset", nb::overload_cast<double>(&GraspController::reset), "current_force"_a)
      .def("request_pivoting", &GraspController::request_pivoting)
      .def("request_slipping_avoidance", &GraspController::request_slipping_avoidance)
      .def("set_dynamic_enabled", &GraspController::set_dynamic_enabled, "enabled"_a)
      .def("set_settings", &GraspController::set_settings, "settings"_a)
      .def_prop_ro("settings", &GraspController::settings)
      .def_prop_ro("mode", &GraspController::mode)
      .def_prop_ro("command", &GraspController::command)
      .def_prop_ro("command_period", &GraspController::command_period)
      .def_prop_ro("mu", &GraspController::mu)
      .def_prop_ro("dynamic_filter", [](const GraspController& c) { return c.dynamic_filter(0); })
      .def("step", [](GraspController& c, double w0, double s0, double c0, double f0, int st0, bool p0,
                      double w1, double s1, double c1, double f1, int st1, bool p1, double r0,
                      double r1) {
        GraspControllerInput in;
        in.fingers[0] = FingerInput{w0, s0, c0, f0, static_cast<Status>(st0), p0, r0};
        in.fingers[1] = FingerInput{w1, s1, c1, f1, static_cast<Status>(st1), p1, r1};
        GraspControllerOutput out;
        c.step(in, out);
        return out;
      }, "Per-finger values of finger 0 then finger 1: omega_hat, S, c_tilde, f_t, status, present; then omega_resolution of both.")
      .def("run", [](GraspController& c, const Fingers2& w, const Fingers2& S, const Fingers2& ct,
                     const Fingers2& ft, const Status2& st, const Bool2& present, const Int1& requests,
                     const Fingers2& res) {
        const size_t n = w.shape(0);
        if (S.shape(0) != n || ct.shape(0) != n || ft.shape(0) != n || st.shape(0) != n ||
            present.shape(0) != n || requests.shape(0) != n || res.shape(0) != n)
          throw std::invalid_argument("arrays must have the same length");
        auto force = new_array<double>(n), fns = new_array<double>(n), fnd = new_array<double>(n),
             floor = new_array<double>(n), slip = new_array<double>(n), err = new_array<double>(n),
             integ = new_array<double>(n), d0 = new_array<double>(n), d1 = new_array<double>(n),
             peak = new_array<double>(n), mct = new_array<double>(n), pt = new_array<double>(n);
        auto mode = new_array<int32_t>(n), pend = new_array<int32_t>(n), status = new_array<int32_t>(n);
        auto issued = new_array<bool>(n), fin = new_array<bool>(n), sat = new_array<bool>(n),
             rl = new_array<bool>(n), held = new_array<bool>(n);
        const double *pw = w.data(), *ps = S.data(), *pc = ct.data(), *pf = ft.data(), *pr = res.data();
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
              in.fingers[k] = FingerInput{pw[j], ps[j], pc[j], pf[j], static_cast<Status>(pst[j]), pp[j], pr[j]};
            }
            c.step(in, o);
            force.data()[i] = o.force; fns.data()[i] = o.static_force; fnd.data()[i] = o.dynamic_force;
            floor.data()[i] = o.floor; slip.data()[i] = o.slippage; err.data()[i] = o.error;
            integ.data()[i] = o.integrator; d0.data()[i] = o.dynamic_sample[0];
            d1.data()[i] = o.dynamic_sample[1]; peak.data()[i] = o.dynamic_peak;
            mct.data()[i] = o.mean_c_tilde; pt.data()[i] = o.pivot_time;
            mode.data()[i] = static_cast<int32_t>(o.mode); pend.data()[i] = static_cast<int32_t>(o.pivot_end);
            status.data()[i] = static_cast<int32_t>(o.status); issued.data()[i] = o.command_issued;
            fin.data()[i] = o.pivot_finished; sat.data()[i] = o.saturated; rl.data()[i] = o.rate_limited;
            held.data()[i] = o.held;
          }
        }
        nb::dict d;
        d["force"] = force; d["static_force"] = fns; d["dynamic_force"] = fnd; d["floor"] = floor;
        d["slippage"] = slip; d["error"] = err; d["integrator"] = integ; d["dynamic_sample_0"] = d0;
        d["dynamic_sample_1"] = d1; d["dynamic_peak"] = peak; d["mean_c_tilde"] = mct;
        d["pivot_time"] = pt; d["mode"] = mode; d["pivot_end"] = pend; d["status"] = status;
        d["command_issued"] = issued; d["pivot_finished"] = fin; d["saturated"] = sat;
        d["rate_limited"] = rl; d["held"] = held;
        return d;
      }, "omega_hat"_a, "S"_a, "c_tilde"_a, "f_t"_a, "status"_a, "present"_a, "requests"_a, "omega_resolution"_a,
         "Runs step() over (N, 2) arrays in C++ (requests: 0 none, 1 pivoting, 2 slipping "
         "avoidance, applied before the sample); returns a dict of (N,) arrays.");

  nb::class_<StaticForceSolver>(m, "StaticForceSolver")
      .def(nb::init<const ContactModel&>(), "model"_a)
      .def("slippage", [](StaticForceSolver& s, const In1& fn, const In1& ft, const In1& tau) {
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
      .def("solve", [](StaticForceSolver& s, const In1& ft, const In1& tau, double s_ref) {
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
  // --- end of controller block ---------------------------------------------------------------
  // --- plant ---------------------------------------------------------------------------------
  // Grasp simulator (include/lugrip/grasp_plant.hpp): config structs, PatchContact, GraspPlant
  // with a batch run() that loops in C++ (GIL released) and returns a dict of arrays.
  {
    nb::enum_<PlantModel>(m, "PlantModel", "Contact model of the grasp plant.")
        .value("Patch", PlantModel::Patch)
        .value("Lumped", PlantModel::Lumped);
    nb::enum_<PulseShape>(m, "PulseShape", "Time profile of a disturbance pulse.")
        .value("Rectangular", PulseShape::Rectangular)
        .value("HalfSine", PulseShape::HalfSine)
        .value("Ramp", PulseShape::Ramp)
        .value("Triangle", PulseShape::Triangle);

    nb::class_<ObjectConfig>(m, "ObjectConfig")
        .def(nb::init<>())
        .def_rw("mass", &ObjectConfig::mass)
        .def_rw("inertia", &ObjectConfig::inertia)
        .def_rw("cog_x", &ObjectConfig::cog_x)
        .def_rw("cog_y", &ObjectConfig::cog_y)
        .def_rw("theta0", &ObjectConfig::theta0);
    nb::class_<GripperMove>(m, "GripperMove")
        .def(nb::init<>())
        .def_rw("t_start", &GripperMove::t_start)
        .def_rw("duration", &GripperMove::duration)
        .def_rw("dx", &GripperMove::dx)
        .def_rw("dy", &GripperMove::dy);
    nb::class_<Disturbance>(m, "Disturbance")
        .def(nb::init<>())
        .def_rw("t_start", &Disturbance::t_start)
        .def_rw("duration", &Disturbance::duration)
        .def_rw("shape", &Disturbance::shape)
        .def_rw("force_x", &Disturbance::force_x)
        .def_rw("force_y", &Disturbance::force_y)
        .def_rw("torque", &Disturbance::torque)
        .def_rw("point_x", &Disturbance::point_x)
        .def_rw("point_y", &Disturbance::point_y);
    nb::class_<ActuatorConfig>(m, "ActuatorConfig")
        .def(nb::init<>())
        .def_rw("f_init", &ActuatorConfig::f_init)
        .def_rw("f_max", &ActuatorConfig::f_max)
        .def_rw("time_constant", &ActuatorConfig::time_constant)
        .def_rw("rate_limit", &ActuatorConfig::rate_limit)
        .def_rw("command_rate", &ActuatorConfig::command_rate);
    nb::class_<SensorConfig>(m, "SensorConfig")
        .def(nb::init<>())
        .def_rw("rate", &SensorConfig::rate)
        .def_rw("force_noise", &SensorConfig::force_noise)
        .def_rw("torque_noise", &SensorConfig::torque_noise)
        .def_rw("force_resolution", &SensorConfig::force_resolution)
        .def_rw("torque_resolution", &SensorConfig::torque_resolution)
        .def_rw("filter_time_constant", &SensorConfig::filter_time_constant)
        .def("get_bias", [](const SensorConfig& s, int finger, int channel) {
          if (finger < 0 || finger > 1 || channel < 0 || channel > 3) throw std::out_of_range("finger 0..1, channel 0..3");
          return s.bias[finger][channel];
        }, "finger"_a, "channel"_a)
        .def("set_bias", [](SensorConfig& s, int finger, int channel, double v) {
          if (finger < 0 || finger > 1 || channel < 0 || channel > 3) throw std::out_of_range("finger 0..1, channel 0..3");
          s.bias[finger][channel] = v;
        }, "finger"_a, "channel"_a, "value"_a, "Bias of (f_n, f_x, f_y, tau)[channel] of a finger.");
    nb::class_<PatchSettings>(m, "PatchSettings")
        .def(nb::init<>())
        .def_rw("rings", &PatchSettings::rings)
        .def_rw("bristle_stiffness", &PatchSettings::bristle_stiffness)
        .def_rw("bristle_damping", &PatchSettings::bristle_damping)
        .def_rw("static_ratio", &PatchSettings::static_ratio)
        .def_rw("stribeck_velocity", &PatchSettings::stribeck_velocity);
    nb::class_<DropConfig>(m, "DropConfig")
        .def(nb::init<>())
        .def_rw("slip_limit", &DropConfig::slip_limit)
        .def_rw("rotation_limit", &DropConfig::rotation_limit)
        .def_rw("contact_force_min", &DropConfig::contact_force_min);
    nb::class_<PlantConfig>(m, "PlantConfig")
        .def(nb::init<>())
        .def_rw("contact", &PlantConfig::contact)
        .def_rw("model", &PlantConfig::model)
        .def_rw("object", &PlantConfig::object)
        .def_rw("actuator", &PlantConfig::actuator)
        .def_rw("sensor", &PlantConfig::sensor)
        .def_rw("patch", &PlantConfig::patch)
        .def_rw("drop", &PlantConfig::drop)
        .def_rw("gravity", &PlantConfig::gravity)
        .def_rw("rate", &PlantConfig::rate)
        .def_rw("substeps", &PlantConfig::substeps)
        .def_rw("support", &PlantConfig::support)
        .def_rw("seed", &PlantConfig::seed)
        .def("clear_moves", [](PlantConfig& c) { c.moves.clear(); })
        .def("add_move", [](PlantConfig& c, const GripperMove& v) { c.moves.push_back(v); })
        .def("clear_disturbances", [](PlantConfig& c) { c.disturbances.clear(); })
        .def("add_disturbance", [](PlantConfig& c, const Disturbance& v) { c.disturbances.push_back(v); })
        .def_prop_ro("n_moves", [](const PlantConfig& c) { return c.moves.size(); })
        .def_prop_ro("n_disturbances", [](const PlantConfig& c) { return c.disturbances.size(); });
    m.def("validate_plant_config", [](const PlantConfig& c) {
      std::string msg;
      validate(c, &msg);
      return msg;
    }, "Empty string when valid, else one line per bad field.");

    nb::class_<FingerSample>(m, "FingerSample")
        .def(nb::init<>())
        .def_ro("index", &FingerSample::index)
        .def_ro("t", &FingerSample::t)
        .def_ro("f_n", &FingerSample::f_n)
        .def_ro("f_x", &FingerSample::f_x)
        .def_ro("f_y", &FingerSample::f_y)
        .def_ro("tau", &FingerSample::tau)
        .def_ro("true_f_n", &FingerSample::true_f_n)
        .def_ro("true_f_x", &FingerSample::true_f_x)
        .def_ro("true_f_y", &FingerSample::true_f_y)
        .def_ro("true_tau", &FingerSample::true_tau)
        .def_ro("slip_x", &FingerSample::slip_x)
        .def_ro("slip_y", &FingerSample::slip_y)
        .def_ro("slip_angle", &FingerSample::slip_angle)
        .def_ro("slip_vx", &FingerSample::slip_vx)
        .def_ro("slip_vy", &FingerSample::slip_vy)
        .def_ro("omega", &FingerSample::omega)
        .def_ro("c_tilde", &FingerSample::c_tilde)
        .def_ro("rho", &FingerSample::rho);
    nb::class_<PlantState>(m, "PlantState")
        .def(nb::init<>())
        .def_ro("t", &PlantState::t)
        .def_ro("f_cmd", &PlantState::f_cmd)
        .def_ro("f_held", &PlantState::f_held)
        .def_ro("f_n", &PlantState::f_n)
        .def_ro("gripper_x", &PlantState::gripper_x)
        .def_ro("gripper_y", &PlantState::gripper_y)
        .def_ro("gripper_vx", &PlantState::gripper_vx)
        .def_ro("gripper_vy", &PlantState::gripper_vy)
        .def_ro("x", &PlantState::x)
        .def_ro("y", &PlantState::y)
        .def_ro("vx", &PlantState::vx)
        .def_ro("vy", &PlantState::vy)
        .def_ro("theta", &PlantState::theta)
        .def_ro("omega", &PlantState::omega)
        .def_ro("slip_x", &PlantState::slip_x)
        .def_ro("slip_y", &PlantState::slip_y)
        .def_ro("slip_angle", &PlantState::slip_angle)
        .def_ro("max_slip", &PlantState::max_slip)
        .def_ro("max_rotation", &PlantState::max_rotation)
        .def_ro("contact_fx", &PlantState::contact_fx)
        .def_ro("contact_fy", &PlantState::contact_fy)
        .def_ro("contact_tau", &PlantState::contact_tau)
        .def_ro("ext_fx", &PlantState::ext_fx)
        .def_ro("ext_fy", &PlantState::ext_fy)
        .def_ro("ext_tau", &PlantState::ext_tau)
        .def_ro("supported", &PlantState::supported)
        .def_ro("dropped", &PlantState::dropped)
        .def_ro("drop_time", &PlantState::drop_time)
        .def_ro("drop_reason", &PlantState::drop_reason)
        .def_ro("steps", &PlantState::steps);

    nb::class_<PatchContact>(m, "PatchContact")
        .def(nb::init<const ContactParams&, const PatchSettings&>(), "params"_a, "settings"_a = PatchSettings())
        .def_prop_ro("cells", &PatchContact::cells)
        .def_prop_ro("rho", &PatchContact::rho)
        .def_prop_ro("moment2", &PatchContact::moment2)
        .def_prop_ro("bristle_energy", &PatchContact::bristle_energy)
        .def("reset", &PatchContact::reset)
        .def("advance", [](PatchContact& pc, double f_n, double vx, double vy, double omega, double h, int steps) {
          PadWrench w;
          for (int i = 0; i < steps; ++i) pc.advance(f_n, vx, vy, omega, h, w);
          return nb::make_tuple(w.fx, w.fy, w.tau);
        }, "f_n"_a, "vx"_a, "vy"_a, "omega"_a, "h"_a, "steps"_a = 1,
           "Prescribed kinematics for `steps` steps of h; wrench of the pad on the object (fx, fy, tau).");

    nb::class_<GraspPlant>(m, "GraspPlant")
        .def(nb::init<const PlantConfig&>(), "config"_a)
        .def("reset", &GraspPlant::reset)
        .def("set_command", &GraspPlant::set_command, "f_cmd"_a)
        .def("set_external", &GraspPlant::set_external, "fx"_a, "fy"_a, "torque"_a)
        .def("step", &GraspPlant::step)
        .def("advance_sample", &GraspPlant::advance_sample)
        .def("sensor_sample", [](const GraspPlant& p, int finger) {
          if (finger < 0 || finger > 1) throw std::out_of_range("finger must be 0 or 1");
          return p.sensor_sample(finger);
        }, "finger"_a)
        .def_prop_ro("state", [](const GraspPlant& p) { return p.state(); })
        .def_prop_ro("config", [](const GraspPlant& p) { return p.config(); })
        .def_prop_ro("time", &GraspPlant::time)
        .def_prop_ro("dt", &GraspPlant::dt)
        .def_prop_ro("steps_per_sample", &GraspPlant::steps_per_sample)
        .def_prop_ro("steps_per_command", &GraspPlant::steps_per_command)
        .def_prop_ro("cells", &GraspPlant::cells)
        .def_prop_ro("energy", &GraspPlant::energy)
        .def("gripper_at", [](const GraspPlant& p, double t) {
          double x, y, vx, vy;
          p.gripper_at(t, x, y, vx, vy);
          return nb::make_tuple(x, y, vx, vy);
        }, "t"_a)
        .def("disturbance_at", [](const GraspPlant& p, double t, double theta) {
          double fx, fy, tz;
          p.disturbance_at(t, theta, fx, fy, tz);
          return nb::make_tuple(fx, fy, tz);
        }, "t"_a, "theta"_a)
        .def("run", [](GraspPlant& p, const In1& command) {
          // Row k: set_command(command[k]) at the current sample, advance to the next sample,
          // record it. NaN commands leave the command unchanged.
          const size_t n = command.shape(0);
          const char* fin[] = {"f_n", "f_x", "f_y", "tau", "true_f_n", "true_f_x", "true_f_y", "true_tau",
                               "slip_x", "slip_y", "slip_angle", "slip_vx", "slip_vy", "omega", "c_tilde", "rho"};
          constexpr int nf = 16;
          const char* pl[] = {"t", "f_cmd", "f_held", "f_act", "gripper_x", "gripper_y", "gripper_vy", "x", "y",
                              "vx", "vy", "theta", "object_omega", "max_slip", "max_rotation", "contact_fx",
                              "contact_fy", "contact_tau", "ext_fx", "ext_fy", "ext_tau", "energy"};
          constexpr int np = 22;
          std::vector<Out1<double>> fa, pa;
          for (int j = 0; j < 2 * nf; ++j) fa.push_back(new_array<double>(n));
          for (int j = 0; j < np; ++j) pa.push_back(new_array<double>(n));
          auto sup = new_array<bool>(n), drop = new_array<bool>(n);
          std::vector<double*> fp(2 * nf), pp(np);
          for (int j = 0; j < 2 * nf; ++j) fp[j] = fa[j].data();
          for (int j = 0; j < np; ++j) pp[j] = pa[j].data();
          const double* cmd = command.data();
          {
            nb::gil_scoped_release release;
            for (size_t k = 0; k < n; ++k) {
              if (cmd[k] == cmd[k]) p.set_command(cmd[k]);
              p.advance_sample();
              for (int i = 0; i < 2; ++i) {
                const FingerSample& s = p.sensor_sample(i);
                const double v[nf] = {s.f_n, s.f_x, s.f_y, s.tau, s.true_f_n, s.true_f_x, s.true_f_y, s.true_tau,
                                      s.slip_x, s.slip_y, s.slip_angle, s.slip_vx, s.slip_vy, s.omega, s.c_tilde, s.rho};
                for (int j = 0; j < nf; ++j) fp[2 * j + i][k] = v[j];
              }
              const PlantState& st = p.state();
              const double v[np] = {st.t, st.f_cmd, st.f_held, st.f_n, st.gripper_x, st.gripper_y, st.gripper_vy,
                                    st.x, st.y, st.vx, st.vy, st.theta, st.omega, st.max_slip, st.max_rotation,
                                    st.contact_fx, st.contact_fy, st.contact_tau, st.ext_fx, st.ext_fy, st.ext_tau,
                                    p.energy()};
              for (int j = 0; j < np; ++j) pp[j][k] = v[j];
              sup.data()[k] = st.supported;
              drop.data()[k] = st.dropped;
            }
          }
          nb::dict d;
          for (int j = 0; j < nf; ++j) {
            d[(std::string(fin[j]) + "_0").c_str()] = fa[2 * j];
            d[(std::string(fin[j]) + "_1").c_str()] = fa[2 * j + 1];
          }
          for (int j = 0; j < np; ++j) d[pl[j]] = pa[j];
          d["supported"] = sup;
          d["dropped"] = drop;
          return d;
        }, "command"_a,
           "One row per sensor sample: set_command(command[k]) (NaN: keep), advance to the next "
           "sample, record. Finger quantities as <name>_0 / <name>_1. Returns a dict of arrays.");
  }
  // --- end of plant block --------------------------------------------------------------------

  // ===== observer block (issue 3): slider model, sliding-velocity observer ================
  nb::enum_<Integrator>(m, "Integrator", "Discretisation of the LuGre rotor over one sample.")
      .value("Implicit", Integrator::Implicit)
      .value("Rk4", Integrator::Rk4)
      .value("Rk4Adaptive", Integrator::Rk4Adaptive)
      .value("Rosenbrock", Integrator::Rosenbrock);
  nb::enum_<GainMode>(m, "GainMode", "Observer gain: fixed l, or l = bandwidth / sigma_1.")
      .value("Fixed", GainMode::Fixed)
      .value("Bandwidth", GainMode::Bandwidth);

  nb::class_<SliderSettings>(m, "SliderSettings")
      .def(nb::init<>())
      .def_rw("integrator", &SliderSettings::integrator)
      .def_rw("max_substep", &SliderSettings::max_substep)
      .def_rw("max_substeps", &SliderSettings::max_substeps)
      .def_rw("g_floor", &SliderSettings::g_floor);
  m.def("validate_slider_settings", [](const SliderSettings& s) {
    std::string msg;
    validate(s, &msg);
    return msg;
  }, "Empty string when valid, else one line per bad field.");

  nb::class_<SliderOutput>(m, "SliderOutput")
      .def(nb::init<>())
      .def_ro("z", &SliderOutput::z)
      .def_ro("omega", &SliderOutput::omega)
      .def_ro("zdot", &SliderOutput::zdot)
      .def_ro("g", &SliderOutput::g)
      .def_ro("sigma_1", &SliderOutput::sigma_1)
      .def_ro("dry_torque", &SliderOutput::dry_torque)
      .def_ro("friction_torque", &SliderOutput::friction_torque)
      .def_ro("slip", &SliderOutput::slip)
      .def_ro("substeps", &SliderOutput::substeps)
      .def_ro("projected", &SliderOutput::projected)
      .def_ro("status", &SliderOutput::status);

  nb::class_<SliderModel>(m, "SliderModel")
      .def(nb::init<const ContactParams&, double, const SliderSettings&>(), "params"_a, "J"_a,
           "settings"_a = SliderSettings())
      .def(nb::init<const ContactModel&, double, const SliderSettings&>(), "model"_a, "J"_a,
           "settings"_a = SliderSettings())
      .def("reset", &SliderModel::reset, "z"_a = 0.0, "omega"_a = 0.0)
      .def_prop_ro("z", &SliderModel::z)
      .def_prop_ro("omega", &SliderModel::omega)
      .def_prop_ro("J", &SliderModel::inertia)
      .def("step", [](SliderModel& s, double f_n, double c_tilde, double tau_e, double dt) {
        SliderOutput out;
        s.step(SliderInput{f_n, c_tilde, tau_e, dt}, out);
        return out;
      }, "f_n"_a, "c_tilde"_a, "tau_e"_a, "dt"_a)
      .def("simulate", [](SliderModel& s, const In1& fn, const In1& ct, const In1& te, const In1& dt) {
        same_size(fn, ct);
        same_size(fn, te);
        same_size(fn, dt);
        const size_t n = fn.shape(0);
        auto z = new_array<double>(n), w = new_array<double>(n), zd = new_array<double>(n),
             g = new_array<double>(n), s1 = new_array<double>(n), dry = new_array<double>(n),
             fr = new_array<double>(n), slip = new_array<double>(n);
        auto sub = new_array<int32_t>(n), status = new_array<int32_t>(n);
        auto proj = new_array<bool>(n);
        const double *pf = fn.data(), *pc = ct.data(), *pe = te.data(), *pd = dt.data();
        {
          nb::gil_scoped_release release;
          SliderOutput o;
          for (size_t i = 0; i < n; ++i) {
            s.step(SliderInput{pf[i], pc[i], pe[i], pd[i]}, o);
            z.data()[i] = o.z; w.data()[i] = o.omega; zd.data()[i] = o.zdot; g.data()[i] = o.g;
            s1.data()[i] = o.sigma_1; dry.data()[i] = o.dry_torque; fr.data()[i] = o.friction_torque;
            slip.data()[i] = o.slip; sub.data()[i] = o.substeps; proj.data()[i] = o.projected;
            status.data()[i] = static_cast<int32_t>(o.status);
          }
        }
        nb::dict d;
        d["z"] = z; d["omega"] = w; d["zdot"] = zd; d["g"] = g; d["sigma_1"] = s1;
        d["dry_torque"] = dry; d["friction_torque"] = fr; d["slip"] = slip; d["substeps"] = sub;
        d["projected"] = proj; d["status"] = status;
        return d;
      }, "f_n"_a, "c_tilde"_a, "tau_e"_a, "dt"_a, "Runs step() over 1-D arrays in C++; returns a dict of arrays.");

  nb::class_<ObserverSettings>(m, "ObserverSettings")
      .def(nb::init<>())
      .def_rw("dt", &ObserverSettings::dt)
      .def_rw("integrator", &ObserverSettings::integrator)
      .def_rw("gain_mode", &ObserverSettings::gain_mode)
      .def_rw("gain", &ObserverSettings::gain)
      .def_rw("bandwidth", &ObserverSettings::bandwidth)
      .def_rw("gain_min", &ObserverSettings::gain_min)
      .def_rw("gain_max", &ObserverSettings::gain_max)
      .def_rw("g_floor", &ObserverSettings::g_floor)
      .def_rw("torque_cutoff", &ObserverSettings::torque_cutoff)
      .def_rw("filter_force", &ObserverSettings::filter_force)
      .def_rw("cor_sign_sigmas", &ObserverSettings::cor_sign_sigmas)
      .def_rw("max_invalid", &ObserverSettings::max_invalid)
      .def_rw("max_dt_gap", &ObserverSettings::max_dt_gap)
      .def_rw("torque_noise", &ObserverSettings::torque_noise)
      .def_rw("resolution_max", &ObserverSettings::resolution_max)
      .def_rw("omega_limit", &ObserverSettings::omega_limit)
      .def_rw("substeps", &ObserverSettings::substeps)
      .def_rw("max_substeps", &ObserverSettings::max_substeps)
      .def_rw("cor", &ObserverSettings::cor);
  m.def("validate_observer_settings", [](const ObserverSettings& s) {
    std::string msg;
    validate(s, &msg);
    return msg;
  }, "Empty string when valid, else one line per bad field.");

  nb::class_<ObserverOutput>(m, "ObserverOutput")
      .def(nb::init<>())
      .def_ro("omega_hat", &ObserverOutput::omega_hat)
      .def_ro("z_hat", &ObserverOutput::z_hat)
      .def_ro("S", &ObserverOutput::S)
      .def_ro("c_tilde", &ObserverOutput::c_tilde)
      .def_ro("c", &ObserverOutput::c)
      .def_ro("g", &ObserverOutput::g)
      .def_ro("sigma_1", &ObserverOutput::sigma_1)
      .def_ro("y", &ObserverOutput::y)
      .def_ro("tau_cor", &ObserverOutput::tau_cor)
      .def_ro("ft_cor", &ObserverOutput::ft_cor)
      .def_ro("gain", &ObserverOutput::gain)
      .def_ro("omega_resolution", &ObserverOutput::omega_resolution)
      .def_ro("speed_observable", &ObserverOutput::speed_observable)
      .def_ro("inside", &ObserverOutput::inside)
      .def_ro("saturated", &ObserverOutput::saturated)
      .def_ro("projected", &ObserverOutput::projected)
      .def_ro("diverged", &ObserverOutput::diverged)
      .def_ro("substeps_capped", &ObserverOutput::substeps_capped)
      .def_ro("substeps", &ObserverOutput::substeps)
      .def_ro("cor_iterations", &ObserverOutput::cor_iterations)
      .def_ro("status", &ObserverOutput::status)
      .def_ro("c_tilde_unclipped", &ObserverOutput::c_tilde_unclipped)
      .def_ro("omega_object", &ObserverOutput::omega_object)
      .def_ro("v_slip", &ObserverOutput::v_slip);

  nb::class_<Observer>(m, "Observer")
      .def(nb::init<const ContactParams&, const ObserverSettings&>(), "params"_a, "settings"_a = ObserverSettings())
      .def(nb::init<const ContactModel&, const ObserverSettings&>(), "model"_a, "settings"_a = ObserverSettings())
      .def("reset", &Observer::reset)
      .def_prop_ro("omega_hat", &Observer::omega_hat)
      .def_prop_ro("z_hat", &Observer::z_hat)
      .def("step", [](Observer& o, double f_n, double f_t, double tau, double dt) {
        ObserverOutput out;
        o.step(ObserverInput{f_n, f_t, tau, dt}, out);
        return out;
      }, "f_n"_a, "f_t"_a, "tau"_a, "dt"_a = 0.0, "One sample (dt = 0: nominal settings.dt).")
      .def("run", [](Observer& o, const In1& fn, const In1& ft, const In1& tau, const In1& dt) {
        same_size(fn, ft);
        same_size(fn, tau);
        same_size(fn, dt);
        const size_t n = fn.shape(0);
        auto w = new_array<double>(n), z = new_array<double>(n), S = new_array<double>(n),
             ct = new_array<double>(n), c = new_array<double>(n), g = new_array<double>(n),
             s1 = new_array<double>(n), y = new_array<double>(n), tc = new_array<double>(n),
             fc = new_array<double>(n), gain = new_array<double>(n), res = new_array<double>(n);
        auto obs = new_array<bool>(n), inside = new_array<bool>(n), sat = new_array<bool>(n),
             proj = new_array<bool>(n), div = new_array<bool>(n), cap = new_array<bool>(n);
        auto sub = new_array<int32_t>(n), iters = new_array<int32_t>(n), status = new_array<int32_t>(n);
        auto cu = new_array<double>(n), wo = new_array<double>(n), vs = new_array<double>(n);
        const double *pf = fn.data(), *pt = ft.data(), *pq = tau.data(), *pd = dt.data();
        {
          nb::gil_scoped_release release;
          ObserverOutput r;
          for (size_t i = 0; i < n; ++i) {
            o.step(ObserverInput{pf[i], pt[i], pq[i], pd[i]}, r);
            w.data()[i] = r.omega_hat; z.data()[i] = r.z_hat; S.data()[i] = r.S;
            ct.data()[i] = r.c_tilde; c.data()[i] = r.c; g.data()[i] = r.g; s1.data()[i] = r.sigma_1;
            y.data()[i] = r.y; tc.data()[i] = r.tau_cor; fc.data()[i] = r.ft_cor; gain.data()[i] = r.gain;
            res.data()[i] = r.omega_resolution; obs.data()[i] = r.speed_observable;
            inside.data()[i] = r.inside; sat.data()[i] = r.saturated; proj.data()[i] = r.projected;
            div.data()[i] = r.diverged; cap.data()[i] = r.substeps_capped; sub.data()[i] = r.substeps;
            iters.data()[i] = r.cor_iterations; status.data()[i] = static_cast<int32_t>(r.status);
            cu.data()[i] = r.c_tilde_unclipped; wo.data()[i] = r.omega_object; vs.data()[i] = r.v_slip;
          }
        }
        nb::dict d;
        d["omega_hat"] = w; d["z_hat"] = z; d["S"] = S; d["c_tilde"] = ct; d["c"] = c; d["g"] = g;
        d["sigma_1"] = s1; d["y"] = y; d["tau_cor"] = tc; d["ft_cor"] = fc; d["gain"] = gain; d["omega_resolution"] = res;
        d["speed_observable"] = obs; d["inside"] = inside; d["saturated"] = sat; d["projected"] = proj;
        d["diverged"] = div; d["substeps_capped"] = cap; d["substeps"] = sub; d["cor_iterations"] = iters;
        d["status"] = status;
        d["c_tilde_unclipped"] = cu; d["omega_object"] = wo; d["v_slip"] = vs;
        return d;
      }, "f_n"_a, "f_t"_a, "tau"_a, "dt"_a, "Runs step() over 1-D arrays in C++ (dt 0: nominal); returns a dict of arrays.");
  // ===== end of observer block =============================================================

  // --- closed loop ---------------------------------------------------------------------------
  // Closed-loop simulation (include/lugrip/closed_loop.hpp): config, and a batch run() that
  // loops in C++ (GIL released) and hands the columns over to numpy without copying.
  {
    nb::enum_<ControllerKind>(m, "ControllerKind", "Law computing the grasp-force command.")
        .value("Lugrip", ControllerKind::Lugrip)
        .value("ConstantForce", ControllerKind::ConstantForce)
        .value("FrictionCone", ControllerKind::FrictionCone);
    nb::enum_<ModeAction>(m, "ModeAction", "Scheduled controller action.")
        .value("Pivot", ModeAction::Pivot)
        .value("SlippingAvoidance", ModeAction::SlippingAvoidance)
        .value("DynamicOn", ModeAction::DynamicOn)
        .value("DynamicOff", ModeAction::DynamicOff);
    nb::class_<ModeEvent>(m, "ModeEvent")
        .def(nb::init<>())
        .def_rw("time", &ModeEvent::time)
        .def_rw("action", &ModeEvent::action);
    nb::class_<ClosedLoopConfig>(m, "ClosedLoopConfig")
        .def(nb::init<>())
        .def_rw("plant", &ClosedLoopConfig::plant)
        .def_rw("observer", &ClosedLoopConfig::observer)
        .def_rw("estimator", &ClosedLoopConfig::estimator)
        .def_rw("controller", &ClosedLoopConfig::controller)
        .def_rw("kind", &ClosedLoopConfig::kind)
        .def_rw("controller_start", &ClosedLoopConfig::controller_start)
        .def_rw("constant_force", &ClosedLoopConfig::constant_force)
        .def_rw("cone_margin", &ClosedLoopConfig::cone_margin)
        .def_rw("cone_release_rate", &ClosedLoopConfig::cone_release_rate)
        .def("clear_schedule", [](ClosedLoopConfig& c) { c.schedule.clear(); })
        .def("add_event", [](ClosedLoopConfig& c, double t, ModeAction a) { c.schedule.push_back(ModeEvent{t, a}); },
             "time"_a, "action"_a)
        .def_prop_ro("n_events", [](const ClosedLoopConfig& c) { return c.schedule.size(); });
    m.def("validate_closed_loop_config", [](const ClosedLoopConfig& c) {
      std::string msg;
      validate(c, &msg);
      return msg;
    }, "Empty string when valid, else one line per problem.");

    nb::class_<ClosedLoop>(m, "ClosedLoop")
        .def(nb::init<const ClosedLoopConfig&>(), "config"_a)
        .def("reset", &ClosedLoop::reset)
        .def_prop_ro("time", &ClosedLoop::time)
        .def_prop_ro("samples", &ClosedLoop::samples)
        .def_prop_ro("sample_period", &ClosedLoop::sample_period)
        .def_prop_ro("plant_state", [](const ClosedLoop& c) { return c.plant().state(); })
        .def_prop_ro("mode", [](const ClosedLoop& c) { return static_cast<int>(c.controller().mode()); })
        .def("run", [](ClosedLoop& c, int64_t samples) {
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
  // --- end of closed loop block --------------------------------------------------------------

  // --- identification ------------------------------------------------------------------------
  {
    using I64 = nb::ndarray<const int64_t, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
    nb::enum_<IdLoss>(m, "IdLoss", "Loss of the identification residuals.")
        .value("Squared", IdLoss::Squared)
        .value("Huber", IdLoss::Huber);
    nb::class_<IdentificationSettings>(m, "IdentificationSettings")
        .def(nb::init<>())
        .def_rw("observer", &IdentificationSettings::observer)
        .def_rw("loss", &IdentificationSettings::loss)
        .def_rw("huber_scale", &IdentificationSettings::huber_scale)
        .def_rw("threads", &IdentificationSettings::threads)
        .def_rw("sensitivity_limit", &IdentificationSettings::sensitivity_limit);
    m.def("validate_identification_settings", [](const IdentificationSettings& s) {
      std::string msg;
      validate(s, &msg);
      return msg;
    }, "Empty string when valid, else one line per bad field.");
    nb::class_<IdentificationProblem>(m, "IdentificationProblem")
        .def("__init__", [](IdentificationProblem* self, const In1& fn, const In1& ft, const In1& tau,
                            const In1& dt, const In1& omega, const In1& weight, const I64& starts,
                            const IdentificationSettings& s) {
          auto vec = [](const In1& a) { return std::vector<double>(a.data(), a.data() + a.shape(0)); };
          IdentificationData d;
          d.f_n = vec(fn);
          d.f_t = vec(ft);
          d.tau = vec(tau);
          d.dt = vec(dt);
          d.omega = vec(omega);
          d.weight = vec(weight);
          d.segment_start.assign(starts.data(), starts.data() + starts.shape(0));
          new (self) IdentificationProblem(std::move(d), s);
        }, "f_n"_a, "f_t"_a, "tau"_a, "dt"_a, "omega"_a, "weight"_a, "segment_start"_a, "settings"_a)
        .def_prop_ro("samples", &IdentificationProblem::samples)
        .def_prop_ro("segments", &IdentificationProblem::segments)
        .def("evaluate", [](const IdentificationProblem& prob, const ContactParams& p, bool derivatives,
                            bool want_omega_hat) {
          const size_t n = prob.samples(), m_seg = prob.segments();
          Out1<double> w_hat = new_array<double>(want_omega_hat ? n : 0);
          IdentificationEval ev;
          {
            nb::gil_scoped_release release;
            ev = prob.evaluate(p, derivatives, want_omega_hat ? w_hat.data() : nullptr);
          }
          auto grad = new_array<double>(kIdParams);
          std::copy(ev.gradient.begin(), ev.gradient.end(), grad.data());
          auto gn = new_array<double>(kIdParams * kIdParams);
          std::copy(ev.gauss_newton.begin(), ev.gauss_newton.end(), gn.data());
          auto sse = new_array<double>(m_seg), loss = new_array<double>(m_seg),
               wsum = new_array<double>(m_seg), sgrad = new_array<double>(m_seg * kIdParams);
          auto count = new_array<int64_t>(m_seg);
          for (size_t j = 0; j < m_seg; ++j) {
            const SegmentSums& s = ev.segments[j];
            sse.data()[j] = s.sse;
            loss.data()[j] = s.loss;
            wsum.data()[j] = s.weight;
            count.data()[j] = s.count;
            for (int k = 0; k < kIdParams; ++k) sgrad.data()[j * kIdParams + k] = s.gradient[k];
          }
          nb::dict d;
          d["cost"] = ev.cost;
          d["weight_sum"] = ev.weight_sum;
          d["scored"] = ev.scored;
          d["gradient"] = grad;
          d["gauss_newton"] = gn;
          d["segment_sse"] = sse;
          d["segment_loss"] = loss;
          d["segment_weight"] = wsum;
          d["segment_count"] = count;
          d["segment_gradient"] = sgrad;
          d["replica_error"] = ev.replica_error;
          d["reinitialized"] = ev.reinitialized;
          d["diverged"] = ev.diverged;
          d["truncated"] = ev.truncated;
          if (want_omega_hat) d["omega_hat"] = w_hat;
          return d;
        }, "params"_a, "derivatives"_a = true, "omega_hat"_a = false,
           "Cost (eq. 32 with weights and loss), gradient and Gauss-Newton matrix (6x6 row-major, "
           "natural parameter units), per-segment sums; omega_hat per sample on request.");
  }
  // --- end of identification block -----------------------------------------------------------
}
