// Seeded random-settings campaign over the Observer: ContactParams and ObserverSettings drawn at
// the edges of what validate() accepts (and inside), fed plausible wrenches mixed with hostile
// samples (NaN, +-Inf, +-1e300, denormals, dt 0 / negative / huge). Checks per sample: every
// output finite, S in [0, 1], |sigma0 z_hat| <= g, |omega_hat| <= omega_limit, statuses from
// the enum, the work counters inside their bounds; a twin observer fed only the samples the
// first one accepted (with the skipped time added to the next dt) gives the same outputs; no
// allocation inside step(). Consistency test of the implementation's guarantees (no plant).
// Negative control: with a CoR failure integrated instead of rejected (the behaviour before
// InvalidSample left the state alone) the default run reports over a hundred twin mismatches.
//
// LUGRIP_FUZZ_SAMPLES (default 400000) and LUGRIP_FUZZ_SEED (default 20261201) scale the run.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <new>
#include <random>
#include <string>

#include "lugrip/observer.hpp"

namespace {
std::atomic<bool> counting{false};
std::atomic<long> allocations{0};

void* allocate(std::size_t size, std::size_t alignment) noexcept {
  if (counting.load(std::memory_order_relaxed)) allocations.fetch_add(1, std::memory_order_relaxed);
  if (size == 0) size = 1;
  if (alignment > alignof(std::max_align_t))
    return std::aligned_alloc(alignment, (size + alignment - 1) / alignment * alignment);
  return std::malloc(size);
}
void* allocate_or_throw(std::size_t size, std::size_t alignment = 0) {
  void* p = allocate(size, alignment);
  if (p == nullptr) throw std::bad_alloc();
  return p;
}
}  // namespace

