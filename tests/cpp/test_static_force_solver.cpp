// StaticForceSolver::force(): the static grasp force without solve()'s checking evaluation where
// that check cannot fail. The reference is solve() itself (the map's root accepted only after the
// estimator evaluated at it agrees, and its bracket fallback where not), so the plant here is
// lugrip's own static map; solve() is checked against bisection of the estimator in
// test_grasp_controller.cpp (ClosedFormRootAgreesWithBisectionOfTheMap).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <vector>

#include "lugrip/grasp_controller.hpp"
#include "lugrip/params.hpp"

using namespace lugrip;

namespace {

// Same double bit for bit (NaN: any NaN).
bool same_bits(double a, double b) {
  if (std::isnan(a) && std::isnan(b)) return true;
  std::uint64_t x, y;
  std::memcpy(&x, &a, sizeof x);
  std::memcpy(&y, &b, sizeof y);
  return x == y;
}

std::vector<ContactParams> contacts() {
  std::vector<ContactParams> out;
  for (const char* name : {"aluminium_can", "small_resin_block", "plastic_bottle", "big_resin_block"})
    out.push_back(object_params(name));
  ContactParams p = object_params("small_resin_block");
  p.k = 2.0;  // Hertzian pressure
  out.push_back(p);
  p.k = std::numeric_limits<double>::infinity();  // uniform pressure
  out.push_back(p);
  p.k = kEllipticLimitSurface;  // closed-form ellipse
  out.push_back(p);
  p = object_params("aluminium_can");
  p.c_max = 1000.0;  // the clip far away: pure translations reach large |c~|
  out.push_back(p);
  p = object_params("plastic_bottle");
  p.c_max = 0.3;  // the clip inside the usual range: many roots at the clip
  out.push_back(p);
  return out;
}

}  // namespace

TEST(StaticForceSolverForce, EqualsSolveBitForBitOverLoadsReferencesAndContacts) {
  // Loads from pure translation to pure torsion over eight decades each, with components next to
  // the estimator's zero thresholds (1e-4 of mu f_n and of tau_max) at the forces involved, so
  // that both the skipped check and the full path (check, re-map, bracket) are exercised.
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> lf(-8.0, 2.0), lt(-10.0, -0.5), u(0.0, 1.0);
  const double refs[] = {0.3, 0.5, 0.8, 0.9, 1.0};
  int n = 0;
  for (const ContactParams& p : contacts()) {
    StaticForceSolver solver(p);
    for (int k = 0; k < 1500; ++k) {
      if (k == 750) ASSERT_TRUE(solver.set_mu(0.5 * p.mu));  // the belief lowered at run time
      const double ft = u(rng) < 0.05 ? 0.0 : std::pow(10.0, lf(rng)) * (u(rng) < 0.2 ? -1.0 : 1.0);
      const double tau = u(rng) < 0.05 ? 0.0 : std::pow(10.0, lt(rng)) * (u(rng) < 0.5 ? -1.0 : 1.0);
      const double s_ref = refs[k % 5];
      const StaticLoadMap m = solver.map(ft, tau);
      const double fast = solver.force(m, ft, tau, s_ref);
      const double full = solver.solve(m, ft, tau, s_ref).force;
      ASSERT_TRUE(same_bits(fast, full)) << "k " << p.k << " c_max " << p.c_max << " ft " << ft << " tau " << tau
                                         << " s_ref " << s_ref << ": " << fast << " vs " << full;
      ASSERT_TRUE(same_bits(solver.force(ft, tau, s_ref), solver.solve(ft, tau, s_ref).force))
          << ft << " " << tau << " " << s_ref;
      ++n;
    }
  }
  EXPECT_EQ(n, 1500 * static_cast<int>(contacts().size()));
}

TEST(StaticForceSolverForce, ArgumentsOutsideTheRangeGiveWhatSolveGives) {
  StaticForceSolver solver(object_params("small_resin_block"));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const StaticLoadMap m = solver.map(0.5, 2e-3);
  ASSERT_TRUE(m.valid && m.inside);
  for (double s_ref : {0.0, -0.5, 1.5, nan})
    EXPECT_TRUE(same_bits(solver.force(m, 0.5, 2e-3, s_ref), solver.solve(m, 0.5, 2e-3, s_ref).force)) << s_ref;
  EXPECT_EQ(solver.force(0.0, 0.0, 0.9), 0.0);  // no load: no force
  EXPECT_TRUE(std::isnan(solver.force(nan, 1e-3, 0.9)));
  EXPECT_TRUE(std::isnan(solver.force(StaticLoadMap{}, nan, 1e-3, 0.9)));
  // A map that is not map()'s (no inside flag) always goes through solve()'s check.
  StaticLoadMap other = m;
  other.inside = false;
  EXPECT_TRUE(same_bits(solver.force(other, 0.5, 2e-3, 0.9), solver.solve(other, 0.5, 2e-3, 0.9).force));
  // The skipped check would have accepted the root: S there is s_ref to the estimator's accuracy.
  const double f = solver.force(m, 0.5, 2e-3, 0.9);
  EXPECT_NEAR(solver.slippage(f, 0.5, 2e-3), 0.9, 1e-10 * 0.9);
}
