// Grasp-force controller (docs/model.md 9) and static grasp force (docs/model.md 6, 10.2, Appendix A).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdlib>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "lugrip/grasp_controller.hpp"

using namespace lugrip;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kPi = 3.14159265358979323846;

ContactParams can() { return object_params("aluminium_can"); }

// The paper's law (paper_settings(): constant gains, no feed-forward, ceiling or learning).
GraspControllerSettings paper_law() { return paper_settings(); }

// One present finger with the given observer values.
GraspControllerInput one(double S, double omega = 0.0, double c_tilde = 0.5, double f_t = 0.5,
                         Status st = Status::Ok) {
  GraspControllerInput in;
  in.fingers[0] = FingerInput{omega, S, c_tilde, f_t, st, true};
  in.fingers[1].present = false;
  return in;
}

// Runs n sensor samples with a constant input; returns the last output.
GraspControllerOutput run(GraspController& c, const GraspControllerInput& in, int n) {
  GraspControllerOutput out;
  for (int i = 0; i < n; ++i) c.step(in, out);
  return out;
}

// Continuous C_d(s) = k (s + z)/(s + p).
std::complex<double> cd_continuous(double w, double k = 10, double z = 250, double p = 7) {
  const std::complex<double> s(0.0, w);
  return k * (s + z) / (s + p);
}

std::complex<double> cd_discrete(const LagFilter& f, double theta) {
  const std::complex<double> zi = std::exp(std::complex<double>(0.0, -theta));
  return (f.b0() + f.b1() * zi) / (1.0 + f.a1() * zi);
}

}  // namespace

// --- settings -----------------------------------------------------------------------------------

TEST(ControllerSettings, DefaultsAreValidAndThePaperPresetIsThePapers) {
  GraspControllerSettings s;
  std::string msg;
  EXPECT_TRUE(validate(s, &msg)) << msg;
  const GraspControllerSettings p = paper_settings();
  EXPECT_TRUE(validate(p, &msg)) << msg;
  EXPECT_EQ(p.k_cd, 10.0);  // paper section 5: C_d = 10 (s + 250)/(s + 7), PI 4 + 10/s, S-bar 0.8
  EXPECT_EQ(p.p_cd, 7.0);
  EXPECT_EQ(p.z_cd, 250.0);
  EXPECT_EQ(p.k_p, 4.0);
  EXPECT_EQ(p.k_i, 10.0);
  EXPECT_EQ(p.s_ref, 0.8);
  EXPECT_EQ(p.gain_force, 0.0);
  EXPECT_FALSE(p.load_floors);
  EXPECT_EQ(p.ceiling_factor, 0.0);
  EXPECT_EQ(p.mu_probe, 0.0);
  EXPECT_EQ(p.reserve_force + p.reserve_torque, 0.0);
  EXPECT_EQ(s.sensor_rate / s.command_ratio, 50.0);
  // lugrip's slope gains equal the paper's at gain_force on a translational load
  EXPECT_EQ(s.k_p, p.k_p);
  EXPECT_NE(to_string(s).find("k_p=4"), std::string::npos);
}

TEST(ControllerSettings, EachBadFieldIsNamed) {
  struct Case {
    const char* field;
    void (*apply)(GraspControllerSettings&);
  };
  const Case cases[] = {
      {"sensor_rate", [](GraspControllerSettings& s) { s.sensor_rate = 0.0; }},
      {"sensor_rate", [](GraspControllerSettings& s) { s.sensor_rate = kNaN; }},
      {"command_ratio", [](GraspControllerSettings& s) { s.command_ratio = 0; }},
      {"k_cd", [](GraspControllerSettings& s) { s.k_cd = -1.0; }},
      {"p_cd", [](GraspControllerSettings& s) { s.p_cd = 0.0; }},
      {"z_cd", [](GraspControllerSettings& s) { s.z_cd = 5.0; }},  // below p_cd
      {"s_ref", [](GraspControllerSettings& s) { s.s_ref = 1.0; }},
      {"s_ref", [](GraspControllerSettings& s) { s.s_ref = 0.0; }},
      {"k_p", [](GraspControllerSettings& s) { s.k_p = 0.0; }},
      {"k_i", [](GraspControllerSettings& s) { s.k_i = kInf; }},
      {"mu_probe", [](GraspControllerSettings& s) { s.mu_probe = -0.1; }},
      {"f_min", [](GraspControllerSettings& s) { s.f_min = 0.0; }},
      {"f_max", [](GraspControllerSettings& s) { s.f_max = 0.05; }},  // below f_min
      {"max_rate", [](GraspControllerSettings& s) { s.max_rate = 0.0; }},
      {"max_rate", [](GraspControllerSettings& s) { s.max_rate = kNaN; }},
      {"s_pivot", [](GraspControllerSettings& s) { s.s_pivot = 1.0; }},
      {"tau_pivot", [](GraspControllerSettings& s) { s.tau_pivot = 0.0; }},
      {"mu_probe", [](GraspControllerSettings& s) { s.mu_probe = kNaN; }},
      {"gain_force", [](GraspControllerSettings& s) { s.gain_force = -1.0; }},
      {"gain_force", [](GraspControllerSettings& s) { s.gain_force = 1e-9; }},
      {"ceiling_factor", [](GraspControllerSettings& s) { s.ceiling_factor = 0.5; }},
      {"reserve_force", [](GraspControllerSettings& s) { s.reserve_force = -1.0; }},
      {"reserve_torque", [](GraspControllerSettings& s) { s.reserve_torque = kNaN; }},
  };
  for (const Case& c : cases) {
    GraspControllerSettings s;
    c.apply(s);
    std::string msg;
    EXPECT_FALSE(validate(s, &msg)) << c.field;
    EXPECT_EQ(msg.rfind(std::string(c.field) + " = ", 0), 0u) << msg;
    EXPECT_EQ(std::count(msg.begin(), msg.end(), '\n'), 1) << msg;  // one message per bad field
    EXPECT_THROW(GraspController(can(), s), std::invalid_argument) << c.field;
  }
  GraspControllerSettings two;
  two.k_p = -1;
  two.f_min = -1;
  std::string msg;
  validate(two, &msg);
  EXPECT_EQ(std::count(msg.begin(), msg.end(), '\n'), 2) << msg;
  GraspControllerSettings off;  // rate limits may be switched off with inf
  off.max_rate = kInf;
  EXPECT_TRUE(validate(off, nullptr));
  EXPECT_THROW(GraspController(ContactParams{}, GraspControllerSettings{}), std::invalid_argument);
}

TEST(ControllerSettings, RunTimeChangesKeepFixedFields) {
  GraspController c(can(), paper_law());
  GraspControllerSettings s = c.settings();
  s.k_p = 2.0;
  s.f_max = 1.0;
  c.reset(5.0);
  c.set_settings(s);
  EXPECT_EQ(c.settings().k_p, 2.0);
  EXPECT_EQ(c.command(), 1.0);  // the held command follows the new range at once
  s.command_ratio = 5;
  EXPECT_THROW(c.set_settings(s), std::invalid_argument);
  s = c.settings();
  s.k_i = -1;
  EXPECT_THROW(c.set_settings(s), std::invalid_argument);
}

