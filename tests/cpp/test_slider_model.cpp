// Planar-slider plant (paper eqs. 1-2) and the rotor integrators shared with the observer.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "lugrip/detail/rotor_steps.hpp"
#include "lugrip/slider_model.hpp"

using namespace lugrip;

namespace {

constexpr double kDt = 0.002;

struct Trajectory {
  std::vector<double> z, omega, friction, slip, g;
};

// Runs the plant at constant f_n, c~ with tau_e(t) given as a multiple of g(f_n, c~).
template <class Profile>
Trajectory simulate(SliderModel& sim, double f_n, double c_tilde, int n, Profile&& load_over_g) {
  const double g = sim.model().g(f_n, c_tilde);
  Trajectory tr;
  SliderOutput out;
  for (int i = 0; i < n; ++i) {
    EXPECT_EQ(sim.step(SliderInput{f_n, c_tilde, load_over_g(i * kDt) * g, kDt}, out), Status::Ok);
    tr.z.push_back(out.z);
    tr.omega.push_back(out.omega);
    tr.friction.push_back(out.friction_torque);
    tr.slip.push_back(out.slip);
    tr.g.push_back(out.g);
  }
  return tr;
}

SliderSettings with_scheme(Integrator i, double max_substep = 2e-5) {
  SliderSettings s;
  s.integrator = i;
  s.max_substep = max_substep;
  s.max_substeps = 1000000;
  return s;
}

}  // namespace

TEST(SliderModel, SteadySlidingReachesTheViscousSpeed) {
  // Constant external torque above the capacity: z -> sign(tau_e) g / sigma0 and
  // tau_e = g + sigma_1 omega (eq. 2 at rest in omega) -> omega = (|tau_e| - g) / sigma_1.
  const ContactParams p = table1_params();
  for (Integrator scheme : {Integrator::Rosenbrock, Integrator::Implicit, Integrator::Rk4Adaptive}) {
    for (double sign : {1.0, -1.0}) {
      SliderModel sim(p, 1e-4, with_scheme(scheme));
      const double f_n = 5.0, ct = 0.5;
      const double g = sim.model().g(f_n, ct), s1 = sim.model().sigma_1(f_n, ct);
      const Trajectory tr = simulate(sim, f_n, ct, 1500, [&](double) { return 1.5 * sign; });
      const double w_expected = sign * 0.5 * g / s1;
      SCOPED_TRACE(to_string(scheme));
      EXPECT_NEAR(tr.omega.back(), w_expected, 1e-9 * std::fabs(w_expected) + 1e-12);
      EXPECT_NEAR(tr.z.back(), sign * g / p.sigma0, 1e-12);
      EXPECT_NEAR(tr.slip.back(), 1.0, 1e-12);
      EXPECT_NEAR(tr.friction.back(), 1.5 * sign * g, 1e-9 * g);
    }
  }
}

TEST(SliderModel, StickHoldsTheBristleDeflection) {
  // Load inside the capacity: omega -> 0, sigma0 z -> tau_e, slip -> tau_e / g.
  const ContactParams p = object_params("aluminium_can");
  SliderModel sim(p, 1e-4);
  const double f_n = 2.0, ct = -0.7;
  const double g = sim.model().g(f_n, ct);
  const Trajectory tr = simulate(sim, f_n, ct, 2000, [](double) { return -0.6; });
  EXPECT_LT(std::fabs(tr.omega.back()), 1e-9);
  EXPECT_NEAR(p.sigma0 * tr.z.back(), -0.6 * g, 1e-9 * g);
  EXPECT_NEAR(tr.slip.back(), 0.6, 1e-9);
  EXPECT_NEAR(tr.friction.back(), -0.6 * g, 1e-9 * g);
}

