// Pivoting mode of the grasp-force controller: the end criterion that waits for the floor and a
// held |c~| (pivot_end_at_floor, pivot_end_hold), against the paper's 3-sample test.
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

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kDt = 0.002;   // default sensor period [s]
constexpr double kTcmd = 0.02;  // default command period [s]

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
  s.max_rate_up = s.max_rate_down = kInf;
  return s;
}

// Time [s] at which the pivoting filter, started from f0 with S = 1 and the default
// tau_p = 2 s, k_f = 4, s_pivot = 1.3, first computes an update below `floor`: the commands
// output f0, f1, ... with f_{n+1} = a f_n + (1 - a) (-1.2); command n happens at n T_cmd.
double first_command_wanting_below(double f0, double floor) {
  const double a = std::exp(-kTcmd / 2.0), target = 4.0 * (1.0 - 1.3);
  double f = f0;
  for (int n = 0; n < 100000; ++n) {
    const double next = a * f + (1.0 - a) * target;
    if (next <= floor) return n * kTcmd;
    f = next;
  }
  return kInf;
}

}  // namespace

TEST(PivotEndSettings, ValidatedAndDumped) {
  for (double bad : {-0.1, kNaN, kInf, 2.0e6}) {
    GraspControllerSettings s;
    s.pivot_end_hold = bad;
    std::string msg;
    EXPECT_FALSE(validate(s, &msg)) << bad;
    EXPECT_EQ(msg.rfind("pivot_end_hold = ", 0), 0u) << msg;
    EXPECT_THROW(GraspController(can(), s), std::invalid_argument);
  }
  GraspControllerSettings s;
  EXPECT_EQ(s.pivot_end_hold, 0.2);
  EXPECT_TRUE(s.pivot_end_at_floor);
  s.pivot_end_hold = 0.0;  // the paper's law
  EXPECT_TRUE(validate(s, nullptr));
  const std::string dump = to_string(s);
  EXPECT_NE(dump.find("pivot_end_hold=0"), std::string::npos) << dump;
  EXPECT_NE(dump.find("pivot_end_at_floor=True"), std::string::npos) << dump;
}

TEST(PivotEnd, WaitsForTheFloorThenForTheHoldTime) {
  // c~ above the threshold from the first pivoting sample (as when the torque passes through
  // zero at a swing's turning point): the paper's test would end at the third sample; the
  // default ends pivot_end_hold after the filter first wants to go below its floor.
  GraspController c(can(), free_rates());
  c.reset(6.0);  // the first call after reset computes a command: the pivot starts with it
  GraspControllerOutput out;
  c.request_pivoting();
  const auto in = one(1.0, 1.4, 0.2);
  const double floor = 1.1 * 0.2 / 0.75;
  const double t_floor = first_command_wanting_below(6.0, floor);
  ASSERT_GT(t_floor, 3.0);  // -1.2 + 7.2 exp(-t / 2) = floor at t = 3.15 s
  ASSERT_LT(t_floor, 3.3);
  long n = 0;
  double before_end = 0.0;
  do {
    before_end = out.force;
    c.step(in, out);
    ++n;
    if (!out.pivot_finished) ASSERT_EQ(out.mode, ControllerMode::Pivoting) << n;
  } while (!out.pivot_finished && n < 100000);
  const double t_end = n * kDt;
  // counting starts at the sample after that command: t_floor + hold + one sample
  EXPECT_NEAR(t_end, t_floor + 0.2 + kDt, 1e-9);
  EXPECT_EQ(out.pivot_end, PivotEnd::CorThreshold);
  EXPECT_NEAR(before_end, floor, 1e-12);
  EXPECT_EQ(out.mode, ControllerMode::SlippingAvoidance);

  // The paper's law on the same input: three samples.
  GraspControllerSettings paper = free_rates();
  paper.pivot_end_hold = 0.0;
  paper.pivot_end_at_floor = false;
  GraspController p(can(), paper);
  p.reset(6.0);
  p.request_pivoting();
  for (int i = 0; i < 2; ++i) {
    p.step(in, out);
    EXPECT_FALSE(out.pivot_finished);
  }
  p.step(in, out);
  EXPECT_TRUE(out.pivot_finished);
  EXPECT_EQ(out.force, 6.0);
}