// --- C_d discretisation (docs/model.md 9.2) ------------------------------------------------------------

TEST(ControllerDynamicPart, TustinCoefficientsMatchTheSpecTable) {
  const LagFilter f500(10, 250, 7, 1.0 / 500);
  EXPECT_NEAR(f500.b0(), 12.413108, 5e-7);
  EXPECT_NEAR(f500.b1(), -7.447865, 5e-7);
  EXPECT_NEAR(f500.a1(), -0.986097, 5e-7);
  const LagFilter f50(10, 250, 7, 1.0 / 50);
  EXPECT_NEAR(f50.b0(), 32.710280, 5e-7);
  EXPECT_NEAR(f50.b1(), 14.018692, 5e-7);
  EXPECT_NEAR(f50.a1(), -0.869159, 5e-7);
  // DC gain k z / p = 357.142857 and gain k = 10 at Nyquist are exact for both rates.
  for (const LagFilter* f : {&f500, &f50}) {
    EXPECT_NEAR((f->b0() + f->b1()) / (1 + f->a1()), 2500.0 / 7.0, 1e-9);
    EXPECT_NEAR((f->b0() - f->b1()) / (1 - f->a1()), 10.0, 1e-12);
  }
  GraspController c(can(), paper_law());
  EXPECT_EQ(c.dynamic_filter(0).b0(), f500.b0());
  EXPECT_EQ(c.dynamic_filter(1).a1(), f500.a1());
}

TEST(ControllerDynamicPart, FrequencyResponseIsTheWarpedContinuousOne) {
  const double T = 1.0 / 500;
  const LagFilter f(10, 250, 7, T);
  for (double theta = 1e-4; theta < kPi; theta *= 1.3) {
    const double warped = 2.0 / T * std::tan(theta / 2);  // Tustin frequency map
    EXPECT_NEAR(std::abs(cd_discrete(f, theta)), std::abs(cd_continuous(warped)), 1e-9 * 357);
    EXPECT_NEAR(std::arg(cd_discrete(f, theta)), std::arg(cd_continuous(warped)), 1e-9);
  }
  EXPECT_NEAR(std::abs(cd_discrete(f, 0.0)), 357.142857, 1e-6);
  EXPECT_NEAR(std::abs(cd_discrete(f, kPi)), 10.0, 1e-9);
  // Below a tenth of Nyquist the discrete gain is within 1 % of the continuous one.
  for (double w = 0.1; w < 0.1 * kPi / T; w *= 1.5)
    EXPECT_NEAR(std::abs(cd_discrete(f, w * T)) / std::abs(cd_continuous(w)), 1.0, 0.01) << w;
}

TEST(ControllerDynamicPart, StepResponseThroughTheControllerMatchesTheContinuousOne) {
  // Unit step of omega_hat; continuous response y(t) = k (z/p + (1 - z/p) e^{-p t}).
  GraspController c(can(), paper_law());
  const auto in = one(0.8, 1.0);
  GraspControllerOutput out;
  const double T = 1.0 / 500, k = 10, z = 250, p = 7;
  auto y_c = [&](double t) { return k * (z / p + (1 - z / p) * std::exp(-p * t)); };
  double max_err = 0, max_err_shift = 0;
  for (int n = 0; n < 1500; ++n) {  // 3 s
    c.step(in, out);
    const double y = out.dynamic_sample[0];
    max_err = std::max(max_err, std::fabs(y - y_c(n * T)));
    // Tustin integrates the step as a trapezoid: exact for a step half a sample earlier.
    max_err_shift = std::max(max_err_shift, std::fabs(y - y_c((n + 0.5) * T)));
  }
  EXPECT_LT(max_err, 0.01 * 357.14);          // measured 2.41 (first sample: b0 vs k)
  EXPECT_LT(max_err_shift, 0.0005 * 357.14);  // measured ~0.1
  EXPECT_NEAR(out.dynamic_sample[0], y_c(3.0), 0.01);
  EXPECT_NEAR(run(c, in, 5000).dynamic_sample[0], 2500.0 / 7.0, 1e-6);  // DC gain after 13 s
}

TEST(ControllerDynamicPart, AbsoluteValueAfterFilteringAndPeakHold) {
  GraspControllerSettings s = paper_law();
  s.max_rate = kInf;
  GraspController c(can(), s);
  c.reset(2.0);
  GraspControllerOutput out;
  c.step(one(0.8), out);  // command 0
  ASSERT_TRUE(out.command_issued);
  // A single negative spike in the middle of the next period: the filter output is negative,
  // |C_d omega| peaks at the spike and has decayed by the next command; the command uses the peak.
  double peak = 0, at_tick = 0;
  for (int i = 1; i <= 10; ++i) {
    c.step(one(0.8, i == 4 ? -0.1 : 0.0), out);
    if (i == 4) {
      EXPECT_LT(out.dynamic_sample[0], 0.0);
    }
    peak = std::max(peak, std::fabs(out.dynamic_sample[0]));
    if (i < 10) {
      EXPECT_FALSE(out.command_issued);
    }
    at_tick = std::fabs(out.dynamic_sample[0]);
  }
  ASSERT_TRUE(out.command_issued);
  EXPECT_NEAR(peak, 0.1 * 12.413108, 1e-5);
  EXPECT_LT(at_tick, 0.5 * peak);
  EXPECT_NEAR(out.dynamic_force, peak, 1e-12);
  EXPECT_NEAR(out.force, out.static_force + peak, 1e-12);
  EXPECT_EQ(out.dynamic_peak, 0.0);  // restarted after the command
}

TEST(ControllerDynamicPart, ClippedToTheHeadRoomWithoutTouchingTheIntegrator) {
  GraspControllerSettings s = paper_law();
  s.max_rate = kInf;
  GraspController c(can(), s);
  c.reset(15.0);
  const auto out = run(c, one(0.8, 1.0), 11);  // second command: C_d output ~ 160 N
  EXPECT_NEAR(out.static_force, 15.0, 1e-12);  // e = 0: PI unchanged
  EXPECT_NEAR(out.dynamic_force, 5.0, 1e-12);
  EXPECT_EQ(out.force, 20.0);
  EXPECT_TRUE(out.saturated);
  EXPECT_NEAR(out.integrator, 15.0, 1e-12);
}

TEST(ControllerDynamicPart, DisabledAndReenabledFromRest) {
  GraspController c(can(), paper_law());
  auto out = run(c, one(0.8, 1.0), 200);  // filter state far from rest
  EXPECT_GT(out.dynamic_sample[0], 100.0);
  c.set_dynamic_enabled(false);
  out = run(c, one(0.8, 1.0), 50);
  EXPECT_EQ(out.dynamic_force, 0.0);
  EXPECT_EQ(out.dynamic_sample[0], 0.0);
  c.set_dynamic_enabled(true);
  c.step(one(0.8, 1.0), out);
  EXPECT_NEAR(out.dynamic_sample[0], 12.413108, 1e-5);  // first sample of a zero-state filter
}

