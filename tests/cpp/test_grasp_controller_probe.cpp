// The grip probe (GraspControllerSettings::mu_probe): friction learned online from the load's
// answer to a small raise of the grip. Consistency tests: the plant below is a quasi-static
// Coulomb contact written here (the friction is min(load, mu_true f_n), the slippage the
// contact model's own static map S_static), not an independent engine; the closed loops on
// MuJoCo are in tests/python/test_mu_learning.py.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "lugrip/grasp_controller.hpp"
#include "lugrip/params.hpp"

using namespace lugrip;

namespace {

constexpr double kDt = 0.002;

struct Result {
  double mu_belief = 0.0;
  double last_force = 0.0;       // the gripper's force at the end [N]
  double mean_force = 0.0;       // over the last `tail` seconds [N]
  double slide_time = 0.0;       // time with the load above the friction capacity [s]
  int probe_slips = 0;
  double first_slip_belief = 0.0;  // the belief right after the first slip found
};

// A translational load `load` [N] per finger on a Coulomb contact with friction mu_true; the
// controller believes the contact model `told` (its mu may be off). The gripper follows the
// command through a 30 ms first-order lag. Sensor noise on f_t: white, std `noise` [N].
Result run(const ContactParams& told, double mu_true, double load, double probe, double seconds,
           double noise = 0.0, double tail = 2.0) {
  GraspControllerSettings s;
  s.mu_probe = probe;
  GraspController c(told, s);
  StaticForceSolver observer_map(told);  // what an observer reads in stick: S_static, <= 1
  c.reset(1.2 * load / told.mu);
  std::mt19937 rng(3);
  std::normal_distribution<double> n01(0.0, 1.0);
  double f = c.command();
  Result r;
  int tail_n = 0;
  const int steps = static_cast<int>(std::lround(seconds / kDt));
  GraspControllerOutput out;
  for (int k = 0; k < steps; ++k) {
    const double capacity = mu_true * f;
    const bool sliding = load > capacity;
    const double ft = (sliding ? capacity : load) + noise * n01(rng);
    GraspControllerInput in;
    for (auto& fi : in.fingers) {
      fi.f_t = std::fabs(ft);
      fi.tau = 0.0;
      fi.f_n = f;
      fi.c_tilde = 1.5;
      fi.slippage = std::min(1.0, observer_map.slippage(f, std::fabs(ft), 0.0));
    }
    c.step(in, out);
    if (out.command_issued && out.probe_slip && ++r.probe_slips == 1) r.first_slip_belief = out.mu_belief;
    f += (out.force - f) * (1.0 - std::exp(-kDt / 0.03));
    if (sliding) r.slide_time += kDt;
    if (k * kDt >= seconds - tail) {
      r.mean_force += f;
      ++tail_n;
    }
  }
  r.mean_force /= tail_n;
  r.mu_belief = c.mu_belief();
  r.last_force = f;
  return r;
}

ContactParams told(double mu) {
  ContactParams p = object_params("small_resin_block");
  p.mu = mu;
  return p;
}

}  // namespace

TEST(ControllerProbe, FindsASlideThatSIndicatesAsStickAndLearnsMu) {
  // mu believed 35 % too high: sliding, S reads mu_true / mu_told ~ 0.74 x 0.95 (the CoR clip),
  // below s_ref, so the PI alone lowers the force while the object slides. The probe's raise
  // makes the friction follow the grip: mu learned, the slide stops.
  const double mu_true = 0.5, load = 1.5;
  const Result with = run(told(1.35 * mu_true), mu_true, load, 0.08, 4.0);
  const Result without = run(told(1.35 * mu_true), mu_true, load, 0.0, 4.0);
  EXPECT_GT(without.slide_time, 3.5);  // slides for good
  EXPECT_LT(with.slide_time, 0.3);
  EXPECT_GE(with.probe_slips, 1);
  // the friction it slid at, read through the model's translational clip (S = 0.95 at mu f_n)
  EXPECT_GT(with.mu_belief, 0.85 * mu_true);
  EXPECT_LT(with.mu_belief, 1.02 * mu_true);
  EXPECT_GT(with.last_force, load / mu_true);  // holds
}

TEST(ControllerProbe, BoundedStepPerProbe) {
  // mu believed 1.8x too high (S ~ 0.53 while sliding): one probe lowers the belief by at most
  // 30 %. The reflex then lifts the grip and the next probe, on the way up, finds stick; the PI
  // lowers the grip again with S flat (a slide), and once the grip is a probe's size below the
  // grip stick was proven at, a probe finds the slide again: the belief ends at the friction.
  const double mu_true = 0.2;
  const ContactParams p = told(1.8 * mu_true);
  const Result r = run(p, mu_true, 1.0, 0.08, 4.0);
  EXPECT_GE(r.probe_slips, 2);
  EXPECT_NEAR(r.first_slip_belief, 0.7 * p.mu, 1e-12);
  EXPECT_GT(r.mu_belief, 0.85 * mu_true);
  EXPECT_LT(r.mu_belief, 1.02 * mu_true);
  EXPECT_GE(r.mu_belief, 0.5 * p.mu);  // never below half the told mu
  EXPECT_LT(r.slide_time, 1.5);
  EXPECT_GT(r.last_force, 1.0 / mu_true);
}

