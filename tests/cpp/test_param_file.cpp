// lugrip::yaml: the parameter-file loader reads what the Python side writes (objects/*.yaml from
// `lugrip params`, an identification result with its observer block) and names bad fields.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <stdexcept>
#include <string>

#include <sstream>
#include <type_traits>

#include "lugrip/grasp_controller_fields.hpp"
#include "lugrip/param_file.hpp"
#include "lugrip/settings_fields.hpp"

using namespace lugrip;

namespace {

std::string error_of(const std::string& yaml) {
  try {
    parse_parameter_file(yaml, "f.yaml");
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

// The layout of IdentificationResult.save_yaml: values with units, standard errors, bounds, the
// observer block, a fit summary.
const char* kIdentified = R"(# lugrip identification
contact:
  mu: {value: 0.61, unit: '-', stderr: 0.01, bounds: [0.05, 3.0]}
  beta_a: {value: 21210000.0, unit: N s/m^3}
  sigma0: {value: 12.5, unit: N m/rad}
  sigma_z: {value: 1.5, unit: N m s/rad}
  delta: {value: 0.0018, unit: m/N^gamma}
  gamma: {value: 0.254, unit: '-'}
  k: {value: .inf, unit: '-'}
  c_max: {value: 1.5, unit: '-'}
observer:
  dt: 0.002
  integrator: rk4
  bandwidth: 800.0
  torque_noise: 2.0e-5
  f_n_min: 0.05
  max_invalid: 4
fit:
  cost: 0.01
  samples: 4000
)";

}  // namespace

TEST(ParamFile, ReadsEveryShippedObjectLikeThePresets) {
  const char* names[] = {"aluminium_can", "big_resin_block", "plastic_bottle", "small_resin_block"};
  for (const char* name : names) {
    const ParameterFile f = load_parameter_file(std::string(LUGRIP_SOURCE_DIR) + "/objects/" + name + ".yaml");
    const ContactParams p = object_params(name);
    EXPECT_EQ(f.params.mu, p.mu) << name;
    EXPECT_EQ(f.params.beta_a, p.beta_a) << name;
    EXPECT_EQ(f.params.sigma0, p.sigma0) << name;
    EXPECT_EQ(f.params.delta, p.delta) << name;
    EXPECT_EQ(f.params.gamma, p.gamma) << name;
    EXPECT_FALSE(f.has_observer) << name;
  }
}

TEST(ParamFile, ReadsAnIdentificationResultWithItsObserver) {
  const ParameterFile f = parse_parameter_file(kIdentified);
  EXPECT_EQ(f.params.mu, 0.61);
  EXPECT_TRUE(std::isinf(f.params.k));
  ASSERT_TRUE(f.has_observer);
  EXPECT_EQ(f.observer.integrator, Integrator::Rk4);
  EXPECT_EQ(f.observer.gain_mode, GainMode::Bandwidth);
  EXPECT_EQ(f.observer.bandwidth, 800.0);
  EXPECT_EQ(f.observer.torque_noise, 2.0e-5);
  EXPECT_EQ(f.observer.cor.f_n_min, 0.05);
  EXPECT_EQ(f.observer.max_invalid, 4);
  EXPECT_EQ(f.observer.gain, ObserverSettings().gain);  // not given: the default
  // straight into SlipControl
  SlipControl sc(f.params, slip_control_settings(f));
  EXPECT_EQ(sc.observer(0).settings().bandwidth, 800.0);
  EXPECT_EQ(sc.params().mu, 0.61);
}

TEST(ParamFile, AGainAloneMeansAFixedGain) {
  const ParameterFile f = parse_parameter_file(
      "mu: 0.5\nbeta_a: 1e7\nsigma0: 16\nsigma_z: 2\ndelta: 0.0018\ngamma: 0.25\nobserver: {gain: 300}\n");
  EXPECT_EQ(f.observer.gain_mode, GainMode::Fixed);
  EXPECT_EQ(f.observer.gain, 300.0);
}

TEST(ParamFile, BadFieldsAreNamed) {
  const std::string base = "contact: {mu: 0.5, beta_a: 1e7, sigma0: 16, sigma_z: 2, delta: 0.0018, gamma: 0.25}\n";
  EXPECT_NE(error_of("contact: {mu: -1, beta_a: 1e7, sigma0: 16, sigma_z: 2, delta: 0.0018, gamma: 0.25}").find("f.yaml: contact: mu = -1"), std::string::npos);
  EXPECT_NE(error_of("contact: {mu: true, beta_a: 1e7, sigma0: 16, sigma_z: 2, delta: 0.0018, gamma: 0.25}").find("contact.mu: expected a number"), std::string::npos);
  EXPECT_NE(error_of("contact: {mu: 0.5}").find("needs mu, beta_a"), std::string::npos);
  EXPECT_NE(error_of("contact: 5").find("expected a mapping of contact parameters"), std::string::npos);
  EXPECT_NE(error_of(base + "observer: {gain: -1}").find("observer: gain = -1"), std::string::npos);
  EXPECT_NE(error_of(base + "observer: {integrater: rk4}").find("observer.integrater: unknown observer setting"), std::string::npos);
  EXPECT_NE(error_of(base + "observer: {max_invalid: 2.5}").find("observer.max_invalid: expected an integer"), std::string::npos);
  EXPECT_NE(error_of(base + "observer: {integrator: euler}").find("observer.integrator"), std::string::npos);
  EXPECT_NE(error_of("[1, 2").find("not valid YAML"), std::string::npos);
  EXPECT_NE(error_of("- 1\n- 2\n").find("expected a mapping"), std::string::npos);
  EXPECT_NE(error_of(std::string(2 << 20, ' ')).find("larger than 1 MiB"), std::string::npos);
  EXPECT_THROW(load_parameter_file("/nonexistent/file.yaml"), std::invalid_argument);
}

TEST(ParamFile, ReadsTheFrictionRatiosAndDefaultsThemToOne) {
  const std::string base = "contact: {mu: 0.5, beta_a: 1e7, sigma0: 16, sigma_z: 2, delta: 0.0018, gamma: 0.25";
  const ParameterFile plain = parse_parameter_file(base + "}\n", "f.yaml");
  EXPECT_EQ(plain.params.static_ratio, 1.0);
  EXPECT_EQ(plain.params.kinetic_ratio, 1.0);
  const ParameterFile stribeck = parse_parameter_file(
      base + ", static_ratio: {value: 1.09, unit: '-'}, kinetic_ratio: 0.9}\n", "f.yaml");
  EXPECT_EQ(stribeck.params.static_ratio, 1.09);
  EXPECT_EQ(stribeck.params.kinetic_ratio, 0.9);
  EXPECT_NE(error_of(base + ", static_ratio: 0.8, kinetic_ratio: 0.9}\n").find("static_ratio = 0.8"),
            std::string::npos);
  EXPECT_NE(error_of(base + ", kinetic_ratio: 4}\n").find("kinetic_ratio = 4"), std::string::npos);
}

// --- the controller block (GraspControllerSettings by name, from the core's field table) -----

TEST(ParamFile, AnIdentificationResultWithAControllerBlockMakesTheSlipControl) {
  // the identify file above with the robot's controller settings added to it
  const std::string text = std::string(kIdentified) +
                           "controller: {f_max: 15.0, max_rate: 100.0, command_ratio: 5, "
                           "load_floors: false, reserve_force: 0.5, s_ref: 0.7}\n";
  const ParameterFile f = parse_parameter_file(text);
  ASSERT_TRUE(f.has_controller);
  EXPECT_EQ(f.controller.f_max, 15.0);
  EXPECT_EQ(f.controller.command_ratio, 5);
  EXPECT_FALSE(f.controller.load_floors);
  EXPECT_EQ(f.controller.k_p, GraspControllerSettings().k_p);  // not given: the default
  SlipControl sc(f.params, slip_control_settings(f));
  EXPECT_EQ(sc.settings().controller.f_max, 15.0);
  EXPECT_EQ(sc.settings().controller.reserve_force, 0.5);
  EXPECT_EQ(sc.controller().settings().s_ref, 0.7);
  EXPECT_EQ(sc.observer(0).settings().bandwidth, 800.0);  // and the observer block as before
  // an explicit controller replaces the file's
  EXPECT_EQ(slip_control_settings(f, GraspControllerSettings()).controller.f_max, 20.0);
  // no block: the defaults
  EXPECT_FALSE(parse_parameter_file(kIdentified).has_controller);
}

namespace {
// Sets the field of `s` to a value other than its default that validate() accepts (an
// enumeration's next value, a switch flipped, a number moved by 10 % or to 0.5 from 0) and
// returns it as the file spells it.
template <class S, class Whole, class F>
std::string change(S& s, const F& f, const Whole& whole, bool (*valid)(const Whole&)) {
  using T = std::decay_t<decltype(s.*(f.member))>;
  std::ostringstream value;
  value.precision(17);
  if constexpr (std::is_same_v<T, bool>) {
    s.*(f.member) = !(s.*(f.member));
    value << (s.*(f.member) ? "true" : "false");
  } else if constexpr (std::is_enum_v<T>) {
    const int next = (static_cast<int>(s.*(f.member)) + 1) % f.n_choices;
    s.*(f.member) = static_cast<T>(next);
    value << f.choices[next];
  } else if constexpr (std::is_integral_v<T>) {
    s.*(f.member) = s.*(f.member) + 1;
    value << s.*(f.member);
  } else {
    const double d = s.*(f.member);
    s.*(f.member) = d == 0.0 ? 0.5 : 1.1 * d;
    if (!valid(whole)) s.*(f.member) = d == 0.0 ? 0.01 : 0.9 * d;
    value << s.*(f.member);
  }
  return value.str();
}
bool valid_observer(const ObserverSettings& s) { return validate(s, nullptr); }
bool valid_controller(const GraspControllerSettings& s) { return validate(s, nullptr); }
}  // namespace

TEST(ParamFile, EveryControllerFieldOfTheTableIsRead) {
  // Each field of grasp_controller_fields, alone in a controller block with a value other than
  // its default (that validate() accepts), reads back into its own member and nowhere else.
  const std::string base = "contact: {mu: 0.5, beta_a: 1e7, sigma0: 16, sigma_z: 2, delta: 0.0018, gamma: 0.25}\n";
  int n = 0;
  detail::for_each_entry(grasp_controller_fields, [&](const auto& f) {
    ++n;
    GraspControllerSettings want;
    const std::string value = change(want, f, want, valid_controller);
    ASSERT_TRUE(validate(want, nullptr)) << f.name;
    const ParameterFile file = parse_parameter_file(base + "controller: {" + f.name + ": " + value + "}\n");
    EXPECT_EQ(to_string(file.controller), to_string(want)) << f.name;
  });
  EXPECT_EQ(n, 20);  // every setting of GraspControllerSettings (docs/controller.md)
}

TEST(ParamFile, EveryObserverFieldOfTheTableIsRead) {
  // Each field of the observer's table (the CoR estimator's by their own names), set away from
  // its default, reads back into its own member and nowhere else (to_string compares them all).
  const std::string base = "contact: {mu: 0.5, beta_a: 1e7, sigma0: 16, sigma_z: 2, delta: 0.0018, gamma: 0.25}\n";
  int n = 0;
  auto check = [&](const char* name, ObserverSettings& want, const std::string& value) {
    ++n;
    ASSERT_TRUE(validate(want, nullptr)) << name;
    // gain_mode given: a gain alone would otherwise mean a fixed gain
    const std::string mode = std::string(name) == "gain_mode" ? "" : std::string(", gain_mode: ") + to_string(want.gain_mode);
    const ParameterFile file = parse_parameter_file(base + "observer: {" + name + ": " + value + mode + "}\n");
    EXPECT_EQ(to_string(file.observer), to_string(want)) << name;
  };
  detail::for_each_entry(FieldTable<ObserverSettings>::fields, [&](const auto& f) {
    using T = std::decay_t<decltype(std::declval<ObserverSettings&>().*(f.member))>;
    if constexpr (std::is_same_v<T, CorSettings>) {
      detail::for_each_entry(FieldTable<CorSettings>::fields, [&](const auto& g) {
        ObserverSettings want;
        const std::string value = change(want.cor, g, want, valid_observer);
        check(g.name, want, value);
      });
    } else {
      ObserverSettings want;
      const std::string value = change(want, f, want, valid_observer);
      check(f.name, want, value);
    }
  });
  EXPECT_EQ(n, 18 + 5);  // every field of ObserverSettings and CorSettings
}

TEST(ParamFile, BadControllerFieldsAreNamed) {
  const std::string base = "contact: {mu: 0.5, beta_a: 1e7, sigma0: 16, sigma_z: 2, delta: 0.0018, gamma: 0.25}\n";
  EXPECT_NE(error_of(base + "controller: {k_pp: 1}").find("controller.k_pp: unknown controller setting"), std::string::npos);
  EXPECT_NE(error_of(base + "controller: {k_p: -1}").find("controller: k_p = -1"), std::string::npos);
  EXPECT_NE(error_of(base + "controller: {command_ratio: 2.5}").find("controller.command_ratio: expected an integer"), std::string::npos);
  EXPECT_NE(error_of(base + "controller: {load_floors: 3}").find("controller.load_floors: expected true or false"), std::string::npos);
  EXPECT_NE(error_of(base + "controller: 5").find("expected a mapping of controller settings"), std::string::npos);
  // the flat layout skips the block like the observer's
  EXPECT_TRUE(parse_parameter_file("mu: 0.5\nbeta_a: 1e7\nsigma0: 16\nsigma_z: 2\ndelta: 0.0018\ngamma: 0.25\ncontroller: {f_max: 12}\n").has_controller);
}
