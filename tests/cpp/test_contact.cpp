// Contact quantities (docs/model.md 2, 5.1, 6), parameter validation and presets, and the CoR
// estimator (docs/model.md 5.2-5.7): round trips inside and outside the LS, sign rule, degenerate
// and invalid samples, saturation, and a seeded random property test.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <map>
#include <random>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include "lugrip/contact.hpp"
#include "lugrip/limit_surface.hpp"
#include "lugrip/params.hpp"
#include "lugrip/status.hpp"

namespace {

using namespace lugrip;

constexpr double kPi = 3.14159265358979323846;
const double kInf = std::numeric_limits<double>::infinity();
const double kNaN = std::numeric_limits<double>::quiet_NaN();

// ContactModel construction integrates the LS tables; build each parameter set once.
const ContactModel& model_for(const ContactParams& p) {
  static std::map<std::string, ContactModel> cache;
  const std::string key = to_string(p);
  auto it = cache.find(key);
  if (it == cache.end()) it = cache.emplace(key, ContactModel(p)).first;
  return it->second;
}

ContactParams with_cmax(double c_max, double k = 4.0) {
  ContactParams p = table1_params();
  p.c_max = c_max;
  p.k = k;
  return p;
}

int count_lines(const std::string& s) {
  int n = 0;
  for (char c : s) n += c == '\n';
  return n;
}

bool all_finite(const CorOutput& o) {
  return std::isfinite(o.c_tilde) && std::isfinite(o.c) && std::isfinite(o.ft_tilde) && std::isfinite(o.tau_tilde) &&
         std::isfinite(o.sigma) && std::isfinite(o.rho) && std::isfinite(o.g) && std::isfinite(o.sigma_1) &&
         std::isfinite(o.y) && std::isfinite(o.c_tilde_unclipped) &&
         std::fabs(o.c_tilde_unclipped) >= std::fabs(o.c_tilde) && std::fabs(o.c_tilde_unclipped) <= kCTildeUnclippedMax &&
         (o.c_tilde == 0.0 || (o.c_tilde < 0.0) == (o.c_tilde_unclipped < 0.0));
}

bool known_status(Status s) {
  const int v = static_cast<int>(s);
  return v >= static_cast<int>(Status::Ok) && v <= static_cast<int>(Status::Reinitialized);
}

// Sensor wrench on the LS at normal force f_n for the signed CoR c~ (frame of docs/model.md 1.2:
// f_t >= 0, sign(c~) = -sign(tau)).
void wrench_on_ls(const ContactModel& m, double f_n, double c_tilde, double& f_t, double& tau) {
  const LsPoint q = m.limit_surface().eval(c_tilde);
  f_t = m.ft_max(f_n) * q.F;
  tau = -(c_tilde < 0.0 ? -1.0 : 1.0) * m.tau_max(f_n) * q.T;
}

// Sensor wrench of a sliding contact from eqs. 9-10 with angular speed omega, CoR at c~
// (sign(c~) = sign(omega)): dry LS part plus viscous excess.
void sliding_wrench(const ContactModel& m, double f_n, double c_tilde, double omega, double& f_t, double& tau) {
  const LimitSurface& ls = m.limit_surface();
  const double K = m.viscous_ratio(f_n), xi = m.xi();
  const double sw = omega < 0.0 ? -1.0 : 1.0;
  const double ft_n = -sw * ls.ft_star(c_tilde) + K * omega * c_tilde;  // eq. 9
  const double tau_n = -sw * ls.tau_star(c_tilde) - K / (2.0 * xi) * omega;  // eq. 10
  f_t = ft_n * m.ft_max(f_n);
  tau = tau_n * m.tau_max(f_n);
}

}  // namespace

// ------------------------------------------------------------ parameters and presets ----

TEST(ContactParamsValidation, Table1AndPresetsAreValid) {
  const ContactParams t1 = table1_params();
  EXPECT_EQ(t1.mu, 0.47);
  EXPECT_EQ(t1.beta_a, 4.9e9);
  EXPECT_EQ(t1.sigma0, 16.66);
  EXPECT_EQ(t1.sigma_z, 2.0);
  EXPECT_EQ(t1.delta, 0.0018);
  EXPECT_EQ(t1.gamma, 0.254);
  EXPECT_EQ(t1.k, 4.0);
  EXPECT_EQ(t1.c_max, 1.5);
  std::string msg = "not cleared";
  EXPECT_TRUE(validate(t1, &msg));
  EXPECT_EQ(msg, "");
  // Paper Table 2: object mu and beta_A, everything else from Table 1.
  const std::vector<std::tuple<std::string, double, double>> table2 = {{"big_resin_block", 0.85, 1.24e7},
                                                                       {"small_resin_block", 0.7, 1.825e7},
                                                                       {"plastic_bottle", 0.85, 1.963e7},
                                                                       {"aluminium_can", 0.75, 2.121e7}};
  for (const auto& [name, mu, beta_a] : table2) {
    const ContactParams p = object_params(name);
    EXPECT_EQ(p.mu, mu) << name;
    EXPECT_EQ(p.beta_a, beta_a) << name;
    EXPECT_EQ(p.sigma0, t1.sigma0);
    EXPECT_EQ(p.sigma_z, t1.sigma_z);
    EXPECT_EQ(p.delta, t1.delta);
    EXPECT_EQ(p.gamma, t1.gamma);
    EXPECT_EQ(p.k, t1.k);
    EXPECT_EQ(p.c_max, t1.c_max);
    EXPECT_TRUE(validate(p, nullptr)) << name;
  }
  EXPECT_THROW(object_params("wooden_spoon"), std::invalid_argument);
  EXPECT_THROW(object_params(""), std::invalid_argument);
}