TEST(ControllerProbe, LeavesAStickingContactAloneAndCostsLittle) {
  // True mu as told, a steady load with sensor noise (1 % of the load): no slip is reported,
  // the belief stays, and the probes cost under 2 % of the mean force.
  const double mu = 0.6, load = 1.5;
  for (double noise : {0.0, 0.015}) {
    const Result with = run(told(mu), mu, load, 0.08, 20.0, noise, 15.0);
    const Result without = run(told(mu), mu, load, 0.0, 20.0, noise, 15.0);
    EXPECT_EQ(with.probe_slips, 0) << noise;
    EXPECT_EQ(with.mu_belief, mu) << noise;
    EXPECT_EQ(with.slide_time, 0.0) << noise;
    EXPECT_LT(with.mean_force, 1.02 * without.mean_force) << noise;
  }
}

TEST(ControllerProbe, OffIsThePaperAndNoForceMeansNoProbe) {
  // mu_probe = 0, or inputs without f_n: the belief is the told mu whatever the contact does.
  const double mu_true = 0.5;
  EXPECT_EQ(run(told(0.7), mu_true, 1.5, 0.0, 2.0).mu_belief, 0.7);
  GraspControllerSettings s;
  GraspController c(told(0.7), s);
  c.reset(2.0);
  GraspControllerOutput out;
  GraspControllerInput in;
  for (auto& fi : in.fingers) {
    fi.f_t = 1.0;
    fi.slippage = 0.72;
    fi.c_tilde = 1.5;
  }
  for (int k = 0; k < 2000; ++k) {
    in.fingers[0].f_t = in.fingers[1].f_t = 0.35 * c.command();  // the load follows the grip
    c.step(in, out);
    EXPECT_FALSE(out.probing);
  }
  EXPECT_EQ(c.mu_belief(), 0.7);
}

TEST(ControllerProbe, SetMuIsRealTimeAndRestartsTheBelief) {
  GraspController c(told(0.7));
  EXPECT_TRUE(c.set_mu(0.4));
  EXPECT_EQ(c.mu(), 0.4);
  EXPECT_EQ(c.mu_belief(), 0.4);
  EXPECT_EQ(c.contact_model().params().mu, 0.4);
  for (double bad : {0.0, -1.0, 10.5, std::numeric_limits<double>::quiet_NaN(),
                     std::numeric_limits<double>::infinity()}) {
    EXPECT_FALSE(c.set_mu(bad)) << bad;
    EXPECT_EQ(c.mu(), 0.4);
  }
  // mu is a factor of every contact map: the model changed in place reads what a model built
  // with that mu reads (a translation: exactly twice the slippage at half the mu)
  StaticForceSolver a(told(0.7)), b(told(0.7)), ref(told(0.35));
  ASSERT_TRUE(b.set_mu(0.35));
  for (double tau : {0.0, 1e-3, 5e-3}) {
    const double s_a = a.slippage(4.0, 1.0, tau), s_b = b.slippage(4.0, 1.0, tau);
    if (tau == 0.0) EXPECT_NEAR(s_b, 2.0 * s_a, 1e-12 * s_b);
    EXPECT_NEAR(s_b, ref.slippage(4.0, 1.0, tau), 1e-12 * s_b) << tau;
    EXPECT_NEAR(b.solve(1.0, tau).force, ref.solve(1.0, tau).force, 1e-9 * ref.solve(1.0, tau).force) << tau;
  }
}

TEST(ControllerCommandTiming, TheCallerSaysWhenACommandIsDue) {
  // A gripper fed in batches of 10 samples takes one command per batch: Hold on the first nine,
  // Now on the newest. The command is computed exactly there, from the batch's own samples (the
  // PI's S is their mean), not from the batch's first sample as the clock would.
  GraspControllerSettings s;
  s.ceiling_factor = 0.0;
  GraspController clock(told(0.6), s), caller(told(0.6), s);
  clock.reset(2.0);
  caller.reset(2.0);
  GraspControllerOutput oc, on;
  int issued = 0;
  for (int batch = 0; batch < 20; ++batch) {
    double sum = 0.0;
    for (int k = 0; k < 10; ++k) {
      GraspControllerInput in;
      for (auto& f : in.fingers) {
        f.slippage = 0.5 + 0.04 * k + 0.01 * batch;  // S rising within each batch
        f.c_tilde = 1.5;
      }
      sum += in.fingers[0].slippage;
      clock.step(in, oc);
      in.command = k == 9 ? CommandTiming::Now : CommandTiming::Hold;
      caller.step(in, on);
      EXPECT_EQ(on.command_issued, k == 9) << batch << " " << k;
      issued += on.command_issued;
      EXPECT_EQ(oc.command_issued, k == 0) << batch << " " << k;
    }
    if (batch > 0) EXPECT_NEAR(on.slippage, sum / 10.0, 1e-12) << batch;
  }
  EXPECT_EQ(issued, 20);
  // Unknown codes count as the clock's (a hostile value never silences the controller).
  GraspController odd(told(0.6), s);
  GraspControllerInput in;
  in.command = static_cast<CommandTiming>(7);
  int n = 0;
  for (int k = 0; k < 30; ++k) {
    odd.step(in, on);
    n += on.command_issued;
  }
  EXPECT_EQ(n, 3);
}
