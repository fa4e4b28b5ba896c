// Accuracy of lugrip::detail::fast_exp / fast_log / fast_pow_pos against long double references
// (x86-64: 64-bit significand, i.e. the reference is good to ~2^-11 ulp of a double), and their
// special values against std::exp / std::log / std::pow.
#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <random>

#include "lugrip/detail/fast_math.hpp"

namespace {

using lugrip::detail::fast_exp;
using lugrip::detail::fast_log;
using lugrip::detail::fast_pow_pos;
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

static_assert(std::numeric_limits<long double>::digits >= 64, "the references need 80-bit long double");

// Error of `got` in units in the last place of the exact result `ref` (the ulp of the double
// binade ref lies in; 2^-1074 in the subnormal range).
double ulp_error(double got, long double ref) {
  const long double a = std::fabs(ref);
  long double ulp;
  if (a < static_cast<long double>(DBL_MIN)) {
    ulp = std::ldexp(1.0L, -1074);
  } else {
    int e;
    std::frexp(a, &e);  // a = m 2^e, m in [0.5, 1)
    ulp = std::ldexp(1.0L, e - 53);
  }
  return static_cast<double>(std::fabs(static_cast<long double>(got) - ref) / ulp);
}

bool same(double a, double b) {  // bitwise, except that any NaN equals any NaN
  if (std::isnan(a) || std::isnan(b)) return std::isnan(a) && std::isnan(b);
  return a == b && std::signbit(a) == std::signbit(b);
}

struct MaxErr {
  double err = 0.0, x = 0.0, y = 0.0;
  void add(double e, double xx, double yy = 0.0) {
    if (e > err) {
      err = e;
      x = xx;
      y = yy;
    }
  }
};

double log_uniform(std::mt19937_64& g, double lo, double hi) {
  std::uniform_real_distribution<double> d(std::log(lo), std::log(hi));
  return std::exp(d(g));
}

// ------------------------------------------------------------------------------------------
// Tables

TEST(FastMath, ExpTableIsTwoToTheJOver128) {
  using namespace lugrip::detail::fm;
  for (std::uint64_t j = 0; j < 128; ++j) {
    const double t = as_f64(kExpTable[j].sbits + (j << 45));
    const long double exact = std::exp2(static_cast<long double>(j) / 128.0L);
    EXPECT_EQ(t, static_cast<double>(exact)) << j;  // T is 2^(j/128) rounded to nearest
    const long double v = static_cast<long double>(t) * (1.0L + static_cast<long double>(kExpTable[j].tail));
    EXPECT_LE(std::fabs(v / exact - 1.0L), 0x1p-62L) << j;
  }
}

TEST(FastMath, LogTableIsLogOfIntervalMidpoints) {
  using namespace lugrip::detail::fm;
  for (std::uint64_t i = 0; i < 128; ++i) {
    const double z0 = as_f64(kLogOff + (i << 45));
    const double z1 = i == 127 ? 1.375 : as_f64(kLogOff + ((i + 1) << 45));
    const LogEntry& e = kLogTable[i];
    if (i == 79 || i == 80) {
      EXPECT_EQ(e.c, 1.0);  // the two intervals next to 1: r = z - 1 exactly
    } else {
      EXPECT_EQ(e.c, 0.5 * (z0 + z1)) << i;
    }
    EXPECT_LE(std::fmax(std::fabs(z0 - e.c), std::fabs(z1 - e.c)) / e.c, 0x1p-7) << i;  // |r| <= 2^-7
    EXPECT_EQ(e.invc, 1.0 / e.c) << i;
    EXPECT_EQ(std::ldexp(e.logc_hi, 42), std::nearbyint(std::ldexp(e.logc_hi, 42))) << i;  // on the 2^-42 grid
    const long double lc = std::log(static_cast<long double>(e.c));
    EXPECT_LE(std::fabs(static_cast<long double>(e.logc_hi) + e.logc_lo - lc), 0x1p-64L) << i;
  }
  EXPECT_EQ(std::ldexp(kLn2Hi, 42), std::nearbyint(std::ldexp(kLn2Hi, 42)));
  EXPECT_LE(std::fabs(static_cast<long double>(kLn2Hi) + kLn2Lo - std::log(2.0L)), 0x1p-64L);
  EXPECT_LE(std::fabs((static_cast<long double>(kExpLn2HiN) + kExpLn2LoN) * 128 - std::log(2.0L)), 0x1p-63L);
}

// ------------------------------------------------------------------------------------------
// exp

TEST(FastMath, ExpAccuracy) {
  std::mt19937_64 g(20240611);
  MaxErr full, core, sub;
  std::uniform_real_distribution<double> d_full(-708.3, 709.78), d_core(-40.0, 40.0), d_sub(-745.13, -708.4);
  for (int i = 0; i < 1000000; ++i) {
    const double x = d_full(g), xc = d_core(g);
    full.add(ulp_error(fast_exp(x), std::exp(static_cast<long double>(x))), x);
    core.add(ulp_error(fast_exp(xc), std::exp(static_cast<long double>(xc))), xc);
  }
  for (int i = 0; i < 200000; ++i) {  // subnormal and near-DBL_MIN results (ulp 2^-1074 there)
    const double x = d_sub(g);
    sub.add(ulp_error(fast_exp(x), std::exp(static_cast<long double>(x))), x);
  }
  std::printf("fast_exp max error: %.4f ulp (at %.17g) full range, %.4f ulp |x| <= 40, %.4f ulp subnormal results\n",
              full.err, full.x, core.err, sub.err);
  EXPECT_LE(full.err, 0.52);
  EXPECT_LE(core.err, 0.52);
  EXPECT_LE(sub.err, 0.52);
}

TEST(FastMath, ExpSpecialValues) {
  EXPECT_EQ(fast_exp(0.0), 1.0);
  EXPECT_EQ(fast_exp(-0.0), 1.0);
  EXPECT_TRUE(std::isnan(fast_exp(kNaN)));
  EXPECT_EQ(fast_exp(kInf), kInf);
  EXPECT_TRUE(same(fast_exp(-kInf), 0.0));
  EXPECT_EQ(fast_exp(1e-300), 1.0);
  EXPECT_EQ(fast_exp(-1e-300), 1.0);
  EXPECT_EQ(fast_exp(DBL_TRUE_MIN), 1.0);
  // overflow threshold ln(DBL_MAX) = 709.782712893383973
  const double big = 709.782712893384;  // largest double below the threshold
  EXPECT_LE(ulp_error(fast_exp(big), std::exp(static_cast<long double>(big))), 0.52);
  EXPECT_EQ(fast_exp(std::nextafter(big, kInf)), kInf);
  EXPECT_EQ(fast_exp(710.0), kInf);
  EXPECT_EQ(fast_exp(DBL_MAX), kInf);
  // underflow: 2^-1074 down to ln(2^-1075) = -745.13321910194122, then +0
  EXPECT_EQ(fast_exp(-745.1332191019411), DBL_TRUE_MIN);
  EXPECT_EQ(fast_exp(-745.1332191019412), std::exp(-745.1332191019412));
  EXPECT_TRUE(same(fast_exp(-745.2), 0.0));
  EXPECT_TRUE(same(fast_exp(-1000.0), 0.0));
  EXPECT_TRUE(same(fast_exp(-DBL_MAX), 0.0));
  // both sides of the fast-path bound |x| <= 700 and of DBL_MIN (ln DBL_MIN = -708.3964)
  for (double x : {-700.0, std::nextafter(-700.0, -kInf), 700.0, std::nextafter(700.0, kInf), -708.3964185322641,
                   -708.3964185322642, -708.39641853226, -709.0, -740.0, -744.44007192138122}) {
    EXPECT_LE(ulp_error(fast_exp(x), std::exp(static_cast<long double>(x))), 0.52) << x;
  }
  // exact results: e^(k ln2) is not exact, but e^0 and the subnormal grid points are
  for (int k = -1074; k <= -1023; k += 7) {
    const double x = static_cast<double>(std::log(std::ldexp(1.0L, k)));
    EXPECT_LE(ulp_error(fast_exp(x), std::exp(static_cast<long double>(x))), 0.52) << k;
  }
}

// ------------------------------------------------------------------------------------------
// log

TEST(FastMath, LogAccuracy) {
  std::mt19937_64 g(77);
  MaxErr full, near1, core, sub;
  std::uniform_real_distribution<double> d_near(0.5, 2.0);
  for (int i = 0; i < 1000000; ++i) {
    const double x = log_uniform(g, DBL_MIN, DBL_MAX);
    const double xn = d_near(g);
    const double xc = log_uniform(g, 1e-6, 1e6);
    full.add(ulp_error(fast_log(x), std::log(static_cast<long double>(x))), x);
    near1.add(ulp_error(fast_log(xn), std::log(static_cast<long double>(xn))), xn);
    core.add(ulp_error(fast_log(xc), std::log(static_cast<long double>(xc))), xc);
  }
  for (int i = 0; i < 200000; ++i) {
    const double x = log_uniform(g, DBL_TRUE_MIN, DBL_MIN);
    sub.add(ulp_error(fast_log(x), std::log(static_cast<long double>(x))), x);
  }
  // x = 1 +- a few ulp to 1 +- 2^-6 (relative accuracy of log near its zero)
  MaxErr one;
  for (int i = 0; i < 200000; ++i) {
    const double x = 1.0 + (i % 2 ? 1.0 : -0.5) * log_uniform(g, 0x1p-52, 0x1p-6);
    one.add(ulp_error(fast_log(x), std::log(static_cast<long double>(x))), x);
  }
  std::printf("fast_log max error: %.4f ulp full range, %.4f ulp [0.5, 2] (at %.17g), %.4f ulp [1e-6, 1e6], "
              "%.4f ulp subnormal x, %.4f ulp |x - 1| <= 2^-6\n",
              full.err, near1.err, near1.x, core.err, sub.err, one.err);
  EXPECT_LE(full.err, 1.0);
  EXPECT_LE(near1.err, 1.0);
  EXPECT_LE(core.err, 1.0);
  EXPECT_LE(sub.err, 1.0);
  EXPECT_LE(one.err, 1.0);
}

TEST(FastMath, LogSpecialValues) {
  EXPECT_EQ(fast_log(0.0), -kInf);
  EXPECT_EQ(fast_log(-0.0), -kInf);
  EXPECT_TRUE(std::isnan(fast_log(-1.0)));
  EXPECT_TRUE(std::isnan(fast_log(-DBL_TRUE_MIN)));
  EXPECT_TRUE(std::isnan(fast_log(-kInf)));
  EXPECT_TRUE(std::isnan(fast_log(kNaN)));
  EXPECT_EQ(fast_log(kInf), kInf);
  EXPECT_TRUE(same(fast_log(1.0), 0.0));  // +0
  for (double x : {DBL_TRUE_MIN, 2 * DBL_TRUE_MIN, 0x1p-1050, std::nextafter(DBL_MIN, 0.0), DBL_MIN,
                   std::nextafter(DBL_MIN, 1.0), DBL_MAX, std::nextafter(1.0, 0.0), std::nextafter(1.0, 2.0),
                   1.0 + 0x1p-30, 1.0 - 0x1p-30, 0.6875, std::nextafter(0.6875, 0.0), 1.375,
                   std::nextafter(1.375, 0.0), 1.0 - 0x1p-8, 1.0 + 0x1p-7, std::nextafter(1.0 + 0x1p-7, 0.0),
                   std::sqrt(2.0), 2.0, 0.5, 10.0, 1e-300, 1e300}) {
    EXPECT_LE(ulp_error(fast_log(x), std::log(static_cast<long double>(x))), 1.0) << x;
  }
  for (int k = -1074; k <= 1023; ++k) {  // exact powers of two: k ln2 (+ the logc of z = 1)
    const double x = std::ldexp(1.0, k);
    EXPECT_LE(ulp_error(fast_log(x), k * std::log(2.0L)), 0.51) << k;
  }
}

// ------------------------------------------------------------------------------------------
// pow

TEST(FastMath, PowAccuracyInTheCoreRanges) {
  std::mt19937_64 g(5);
  std::uniform_real_distribution<double> d_gamma(0.0, 1.0), d_gp1(1.0, 2.0), d_y(-5.0, 5.0);
  MaxErr fn, load, load1, wide;
  for (int i = 0; i < 1000000; ++i) {
    // rho = delta f_n^gamma, f_n in [1e-3, 1e3] N
    const double f_n = log_uniform(g, 1e-3, 1e3), gamma = d_gamma(g);
    fn.add(ulp_error(fast_pow_pos(f_n, gamma), std::pow(static_cast<long double>(f_n), gamma)), f_n, gamma);
    // normalised loads to gamma and gamma + 1
    const double f = log_uniform(g, 1e-6, 1e6), gp1 = d_gp1(g);
    load.add(ulp_error(fast_pow_pos(f, gamma), std::pow(static_cast<long double>(f), gamma)), f, gamma);
    load1.add(ulp_error(fast_pow_pos(f, gp1), std::pow(static_cast<long double>(f), gp1)), f, gp1);
    // |log x| <= 40, |y| <= 5
    const double x = log_uniform(g, 4.3e-18, 2.3e17), y = d_y(g);
    wide.add(ulp_error(fast_pow_pos(x, y), std::pow(static_cast<long double>(x), y)), x, y);
  }
  std::printf("fast_pow_pos max error: %.4f ulp f_n^gamma (at %.17g^%.17g), %.4f ulp load^gamma, "
              "%.4f ulp load^(gamma+1), %.4f ulp |log x| <= 40 and |y| <= 5\n",
              fn.err, fn.x, fn.y, load.err, load1.err, wide.err);
  EXPECT_LE(fn.err, 0.52);
  EXPECT_LE(load.err, 0.52);
  EXPECT_LE(load1.err, 0.53);
  EXPECT_LE(wide.err, 0.56);  // bound 0.51 + |y|/128
}

TEST(FastMath, PowAccuracyOverTheWholeRangeForModerateExponents) {
  // error bound 0.51 + |y|/128 ulp from log x's absolute error <= 2^-60, for every x > 0 and
  // |y| <= 64 with a normal result; x near 1 is sampled separately (there |y log x| is small)
  std::mt19937_64 g(11);
  std::uniform_real_distribution<double> d_y(-64.0, 64.0), d_z(-708.0, 709.0), d_near(-0.25, 0.25);
  double worst_excess = -1.0, worst = 0.0;
  for (int i = 0; i < 1000000; ++i) {
    const double x = i % 2 ? log_uniform(g, DBL_MIN, DBL_MAX) : 1.0 + d_near(g);
    double y = d_y(g);
    const double lx = std::log(x);
    if (std::fabs(y * lx) > 708.0) y = d_z(g) / lx;  // keep the result normal
    const long double ref = std::pow(static_cast<long double>(x), static_cast<long double>(y));
    if (!(ref >= DBL_MIN && ref <= DBL_MAX)) continue;
    const double e = ulp_error(fast_pow_pos(x, y), ref);
    worst = std::fmax(worst, e);
    worst_excess = std::fmax(worst_excess, e - (0.51 + std::fabs(y) / 128.0));
  }
  std::printf("fast_pow_pos max error for |y| <= 64: %.4f ulp; max over the bound 0.51 + |y|/128: %.4f ulp\n",
              worst, worst_excess);
  EXPECT_LE(worst_excess, 0.0);
  EXPECT_LE(worst, 1.01);
}

TEST(FastMath, PowExactResults) {
  std::mt19937_64 g(3);
  for (int i = 0; i < 100000; ++i) {
    const double x = log_uniform(g, 1e-300, 1e300);
    ASSERT_EQ(fast_pow_pos(x, 1.0), x) << x;
    ASSERT_EQ(fast_pow_pos(x, 0.0), 1.0) << x;
  }
  for (int k = -60; k <= 60; ++k) {  // (2^k)^y with exact results
    EXPECT_EQ(fast_pow_pos(std::ldexp(1.0, k), 2.0), std::ldexp(1.0, 2 * k)) << k;
    EXPECT_EQ(fast_pow_pos(std::ldexp(1.0, 2 * k), 0.5), std::ldexp(1.0, k)) << k;
    EXPECT_EQ(fast_pow_pos(std::ldexp(1.0, 3 * k), -1.0), std::ldexp(1.0, -3 * k)) << k;
  }
  EXPECT_EQ(fast_pow_pos(4.0, 0.5), 2.0);
  EXPECT_EQ(fast_pow_pos(1.0, 0.254), 1.0);
  EXPECT_EQ(fast_pow_pos(10.0, 3.0), 1000.0);
}

TEST(FastMath, PowSpecialValuesAsStdPow) {
  const double xs[] = {0.0, -0.0, kInf, -kInf, kNaN, 1.0, -1.0, 0.5, -0.5, 2.0, -2.0, 3.0, -3.0, DBL_TRUE_MIN,
                       -DBL_TRUE_MIN, DBL_MIN, DBL_MAX, -DBL_MAX, 1e-300, 1e300, std::nextafter(1.0, 0.0),
                       std::nextafter(1.0, 2.0)};
  const double ys[] = {0.0, -0.0, kInf, -kInf, kNaN, 1.0, -1.0, 2.0, -2.0, 3.0, -3.0, 0.5, -0.5, 0.254, 1.254,
                       1e300, -1e300, 0x1p64, -0x1p64, 0x1p53 + 2.0, 0x1p53 - 1.0, -(0x1p53 - 1.0), 1075.0,
                       -1075.0, DBL_TRUE_MIN, -DBL_TRUE_MIN, 5e15 + 1.0};
  int compared = 0;
  for (double x : xs) {
    for (double y : ys) {
      const double want = std::pow(x, y), got = fast_pow_pos(x, y);
      if (std::isnan(want) || std::isinf(want) || want == 0.0) {
        EXPECT_TRUE(same(got, want)) << x << "^" << y << ": " << got << " vs std::pow " << want;
      } else {
        const long double ref = std::pow(static_cast<long double>(x), static_cast<long double>(y));
        const double bound = 0.52 + std::fmin(std::fabs(y), 1e9) / 128.0;
        EXPECT_LE(ulp_error(got, ref), bound) << x << "^" << y;
        EXPECT_EQ(std::signbit(got), std::signbit(want)) << x << "^" << y;
      }
      ++compared;
    }
  }
  EXPECT_EQ(compared, 22 * 27);
  // the fast path's edges: subnormal x, the largest |y|, overflow and underflow of the result
  EXPECT_EQ(fast_pow_pos(2.0, 1024.0), kInf);
  EXPECT_EQ(fast_pow_pos(2.0, 1023.0), 0x1p1023);
  EXPECT_EQ(fast_pow_pos(2.0, -1074.0), DBL_TRUE_MIN);
  EXPECT_TRUE(same(fast_pow_pos(2.0, -1076.0), 0.0));
  EXPECT_EQ(fast_pow_pos(0x1p-1074, 0.5), 0x1p-537);
  EXPECT_EQ(fast_pow_pos(0x1p-1060, -0.5), 0x1p530);
  EXPECT_LE(ulp_error(fast_pow_pos(1e-310, 0.254), std::pow(static_cast<long double>(1e-310), static_cast<long double>(0.254))), 0.52);
  EXPECT_TRUE(same(fast_pow_pos(1e-310, 1e10), 0.0));
  EXPECT_EQ(fast_pow_pos(1e-310, -1e10), kInf);
}

}  // namespace