TEST(ContactParamsValidation, OneBadFieldAtATime) {
  struct Case {
    const char* field;
    double ContactParams::*member;
    std::vector<double> bad;
    std::vector<double> good;
  };
  const std::vector<Case> cases = {
      {"mu", &ContactParams::mu, {0.0, -0.5, 10.5, kNaN, kInf, -kInf}, {1e-6, 0.47, 10.0}},
      {"beta_a", &ContactParams::beta_a, {-1.0, kNaN, kInf}, {0.0, 4.9e9}},
      {"sigma0", &ContactParams::sigma0, {0.0, -1.0, kNaN, kInf}, {1e-9, 16.66}},
      {"sigma_z", &ContactParams::sigma_z, {-1e-9, kNaN, kInf}, {0.0, 2.0}},
      {"delta", &ContactParams::delta, {0.0, -0.0018, 1.0, kNaN, kInf}, {1e-6, 0.0018}},
      {"gamma", &ContactParams::gamma, {0.0, -0.1, 1.0 / 3.0, 0.5, kNaN, kInf}, {1e-6, 0.254, 0.333}},
      {"k", &ContactParams::k, {1e-9, 0.4, -4.0, kNaN, -kInf}, {0.0, 0.5, 2.0, 4.0, kInf}},
      {"c_max", &ContactParams::c_max, {0.0, -1.5, kNaN, kInf, 1e4}, {1e-3, 1.5, 1000.0}},
  };
  for (const Case& c : cases) {
    for (double v : c.bad) {
      ContactParams p = table1_params();
      p.*c.member = v;
      std::string msg;
      SCOPED_TRACE(std::string(c.field) + " = " + std::to_string(v));
      EXPECT_FALSE(validate(p, &msg));
      EXPECT_EQ(count_lines(msg), 1) << msg;  // only the bad field is reported
      EXPECT_EQ(msg.rfind(std::string(c.field) + " = ", 0), 0u) << msg;  // and it is named first
      try {
        ContactModel m(p);
        ADD_FAILURE() << "ContactModel accepted " << c.field << " = " << v;
      } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find(std::string(c.field) + " = "), std::string::npos) << e.what();
      }
      EXPECT_THROW(validate_or_throw(p), std::invalid_argument);
      EXPECT_THROW(CorEstimator{p}, std::invalid_argument);
    }
    for (double v : c.good) {
      ContactParams p = table1_params();
      p.*c.member = v;
      EXPECT_TRUE(validate(p, nullptr)) << c.field << " = " << v;
    }
  }
}

TEST(ContactParamsValidation, DefaultParamsNameEveryPhysicalField) {
  // No silent defaults for the physical fields.
  std::string msg;
  EXPECT_FALSE(validate(ContactParams(), &msg));
  EXPECT_EQ(count_lines(msg), 6) << msg;
  for (const char* f : {"mu = ", "beta_a = ", "sigma0 = ", "sigma_z = ", "delta = ", "gamma = "})
    EXPECT_NE(msg.find(f), std::string::npos) << f << " missing in\n" << msg;
  EXPECT_EQ(msg.find("c_max"), std::string::npos);
  EXPECT_EQ(msg.find("k = "), std::string::npos);
}

TEST(ContactParamsValidation, CorSettingsOneBadFieldAtATime) {
  const std::vector<std::pair<const char*, double CorSettings::*>> fields = {
      {"f_n_min", &CorSettings::f_n_min},       {"force_limit", &CorSettings::force_limit},
      {"torque_limit", &CorSettings::torque_limit}, {"zero_force", &CorSettings::zero_force},
      {"zero_torque", &CorSettings::zero_torque}};
  EXPECT_TRUE(validate(CorSettings(), nullptr));
  const ContactModel& m = model_for(table1_params());
  for (const auto& [name, member] : fields) {
    for (double v : {0.0, -1.0, kNaN, kInf}) {
      CorSettings s;
      s.*member = v;
      std::string msg;
      EXPECT_FALSE(validate(s, &msg)) << name << " = " << v;
      EXPECT_EQ(count_lines(msg), 1) << msg;
      EXPECT_EQ(msg.rfind(std::string(name) + " = ", 0), 0u) << msg;
      EXPECT_THROW(CorEstimator(m, s), std::invalid_argument) << name;
    }
  }
}

TEST(ContactParamsValidation, PrintableAndStatusStrings) {
  ContactParams p = table1_params();
  p.k = kInf;
  const std::string s = to_string(p);
  for (const char* f : {"mu=0.47,", "beta_a=4.9e+09,", "sigma0=", "sigma_z=", "delta=", "gamma=", "k=float('inf')",
                        "c_max=1.5"})
    EXPECT_NE(s.find(f), std::string::npos) << f << " in " << s;
  std::vector<std::string> seen;
  for (int v = 0; v <= 6; ++v) {
    const std::string d = to_string(static_cast<Status>(v));
    EXPECT_FALSE(d.empty());
    for (const std::string& o : seen) EXPECT_NE(d, o);
    seen.push_back(d);
  }
  EXPECT_TRUE(is_valid(Status::Ok));
  EXPECT_TRUE(is_valid(Status::Saturated));
  EXPECT_TRUE(is_valid(Status::Degenerate));
  EXPECT_FALSE(is_valid(Status::NoContact));
  EXPECT_FALSE(is_valid(Status::InvalidSample));
}

// ------------------------------------------------------ contact quantities (docs/model.md 2, 5.1, 6) ----

TEST(ContactQuantities, FormulasOfTheSpec) {
  for (const ContactParams& p : {table1_params(), object_params("big_resin_block")}) {
    const ContactModel& m = model_for(p);
    const double xi = shape_factor(p.k);
    EXPECT_EQ(m.xi(), xi);
    for (double f_n : {0.03, 0.2, 1.0, 5.0, 16.0, 100.0}) {
      const double rho = p.delta * std::pow(f_n, p.gamma);
      EXPECT_NEAR(m.rho(f_n), rho, 1e-15 * rho);
      EXPECT_NEAR(m.ft_max(f_n), p.mu * f_n, 1e-15 * f_n);                           // eq. 3
      EXPECT_NEAR(m.tau_max(f_n), p.mu * xi * rho * f_n, 1e-14 * p.mu * rho * f_n);   // eq. 4
      const double K = kPi * std::pow(p.delta, 3) * p.beta_a * std::pow(f_n, 3 * p.gamma - 1) / p.mu;
      EXPECT_NEAR(m.viscous_ratio(f_n), K, 1e-13 * K);  // eqs. 9-10
      for (double c : {-3.0, -1.0, -0.2, 0.0, 0.4, 1.5, 10.0}) {
        // eq. 17, and its derivation: tau_cv = tau_v - c f_tv = -sigma_1 omega with (7)-(8).
        const double s1 = kPi * p.beta_a * std::pow(rho, 4) * (c * c + 0.5);
        EXPECT_NEAR(m.sigma_1(f_n, c), s1, 1e-13 * s1);
        const double omega = 0.7, cc = c * rho;
        const double f_tv = kPi * p.beta_a * rho * rho * omega * cc;
        const double tau_v = -0.5 * kPi * p.beta_a * std::pow(rho, 4) * omega;
        EXPECT_NEAR(-(tau_v - cc * f_tv) / omega, m.sigma_1(f_n, c), 1e-12 * s1);
        // eq. 18 both ways: tau*_LS tau_max + |c f*_tLS| f_t,max = mu f_n rho G(|c~|) > 0.
        const LimitSurface& ls = m.limit_surface();
        const double g18 = ls.tau_star(c) * m.tau_max(f_n) + std::fabs(cc * ls.ft_star(c)) * m.ft_max(f_n);
        EXPECT_NEAR(m.g(f_n, c), g18, 1e-13 * g18);
        EXPECT_GT(m.g(f_n, c), 0.0);
        EXPECT_EQ(m.g(f_n, c), m.g(f_n, -c));
      }
      // dg/d|c| = mu f_n F(a) (docs/model.md 3.2) with c = c~ rho.
      const double a = 0.8, h = 1e-5;
      const double dg = (m.g(f_n, a + h) - m.g(f_n, a - h)) / (2 * h * rho);
      EXPECT_NEAR(dg, p.mu * f_n * m.limit_surface().F(a), 1e-5 * p.mu * f_n);
    }
  }
}