TEST(SliderModel, SchemesAgreeOnALoadRamp) {
  // Ramp through the limit surface and back; the default (Rosenbrock, 2e-5 s substeps) agrees
  // with fine-step RK4 and a finer exponential-implicit run.
  const ContactParams p = table1_params();
  auto profile = [](double t) { return t < 0.2 ? 0.0 : (t < 1.2 ? 3.0 * (t - 0.2) : std::max(0.0, 3.0 - 3.0 * (t - 1.2))); };
  const double f_n = 1.0, ct = 0.8;
  SliderModel ref(p, 1e-4, with_scheme(Integrator::Rk4Adaptive, 1e-6));
  SliderModel ros(p, 1e-4);
  SliderModel imp(p, 1e-4, with_scheme(Integrator::Implicit, 2e-6));
  const Trajectory a = simulate(ref, f_n, ct, 1200, profile);
  const Trajectory b = simulate(ros, f_n, ct, 1200, profile);
  const Trajectory c = simulate(imp, f_n, ct, 1200, profile);
  double w_max = 0.0, err_b = 0.0, err_c = 0.0;
  for (size_t i = 0; i < a.omega.size(); ++i) {
    w_max = std::max(w_max, std::fabs(a.omega[i]));
    err_b = std::max(err_b, std::fabs(b.omega[i] - a.omega[i]));
    err_c = std::max(err_c, std::fabs(c.omega[i] - a.omega[i]));
  }
  EXPECT_GT(w_max, 5e-3);  // it really slid
  EXPECT_LT(err_b, 1e-4 * w_max);
  EXPECT_LT(err_c, 2e-2 * w_max);
}

TEST(SliderModel, ProjectionLetsTheObjectSlipWhenTheGripOpens) {
  // Stick at 0.8 g with 5 N, then the normal force drops to 1 N: the old deflection exceeds the
  // new capacity. With the projection (docs/model.md 7.1) |sigma0 z| <= g after every step, the
  // friction cannot exceed the new capacity and the object starts sliding.
  const ContactParams p = table1_params();
  SliderModel sim(p, 1e-4);
  const double ct = 0.3, tau = 0.8 * sim.model().g(5.0, ct);
  SliderOutput out;
  for (int i = 0; i < 1000; ++i) sim.step(SliderInput{5.0, ct, tau, kDt}, out);
  EXPECT_LT(std::fabs(out.omega), 1e-5);
  const double g1 = sim.model().g(1.0, ct);
  ASSERT_GT(tau, g1);
  for (int i = 0; i < 200; ++i) {
    sim.step(SliderInput{1.0, ct, tau, kDt}, out);
    EXPECT_LE(p.sigma0 * std::fabs(out.z), out.g * (1.0 + 1e-12));
    EXPECT_LE(out.slip, 1.0 + 1e-12);
  }
  EXPECT_GT(out.omega, 0.5 * (tau - g1) / sim.model().sigma_1(1.0, ct));
}

TEST(SliderModel, InvalidInputLeavesTheStateUntouched) {
  SliderModel sim(table1_params(), 1e-4);
  SliderOutput out, ok;
  sim.step(SliderInput{5.0, 0.2, 1e-3, kDt}, ok);
  const double z = sim.z(), w = sim.omega();
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  const SliderInput bad[] = {{nan, 0.2, 1e-3, kDt}, {5.0, nan, 1e-3, kDt}, {5.0, 0.2, inf, kDt},
                             {5.0, 0.2, 1e-3, 0.0}, {5.0, 0.2, 1e-3, -kDt}, {0.0, 0.2, 1e-3, kDt},
                             {-1.0, 0.2, 1e-3, kDt}, {5.0, 0.2, 1e-3, nan}};
  for (const SliderInput& in : bad) {
    EXPECT_EQ(sim.step(in, out), Status::InvalidSample);
    EXPECT_EQ(sim.z(), z);
    EXPECT_EQ(sim.omega(), w);
    EXPECT_EQ(out.z, ok.z);
    EXPECT_EQ(out.friction_torque, ok.friction_torque);
  }
  sim.reset(1e-5, 0.25);
  EXPECT_EQ(sim.z(), 1e-5);
  EXPECT_EQ(sim.omega(), 0.25);
}

TEST(SliderModel, SettingsValidationNamesTheField) {
  std::string msg;
  EXPECT_TRUE(validate(SliderSettings(), &msg)) << msg;
  EXPECT_TRUE(msg.empty());
  auto expect_bad = [](SliderSettings s, const char* field) {
    std::string m;
    EXPECT_FALSE(validate(s, &m)) << field;
    EXPECT_NE(m.find(field), std::string::npos) << m;
    EXPECT_THROW(SliderModel(table1_params(), 1e-4, s), std::invalid_argument);
  };
  SliderSettings s;
  s.max_substep = 0.0;
  expect_bad(s, "max_substep");
  s = SliderSettings();
  s.max_substeps = 0;
  expect_bad(s, "max_substeps");
  s = SliderSettings();
  s.g_floor = -1.0;
  expect_bad(s, "g_floor");
  s = SliderSettings();
  s.integrator = static_cast<Integrator>(42);
  expect_bad(s, "integrator");
  for (double J : {0.0, -1.0, std::numeric_limits<double>::quiet_NaN()}) {
    try {
      SliderModel sim(table1_params(), J);
      ADD_FAILURE() << "no throw for J = " << J;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("J ="), std::string::npos);
    }
  }
  ContactParams bad = table1_params();
  bad.sigma0 = -1.0;
  EXPECT_THROW(SliderModel(bad, 1e-4), std::invalid_argument);
}

