// lugrip — per-step timings of the sliding-velocity observer including the CoR estimate
// (median and p99 ns per step; BENCHMARKS.md, section Sliding-velocity observer).
//
//   bench_observer [--quick] [--json] [--seed N]
//
// Input stream (built before any timing, from a seeded std::mt19937): synthetic sliding
// maneuvers with the recipe of lugrip.sliding.simulate_maneuvers — f_n uniform in [1, 10] N,
// |c~| log-uniform in [0.02, 2 c_max], a torque about the CoR that ramps past the capacity g to
// g + sigma_1 omega_peak (omega_peak = omega_0 / sqrt(1 + 2 c~^2), omega_0 log-uniform in
// [0.05, 0.5] rad/s), holds and releases, 15 % of the maneuvers staying inside the limit surface;
// plant = SliderModel (J = 1e-4 kg m^2), sensor = ContactModel::wrench_at (the wrench the object
// exerts on the fingertip) with white noise 0.005 N / 1e-5 N m at 500 Hz. The stream is replayed
// through one Observer without resets, as an online loop would.
//
// What is timed, for paper Table 1 and the big resin block of Table 2:
//   observer/<integrator>  Observer::step (CoR estimate with torque filter and sign hysteresis,
//                          g, sigma_1, y, one update, projection, S) with the default settings
//                          (Rosenbrock, bandwidth gain) and the alternatives: implicit, the
//                          paper's one RK4 step per sample with l = 200, adaptive RK4;
//   cor                    CorEstimator::step alone on the same stream (the share of the CoR).
//
// Method (as bench_core): per-call time = (time of a batch of kBatch = 16 consecutive steps
// - the median cost of an empty timed batch) / 16, std::chrono::steady_clock; median, p99, mean
// over all batches, "worst" = the slowest batch. For the default observer a second pass times
// every step alone (single-call p99 / worst, what a 500 Hz loop sees). Allocations during the
// timed loops are counted (global operator new replaced): they must be 0.
// Output: a table, or JSON with --json (for benchmarks/observer_report.py). No assertion on times.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "bench_timing.hpp"  // timing helpers; includes the allocation counter (counting_new.hpp)
#include "lugrip/contact.hpp"
#include "lugrip/observer.hpp"
#include "lugrip/params.hpp"
#include "lugrip/slider_model.hpp"