TEST(ContactQuantities, MagnitudeTableOfSpecSection6) {
  // docs/model.md 6 (delta = 0.0018, gamma = 0.254), printed to 3-4 significant digits. Tolerance
  // 4e-3 relative: two entries are rounded up in their last digit in the spec (sigma_1(0.2 N,
  // 0) = 1.5749e-2 printed 1.58e-2; g(5 N, 1.5) for mu = 0.85 = 18.165 printed 18.17); a
  // wrong exponent or factor in any formula is far outside.
  struct Row {
    double mu, beta_a, f_n, rho_mm, tau_max_nmm, g0_nmm, g15_nmm, s1_0, s1_15;
  };
  const std::vector<Row> rows = {
      {0.47, 4.9e9, 0.2, 1.196, 0.071, 0.071, 0.177, 1.58e-2, 8.66e-2},
      {0.47, 4.9e9, 5, 2.709, 4.045, 4.045, 10.04, 0.415, 2.28},
      {0.47, 4.9e9, 16, 3.640, 17.39, 17.39, 43.19, 1.35, 7.43},
      {0.85, 1.24e7, 0.2, 1.196, 0.129, 0.129, 0.321, 3.99e-5, 2.19e-4},
      {0.85, 1.24e7, 5, 2.709, 7.316, 7.316, 18.17, 1.05e-3, 5.77e-3},
      {0.85, 1.24e7, 16, 3.640, 31.46, 31.46, 78.11, 3.42e-3, 1.88e-2},
  };
  const double rel = 4e-3;
  for (const Row& r : rows) {
    ContactParams p = table1_params();
    p.mu = r.mu;
    p.beta_a = r.beta_a;
    const ContactModel& m = model_for(p);
    SCOPED_TRACE("mu = " + std::to_string(r.mu) + ", f_n = " + std::to_string(r.f_n));
    EXPECT_NEAR(m.rho(r.f_n) * 1e3, r.rho_mm, 1e-3 * r.rho_mm);
    // 0.071 and 0.129 N mm have two significant digits: half a unit is 7e-3 relative.
    const double rel_tau = r.tau_max_nmm < 1.0 ? 7e-3 : rel;
    EXPECT_NEAR(m.tau_max(r.f_n) * 1e3, r.tau_max_nmm, rel_tau * r.tau_max_nmm);
    EXPECT_NEAR(m.g(r.f_n, 0.0) * 1e3, r.g0_nmm, rel_tau * r.g0_nmm);
    EXPECT_NEAR(m.g(r.f_n, 1.5) * 1e3, r.g15_nmm, rel * r.g15_nmm);
    EXPECT_NEAR(m.sigma_1(r.f_n, 0.0), r.s1_0, rel * r.s1_0);
    EXPECT_NEAR(m.sigma_1(r.f_n, 1.5), r.s1_15, rel * r.s1_15);
    EXPECT_NEAR(m.g(r.f_n, 0.0), m.tau_max(r.f_n), 1e-14 * m.tau_max(r.f_n));  // pure rotation: g = tau_max
  }
  // K at f_n = 5 N: 130 s/rad with Table 1, 0.18 s/rad for the big resin block (docs/model.md 5.1).
  EXPECT_NEAR(model_for(table1_params()).viscous_ratio(5.0), 130.0, 1.0);
  EXPECT_NEAR(model_for(object_params("big_resin_block")).viscous_ratio(5.0), 0.18, 0.005);
}

// ------------------------------------------------------------- sigma inversion (docs/model.md 5.2) ----

TEST(SigmaInversion, AppendixAValues) {
  const ContactModel& m = model_for(table1_params());
  EXPECT_NEAR(m.invert_sigma(2.066547), 1.0, 2e-6);
  EXPECT_NEAR(m.invert_sigma(3.736957), 1.5, 2e-6);
  EXPECT_NEAR(m.invert_sigma(30.0), 10.824, 5e-4);
  EXPECT_NEAR(m.invert_sigma(0.25237), 0.3, 2e-5);
  EXPECT_NEAR(m.invert_sigma(0.37946), 0.4, 2e-5);
  EXPECT_EQ(m.invert_sigma(-3.736957), m.invert_sigma(3.736957));  // |sigma|
  EXPECT_EQ(m.invert_sigma(0.0), 0.0);
  EXPECT_TRUE(std::isinf(m.invert_sigma(kInf)));
  EXPECT_TRUE(std::isnan(m.invert_sigma(kNaN)));
}

TEST(SigmaInversion, RoundTripOverTheWholeRange) {
  for (double k : {2.0, 4.0, kInf}) {
    for (double gamma : {0.254, 0.1, 0.33}) {
      ContactParams p = table1_params();
      p.k = k;
      p.gamma = gamma;
      const ContactModel& m = model_for(p);
      int worst_it = 0;
      for (double a = 1e-7; a < 1e6; a *= 1.037) {
        const double s = m.limit_surface().sigma_ls(a, gamma);
        int it = -1;
        const double back = m.invert_sigma(s, &it);
        ASSERT_NEAR(back, a, 1e-8 * a) << "k = " << k << ", gamma = " << gamma << ", a = " << a;
        ASSERT_GE(it, 0);
        worst_it = std::max(worst_it, it);
      }
      EXPECT_LE(worst_it, 60) << "k = " << k;
    }
  }
}

