// Planar-slider plant model and the sliding-velocity observer.
#include <nanobind/nanobind.h>
#include <nanobind/stl/string.h>

#include "common.hpp"
#include "tables.hpp"

namespace lugrip_bind {

using namespace nb::literals;

void bind_observer(nb::module_& m) {
  nb::enum_<Integrator>(m, "Integrator", "Discretisation of the LuGre rotor over one sample.")
      .value("Implicit", Integrator::Implicit)
      .value("Rk4", Integrator::Rk4)
      .value("Rk4Adaptive", Integrator::Rk4Adaptive)
      .value("Rosenbrock", Integrator::Rosenbrock);
  nb::enum_<GainMode>(m, "GainMode", "Observer gain: fixed l, or l = bandwidth / sigma_1.")
      .value("Fixed", GainMode::Fixed)
      .value("Bandwidth", GainMode::Bandwidth);

  nb::class_<SliderSettings> slider_settings(m, "SliderSettings");
  slider_settings.def(nb::init<>());
  def_fields_rw(slider_settings);
  m.def("validate_slider_settings", &validation_message<SliderSettings>,
        "Empty string when valid, else one line per bad field.");

  nb::class_<SliderOutput> slider_out(m, "SliderOutput");
  slider_out.def(nb::init<>());
  def_fields_ro(slider_out);

  using Slider = Guarded<SliderModel>;
  nb::class_<Slider>(m, "SliderModel")
      .def(nb::init<const ContactParams&, double, const SliderSettings&>(), "params"_a, "J"_a,
           "settings"_a = SliderSettings())
      .def(nb::init<const ContactModel&, double, const SliderSettings&>(), "model"_a, "J"_a,
           "settings"_a = SliderSettings())
      .def("reset", [](Slider& s, double z, double omega) {
        s.guard.check("SliderModel");
        s.reset(z, omega);
      }, "z"_a = 0.0, "omega"_a = 0.0)
      .def_prop_ro("z", [](const Slider& s) { return s.z(); })
      .def_prop_ro("omega", [](const Slider& s) { return s.omega(); })
      .def_prop_ro("J", [](const Slider& s) { return s.inertia(); })
      .def("step", [](Slider& s, double f_n, double c_tilde, double tau_e, double dt) {
        s.guard.check("SliderModel");
        SliderOutput out;
        s.step(SliderInput{f_n, c_tilde, tau_e, dt}, out);
        return out;
      }, "f_n"_a, "c_tilde"_a, "tau_e"_a, "dt"_a)
      .def("simulate", [](Slider& s, const In1& fn, const In1& ct, const In1& te, const In1& dt) {
        s.guard.check("SliderModel");
        same_size(fn, ct);
        same_size(fn, te);
        same_size(fn, dt);
        const size_t n = fn.shape(0);
        Columns<SliderOutput> cols(n);
        const double *pf = fn.data(), *pc = ct.data(), *pe = te.data(), *pd = dt.data();
        {
          nb::gil_scoped_release release;
          SliderOutput o;
          for (size_t i = 0; i < n; ++i) {
            s.step(SliderInput{pf[i], pc[i], pe[i], pd[i]}, o);
            cols.set(i, o);
          }
        }
        nb::dict d;
        cols.into(d);
        return d;
      }, "f_n"_a, "c_tilde"_a, "tau_e"_a, "dt"_a, "Runs step() over 1-D arrays in C++; returns a dict of arrays.");

  nb::class_<ObserverSettings> obs_settings(m, "ObserverSettings");
  obs_settings.def(nb::init<>());
  def_fields_rw(obs_settings);
  m.def("validate_observer_settings", &validation_message<ObserverSettings>,
        "Empty string when valid, else one line per bad field.");

  nb::class_<ObserverOutput> obs_out(m, "ObserverOutput");
  obs_out.def(nb::init<>());
  def_fields_ro(obs_out);

  using Obs = Guarded<Observer>;
  nb::class_<Obs>(m, "Observer")
      .def(nb::init<const ContactParams&, const ObserverSettings&>(), "params"_a, "settings"_a = ObserverSettings())
      .def(nb::init<const ContactModel&, const ObserverSettings&>(), "model"_a, "settings"_a = ObserverSettings())
      .def("reset", [](Obs& o) {
        o.guard.check("Observer");
        o.reset();
      })
      .def_prop_ro("omega_hat", [](const Obs& o) { return o.omega_hat(); })
      .def_prop_ro("omega_state", [](const Obs& o) { return o.omega_state(); })
      .def_prop_ro("z_hat", [](const Obs& o) { return o.z_hat(); })
      .def("step", [](Obs& o, double f_n, double f_t, double tau, double dt) {
        o.guard.check("Observer");
        ObserverOutput out;
        o.step(ObserverInput{f_n, f_t, tau, dt}, out);
        return out;
      }, "f_n"_a, "f_t"_a, "tau"_a, "dt"_a = 0.0, "One sample (dt = 0: nominal settings.dt).")
      .def("run", [](Obs& o, const In1& fn, const In1& ft, const In1& tau, const In1& dt) {
        o.guard.check("Observer");
        same_size(fn, ft);
        same_size(fn, tau);
        same_size(fn, dt);
        const size_t n = fn.shape(0);
        Columns<ObserverOutput> cols(n);
        const double *pf = fn.data(), *pt = ft.data(), *pq = tau.data(), *pd = dt.data();
        {
          nb::gil_scoped_release release;
          ObserverOutput r;
          for (size_t i = 0; i < n; ++i) {
            o.step(ObserverInput{pf[i], pt[i], pq[i], pd[i]}, r);
            cols.set(i, r);
          }
        }
        nb::dict d;
        cols.into(d);
        return d;
      }, "f_n"_a, "f_t"_a, "tau"_a, "dt"_a,
         "Runs step() over 1-D arrays in C++ (dt 0: nominal); returns a dict of arrays (ObserverOutput.fields).");
}

}  // namespace lugrip_bind