// --- static part: PI (docs/model.md 9.4-9.5) ----------------------------------------------------------

TEST(ControllerStaticPart, SAboveTheReferenceRaisesTheForceAndBelowLowersIt) {
  const double T = 0.02;
  for (double S : {0.9, 0.7}) {
    GraspController c(can(), paper_law());
    c.reset(5.0);
    GraspControllerOutput out;
    c.step(one(S), out);
    EXPECT_NEAR(out.force, 5.0, 1e-12);  // bumpless start: I = f - k_p e
    for (int n = 1; n <= 20; ++n) {
      out = run(c, one(S), 10);
      ASSERT_TRUE(out.command_issued);
      // forward Euler at 50 Hz: f_n = f_0 + k_i T e n
      EXPECT_NEAR(out.force, 5.0 + 10.0 * T * (S - 0.8) * n, 1e-9);
    }
    if (S > 0.8)
      EXPECT_GT(out.force, 5.3);
    else
      EXPECT_LT(out.force, 4.7);
  }
}

TEST(ControllerStaticPart, ProportionalStepHasTheRightSign) {
  GraspControllerSettings s = paper_law();
  s.max_rate = kInf;
  GraspController c(can(), s);
  c.reset(5.0);
  auto out = run(c, one(0.8), 1);  // the first command, at e = 0
  out = run(c, one(1.0), 10);  // the period's mean S jumps by +0.2: +k_p 0.2 = +0.8 N at once
  EXPECT_NEAR(out.force, 5.8, 1e-12);
  EXPECT_NEAR(out.error, 0.2, 1e-12);
}

TEST(ControllerStaticPart, NoLoadDecaysToTheFloorInAQuarterSecond) {
  // docs/model.md 9.5: from 2 N with S = 0 the integrator drains at k_i S_ref = 8 N/s.
  GraspController c(can(), paper_law());
  c.reset(2.0);
  GraspControllerOutput out;
  double t_floor = -1;
  for (int n = 0; n < 500; ++n) {
    c.step(one(0.0), out);
    if (t_floor < 0 && out.force <= 0.1 + 1e-12) t_floor = n / 500.0;
  }
  EXPECT_NEAR(t_floor, 0.25, 0.03);
  EXPECT_EQ(out.force, 0.1);
}

namespace {
// Saturates at f_max with S = 1 for `hold` seconds, then reverses the error (S = 0.5); returns
// the number of commands until the force leaves f_max.
int commands_to_leave_ceiling(double hold) {
  GraspControllerSettings s = paper_law();
  s.max_rate = kInf;
  GraspController c(can(), s);
  c.reset(5.0);
  auto out = run(c, one(1.0), static_cast<int>(hold * 500));
  EXPECT_EQ(out.force, 20.0);
  for (int k = 1; k < 10000; ++k) {
    out = run(c, one(0.5), 10);
    if (out.force < 20.0) return k;
  }
  return 10000;
}
}  // namespace

TEST(ControllerStaticPart, AntiWindupLeavesTheCeilingAtOnce) {
  // Back-calculation: after 30 s at f_max with e = 0.2 the first command with e < 0 leaves it
  // (without it the integrator would have wound up by k_i 0.2 30 = 60 N: ~640 commands).
  EXPECT_EQ(commands_to_leave_ceiling(30.0), 1);
}

TEST(ControllerStaticPart, AntiWindupAtTheFloorToo) {
  GraspControllerSettings s = paper_law();
  s.max_rate = kInf;
  GraspController c(can(), s);
  c.reset(1.0);
  auto out = run(c, one(0.0), 500 * 30);
  EXPECT_EQ(out.force, 0.1);
  out = run(c, one(0.9), 10);  // error reverses: leaves the floor at the next command
  EXPECT_GT(out.force, 0.1);
}

TEST(ControllerStaticPart, RateLimitsBoundEachCommandChange) {
  GraspControllerSettings s = paper_law();
  s.max_rate = 10.0;  // 0.2 N per command, either way
  GraspController c(can(), s);
  c.reset(5.0);
  auto out = run(c, one(0.8), 1);
  out = run(c, one(1.0), 10);  // wants +0.8 N
  EXPECT_NEAR(out.force, 5.2, 1e-12);
  EXPECT_TRUE(out.rate_limited);
  out = run(c, one(0.0), 10);  // wants -3.2 N
  EXPECT_NEAR(out.force, 5.0, 1e-12);
  s.max_rate = kInf;
  c.set_settings(s);
  out = run(c, one(0.8), 10);
  EXPECT_FALSE(out.rate_limited);
}

// --- multi-rate -----------------------------------------------------------------------------------

TEST(ControllerMultiRate, CommandChangesOnlyEveryTenthCall) {
  GraspController c(can(), paper_law());
  c.reset(3.0);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  GraspControllerOutput out;
  double held = -1;
  int changes = 0;
  for (int n = 0; n < 1000; ++n) {
    c.step(one(u(rng), 0.05 * (u(rng) - 0.5)), out);
    EXPECT_EQ(out.command_issued, n % 10 == 0) << n;
    if (n % 10 != 0) {
      EXPECT_EQ(out.force, held) << n;  // zero-order hold
    } else if (out.force != held) {
      ++changes;
    }
    held = out.force;
  }
  EXPECT_GT(changes, 90);  // random inputs: (almost) every command differs
  GraspControllerSettings s = paper_law();
  s.command_ratio = 4;
  GraspController c4(can(), s);
  EXPECT_NEAR(c4.command_period(), 4.0 / 500, 1e-15);
  for (int n = 0; n < 20; ++n) {
    c4.step(one(0.9), out);
    EXPECT_EQ(out.command_issued, n % 4 == 0);
  }
}

// --- two fingers (docs/model.md 9.8) -------------------------------------------------------------------

TEST(ControllerTwoFingers, MaxOfSMaxOfDynamicPartMeanOfCoR) {
  GraspControllerSettings s = paper_law();
  s.max_rate = kInf;
  GraspController c(can(), s);
  c.reset(5.0);
  GraspControllerInput in;
  in.fingers[0] = FingerInput{0.0, 0.6, 0.2, 1.0, Status::Ok, true};
  in.fingers[1] = FingerInput{0.0, 0.9, 1.4, 1.0, Status::Ok, true};
  GraspControllerOutput out;
  c.step(in, out);
  EXPECT_EQ(out.slippage, 0.9);
  EXPECT_NEAR(out.mean_c_tilde, 0.8, 1e-15);
  // Dynamic part: one filter per finger, the larger magnitude wins.
  in.fingers[0].omega_hat = 0.02;
  in.fingers[1].omega_hat = -0.05;
  out = run(c, in, 10);
  EXPECT_NEAR(out.dynamic_sample[0], -0.4 * out.dynamic_sample[1], 1e-12);
  EXPECT_NEAR(out.dynamic_force, std::fabs(out.dynamic_sample[1]), 0.01);
  GraspController c1(can(), s);  // the same run with finger 1 alone gives the same f_nd
  c1.reset(5.0);
  GraspControllerInput in1 = in;
  in1.fingers[0].present = false;
  GraspControllerOutput out1;
  c1.step(one(0.9, 0.0, 1.4, 1.0), out1);
  out1 = run(c1, in1, 10);
  EXPECT_DOUBLE_EQ(out1.dynamic_force, out.dynamic_force);
  EXPECT_DOUBLE_EQ(out1.force, out.force);
}

