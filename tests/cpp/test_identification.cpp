// Identification cost (docs/model.md 8.1, eqs. 32-33): the cost runs the online Observer, the gradient
// is the exact derivative of that discretisation (checked against central differences of the
// cost itself), the Gauss-Newton matrix against finite-difference Jacobians of omega_hat,
// segments restart the observer, threads do not change a bit, bad input is named.
//
// Data: SliderModel (eqs. 1-2 about a known CoR) pushed past the limit surface and released;
// sensor wrench = ContactModel::wrench_at of the plant's friction torque plus white noise.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "lugrip/identification.hpp"

using namespace lugrip;

namespace {

constexpr double kDt = 0.002;
const char* kNames[kIdParams] = {"mu", "beta_a", "sigma0", "sigma_z", "delta", "gamma"};

double& field(ContactParams& p, int k) {
  switch (k) {
    case 0: return p.mu;
    case 1: return p.beta_a;
    case 2: return p.sigma0;
    case 3: return p.sigma_z;
    case 4: return p.delta;
    default: return p.gamma;
  }
}

// `count` maneuvers: constant f_n (log-uniform 0.5-10 N), CoR |c~| <= 1.3 with random side,
// external torque ramped to `peak` x g (log-uniform), held, released.
IdentificationData maneuvers(const ContactParams& p, int count, unsigned seed, double peak_lo, double peak_hi,
                             double tau_noise = 1e-5, double force_noise = 0.005) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  SliderModel sim(p, 1e-4);
  const ContactModel& m = sim.model();
  IdentificationData d;
  d.segment_start.push_back(0);
  for (int j = 0; j < count; ++j) {
    const double f_n = 0.5 * std::pow(20.0, u(rng));
    const double ct = (u(rng) < 0.5 ? -1.0 : 1.0) * 1.3 * u(rng);
    const double peak = peak_lo * std::pow(peak_hi / peak_lo, u(rng));
    const double t1 = 0.05, t2 = t1 + 0.2 + 0.3 * u(rng), t3 = t2 + 0.1 * u(rng), t4 = t3 + 0.1 + 0.2 * u(rng);
    const int n = static_cast<int>((t4 + 0.1) / kDt);
    const double g = m.g(f_n, ct);
    sim.reset();
    SliderOutput out;
    for (int i = 0; i < n; ++i) {
      const double t = i * kDt;
      const double load = t < t1 ? 0.0 : t < t2 ? peak * (t - t1) / (t2 - t1) : t < t3 ? peak
                        : t < t4 ? peak * (t4 - t) / (t4 - t3) : 0.0;
      sim.step(SliderInput{f_n, ct, (ct < 0.0 ? -1.0 : 1.0) * load * g, kDt}, out);
      double ft = 0.0, tau = 0.0;
      m.wrench_at(f_n, ct, out.friction_torque, ft, tau);
      d.f_n.push_back(f_n + force_noise * normal(rng));
      d.f_t.push_back(std::fabs(ft + force_noise * normal(rng)));
      d.tau.push_back(tau + tau_noise * normal(rng));
      d.dt.push_back(kDt);
      d.omega.push_back(out.omega);
      d.weight.push_back(1.0);
    }
    d.segment_start.push_back(static_cast<int64_t>(d.f_n.size()));
  }
  return d;
}

ContactParams perturbed(ContactParams p) {
  p.mu *= 1.1;
  p.beta_a *= 0.8;
  p.sigma0 *= 1.3;
  p.sigma_z *= 0.7;
  p.delta *= 0.95;
  p.gamma *= 1.05;
  return p;
}

// Central difference of the cost in log-parameters, relative step 1e-6.
void expect_gradient_matches(const IdentificationProblem& prob, const ContactParams& p, double rel_tol) {
  const IdentificationEval ev = prob.evaluate(p, true);
  ASSERT_TRUE(std::isfinite(ev.cost));
  EXPECT_LT(ev.replica_error, 1e-12);
  double scale = 0.0;
  ContactParams q = p;
  std::vector<double> fd(kIdParams);
  for (int k = 0; k < kIdParams; ++k) {
    const double v = field(q, k), h = 1e-6 * v;
    field(q, k) = v + h;
    const double cp = prob.evaluate(q, false).cost;
    field(q, k) = v - h;
    const double cm = prob.evaluate(q, false).cost;
    field(q, k) = v;
    fd[k] = (cp - cm) / (2.0 * h) * v;
    scale = std::max(scale, std::fabs(fd[k]));
  }
  for (int k = 0; k < kIdParams; ++k) {
    SCOPED_TRACE(kNames[k]);
    EXPECT_NEAR(ev.gradient[k] * field(q, k), fd[k], rel_tol * std::fabs(fd[k]) + 1e-7 * scale);
  }
}

