// Grasp simulator: configuration structs, the patch contact and the grasp plant with a batch
// run() that loops in C++ (GIL released).
#include <nanobind/nanobind.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/tuple.h>
#include <nanobind/stl/vector.h>

#include <stdexcept>
#include <vector>

#include "common.hpp"
#include "tables.hpp"

namespace lugrip_bind {

using namespace nb::literals;

void bind_plant(nb::module_& m) {
  nb::enum_<PlantModel>(m, "PlantModel", "Contact model of the grasp plant.")
      .value("Patch", PlantModel::Patch)
      .value("Lumped", PlantModel::Lumped);
  nb::enum_<PulseShape>(m, "PulseShape", "Time profile of a disturbance pulse.")
      .value("Rectangular", PulseShape::Rectangular)
      .value("HalfSine", PulseShape::HalfSine)
      .value("Ramp", PulseShape::Ramp)
      .value("Triangle", PulseShape::Triangle);

  nb::class_<ObjectConfig> object(m, "ObjectConfig");
  object.def(nb::init<>());
  def_fields_rw(object);
  nb::class_<GripperMove> move(m, "GripperMove");
  move.def(nb::init<>());
  def_fields_rw(move);
  nb::class_<Disturbance> disturbance(m, "Disturbance");
  disturbance.def(nb::init<>());
  def_fields_rw(disturbance);
  nb::class_<ActuatorConfig> actuator(m, "ActuatorConfig");
  actuator.def(nb::init<>());
  def_fields_rw(actuator);
  nb::class_<SensorConfig> sensor(m, "SensorConfig");
  sensor.def(nb::init<>())
      .def("get_bias", [](const SensorConfig& s, int finger, int channel) {
        if (finger < 0 || finger > 1 || channel < 0 || channel > 3) throw std::out_of_range("finger 0..1, channel 0..3");
        return s.bias[finger][channel];
      }, "finger"_a, "channel"_a)
      .def("set_bias", [](SensorConfig& s, int finger, int channel, double v) {
        if (finger < 0 || finger > 1 || channel < 0 || channel > 3) throw std::out_of_range("finger 0..1, channel 0..3");
        s.bias[finger][channel] = v;
      }, "finger"_a, "channel"_a, "value"_a, "Bias of (f_n, f_x, f_y, tau)[channel] of a finger.");
  def_fields_rw(sensor);
  nb::class_<PatchSettings> patch(m, "PatchSettings");
  patch.def(nb::init<>());
  def_fields_rw(patch);
  nb::class_<DropConfig> drop(m, "DropConfig");
  drop.def(nb::init<>());
  def_fields_rw(drop);
  nb::class_<PlantConfig> config(m, "PlantConfig");
  config.def(nb::init<>())
      .def("clear_moves", [](PlantConfig& c) { c.moves.clear(); })
      .def("add_move", [](PlantConfig& c, const GripperMove& v) { c.moves.push_back(v); })
      .def("clear_disturbances", [](PlantConfig& c) { c.disturbances.clear(); })
      .def("add_disturbance", [](PlantConfig& c, const Disturbance& v) { c.disturbances.push_back(v); })
      .def_prop_ro("n_moves", [](const PlantConfig& c) { return c.moves.size(); })
      .def_prop_ro("n_disturbances", [](const PlantConfig& c) { return c.disturbances.size(); });
  def_fields_rw(config);
  m.def("validate_plant_config", &validation_message<PlantConfig>, "Empty string when valid, else one line per bad field.");

  nb::class_<FingerSample> sample(m, "FingerSample");
  sample.def(nb::init<>());
  def_fields_ro(sample);
  nb::class_<PlantState> state(m, "PlantState");
  state.def(nb::init<>());
  def_fields_ro(state);

  using Patch = Guarded<PatchContact>;
  using Plant = Guarded<GraspPlant>;
  {
    nb::class_<Patch>(m, "PatchContact")
        .def(nb::init<const ContactParams&, const PatchSettings&>(), "params"_a, "settings"_a = PatchSettings())
        .def_prop_ro("cells", [](const Patch& p) { return p.cells(); })
        .def_prop_ro("rho", [](const Patch& p) { return p.rho(); })
        .def_prop_ro("moment2", [](const Patch& p) { return p.moment2(); })
        .def_prop_ro("bristle_energy", [](const Patch& p) { return p.bristle_energy(); })
        .def("reset", [](Patch& p) {
          p.guard.check("PatchContact");
          p.reset();
        })
        .def("advance", [](Patch& pc, double f_n, double vx, double vy, double omega, double h, int steps) {
          pc.guard.check("PatchContact");
          PadWrench w;
          for (int i = 0; i < steps; ++i) pc.advance(f_n, vx, vy, omega, h, w);
          return nb::make_tuple(w.fx, w.fy, w.tau);
        }, "f_n"_a, "vx"_a, "vy"_a, "omega"_a, "h"_a, "steps"_a = 1,
           "Prescribed kinematics for `steps` steps of h; wrench of the pad on the object (fx, fy, tau).");

    nb::class_<Plant>(m, "GraspPlant")
        .def(nb::init<const PlantConfig&>(), "config"_a)
        .def("reset", [](Plant& p) {
          p.guard.check("GraspPlant");
          p.reset();
        })
        .def("set_command", [](Plant& p, double f) {
          p.guard.check("GraspPlant");
          p.set_command(f);
        }, "f_cmd"_a)
        .def("set_external", [](Plant& p, double fx, double fy, double torque) {
          p.guard.check("GraspPlant");
          p.set_external(fx, fy, torque);
        }, "fx"_a, "fy"_a, "torque"_a)
        .def("step", [](Plant& p) {
          p.guard.check("GraspPlant");
          return p.step();
        })
        .def("advance_sample", [](Plant& p) {
          p.guard.check("GraspPlant");
          return p.advance_sample();
        })
        .def("sensor_sample", [](const Plant& p, int finger) {
          if (finger < 0 || finger > 1) throw std::out_of_range("finger must be 0 or 1");
          return p.sensor_sample(finger);
        }, "finger"_a)
        .def_prop_ro("state", [](const Plant& p) { return p.state(); })
        .def_prop_ro("config", [](const Plant& p) { return p.config(); })
        .def_prop_ro("time", [](const Plant& p) { return p.time(); })
        .def_prop_ro("dt", [](const Plant& p) { return p.dt(); })
        .def_prop_ro("steps_per_sample", [](const Plant& p) { return p.steps_per_sample(); })
        .def_prop_ro("steps_per_command", [](const Plant& p) { return p.steps_per_command(); })
        .def_prop_ro("cells", [](const Plant& p) { return p.cells(); })
        .def_prop_ro("energy", [](const Plant& p) { return p.energy(); })
        .def("gripper_at", [](const Plant& p, double t) {
          double x, y, vx, vy;
          p.gripper_at(t, x, y, vx, vy);
          return nb::make_tuple(x, y, vx, vy);
        }, "t"_a)
        .def("disturbance_at", [](const Plant& p, double t, double theta) {
          double fx, fy, tz;
          p.disturbance_at(t, theta, fx, fy, tz);
          return nb::make_tuple(fx, fy, tz);
        }, "t"_a, "theta"_a)
        .def("run", [](Plant& p, const In1& command) {
          p.guard.check("GraspPlant");
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
}

}  // namespace lugrip_bind