TEST(ControllerTwoFingers, AbsentFingerIsIgnoredEvenWithGarbage) {
  GraspController c(can(), paper_law());
  GraspControllerInput in = one(0.7);
  in.fingers[1] = FingerInput{kNaN, kNaN, kNaN, kNaN, Status::SensorFault, false};
  GraspControllerOutput out;
  c.step(in, out);
  EXPECT_EQ(out.status, Status::Ok);
  EXPECT_EQ(out.slippage, 0.7);
  EXPECT_FALSE(out.held);
  in.fingers[0].present = false;  // no finger at all: hold, NoContact
  c.step(in, out);
  EXPECT_EQ(out.status, Status::NoContact);
}

// --- invalid inputs ---------------------------------------------------------------------------

TEST(ControllerBadInput, InvalidStatusesAndValuesHoldTheCommand) {
  const FingerInput bad[] = {
      {0, 0.0, 0.5, 0.5, Status::InvalidSample, true}, {0, 0.0, 0.5, 0.5, Status::SensorFault, true},
      {0, 0.0, 0.5, 0.5, Status::NoContact, true},     {kNaN, 0.0, 0.5, 0.5, Status::Ok, true},
      {0, kNaN, 0.5, 0.5, Status::Ok, true},           {0, 0.0, kInf, 0.5, Status::Ok, true},
      {0, 0.0, 0.5, -kInf, Status::Ok, true},          {0, -0.5, 0.5, 0.5, Status::Ok, true},
      {1e9, 0.0, 0.5, 0.5, Status::Ok, true},
      {0, 0.0, 0.5, 0.5, static_cast<Status>(7), true},  // a code outside the enum
      {0, 0.0, 0.5, 0.5, static_cast<Status>(-1), true},
  };
  const Status expected[] = {Status::InvalidSample, Status::SensorFault, Status::NoContact,
                             Status::InvalidSample, Status::InvalidSample, Status::InvalidSample,
                             Status::InvalidSample, Status::InvalidSample, Status::InvalidSample,
                             Status::InvalidSample, Status::InvalidSample};
  for (int k = 0; k < 11; ++k) {
    GraspController c(can(), paper_law());
    c.reset(3.0);
    GraspControllerInput in = one(0.8);
    in.fingers[1] = bad[k];  // S = 0 on the bad finger would lower the force if it were used
    auto out = run(c, in, 500);
    EXPECT_EQ(out.status, expected[k]) << k;
    EXPECT_EQ(out.force, 3.0) << k;
    EXPECT_TRUE(out.held) << k;
    // Valid again: bumpless restart from the held command.
    in.fingers[1] = FingerInput{0, 0.5, 0.5, 0.5, Status::Ok, true};
    c.step(in, out);
    EXPECT_TRUE(out.command_issued);
    EXPECT_EQ(out.force, 3.0) << k;
    EXPECT_FALSE(out.held);
  }
  // The worst status wins.
  GraspController c(can(), paper_law());
  GraspControllerInput in;
  in.fingers[0] = bad[2];
  in.fingers[1] = bad[1];
  GraspControllerOutput out;
  c.step(in, out);
  EXPECT_EQ(out.status, Status::SensorFault);
}

TEST(ControllerBadInput, RandomAdversarialInputsKeepTheCommandFiniteAndInRange) {
  // Property: 1e6 seeded samples (NaN, Inf, huge, negative, random statuses, presence, mode
  // requests and resets) -> command finite and in [f_min, f_max]; never lowered by a held command.
  GraspControllerSettings s = paper_law();
  s.f_min = 0.3;
  s.f_max = 12.0;
  GraspController c(can(), s);
  // Defaults: 1e6 samples, seed 20240607; LUGRIP_PROPERTY_SAMPLES / LUGRIP_PROPERTY_SEED override.
  const char* env_n = std::getenv("LUGRIP_PROPERTY_SAMPLES");
  const char* env_seed = std::getenv("LUGRIP_PROPERTY_SEED");
  const long samples = env_n ? std::max(1L, std::atol(env_n)) : 1000000L;
  std::mt19937_64 rng(env_seed ? std::strtoull(env_seed, nullptr, 10) : 20240607u);
  SCOPED_TRACE("seed " + std::string(env_seed ? env_seed : "20240607"));
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double specials[] = {kNaN, kInf, -kInf, 1e300, -1e300, 1e7, -1e7, 0.0, -0.0, 1e-300};
  auto value = [&](double scale) {
    const double r = u(rng);
    if (r < 0.05) return specials[rng() % 10];
    if (r < 0.15) return scale * 1e3 * (u(rng) - 0.5);
    return scale * (u(rng) - 0.3);
  };
  GraspControllerOutput out;
  double previous = c.command();
  for (long n = 0; n < samples; ++n) {
    GraspControllerInput in;
    for (auto& f : in.fingers) {
      f.omega_hat = value(0.5);
      f.slippage = value(1.5);
      f.c_tilde = value(2.0);
      f.f_t = value(10.0);
      f.status = static_cast<Status>(rng() % 7);
      f.present = u(rng) < 0.9;
    }
    const double r = u(rng);
    if (r < 1e-3) c.request_pivoting();
    else if (r < 2e-3) c.request_slipping_avoidance();
    else if (r < 2.1e-3) c.reset(value(10.0));
    c.step(in, out);
    ASSERT_TRUE(std::isfinite(out.force)) << n;
    ASSERT_GE(out.force, s.f_min) << n;
    ASSERT_LE(out.force, s.f_max) << n;
    ASSERT_EQ(out.force, c.command());
    ASSERT_TRUE(std::isfinite(out.static_force) && std::isfinite(out.dynamic_force) &&
                std::isfinite(out.integrator) && std::isfinite(out.dynamic_peak));
    if (out.command_issued && out.held && r >= 2.1e-3) {
      ASSERT_GE(out.force, std::min(previous, s.f_max));
    }
    previous = out.force;
  }
}

// --- pivoting (docs/model.md 9.6) ----------------------------------------------------------------------