TEST(SigmaInversion, SolveOutsideRoundTrip) {
  // Sliding state = LS point plus a non-negative multiple of (2 xi a, 1) (docs/model.md 5.1).
  const ContactModel& m = model_for(table1_params());
  const LimitSurface& ls = m.limit_surface();
  const double xi = m.xi();
  for (double a : {1e-3, 0.05, 0.3, 0.7, 1.0, 1.2, 1.49}) {
    for (double lambda : {1e-6, 1e-3, 0.1, 1.0, 30.0}) {
      const LsPoint q = ls.eval(a);
      int it = -1;
      const double back = m.solve_outside(q.F + 2 * xi * a * lambda, q.T + lambda, &it);
      EXPECT_NEAR(back, a, 1e-9 * (1 + a)) << "a = " << a << ", lambda = " << lambda;
      EXPECT_GE(it, 1);
      EXPECT_LE(it, 62);
    }
  }
  // Root beyond the clip: c_max.
  const LsPoint q = ls.eval(4.0);
  EXPECT_EQ(m.solve_outside(q.F + 2 * xi * 4.0 * 0.1, q.T + 0.1), 1.5);
}

// ------------------------------------------------------------ CoR estimator round trips ----

TEST(CorEstimator, InsideRoundTripAtLargerNormalForce) {
  // A wrench on the LS at f_n0 evaluated at f_n > f_n0 lies on the same sigma-curve: same c~,
  // inside. Slightly below f_n0 it is outside.
  for (double k : {4.0, 2.0, kInf}) {
    const ContactParams p = with_cmax(1.5, k);
    const ContactModel& m = model_for(p);
    CorEstimator est(m);
    for (double a : {0.01, 0.1, 0.3, 0.5, 0.9, 1.0, 1.1, 1.45}) {
      for (double side : {1.0, -1.0}) {
        for (double f_n0 : {0.1, 2.0, 12.0}) {
          double f_t, tau;
          wrench_on_ls(m, f_n0, side * a, f_t, tau);
          SCOPED_TRACE("k = " + std::to_string(k) + ", c~ = " + std::to_string(side * a) +
                       ", f_n0 = " + std::to_string(f_n0));
          for (double ratio : {1.0001, 1.5, 4.0, 50.0}) {
            CorOutput o;
            const Status s = est.step({f_n0 * ratio, f_t, tau}, o);
            EXPECT_EQ(s, Status::Ok);
            EXPECT_EQ(o.status, Status::Ok);
            EXPECT_NEAR(o.c_tilde, side * a, 2e-8 * (1 + a)) << "ratio " << ratio;
            EXPECT_TRUE(o.inside) << "ratio " << ratio;
            EXPECT_FALSE(o.saturated);
          }
          CorOutput o;
          est.step({f_n0 * (1.0 - 1e-4), f_t, tau}, o);
          EXPECT_FALSE(o.inside);
          EXPECT_NEAR(o.c_tilde, side * a, 1e-3);  // continuous across the LS
          EXPECT_EQ(o.c_tilde > 0.0, side > 0.0);
        }
      }
    }
  }
}

TEST(CorEstimator, InsideBeyondClipSaturates) {
  const ContactModel& m = model_for(table1_params());
  CorEstimator est(m);
  for (double a : {1.6, 3.0, 20.0, 500.0}) {
    double f_t, tau;
    wrench_on_ls(m, 1.0, -a, f_t, tau);
    CorOutput o;
    EXPECT_EQ(est.step({3.0, f_t, tau}, o), Status::Saturated);
    EXPECT_EQ(o.c_tilde, -1.5);
    EXPECT_TRUE(o.saturated);
    EXPECT_TRUE(o.inside);
  }
}

TEST(CorEstimator, OutsideRoundTripWithViscousExcess) {
  // Eqs. 9-10 with omega != 0: the estimator returns the CoR of the motion, flags it outside,
  // and the quasi-static speed |omega| = 2 xi (t - T(a)) / K is recovered (docs/model.md 5.4).
  for (const ContactParams& p : {table1_params(), object_params("big_resin_block"), with_cmax(3.0, 2.0)}) {
    const ContactModel& m = model_for(p);
    CorEstimator est(m);
    const double xi = m.xi();
    for (double f_n : {0.3, 5.0, 16.0}) {
      const double K = m.viscous_ratio(f_n);
      for (double a : {0.02, 0.3, 0.7, 1.0, 1.3, 1.45}) {
        for (double lambda : {1e-4, 0.01, 0.3, 3.0}) {
          for (double sw : {1.0, -1.0}) {
            const double omega = sw * lambda * 2.0 * xi / K;
            const double c_true = sw * a;  // sign(c~) = sign(omega)
            double f_t, tau;
            sliding_wrench(m, f_n, c_true, omega, f_t, tau);
            SCOPED_TRACE("f_n = " + std::to_string(f_n) + ", c~ = " + std::to_string(c_true) +
                         ", lambda = " + std::to_string(lambda));
            ASSERT_GT(f_t, 0.0);
            EXPECT_EQ(tau < 0.0, omega > 0.0);  // sign(tau) = -sign(omega)
            for (double ft_sign : {1.0, -1.0}) {  // reversed in-plane axis: c~ flips with f_t
              CorOutput o;
              EXPECT_EQ(est.step({f_n, ft_sign * f_t, tau}, o), Status::Ok);
              EXPECT_NEAR(o.c_tilde, ft_sign * c_true, 1e-8 * (1 + a));
              EXPECT_FALSE(o.inside);
              EXPECT_FALSE(o.saturated);
              const double t = std::fabs(o.tau_tilde);
              const double speed = 2.0 * xi * (t - m.limit_surface().T(o.c_tilde)) / K;
              EXPECT_NEAR(speed, std::fabs(omega), 1e-6 * std::fabs(omega) + 1e-12);
            }
          }
        }
      }
    }
  }
}

TEST(CorEstimator, OutsideBeyondClipSaturates) {
  const ContactModel& m = model_for(table1_params());
  CorEstimator est(m);
  const double K = m.viscous_ratio(5.0);
  double f_t, tau;
  sliding_wrench(m, 5.0, 6.0, 0.5 * 2.0 * m.xi() / K, f_t, tau);
  CorOutput o;
  EXPECT_EQ(est.step({5.0, f_t, tau}, o), Status::Saturated);
  EXPECT_EQ(o.c_tilde, 1.5);
  EXPECT_FALSE(o.inside);
  EXPECT_TRUE(o.saturated);
}