TEST(RotorStep, EquilibriaAreFixedPointsOfTheStableSchemes) {
  RotorCoefficients c;
  c.sigma0 = 16.66;
  c.sigma_z = 2.0;
  c.sigma_1 = 0.4;
  c.g = 4e-3;
  c.gain = 200.0;
  // Steady sliding: z = g/sigma0, omega = (u - g)/sigma_1.
  c.drive = 1.7 * c.g;
  for (Integrator s : {Integrator::Implicit, Integrator::Rosenbrock, Integrator::Rk4, Integrator::Rk4Adaptive}) {
    double z = c.g / c.sigma0, w = 0.7 * c.g / c.sigma_1;
    const double z0 = z, w0 = w;
    for (int i = 0; i < 100; ++i) rotor_advance(z, w, kDt, c, s, 1, 500, nullptr, nullptr);
    EXPECT_NEAR(z, z0, 1e-15) << to_string(s);
    EXPECT_NEAR(w, w0, 1e-12 * w0) << to_string(s);
  }
  // Stick: omega = 0, sigma0 z = u.
  c.drive = 0.4 * c.g;
  for (Integrator s : {Integrator::Implicit, Integrator::Rosenbrock, Integrator::Rk4, Integrator::Rk4Adaptive}) {
    double z = c.drive / c.sigma0, w = 0.0;
    for (int i = 0; i < 100; ++i) rotor_advance(z, w, kDt, c, s, 1, 500, nullptr, nullptr);
    EXPECT_NEAR(z, c.drive / c.sigma0, 1e-15) << to_string(s);
    EXPECT_EQ(w, 0.0) << to_string(s);
  }
}

TEST(RotorStep, Rk4StabilityLimitOfTheLinearMode) {
  // docs/model.md 7.4: in stick the fast mode is lambda_1 ~ -l (sigma_z + sigma_1); one RK4 step per
  // sample is stable only for h |lambda| <= 2.785. The scheme-independent check: above the limit
  // a perturbation grows with Rk4 and decays with Rk4Adaptive, Rosenbrock and Implicit.
  RotorCoefficients c;
  c.sigma0 = 16.66;
  c.sigma_z = 2.0;
  c.sigma_1 = 0.0;
  c.g = 1.0;  // large capacity: linear regime
  c.drive = 0.0;
  auto amplitude = [&](Integrator s, double gain) {
    c.gain = gain;
    double z = 0.0, w = 1e-6;
    double peak = 0.0;
    for (int i = 0; i < 200; ++i) {
      rotor_advance(z, w, kDt, c, s, 1, 500, nullptr, nullptr);
      peak = std::fabs(w);
    }
    return peak;
  };
  const double l_unstable = 3.0 / (kDt * c.sigma_z);  // h l sigma_z = 3.0 (lambda_1 ~ -l sigma_z)
  const double l_stable = 2.5 / (kDt * c.sigma_z);
  EXPECT_FALSE(amplitude(Integrator::Rk4, l_unstable) < 1e-3);  // grows (or overflows to NaN)
  EXPECT_LT(amplitude(Integrator::Rk4, l_stable), 1e-7);
  for (Integrator s : {Integrator::Rk4Adaptive, Integrator::Rosenbrock, Integrator::Implicit})
    EXPECT_LT(amplitude(s, 100.0 * l_unstable), 1e-7) << to_string(s);
}