std::vector<double> observer_replay(const ContactParams& p, const ObserverSettings& s, const IdentificationData& d) {
  Observer obs(p, s);
  std::vector<double> w(d.f_n.size());
  ObserverOutput out;
  for (size_t j = 0; j + 1 < d.segment_start.size(); ++j) {
    obs.reset();
    for (int64_t i = d.segment_start[j]; i < d.segment_start[j + 1]; ++i) {
      obs.step(ObserverInput{d.f_n[i], d.f_t[i], d.tau[i], i == d.segment_start[j] ? 0.0 : d.dt[i]}, out);
      w[i] = out.omega_hat;
    }
  }
  return w;
}

}  // namespace

TEST(Identification, GradientIsTheExactDerivativeOfTheOnlineDiscretisation) {
  // every integrator and both gain rules; Table 1 (strong viscous friction) and a Table 2 object
  // with the paper's fixed gain
  struct Case {
    ContactParams p;
    Integrator integ;
    GainMode gain;
    double peak_lo, peak_hi;
  };
  const Case cases[] = {
      {table1_params(), Integrator::Rosenbrock, GainMode::Bandwidth, 1.2, 20.0},
      {table1_params(), Integrator::Implicit, GainMode::Bandwidth, 1.2, 20.0},
      {table1_params(), Integrator::Rk4, GainMode::Fixed, 1.2, 5.0},
      {table1_params(), Integrator::Rk4Adaptive, GainMode::Fixed, 1.2, 20.0},
      {object_params("big_resin_block"), Integrator::Rosenbrock, GainMode::Fixed, 1.05, 1.6},
  };
  int i = 0;
  for (const Case& c : cases) {
    SCOPED_TRACE("case " + std::to_string(i++) + " integrator " + to_string(c.integ));
    IdentificationSettings s;
    s.observer.integrator = c.integ;
    s.observer.gain_mode = c.gain;
    const IdentificationProblem prob(maneuvers(c.p, 6, 11 + i, c.peak_lo, c.peak_hi), s);
    EXPECT_EQ(prob.evaluate(perturbed(c.p), true).truncated, 0);
    expect_gradient_matches(prob, perturbed(c.p), 1e-4);
  }
}

TEST(Identification, ChatteringGuardKeepsTheGradientBoundedAndUseful) {
  // Table 2 viscous friction with the bandwidth gain (l = B / sigma_1 ~ 1e5): at slip ends the
  // observer's discrete map is locally chaotic and pathwise derivatives explode; the guard
  // restarts them, so the gradient stays finite and points like a coarse central difference.
  const ContactParams p = object_params("big_resin_block");
  IdentificationSettings s;
  const IdentificationProblem prob(maneuvers(p, 30, 12, 1.05, 1.6), s);
  const ContactParams q = perturbed(p);
  const IdentificationEval ev = prob.evaluate(q, true);
  EXPECT_GT(ev.truncated, 0);
  double dot = 0.0, n_g = 0.0, n_fd = 0.0;
  ContactParams r = q;
  for (int k = 0; k < kIdParams; ++k) {
    const double v = field(r, k), g = ev.gradient[k] * v;
    ASSERT_TRUE(std::isfinite(g));
    field(r, k) = v * std::exp(0.01);
    const double cp = prob.evaluate(r, false).cost;
    field(r, k) = v * std::exp(-0.01);
    const double cm = prob.evaluate(r, false).cost;
    field(r, k) = v;
    const double fd = (cp - cm) / 0.02;
    dot += g * fd;
    n_g += g * g;
    n_fd += fd * fd;
  }
  EXPECT_GT(dot / std::sqrt(n_g * n_fd), 0.5);
  // a tighter guard truncates more; the sensitivities without guard overflow
  IdentificationSettings loose = s;
  loose.sensitivity_limit = 1e300;
  const IdentificationEval wild = IdentificationProblem(prob.data(), loose).evaluate(q, true);
  double big = 0.0;
  for (int k = 0; k < kIdParams; ++k) big = std::max(big, std::fabs(wild.gradient[k] * field(r, k)));
  EXPECT_TRUE(!(big < 1e6)) << "expected the unguarded pathwise gradient to blow up";
}