TEST(CorEstimator, WrenchAtRoundTrip) {
  // ContactModel::wrench_at is the inverse of the estimate (inside and outside).
  const ContactModel& m = model_for(table1_params());
  CorEstimator est(m);
  for (double a : {0.0, 0.2, 0.9, 1.3}) {
    for (double util : {0.3, 0.99, 1.5, 10.0}) {  // |y| / g
      for (double sy : {1.0, -1.0}) {
        const double f_n = 4.0, y = sy * util * m.g(f_n, a);
        double f_t, tau;
        m.wrench_at(f_n, a, y, f_t, tau);
        CorOutput o;
        est.step({f_n, f_t, tau}, o);
        SCOPED_TRACE("a = " + std::to_string(a) + ", |y|/g = " + std::to_string(util));
        EXPECT_NEAR(std::fabs(o.c_tilde), a, 1e-7);
        if (a > 0.0) {
          EXPECT_EQ(o.c_tilde < 0.0, y > 0.0);  // sign(c~) = -sign(y)
        }
        EXPECT_NEAR(o.y, y, 1e-7 * std::fabs(y));
        EXPECT_EQ(o.inside, util < 1.0);
      }
    }
  }
}

// ------------------------------------------------------------ sign rule and mirroring ----

TEST(CorEstimator, SignRuleAndMirroredLoads) {
  const ContactModel& m = model_for(table1_params());
  CorEstimator est(m);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < 20000; ++i) {
    const double f_n = 0.1 + 20.0 * u(rng);
    const double f_t = m.ft_max(f_n) * 2.0 * u(rng) + 1e-3;
    const double tau = m.tau_max(f_n) * (2.0 * u(rng) + 1e-3);
    CorOutput pp, np, pn, nn;
    est.step({f_n, f_t, tau}, pp);
    est.step({f_n, -f_t, tau}, np);
    est.step({f_n, f_t, -tau}, pn);
    est.step({f_n, -f_t, -tau}, nn);
    ASSERT_TRUE(is_valid(pp.status));
    // sign(c~) = -sign(f_t) sign(tau)
    ASSERT_LT(pp.c_tilde, 0.0) << f_n << " " << f_t << " " << tau;
    ASSERT_GT(np.c_tilde, 0.0);
    ASSERT_GT(pn.c_tilde, 0.0);
    ASSERT_LT(nn.c_tilde, 0.0);
    // Mirrored loads give mirrored CoRs, same inside flag, same capacity.
    ASSERT_EQ(np.c_tilde, -pp.c_tilde);
    ASSERT_EQ(pn.c_tilde, -pp.c_tilde);
    ASSERT_EQ(nn.c_tilde, pp.c_tilde);
    ASSERT_EQ(pn.inside, pp.inside);
    ASSERT_EQ(np.inside, pp.inside);
    ASSERT_EQ(pn.g, pp.g);
    ASSERT_NEAR(pn.y, -pp.y, 1e-15 * std::fabs(pp.y));  // z flipped: y flips
    ASSERT_NEAR(np.y, pp.y, 1e-15 * std::fabs(pp.y));   // frame rotated by pi: y unchanged
    // The load-motion inequality: tau and c have opposite signs.
    ASSERT_LT(pp.c * tau, 0.0);
  }
}

TEST(CorEstimator, OutputFieldsAreConsistent) {
  const ContactParams p = table1_params();
  const ContactModel& m = model_for(p);
  CorEstimator est(m);
  const double xi = m.xi();
  for (double f_n : {0.05, 1.0, 7.0}) {
    for (double c : {-1.2, -0.3, 0.4, 1.0}) {
      for (double util : {0.5, 2.0}) {
        double f_t, tau;
        m.wrench_at(f_n, c, -(c < 0 ? -1.0 : 1.0) * util * m.g(f_n, c), f_t, tau);
        CorOutput o;
        est.step({f_n, f_t, tau}, o);
        const double rho = p.delta * std::pow(f_n, p.gamma);
        EXPECT_NEAR(o.rho, rho, 1e-15 * rho);
        EXPECT_NEAR(o.ft_tilde, f_t / (p.mu * f_n), 1e-14);
        EXPECT_NEAR(o.tau_tilde, tau / (p.mu * xi * rho * f_n), 1e-13);
        // eq. 14 from raw f_t, tau (f_n cancels)
        const double sigma = xi * p.delta / std::pow(p.mu, p.gamma) * std::pow(std::fabs(f_t), p.gamma + 1) / tau;
        EXPECT_NEAR(o.sigma, sigma, 1e-12 * std::fabs(sigma));
        EXPECT_NEAR(o.c, o.c_tilde * rho, 1e-15 * rho);
        EXPECT_NEAR(o.y, tau - o.c * f_t, 1e-15);  // eq. 16
        EXPECT_NEAR(o.g, m.g(f_n, o.c_tilde), 1e-13 * o.g);
        EXPECT_NEAR(o.sigma_1, m.sigma_1(f_n, o.c_tilde), 1e-13 * o.sigma_1);
        EXPECT_NEAR(o.c_tilde, c, 1e-7);
        // Static utilization |tau - c f_t| / g: < 1 inside, > 1 outside, 1 on the LS (docs/model.md 6).
        EXPECT_NEAR(std::fabs(o.y) / o.g, util, 1e-7);
      }
    }
  }
}

// The lumped plant (GraspPlant) takes rho, g and sigma_1 of a fresh estimate from the CorOutput
// instead of calling ContactModel::rho / g / sigma_1 again; that is only an exact shortcut if the
// estimator's fields are bit-identical to those functions. Checked on every branch (inside,
// outside, saturated, pure torque, degenerate) at random loads.
TEST(CorEstimator, RhoGSigma1AreBitIdenticalToTheModelFunctions) {
  for (const ContactParams& p : {table1_params(), object_params("small_resin_block")}) {
    const ContactModel& m = model_for(p);
    CorEstimator est(m);
    std::mt19937 gen(77);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    int fresh = 0, by_status[3] = {0, 0, 0};
    for (int i = 0; i < 20000; ++i) {
      const double f_n = 0.03 * std::pow(500.0, u(gen));
      const double tmax = p.mu * m.xi() * p.delta * std::pow(f_n, p.gamma + 1.0);
      double f_t = p.mu * f_n * 2.0 * u(gen), tau = tmax * (4.0 * u(gen) - 2.0);
      switch (i % 10) {
        case 0: f_t = 0.0; break;                   // pure torque
        case 1: f_t = 0.0; tau = 0.0; break;         // degenerate (previous CoR held)
        case 2: tau = 1e-3 * tmax * u(gen); break;   // translation-dominated: saturated
        default: break;
      }
      CorOutput o;
      const Status st = est.step({f_n, f_t, tau}, o);
      ASSERT_TRUE(st == Status::Ok || st == Status::Saturated || st == Status::Degenerate) << to_string(st);
      ++fresh;
      ++by_status[static_cast<int>(st)];
      ASSERT_EQ(o.rho, m.rho(f_n)) << f_n;
      ASSERT_EQ(o.g, m.g(f_n, o.c_tilde)) << f_n << " " << f_t << " " << tau;
      ASSERT_EQ(o.sigma_1, m.sigma_1(f_n, o.c_tilde)) << f_n << " " << f_t << " " << tau;
      ASSERT_EQ(o.c, o.c_tilde * m.rho(f_n));
    }
    EXPECT_EQ(fresh, 20000);
    EXPECT_GT(by_status[0], 1000);  // every branch was exercised
    EXPECT_GT(by_status[1], 1000);
    EXPECT_GT(by_status[2], 1000);
  }
}

