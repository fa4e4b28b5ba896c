// Pivoting mode of the grasp-force controller: the end test that waits for the floor and
// low-passes the mean |c~| (0.2 s), and the end after 1 s at the floor (constants of the law,
// docs/controller.md).
//
// Consistency tests of the law itself: the inputs are synthetic observer values, no plant. The
// physics (a swing through the vertical on MuJoCo) is in tests/python/test_pivot_mujoco.py.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "lugrip/grasp_controller.hpp"

using namespace lugrip;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kDt = 0.002;   // default sensor period [s]
constexpr double kTcmd = 0.02;  // default command period [s]
constexpr double kS = 0.95;     // slippage of a contact at rest near its limit (below 0.99)

ContactParams can() { return object_params("aluminium_can"); }  // mu = 0.75

GraspControllerInput one(double S, double c_tilde, double f_t) {
  GraspControllerInput in;
  in.fingers[0] = FingerInput{0.0, S, c_tilde, f_t, Status::Ok, true};
  in.fingers[1].present = false;
  return in;
}

// Default settings, unlimited rates (the filter's decay is then exact).
GraspControllerSettings free_rates() {
  GraspControllerSettings s;
  s.max_rate = kInf;
  return s;
}

// Time [s] at which the pivoting filter, started from f0 with S = kS and the default
// tau_p = 2 s, k_f = 4, s_pivot = 1.3, first computes an update below `floor`: the commands
// output f0, f1, ... with f_{n+1} = a f_n + (1 - a) k_f (kS - 1.3); command n at n T_cmd.
// Steps c with the same input until its pivot ends (at most 100000 samples); the samples taken.
long steps_to_pivot_end(GraspController& c, const GraspControllerInput& in, GraspControllerOutput& out) {
  long n = 0;
  do {
    c.step(in, out);
    ++n;
  } while (!out.pivot_finished && n < 100000);
  return n;
}

double first_command_wanting_below(double f0, double floor) {
  const double a = std::exp(-kTcmd / 2.0), target = 4.0 * (kS - 1.3);
  double f = f0;
  for (int n = 0; n < 100000; ++n) {
    const double next = a * f + (1.0 - a) * target;
    if (next <= floor) return n * kTcmd;
    f = next;
  }
  return kInf;
}

}  // namespace

// Reference for the end test: samples until the low-pass (time constant tc, started at the
// first value) of the sequence c(n) stays above 1 on 3 consecutive samples.
template <class F>
int samples_to_end(F c, double tc, int from = 0) {
  const double a = 1.0 - std::exp(-kDt / tc);
  double y = c(0);
  int count = 0;
  for (int n = 0; n < 100000; ++n) {
    if (n > 0) y += a * (c(n) - y);
    count = (n >= from && y > 1.0) ? count + 1 : 0;
    if (count >= 3) return n + 1;
  }
  return -1;
}

TEST(PivotEnd, WaitsForTheFloor) {
  // |c~| above the threshold from the first pivoting sample (as when the torque passes through
  // zero at a swing's turning point): the paper's test ends at the third sample; the default
  // ends three samples after the filter first wants to go below its floor.
  GraspController c(can(), free_rates());
  c.reset(6.0);  // the first call after reset computes a command: the pivot starts with it
  GraspControllerOutput out;
  c.request_pivoting();
  const auto in = one(kS, 1.4, 0.2);
  const double floor = 1.1 * 0.2 / 0.75;
  const double t_floor = first_command_wanting_below(6.0, floor);
  ASSERT_GT(t_floor, 2.7);  // -1.4 + 7.4 exp(-t / 2) = floor at t = 2.9 s
  ASSERT_LT(t_floor, 3.1);
  long n = 0;
  double before_end = 0.0;
  do {
    before_end = out.force;
    c.step(in, out);
    ++n;
    if (!out.pivot_finished) ASSERT_EQ(out.mode, ControllerMode::Pivoting) << n;
  } while (!out.pivot_finished && n < 100000);
  // the flag is set by the command of call t_floor / dt + 1; counting starts at the next call
  EXPECT_NEAR(n * kDt, t_floor + 4 * kDt, 1e-9);
  EXPECT_EQ(out.pivot_end, PivotEnd::CorThreshold);
  // the last command output the filter state before its update, one step above the floor
  EXPECT_GT(before_end, floor);
  EXPECT_LT(before_end, floor + 0.02);
  EXPECT_EQ(out.mode, ControllerMode::SlippingAvoidance);
  EXPECT_STREQ(to_string(PivotEnd::AtFloor), "held at the floor");
}

TEST(PivotEnd, ATurningPointAtTheFloorDoesNotEndIt) {
  // At the floor (from 0.7 s), |c~| at 1.3 for 0.1 s between 0.4 and 0.7: the low-pass (0.2 s)
  // stays below 1; a lasting 1.3 ends it when the low-pass has been above 1 on three samples
  // (before 1 s at the floor).
  GraspController c(can(), free_rates());
  c.reset(1.0);
  c.request_pivoting();
  GraspControllerOutput out;
  auto seq = [](int n) { return n < 500 ? 0.4 : n < 550 ? 1.3 : n < 551 ? 0.7 : 1.3; };
  int n = 0;
  do {
    c.step(one(kS, n >= 500 && n < 550 ? -seq(n) : seq(n), 0.2), out);  // |c~| is used
    ++n;
    if (n <= 551) ASSERT_FALSE(out.pivot_finished) << n;
  } while (!out.pivot_finished && n < 5000);
  ASSERT_NEAR(out.floor, 1.1 * 0.2 / 0.75, 1e-12);
  EXPECT_EQ(n, samples_to_end(seq, 0.2));
  EXPECT_GT(n, 551 + 50);  // about 0.12 s after the lasting 1.3 began
  EXPECT_EQ(out.pivot_end, PivotEnd::CorThreshold);
}