TEST(Identification, CostRunsTheOnlineObserverSegmentBySegment) {
  const ContactParams p = table1_params();
  IdentificationSettings s;
  const IdentificationData d = maneuvers(p, 5, 3, 1.2, 20.0);
  const IdentificationProblem prob(d, s);
  std::vector<double> w(d.f_n.size(), std::nan(""));
  const ContactParams q = perturbed(p);
  const IdentificationEval ev = prob.evaluate(q, true, w.data());
  const std::vector<double> ref = observer_replay(q, s.observer, d);
  double sse = 0.0;
  for (size_t i = 0; i < w.size(); ++i) {
    ASSERT_EQ(w[i], ref[i]) << "sample " << i;
    sse += (ref[i] - d.omega[i]) * (ref[i] - d.omega[i]);
  }
  EXPECT_EQ(ev.scored, static_cast<int64_t>(w.size()));
  EXPECT_NEAR(ev.cost, sse / w.size(), 1e-12 * ev.cost);
  EXPECT_EQ(ev.reinitialized, 5);  // one initialisation per segment
  ASSERT_EQ(ev.segments.size(), 5u);
  double sum = 0.0;
  for (const SegmentSums& g : ev.segments) sum += g.sse;
  EXPECT_NEAR(sum, sse, 1e-12 * sse);

  // never integrated across segments: the last segment alone gives the same residuals
  IdentificationData last;
  const int64_t a = d.segment_start[4], b = d.segment_start[5];
  auto tail = [&](const std::vector<double>& v) { return std::vector<double>(v.begin() + a, v.begin() + b); };
  last.f_n = tail(d.f_n);
  last.f_t = tail(d.f_t);
  last.tau = tail(d.tau);
  last.dt = tail(d.dt);
  last.omega = tail(d.omega);
  last.weight = tail(d.weight);
  last.segment_start = {0, b - a};
  const IdentificationEval alone = IdentificationProblem(last, s).evaluate(q, true);
  EXPECT_DOUBLE_EQ(alone.segments[0].sse, ev.segments[4].sse);
  for (int k = 0; k < kIdParams; ++k) EXPECT_DOUBLE_EQ(alone.segments[0].gradient[k], ev.segments[4].gradient[k]);
}

TEST(Identification, ThreadCountDoesNotChangeABit) {
  const ContactParams p = table1_params();
  const IdentificationData d = maneuvers(p, 9, 5, 1.2, 20.0);
  IdentificationSettings s1, s3;
  s1.threads = 1;
  s3.threads = 3;
  const IdentificationEval a = IdentificationProblem(d, s1).evaluate(perturbed(p), true);
  const IdentificationEval b = IdentificationProblem(d, s3).evaluate(perturbed(p), true);
  EXPECT_EQ(a.cost, b.cost);
  for (int k = 0; k < kIdParams; ++k) EXPECT_EQ(a.gradient[k], b.gradient[k]);
  for (int k = 0; k < kIdParams * kIdParams; ++k) EXPECT_EQ(a.gauss_newton[k], b.gauss_newton[k]);
}

TEST(Identification, GaussNewtonMatrixIsTwiceJacobianProduct) {
  // squared loss: GN = 2 sum J J^T / N with J = d omega_hat / dP from central differences
  const ContactParams p = table1_params();
  IdentificationSettings s;
  const IdentificationData d = maneuvers(p, 3, 21, 1.2, 20.0);
  const IdentificationProblem prob(d, s);
  const ContactParams q = perturbed(p);
  const IdentificationEval ev = prob.evaluate(q, true);
  const size_t n = d.f_n.size();
  std::vector<std::vector<double>> J(kIdParams, std::vector<double>(n));
  ContactParams r = q;
  std::vector<double> wp(n), wm(n);
  for (int k = 0; k < kIdParams; ++k) {
    const double v = field(r, k), h = 1e-6 * v;
    field(r, k) = v + h;
    prob.evaluate(r, false, wp.data());
    field(r, k) = v - h;
    prob.evaluate(r, false, wm.data());
    field(r, k) = v;
    for (size_t i = 0; i < n; ++i) J[k][i] = (wp[i] - wm[i]) / (2.0 * h) * v;
  }
  for (int k = 0; k < kIdParams; ++k) {
    for (int m = 0; m < kIdParams; ++m) {
      double ref = 0.0;
      for (size_t i = 0; i < n; ++i) ref += 2.0 * J[k][i] * J[m][i];
      ref /= static_cast<double>(n);
      const double got = ev.gauss_newton[k * kIdParams + m] * field(r, k) * field(r, m);
      const double diag = std::sqrt(std::fabs(ev.gauss_newton[k * kIdParams + k] * ev.gauss_newton[m * kIdParams + m])) *
                          field(r, k) * field(r, m);
      EXPECT_NEAR(got, ref, 1e-4 * diag + 1e-12) << kNames[k] << ", " << kNames[m];
    }
  }
}

