// lugrip — SlipControl::step for two fingers in C++: the real-time call a robot loop makes at
// the sensor rate (both observers, the controller with the grip probe and the ceiling).
//
// Input: a precomputed stream of two-finger wrenches of a quasi-static grasp (a lift-like ramp
// of the load, a steady hold, a push, sensor noise), replayed in order so that the controller
// runs its real branches (feed-forward, reflex, probes). Each repetition resets the object and
// steps the whole stream; the per-call figure is the median over repetitions of the stream's
// mean time per step (time_batched: batches of 16 calls). Allocations inside the timed loops are
// counted (counting operator new). After the timing, one untimed pass over the stream hashes the
// outputs bit for bit (the command, the controller's forces, every finger's estimate), so that
// two builds can be shown to compute the same numbers. The same source builds against any lugrip
// version with this API, so a baseline can be built from another checkout and run beside it:
//   bench_slip_control [--quick] [--observe]
// Last, every call is timed alone: the median call, and apart the calls that compute a command.
// --observe times SlipControl::observe() instead (the two observers without the controller).
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <random>
#include <vector>

#include "bench_timing.hpp"
#include "lugrip/slip_control.hpp"

using namespace lugrip;

namespace {
// FNV-1a over the bits of the values hashed
struct BitHash {
  std::uint64_t h = 14695981039346656037ULL;
  void add(std::uint64_t v) {
    for (int b = 0; b < 8; ++b) {
      h ^= (v >> (8 * b)) & 0xffU;
      h *= 1099511628211ULL;
    }
  }
  void add(double x) {
    std::uint64_t v;
    std::memcpy(&v, &x, sizeof v);
    add(v);
  }
  void add_all(const SlipControlOutput& o) {
    add(o.force);
    add(static_cast<std::uint64_t>(o.status));
    const GraspControllerOutput& c = o.controller;
    for (double x : {c.force, c.static_force, c.dynamic_force, c.floor, c.slippage, c.error, c.integrator,
                     c.gain_p, c.gain_i, c.feedforward_force, c.reserve_force, c.reserve_torque,
                     c.peak_slippage, c.mu_belief, c.ceiling, c.dynamic_peak, c.mean_c_tilde,
                     c.dynamic_sample[0], c.dynamic_sample[1]})
      add(x);
    add(static_cast<std::uint64_t>(c.reflex) | static_cast<std::uint64_t>(c.probing) << 1 |
        static_cast<std::uint64_t>(c.saturated) << 2 | static_cast<std::uint64_t>(c.rate_limited) << 3 |
        static_cast<std::uint64_t>(c.held) << 4 | static_cast<std::uint64_t>(c.command_issued) << 5);
    for (int i = 0; i < 2; ++i) {
      const ObserverOutput& f = o.fingers[static_cast<size_t>(i)];
      for (double x : {f.omega_hat, f.z_hat, f.S, f.c_tilde, f.c, f.g, f.sigma_1, f.y, f.tau_cor, f.ft_cor,
                       f.gain, f.omega_resolution, f.c_tilde_unclipped, f.omega_object, f.v_slip, f.omega_state})
        add(x);
      add(static_cast<std::uint64_t>(f.status) | static_cast<std::uint64_t>(f.substeps) << 8 |
          static_cast<std::uint64_t>(f.cor_iterations) << 24 | static_cast<std::uint64_t>(f.projected) << 40 |
          static_cast<std::uint64_t>(f.inside) << 41 | static_cast<std::uint64_t>(f.saturated) << 42 |
          static_cast<std::uint64_t>(f.kinetic) << 43 | static_cast<std::uint64_t>(f.speed_observable) << 44);
    }
  }
};
}  // namespace

