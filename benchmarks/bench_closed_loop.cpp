// lugrip — closed-loop simulation speed: steps per second on one core and the ratio to
// real time, for the lumped-slider plant and the distributed (patch) contact plant.
//
//   bench_closed_loop [--quick] [--json | --markdown]
//
// One closed-loop step = one sensor sample (500 Hz): the plant advanced by one sample period
// (two 1 kHz plant steps, or one with the 500 Hz lumped variant), both fingertip observers and
// the grasp controller (docs/model.md 9.7). "x real time" = simulated seconds per wall-clock second.
// The scenario is a lift of a 0.3 kg block grasped 3 mm beside its CoG with a push (every branch:
// support, lift-off transient, hold, disturbance), repeated from reset() until the time budget
// is spent. Components are timed alone with the same inputs (plant open loop at a constant
// command; one observer replaying the recorded sensor samples; the controller replaying the
// recorded observer outputs). Timing: std::chrono::steady_clock around whole runs (best and
// median of the repetitions), plus a per-step pass (each step timed alone, clock overhead
// subtracted) for p99 / worst. Benchmarks are not tests: nothing here asserts a timing; the
// allocation count of the timed loops is reported. --markdown prints the closed-loop speed section of
// BENCHMARKS.md (between <!-- issue5:begin --> and <!-- issue5:end -->, which it replaces).
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "bench_timing.hpp"  // timing helpers; includes the allocation counter (counting_new.hpp)
#include "lugrip/closed_loop.hpp"

using namespace lugrip;

