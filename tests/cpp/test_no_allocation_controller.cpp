// GraspController::step() and StaticForceSolver never allocate: this binary replaces the global
// operator new and counts calls while stepping.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <new>
#include <random>

#include "lugrip/grasp_controller.hpp"

#include "counting_new.hpp"

using namespace lugrip;

TEST(NoAllocation, GraspControllerStep) {
  GraspController c(object_params("aluminium_can"));
  StaticForceSolver plant(object_params("aluminium_can"));
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  GraspControllerInput in;
  GraspControllerOutput out;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const long before = lugrip_support::g_allocations.load();
  for (int n = 0; n < 100000; ++n) {
    for (auto& f : in.fingers) {
      f.omega_hat = u(rng) < 0.01 ? nan : 0.1 * (u(rng) - 0.5);
      f.slippage = u(rng);
      f.c_tilde = 2.0 * u(rng);
      f.f_t = u(rng);
      f.tau = 2e-3 * (u(rng) - 0.5);  // feed-forward and slope of the controller
      f.status = static_cast<Status>(rng() % 7);
    }
    if (n % 5000 == 100) c.request_pivoting();
    if (n % 5000 == 2600) c.request_slipping_avoidance();
    if (n % 20000 == 7) c.set_dynamic_enabled(n % 40000 != 7);
    c.step(in, out);
  }
  StaticForceResult r;
  for (int n = 0; n < 200; ++n) r = plant.solve(0.1 + 0.02 * n, 1e-4 * n);
  const long used = lugrip_support::g_allocations.load() - before;
  EXPECT_EQ(used, 0);
  EXPECT_TRUE(std::isfinite(out.force));
  EXPECT_TRUE(r.converged);
}