TEST(PivotEnd, InvalidSamplesRestartTheCount) {
  GraspController c(can(), free_rates());
  c.reset(0.3);  // at the floor (0.293 N) from the first command
  c.request_pivoting();
  GraspControllerOutput out;
  c.step(one(kS, 1.3, 0.2), out);  // the command: the filter wants to go below the floor
  c.step(one(kS, 1.3, 0.2), out);
  c.step(one(kS, 1.3, 0.2), out);
  EXPECT_FALSE(out.pivot_finished);  // two samples counted
  GraspControllerInput bad = one(kS, 1.3, 0.2);
  bad.fingers[0].status = Status::SensorFault;
  c.step(bad, out);
  EXPECT_FALSE(out.pivot_finished);
  c.step(one(kS, 1.3, 0.2), out);
  c.step(one(kS, 1.3, 0.2), out);
  EXPECT_FALSE(out.pivot_finished);
  c.step(one(kS, 1.3, 0.2), out);
  EXPECT_TRUE(out.pivot_finished);
  EXPECT_EQ(out.pivot_end, PivotEnd::CorThreshold);
}

TEST(PivotEnd, EndsAfterTheTimeAtTheFloorWhenTheCoRStaysIn) {
  // With the identified limit surface, an object at rest near the vertical may read |c~| < 1:
  // after 1 s at the floor the pivot ends anyway (AtFloor).
  GraspController c(can(), free_rates());
  c.reset(0.5);
  c.request_pivoting();
  const double floor = 1.1 * 0.2 / 0.75;
  const double t_floor = first_command_wanting_below(0.5, floor);
  GraspControllerOutput out;
  long n = steps_to_pivot_end(c, one(kS, 0.9, 0.2), out);
  EXPECT_EQ(out.pivot_end, PivotEnd::AtFloor);
  EXPECT_NEAR(n * kDt, t_floor + 1.0 + kDt, 1e-9);
  EXPECT_EQ(out.mode, ControllerMode::SlippingAvoidance);
  // a load rise lifts the floor: the filter is clamped up to it and still counts as held there
  GraspController d(can(), free_rates());
  d.reset(0.5);
  d.request_pivoting();
  n = 0;
  do {
    d.step(one(kS, 0.9, n < 400 ? 0.2 : 0.4), out);
    ++n;
  } while (!out.pivot_finished && n < 100000);
  EXPECT_EQ(out.pivot_end, PivotEnd::AtFloor);
  EXPECT_NEAR(n * kDt, t_floor + 1.0 + kDt, 1e-9);
}

TEST(PivotEnd, BumplessReturnAtTheFloorAndTheNextPivotStartsAfresh) {
  GraspController c(can(), free_rates());
  c.reset(2.0);
  c.request_pivoting();
  GraspControllerOutput out;
  int n = 0;
  double last = 0.0;
  do {
    last = c.command();
    c.step(one(0.8, 1.4, 0.3), out);  // S below the sliding bound
    ++n;
  } while (!out.pivot_finished && n < 100000);
  ASSERT_TRUE(out.pivot_finished);
  EXPECT_GT(last, 1.1 * 0.3 / 0.75);  // one filter step above the floor
  EXPECT_LT(last, 1.1 * 0.3 / 0.75 + 0.02);
  // next command: slipping avoidance from the last command (no jump at the hand-over; the
  // feed-forward of the measured load may only lift it)
  do c.step(one(0.8, 1.4, 0.3), out);
  while (!out.command_issued);
  EXPECT_EQ(out.mode, ControllerMode::SlippingAvoidance);
  EXPECT_GE(out.force, last - 1e-12);
  EXPECT_LE(out.force, last + 200.0 * kTcmd);
  // a new pivot far above the floor inherits neither the floor flag nor the counts
  c.reset(6.0);
  c.request_pivoting();
  for (int i = 0; i < 500; ++i) {
    c.step(one(kS, 1.4, 0.3), out);
    ASSERT_FALSE(out.pivot_finished) << i;
  }
  EXPECT_EQ(out.mode, ControllerMode::Pivoting);
}

TEST(PivotEnd, ASlidingContactDoesNotEndItOnTheCoR) {
  // S at the projection bound (1: the contact slides, the object still turns) blocks the CoR
  // test even at the floor with |c~| = 1.4; the time at the floor ends it.
  GraspController c(can(), free_rates());
  c.reset(0.3);
  c.request_pivoting();
  GraspControllerOutput out;
  long n = steps_to_pivot_end(c, one(1.0, 1.4, 0.2), out);
  EXPECT_EQ(out.pivot_end, PivotEnd::AtFloor);
  EXPECT_NEAR(n * kDt, 1.0 + kDt, 1e-9);
  // below the bound the same input ends it after three samples at the floor
  GraspController d(can(), free_rates());
  d.reset(0.3);
  d.request_pivoting();
  n = steps_to_pivot_end(d, one(0.98, 1.4, 0.2), out);
  EXPECT_EQ(out.pivot_end, PivotEnd::CorThreshold);
  EXPECT_EQ(n, 4);
}
