// SlipControl::step() and its run-time calls (set_mu included) never allocate: this binary replaces the global
// operator new and counts calls while stepping (random wrenches, NaN, contact loss, requests).
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <limits>
#include <new>
#include <random>

#include "lugrip/slip_control.hpp"

#include "counting_new.hpp"

using namespace lugrip;

TEST(NoAllocation, SlipControlStep) {
  SlipControl sc(object_params("aluminium_can"));
  SlipControlSettings one;
  one.fingers = 1;
  SlipControl single(object_params("plastic_bottle"), one);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  SlipControlInput in;
  SlipControlOutput out, out1;
  const long before = lugrip_support::g_allocations.load();
  for (int n = 0; n < 100000; ++n) {
    for (auto& f : in.fingers) {
      f.f_n = u(rng) < 0.02 ? 0.0 : 0.5 + 5.0 * u(rng);
      f.f_x = 0.5 * (u(rng) - 0.5);
      f.f_y = u(rng) < 0.01 ? nan : 0.5 * (u(rng) - 0.5);
      f.tau = 0.01 * (u(rng) - 0.5);
    }
    in.dt = u(rng) < 0.05 ? 0.001 + 0.002 * u(rng) : 0.0;
    if (n % 5000 == 100) sc.request_pivoting();
    if (n % 5000 == 2600) sc.request_slipping_avoidance();
    if (n % 20000 == 7) sc.set_dynamic_enabled(n % 40000 != 7);
    if (n % 30000 == 9) sc.reset(2.0);
    if (n % 7000 == 11) sc.set_mu(0.3 + u(rng));  // the per-object refit, mid-loop
    if (n % 9000 == 13) sc.set_mu(nan);           // refused, nothing changed
    sc.step(in, out);
    single.step(in, out1);
  }
  const long used = lugrip_support::g_allocations.load() - before;
  EXPECT_EQ(used, 0);
  EXPECT_TRUE(std::isfinite(out.force));
  EXPECT_TRUE(std::isfinite(out1.force));
}