// ------------------------------------------------------------ degenerate cases (docs/model.md 5.5) ----

TEST(CorEstimator, DegenerateCases) {
  const ContactModel& m = model_for(table1_params());
  CorEstimator est(m);
  CorOutput o;
  // tau = 0, f_t != 0: pure translation, |c~| = c_max (saturated).
  EXPECT_EQ(est.step({5.0, 1.0, 0.0}, o), Status::Saturated);
  EXPECT_EQ(std::fabs(o.c_tilde), 1.5);
  EXPECT_TRUE(o.saturated);
  EXPECT_TRUE(all_finite(o));
  // The side of a torque below the threshold is held from the previous estimate.
  double f_t, tau;
  wrench_on_ls(m, 5.0, -0.4, f_t, tau);
  est.step({6.0, f_t, tau}, o);
  ASSERT_NEAR(o.c_tilde, -0.4, 1e-8);
  EXPECT_EQ(est.step({5.0, 1.0, 0.0}, o), Status::Saturated);
  EXPECT_EQ(o.c_tilde, -1.5);
  EXPECT_EQ(est.step({5.0, 1.0, 1e-12}, o), Status::Saturated);  // |tau~| < zero_torque
  EXPECT_EQ(o.c_tilde, -1.5);
  // f_t = 0, tau != 0: pure rotation, c~ = 0.
  for (double t : {1e-3, -1e-3, 1e-6}) {
    EXPECT_EQ(est.step({5.0, 0.0, t}, o), Status::Ok);
    EXPECT_EQ(o.c_tilde, 0.0);
    EXPECT_EQ(o.c, 0.0);
    EXPECT_EQ(o.y, t);
    EXPECT_NEAR(o.g, m.g(5.0, 0.0), 1e-18);
  }
  // Both ~ 0: previous c~ held, status Degenerate.
  wrench_on_ls(m, 2.0, 0.73, f_t, tau);
  est.step({3.0, f_t, tau}, o);
  const double held = o.c_tilde;
  ASSERT_NEAR(held, 0.73, 1e-8);
  for (const CorInput& in : std::vector<CorInput>{{5.0, 0.0, 0.0}, {5.0, 1e-9, -1e-12}, {9.0, -1e-6, 0.0}}) {
    EXPECT_EQ(est.step(in, o), Status::Degenerate);
    EXPECT_EQ(o.status, Status::Degenerate);
    EXPECT_EQ(o.c_tilde, held);
    EXPECT_NEAR(o.c, held * m.rho(in.f_n), 1e-15);  // rho at the current f_n
    EXPECT_TRUE(all_finite(o));
  }
  // From a fresh estimator the held value is 0.
  CorEstimator fresh(m);
  EXPECT_EQ(fresh.step({5.0, 0.0, 0.0}, o), Status::Degenerate);
  EXPECT_EQ(o.c_tilde, 0.0);
  EXPECT_TRUE(all_finite(o));
}

TEST(CorEstimator, InvalidAndNoContactSamplesHoldThePreviousEstimate) {
  const ContactModel& m = model_for(table1_params());
  CorEstimator est(m);
  CorOutput o;
  // Before any valid sample: finite defaults.
  EXPECT_EQ(est.step({kNaN, 1.0, 0.0}, o), Status::InvalidSample);
  EXPECT_TRUE(all_finite(o));
  EXPECT_EQ(o.c_tilde, 0.0);
  double f_t, tau;
  wrench_on_ls(m, 3.0, 0.6, f_t, tau);
  CorOutput good;
  ASSERT_EQ(est.step({4.0, f_t, tau}, good), Status::Ok);
  const std::vector<std::pair<CorInput, Status>> bad = {
      {{kNaN, f_t, tau}, Status::InvalidSample},    {{4.0, kNaN, tau}, Status::InvalidSample},
      {{4.0, f_t, kNaN}, Status::InvalidSample},    {{kInf, f_t, tau}, Status::InvalidSample},
      {{-kInf, f_t, tau}, Status::InvalidSample},   {{4.0, kInf, tau}, Status::InvalidSample},
      {{4.0, f_t, -kInf}, Status::InvalidSample},   {{1e5, f_t, tau}, Status::InvalidSample},
      {{1e300, f_t, tau}, Status::InvalidSample},   {{4.0, -1e300, tau}, Status::InvalidSample},
      {{4.0, f_t, 1e4}, Status::InvalidSample},     {{-1e300, f_t, tau}, Status::InvalidSample},
      {{0.0, f_t, tau}, Status::NoContact},         {{-0.0, f_t, tau}, Status::NoContact},
      {{-4.0, f_t, tau}, Status::NoContact},        {{0.029, f_t, tau}, Status::NoContact},
      {{1e-300, f_t, tau}, Status::NoContact},      {{4.9e-324, f_t, tau}, Status::NoContact},
  };
  for (const auto& [in, expected] : bad) {
    SCOPED_TRACE("f_n = " + std::to_string(in.f_n) + ", f_t = " + std::to_string(in.f_t) +
                 ", tau = " + std::to_string(in.tau));
    EXPECT_EQ(est.step(in, o), expected);
    EXPECT_EQ(o.status, expected);
    EXPECT_TRUE(all_finite(o));
    EXPECT_EQ(o.c_tilde, good.c_tilde);
    EXPECT_EQ(o.c, good.c);
    EXPECT_EQ(o.g, good.g);
    EXPECT_EQ(o.y, good.y);
    EXPECT_EQ(o.iterations, 0);
  }
  // The threshold itself is contact.
  EXPECT_EQ(est.step({0.03, 0.0, 1e-6}, o), Status::Ok);
  // After the bad samples the estimator continues normally.
  EXPECT_EQ(est.step({4.0, f_t, tau}, o), Status::Ok);
  EXPECT_EQ(o.c_tilde, good.c_tilde);
  // reset() forgets the held estimate.
  est.reset();
  EXPECT_EQ(est.step({kNaN, 0.0, 0.0}, o), Status::InvalidSample);
  EXPECT_EQ(o.c_tilde, 0.0);
}

