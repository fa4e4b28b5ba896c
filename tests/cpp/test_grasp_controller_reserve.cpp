// Standing reserve of the grasp-force controller (reserve_force, reserve_torque): the static
// part is floored at the static grasp force, at the sliding limit S = 1, of the measured load
// plus the reserve, so a push up to the reserve that arrives faster than a command period finds
// the force already there.
//
// Consistency tests of the law: synthetic observer values, reference forces from the model's
// own StaticForceSolver and from the closed form of a pure translational load (f = f_t / mu).
// The closed loops on MuJoCo are in tests/python/test_reserve.py.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "lugrip/grasp_controller.hpp"
#include "lugrip/params.hpp"

using namespace lugrip;

namespace {

ContactParams box() {
  ContactParams p = object_params("small_resin_block");
  p.mu = 0.6;
  return p;
}

GraspControllerInput both(double S, double f_t, double tau) {
  GraspControllerInput in;
  for (auto& f : in.fingers) {
    f.slippage = S;
    f.c_tilde = 1.5;
    f.f_t = f_t;
    f.tau = tau;
  }
  return in;
}

// Settled command after `periods` command periods at a constant input.
double settle(GraspController& c, const GraspControllerInput& in, int periods = 200) {
  GraspControllerOutput out;
  for (int k = 0; k < periods * c.settings().command_ratio; ++k) c.step(in, out);
  return out.force;
}

GraspControllerSettings quiet() { return {}; }  // the inputs have omega_hat = 0: C_d adds nothing

}  // namespace

TEST(ControllerReserve, TranslationalReserveHoldsTheLoadPlusThePushAtTheSlidingLimit) {
  // Pure translation: g = mu f_n at the clip, so the force at S = 1 for f_t + r is (f_t + r) / mu
  // (the estimator's |c~| clip at c_max makes S = 0.95 at f_t = mu f_n: the solver's force is
  // the model's, compared with the closed form to 6 %). Without the reserve the PI, at
  // S = 0.3 << s_ref, unwinds to the feed-forward of the load alone (at S = 0.9).
  const ContactParams p = box();
  GraspControllerSettings s = quiet();
  s.reserve_force = 1.5;
  GraspController c(p, s);
  c.reset(2.0);
  const double f = settle(c, both(0.3, 2.2, 0.0));
  StaticForceSolver solver(p);
  EXPECT_NEAR(f, solver.solve(2.2 + 1.5, 0.0, 1.0).force, 1e-9);
  EXPECT_NEAR(f, (2.2 + 1.5) / 0.6, 0.06 * (2.2 + 1.5) / 0.6);
  GraspController off(p, quiet());
  off.reset(2.0);
  const double ff = solver.solve(2.2, 0.0, 0.9).force;  // the feed-forward's S = 0.9
  EXPECT_NEAR(settle(off, both(0.3, 2.2, 0.0)), ff, 1e-9);
  EXPECT_GT(f, 1.5 * ff);
}

TEST(ControllerReserve, TorqueReserveAddsToTheMeasuredTwistWhateverItsSign) {
  const ContactParams p = box();
  StaticForceSolver solver(p);
  GraspControllerSettings s = quiet();
  s.reserve_torque = 0.005;
  for (const double tau : {0.004, -0.004}) {
    GraspController c(p, s);
    c.reset(2.0);
    const double f = settle(c, both(0.3, 1.0, tau));
    EXPECT_NEAR(f, solver.solve(1.0, 0.009, 1.0).force, 1e-9) << tau;
    EXPECT_GT(f, solver.solve(1.0, 0.004, 1.0).force * 1.3) << tau;  // the reserve matters
  }
}

TEST(ControllerReserve, AboveTheReserveThePiStillRegulates) {
  // S held above s_ref (the observer reads a load the model underrates) raises the force beyond
  // the floor: the reserve is a floor, never a cap. 2 s at e = 0.15 with the slope gains
  // (k_i f / gain_force = 2.5 f) grow the force by about exp(2.5 * 0.15 * 2) = 2.1.
  const ContactParams p = box();
  GraspControllerSettings s = quiet();
  s.reserve_force = 1.0;
  s.f_max = 40.0;
  GraspController c(p, s);
  c.reset(2.0);
  const double floor = StaticForceSolver(p).solve(2.2 + 1.0, 0.0, 1.0).force;
  const double f = settle(c, both(0.95, 2.2, 0.0), 100);
  EXPECT_GT(f, 1.5 * floor);
}