void* operator new(std::size_t n) { return allocate_or_throw(n); }
void* operator new[](std::size_t n) { return allocate_or_throw(n); }
void* operator new(std::size_t n, std::align_val_t a) { return allocate_or_throw(n, static_cast<std::size_t>(a)); }
void* operator new[](std::size_t n, std::align_val_t a) { return allocate_or_throw(n, static_cast<std::size_t>(a)); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept { return allocate(n, 0); }
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept { return allocate(n, 0); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }

using namespace lugrip;

namespace {

long env_long(const char* name, long fallback) {
  const char* v = std::getenv(name);
  return v ? std::atol(v) : fallback;
}

struct Draw {
  std::mt19937_64 rng;
  std::uniform_real_distribution<double> u{0.0, 1.0};
  explicit Draw(unsigned long long seed) : rng(seed) {}
  double uniform() { return u(rng); }
  double log_uniform(double lo, double hi) {
    const double x = std::exp(std::log(lo) + (std::log(hi) - std::log(lo)) * u(rng));
    return std::min(std::max(x, lo), hi);
  }
  // the lower edge, the upper edge, the default or a log-uniform value in between
  double edge(double lo, double hi, double def) {
    const double r = u(rng);
    if (r < 0.25) return lo;
    if (r < 0.5) return hi;
    if (r < 0.7) return def;
    return log_uniform(lo, hi);
  }
  int edge_int(int lo, int hi, int def) {
    const double r = u(rng);
    if (r < 0.25) return lo;
    if (r < 0.4) return hi;
    if (r < 0.7) return def;
    return static_cast<int>(std::lround(log_uniform(lo, hi)));
  }
};

ContactParams draw_params(Draw& d) {
  ContactParams p = table1_params();
  p.mu = d.edge(1e-300, 10.0, 0.47);
  p.beta_a = d.uniform() < 0.15 ? 0.0 : d.edge(1e-300, 1e300, 4.9e9);
  p.sigma0 = d.edge(1e-12, 1e12, 16.66);
  p.sigma_z = d.uniform() < 0.2 ? 0.0 : d.edge(1e-12, 1e6, 2.0);
  p.delta = d.edge(1e-300, 0.999, 0.0018);
  p.gamma = d.edge(1e-12, 0.33333333, 0.254);
  const double ks[] = {0.5, 2.0, 4.0, std::numeric_limits<double>::infinity()};
  p.k = d.uniform() < 0.6 ? 4.0 : ks[static_cast<int>(d.uniform() * 4) % 4];
  p.c_max = d.edge(1e-3, 1e3, 1.5);
  return p;
}

ObserverSettings draw_settings(Draw& d) {
  ObserverSettings s;
  const Integrator schemes[] = {Integrator::Rosenbrock, Integrator::Implicit, Integrator::Rk4, Integrator::Rk4Adaptive};
  s.integrator = schemes[static_cast<int>(d.uniform() * 4) % 4];
  s.gain_mode = d.uniform() < 0.5 ? GainMode::Bandwidth : GainMode::Fixed;
  s.dt = d.edge(1e-9, 10.0, 0.002);
  s.gain = d.edge(1e-300, 1e15, 200.0);
  s.bandwidth = d.edge(1e-300, 1e9, 3000.0);
  s.gain_min = d.edge(1e-300, 1e15, 1.0);
  s.gain_max = d.edge(s.gain_min, 1e15, std::max(s.gain_min, 1e7));
  s.g_floor = d.edge(1e-300, 1.0, 1e-7);
  s.torque_cutoff = d.uniform() < 0.15 ? 0.0 : d.edge(1e-300, 1e9, 2.0);
  s.filter_force = d.uniform() < 0.7;
  s.cor_sign_sigmas = d.uniform() < 0.15 ? 0.0 : d.edge(1e-300, 1e3, 5.0);
  s.max_invalid = d.edge_int(1, 1000000, 10);
  s.cor.force_limit = d.edge(1e-3, kMaxForceLimit, 1e4);
  s.cor.torque_limit = d.edge(1e-300, kMaxForceLimit, 1e3);
  s.cor.f_n_min = std::min(d.edge(kMinContactForce, kMaxForceLimit, 0.03), 0.5 * s.cor.force_limit);
  s.cor.zero_force = d.edge(1e-300, 1e300, 1e-4);
  s.cor.zero_torque = d.edge(1e-300, 1e300, 1e-4);
  s.max_dt_gap = d.edge(s.dt, 10.0, std::max(s.dt, 0.05));
  s.torque_noise = d.uniform() < 0.15 ? 0.0 : d.edge(1e-300, s.cor.torque_limit, std::min(1e-5, s.cor.torque_limit));
  s.omega_limit = d.edge(1e-300, 1e6, 1e3);
  s.resolution_max = d.edge(1e-300, s.omega_limit, std::min(0.02, s.omega_limit));
  // the work bound: a few configurations at the largest substep counts, the rest small
  const double r = d.uniform();
  s.max_substeps = r < 0.03 ? kMaxObserverSubsteps : d.edge_int(1, 1000, 500);
  s.substeps = r < 0.015 ? s.max_substeps : d.edge_int(1, std::min(s.max_substeps, 20), 1);
  return s;
}

bool finite_output(const ObserverOutput& o) {
  const double v[] = {o.omega_hat, o.z_hat, o.S, o.c_tilde, o.c, o.g, o.sigma_1, o.y, o.tau_cor, o.ft_cor,
                      o.gain, o.omega_resolution, o.c_tilde_unclipped, o.omega_object, o.v_slip};
  for (double x : v)
    if (!std::isfinite(x)) return false;
  return true;
}

// The state-carrying and per-sample fields agree exactly.
bool same(const ObserverOutput& a, const ObserverOutput& b, bool estimate) {
  if (a.status != b.status || a.omega_hat != b.omega_hat || a.z_hat != b.z_hat || a.S != b.S || a.y != b.y ||
      a.omega_object != b.omega_object || a.v_slip != b.v_slip)
    return false;
  if (!estimate) return true;
  return a.c_tilde == b.c_tilde && a.c == b.c && a.g == b.g && a.sigma_1 == b.sigma_1 && a.tau_cor == b.tau_cor &&
         a.ft_cor == b.ft_cor && a.gain == b.gain && a.omega_resolution == b.omega_resolution &&
         a.c_tilde_unclipped == b.c_tilde_unclipped && a.substeps == b.substeps &&
         a.cor_iterations == b.cor_iterations && a.saturated == b.saturated && a.inside == b.inside;
}

}  // namespace

TEST(NoAllocationObserverSettings, EdgeOfValiditySettingsKeepTheGuarantees) {
  const long total = env_long("LUGRIP_FUZZ_SAMPLES", 400000);
  const unsigned long long seed = static_cast<unsigned long long>(env_long("LUGRIP_FUZZ_SEED", 20261201));
  const long per_config = 8000;
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  const double denorm = std::numeric_limits<double>::denorm_min();
  Draw d(seed);
  long samples = 0, rejected = 0, estimates = 0, mismatches = 0, non_finite = 0, bound_violations = 0;
  long allocs = 0, configs = 0, max_substeps_seen = 0, max_iterations = 0, saturated = 0;
  while (samples < total) {
    const ContactParams p = draw_params(d);
    const ObserverSettings s = draw_settings(d);
    std::string msg;
    ASSERT_TRUE(validate(p, &msg)) << msg;
    ASSERT_TRUE(validate(s, &msg)) << msg;
    const ContactModel model(p);
    Observer a(model, s), twin(model, s);
    ++configs;
    // plausible wrenches of this contact: f_n log-uniform over the sensor range above f_n_min
    const double f_lo = s.cor.f_n_min, f_hi = std::min(s.cor.force_limit, 1e3);
    double pending = 0.0;
    ObserverOutput oa, ob;
    const long n = std::min(per_config, total - samples);
    counting = true;
    const long before = allocations.load();
    for (long i = 0; i < n; ++i) {
      const double f_n = f_hi > f_lo ? d.log_uniform(f_lo, f_hi) : f_lo;
      const double load = d.uniform() * 1.5;
      const double share = d.uniform();
      ObserverInput in{f_n, load * share * model.ft_max(f_n),
                       (d.uniform() < 0.5 ? -1.0 : 1.0) * load * (1.0 - share) * model.tau_max(f_n), 0.0};
      const double r = d.uniform();
      if (r < 0.02) in.f_n = nan;
      else if (r < 0.03) in.tau = d.uniform() < 0.5 ? inf : -inf;
      else if (r < 0.04) in.f_t = 1e300;
      else if (r < 0.05) in.tau = -1e300;
      else if (r < 0.06) in.f_n = d.uniform() < 0.5 ? 0.0 : -1e300;
      else if (r < 0.07) in.dt = nan;
      else if (r < 0.08) in.dt = -s.dt;
      else if (r < 0.085) in.dt = 1e300;
      else if (r < 0.09) in.dt = denorm;
      else if (r < 0.10) { in.f_t = denorm; in.tau = -denorm; }
      else if (r < 0.11) { in.f_t = 0.0; in.tau = 0.0; }
      else if (r < 0.12) in.f_n = f_lo * (1.0 - 1e-12);  // just below contact
      else if (r < 0.13) in.dt = s.dt * d.log_uniform(1e-6, 1e3);
      else if (r < 0.14) { in.f_n = s.cor.force_limit; in.f_t = s.cor.force_limit; in.tau = s.cor.torque_limit; }
      else if (r < 0.15) {  // the whole sensor range at the smallest contact force: with a tiny
        in.f_n = f_lo;      // mu or delta the CoR's normalisation overflows (rejected, not input)
        in.f_t = s.cor.force_limit;
        in.tau = (d.uniform() < 0.5 ? -1.0 : 1.0) * s.cor.torque_limit;
      }
      const double dt_used = in.dt == 0.0 ? s.dt : in.dt;
      const bool dt_ok = std::isfinite(dt_used) && dt_used > 0.0;
      const Status st = a.step(in, oa);
      ++samples;
      if (st != oa.status) ++bound_violations;
      if (st == Status::InvalidSample || st == Status::SensorFault) {
        ++rejected;
        pending = std::min(pending + (dt_ok ? dt_used : s.dt), 1.0e9);
        if (st == Status::SensorFault) {
          twin.reset();  // the twin re-initialises at the next accepted sample as well
          pending = 0.0;
        }
        if (!finite_output(oa)) ++non_finite;
        continue;
      }
      // The twin sees this sample only, with the skipped time added to its period.
      ObserverInput tin = in;
      tin.dt = pending + dt_used;
      pending = 0.0;
      twin.step(tin, ob);
      const bool estimate = is_valid(st);
      estimates += estimate;
      saturated += oa.saturated;
      if (!same(oa, ob, estimate)) ++mismatches;
      if (!finite_output(oa)) ++non_finite;
      const int code = static_cast<int>(st);
      const bool ok = code >= 0 && code <= 6 && oa.S >= 0.0 && oa.S <= 1.0 &&
                      p.sigma0 * std::fabs(oa.z_hat) <= oa.g * (1.0 + 1e-12) + 1e-300 &&
                      std::fabs(oa.omega_hat) <= s.omega_limit && std::fabs(oa.omega_object) <= std::fabs(oa.omega_hat) &&
                      oa.v_slip >= 0.0 && std::fabs(oa.c_tilde_unclipped) >= std::fabs(oa.c_tilde) &&
                      std::fabs(oa.c_tilde) <= p.c_max && oa.substeps <= s.max_substeps;
      if (!ok) ++bound_violations;
      if (oa.substeps > max_substeps_seen) max_substeps_seen = oa.substeps;
      if (oa.cor_iterations > max_iterations) max_iterations = oa.cor_iterations;
    }
    allocs += allocations.load() - before;
    counting = false;
    if (non_finite + mismatches + bound_violations > 0) {
      ADD_FAILURE() << "configuration " << configs << ": " << to_string(p) << " integrator "
                    << to_string(s.integrator) << " dt " << s.dt << " max_substeps " << s.max_substeps;
      break;
    }
  }
  std::printf("  [observer settings campaign] seed %llu: %ld configurations, %ld samples (%ld rejected, %ld "
              "estimates, %ld saturated); non-finite %ld, twin mismatches %ld, bound violations %ld, "
              "allocations %ld; max substeps %ld, max CoR iterations %ld\n",
              seed, configs, samples, rejected, estimates, saturated, non_finite, mismatches, bound_violations,
              allocs, max_substeps_seen, max_iterations);
  EXPECT_EQ(non_finite, 0);
  EXPECT_EQ(mismatches, 0);
  EXPECT_EQ(bound_violations, 0);
  EXPECT_EQ(allocs, 0);
  EXPECT_GE(samples, total);
  EXPECT_GT(estimates, samples / 4);  // the draw exercises the estimator, not only the guards
  EXPECT_GT(saturated, samples / 50);
}