TEST(RotorStep, Rk4AdaptiveChoosesSubstepsFromTheStiffness) {
  RotorCoefficients c;
  c.sigma0 = 16.66;
  c.sigma_z = 2.0;
  c.sigma_1 = 0.01;
  c.g = 7e-5;  // f_n ~ 0.2 N
  c.gain = 200.0;
  c.drive = c.g + c.sigma_1 * 0.05;
  double z = c.g / c.sigma0, w = 0.05;
  int n = 0;
  bool capped = true;
  rotor_advance(z, w, kDt, c, Integrator::Rk4Adaptive, 1, 500, &n, &capped);
  const double lambda = c.sigma0 * 0.05 / c.g;  // 1.19e4 1/s, above l (sigma_z + sigma_1)
  EXPECT_GE(n, static_cast<int>(std::ceil(kDt * lambda / 2.0)));
  EXPECT_LE(kDt / n * lambda, kRk4StabilityLimit);
  EXPECT_FALSE(capped);
  rotor_advance(z, w, kDt, c, Integrator::Rk4Adaptive, 1, 3, &n, &capped);
  EXPECT_EQ(n, 3);
  EXPECT_TRUE(capped);
}

namespace {

// A one-parameter forward-mode dual number: the shared rotor templates
// (lugrip/detail/rotor_steps.hpp) instantiated with it must give the double functions' values
// bit for bit (what the identification's tangent replica relies on) and the exact derivative.
struct D1 {
  double v = 0.0, d = 0.0;
  D1() = default;
  D1(double value, double deriv = 0.0) : v(value), d(deriv) {}  // NOLINT: constants promote
};
D1 operator-(const D1& a) { return {-a.v, -a.d}; }
D1 operator+(const D1& a, const D1& b) { return {a.v + b.v, a.d + b.d}; }
D1 operator-(const D1& a, const D1& b) { return {a.v - b.v, a.d - b.d}; }
D1 operator*(const D1& a, const D1& b) { return {a.v * b.v, a.d * b.v + a.v * b.d}; }
D1 operator/(const D1& a, const D1& b) {
  const double q = a.v / b.v;
  return {q, (a.d - q * b.d) / b.v};
}
D1& operator+=(D1& a, const D1& b) { return a = a + b; }
D1& operator-=(D1& a, const D1& b) { return a = a - b; }
double scalar_value(const D1& x) { return x.v; }
D1 scalar_fabs(const D1& x) { return x.v < 0.0 ? -x : x; }
D1 scalar_expm1(const D1& x) { return {std::expm1(x.v), std::exp(x.v) * x.d}; }

struct D1Coefficients {
  D1 sigma0, sigma_z, sigma_1, g, gain, drive;
};

// Coefficients and a state over several decades (stick, sliding, stiff and soft).
struct RotorCase {
  RotorCoefficients c;
  double z, w, h;
};
RotorCase random_case(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  RotorCase r;
  r.c.sigma0 = std::pow(10.0, 3.0 * u(rng) - 1.0);
  r.c.sigma_z = std::pow(10.0, 4.0 * u(rng) - 5.0);
  r.c.sigma_1 = std::pow(10.0, 5.0 * u(rng) - 6.0);
  r.c.g = std::pow(10.0, 4.0 * u(rng) - 5.0);
  r.c.gain = std::pow(10.0, 5.0 * u(rng) + 1.0);
  r.c.drive = (4.0 * u(rng) - 2.0) * r.c.g;
  r.z = (2.0 * u(rng) - 1.0) * r.c.g / r.c.sigma0;
  r.w = (u(rng) < 0.5 ? -1.0 : 1.0) * std::pow(10.0, 4.0 * u(rng) - 3.0);
  r.h = std::pow(10.0, 2.0 * u(rng) - 5.0);
  return r;
}

// Dual coefficients from double ones, d/d drive seeded when seed_drive, else d/d sigma0.
D1Coefficients dual(const RotorCoefficients& c, bool seed_drive) {
  D1Coefficients r;
  r.sigma0 = D1(c.sigma0, seed_drive ? 0.0 : 1.0);
  r.sigma_z = c.sigma_z;
  r.sigma_1 = c.sigma_1;
  r.g = c.g;
  r.gain = c.gain;
  r.drive = D1(c.drive, seed_drive ? 1.0 : 0.0);
  return r;
}

using DoubleStep = void (*)(double&, double&, double, const RotorCoefficients&) noexcept;

}  // namespace