TEST(ControllerPivoting, NoDynamicPartExponentialDecayNoJump) {
  GraspControllerSettings s = paper_law();
  s.max_rate = kInf;
  GraspController c(can(), s);
  c.reset(8.0);
  auto out = run(c, one(1.0, 0.01), 20);  // slipping avoidance with some f_nd
  const double before = c.command();
  EXPECT_GT(out.dynamic_force, 0.0);
  c.request_pivoting();
  // S = 1 (sliding), f_t small: f(t) = -1.2 + (f0 + 1.2) exp(-t / tau_p) until the floor.
  const auto in = one(1.0, 5.0, 0.3, 0.05);
  c.step(in, out);
  EXPECT_EQ(out.mode, ControllerMode::Pivoting);
  EXPECT_TRUE(out.command_issued);
  EXPECT_EQ(out.force, before);  // no jump at the switch
  EXPECT_EQ(out.dynamic_force, 0.0);
  EXPECT_EQ(out.dynamic_sample[0], 0.0);
  const double T = 0.02, k_f = s.k_p, target = k_f * (1.0 - 1.3);  // k_f = k_p (docs/model.md 9.6)
  for (int n = 1; n <= 100; ++n) {
    out = run(c, in, 10);
    const double expected = target + (before - target) * std::exp(-n * T / 2.0);
    EXPECT_NEAR(out.force, std::max(expected, 0.1), 1e-9) << n;
    EXPECT_EQ(out.dynamic_force, 0.0);
  }
  EXPECT_NEAR(out.force, -1.2 + (before + 1.2) * std::exp(-1.0), 1e-9);  // after 2 s = tau_p
}

TEST(ControllerPivoting, FloorFromTheTangentialForceHoldsTheFilterState) {
  GraspController c(can(), paper_law());
  c.reset(3.0);
  GraspControllerOutput out;
  c.step(one(0.8), out);
  c.request_pivoting();
  // Finger 0 carries f_t = 1.5 N: floor 1.1 * 1.5 / 0.75 = 2.2 N, reached after 0.42 s
  // (-1.2 + 4.2 exp(-t / 2) = 2.2); checked before 1 s at the floor ends the pivot.
  GraspControllerInput in = one(1.0, 0.0, 0.3, 0.3);
  in.fingers[1] = FingerInput{0.0, 0.9, 0.3, 1.5, Status::Ok, true};
  out = run(c, in, 400);
  ASSERT_EQ(out.mode, ControllerMode::Pivoting);
  EXPECT_NEAR(out.force, 2.2, 1e-12);
  EXPECT_NEAR(out.floor, 2.2, 1e-12);
  // The load drops: the force continues from the floor (state kept at it), not from a wound-down
  // negative state.
  in.fingers[1].f_t = 0.3;
  out = run(c, in, 10);  // this command outputs the state (at the old floor), then updates it
  EXPECT_NEAR(out.force, 2.2, 1e-12);
  EXPECT_NEAR(out.floor, 1.1 * 0.3 / 0.75, 1e-12);
  out = run(c, in, 10);
  const double a = std::exp(-0.02 / 2.0);
  EXPECT_NEAR(out.force, a * 2.2 + (1 - a) * -1.2, 1e-9);
  EXPECT_GT(out.force, 2.0);
}

TEST(ControllerPivoting, TwoFingersEndOnTheMeanOfTheCoR) {
  // At the floor (0.29 N for f_t = 0.2 N) from the start, S below the sliding bound: the end
  // test sees the mean |c~| of the fingers through its 0.2 s low-pass.
  GraspController c(can(), paper_law());
  c.reset(0.3);
  GraspControllerInput in;
  in.fingers[0] = FingerInput{0.0, 0.95, 1.5, 0.2, Status::Ok, true};
  in.fingers[1] = FingerInput{0.0, 0.95, 0.4, 0.2, Status::Ok, true};  // mean 0.95
  c.request_pivoting();
  auto out = run(c, in, 200);
  EXPECT_EQ(out.mode, ControllerMode::Pivoting);
  in.fingers[1].c_tilde = 0.6;  // mean 1.05: the low-pass crosses 1 after 0.2 ln 2 = 0.14 s
  int n = 0;
  do {
    c.step(in, out);
    ++n;
  } while (!out.pivot_finished && n < 1000);
  EXPECT_EQ(out.pivot_end, PivotEnd::CorThreshold);
  EXPECT_NEAR(n * 0.002, 0.2 * std::log(2.0) + 3 * 0.002, 0.006);
}

TEST(ControllerPivoting, TimeoutAndRequestEndIt) {
  GraspController c(can(), paper_law());
  c.request_pivoting();
  GraspControllerOutput out;
  int n = 0;
  do {  // S = 2 > s_pivot: the filter rises, never held at its floor
    c.step(one(2.0, 0.0, 0.2, 0.1), out);
    ++n;
  } while (!out.pivot_finished && n < 10000);
  EXPECT_EQ(out.pivot_end, PivotEnd::Timeout);
  EXPECT_EQ(n, 5000);  // 10 s at 500 Hz
  c.request_pivoting();
  run(c, one(1.0), 30);
  c.request_slipping_avoidance();
  c.step(one(1.0), out);
  EXPECT_EQ(out.pivot_end, PivotEnd::Requested);
  EXPECT_EQ(out.mode, ControllerMode::SlippingAvoidance);
  c.request_slipping_avoidance();  // already avoiding: no event
  c.step(one(1.0), out);
  EXPECT_FALSE(out.pivot_finished);
}

TEST(ControllerPivoting, InvalidInputHoldsInsteadOfDecaying) {
  GraspController c(can(), paper_law());
  c.reset(5.0);
  c.request_pivoting();
  auto out = run(c, one(1.0, 0, 0.3, 0.1), 100);
  const double f = out.force;
  out = run(c, one(1.0, 0, 0.3, 0.1, Status::SensorFault), 100);
  EXPECT_EQ(out.force, f);
  EXPECT_EQ(out.mode, ControllerMode::Pivoting);
  out = run(c, one(1.0, 0, 0.3, 0.1), 1);  // resumes from the held command
  EXPECT_EQ(out.force, f);
}

// --- static grasp force (docs/model.md 6, 10.2, Appendix A) --------------------------------------------

