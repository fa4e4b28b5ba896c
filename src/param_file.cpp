// Parameter-file loader on yaml-cpp.
#include "lugrip/param_file.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <type_traits>
#include <vector>

#include "lugrip/settings_fields.hpp"

#include "field_checks.hpp"

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

// Sets one field from a scalar, by the field's type (an enumeration by its values' names).
template <class S, class F>
void read_value(S& s, const F& f, const YAML::Node& v, const std::string& at) {
  using T = std::decay_t<decltype(s.*(f.member))>;
  if constexpr (std::is_same_v<T, bool>) {
    s.*(f.member) = boolean(v, at);
  } else if constexpr (std::is_enum_v<T>) {
    const std::string name = text(v, at);
    std::string names;
    for (int k = 0; k < f.n_choices; ++k) {
      if (name == f.choices[k]) {
        s.*(f.member) = static_cast<T>(k);
        return;
      }
      names += (k ? (k + 1 == f.n_choices ? " or " : ", ") : "") + std::string(f.choices[k]);
    }
    fail(at, "expected " + names);
  } else if constexpr (std::is_integral_v<T>) {
    s.*(f.member) = integer(v, at);
  } else {
    s.*(f.member) = number(v, at);
  }
}

// Sets the field named `key` (a nested struct's fields by their own names: the observer block's
// f_n_min is cor.f_n_min); false when the table has no such field.
template <class S>
bool read_key(S& s, const std::string& key, const YAML::Node& v, const std::string& at) {
  bool known = false;
  detail::for_each_entry(FieldTable<S>::fields, [&](const auto& f) {
    using T = std::decay_t<decltype(s.*(f.member))>;
    if (known) return;
    if constexpr (std::is_class_v<T>) {
      known = read_key(s.*(f.member), key, v, at);
    } else if (key == f.name) {
      known = true;
      read_value(s, f, v, at);
    }
  });
  return known;
}

// The table's fields a default-constructed struct leaves out of range: a file must give them.
template <class S>
std::vector<const char*> required_fields() {
  std::vector<const char*> out;
  const S s{};
  detail::for_each_entry(FieldTable<S>::fields, [&](const auto& f) {
    using T = std::decay_t<decltype(s.*(f.member))>;
    if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>)
      if (!detail::in_range(f, static_cast<double>(s.*(f.member)))) out.push_back(f.name);
  });
  return out;
}

std::string name_list(const std::vector<const char*>& names, const char* last) {
  std::string out;
  for (size_t k = 0; k < names.size(); ++k)
    out += (k ? (k + 1 == names.size() ? std::string(" ") + last + " " : ", ") : "") + std::string(names[k]);
  return out;
}

ContactParams read_contact(const YAML::Node& block, const std::string& where) {
  if (!block.IsMap()) fail(where, "expected a mapping of contact parameters");
  ContactParams p;
  const std::vector<const char*> required = required_fields<ContactParams>();
  size_t given = 0;
  for (const auto& kv : block) {
    const std::string key = kv.first.as<std::string>();
    if (key == "observer" || key == "controller") continue;  // flat layout: blocks of their own
    YAML::Node v = kv.second;
    const std::string at = where + "." + key;
    if (v.IsMap()) {
      if (!v["value"]) fail(at, "a mapping needs a value");
      v = v["value"];
    }
    if (!read_key(p, key, v, at)) {
      std::vector<const char*> names;
      detail::for_each_entry(FieldTable<ContactParams>::fields, [&](const auto& f) { names.push_back(f.name); });
      fail(at, "unknown parameter (expected " + name_list(names, "or") + ")");
    }
    for (const char* r : required) given += key == r;
  }
  if (given < required.size()) fail(where, "needs " + name_list(required, "and"));
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
    if (!read_key(s, key, v, at)) fail(at, "unknown observer setting");
    gain |= key == "gain";
    bandwidth |= key == "bandwidth";
    mode |= key == "gain_mode";
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
    if (!read_key(s, key, v, at)) fail(at, "unknown controller setting");
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
