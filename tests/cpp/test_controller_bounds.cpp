// The ranges of validate(const GraspControllerSettings&) imply the promises of step() (finite
// command inside [f_min, f_max]) and static_grasp_force() reports loads it cannot solve.
// Invariant tests: no plant, worst-case inputs at the largest magnitudes step() accepts.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "lugrip/grasp_controller.hpp"
#include "lugrip/params.hpp"

using namespace lugrip;

namespace {
constexpr double kDenorm = std::numeric_limits<double>::denorm_min();

bool accepted(const GraspControllerSettings& s) { return validate(s, nullptr); }

std::string message(const GraspControllerSettings& s) {
  std::string m;
  validate(s, &m);
  return m;
}
}  // namespace

// Values that passed validate() before and made the command NaN, and their neighbours.
TEST(ControllerBounds, RejectsSettingsThatOverflow) {
  struct Case {
    const char* field;
    void (*set)(GraspControllerSettings&);
  };
  const Case cases[] = {
      {"mu_probe", [](GraspControllerSettings& s) { s.mu_probe = 0.5000000001; }},
      {"mu_probe", [](GraspControllerSettings& s) { s.mu_probe = -kDenorm; }},
      {"k_p", [](GraspControllerSettings& s) { s.k_p = 1e306; }},
      {"k_i", [](GraspControllerSettings& s) { s.k_i = 1e308; }},
      {"sensor_rate", [](GraspControllerSettings& s) { s.sensor_rate = 9e307; }},
      {"z_cd", [](GraspControllerSettings& s) { s.z_cd = std::numeric_limits<double>::max(); }},
      {"p_cd", [](GraspControllerSettings& s) { s.p_cd = kDenorm; }},
      {"k_cd", [](GraspControllerSettings& s) { s.k_cd = 1e300; }},
      {"f_min", [](GraspControllerSettings& s) { s.f_min = kDenorm; }},
      {"f_max", [](GraspControllerSettings& s) { s.f_max = 1e300; }},
      {"s_pivot", [](GraspControllerSettings& s) { s.s_pivot = 1e308; }},
      {"command_ratio", [](GraspControllerSettings& s) { s.command_ratio = 2000000000; }},
  };
  for (const Case& c : cases) {
    GraspControllerSettings s;
    c.set(s);
    const std::string m = message(s);
    EXPECT_EQ(m.rfind(std::string(c.field) + " = ", 0), 0u) << c.field << ": " << m;
    EXPECT_THROW(GraspController(table1_params(), s), std::invalid_argument) << c.field;
  }
}

TEST(ControllerBounds, EdgesAreInsideAndJustOutsideIsNot) {
  GraspControllerSettings s;
  s.mu_probe = 0.5;
  EXPECT_TRUE(accepted(s));
  s.mu_probe = std::nextafter(0.5, 1.0);
  EXPECT_FALSE(accepted(s));
  s = {};
  s.sensor_rate = 1e9;
  EXPECT_TRUE(accepted(s));
  s.sensor_rate = std::nextafter(1e9, 2e9);
  EXPECT_FALSE(accepted(s));
  s = {};
  s.f_max = 1e6;
  EXPECT_TRUE(accepted(s));
  s.f_max = std::nextafter(1e6, 2e6);
  EXPECT_FALSE(accepted(s));
  s = {};
  s.f_min = 1e-6;
  EXPECT_TRUE(accepted(s));
  s.f_min = std::nextafter(1e-6, 0.0);
  EXPECT_FALSE(accepted(s));
  s = {};
  s.s_ref = 1e-3;
  EXPECT_TRUE(accepted(s));
  s.s_ref = std::nextafter(1e-3, 0.0);
  EXPECT_FALSE(accepted(s));
  s = {};
  s.gain_force = 0.0;  // the paper's constant gains
  EXPECT_TRUE(accepted(s));
  s.gain_force = 1e-6;
  EXPECT_TRUE(accepted(s));
  s.gain_force = std::nextafter(1e-6, 0.0);
  EXPECT_FALSE(accepted(s));
  s.gain_force = 1e6;
  EXPECT_TRUE(accepted(s));
  s.gain_force = std::nextafter(1e6, 2e6);
  EXPECT_FALSE(accepted(s));
}

// Every range at its worst end at once, inputs at the largest magnitudes step() accepts
// (|S| = 1e3, |omega_hat| = 1e6): the command stays finite and in range.
TEST(ControllerBounds, WorstEdgeSettingsKeepTheCommandFinite) {
  for (int variant = 0; variant < 8; ++variant) {
    GraspControllerSettings s;
    // variants 0-3: constant gains; 4-7: gains from the slope dS/df at the smallest gain_force
    // with every addition of the default law at its extreme
    s.gain_force = variant >= 4 ? 1e-6 : 0.0;
    s.sensor_rate = variant % 2 ? 1e9 : 1e-3;
    s.command_ratio = variant % 4 < 2 ? 1 : 1000000;
    s.k_cd = 1e9;
    s.p_cd = 1e-9;
    s.z_cd = 1e12;
    s.k_p = 1e9;
    s.k_i = 1e9;
    s.mu_probe = variant % 2 ? 0.5 : 0.0;
    s.s_ref = 1e-3;
    s.f_min = 1e-6;
    s.f_max = 1e6;
    s.max_rate = std::numeric_limits<double>::infinity();
    s.s_pivot = 1e3;
    ASSERT_TRUE(accepted(s)) << message(s);
    GraspController c(object_params("aluminium_can"), s);
    GraspControllerInput in;
    GraspControllerOutput out;
    for (int n = 0; n < 200000; ++n) {
      const double sign = (n / 7) % 2 ? 1.0 : -1.0;
      for (auto& f : in.fingers) {
        f.slippage = (n / 3) % 2 ? 1e3 : 0.0;
        f.omega_hat = sign * 1e6;
        f.c_tilde = 1e6;
        f.f_t = 1e6;
      }
      if (n == 100000) c.request_pivoting();
      c.step(in, out);
      ASSERT_TRUE(std::isfinite(out.force) && out.force >= s.f_min && out.force <= s.f_max)
          << "variant " << variant << " sample " << n << " force " << out.force;
      ASSERT_TRUE(std::isfinite(out.integrator) && std::isfinite(out.dynamic_peak) &&
                  std::isfinite(out.dynamic_sample[0]))
          << "variant " << variant << " sample " << n;
    }
  }
}

TEST(ControllerBounds, StaticGraspForceReportsLoadsItCannotSolve) {
  const ContactParams can = object_params("aluminium_can");
  // inside the solver's range: finite, positive, and about |f_t| / (mu s_ref) for translation
  for (double ft : {1e-9, 1e-3, 1.0, 1e3, 1e9}) {
    const double f = static_grasp_force(can, ft, 0.0, 0.8);
    EXPECT_TRUE(std::isfinite(f) && f > 0.0) << ft;
  }
  EXPECT_THROW(static_grasp_force(can, 1e-15, 0.0), std::invalid_argument);
  EXPECT_THROW(static_grasp_force(can, 1e16, 0.0), std::invalid_argument);
  EXPECT_THROW(static_grasp_force(can, std::nan(""), 0.0), std::invalid_argument);
  EXPECT_THROW(static_grasp_force(can, 1.0, std::numeric_limits<double>::infinity()), std::invalid_argument);
  EXPECT_EQ(static_grasp_force(can, 0.0, 0.0), 0.0);  // no load
}