TEST(ControllerStaticGraspForce, ReferenceValues) {
  StaticForceSolver can_solver(can());
  EXPECT_NEAR(can_solver.solve(0.12, 0.0).force, 0.190, 0.0005);  // empty can, c_max = 1.5
  EXPECT_NEAR(can_solver.solve(0.12, 0.0).force, 0.12 / 0.75 / 0.8 / 1.0518, 2e-4);
  EXPECT_NEAR(can_solver.solve(2.0, 3e-3).force, 4.75, 0.005);  // full can
  EXPECT_NEAR(can_solver.solve(2.0, 6e-3).force, 6.66, 0.005);
  EXPECT_NEAR(can_solver.solve(4.0, 6e-3).force, 8.90, 0.005);
  ContactParams wide = can();
  wide.c_max = 1000.0;  // c_max -> inf
  StaticForceSolver wide_solver(wide);
  EXPECT_NEAR(wide_solver.solve(0.12, 0.0).force, 0.200, 1e-5);
  EXPECT_NEAR(wide_solver.solve(2.0, 0.0).force, 2.0 / 0.75 / 0.8, 1e-4);  // 3.33 N
  // E2: S = 0.8 with c~ = 0.4 at 5 N needs f_t ~ 1.20 N and tau ~ 4.15 N mm (mu = 0.70).
  StaticForceSolver block(object_params("small_resin_block"));
  const StaticForceResult e2 = block.solve(1.20, 4.15e-3);
  EXPECT_TRUE(e2.converged);
  EXPECT_NEAR(e2.force, 5.0, 0.01);
  EXPECT_NEAR(e2.c_tilde, 0.4, 0.002);
  EXPECT_NEAR(e2.slippage, 0.8, 1e-12);
  EXPECT_LT(e2.iterations, 30);
  // S_ref = 1 gives the slip threshold: the pure-rotation capacity tau_max = mu xi delta f^(1+g).
  const double f_rot = can_solver.solve(0.0, 4e-3, 1.0).force;
  const ContactModel& m = can_solver.model();
  EXPECT_NEAR(m.tau_max(f_rot), 4e-3, 1e-12);
  // Convenience function and invalid arguments.
  EXPECT_NEAR(static_grasp_force(can(), 2.0, 3e-3), 4.7495, 1e-3);
  EXPECT_THROW(static_grasp_force(can(), 2.0, 0.0, 1.2), std::invalid_argument);
  EXPECT_EQ(can_solver.solve(0.0, 0.0).force, 0.0);
  EXPECT_TRUE(std::isnan(can_solver.solve(kNaN, 0.0).force));
  EXPECT_EQ(can_solver.solve(-2.0, -3e-3).force, can_solver.solve(2.0, 3e-3).force);
}

TEST(ControllerStaticGraspForce, MoreLoadNeverLowersTheForceAndSlippageDecreases) {
  StaticForceSolver solver(object_params("plastic_bottle"));
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> lf(-3.0, 1.5), lt(-6.0, -1.5), grow(1.0, 1.5);
  for (int k = 0; k < 400; ++k) {
    const double ft = std::pow(10.0, lf(rng)), tau = std::pow(10.0, lt(rng));
    const StaticForceResult r = solver.solve(ft, tau);
    ASSERT_TRUE(r.converged) << ft << " " << tau;
    EXPECT_NEAR(solver.slippage(r.force, ft, tau), 0.8, 1e-9);
    EXPECT_GE(solver.solve(ft * grow(rng), tau).force, r.force * (1 - 1e-12));
    EXPECT_GE(solver.solve(ft, tau * grow(rng)).force, r.force * (1 - 1e-12));
    EXPECT_GE(solver.solve(ft, tau, 0.7).force, r.force);  // a lower S_ref needs more force
    EXPECT_GT(solver.slippage(0.9 * r.force, ft, tau), 0.8);
    EXPECT_LT(solver.slippage(1.1 * r.force, ft, tau), 0.8);
  }
}

TEST(ControllerStaticGraspForce, ClosedFormRootAgreesWithBisectionOfTheMap) {
  // Reference: 200 bisection steps on log f_n of slippage() itself (no closed form, no secant).
  // solve() takes the root of S = A f^-(1+gamma) + B f^-1 from one evaluation and checks it with
  // a second; loads span pure translation, pure torsion, the c_max clip and tiny components
  // next to the estimator's zero thresholds (where its fallback, the bracket, takes over).
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> lf(-6.0, 1.0), lt(-8.0, -1.5), u(0.0, 1.0);
  const double refs[] = {0.5, 0.8, 0.9, 1.0};
  int n = 0, fast = 0;
  for (const char* name : {"aluminium_can", "small_resin_block", "plastic_bottle"}) {
    StaticForceSolver solver(object_params(name));
    for (int k = 0; k < 300; ++k) {
      const double ft = u(rng) < 0.1 ? 0.0 : std::pow(10.0, lf(rng));
      const double tau = u(rng) < 0.1 ? 0.0 : std::pow(10.0, lt(rng)) * (u(rng) < 0.5 ? -1.0 : 1.0);
      if (ft == 0.0 && tau == 0.0) continue;
      const double s_ref = refs[k % 4];
      const StaticForceResult r = solver.solve(ft, tau, s_ref);
      ASSERT_TRUE(r.converged) << name << " " << ft << " " << tau << " " << s_ref;
      double lo = std::log(1e-9), hi = std::log(1e9);
      for (int i = 0; i < 200; ++i) {
        const double mid = 0.5 * (lo + hi);
        (solver.slippage(std::exp(mid), ft, tau) > s_ref ? lo : hi) = mid;
      }
      const double ref = std::exp(0.5 * (lo + hi));
      EXPECT_NEAR(r.force, ref, 1e-9 * ref) << name << " " << ft << " " << tau << " " << s_ref;
      EXPECT_NEAR(r.slippage, s_ref, 1e-10 * s_ref);
      ++n;
      fast += r.iterations <= 3;
    }
  }
  EXPECT_GE(fast, 0.95 * n) << fast << " of " << n;  // two evaluations, three from outside the LS
}

// --- closed loop on a quasi-static plant ----------------------------------------------------------

namespace {
// S = S_static(f_n) at the commanded force (stick, constant load); returns the force range over
// the last `tail` seconds of a `duration` s run.
std::pair<double, double> quasi_static_loop(const ContactParams& p, double ft, double tau,
                                            const GraspControllerSettings& s, double duration,
                                            double tail) {
  StaticForceSolver plant(p);
  GraspController c(p, s);
  c.reset(2.0);
  GraspControllerOutput out;
  double lo = 1e9, hi = 0;
  const int n = static_cast<int>(duration * 500);
  for (int k = 0; k < n; ++k) {
    double ct = 0;
    const double S = plant.slippage(c.command(), ft, tau, &ct);
    c.step(one(std::min(S, 1.0), 0.0, ct, ft), out);
    if (k >= n - tail * 500) {
      lo = std::min(lo, out.force);
      hi = std::max(hi, out.force);
    }
  }
  return {lo, hi};
}
}  // namespace

TEST(ControllerClosedLoop, SettlesAtTheStaticGraspForce) {
  struct Load {
    const char* object;
    double ft, tau;
  };
  for (const Load& l : {Load{"aluminium_can", 2.0, 3e-3}, Load{"aluminium_can", 4.0, 6e-3},
                        Load{"small_resin_block", 1.2, 4.15e-3}}) {
    const ContactParams p = object_params(l.object);
    const double f_static = StaticForceSolver(p).solve(l.ft, l.tau).force;
    const auto range = quasi_static_loop(p, l.ft, l.tau, paper_law(), 40.0, 5.0);
    EXPECT_NEAR(range.first, f_static, 0.01 * f_static) << l.object << " " << l.ft;
    EXPECT_NEAR(range.second, f_static, 0.01 * f_static) << l.object << " " << l.ft;
  }
}

