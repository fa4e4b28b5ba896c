// lugrip::yaml: the parameter-file loader reads what the Python side writes (objects/*.yaml from
// `lugrip params`, an identification result with its observer block) and names bad fields.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <stdexcept>
#include <string>

#include "lugrip/param_file.hpp"

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