// ------------------------------------------------------------ saturation (docs/model.md 5.6) ----

TEST(CorEstimator, SaturationAtCustomCmax) {
  for (double c_max : {0.5, 1.0, 3.0, 10.0, 100.0}) {
    const ContactModel& m = model_for(with_cmax(c_max));
    CorEstimator est(m);
    CorOutput o;
    EXPECT_EQ(est.step({2.0, 0.5, 0.0}, o), Status::Saturated);  // pure translation
    EXPECT_EQ(std::fabs(o.c_tilde), c_max);
    EXPECT_TRUE(o.saturated);
    // Just below the clip the estimate is not clipped.
    double f_t, tau;
    wrench_on_ls(m, 1.0, 0.9 * c_max, f_t, tau);
    EXPECT_EQ(est.step({1.5, f_t, tau}, o), Status::Ok);
    EXPECT_NEAR(o.c_tilde, 0.9 * c_max, 1e-7 * c_max);
    EXPECT_FALSE(o.saturated);
  }
}

TEST(CorEstimator, TranslationalSlipThreshold) {
  // With |c~| clipped at c_max, a pure translational load reaches S_static = |y|/g = 1 at
  // f_t/(mu f_n) = F(c_max) + xi T(c_max)/c_max (docs/model.md 5.6): 1.0518 for c_max = 1.5.
  const std::vector<std::pair<double, double>> table = {{1.0, 1.120}, {1.5, 1.052}, {2.0, 1.029},
                                                        {5.0, 1.0046}, {10.0, 1.0011}, {20.0, 1.0003}};
  for (const auto& [c_max, printed] : table) {
    const ContactModel& m = model_for(with_cmax(c_max));
    CorEstimator est(m);
    const LimitSurface& ls = m.limit_surface();
    const double thr = ls.F(c_max) + m.xi() * ls.T(c_max) / c_max;
    const double digits = c_max < 5.0 ? 5e-4 : 5e-5;
    EXPECT_NEAR(thr, printed, digits) << "c_max = " << c_max;
    const double f_n = 5.0;
    for (double r : {0.5 * thr, thr * (1 - 1e-6), thr, thr * (1 + 1e-6), 1.2 * thr}) {
      CorOutput o;
      est.step({f_n, r * m.ft_max(f_n), 0.0}, o);
      ASSERT_EQ(std::fabs(o.c_tilde), c_max);
      const double S = std::fabs(o.y) / o.g;
      EXPECT_NEAR(S, r / thr, 1e-12) << "c_max = " << c_max << ", f~_t = " << r;
    }
  }
  const ContactModel& m = model_for(table1_params());
  EXPECT_NEAR(m.limit_surface().F(1.5) + m.xi() * m.limit_surface().T(1.5) / 1.5, 1.0518, 5e-5);  // Appendix A
}

// ------------------------------------------------------------ seeded random property test ----

namespace {
double draw(std::mt19937_64& rng, double scale) {
  std::uniform_int_distribution<int> kind(0, 19);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  switch (kind(rng)) {
    case 0: return std::numeric_limits<double>::quiet_NaN();
    case 1: return u(rng) < 0 ? -kInf : kInf;
    case 2: return u(rng) * 1e300;
    case 3: return 0.0;
    case 4: return u(rng) * 1e-300;
    case 5: return std::numeric_limits<double>::denorm_min() * (u(rng) < 0 ? -1 : 1);
    case 6: return u(rng) * 2e4 * scale;  // partly beyond the sensor range
    case 7: {  // arbitrary bit pattern
      std::uint64_t bits = rng();
      double d;
      std::memcpy(&d, &bits, sizeof d);
      return d;
    }
    default: return u(rng) * scale * std::pow(10.0, 4.0 * u(rng));  // physical, log-spread
  }
}
}  // namespace

TEST(CorEstimatorProperty, MillionRandomSamples) {
  // Every output finite, |c~| <= c_max, bounded iterations, a known status; the estimate of a
  // non-degenerate sample does not depend on the history (no initial-guess logic).
  const std::vector<ContactParams> params = {table1_params(), with_cmax(10.0, 2.0), with_cmax(1.0, kInf),
                                             object_params("aluminium_can")};
  // Defaults: 4 x 300000 samples, seed 20240611. Longer runs: LUGRIP_PROPERTY_SAMPLES (per
  // parameter set) and LUGRIP_PROPERTY_SEED in the environment.
  const char* env_n = std::getenv("LUGRIP_PROPERTY_SAMPLES");
  const char* env_seed = std::getenv("LUGRIP_PROPERTY_SEED");
  const int per = env_n ? std::max(1, std::atoi(env_n)) : 300000;
  const std::uint64_t seed = env_seed ? std::strtoull(env_seed, nullptr, 10) : 20240611u;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  long total = 0, valid = 0, saturated = 0, outside = 0;
  int max_iter = 0;
  for (const ContactParams& p : params) {
    const ContactModel& m = model_for(p);
    CorEstimator est(m);
    CorOutput o;
    for (int i = 0; i < per; ++i) {
      CorInput in;
      if (u(rng) < 0.5) {  // physically plausible wrench around the LS
        in.f_n = std::pow(10.0, -2.0 + 4.0 * u(rng));
        in.f_t = (u(rng) < 0.5 ? -1 : 1) * m.ft_max(in.f_n) * 3.0 * u(rng) * u(rng);
        in.tau = (u(rng) < 0.5 ? -1 : 1) * m.tau_max(in.f_n) * 3.0 * u(rng) * u(rng);
      } else {
        in.f_n = draw(rng, 10.0);
        in.f_t = draw(rng, 5.0);
        in.tau = draw(rng, 0.02);
      }
      const Status s = est.step(in, o);
      ++total;
      ASSERT_EQ(s, o.status);
      ASSERT_TRUE(known_status(s)) << static_cast<int>(s);
      ASSERT_TRUE(s == Status::Ok || s == Status::Saturated || s == Status::Degenerate || s == Status::NoContact ||
                  s == Status::InvalidSample);
      ASSERT_TRUE(all_finite(o)) << "f_n = " << in.f_n << ", f_t = " << in.f_t << ", tau = " << in.tau;
      ASSERT_LE(std::fabs(o.c_tilde), p.c_max);
      ASSERT_GE(o.iterations, 0);
      ASSERT_LE(o.iterations, 62);
      ASSERT_GT(o.g, -1e-300);
      max_iter = std::max(max_iter, o.iterations);
      if (s == Status::Ok || s == Status::Saturated) {
        ++valid;
        saturated += s == Status::Saturated;
        outside += !o.inside;
        ASSERT_GT(o.g, 0.0);
        ASSERT_EQ(o.saturated, s == Status::Saturated);
        if (std::fabs(o.tau_tilde) >= est.settings().zero_torque && std::fabs(o.ft_tilde) >= est.settings().zero_force) {
          ASSERT_EQ(o.c_tilde < 0.0, (in.f_t < 0.0) == (in.tau < 0.0)) << in.f_n << " " << in.f_t << " " << in.tau;
        }
        if (i % 97 == 0 && std::fabs(o.tau_tilde) >= est.settings().zero_torque) {
          CorEstimator fresh(m);
          CorOutput f;
          fresh.step(in, f);
          ASSERT_EQ(f.c_tilde, o.c_tilde);
          ASSERT_EQ(f.inside, o.inside);
        }
      }
    }
  }
  std::printf("  [property] seed %llu: %ld samples, %ld valid (%ld saturated, %ld outside), max iterations %d\n",
              static_cast<unsigned long long>(seed), total, valid,
              saturated, outside, max_iter);
  if (!env_n) EXPECT_GE(total, 1000000);
  EXPECT_GT(valid, total / 3);      // the generator exercises the estimator, not only the guards
  EXPECT_GT(outside, valid / 20);
  EXPECT_GT(saturated, valid / 50);
}