namespace {

using lugrip_bench::Clock;
using lugrip_bench::seconds_between;
volatile double g_sink = 0.0;

ClosedLoopConfig scenario(PlantModel model, double plant_rate) {
  ClosedLoopConfig c;
  c.plant.contact = object_params("small_resin_block");
  c.plant.model = model;
  c.plant.rate = plant_rate;
  c.plant.object.mass = 0.3;
  c.plant.object.inertia = 6e-4;
  c.plant.object.cog_x = 0.003;
  c.plant.actuator.f_init = 2.0;
  c.plant.support = true;
  c.plant.moves.push_back(GripperMove{0.5, 1.5, 0.0, 0.05});
  c.plant.disturbances.push_back(Disturbance{4.0, 0.5, PulseShape::HalfSine, 0.0, -1.0, 0.0, 0.0, 0.0});
  c.observer.cor_sign_sigmas = 100.0;
  return c;
}

struct Result {
  std::string name;
  double steps_per_s_best = 0, steps_per_s_median = 0, realtime_best = 0, realtime_median = 0;
  double plant_steps_per_sample = 0;
  double p50_ns = 0, p99_ns = 0, worst_ns = 0;
  long steps = 0, allocations = 0;
  int cells = 0;
};

// Whole runs of `samples` closed-loop steps from reset(), repeated `reps` times.
Result bench_loop(const char* name, const ClosedLoopConfig& cfg, long samples, int reps) {
  ClosedLoop loop(cfg);
  ClosedLoopSample s;
  Result r;
  r.name = name;
  r.cells = loop.plant().cells();
  r.plant_steps_per_sample = loop.plant().steps_per_sample();
  std::vector<double> rates;
  rates.reserve(static_cast<size_t>(reps));
  long allocations = 0;
  for (int k = 0; k < reps; ++k) {
    loop.reset();
    const long a0 = lugrip_support::g_allocations.load();
    const auto t0 = Clock::now();
    for (long n = 0; n < samples; ++n) loop.step(s);
    const auto t1 = Clock::now();
    allocations += lugrip_support::g_allocations.load() - a0;
    g_sink = g_sink + s.command;
    rates.push_back(samples / seconds_between(t0, t1));
    r.steps += samples;
  }
  r.allocations = allocations;
  std::sort(rates.begin(), rates.end());
  r.steps_per_s_best = rates.back();
  r.steps_per_s_median = rates[rates.size() / 2];
  r.realtime_best = r.steps_per_s_best * loop.sample_period();
  r.realtime_median = r.steps_per_s_median * loop.sample_period();
  // per-step pass: every step timed alone (overhead of an empty timed region subtracted)
  const double overhead = lugrip_bench::timer_overhead_ns(2000);
  std::vector<double> each = lugrip_bench::time_each_ns(
      static_cast<int>(samples), 1, overhead, false, [&] { loop.reset(); }, [&](int) { loop.step(s); });
  r.worst_ns = *std::max_element(each.begin(), each.end());
  r.p99_ns = lugrip_bench::percentile_nearest(each, 0.99);
  r.p50_ns = lugrip_bench::percentile_nearest(each, 0.5);
  return r;
}

// Components alone on the same data: plant open loop, one observer, the controller.
struct Parts {
  double plant_ns = 0, observer_ns = 0, controller_ns = 0;
  double observer_substeps = 0;  // mean integrator substeps per observer step
  long capped = 0;               // observer steps that needed max_substeps
};

Parts bench_parts(const ClosedLoopConfig& cfg, long samples) {
  Parts p;
  // record the closed loop once (inputs for the observer and controller replays)
  ClosedLoop loop(cfg);
  std::vector<ObserverInput> obs_in(static_cast<size_t>(samples));
  std::vector<GraspControllerInput> ctrl_in(static_cast<size_t>(samples));
  std::vector<double> cmd(static_cast<size_t>(samples));
  ClosedLoopSample s;
  for (long n = 0; n < samples; ++n) {
    loop.step(s);
    obs_in[static_cast<size_t>(n)] = ObserverInput{s.f_n_meas[0], s.f_t_meas[0], s.tau_meas[0], 0.0};
    for (int i = 0; i < 2; ++i) {
      FingerInput& f = ctrl_in[static_cast<size_t>(n)].fingers[i];
      f.omega_hat = s.omega_hat[i];
      f.slippage = s.slippage[i];
      f.c_tilde = s.c_tilde[i];
      f.f_t = s.f_t_meas[i];
      f.status = static_cast<Status>(s.observer_status[i]);
    }
    cmd[static_cast<size_t>(n)] = s.command;
  }
  {
    GraspPlant plant(cfg.plant);
    const auto t0 = Clock::now();
    for (long n = 0; n < samples; ++n) {
      plant.set_command(cmd[static_cast<size_t>(n)]);
      plant.advance_sample();
    }
    const auto t1 = Clock::now();
    g_sink = g_sink + plant.state().f_n;
    p.plant_ns = seconds_between(t0, t1) * 1e9 / samples;
  }
  {
    Observer obs(cfg.plant.contact, cfg.observer);
    ObserverOutput o;
    const auto t0 = Clock::now();
    for (const ObserverInput& in : obs_in) obs.step(in, o);
    const auto t1 = Clock::now();
    g_sink = g_sink + o.S;
    p.observer_ns = seconds_between(t0, t1) * 1e9 / samples;
    obs.reset();  // untimed pass: how many integrator substeps the replay took
    long substeps = 0;
    for (const ObserverInput& in : obs_in) {
      obs.step(in, o);
      substeps += o.substeps;
      if (o.substeps >= cfg.observer.max_substeps) ++p.capped;
    }
    p.observer_substeps = static_cast<double>(substeps) / samples;
  }
  {
    GraspController ctrl(cfg.plant.contact, cfg.controller);
    GraspControllerOutput o;
    const auto t0 = Clock::now();
    for (const GraspControllerInput& in : ctrl_in) ctrl.step(in, o);
    const auto t1 = Clock::now();
    g_sink = g_sink + o.force;
    p.controller_ns = seconds_between(t0, t1) * 1e9 / samples;
  }
  return p;
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false, json = false, markdown = false;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--quick")) quick = true;
    else if (!std::strcmp(argv[i], "--json")) json = true;
    else if (!std::strcmp(argv[i], "--markdown")) markdown = true;
    else {
      std::fprintf(stderr, "usage: %s [--quick] [--json | --markdown]\n", argv[0]);
      return 2;
    }
  }
  const std::string load_before = lugrip_bench::load_average_string();
  const long samples = 3000;  // 6 s simulated per run
  const int reps_lumped = quick ? 5 : 30, reps_patch = quick ? 2 : 8;
  const int plant_rate_default = 1000;