TEST(ControllerClosedLoop, LowForcesNeedTheSlopeGain) {
  // Empty can (0.12 N per finger -> 0.190 N): k_p |dS/df| = 4 * 0.8 / 0.19 = 17 > 1, the 50 Hz
  // loop with the paper's gains limit-cycles; with the gains from the slope it settles.
  const double f_static = StaticForceSolver(can()).solve(0.12, 0.0).force;
  const auto paper = quasi_static_loop(can(), 0.12, 0.0, paper_law(), 20.0, 5.0);
  EXPECT_GT(paper.second - paper.first, 0.5);
  GraspControllerSettings s = paper_law();
  s.gain_force = GraspControllerSettings().gain_force;  // lugrip's gains from the slope
  s.k_i = GraspControllerSettings().k_i;
  const auto scheduled = quasi_static_loop(can(), 0.12, 0.0, s, 20.0, 5.0);
  EXPECT_NEAR(scheduled.first, f_static, 0.01 * f_static);
  EXPECT_NEAR(scheduled.second, f_static, 0.01 * f_static);
  const auto full = quasi_static_loop(can(), 2.0, 3e-3, s, 40.0, 5.0);
  EXPECT_NEAR(0.5 * (full.first + full.second), 4.7495, 0.05);
}

// --- beyond the paper: slope gain, feed-forward, slip reflex (docs/controller.md) ----------------
// Consistency tests: the plant below is lugrip's own static map S_static(f_n) (StaticForceSolver)
// behind a first-order force lag; they check the law, not the contact physics (the closed loops
// on the patch and MuJoCo plants are in tests/python/test_controller.py).

namespace {
// S = S_static(f_act) with f_act following the command through a 30 ms first-order lag at the
// sensor rate; returns {min, max} of the command over the last `tail` seconds.
std::pair<double, double> lagged_loop(const ContactParams& p, double ft, double tau,
                                      const GraspControllerSettings& s, double duration, double tail,
                                      double f0 = 2.0) {
  StaticForceSolver plant(p);
  GraspController c(p, s);
  c.reset(f0);
  GraspControllerOutput out;
  double lo = 1e9, hi = 0, f_act = f0;
  const double decay = std::exp(-0.002 / 0.03);
  const int n = static_cast<int>(duration * 500);
  for (int k = 0; k < n; ++k) {
    double ct = 0;
    const double S = std::min(plant.slippage(f_act, ft, tau, &ct), 1.0);
    GraspControllerInput in = one(S, 0.0, ct, ft);
    in.fingers[0].tau = tau;
    c.step(in, out);
    f_act = out.force + (f_act - out.force) * decay;
    if (k >= n - tail * 500) {
      lo = std::min(lo, out.force);
      hi = std::max(hi, out.force);
    }
  }
  return {lo, hi};
}
}  // namespace

TEST(ControllerSlopeGain, LoopGainIsTheSameAtEveryForce) {
  // k_p |dS/df_n| at the settled force, with the slope from the model by central differences.
  double paper_lo = kInf, paper_hi = 0.0;
  for (const double tau : {0.0, 2e-3}) {
    for (const double ft : {0.1, 0.3, 1.0, 3.0, 6.0}) {
      const ContactParams p = can();
      StaticForceSolver solver(p);
      GraspControllerSettings s;
      s.s_ref = 0.8;  // the operating point of the inputs below
      s.max_rate = kInf;
      GraspController c(p, s);
      const double f = solver.solve(ft, tau).force;
      c.reset(f);
      GraspControllerInput in = one(0.8, 0.0, 1.5, ft);
      in.fingers[0].tau = tau;
      const auto out = run(c, in, 21);  // three commands at the set point
      const double h = 1e-4 * f;
      const double slope = (solver.slippage(f - h, ft, tau) - solver.slippage(f + h, ft, tau)) / (2 * h);
      EXPECT_NEAR(out.force, f, 1e-9 * f);
      // n is clamped to [1, 1 + gamma]: mixed loads whose exponent lies inside are exact.
      // the loop gains k |dS/df_n| = k s_ref / gain_force at every force
      const double loop_p = s.k_p * s.s_ref / s.gain_force, loop_i = s.k_i * s.s_ref / s.gain_force;
      EXPECT_NEAR(out.gain_p * slope, loop_p, 0.03 * loop_p) << ft << " " << tau << " f " << f;
      EXPECT_NEAR(out.gain_i * slope, loop_i, 0.03 * loop_i) << ft << " " << tau;
      paper_lo = std::min(paper_lo, 4.0 * slope);  // the paper's constant k_p = 4 N
      paper_hi = std::max(paper_hi, 4.0 * slope);
    }
  }
  // The paper's loop gain spans the force range (0.13-9 N): unstable (> 1) at the low end.
  EXPECT_GT(paper_hi, 10.0);
  EXPECT_LT(paper_lo, 0.5);
}

TEST(ControllerSlopeGain, NoLimitCycleAnywhereInTheForceRange) {
  // Static forces from 0.14 N to 17 N (pure translation): with the slope gain the command settles
  // (peak-to-peak < 0.5 % of the force); the paper's constant gains limit-cycle below ~3 N.
  const ContactParams p = can();
  StaticForceSolver solver(p);
  GraspControllerSettings s;
  s.f_max = 40.0;
  for (const double ft : {0.09, 0.3, 1.0, 3.0, 7.0}) {
    const double f = solver.solve(ft, 0.0, s.s_ref).force;
    const auto r = lagged_loop(p, ft, 0.0, s, 20.0, 3.0);
    EXPECT_LT(r.second - r.first, 0.005 * f) << "ft " << ft << " f " << f;
    EXPECT_NEAR(0.5 * (r.first + r.second), f, 0.01 * f) << ft;
    GraspControllerSettings ps = paper_law();
    ps.f_max = s.f_max;
    const auto paper = lagged_loop(p, ft, 0.0, ps, 20.0, 3.0);
    if (f < 1.0) EXPECT_GT(paper.second - paper.first, 0.5 * f) << "paper law at " << f << " N";
  }
}

