// Sliding-velocity observer (paper eqs. 19-23) and slippage indicator S (eq. 37).
//
// Plant data: SliderModel (eqs. 1-2 about a known CoR) and the sensor wrench built from the
// plant's friction torque about the CoR with ContactModel::wrench_at (the inverse of the CoR
// estimate), optionally with white noise. The sign test builds the wrench from first principles
// instead (quadrature of dry + viscous stress over the contact patch).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "lugrip/observer.hpp"

using namespace lugrip;

namespace {

constexpr double kDt = 0.002;
constexpr double kPi = 3.14159265358979323846;

struct Samples {
  std::vector<double> f_n, f_t, tau;
  std::vector<double> omega, slip, load;  // plant ground truth; load = tau_e / g
};

// Plant driven by tau_e(t) = profile(t) g(f_n, c~); sensor = wrench_at(friction torque) + noise.
template <class Profile>
Samples plant_data(const ContactParams& p, double f_n, double ct, int n, Profile&& profile,
                   double tau_noise = 0.0, double force_noise = 0.0, unsigned seed = 1) {
  SliderModel sim(p, 1e-4);
  const ContactModel& m = sim.model();
  const double g = m.g(f_n, ct);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  Samples s;
  SliderOutput out;
  for (int i = 0; i < n; ++i) {
    const double load = profile(i * kDt);
    sim.step(SliderInput{f_n, ct, load * g, kDt}, out);
    double ft = 0.0, tau = 0.0;
    m.wrench_at(f_n, ct, out.friction_torque, ft, tau);
    s.f_n.push_back(f_n + force_noise * normal(rng));
    s.f_t.push_back(std::fabs(ft + force_noise * normal(rng)));
    s.tau.push_back(tau + tau_noise * normal(rng));
    s.omega.push_back(out.omega);
    s.slip.push_back(out.slip);
    s.load.push_back(load);
  }
  return s;
}

// Constant sensor wrench whose friction torque about the CoR (|c~| = ct) is y.
Samples constant_wrench(const ContactModel& m, double f_n, double ct, double y, int n) {
  double ft = 0.0, tau = 0.0;
  m.wrench_at(f_n, ct, y, ft, tau);
  Samples s;
  s.f_n.assign(n, f_n);
  s.f_t.assign(n, ft);
  s.tau.assign(n, tau);
  return s;
}

std::vector<ObserverOutput> observe(Observer& obs, const Samples& s) {
  std::vector<ObserverOutput> out(s.f_n.size());
  for (size_t i = 0; i < s.f_n.size(); ++i) obs.step(ObserverInput{s.f_n[i], s.f_t[i], s.tau[i], kDt}, out[i]);
  return out;
}

ObserverSettings settings_with(Integrator i, GainMode m) {
  ObserverSettings s;
  s.integrator = i;
  s.gain_mode = m;
  return s;
}

double rmse(const std::vector<ObserverOutput>& o, const std::vector<double>& w) {
  double acc = 0.0;
  for (size_t i = 0; i < w.size(); ++i) acc += (o[i].omega_hat - w[i]) * (o[i].omega_hat - w[i]);
  return std::sqrt(acc / w.size());
}

// Wrench the OBJECT exerts on the FINGERTIP (the sensor's reading, z along the contact normal)
// when the object rotates with omega about the point (c cos phi, c sin phi) of the patch plane:
// quadrature of the dry stress mu p v/|v| and the viscous stress beta_A v over the patch, with
// the pressure p ~ (1 - (r/rho)^k)^(1/k) and v = omega z x (r - r_c) the object's velocity
// relative to the fingertip. Independent of the limit-surface tables and their sign conventions.
struct Wrench {
  double fx = 0.0, fy = 0.0, tau = 0.0;
};
Wrench patch_wrench(const ContactParams& p, double f_n, double c, double phi, double omega) {
  const int nr = 200, nt = 256;
  const double rho = p.delta * std::pow(f_n, p.gamma);
  const double dr = rho / nr, dth = 2.0 * kPi / nt;
  const double cx = c * std::cos(phi), cy = c * std::sin(phi);
  double wsum = 0.0;
  for (int i = 0; i < nr; ++i) {
    const double r = (i + 0.5) * dr;
    wsum += std::pow(1.0 - std::pow(r / rho, p.k), 1.0 / p.k) * r * dr * dth * nt;
  }
  const double p0 = f_n / wsum;
  Wrench w;
  for (int i = 0; i < nr; ++i) {
    const double r = (i + 0.5) * dr;
    const double pr = p0 * std::pow(1.0 - std::pow(r / rho, p.k), 1.0 / p.k);
    const double da = r * dr * dth;
    for (int j = 0; j < nt; ++j) {
      const double th = (j + 0.5) * dth;
      const double x = r * std::cos(th), y = r * std::sin(th);
      const double vx = -omega * (y - cy), vy = omega * (x - cx);
      const double v = std::hypot(vx, vy);
      const double fx = (p.mu * pr * vx / v + p.beta_a * vx) * da;
      const double fy = (p.mu * pr * vy / v + p.beta_a * vy) * da;
      w.fx += fx;
      w.fy += fy;
      w.tau += x * fy - y * fx;
    }
  }
  return w;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Steady states
// ---------------------------------------------------------------------------------------------

TEST(PlanarNorm, WithinAnUlpOfHypotOverEveryScale) {
  // log-uniform magnitudes from 1e-320 (denormal) to 1e307, random signs: at most one ulp from
  // std::hypot (its own error is below one ulp), exact special values.
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> e(-320.0, 307.0), sgn(-1.0, 1.0);
  int worst = 0;
  for (int k = 0; k < 1000000; ++k) {
    const double x = std::copysign(std::pow(10.0, e(rng)), sgn(rng));
    const double y = k % 4 == 0 ? x * sgn(rng) : std::copysign(std::pow(10.0, e(rng)), sgn(rng));
    const double a = planar_norm(x, y), b = std::hypot(x, y);
    ASSERT_TRUE(std::isfinite(a)) << x << " " << y;
    int ulps = 0;
    for (double v = std::min(a, b); v < std::max(a, b) && ulps < 10; v = std::nextafter(v, 1e308)) ++ulps;
    worst = std::max(worst, ulps);
  }
  EXPECT_LE(worst, 1);
  const double inf = std::numeric_limits<double>::infinity(), nan = std::nan("");
  EXPECT_EQ(planar_norm(0.0, 0.0), 0.0);
  EXPECT_EQ(planar_norm(-3.0, 4.0), 5.0);
  EXPECT_EQ(planar_norm(1e200, 1e200), std::hypot(1e200, 1e200));
  EXPECT_EQ(planar_norm(inf, nan), inf);
  EXPECT_TRUE(std::isnan(planar_norm(nan, 1.0)));
  EXPECT_EQ(planar_norm(-inf, 0.0), inf);
  EXPECT_EQ(ObserverInput::from_force_vector(2.0, 0.3, -0.4, 0.01).f_t, planar_norm(0.3, -0.4));
}

TEST(Observer, SteadySlidingOnTheStaticFrictionCurve) {
  // Constant slip speed w0: the sensor reads y = sign(w0) g + sigma_1 w0 (LuGre steady state).
  // Expected: z_hat -> sign(w0) g/sigma0 (S -> 1), omega_hat -> w0 (sigma_1 significant).
  for (const char* object : {"table1", "aluminium_can"}) {
    const ContactParams p = std::string(object) == "table1" ? table1_params() : object_params(object);
    const ContactModel m(p);
    const double f_n = 3.0, ct = 0.6;
    const double g = m.g(f_n, ct), s1 = m.sigma_1(f_n, ct);
    for (Integrator scheme : {Integrator::Rosenbrock, Integrator::Implicit, Integrator::Rk4Adaptive}) {
      for (GainMode mode : {GainMode::Bandwidth, GainMode::Fixed}) {
        // weak viscous friction: l = 200 needs ~ 1/(l sigma_1) s; Implicit is slow (next test)
        if (s1 < 0.01 && (mode == GainMode::Fixed || scheme == Integrator::Implicit)) continue;
        for (double w0 : {0.01, -0.2}) {
          SCOPED_TRACE(std::string(object) + " " + to_string(scheme) + " " + to_string(mode) + " w0=" + std::to_string(w0));
          Observer obs(m, settings_with(scheme, mode));
          const auto out = observe(obs, constant_wrench(m, f_n, ct, std::copysign(g, w0) + s1 * w0, 1500));
          const ObserverOutput& e = out.back();
          EXPECT_EQ(e.status, Status::Ok);
          EXPECT_NEAR(e.omega_hat, w0, 1e-6 * std::fabs(w0));
          EXPECT_NEAR(e.z_hat, std::copysign(g, w0) / p.sigma0, 1e-12);
          EXPECT_NEAR(e.S, 1.0, 1e-9);
          EXPECT_NEAR(std::fabs(e.c_tilde), ct, 1e-6);
          EXPECT_NEAR(e.g, g, 1e-9 * g);
        }
      }
    }
  }
}

TEST(Observer, ImplicitSchemeIsSecondsLateWithWeakViscousFriction) {
  // Why Rosenbrock is the default: with weak viscous friction the bandwidth gain is large
  // (l = B / sigma_1 ~ 5e4) and h l sigma_z >> 1. The exponential-implicit scheme freezes the
  // bristle rate at the previous sample, so in sliding the micro-damping sigma_z acts like extra
  // viscous damping: per sample omega_hat approaches its steady value by only
  // h l sigma_1 / (1 + h l (sigma_1 + sigma_z)) ~ sigma_1 / sigma_z ~ 1e-3. Rosenbrock (exact
  // Jacobian) converges at the bandwidth B (default 3000/s).
  const ContactParams p = object_params("aluminium_can");
  const ContactModel m(p);
  const double f_n = 3.0, ct = 0.6, w0 = 0.01;
  const double g = m.g(f_n, ct), s1 = m.sigma_1(f_n, ct);
  const Samples s = constant_wrench(m, f_n, ct, g + s1 * w0, 1500);
  auto time_to_1pct = [&](Integrator scheme) {
    Observer obs(m, settings_with(scheme, GainMode::Bandwidth));
    const auto out = observe(obs, s);
    for (size_t i = 0; i < out.size(); ++i)
      if (std::fabs(out[i].omega_hat - w0) < 0.01 * w0) return i * kDt;
    return std::numeric_limits<double>::infinity();
  };
  EXPECT_LT(time_to_1pct(Integrator::Rosenbrock), 0.1);
  EXPECT_LT(time_to_1pct(Integrator::Rk4Adaptive), 0.1);
  EXPECT_GT(time_to_1pct(Integrator::Implicit), 2.0);
}

TEST(Observer, StickConstantLoadInsideTheLimitSurface) {
  // Constant load inside the LS: omega_hat -> 0, sigma0 z_hat -> y and S -> S_static = |y|/g,
  // which equals (xi |tau~| + a f~_t) / (xi T(a) + a F(a)) computed from the wrench (docs/model.md 6).
  for (const char* object : {"table1", "big_resin_block"}) {
    const ContactParams p = std::string(object) == "table1" ? table1_params() : object_params(object);
    const ContactModel m(p);
    for (double frac : {0.3, 0.85}) {
      const double f_n = 4.0, ct = 1.1;
      const double g = m.g(f_n, ct);
      const Samples s = constant_wrench(m, f_n, ct, -frac * g, 2500);
      Observer obs(m);
      const auto out = observe(obs, s);
      const ObserverOutput& e = out.back();
      const double ft_n = s.f_t[0] / m.ft_max(f_n), tau_n = std::fabs(s.tau[0]) / m.tau_max(f_n);
      const LsPoint q = m.limit_surface().eval(ct);
      const double s_static = (m.xi() * tau_n + ct * ft_n) / (m.xi() * q.T + ct * q.F);
      SCOPED_TRACE(std::string(object) + " frac=" + std::to_string(frac));
      EXPECT_LT(std::fabs(e.omega_hat), 1e-9);
      EXPECT_NEAR(p.sigma0 * e.z_hat, -frac * g, 1e-9 * g);
      EXPECT_NEAR(e.S, frac, 1e-9);
      EXPECT_NEAR(e.S, s_static, 1e-6);
      EXPECT_TRUE(e.inside);
    }
  }
}

TEST(Observer, SlipOnsetDetectedWhenTheLoadCrossesTheLimitSurface) {
  // Load ramp (1 g/s) through the LS. The plant's own bristle state lags the load (time
  // constant ~ (sigma_z + sigma_1)/sigma0), so the reference is the plant's slip onset: its
  // sigma0 |z| / g reaching 0.99. Stated delay: the observer's S reaches 0.99 within 30 ms of it,
  // and no false alarm (S >= 0.99) while the plant is below 0.95. Noise at the spec's default.
  for (const char* object : {"table1", "aluminium_can"}) {
    const ContactParams p = std::string(object) == "table1" ? table1_params() : object_params(object);
    for (double ct : {0.4, 1.2}) {
      const Samples s = plant_data(p, 2.0, ct, 2000, [](double t) { return std::max(0.0, t - 0.2); },
                                   1e-5, 0.005, 7);
      Observer obs(p);
      const auto out = observe(obs, s);
      int i_true = -1, i_det = -1;
      for (size_t i = 0; i < out.size(); ++i) {
        if (i_true < 0 && s.slip[i] >= 0.99) i_true = static_cast<int>(i);
        if (i_det < 0 && out[i].S >= 0.99) i_det = static_cast<int>(i);
        if (s.slip[i] < 0.95) EXPECT_LT(out[i].S, 0.99) << object << " t=" << i * kDt;
      }
      SCOPED_TRACE(std::string(object) + " c~=" + std::to_string(ct));
      ASSERT_GE(i_true, 0);
      ASSERT_GE(i_det, 0);
      EXPECT_LE(std::abs(i_det - i_true) * kDt, 0.030);
      // and while sliding the slip direction is right
      for (size_t i = i_true + 50; i < out.size(); ++i)
        if (std::fabs(s.omega[i]) > 1e-3) EXPECT_GT(out[i].omega_hat * s.omega[i], 0.0);
    }
  }
}

TEST(Observer, SignOfOmegaHatFollowsGroundTruth) {
  // Wrench from first principles (patch quadrature, as a fingertip sensor reads it) for a known
  // rotation omega about a CoR off the patch centre, in a frame rotated by an arbitrary angle.
  // The observer is fed f_t = |(f_x, f_y)| and tau, as from a real sensor.
  const ContactParams p = table1_params();
  const ContactModel m(p);
  const double f_n = 5.0, rho = m.rho(f_n);
  for (double omega : {0.03, -0.03, 0.3, -0.3}) {
    for (double phi : {0.4, 2.5, -1.9}) {
      const Wrench w = patch_wrench(p, f_n, 0.7 * rho, phi, omega);
      Observer obs(p);
      ObserverOutput out;
      for (int i = 0; i < 1000; ++i) obs.step(ObserverInput::from_force_vector(f_n, w.fx, w.fy, w.tau, kDt), out);
      SCOPED_TRACE("omega=" + std::to_string(omega) + " phi=" + std::to_string(phi));
      EXPECT_GT(out.omega_hat * omega, 0.0);
      EXPECT_NEAR(out.omega_hat, omega, 0.03 * std::fabs(omega));  // quadrature vs LS tables
      EXPECT_NEAR(std::fabs(out.c_tilde), 0.7, 0.02);
      EXPECT_NEAR(out.S, 1.0, 1e-9);
      // The opposite wrench (fingertip on object) gives -omega_hat with the same S (docs/model.md 7.2).
      Observer flipped(p);
      ObserverOutput o2;
      for (int i = 0; i < 1000; ++i) flipped.step(ObserverInput::from_force_vector(f_n, -w.fx, -w.fy, -w.tau, kDt), o2);
      EXPECT_NEAR(o2.omega_hat, -out.omega_hat, 1e-12 * std::fabs(omega));
      EXPECT_NEAR(o2.S, out.S, 1e-12);
    }
  }
}

TEST(Observer, BeyondTheClipOmegaObjectOnAnIndependentPatchPlant) {
  // Independent plant: steady slip omega about a CoR at c~ rho (c~ from 0.5 to 20), wrench by
  // quadrature of the dry and viscous stress over the patch (patch_wrench), sensor noise 2e-5 N m
  // and 0.01 N; beta_A = 2e7 (speed observable at these forces), sigma_z = 1e-3 (with Table 1's
  // sigma_z = 2 the normal-force noise, through sigma_z dz/dt, biases omega_hat low by up to
  // 65 % at 0.1 rad/s and 2 N; noise-free it is exact). The truth is the prescribed
  // kinematics: omega, and the patch centre sliding at |omega| c~ rho.
  // Below the clip omega_object is omega_hat exactly; beyond it (c~ > 3) the error of
  // omega_object must not exceed that of predicting zero, where omega_hat's does.
  ContactParams p = table1_params();
  p.mu = 0.5;
  p.beta_a = 2e7;
  p.sigma_z = 1e-3;
  const ContactModel m(p);
  std::mt19937_64 rng(17);
  std::normal_distribution<double> normal(0.0, 1.0);
  double e_obj = 0.0, e_hat = 0.0, e_zero = 0.0, v_rel = 0.0, v_rel_clip = 0.0;
  int n_far = 0, n_near = 0;
  for (double f_n : {2.0, 6.0}) {
    const double rho = m.rho(f_n);
    for (double ct : {0.5, 1.0, 1.4, 3.0, 5.0, 10.0, 20.0}) {
      for (double omega : {0.1, -0.5, 1.0}) {
        const Wrench w = patch_wrench(p, f_n, ct * rho, 0.3, omega);
        Observer obs(m);
        ObserverOutput out;
        double w_obj = 0.0, w_hat = 0.0, v = 0.0;
        const int n = 600, tail = 200;
        for (int i = 0; i < n; ++i) {
          obs.step(ObserverInput::from_force_vector(f_n + 0.01 * normal(rng), w.fx + 0.01 * normal(rng),
                                                    w.fy + 0.01 * normal(rng), w.tau + 2e-5 * normal(rng), kDt),
                   out);
          ASSERT_GE(std::fabs(out.c_tilde_unclipped), std::fabs(out.c_tilde));
          ASSERT_LE(std::fabs(out.omega_object), std::fabs(out.omega_hat));
          if (!out.saturated) {  // nothing changes below the clip
            ASSERT_EQ(out.omega_object, out.omega_hat);
            ASSERT_EQ(out.c_tilde_unclipped, out.c_tilde);
            ASSERT_DOUBLE_EQ(out.v_slip, std::fabs(out.omega_hat * out.c));
          }
          if (i >= n - tail) {
            w_obj += out.omega_object / tail;
            w_hat += out.omega_hat / tail;
            v += out.v_slip / tail;
          }
        }
        SCOPED_TRACE("f_n=" + std::to_string(f_n) + " c~=" + std::to_string(ct) + " omega=" + std::to_string(omega));
        EXPECT_GT(w_obj * omega, 0.0);
        const double v_true = std::fabs(omega) * ct * rho;
        if (std::getenv("LUGRIP_VERBOSE"))
          std::printf("f_n %.0f c~ %5.1f (est %7.2f, S %.3f) omega %5.2f: omega_hat %8.4f omega_object %8.4f v/v_true %.3f\n", f_n, ct,
                      std::fabs(out.c_tilde_unclipped), out.S, omega, w_hat, w_obj, v / v_true);
        if (ct > 3.0 - 1e-9) {
          e_obj += (w_obj - omega) * (w_obj - omega);
          e_hat += (w_hat - omega) * (w_hat - omega);
          e_zero += omega * omega;
          ++n_far;
          EXPECT_NEAR(std::fabs(out.c_tilde_unclipped), ct, 0.25 * ct);
          v_rel += (v - v_true) * (v - v_true) / (v_true * v_true);
          const double v_clip = std::fabs(w_hat) * p.c_max * rho;  // |omega_hat c| at the clip
          v_rel_clip += (v_clip - v_true) * (v_clip - v_true) / (v_true * v_true);
          // within 15 %: the residual is the dry torque about the clipped point, (xi T(a_u) +
          // a F(a_u)) mu f_n rho <= g(a), which omega_hat (and so omega_object) reads as less slip
          EXPECT_NEAR(w_obj, omega, 0.15 * std::fabs(omega));
          EXPECT_NEAR(v, v_true, 0.15 * v_true);
        } else if (ct < p.c_max) {
          ++n_near;
          EXPECT_NEAR(w_obj, omega, 0.1 * std::fabs(omega));
          EXPECT_NEAR(v, v_true, 0.1 * v_true);
        }
      }
    }
  }
  ASSERT_GT(n_far, 0);
  ASSERT_GT(n_near, 0);
  e_obj = std::sqrt(e_obj / n_far);
  e_hat = std::sqrt(e_hat / n_far);
  e_zero = std::sqrt(e_zero / n_far);
  v_rel = std::sqrt(v_rel / n_far);
  v_rel_clip = std::sqrt(v_rel_clip / n_far);
  std::printf("  [beyond clip] |c~| >= 3 RMSE: omega_object %.4f, omega_hat %.4f, zero %.4f rad/s; "
              "relative RMSE of v_slip %.3f (|omega_hat c| at the clip: %.3f)\n", e_obj, e_hat, e_zero, v_rel, v_rel_clip);
  EXPECT_LE(e_obj, 0.05 * e_zero);  // measured 0.011
  EXPECT_GT(e_hat, e_zero);  // the clipped CoR's omega_hat is not the object's angular velocity
  EXPECT_LT(v_rel, 0.1);     // measured 0.04
  EXPECT_LT(v_rel, 0.5 * v_rel_clip);
}

// ---------------------------------------------------------------------------------------------
// Discretisation
// ---------------------------------------------------------------------------------------------

TEST(Observer, OneStepRk4DivergesAtLowNormalForceWhileStableSchemesTrack) {
  // docs/model.md 7.4: RK4 one step per sample needs h sigma0 |omega| / g <= 2.785. Regime (Table 1,
  // c~ = 0.3, fixed l = 200, 500 Hz): slip onset from 0.5 g to steady sliding at w0 within 0.2 s,
  //   f_n = 0.2 N, w0 = 0.02 rad/s  (h sigma0 w0 / g = 8.7)
  //   f_n = 1.0 N, w0 = 0.2 rad/s   (h sigma0 w0 / g = 11.5)
  // One-step RK4 blows up (|omega_hat| > omega_limit = 1000 rad/s: the guard re-initialises), the
  // stable schemes converge to w0 without overshoot.
  const ContactParams p = table1_params();
  const ContactModel m(p);
  struct Case {
    double f_n, w0;
  };
  for (const Case c : {Case{0.2, 0.02}, Case{1.0, 0.2}}) {
    const double ct = 0.3, g = m.g(c.f_n, ct), s1 = m.sigma_1(c.f_n, ct);
    ASSERT_GT(kDt * p.sigma0 * c.w0 / g, 2.7853);
    Samples s;
    for (int i = 0; i < 1500; ++i) {
      const double t = i * kDt;
      const double frac = std::min(1.0, std::max(0.0, (t - 0.1) / 0.2));
      const double y = (1.0 - frac) * 0.5 * g + frac * (g + s1 * c.w0);
      double ft = 0.0, tau = 0.0;
      m.wrench_at(c.f_n, ct, y, ft, tau);
      s.f_n.push_back(c.f_n);
      s.f_t.push_back(ft);
      s.tau.push_back(tau);
    }
    SCOPED_TRACE("f_n=" + std::to_string(c.f_n) + " w0=" + std::to_string(c.w0));
    {
      ObserverSettings st = settings_with(Integrator::Rk4, GainMode::Fixed);
      Observer obs(m, st);
      const auto out = observe(obs, s);
      int diverged = 0;
      for (const auto& o : out) {
        diverged += o.diverged;
        EXPECT_TRUE(std::isfinite(o.omega_hat));
        if (o.diverged) EXPECT_EQ(o.status, Status::Reinitialized);
      }
      EXPECT_GE(diverged, 1);
    }
    for (Integrator scheme : {Integrator::Rosenbrock, Integrator::Implicit, Integrator::Rk4Adaptive}) {
      Observer obs(m, settings_with(scheme, GainMode::Fixed));
      const auto out = observe(obs, s);
      double peak = 0.0;
      for (const auto& o : out) {
        EXPECT_FALSE(o.diverged) << to_string(scheme);
        peak = std::max(peak, std::fabs(o.omega_hat));
      }
      EXPECT_LE(peak, 1.001 * c.w0) << to_string(scheme);
      EXPECT_NEAR(out.back().omega_hat, c.w0, 2e-3 * c.w0) << to_string(scheme);
    }
  }
}

TEST(Observer, StableSchemesAgreeOnPlantData) {
  // Table 1 maneuver: RMSE against the plant far below the paper's 0.0222 rad/s for every
  // stable scheme, and Rosenbrock within 2 % of a 200-substep RK4 reference of the same ODE.
  const ContactParams p = table1_params();
  const Samples s = plant_data(p, 3.0, 0.5, 1200, [](double t) { return t < 0.2 ? 0.0 : std::min(12.0, 20.0 * (t - 0.2)); }, 1e-5, 0.005, 3);
  double peak = 0.0;
  for (double w : s.omega) peak = std::max(peak, std::fabs(w));
  ASSERT_GT(peak, 0.05);
  ObserverSettings ref_s;
  ref_s.integrator = Integrator::Rk4Adaptive;
  ref_s.substeps = 200;
  ref_s.max_substeps = kMaxObserverSubsteps;
  Observer ref(p, ref_s);
  const auto r = observe(ref, s);
  for (Integrator scheme : {Integrator::Rosenbrock, Integrator::Implicit, Integrator::Rk4Adaptive}) {
    ObserverSettings st;
    st.integrator = scheme;
    Observer obs(p, st);
    const auto out = observe(obs, s);
    EXPECT_LT(rmse(out, s.omega), 0.0222 / 10) << to_string(scheme);
    if (scheme == Integrator::Rosenbrock) {
      double d = 0.0;
      for (size_t i = 0; i < out.size(); ++i) d = std::max(d, std::fabs(out[i].omega_hat - r[i].omega_hat));
      EXPECT_LT(d, 0.02 * peak);
    }
  }
}

// ---------------------------------------------------------------------------------------------
// CoR filter and sign hysteresis on translational loads
// ---------------------------------------------------------------------------------------------

TEST(Observer, TorqueFilterAndSignHysteresisStopCorChatterOnTranslationalLoads) {
  // Pure translational stick load (tau = 0) at half the translational capacity, with the
  // spec's default noise (0.01 N mm torque, 5 mN forces). The CoR side follows sign(tau): raw it
  // flips on most samples, flipping y = tau - c f_t and with it z_hat. Measured (10 s):
  //   no filter:                      > 100 side flips/s, S std ~ 0.008 (state mirrored per flip)
  //   2 Hz filter, no hysteresis:     ~ 10-30 flips/s,     S std ~ 0.02-0.05
  //   2 Hz + 5-sigma hysteresis (default): no flip,        S std < 0.005, |omega_hat| ~ 1e-6
  // The filter's cost on a proportional rotational ramp is checked below (filter_force keeps
  // f_t and tau in phase).
  const ContactParams p = table1_params();
  const int n = 5000;
  for (double f_n : {1.0, 5.0}) {
    std::mt19937_64 rng(11);
    std::normal_distribution<double> normal(0.0, 1.0);
    Samples s;
    for (int i = 0; i < n; ++i) {
      s.f_n.push_back(f_n + 0.005 * normal(rng));
      s.f_t.push_back(std::fabs(0.5 * p.mu * f_n + 0.005 * normal(rng)));
      s.tau.push_back(1e-5 * normal(rng));
    }
    auto stats = [&](const ObserverSettings& st, double& flips_per_s, double& s_std, double& w_rms) {
      Observer obs(p, st);
      const auto out = observe(obs, s);
      int flips = 0;
      double sum = 0.0, sum2 = 0.0, w2 = 0.0;
      const int start = 500;
      for (int i = start; i < n; ++i) {
        flips += (out[i].c_tilde > 0.0) != (out[i - 1].c_tilde > 0.0);
        sum += out[i].S;
        sum2 += out[i].S * out[i].S;
        w2 += out[i].omega_hat * out[i].omega_hat;
      }
      const int m = n - start;
      flips_per_s = flips / (m * kDt);
      s_std = std::sqrt(std::max(0.0, sum2 / m - (sum / m) * (sum / m)));
      w_rms = std::sqrt(w2 / m);
    };
    double flips, s_std, w_rms;
    SCOPED_TRACE("f_n=" + std::to_string(f_n));
    ObserverSettings raw;
    raw.torque_cutoff = 0.0;
    raw.cor_sign_sigmas = 0.0;
    // Each side change mirrors the state (z, omega -> -z, -omega), which keeps S continuous;
    // the chatter still shows in c~ and, through the filter lag, in S.
    double s_std_raw, s_std_filtered;
    stats(raw, flips, s_std_raw, w_rms);
    EXPECT_GT(flips, 100.0);
    ObserverSettings filtered;
    filtered.cor_sign_sigmas = 0.0;
    stats(filtered, flips, s_std_filtered, w_rms);
    EXPECT_GT(flips, 1.0);
    stats(ObserverSettings(), flips, s_std, w_rms);
    EXPECT_EQ(flips, 0.0);
    EXPECT_LT(s_std, 0.005);
    EXPECT_LT(s_std, 0.5 * std::min(s_std_raw, s_std_filtered));
    EXPECT_LT(w_rms, 1e-5);
  }
  // Cost on a rotation-dominated proportional ramp: the filtered CoR stays at the true |c~|.
  const Samples r = plant_data(p, 2.0, 0.25, 1000, [](double t) { return 2.0 * t; }, 0.0, 0.0);
  Observer obs(p);
  const auto out = observe(obs, r);
  for (size_t i = 100; i < out.size(); ++i) EXPECT_NEAR(std::fabs(out[i].c_tilde), 0.25, 0.01) << i;
}

// ---------------------------------------------------------------------------------------------
// Robustness, statuses, re-initialisation
// ---------------------------------------------------------------------------------------------

TEST(Observer, BoundedUnderAMillionRandomInputs) {
  // Random walks of plausible wrenches interleaved with garbage: NaN, +-Inf, zero and negative
  // f_n, out-of-range values, bad dt. Outputs stay finite, |sigma0 z_hat| <= g, S in [0, 1],
  // statuses are from the documented set, and every scheme / gain mode survives.
  const ContactParams params[] = {table1_params(), object_params("big_resin_block")};
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  std::mt19937_64 rng(2024);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const Integrator schemes[] = {Integrator::Rosenbrock, Integrator::Implicit, Integrator::Rk4, Integrator::Rk4Adaptive};
  int n_status[7] = {0, 0, 0, 0, 0, 0, 0};
  for (int run = 0; run < 8; ++run) {
    ObserverSettings st;
    st.integrator = schemes[run % 4];
    st.gain_mode = (run / 4) % 2 ? GainMode::Fixed : GainMode::Bandwidth;
    Observer obs(params[run % 2], st);
    const ContactModel& m = obs.model();
    double f_n = 2.0, ft = 0.5, tau = 0.0;
    ObserverOutput out;
    for (int i = 0; i < 125000; ++i) {
      f_n = std::min(20.0, std::max(-1.0, f_n + 0.2 * (u(rng) - 0.5)));
      ft = std::min(3.0 * m.ft_max(std::max(f_n, 0.1)), std::max(0.0, ft + 0.05 * (u(rng) - 0.5)));
      tau = tau + 2e-4 * (u(rng) - 0.5);
      tau = std::max(-0.05, std::min(0.05, tau));
      ObserverInput in{f_n, ft, tau, kDt};
      const double r = u(rng);
      if (r < 0.01) in.f_n = nan;
      else if (r < 0.02) in.tau = (u(rng) < 0.5 ? inf : -inf);
      else if (r < 0.03) in.f_t = nan;
      else if (r < 0.04) in.f_n = 0.0;
      else if (r < 0.05) in.f_n = -5.0;
      else if (r < 0.055) in.dt = nan;
      else if (r < 0.06) in.dt = -kDt;
      else if (r < 0.062) in.dt = 1.0;  // gap
      else if (r < 0.064) in.tau = 1e6;
      else if (r < 0.066) in.f_t = 1e300;
      else if (r < 0.068) in.dt = 0.0;  // nominal
      else if (r < 0.07) { in.f_t = 0.0; in.tau = 0.0; }
      else if (r < 0.0705) {  // a burst of invalid samples: SensorFault
        for (int k = 0; k < 20; ++k) {
          obs.step(ObserverInput{nan, nan, nan, nan}, out);
          ++n_status[static_cast<int>(out.status)];
          ASSERT_TRUE(std::isfinite(out.omega_hat) && std::isfinite(out.S));
        }
      }
      const Status st_out = obs.step(in, out);
      ASSERT_EQ(st_out, out.status);
      const int code = static_cast<int>(out.status);
      ASSERT_GE(code, 0);
      ASSERT_LE(code, 6);
      ++n_status[code];
      ASSERT_TRUE(std::isfinite(out.omega_hat) && std::isfinite(out.z_hat) && std::isfinite(out.S) &&
                  std::isfinite(out.c_tilde) && std::isfinite(out.c) && std::isfinite(out.g) &&
                  std::isfinite(out.sigma_1) && std::isfinite(out.y) && std::isfinite(out.gain) &&
                  std::isfinite(out.omega_resolution) && std::isfinite(out.tau_cor) && std::isfinite(out.ft_cor) &&
                  std::isfinite(out.c_tilde_unclipped) && std::isfinite(out.omega_object) && std::isfinite(out.v_slip))
          << "run " << run << " sample " << i;
      ASSERT_GE(out.S, 0.0);
      ASSERT_LE(out.S, 1.0);
      ASSERT_LE(params[run % 2].sigma0 * std::fabs(out.z_hat), out.g * (1.0 + 1e-12) + 1e-300);
      ASSERT_LE(std::fabs(out.omega_hat), st.omega_limit);
    }
  }
  for (Status s : {Status::Ok, Status::NoContact, Status::InvalidSample, Status::SensorFault, Status::Reinitialized})
    EXPECT_GT(n_status[static_cast<int>(s)], 0) << to_string(s);
}

TEST(Observer, StatusesAndReinitialisation) {
  const ContactParams p = table1_params();
  ObserverSettings st;
  st.max_invalid = 3;
  Observer obs(p, st);
  ObserverOutput o;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const ObserverInput good{5.0, 1.0, 1e-3, kDt};
  const ObserverInput sliding{5.0, 1.0, 2e-2, kDt};
  // first valid sample initialises: omega_hat = 0, z_hat = clip(y / sigma0)
  EXPECT_EQ(obs.step(good, o), Status::Reinitialized);
  EXPECT_EQ(o.omega_hat, 0.0);
  EXPECT_NEAR(o.z_hat, std::max(-o.g, std::min(o.g, o.y)) / p.sigma0, 1e-18);
  EXPECT_EQ(o.substeps, 0);
  EXPECT_EQ(obs.step(good, o), Status::Ok);
  for (int i = 0; i < 50; ++i) obs.step(sliding, o);
  const ObserverOutput held = o;
  ASSERT_GT(held.omega_hat, 0.0);
  // invalid samples: state and outputs held
  EXPECT_EQ(obs.step(ObserverInput{nan, 1.0, 1e-3, kDt}, o), Status::InvalidSample);
  EXPECT_EQ(o.omega_hat, held.omega_hat);
  EXPECT_EQ(o.S, held.S);
  EXPECT_EQ(obs.omega_hat(), held.omega_hat);
  EXPECT_EQ(obs.step(ObserverInput{5.0, 1.0, 1e-3, -1.0}, o), Status::InvalidSample);
  // the valid sample after a short dropout integrates over the whole elapsed time
  EXPECT_EQ(obs.step(sliding, o), Status::Ok);
  // max_invalid in a row -> SensorFault, then re-initialisation
  EXPECT_EQ(obs.step(ObserverInput{nan, nan, nan, kDt}, o), Status::InvalidSample);
  EXPECT_EQ(obs.step(ObserverInput{nan, nan, nan, kDt}, o), Status::InvalidSample);
  EXPECT_EQ(obs.step(ObserverInput{nan, nan, nan, kDt}, o), Status::SensorFault);
  EXPECT_EQ(obs.step(ObserverInput{nan, nan, nan, kDt}, o), Status::SensorFault);
  EXPECT_TRUE(std::isfinite(o.omega_hat));
  EXPECT_EQ(obs.step(sliding, o), Status::Reinitialized);
  EXPECT_EQ(o.omega_hat, 0.0);
  // contact loss: state shown reset, next contact re-initialises
  for (int i = 0; i < 20; ++i) obs.step(sliding, o);
  EXPECT_EQ(obs.step(ObserverInput{0.01, 0.0, 0.0, kDt}, o), Status::NoContact);
  EXPECT_EQ(o.omega_hat, 0.0);
  EXPECT_EQ(o.S, 0.0);
  EXPECT_EQ(obs.step(ObserverInput{-2.0, 0.0, 0.0, kDt}, o), Status::NoContact);
  EXPECT_EQ(obs.step(good, o), Status::Reinitialized);
  // a gap longer than max_dt_gap re-initialises instead of integrating across it
  EXPECT_EQ(obs.step(sliding, o), Status::Ok);
  EXPECT_EQ(obs.step(ObserverInput{5.0, 1.0, 2e-2, 0.2}, o), Status::Reinitialized);
  // dropped samples add up: 30 invalid samples of 2 ms exceed max_dt_gap = 50 ms
  ObserverSettings st2;
  st2.max_invalid = 1000;
  Observer obs2(p, st2);
  obs2.step(good, o);
  obs2.step(good, o);
  for (int i = 0; i < 30; ++i) obs2.step(ObserverInput{nan, 1.0, 1e-3, kDt}, o);
  EXPECT_EQ(obs2.step(good, o), Status::Reinitialized);
  // dt = 0 means the nominal period: identical to an explicit dt
  Observer a(p), b(p);
  ObserverOutput oa, ob;
  for (int i = 0; i < 100; ++i) {
    a.step(ObserverInput{5.0, 1.0, 2e-2, 0.0}, oa);
    b.step(ObserverInput{5.0, 1.0, 2e-2, st.dt}, ob);
  }
  EXPECT_EQ(oa.omega_hat, ob.omega_hat);
  EXPECT_EQ(oa.z_hat, ob.z_hat);
}

TEST(Observer, ResetReproducesTheRun) {
  const ContactParams p = object_params("plastic_bottle");
  const Samples s = plant_data(p, 4.0, 0.7, 800, [](double t) { return 2.0 * t; }, 1e-5, 0.005, 5);
  Observer obs(p);
  const auto first = observe(obs, s);
  obs.reset();
  EXPECT_EQ(obs.omega_hat(), 0.0);
  EXPECT_EQ(obs.z_hat(), 0.0);
  const auto second = observe(obs, s);
  ASSERT_EQ(first.size(), second.size());
  EXPECT_EQ(second.front().status, Status::Reinitialized);
  for (size_t i = 0; i < first.size(); ++i) {
    ASSERT_EQ(first[i].omega_hat, second[i].omega_hat) << i;
    ASSERT_EQ(first[i].z_hat, second[i].z_hat) << i;
    ASSERT_EQ(first[i].S, second[i].S) << i;
    ASSERT_EQ(first[i].status, second[i].status) << i;
  }
}

TEST(Observer, GainModes) {
  const ContactParams p = table1_params();
  const ContactModel m(p);
  const Samples s = constant_wrench(m, 5.0, 0.4, 0.5 * m.g(5.0, 0.4), 3);
  ObserverSettings st;
  st.gain_mode = GainMode::Bandwidth;
  st.bandwidth = 80.0;
  Observer bw(m, st);
  auto out = observe(bw, s);
  EXPECT_NEAR(out.back().gain * out.back().sigma_1, 80.0, 1e-9);
  st.gain_max = 10.0;
  Observer clipped(m, st);
  out = observe(clipped, s);
  EXPECT_EQ(out.back().gain, 10.0);
  st = ObserverSettings();
  st.gain_mode = GainMode::Fixed;
  st.gain = 321.0;
  Observer fixed(m, st);
  out = observe(fixed, s);
  EXPECT_EQ(out.back().gain, 321.0);
  // speed observability: resolution = torque_noise / sigma_1
  EXPECT_NEAR(out.back().omega_resolution, st.torque_noise / out.back().sigma_1, 1e-18);
  EXPECT_TRUE(out.back().speed_observable);
  const ContactParams weak = object_params("big_resin_block");
  Observer w(weak);
  ObserverOutput o;
  w.step(ObserverInput{0.2, 0.05, 1e-5, kDt}, o);
  EXPECT_GT(o.omega_resolution, st.resolution_max);  // sigma_1 ~ 1e-4: speed not observable
  EXPECT_FALSE(o.speed_observable);
}

TEST(Observer, InputFromForceVector) {
  const ObserverInput in = ObserverInput::from_force_vector(3.0, 0.3, -0.4, 1e-3, 0.001);
  EXPECT_EQ(in.f_n, 3.0);
  EXPECT_NEAR(in.f_t, 0.5, 1e-15);
  EXPECT_EQ(in.tau, 1e-3);
  EXPECT_EQ(in.dt, 0.001);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(std::isfinite(ObserverInput::from_force_vector(3.0, nan, 0.1, 0.0).f_t));
}

TEST(Observer, SettingsValidationNamesEachBadField) {
  std::string msg;
  EXPECT_TRUE(validate(ObserverSettings(), &msg)) << msg;
  auto expect_bad = [](const ObserverSettings& s, const char* field) {
    std::string m;
    EXPECT_FALSE(validate(s, &m)) << field;
    EXPECT_EQ(m.find(std::string(field) + " = "), 0u) << m;
    EXPECT_EQ(std::count(m.begin(), m.end(), '\n'), 1) << m;
    try {
      Observer obs(table1_params(), s);
      ADD_FAILURE() << "no throw for " << field;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos);
    }
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  ObserverSettings s;
  s.dt = 0.0; expect_bad(s, "dt"); s = ObserverSettings();
  s.integrator = static_cast<Integrator>(9); expect_bad(s, "integrator"); s = ObserverSettings();
  s.gain_mode = static_cast<GainMode>(9); expect_bad(s, "gain_mode"); s = ObserverSettings();
  s.gain = -1.0; expect_bad(s, "gain"); s = ObserverSettings();
  s.bandwidth = nan; expect_bad(s, "bandwidth"); s = ObserverSettings();
  s.gain_min = 0.0; expect_bad(s, "gain_min"); s = ObserverSettings();
  s.gain_max = 0.5; expect_bad(s, "gain_max"); s = ObserverSettings();  // < gain_min
  s.g_floor = 0.0; expect_bad(s, "g_floor"); s = ObserverSettings();
  s.torque_cutoff = -1.0; expect_bad(s, "torque_cutoff"); s = ObserverSettings();
  s.cor_sign_sigmas = -1.0; expect_bad(s, "cor_sign_sigmas"); s = ObserverSettings();
  s.max_invalid = 0; expect_bad(s, "max_invalid"); s = ObserverSettings();
  s.max_dt_gap = 0.001; expect_bad(s, "max_dt_gap"); s = ObserverSettings();  // < dt
  s.torque_noise = -1e-5; expect_bad(s, "torque_noise"); s = ObserverSettings();
  s.resolution_max = 0.0; expect_bad(s, "resolution_max"); s = ObserverSettings();
  s.omega_limit = nan; expect_bad(s, "omega_limit"); s = ObserverSettings();
  s.substeps = 0; expect_bad(s, "substeps"); s = ObserverSettings();
  s.max_substeps = 0; expect_bad(s, "max_substeps"); s = ObserverSettings();
  s.cor.f_n_min = -1.0; expect_bad(s, "cor.f_n_min"); s = ObserverSettings();
  // several bad fields: one line each
  s.dt = -1.0;
  s.gain = 0.0;
  s.cor.zero_torque = 0.0;
  EXPECT_FALSE(validate(s, &msg));
  EXPECT_EQ(std::count(msg.begin(), msg.end(), '\n'), 3) << msg;
}

TEST(Observer, SettingsRangesAtTheirEdges) {
  // Each bounded field: the edge value is accepted, one step past it is refused with one line
  // naming the field. The edges are those of the settings table in observer.hpp.
  struct Edge {
    const char* field;
    void (*set)(ObserverSettings&, double);
    double ok, bad;
    int lines = 1;  // lines of the refusal (a dt above 10 s also puts max_dt_gap below dt)
  };
  const Edge edges[] = {
      {"dt", [](ObserverSettings& s, double v) { s.dt = v; s.max_dt_gap = std::max(s.max_dt_gap, std::min(v, 10.0)); }, 1e-9, 9e-10},
      {"dt", [](ObserverSettings& s, double v) { s.dt = v; s.max_dt_gap = 10.0; }, 10.0, 10.5, 2},
      {"gain", [](ObserverSettings& s, double v) { s.gain = v; }, 1e15, 2e15},
      {"bandwidth", [](ObserverSettings& s, double v) { s.bandwidth = v; }, 1e9, 2e9},
      {"gain_max", [](ObserverSettings& s, double v) { s.gain_max = v; }, 1e15, 2e15},
      {"g_floor", [](ObserverSettings& s, double v) { s.g_floor = v; }, 1.0, 1.5},
      {"torque_cutoff", [](ObserverSettings& s, double v) { s.torque_cutoff = v; }, 1e9, 2e9},
      {"cor_sign_sigmas", [](ObserverSettings& s, double v) { s.cor_sign_sigmas = v; }, 1e3, 2e3},
      {"max_invalid", [](ObserverSettings& s, double v) { s.max_invalid = static_cast<int>(v); }, 1e6, 1e6 + 1},
      {"max_dt_gap", [](ObserverSettings& s, double v) { s.max_dt_gap = v; }, 10.0, 10.5},
      {"torque_noise", [](ObserverSettings& s, double v) { s.torque_noise = v; }, 1e3, 2e3},  // cor.torque_limit
      {"omega_limit", [](ObserverSettings& s, double v) { s.omega_limit = v; }, 1e6, 2e6},
      {"resolution_max", [](ObserverSettings& s, double v) { s.resolution_max = v; }, 1e3, 2e3},  // omega_limit
      {"max_substeps", [](ObserverSettings& s, double v) { s.max_substeps = static_cast<int>(v); }, kMaxObserverSubsteps, 1e8},
      {"max_substeps", [](ObserverSettings& s, double v) { s.substeps = s.max_substeps = static_cast<int>(v); }, kMaxObserverSubsteps, 1e8},
      {"cor.f_n_min", [](ObserverSettings& s, double v) { s.cor.f_n_min = v; }, kMinContactForce, 1e-300},
      {"cor.force_limit", [](ObserverSettings& s, double v) { s.cor.force_limit = v; }, kMaxForceLimit, 1e300},
      {"cor.torque_limit", [](ObserverSettings& s, double v) { s.cor.torque_limit = v; }, kMaxForceLimit, 1e300},
  };
  for (const Edge& e : edges) {
    ObserverSettings ok, bad;
    e.set(ok, e.ok);
    e.set(bad, e.bad);
    std::string msg;
    EXPECT_TRUE(validate(ok, &msg)) << e.field << " = " << e.ok << ": " << msg;
    EXPECT_FALSE(validate(bad, &msg)) << e.field << " = " << e.bad;
    EXPECT_EQ(msg.rfind(std::string(e.field) + " = ", 0), 0u) << msg;
    EXPECT_EQ(std::count(msg.begin(), msg.end(), '\n'), e.lines) << msg;
  }
  // ContactParams: a bristle stiffness that makes g / sigma0 overflow is refused.
  ContactParams p = table1_params();
  p.sigma0 = std::numeric_limits<double>::denorm_min();
  EXPECT_FALSE(validate(p, nullptr));
  p.sigma0 = 1e-12;
  EXPECT_TRUE(validate(p, nullptr));
}

TEST(Observer, EdgeSettingsKeepOutputsFiniteAndTheWorkBounded) {
  // The cases found with settings that passed validate() before the ranges existed, now at the
  // edges of the ranges: the smallest sigma0 at the largest sensor range (z_hat was +-inf with a
  // denormal sigma0), the largest substep counts (minutes per log with 1e8), the shortest and
  // longest periods.
  const double f_max = kMaxForceLimit;
  ContactParams p = table1_params();
  p.sigma0 = 1e-12;
  ObserverSettings s;
  s.cor.force_limit = s.cor.torque_limit = f_max;
  s.substeps = s.max_substeps = kMaxObserverSubsteps;
  for (Integrator scheme : {Integrator::Rosenbrock, Integrator::Implicit, Integrator::Rk4, Integrator::Rk4Adaptive}) {
    s.integrator = scheme;
    Observer obs(p, s);
    ObserverOutput out;
    for (double f_n : {0.5, 1e3, f_max}) {
      for (int i = 0; i < 20; ++i) {
        const double load = 0.05 * i;
        obs.step(ObserverInput{f_n, std::min(f_max, load * obs.model().ft_max(f_n)),
                               std::min(f_max, load * obs.model().tau_max(f_n)), 0.0}, out);
        ASSERT_TRUE(std::isfinite(out.z_hat) && std::isfinite(out.omega_hat) && std::isfinite(out.S) &&
                    std::isfinite(out.y) && std::isfinite(out.v_slip) && std::isfinite(out.omega_object))
            << to_string(scheme) << " f_n " << f_n;
        ASSERT_LE(out.substeps, kMaxObserverSubsteps);
        ASSERT_LE(p.sigma0 * std::fabs(out.z_hat), out.g * (1.0 + 1e-12));
      }
    }
  }
  for (double dt : {1e-9, 10.0}) {
    ObserverSettings st;
    st.dt = dt;
    st.max_dt_gap = 10.0;
    Observer obs(table1_params(), st);
    ObserverOutput out;
    for (int i = 0; i < 200; ++i) {
      obs.step(ObserverInput{5.0, 0.01 * i, -1e-4 * i, 0.0}, out);
      ASSERT_TRUE(std::isfinite(out.omega_hat) && std::isfinite(out.z_hat) && std::isfinite(out.v_slip)) << dt;
      ASSERT_TRUE(is_valid(out.status)) << dt;
    }
  }
}

TEST(Observer, RejectedSamplesLeaveTheStateAsItWas) {
  // A sample that passes the input checks but whose CoR cannot be computed (here mu = 1e-300:
  // f_t / (mu f_n) overflows at large forces) is InvalidSample and must not advance the state:
  // a twin that never saw it, fed the skipped time with the next sample, agrees exactly.
  ContactParams p = table1_params();
  p.mu = 1e-300;
  p.beta_a = 1e20;
  ObserverSettings s;
  s.cor.force_limit = s.cor.torque_limit = kMaxForceLimit;
  s.filter_force = false;  // the CoR sees the raw f_t
  Observer a(p, s), twin(p, s);
  ObserverOutput oa, ob;
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int rejected = 0, compared = 0;
  double pending = 0.0;
  for (int i = 0; i < 3000; ++i) {
    ObserverInput in{1.0, 1e-301 * u(rng), -1e-304 * u(rng), 0.0};  // tiny loads of a tiny mu
    if (i % 7 == 3) in.f_t = 1e9;                                     // overflow: rejected
    const double omega_before = a.omega_hat(), z_before = a.z_hat();
    const Status st = a.step(in, oa);
    if (st == Status::InvalidSample) {
      ++rejected;
      EXPECT_EQ(a.omega_hat(), omega_before);
      EXPECT_EQ(a.z_hat(), z_before);
      pending += s.dt;
      continue;
    }
    twin.step(ObserverInput{in.f_n, in.f_t, in.tau, pending + s.dt}, ob);
    pending = 0.0;
    ++compared;
    ASSERT_EQ(oa.status, ob.status) << i;
    ASSERT_EQ(oa.omega_hat, ob.omega_hat) << i;
    ASSERT_EQ(oa.z_hat, ob.z_hat) << i;
    ASSERT_EQ(oa.c_tilde, ob.c_tilde) << i;
    ASSERT_EQ(oa.omega_object, ob.omega_object) << i;
  }
  EXPECT_GT(rejected, 300);
  EXPECT_GT(compared, 2000);
  // f_n_min at 1e-300 is refused outright in an observer (it was accepted, and such samples
  // returned InvalidSample while still advancing omega_hat).
  s.cor.f_n_min = 1e-300;
  EXPECT_THROW(Observer(p, s), std::invalid_argument);
}

// No plant: pure-rotation wrenches (f_t = 0, c~ = 0) at load fractions of tau_max, eqs. 16-18.
TEST(ObserverFrictionRatios, StaticLevelInStickKineticOnceSlidingAndTheResolutionGate) {
  ContactParams p = table1_params();
  p.beta_a = 1.0e4;  // speed not in the data
  p.sigma_z = 1.0e-3;
  const double f_n = 4.0;
  const double tau_max = p.mu * shape_factor(p.k) * p.delta * std::pow(f_n, 1.0 + p.gamma);
  auto run = [&](const ContactParams& q, const std::vector<double>& loads) {
    Observer obs(q);
    std::vector<ObserverOutput> out(loads.size());
    for (std::size_t i = 0; i < loads.size(); ++i) obs.step(ObserverInput{f_n, 0.0, loads[i] * tau_max, 0.002}, out[i]);
    return out;
  };
  std::vector<double> loads;
  auto hold = [&](double v, int n) { for (int i = 0; i < n; ++i) loads.push_back(v); };
  hold(0.6, 300);   // stick
  hold(0.95, 300);  // the kinetic level (0.9) reached
  hold(0.8, 300);   // above the release (0.72)
  hold(0.5, 300);   // stuck again
  ContactParams r = p;
  r.static_ratio = 1.3;
  r.kinetic_ratio = 0.9;
  const auto a = run(p, loads), b = run(r, loads);
  for (const auto& o : a) {  // default ratios: the paper's S, never kinetic
    EXPECT_EQ(o.S, std::min(p.sigma0 * std::fabs(o.z_hat) / o.g, 1.0));
    EXPECT_FALSE(o.kinetic);
    EXPECT_FALSE(o.speed_observable);
    EXPECT_EQ(o.omega_hat, 0.0);  // resolution far beyond 1.5 x resolution_max
    EXPECT_EQ(o.omega_object, 0.0);
    EXPECT_EQ(o.v_slip, 0.0);
  }
  double moved = 0.0;  // the state moves at the load steps while the reported value stays 0
  for (const auto& o : a) moved = std::max(moved, std::fabs(o.omega_state));
  EXPECT_GT(moved, 0.0);
  EXPECT_FALSE(b[299].kinetic);
  EXPECT_NEAR(b[299].S, 0.6 / 1.3, 0.01);
  EXPECT_TRUE(b[599].kinetic);
  EXPECT_EQ(b[599].S, 1.0);
  EXPECT_TRUE(b[899].kinetic);
  EXPECT_NEAR(b[899].S, 0.8 / 0.9, 0.01);
  EXPECT_FALSE(b[1199].kinetic);
  EXPECT_NEAR(b[1199].S, 0.5 / 1.3, 0.01);
}