TEST(ControllerReserve, ValidationNamesANegativeOrNonFiniteReserve) {
  for (const double v : {-1.0, std::nan(""), HUGE_VAL}) {
    GraspControllerSettings s;
    s.reserve_force = v;
    s.reserve_torque = v;
    std::string msg;
    EXPECT_FALSE(validate(s, &msg));
    EXPECT_NE(msg.find("reserve_force"), std::string::npos) << msg;
    EXPECT_NE(msg.find("reserve_torque"), std::string::npos) << msg;
  }
  GraspControllerSettings s;
  EXPECT_TRUE(validate(s, nullptr));
  EXPECT_EQ(s.reserve_force, 0.0);  // off by default: the paper's margin S_ref alone
  EXPECT_EQ(s.reserve_torque, 0.0);
  EXPECT_NE(to_string(s).find("reserve_torque=0"), std::string::npos);
}

// --- the reserve learned from the pushes (no setting; part of the load floors) --------------

namespace {
// A settled 2.2 N load, a 1 N push for 0.2 s (100 samples), then the load again for 40 ms;
// *during: the reserve at the push's last sample.
void push_and_return(GraspController& c, GraspControllerOutput& out, double* during = nullptr) {
  c.reset(2.0);
  settle(c, both(0.3, 2.2, 0.0));
  for (int k = 0; k < 100; ++k) c.step(both(0.3, 3.2, 0.0), out);
  if (during) *during = out.reserve_force;
  for (int k = 0; k < 20; ++k) c.step(both(0.3, 2.2, 0.0), out);
}
}  // namespace

TEST(ControllerReserve, APushSeenIsLearnedAsAReserveThatDecaysOverTenSeconds) {
  // Synthetic observer values (the model's own solver as the reference): a steady 2.2 N load,
  // a 1 N push for 0.2 s, then the load again. After the push the floor holds the load plus 0.6
  // of the push at S = 1; the learned excursion forgets with a 10 s time constant (its peak
  // too), so 10 s later the reserve is e^-1 of it to within the decay of the peak.
  const ContactParams p = box();
  GraspController c(p, quiet());
  GraspControllerOutput out;
  double during = -1.0;
  push_and_return(c, out, &during);
  EXPECT_NEAR(during, 0.0, 1e-12);  // the push itself: nothing came and went yet
  // the peak decays over 10 s from 3.2 toward 2.2 while the excursion is measured
  EXPECT_NEAR(out.reserve_force, 0.6 * 1.0, 0.6 * 0.02);
  // the PI at S = 0.3 unwinds onto the floor: the load plus the reserve at S = 1
  StaticForceSolver solver(p);
  for (int k = 0; k < 500; ++k) c.step(both(0.3, 2.2, 0.0), out);  // 1 s
  EXPECT_NEAR(out.force, solver.solve(2.2 + out.reserve_force, 0.0, 1.0).force, 1e-6 * out.force);
  EXPECT_GT(out.force, 1.1 * solver.solve(2.2, 0.0, 0.9).force);  // above the feed-forward alone
  const double r0 = out.reserve_force;
  for (int k = 0; k < 5000; ++k) c.step(both(0.3, 2.2, 0.0), out);  // 10 s
  EXPECT_NEAR(out.reserve_force / r0, std::exp(-1.0), 0.02);
}

TEST(ControllerReserve, ALoadThatFallsToNothingIsAReleaseNotAPush) {
  // The excursion is learned only while the finger carries half its peak load: a release
  // (2.2 N to nothing, here within one sample) leaves at most what the one period straddling
  // the fall shows (its mean 9/10 of the load), far from the 0.6 x 2.2 N a push would leave.
  const ContactParams p = box();
  GraspController c(p, quiet());
  c.reset(2.0);
  settle(c, both(0.3, 2.2, 0.0));
  GraspControllerOutput out;
  for (int k = 0; k < 200; ++k) c.step(both(0.0, 0.0, 0.0), out);
  EXPECT_LE(out.reserve_force, 0.6 * 0.5 * 2.2);
  EXPECT_LT(out.reserve_force, 0.2 * 0.6 * 2.2);
  EXPECT_DOUBLE_EQ(out.reserve_torque, 0.0);
  // and the paper's law learns nothing
  GraspController paper(p, paper_settings());
  push_and_return(paper, out);
  EXPECT_DOUBLE_EQ(out.reserve_force, 0.0);
}

TEST(ControllerReserve, TheStatedReserveWinsWhereItIsLarger) {
  const ContactParams p = box();
  GraspControllerSettings s = quiet();
  s.reserve_force = 2.0;
  GraspController c(p, s);
  GraspControllerOutput out;
  push_and_return(c, out);
  EXPECT_DOUBLE_EQ(out.reserve_force, 2.0);
}