TEST(CorEstimatorProperty, ExtremeButValidParametersAndSettings) {
  // Every field at the edge of what validate() accepts, settings down to the smallest positive
  // double: still finite outputs and a status for every sample (f_t,max or tau_max underflow
  // for a denormal f_n is an InvalidSample, not Inf/NaN).
  std::vector<ContactParams> params;
  const ContactParams base = table1_params();
  auto edit = [&](double ContactParams::*m, double v) {
    ContactParams p = base;
    p.*m = v;
    params.push_back(p);
  };
  edit(&ContactParams::mu, 1e-300);
  edit(&ContactParams::mu, 10.0);
  edit(&ContactParams::beta_a, 0.0);
  edit(&ContactParams::beta_a, 1e300);
  edit(&ContactParams::delta, 1e-300);
  edit(&ContactParams::delta, 0.999);
  edit(&ContactParams::gamma, 1e-12);
  edit(&ContactParams::gamma, 0.3333333);
  edit(&ContactParams::k, 1e6);
  edit(&ContactParams::k, kInf);
  edit(&ContactParams::c_max, 1e-3);
  edit(&ContactParams::c_max, 1000.0);
  CorSettings tiny;
  tiny.f_n_min = std::numeric_limits<double>::denorm_min();
  tiny.zero_force = tiny.zero_torque = std::numeric_limits<double>::denorm_min();
  tiny.force_limit = tiny.torque_limit = std::numeric_limits<double>::max();
  CorSettings huge;
  huge.f_n_min = std::numeric_limits<double>::denorm_min();
  huge.zero_force = huge.zero_torque = 1e300;
  std::mt19937_64 rng(99);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  auto logu = [&](double lo, double hi) { return std::pow(10.0, lo + (hi - lo) * u(rng)); };
  long valid = 0;
  int max_iter = 0;
  for (const ContactParams& p : params) {
    ASSERT_TRUE(validate(p, nullptr));
    const ContactModel& m = model_for(p);
    for (const CorSettings& s : {tiny, huge}) {
      CorEstimator est(m, s);
      CorOutput o;
      for (int i = 0; i < 20000; ++i) {
        CorInput in{logu(-323, 300), (u(rng) < 0.5 ? -1 : 1) * logu(-323, 300),
                    (u(rng) < 0.5 ? -1 : 1) * logu(-323, 300)};
        if (i % 5 == 0) in.f_n = std::numeric_limits<double>::denorm_min();
        if (i % 7 == 0) in.tau = 0.0;
        const Status st = est.step(in, o);
        ASSERT_TRUE(known_status(st));
        ASSERT_TRUE(all_finite(o)) << to_string(p) << "\nf_n = " << in.f_n << ", f_t = " << in.f_t
                                   << ", tau = " << in.tau;
        ASSERT_LE(std::fabs(o.c_tilde), p.c_max);
        max_iter = std::max(max_iter, o.iterations);
        ASSERT_GE(o.g, 0.0);
        valid += is_valid(st);
      }
    }
  }
  std::printf("  [extreme] max iterations %d\n", max_iter);
  EXPECT_LE(max_iter, 200);
  EXPECT_GT(valid, 10000);
}

// Consistency: the contact model on the elliptic limit surface (k = 0) inverts sigma_LS of the
// closed form (f~ = u/sqrt(1+u^2), tau~ = 1/sqrt(1+u^2), u = a/xi, written here) back to a,
// and its capacity about the CoR is mu f_n rho (xi tau~ + a f~) = mu f_n rho xi sqrt(1+u^2).
TEST(EllipticContactModel, InvertsSigmaAndGivesTheClosedFormCapacity) {
  ContactParams p = table1_params();
  p.k = lugrip::kEllipticLimitSurface;
  const lugrip::ContactModel m(p);
  const double xi = lugrip::kEllipseShapeFactor;
  EXPECT_NEAR(m.tau_max(3.0), p.mu * xi * p.delta * std::pow(3.0, 1.0 + p.gamma), 1e-15);
  for (double a = 1e-3; a < 2e3; a *= 1.9) {
    const double u = a / xi, F = u / std::sqrt(1.0 + u * u), T = 1.0 / std::sqrt(1.0 + u * u);
    const double s = std::pow(F, 1.0 + p.gamma) / T;
    EXPECT_NEAR(m.invert_sigma(s, nullptr), a, 1e-8 * a) << "a = " << a;
    const double f_n = 2.5;
    EXPECT_NEAR(m.g(f_n, a), p.mu * f_n * m.rho(f_n) * xi * std::sqrt(1.0 + u * u), 1e-12 * m.g(f_n, a))
        << "a = " << a;
  }
}