int main(int argc, char** argv) {
  bool quick = false, observe_only = false;
  for (int i = 1; i < argc; ++i) {
    quick = quick || std::strcmp(argv[i], "--quick") == 0;
    observe_only = observe_only || std::strcmp(argv[i], "--observe") == 0;
  }
  const int n = quick ? 20000 : 100000;
  const int reps = quick ? 5 : 15;
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::vector<SlipControlInput> stream(static_cast<size_t>(n));
  for (int k = 0; k < n; ++k) {
    const double t = k * 0.002;
    const double load = 0.6 * std::min(1.0, t / 0.5) + (std::fmod(t, 20.0) > 10.0 && std::fmod(t, 20.0) < 10.3 ? 0.4 : 0.0);
    for (int i = 0; i < 2; ++i) {
      FingerWrench& w = stream[static_cast<size_t>(k)].fingers[static_cast<size_t>(i)];
      w.f_n = 3.0 + 0.01 * noise(rng);
      w.f_x = 0.005 * noise(rng);
      w.f_y = load + 0.005 * noise(rng);
      w.tau = 1.5e-3 * std::min(1.0, t / 0.5) + 2e-5 * noise(rng);
    }
  }
  SlipControl sc(object_params("small_resin_block"));
  SlipControlOutput out;
  std::vector<double> per_step;
  per_step.reserve(static_cast<size_t>(reps));
  long allocs = 0;
  double sink = 0.0;
  for (int r = 0; r < reps; ++r) {
    sc.reset(3.0);
    const long before = lugrip_support::g_allocations.load();
    const auto t0 = lugrip_bench::Clock::now();
    for (int k = 0; k < n; ++k) {
      if (observe_only)
        sc.observe(stream[static_cast<size_t>(k)], out);
      else
        sc.step(stream[static_cast<size_t>(k)], out);
      sink += out.force;
    }
    const auto t1 = lugrip_bench::Clock::now();
    allocs += lugrip_support::g_allocations.load() - before;
    per_step.push_back(lugrip_bench::ns_between(t0, t1) / n);
  }
  std::sort(per_step.begin(), per_step.end());
  BitHash hash;
  std::vector<char> issued(static_cast<size_t>(n));  // the calls that compute a command
  sc.reset(3.0);
  for (int k = 0; k < n; ++k) {
    sc.step(stream[static_cast<size_t>(k)], out);
    hash.add_all(out);
    issued[static_cast<size_t>(k)] = out.controller.command_issued ? 1 : 0;
  }
  // Every call timed alone (one pass after a warm-up, the timer's overhead subtracted): the
  // median call, and apart the calls that compute a command (every command_ratio-th) and the
  // others, which only observe and accumulate.
  const double overhead = lugrip_bench::timer_overhead_ns();
  const std::vector<double> each = lugrip_bench::time_each_ns(
      n, 1, overhead, true, [&] { sc.reset(3.0); },
      [&](int k) {
        if (observe_only)
          sc.observe(stream[static_cast<size_t>(k)], out);
        else
          sc.step(stream[static_cast<size_t>(k)], out);
      });
  std::vector<double> all = each, at_command, between;
  for (int k = 0; k < n; ++k) (issued[static_cast<size_t>(k)] ? at_command : between).push_back(each[static_cast<size_t>(k)]);
  for (std::vector<double>* v : {&all, &at_command, &between}) std::sort(v->begin(), v->end());
  std::printf("SlipControl::%s, two fingers: median %.1f ns per step, best %.1f ns, worst %.1f ns "
              "(%d repetitions of %d steps); allocations in the timed loops: %ld; build %s (%s); "
              "outputs' bit hash %016llx%s\n",
              observe_only ? "observe" : "step", per_step[per_step.size() / 2], per_step.front(), per_step.back(), reps, n, allocs,
              LUGRIP_BENCH_BUILD_TYPE, LUGRIP_BENCH_CXX_FLAGS, static_cast<unsigned long long>(hash.h),
              sink > 0 ? "" : " ");
  std::printf("each call timed alone: median %.1f ns, p99 %.1f ns, worst %.1f ns; calls that compute a "
              "command (%zu): median %.1f ns, p99 %.1f ns; the others (%zu): median %.1f ns, p99 %.1f ns "
              "(timer overhead %.1f ns subtracted)\n",
              lugrip_bench::percentile(all, 0.5), lugrip_bench::percentile(all, 0.99), all.back(),
              at_command.size(), lugrip_bench::percentile(at_command, 0.5), lugrip_bench::percentile(at_command, 0.99),
              between.size(), lugrip_bench::percentile(between, 0.5), lugrip_bench::percentile(between, 0.99), overhead);
  return 0;
}
