// Parameter-file loader on yaml-cpp.
#include "lugrip/param_file.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <type_traits>

#include "lugrip/grasp_controller_fields.hpp"

namespace lugrip {

namespace {

constexpr std::streamoff kMaxFileBytes = 1 << 20;

[[noreturn]] void fail(const std::string& where, const std::string& what) {
  throw std::invalid_argument(where + ": " + what);
}

double number(const YAML::Node& n, const std::string& where) {
  if (!n.IsScalar()) fail(where, "expected a number");
  const std::string s = n.Scalar();
  if (s == ".inf" || s == "inf" || s == "Infinity" || s == ".Inf") return std::numeric_limits<double>::infinity();
  if (s == "true" || s == "false" || s == "True" || s == "False") fail(where, "expected a number, got " + s);
  try {
    return n.as<double>();
  } catch (const YAML::Exception&) {
    fail(where, "expected a number");
  }
}

int integer(const YAML::Node& n, const std::string& where) {
  const double v = number(n, where);
  if (!(std::fabs(v) <= 2.0e9) || std::floor(v) != v) fail(where, "expected an integer");
  return static_cast<int>(v);
}

bool boolean(const YAML::Node& n, const std::string& where) {
  if (!n.IsScalar()) fail(where, "expected true or false");
  try {
    return n.as<bool>();
  } catch (const YAML::Exception&) {
    fail(where, "expected true or false");
  }
}

std::string text(const YAML::Node& n, const std::string& where) {
  if (!n.IsScalar()) fail(where, "expected a name");
  return n.Scalar();
}

// validate() on a read block; throws with its first bad field.
template <class T>
void validated(const T& value, const std::string& where) {
  std::string msg;
  if (!validate(value, &msg)) {
    std::istringstream lines(msg);
    std::string first;
    std::getline(lines, first);
    fail(where, first);
  }
}

ContactParams read_contact(const YAML::Node& block, const std::string& where) {
  if (!block.IsMap()) fail(where, "expected a mapping of contact parameters");
  ContactParams p;
  int required = 0;
  for (const auto& kv : block) {
    const std::string key = kv.first.as<std::string>();
    if (key == "observer" || key == "controller") continue;  // flat layout: blocks of their own
    YAML::Node v = kv.second;
    const std::string at = where + "." + key;
    if (v.IsMap()) {
      if (!v["value"]) fail(at, "a mapping needs a value");
      v = v["value"];
    }
    double* field = nullptr;
    if (key == "mu") field = &p.mu;
    else if (key == "beta_a") field = &p.beta_a;
    else if (key == "sigma0") field = &p.sigma0;
    else if (key == "sigma_z") field = &p.sigma_z;
    else if (key == "delta") field = &p.delta;
    else if (key == "gamma") field = &p.gamma;
    else if (key == "k") field = &p.k;
    else if (key == "c_max") field = &p.c_max;
    else if (key == "static_ratio") field = &p.static_ratio;
    else if (key == "kinetic_ratio") field = &p.kinetic_ratio;
    else fail(at, "unknown parameter (expected mu, beta_a, sigma0, sigma_z, delta, gamma, k, c_max, static_ratio, kinetic_ratio)");
    *field = number(v, at);
    if (key != "k" && key != "c_max" && key != "static_ratio" && key != "kinetic_ratio") ++required;
  }
  if (required < 6) fail(where, "needs mu, beta_a, sigma0, sigma_z, delta and gamma");
  validated(p, where);
  return p;
}

ObserverSettings read_observer(const YAML::Node& block, const std::string& where) {
  if (!block.IsMap()) fail(where, "expected a mapping of observer settings");
  ObserverSettings s;
  bool gain = false, bandwidth = false, mode = false;
  for (const auto& kv : block) {
    const std::string key = kv.first.as<std::string>();
    const YAML::Node& v = kv.second;
    const std::string at = where + "." + key;
    if (v.IsNull()) continue;  // "not given"
    if (key == "dt") s.dt = number(v, at);
    else if (key == "integrator") {
      const std::string name = text(v, at);
      if (name == "implicit") s.integrator = Integrator::Implicit;
      else if (name == "rk4") s.integrator = Integrator::Rk4;
      else if (name == "rk4_adaptive") s.integrator = Integrator::Rk4Adaptive;
      else if (name == "rosenbrock") s.integrator = Integrator::Rosenbrock;
      else fail(at, "expected implicit, rk4, rk4_adaptive or rosenbrock");
    } else if (key == "gain_mode") {
      const std::string name = text(v, at);
      if (name == "fixed") s.gain_mode = GainMode::Fixed;
      else if (name == "bandwidth") s.gain_mode = GainMode::Bandwidth;
      else fail(at, "expected fixed or bandwidth");
      mode = true;
    } else if (key == "gain") { s.gain = number(v, at); gain = true; }
    else if (key == "bandwidth") { s.bandwidth = number(v, at); bandwidth = true; }
    else if (key == "gain_min") s.gain_min = number(v, at);
    else if (key == "gain_max") s.gain_max = number(v, at);
    else if (key == "g_floor") s.g_floor = number(v, at);
    else if (key == "torque_cutoff") s.torque_cutoff = number(v, at);
    else if (key == "filter_force") s.filter_force = boolean(v, at);
    else if (key == "cor_sign_sigmas") s.cor_sign_sigmas = number(v, at);
    else if (key == "max_invalid") s.max_invalid = integer(v, at);
    else if (key == "max_dt_gap") s.max_dt_gap = number(v, at);
    else if (key == "torque_noise") s.torque_noise = number(v, at);
    else if (key == "resolution_max") s.resolution_max = number(v, at);
    else if (key == "omega_limit") s.omega_limit = number(v, at);
    else if (key == "substeps") s.substeps = integer(v, at);
    else if (key == "max_substeps") s.max_substeps = integer(v, at);
    else if (key == "f_n_min") s.cor.f_n_min = number(v, at);
    else if (key == "force_limit") s.cor.force_limit = number(v, at);
    else if (key == "torque_limit") s.cor.torque_limit = number(v, at);
    else if (key == "zero_force") s.cor.zero_force = number(v, at);
    else if (key == "zero_torque") s.cor.zero_torque = number(v, at);
    else fail(at, "unknown observer setting");
  }
  // The Python Observer's rule: a gain alone means a fixed gain.
  if (!mode) s.gain_mode = gain && !bandwidth ? GainMode::Fixed : GainMode::Bandwidth;
  validated(s, where);
  return s;
}

GraspControllerSettings read_controller(const YAML::Node& block, const std::string& where) {
  if (!block.IsMap()) fail(where, "expected a mapping of controller settings");
  GraspControllerSettings s;
  for (const auto& kv : block) {
    const std::string key = kv.first.as<std::string>();
    const YAML::Node& v = kv.second;
    const std::string at = where + "." + key;
    if (v.IsNull()) continue;  // "not given"
    bool known = false;
    detail::for_each_entry(grasp_controller_fields, [&](const auto& f) {
      if (known || key != f.name) return;
      known = true;
      using T = std::decay_t<decltype(s.*(f.member))>;
      if constexpr (std::is_same_v<T, bool>) s.*(f.member) = boolean(v, at);
      else if constexpr (std::is_integral_v<T>) s.*(f.member) = integer(v, at);
      else s.*(f.member) = number(v, at);
    });
    if (!known) fail(at, "unknown controller setting");
  }
  validated(s, where);
  return s;
}

}  // namespace

ParameterFile parse_parameter_file(const std::string& yaml_text, const std::string& name) {
  if (yaml_text.size() > static_cast<size_t>(kMaxFileBytes)) fail(name, "larger than 1 MiB");
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    fail(name, std::string("not valid YAML: ") + e.what());
  }
  if (!root.IsMap()) fail(name, "expected a mapping of parameters");
  ParameterFile file;
  try {
    if (root["contact"]) file.params = read_contact(root["contact"], "contact");
    else file.params = read_contact(root, "parameters");
    const YAML::Node obs = root["observer"];
    if (obs && !obs.IsNull()) {
      file.observer = read_observer(obs, "observer");
      file.has_observer = true;
    }
    const YAML::Node ctl = root["controller"];
    if (ctl && !ctl.IsNull()) {
      file.controller = read_controller(ctl, "controller");
      file.has_controller = true;
    }
  } catch (const std::invalid_argument& e) {
    fail(name, e.what());
  } catch (const YAML::Exception& e) {
    fail(name, std::string("unreadable field: ") + e.what());
  }
  return file;
}

ParameterFile load_parameter_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, "cannot be opened");
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  if (size > kMaxFileBytes) fail(path, "larger than 1 MiB");
  in.seekg(0);
  std::string content(static_cast<size_t>(size > 0 ? size : 0), '\0');
  in.read(content.data(), static_cast<std::streamsize>(content.size()));
  return parse_parameter_file(content, path);
}

SlipControlSettings slip_control_settings(const ParameterFile& file) {
  return slip_control_settings(file, file.controller);
}

SlipControlSettings slip_control_settings(const ParameterFile& file, const GraspControllerSettings& controller) {
  SlipControlSettings s;
  if (file.has_observer) s.observer = file.observer;
  s.controller = controller;
  return s;
}

}  // namespace lugrip