namespace {

using lugrip_bench::compiler_string;
using lugrip_bench::json_escape;
using lugrip_bench::kBatch;
using lugrip_bench::Stats;

constexpr double kDt = 0.002;
volatile double g_sink = 0.0;
double g_timer = 0.0;  // timer overhead, subtracted from every timed batch / step

// One pass over the stream in batches of kBatch (after `prepare()`), `passes` times.
template <class Prepare, class Step>
Stats time_stream(int n, int passes, Prepare&& prepare, Step&& step) {
  return lugrip_bench::time_batched(n, passes, g_timer, prepare, step);
}

// Every step of one pass timed alone (after `prepare()`, no warm-up).
template <class Prepare, class Step>
Stats time_single(int n, Prepare&& prepare, Step&& step) {
  return lugrip_bench::time_each(n, 1, g_timer, false, prepare, step);
}

// ---- input stream ------------------------------------------------------------------------------

struct Stream {
  std::vector<lugrip::ObserverInput> in;
  int maneuvers = 0;
  double peak_omega = 0.0;
};

Stream make_stream(const lugrip::ContactParams& p, int n_samples, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  std::normal_distribution<double> gauss(0.0, 1.0);
  auto uniform = [&](double lo, double hi) { return lo + (hi - lo) * u01(rng); };
  auto log_uniform = [&](double lo, double hi) { return std::exp(uniform(std::log(lo), std::log(hi))); };
  const lugrip::ContactModel model(p);
  lugrip::SliderSettings ss;
  ss.max_substep = 1e-4;
  const double J = 1e-4;
  lugrip::SliderModel plant(model, J, ss);
  Stream s;
  s.in.reserve(static_cast<size_t>(n_samples));
  const double noise_f = 0.005, noise_t = 1e-5;
  while (static_cast<int>(s.in.size()) < n_samples) {
    const double f_n = uniform(1.0, 10.0);
    const double a = log_uniform(0.02, 2.0 * p.c_max);
    const double dir = u01(rng) < 0.5 ? -1.0 : 1.0;
    const double phi = uniform(-3.141592653589793, 3.141592653589793);
    const double g = model.g(f_n, a), s1 = model.sigma_1(f_n, a);
    const bool stick = u01(rng) < 0.15;
    double hold = uniform(0.1, 0.5);
    double ratio;
    if (stick) {
      ratio = uniform(0.3, 0.85);
    } else {
      const double w_peak = log_uniform(0.05, 0.5) / std::sqrt(1.0 + 2.0 * a * a);
      ratio = 1.0 + s1 * w_peak / g;
      hold = std::max(hold, std::min(3.0 * J / s1, 2.0));
    }
    const double ramp = uniform(0.3, 1.0), release = uniform(0.1, 0.4), rest = 0.2;
    const double knots[6] = {0.0, rest, rest + ramp, rest + ramp + hold, rest + ramp + hold + release,
                             2.0 * rest + ramp + hold + release};
    const double level[6] = {0.0, 0.0, 1.0, 1.0, 0.0, 0.0};
    plant.reset();
    lugrip::SliderOutput out;
    const int n = static_cast<int>(std::ceil(knots[5] / kDt));
    for (int i = 0; i <= n; ++i) {
      const double t = i * kDt;
      int k = 0;
      while (k < 4 && t > knots[k + 1]) ++k;
      const double w = knots[k + 1] > knots[k] ? std::min(1.0, (t - knots[k]) / (knots[k + 1] - knots[k])) : 1.0;
      const double load = dir * ratio * g * (level[k] + w * (level[k + 1] - level[k]));
      plant.step(lugrip::SliderInput{f_n, a, load, kDt}, out);
      double f_t = 0.0, tau = 0.0;
      model.wrench_at(f_n, a, out.friction_torque, f_t, tau);
      const double fx = f_t * std::cos(phi) + noise_f * gauss(rng);
      const double fy = f_t * std::sin(phi) + noise_f * gauss(rng);
      s.in.push_back(lugrip::ObserverInput::from_force_vector(f_n + noise_f * gauss(rng), fx, fy,
                                                              tau + noise_t * gauss(rng), kDt));
      s.peak_omega = std::max(s.peak_omega, std::fabs(out.omega));
      if (static_cast<int>(s.in.size()) >= n_samples) break;
    }
    ++s.maneuvers;
  }
  return s;
}

// ---- cases -------------------------------------------------------------------------------------

struct Row {
  std::string params, name, detail;
  Stats batched;
  bool has_single = false;
  Stats single;
  double mean_substeps = 0.0, mean_cor_iterations = 0.0;
  long diverged = 0;
};

void run_params(const char* label, const lugrip::ContactParams& p, const Stream& stream, int passes,
                std::vector<Row>& rows) {
  const int n = static_cast<int>(stream.in.size());
  const lugrip::ContactModel model(p);
  struct Variant {
    const char* name;
    const char* detail;
    lugrip::Integrator integrator;
    lugrip::GainMode mode;
    bool single;
  };
  const Variant variants[] = {
      {"observer/rosenbrock", "default settings (ROS2, l = bandwidth/sigma_1)", lugrip::Integrator::Rosenbrock,
       lugrip::GainMode::Bandwidth, true},
      {"observer/implicit", "exponential-implicit Euler, l = bandwidth/sigma_1", lugrip::Integrator::Implicit,
       lugrip::GainMode::Bandwidth, false},
      {"observer/rk4", "one RK4 step per sample, fixed l = 200 (paper)", lugrip::Integrator::Rk4,
       lugrip::GainMode::Fixed, false},
      {"observer/rk4_adaptive", "RK4 with adaptive substeps, l = bandwidth/sigma_1", lugrip::Integrator::Rk4Adaptive,
       lugrip::GainMode::Bandwidth, false},
  };
  for (const Variant& v : variants) {
    lugrip::ObserverSettings s;
    s.integrator = v.integrator;
    s.gain_mode = v.mode;
    lugrip::Observer obs(model, s);
    lugrip::ObserverOutput out;
    long substeps = 0, iterations = 0, diverged = 0;
    auto prepare = [&] { obs.reset(); };
    auto step = [&](int i) {
      obs.step(stream.in[static_cast<size_t>(i)], out);
      g_sink = g_sink + out.omega_hat;
    };
    Row r;
    r.params = label;
    r.name = v.name;
    r.detail = v.detail;
    r.batched = time_stream(n, passes, prepare, step);
    // statistics of the work done (one untimed pass)
    obs.reset();
    for (int i = 0; i < n; ++i) {
      obs.step(stream.in[static_cast<size_t>(i)], out);
      substeps += out.substeps;
      iterations += out.cor_iterations;
      diverged += out.diverged ? 1 : 0;
    }
    r.mean_substeps = static_cast<double>(substeps) / n;
    r.mean_cor_iterations = static_cast<double>(iterations) / n;
    r.diverged = diverged;
    if (v.single) {
      r.has_single = true;
      r.single = time_single(n, prepare, step);
    }
    rows.push_back(r);
  }
  lugrip::CorEstimator cor(model);
  lugrip::CorOutput co;
  Row r;
  r.params = label;
  r.name = "cor";
  r.detail = "CorEstimator::step alone on the same stream (raw torque)";
  r.batched = time_stream(
      n, passes, [&] { cor.reset(); },
      [&](int i) {
        const lugrip::ObserverInput& in = stream.in[static_cast<size_t>(i)];
        cor.step(lugrip::CorInput{in.f_n, in.f_t, in.tau}, co);
        g_sink = g_sink + co.c_tilde;
      });
  long iterations = 0;
  cor.reset();
  for (int i = 0; i < n; ++i) {
    const lugrip::ObserverInput& in = stream.in[static_cast<size_t>(i)];
    cor.step(lugrip::CorInput{in.f_n, in.f_t, in.tau}, co);
    iterations += co.iterations;
  }
  r.mean_cor_iterations = static_cast<double>(iterations) / n;
  rows.push_back(r);
}

void print_stats_json(const Stats& s) {
  std::printf("{\"median_ns\": %.3f, \"p99_ns\": %.3f, \"mean_ns\": %.3f, \"worst_ns\": %.3f, "
              "\"calls\": %ld, \"allocations\": %ld}",
              s.median, s.p99, s.mean, s.worst, s.calls, s.allocations);
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false, json = false;
  unsigned seed = 7;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--quick")) {
      quick = true;
    } else if (!std::strcmp(argv[i], "--json")) {
      json = true;
    } else if (!std::strcmp(argv[i], "--seed") && i + 1 < argc) {
      seed = static_cast<unsigned>(std::strtoul(argv[++i], nullptr, 10));
    } else {
      std::fprintf(stderr, "usage: %s [--quick] [--json] [--seed N]\n", argv[0]);
      return 2;
    }
  }
  const int n_samples = quick ? 20000 : 100000;
  const int passes = quick ? 2 : 5;
  g_timer = lugrip_bench::timer_overhead_ns();
  struct Named {
    const char* label;
    lugrip::ContactParams params;
  };
  const Named sets[] = {{"table1", lugrip::table1_params()},
                        {"big_resin_block", lugrip::object_params("big_resin_block")}};
  std::vector<Row> rows;
  std::vector<Stream> streams;
  for (const Named& s : sets) {
    streams.push_back(make_stream(s.params, n_samples, seed));
    run_params(s.label, s.params, streams.back(), passes, rows);
  }
  if (json) {
    std::printf("{\n  \"benchmark\": \"bench_observer\",\n  \"compiler\": \"%s\",\n",
                json_escape(compiler_string()).c_str());
    std::printf("  \"build_type\": \"%s\",\n  \"cxx_flags\": \"%s\",\n", json_escape(LUGRIP_BENCH_BUILD_TYPE).c_str(),
                json_escape(LUGRIP_BENCH_CXX_FLAGS).c_str());
    std::printf("  \"seed\": %u,\n  \"quick\": %s,\n  \"samples\": %d,\n  \"passes\": %d,\n  \"batch\": %d,\n",
                seed, quick ? "true" : "false", n_samples, passes, kBatch);
    std::printf("  \"timer_overhead_ns\": %.3f,\n  \"streams\": [", g_timer);
    for (size_t i = 0; i < streams.size(); ++i)
      std::printf("%s{\"params\": \"%s\", \"maneuvers\": %d, \"peak_omega\": %.6g}", i ? ", " : "",
                  sets[i].label, streams[i].maneuvers, streams[i].peak_omega);
    std::printf("],\n  \"rows\": [\n");
    for (size_t i = 0; i < rows.size(); ++i) {
      const Row& r = rows[i];
      std::printf("    {\"params\": \"%s\", \"name\": \"%s\", \"detail\": \"%s\", \"batched\": ", r.params.c_str(),
                  r.name.c_str(), json_escape(r.detail).c_str());
      print_stats_json(r.batched);
      if (r.has_single) {
        std::printf(", \"single\": ");
        print_stats_json(r.single);
      }
      std::printf(", \"mean_substeps\": %.4f, \"mean_cor_iterations\": %.4f, \"diverged\": %ld}%s\n",
                  r.mean_substeps, r.mean_cor_iterations, r.diverged, i + 1 < rows.size() ? "," : "");
    }
    std::printf("  ]\n}\n");
    return 0;
  }
  std::printf("lugrip bench_observer — %s; build %s; flags \"%s\"\n", compiler_string().c_str(),
              LUGRIP_BENCH_BUILD_TYPE, LUGRIP_BENCH_CXX_FLAGS);
  std::printf("stream: %d samples at 500 Hz per parameter set, %d timed passes, batches of %d, timer %.1f ns\n\n",
              n_samples, passes, kBatch, g_timer);
  std::printf("%-16s %-22s %9s %9s %9s %9s %8s %7s %6s  %s\n", "params", "case", "median", "p99", "mean", "worst",
              "substeps", "cor_it", "alloc", "detail");
  for (const Row& r : rows) {
    std::printf("%-16s %-22s %7.0fns %7.0fns %7.0fns %7.0fns %8.2f %7.2f %6ld  %s%s\n", r.params.c_str(),
                r.name.c_str(), r.batched.median, r.batched.p99, r.batched.mean, r.batched.worst, r.mean_substeps,
                r.mean_cor_iterations, r.batched.allocations, r.detail.c_str(),
                r.diverged ? (" [diverged " + std::to_string(r.diverged) + "x]").c_str() : "");
    if (r.has_single)
      std::printf("%-16s %-22s %7.0fns %7.0fns %7.0fns %7.0fns   (each step timed alone)\n", "", "  single call",
                  r.single.median, r.single.p99, r.single.mean, r.single.worst);
  }
  return 0;
}