TEST(Identification, HuberLossCapsOutliersAndKeepsAnExactGradient) {
  const ContactParams p = table1_params();
  IdentificationData d = maneuvers(p, 4, 8, 1.2, 20.0);
  for (size_t i = 17; i < d.omega.size(); i += 97) d.omega[i] += 5.0;  // outliers in the ground truth
  IdentificationSettings sq, hu;
  hu.loss = IdLoss::Huber;
  hu.huber_scale = 0.01;
  const IdentificationProblem a(d, sq), b(d, hu);
  const IdentificationEval ea = a.evaluate(p, false), eb = b.evaluate(p, false);
  EXPECT_LT(eb.cost, 0.1 * ea.cost);
  EXPECT_NEAR(ea.segments[0].sse, eb.segments[0].sse, 1e-12 * ea.segments[0].sse);  // RMSE sums stay squared
  expect_gradient_matches(b, perturbed(p), 1e-4);
}

TEST(Identification, InvalidAndNoContactSamplesInsideASegment) {
  // a NaN sample is skipped (its time added to the next step), a no-contact sample resets the
  // state; values stay those of the online observer and the gradient stays exact
  const ContactParams p = table1_params();
  IdentificationData d = maneuvers(p, 2, 4, 1.2, 20.0);
  d.tau[60] = std::numeric_limits<double>::quiet_NaN();
  d.f_n[61] = std::numeric_limits<double>::infinity();
  d.f_n[200] = 0.01;  // below f_n_min
  d.omega[300] = std::numeric_limits<double>::quiet_NaN();  // unknown ground truth: not scored
  d.weight[301] = 0.0;
  IdentificationSettings s;
  const IdentificationProblem prob(d, s);
  std::vector<double> w(d.f_n.size());
  const IdentificationEval ev = prob.evaluate(perturbed(p), true, w.data());
  const std::vector<double> ref = observer_replay(perturbed(p), s.observer, d);
  for (size_t i = 0; i < w.size(); ++i) ASSERT_EQ(w[i], ref[i]) << "sample " << i;
  EXPECT_EQ(ev.scored, static_cast<int64_t>(d.f_n.size()) - 5);
  EXPECT_EQ(ev.reinitialized, 3);  // two segment starts + after the no-contact sample
  expect_gradient_matches(prob, perturbed(p), 1e-4);
}

TEST(Identification, CostIsSmallestNearTheTruth) {
  // A fast observer (bandwidth 3000/s): with a slow one the stick parameters sigma0, sigma_z
  // absorb its lag and the minimum moves away from the plant's values (docs/model.md 8.2).
  const ContactParams p = table1_params();
  IdentificationSettings s;
  s.observer.bandwidth = 3000.0;
  const IdentificationProblem prob(maneuvers(p, 8, 9, 1.2, 20.0), s);
  const double at_truth = prob.evaluate(p, false).cost;
  for (int k = 0; k < kIdParams; ++k) {
    for (double f : {0.7, 1.3}) {
      ContactParams q = p;
      field(q, k) *= f;
      if (k == 5) field(q, k) = std::min(field(q, k), 0.33);
      EXPECT_GT(prob.evaluate(q, false).cost, at_truth) << kNames[k] << " x " << f;
    }
  }
}

TEST(Identification, ValidationNamesEveryProblem) {
  const IdentificationData good = maneuvers(table1_params(), 2, 1, 1.2, 2.0);
  IdentificationSettings s;
  auto message = [&](const IdentificationData& d, const IdentificationSettings& st) {
    try {
      IdentificationProblem prob(d, st);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(message(good, s), "");
  IdentificationData d = good;
  d.tau.pop_back();
  EXPECT_NE(message(d, s).find("tau has"), std::string::npos);
  d = good;
  d.segment_start = {0, 5, 5, static_cast<int64_t>(good.f_n.size())};
  EXPECT_NE(message(d, s).find("segment_start[2]"), std::string::npos);
  d = good;
  d.segment_start = {1, static_cast<int64_t>(good.f_n.size())};
  EXPECT_NE(message(d, s).find("segment_start must start with 0"), std::string::npos);
  d = good;
  d.dt[3] = std::nan("");
  EXPECT_NE(message(d, s).find("dt[3]"), std::string::npos);
  d = good;
  d.weight[4] = -1.0;
  EXPECT_NE(message(d, s).find("weight[4]"), std::string::npos);
  IdentificationSettings bad;
  bad.huber_scale = 0.0;
  bad.threads = -1;
  bad.observer.bandwidth = -1.0;
  const std::string m = message(good, bad);
  EXPECT_NE(m.find("huber_scale"), std::string::npos);
  EXPECT_NE(m.find("threads"), std::string::npos);
  EXPECT_NE(m.find("observer.bandwidth"), std::string::npos);
  ContactParams p = table1_params();
  p.gamma = 0.5;
  EXPECT_THROW(IdentificationProblem(good, s).evaluate(p, true), std::invalid_argument);
}