TEST(ControllerFeedForward, StaticGraspForceOfTheMeanLoadAtTheNextCommand) {
  const ContactParams p = can();
  StaticForceSolver solver(p);
  GraspControllerSettings s;
  s.max_rate = kInf;
  GraspController c(p, s);
  c.reset(0.1);
  GraspControllerOutput out;
  GraspControllerInput in = one(0.05, 0.0, 1.5, 0.0);
  c.step(in, out);  // first command: unloaded
  ASSERT_TRUE(out.command_issued);
  EXPECT_EQ(out.feedforward_force, 0.0);
  // The load arrives inside the period (two values of f_t, tau, alternating: no trend for the
  // trend's extrapolation, ControllerReaction.*): the next command uses the mean.
  double sum_ft = 0, sum_tau = 0;
  for (int k = 1; k < 10; ++k) {
    in.fingers[0].f_t = k % 2 ? 1.0 : 2.0;
    in.fingers[0].tau = k % 2 ? 1e-3 : 3e-3;
    in.fingers[0].slippage = 0.5;
    sum_ft += in.fingers[0].f_t;
    sum_tau += in.fingers[0].tau;
    c.step(in, out);
    EXPECT_FALSE(out.command_issued);
  }
  c.step(in, out);  // the next command (this sample included)
  ASSERT_TRUE(out.command_issued);
  sum_ft += in.fingers[0].f_t;
  sum_tau += in.fingers[0].tau;
  const double f_ff = solver.solve(sum_ft / 10, sum_tau / 10, 0.9).force;  // S = 0.9
  EXPECT_NEAR(out.feedforward_force, f_ff, 1e-12 * f_ff);
  EXPECT_NEAR(out.static_force, f_ff, 1e-12 * f_ff);  // the PI alone would be far lower
  // Two fingers: the larger of the two forces.
  GraspController two(p, s);
  two.reset(0.1);
  GraspControllerInput in2;
  in2.fingers[0] = FingerInput{0.0, 0.5, 1.5, 1.0, Status::Ok, true, 0.0, 0.0};
  in2.fingers[1] = FingerInput{0.0, 0.5, 0.3, 0.5, Status::Ok, true, 0.0, 4e-3};
  const auto o2 = run(two, in2, 11);
  const double f0 = solver.solve(1.0, 0.0, 0.9).force, f1 = solver.solve(0.5, 4e-3, 0.9).force;
  EXPECT_NEAR(o2.feedforward_force, std::max(f0, f1), 1e-12);
  // Off: the PI alone.
  GraspControllerSettings off = s;
  off.load_floors = false;
  GraspController c_off(p, off);
  c_off.reset(0.1);
  const auto o3 = run(c_off, in2, 11);
  EXPECT_EQ(o3.feedforward_force, 0.0);
  EXPECT_LT(o3.force, 0.2);
}

TEST(ControllerFeedForward, RangeAndRateLimitsStillBound) {
  const ContactParams p = can();
  GraspControllerSettings s;
  s.f_max = 5.0;
  s.max_rate = 10.0;  // 0.2 N per command
  GraspController c(p, s);
  c.reset(0.1);
  GraspControllerInput in = one(0.5, 0.0, 1.5, 20.0);  // needs ~30 N
  GraspControllerOutput out;
  double last = 0.1;
  for (int k = 0; k < 500; ++k) {
    c.step(in, out);
    if (out.command_issued) {
      EXPECT_LE(out.force, last + 0.2 + 1e-12);
      last = out.force;
    }
    EXPECT_LE(out.force, 5.0);
  }
  EXPECT_EQ(out.force, 5.0);
  EXPECT_EQ(out.static_force, 5.0);
  // Pivoting: no feed-forward, the force decays.
  c.request_pivoting();
  const double before = c.command();
  in.fingers[0].c_tilde = 0.5;  // below the pivot end threshold
  in.fingers[0].f_t = 1.0;       // pivoting floor 1.1 f_t / mu below f_max
  out = run(c, in, 100);
  ASSERT_EQ(out.mode, ControllerMode::Pivoting);
  EXPECT_EQ(out.feedforward_force, 0.0);
  EXPECT_LT(out.force, before);
}

TEST(ControllerReflex, RaisesWithinOneCommandPeriodWhenTheSpeedIsUnobservable) {
  // omega_hat = 0 throughout (Coulomb-like contact: C_d adds nothing); S at the projection bound
  // on three consecutive samples inside a period.
  // No load in the inputs (f_t = tau = 0): the feed-forward of the load floors adds nothing.
  auto one = [](double S) { return ::one(S, 0.0, 0.5, 0.0); };
  GraspControllerSettings s;
  s.ceiling_factor = 0.0;  // the inputs' S is not their load's (the ceiling: ClosedLoop.Ceiling*)
  s.s_ref = 0.8;          // the set point of the inputs below
  s.reaction_lag = 0.0;   // the raise itself (the lag compensation: ControllerReaction.*)
  s.max_rate = kInf;
  GraspController c(can(), s);
  c.reset(2.0);
  GraspControllerOutput out = run(c, one(0.8), 11);  // two commands at the set point
  const double f0 = out.force;
  EXPECT_NEAR(f0, 2.0, 1e-12);
  for (int k = 0; k < 9; ++k) {
    c.step(one(k >= 4 && k < 7 ? 1.0 : 0.8), out);
    EXPECT_FALSE(out.command_issued);
  }
  c.step(one(0.8), out);
  ASSERT_TRUE(out.command_issued);
  EXPECT_TRUE(out.reflex);
  EXPECT_GE(out.force, 1.25 * f0 - 1e-12);
  // Isolated samples above the threshold (noise: two per period, fewer than three) do
  // not trigger it.
  GraspController d(can(), s);
  d.reset(2.0);
  out = run(d, one(0.8), 11);
  for (int k = 0; k < 50; ++k) {
    d.step(one(k % 5 == 2 ? 1.0 : 0.8), out);
    EXPECT_FALSE(out.reflex);
  }
  // Every other sample at the bound (a chattering slide: five per period, never three in a row)
  // triggers it: the samples may lie anywhere in the period.
  {
    GraspController g(can(), s);
    g.reset(2.0);
    out = run(g, one(0.8), 11);
    bool fired = false;
    for (int k = 0; k < 20; ++k) {
      g.step(one(k % 2 ? 1.0 : 0.8), out);
      fired = fired || out.reflex;
    }
    EXPECT_TRUE(fired);
  }
  // Without the load floors (the paper's law) only the PI moves (one command: + k_p e at most).
  GraspControllerSettings off = s;
  off.load_floors = false;
  GraspController e(can(), off);
  e.reset(2.0);
  out = run(e, one(0.8), 11);
  for (int k = 0; k < 9; ++k) e.step(one(k >= 4 && k < 7 ? 1.0 : 0.8), out);
  e.step(one(0.8), out);
  EXPECT_FALSE(out.reflex);
  EXPECT_LT(out.force, 1.1 * f0);
}

TEST(ControllerReflex, RepeatsWhileSlidingAndStopsAtTheCeiling) {
  auto one = [](double S) { return ::one(S, 0.0, 0.5, 0.0); };  // no load: no feed-forward
  GraspControllerSettings s;
  s.ceiling_factor = 0.0;  // f_max is the ceiling here
  s.max_rate = kInf;
  GraspController c(can(), s);
  c.reset(1.0);
  GraspControllerOutput out;
  double last = 1.0;
  int raises = 0;
  for (int k = 0; k < 500; ++k) {
    c.step(one(1.0), out);
    if (out.command_issued && k > 0) {
      EXPECT_GE(out.force, std::min(1.25 * last, s.f_max) - 1e-9) << k;
      EXPECT_LE(out.force, s.f_max);
      raises += out.reflex;
      last = out.force;
    }
  }
  EXPECT_EQ(out.force, s.f_max);
  EXPECT_GT(raises, 10);
}