  std::vector<Result> rs;
  std::vector<Parts> parts;
  const ClosedLoopConfig lumped = scenario(PlantModel::Lumped, plant_rate_default);
  const ClosedLoopConfig lumped500 = scenario(PlantModel::Lumped, 500.0);
  const ClosedLoopConfig patch = scenario(PlantModel::Patch, plant_rate_default);
  rs.push_back(bench_loop("lumped (plant 1 kHz)", lumped, samples, reps_lumped));
  rs.push_back(bench_loop("lumped (plant 500 Hz)", lumped500, samples, reps_lumped));
  rs.push_back(bench_loop("patch (plant 1 kHz, 314 cells)", patch, samples, reps_patch));
  parts.push_back(bench_parts(lumped, samples));
  parts.push_back(bench_parts(lumped500, samples));
  parts.push_back(bench_parts(patch, samples));

  if (json) {
    std::printf("{\n  \"build_type\": \"%s\",\n  \"cxx_flags\": \"%s\",\n  \"sizeof_closed_loop\": %zu,\n  \"results\": [\n",
                LUGRIP_BENCH_BUILD_TYPE, LUGRIP_BENCH_CXX_FLAGS, sizeof(ClosedLoop));
    for (size_t i = 0; i < rs.size(); ++i) {
      const Result& r = rs[i];
      const Parts& p = parts[i];
      std::printf("    {\"name\": \"%s\", \"cells\": %d, \"plant_steps_per_sample\": %.0f, \"steps\": %ld, "
                  "\"steps_per_s_best\": %.6g, \"steps_per_s_median\": %.6g, \"realtime_best\": %.6g, "
                  "\"realtime_median\": %.6g, \"p50_ns\": %.6g, \"p99_ns\": %.6g, \"worst_ns\": %.6g, "
                  "\"allocations\": %ld, \"plant_ns\": %.6g, \"observer_ns\": %.6g, \"controller_ns\": %.6g}%s\n",
                  r.name.c_str(), r.cells, r.plant_steps_per_sample, r.steps, r.steps_per_s_best,
                  r.steps_per_s_median, r.realtime_best, r.realtime_median, r.p50_ns, r.p99_ns, r.worst_ns,
                  r.allocations, p.plant_ns, p.observer_ns, p.controller_ns, i + 1 < rs.size() ? "," : "");
    }
    std::printf("  ]\n}\n");
    return 0;
  }
  if (markdown) {
    const Result& l = rs[0];
    const Result& p = rs[2];
    std::printf("<!-- issue5:begin -->\n\n## Closed-loop simulation speed\n\n");
    std::printf("Generated by `build/cpp/benchmarks/bench_closed_loop --markdown` (this section only, between the "
                "`issue5` markers). One closed-loop step = one 500 Hz sample: the plant advanced by one sample "
                "period (two 1 kHz plant steps, or one for the 500 Hz lumped variant), both fingertip observers "
                "(CoR estimate + rotor update each) and the grasp controller. Scenario: 0.3 kg block grasped 3 mm "
                "beside its CoG, lifted from a table, pushed; 6 s simulated per run, repeated from reset(); "
                "build %s, `%s`, sizeof(ClosedLoop) = %zu B. Median of the runs; p50/p99/worst from a pass that "
                "times every step alone (worst includes preemption on this shared machine).\n\n",
                LUGRIP_BENCH_BUILD_TYPE, LUGRIP_BENCH_CXX_FLAGS, sizeof(ClosedLoop));
    std::printf("- Measured %s on %s (one core); %s; load average (1/5/15 min) before / after: %s -> %s.\n\n",
                lugrip_bench::utc_now_string().c_str(), lugrip_bench::cpu_model_string().c_str(),
                lugrip_bench::compiler_string().c_str(), load_before.c_str(),
                lugrip_bench::load_average_string().c_str());
    std::printf("| target | measured | status |\n|---|---|---|\n");
    std::printf("| >= 1e6 plant+observer+controller steps/s, lumped plant | %.2e closed-loop steps/s (plant 1 kHz), "
                "%.2e (plant 500 Hz); counting the component steps (2 plant + 2 observer + 1 controller per sample at "
                "1 kHz) %.2e/s | **%s** as closed-loop steps |\n",
                l.steps_per_s_median, rs[1].steps_per_s_median, 5.0 * l.steps_per_s_median,
                l.steps_per_s_median >= 1e6 ? "met" : "not met");
    std::printf("| >= 20x real time, patch plant | %.0fx (%.2e steps/s) | **%s** |\n\n", p.realtime_median,
                p.steps_per_s_median, p.realtime_median >= 20.0 ? "met" : "not met");
    std::printf("| plant | steps/s (median) | x real time | p50 | p99 | worst | plant / observer / controller alone "
                "[ns per step] | allocations |\n|---|---|---|---|---|---|---|---|\n");
    for (size_t i = 0; i < rs.size(); ++i)
      std::printf("| %s | %.3g | %.0f | %.2f µs | %.2f µs | %.1f µs | %.0f / %.0f (x2) / %.0f | %ld |\n",
                  rs[i].name.c_str(), rs[i].steps_per_s_median, rs[i].realtime_median, rs[i].p50_ns / 1e3,
                  rs[i].p99_ns / 1e3, rs[i].worst_ns / 1e3, parts[i].plant_ns, parts[i].observer_ns,
                  parts[i].controller_ns, rs[i].allocations);
    std::printf("\nWhere the time goes (lumped plant, 1 kHz): per sample the plant takes two steps (%.0f ns together, "
                "each with a CoR estimate of the quasi-static load and an implicit rotor step, plus the sensor sample "
                "with its 8 normal random numbers from a ziggurat), each of the two observers one CoR estimate and its "
                "Rosenbrock update (%.0f ns each), the controller %.0f ns. The four CoR estimates per sample (two pow, a "
                "log and an exp each, from include/lugrip/detail/fast_math.hpp, and LS table evaluations; per-call "
                "time in the contact-model core table) are the largest share. The replayed observer (finger 0) averages %.2f "
                "Rosenbrock substeps per sample and %s of its %ld samples reached the cap of %d substeps: one "
                "L-stable step in stick and hold, about h B = 6 while sliding, where the omega mode relaxes at the "
                "observer's bandwidth B, and never the bristle rate sigma0 |omega| / g itself, which is huge at "
                "lift-off with the force at its floor (slider_model.hpp, rosenbrock_rate). The plant reuses what is "
                "exactly reusable: the CoR estimate's rho, g and sigma_1 (bit-identical to the model functions), "
                "cos/sin of the object angle from the previous step, rho at an unchanged actuator force, run-time "
                "constants; its CoR inputs change at every step (the actuator force follows a first-order lag, the "
                "load turns with the object), so no estimate can be reused exactly. Absolute rates scale with the "
                "load of this shared machine (stated above); the component times come from separate replays and "
                "vary by +-30 %% between runs.\n\n",
                parts[0].plant_ns, parts[0].observer_ns, parts[0].controller_ns, parts[0].observer_substeps,
                parts[0].capped == 0 ? "none" : std::to_string(parts[0].capped).c_str(), samples,
                lumped.observer.max_substeps);
    std::printf("<!-- issue5:end -->\n");
    return 0;
  }
  std::printf("closed loop: plant -> 2 sensors -> 2 observers -> controller (one step = one 500 Hz sample)\n");
  std::printf("build %s, flags \"%s\", sizeof(ClosedLoop) = %zu B\n\n", LUGRIP_BENCH_BUILD_TYPE,
              LUGRIP_BENCH_CXX_FLAGS, sizeof(ClosedLoop));
  std::printf("%-32s %14s %14s %12s %10s %10s %10s %7s\n", "plant", "steps/s best", "steps/s med",
              "x real time", "p50", "p99", "worst", "allocs");
  for (const Result& r : rs)
    std::printf("%-32s %14.3e %14.3e %12.0f %8.2f us %8.2f us %8.1f us %7ld\n", r.name.c_str(), r.steps_per_s_best,
                r.steps_per_s_median, r.realtime_median, r.p50_ns / 1e3, r.p99_ns / 1e3, r.worst_ns / 1e3,
                r.allocations);
  std::printf("\nper step, components alone (same data): plant advance to the next sample, one observer, controller\n");
  for (size_t i = 0; i < rs.size(); ++i)
    std::printf("%-32s plant %8.1f ns   observer %7.1f ns (x2)   controller %6.1f ns\n", rs[i].name.c_str(),
                parts[i].plant_ns, parts[i].observer_ns, parts[i].controller_ns);
  return 0;
}