TEST(RotorStep, DualInstantiationReproducesTheDoubleStepsAndDifferentiatesThem) {
  std::mt19937_64 rng(2024);
  const struct {
    Integrator scheme;
    DoubleStep step;
  } kinds[] = {{Integrator::Implicit, rotor_step_implicit},
               {Integrator::Rk4, rotor_step_rk4},
               {Integrator::Rosenbrock, rotor_step_rosenbrock}};
  int checked_derivatives = 0;
  for (int k = 0; k < 2000; ++k) {
    const RotorCase r = random_case(rng);
    for (const auto& kind : kinds) {
      SCOPED_TRACE(std::string(to_string(kind.scheme)) + " case " + std::to_string(k));
      double z = r.z, w = r.w;
      kind.step(z, w, r.h, r.c);
      for (bool seed_drive : {false, true}) {
        const D1Coefficients dc = dual(r.c, seed_drive);
        D1 zd(r.z), wd(r.w);
        if (kind.scheme == Integrator::Implicit) detail::rotor_implicit(zd, wd, r.h, dc);
        else if (kind.scheme == Integrator::Rk4) detail::rotor_rk4(zd, wd, r.h, dc);
        else detail::rotor_rosenbrock(zd, wd, r.h, dc);
        // values: the same operations in the same order
        ASSERT_EQ(zd.v, z);
        ASSERT_EQ(wd.v, w);
        // derivative: central difference of the double step, where the step resolves the
        // dynamics (h Lambda <= 0.5) and omega keeps its sign (|omega| is not smooth at 0)
        if (!(w * r.w > 0.0) || r.h * rotor_stiffness(r.w, r.c) > 0.5) continue;
        auto run = [&](double delta) {
          RotorCoefficients c = r.c;
          (seed_drive ? c.drive : c.sigma0) += delta;
          double zz = r.z, ww = r.w;
          kind.step(zz, ww, r.h, c);
          return std::make_pair(zz, ww);
        };
        const double p = seed_drive ? r.c.g : r.c.sigma0;
        const double eps = 1e-6 * p;
        const auto plus = run(eps), minus = run(-eps);
        const double fd_w = (plus.second - minus.second) / (2.0 * eps);
        const double fd_z = (plus.first - minus.first) / (2.0 * eps);
        if (w * plus.second <= 0.0 || w * minus.second <= 0.0) continue;
        const double tol_w = 1e-5 * (std::fabs(fd_w) + std::fabs(w) / p) + 1e-12;
        const double tol_z = 1e-5 * (std::fabs(fd_z) + r.c.g / r.c.sigma0 / p) + 1e-15;
        EXPECT_NEAR(wd.d, fd_w, tol_w) << (seed_drive ? "d/d drive" : "d/d sigma0");
        EXPECT_NEAR(zd.d, fd_z, tol_z) << (seed_drive ? "d/d drive" : "d/d sigma0");
        ++checked_derivatives;
      }
    }
  }
  EXPECT_GT(checked_derivatives, 4000);
}

TEST(RotorStep, AdaptiveSampleEqualsTheFixedPassWithItsSubstepCount) {
  // The identification replays an adaptive sample as a fixed pass with the observer's reported
  // substep count: rotor_advance must end exactly where that pass (dual, from the projected
  // start) ends, for every scheme.
  std::mt19937_64 rng(7);
  int multi = 0;
  for (int k = 0; k < 3000; ++k) {
    RotorCase r = random_case(rng);
    r.h *= 100.0;  // samples long enough to need substeps
    if (k % 3 == 0) r.z *= 1.5;  // starts outside the current bound (g dropped)
    for (Integrator s : {Integrator::Implicit, Integrator::Rk4, Integrator::Rk4Adaptive, Integrator::Rosenbrock}) {
      SCOPED_TRACE(std::string(to_string(s)) + " case " + std::to_string(k));
      double z = r.z, w = r.w;
      int n = 0;
      bool capped = false;
      const bool projected = rotor_advance(z, w, r.h, r.c, s, 1 + k % 2, 400, &n, &capped);
      if (capped || !std::isfinite(w)) continue;
      if (n > 2) ++multi;
      const D1Coefficients dc = dual(r.c, false);
      D1 zd(r.z), wd(r.w);
      bool pd = detail::rotor_project(zd, dc);
      detail::rotor_fixed_pass(zd, wd, r.h, n, dc, s, pd);
      ASSERT_EQ(zd.v, z);
      ASSERT_EQ(wd.v, w);
      EXPECT_EQ(pd, projected);
    }
  }
  EXPECT_GT(multi, 500);  // the adaptive schemes did take several substeps
}