TEST(PivotEnd, ATurningPointAtTheFloorDoesNotEndIt) {
  // At the floor, |c~| above the threshold for 0.1 s (< pivot_end_hold), then below: the count
  // restarts; a second, long enough run ends it after exactly pivot_end_hold.
  GraspController c(can(), free_rates());
  c.reset(0.5);
  c.request_pivoting();
  GraspControllerOutput out;
  for (int i = 0; i < 500; ++i) {  // 1 s at c~ = 0.4: the filter reaches the floor 0.293 N
    c.step(one(1.0, 0.4, 0.2), out);
    ASSERT_FALSE(out.pivot_finished);
  }
  ASSERT_NEAR(out.force, 1.1 * 0.2 / 0.75, 1e-12);
  for (int i = 0; i < 50; ++i) {
    c.step(one(1.0, -1.3, 0.2), out);  // |c~| is used
    ASSERT_FALSE(out.pivot_finished) << i;
  }
  c.step(one(1.0, 0.7, 0.2), out);
  EXPECT_FALSE(out.pivot_finished);
  int n = 0;
  do {
    c.step(one(1.0, 1.3, 0.2), out);
    ++n;
  } while (!out.pivot_finished && n < 1000);
  EXPECT_EQ(n, 100);  // 0.2 s at 500 Hz
  EXPECT_EQ(out.pivot_end, PivotEnd::CorThreshold);
}

TEST(PivotEnd, WithoutTheFloorConditionTheHoldTimeAloneCounts) {
  GraspControllerSettings s = free_rates();
  s.pivot_end_at_floor = false;
  s.pivot_end_hold = 0.05;
  GraspController c(can(), s);
  c.reset(8.0);
  c.request_pivoting();
  GraspControllerOutput out;
  int n = 0;
  do {
    c.step(one(1.0, 1.2, 0.2), out);
    ++n;
  } while (!out.pivot_finished && n < 1000);
  EXPECT_EQ(n, 25);  // 0.05 s; far above the floor
  EXPECT_GT(out.force, 7.0);
}

TEST(PivotEnd, InvalidSamplesRestartTheCount) {
  GraspController c(can(), free_rates());
  c.reset(0.3);
  c.request_pivoting();
  GraspControllerOutput out;
  for (int i = 0; i < 100; ++i) c.step(one(1.0, 0.4, 0.2), out);  // at the floor
  for (int i = 0; i < 90; ++i) c.step(one(1.0, 1.3, 0.2), out);
  GraspControllerInput bad = one(1.0, 1.3, 0.2);
  bad.fingers[0].status = Status::SensorFault;
  c.step(bad, out);
  EXPECT_FALSE(out.pivot_finished);
  for (int i = 0; i < 20; ++i) {
    c.step(one(1.0, 1.3, 0.2), out);
    ASSERT_FALSE(out.pivot_finished) << i;
  }
  // still at the floor: ends 0.2 s (100 valid samples) after the fault
  int n = 20;
  do {
    c.step(one(1.0, 1.3, 0.2), out);
    ++n;
  } while (!out.pivot_finished && n < 1000);
  EXPECT_EQ(n, 100);
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
    c.step(one(0.8, 1.4, 0.3), out);  // S below the reflex threshold
    ++n;
  } while (!out.pivot_finished && n < 100000);
  ASSERT_TRUE(out.pivot_finished);
  EXPECT_NEAR(last, 1.1 * 0.3 / 0.75, 1e-12);
  // next command: slipping avoidance from the last command (no jump at the hand-over; the
  // feed-forward of the measured load may only lift it)
  do c.step(one(0.8, 1.4, 0.3), out);
  while (!out.command_issued);
  EXPECT_EQ(out.mode, ControllerMode::SlippingAvoidance);
  EXPECT_GE(out.force, last - 1e-12);
  EXPECT_LE(out.force, last + 200.0 * kTcmd);
  // a new pivot far above the floor does not inherit the floor flag nor the count
  c.reset(6.0);
  c.request_pivoting();
  for (int i = 0; i < 500; ++i) {
    c.step(one(1.0, 1.4, 0.3), out);
    ASSERT_FALSE(out.pivot_finished) << i;
  }
  EXPECT_EQ(out.mode, ControllerMode::Pivoting);
}
