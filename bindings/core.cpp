// The only nanobind file: builds lugrip._core. Thin: structs and step() as they are, plus batch
// loops over 1-D contiguous float64 arrays (shape handling lives in the Python layer).
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
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
      .def_ro("status", &CorOutput::status);

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
          }
        }
        nb::dict d;
        d["c_tilde"] = c_tilde; d["c"] = c; d["ft_tilde"] = ft_t; d["tau_tilde"] = tau_t;
        d["sigma"] = sigma; d["rho"] = rho; d["g"] = g; d["sigma_1"] = s1; d["y"] = y;
        d["inside"] = inside; d["saturated"] = sat; d["iterations"] = iters; d["status"] = status;
        return d;
      }, "f_n"_a, "f_t"_a, "tau"_a, "Runs step() over 1-D arrays in C++; returns a dict of arrays.");
}
