// Status, contact parameters, limit surface, contact model and CoR estimator.
#include <nanobind/nanobind.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/tuple.h>

#include "common.hpp"
#include "tables.hpp"

namespace lugrip_bind {

using namespace nb::literals;

void bind_contact(nb::module_& m) {
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

  nb::class_<ContactParams> params(m, "ContactParams");
  params.def(nb::init<>());
  def_fields_rw(params);
  m.def("validate_params", &validation_message<ContactParams>, "Empty string when valid, else one line per bad field.");
  m.def("table1_params", &table1_params);
  m.def("object_params", &object_params, "name"_a);

  nb::class_<CorSettings> cor(m, "CorSettings");
  cor.def(nb::init<>());
  def_fields_rw(cor);
  m.def("validate_cor_settings", &validation_message<CorSettings>);

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

  nb::class_<CorOutput> cor_out(m, "CorOutput");
  cor_out.def(nb::init<>());
  def_fields_ro(cor_out);

  using Est = Guarded<CorEstimator>;
  nb::class_<Est>(m, "CorEstimator")
      .def(nb::init<const ContactParams&, const CorSettings&>(), "params"_a, "settings"_a = CorSettings())
      .def(nb::init<const ContactModel&, const CorSettings&>(), "model"_a, "settings"_a = CorSettings())
      .def("reset", [](Est& e) {
        e.guard.check("CorEstimator");
        e.reset();
      })
      .def("step", [](Est& e, double f_n, double f_t, double tau) {
        e.guard.check("CorEstimator");
        CorOutput out;
        e.step(CorInput{f_n, f_t, tau}, out);
        return out;
      }, "f_n"_a, "f_t"_a, "tau"_a)
      .def("run", [](Est& e, const In1& fn, const In1& ft, const In1& tau) {
        e.guard.check("CorEstimator");
        same_size(fn, ft);
        same_size(fn, tau);
        const size_t n = fn.shape(0);
        Columns<CorOutput> cols(n);
        const double *pf = fn.data(), *pt = ft.data(), *pq = tau.data();
        {
          nb::gil_scoped_release release;
          CorOutput o;
          for (size_t i = 0; i < n; ++i) {
            e.step(CorInput{pf[i], pt[i], pq[i]}, o);
            cols.set(i, o);
          }
        }
        nb::dict d;
        cols.into(d);
        return d;
      }, "f_n"_a, "f_t"_a, "tau"_a, "Runs step() over 1-D arrays in C++; returns a dict of arrays (CorOutput.fields).");
}

}  // namespace lugrip_bind
