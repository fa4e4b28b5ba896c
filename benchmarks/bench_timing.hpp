// lugrip — timing helpers shared by the C++ benchmarks (bench_core, bench_observer,
// bench_closed_loop). Header-only, C++17, standard library only.
//
// Method: std::chrono::steady_clock. A per-call figure from time_batched is
// the time of a batch of kBatch = 16 consecutive calls (two clock reads around the batch) minus
// the median cost of an empty timed region (timer_overhead_ns), divided by kBatch; time_each
// times every call alone, with the same overhead subtracted. Median / p99 of per-call figures
// interpolate linearly between sorted samples (percentile); "worst" is the slowest sample.
// The timed loops' allocations are read from the counting global operator new of
// tests/support/counting_new.hpp, which this header includes: include it from the benchmark's
// one translation unit only.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "counting_new.hpp"

// The build records its flags in the binary (benchmarks/CMakeLists.txt) so the reports can state them.
#ifndef LUGRIP_BENCH_CXX_FLAGS
#define LUGRIP_BENCH_CXX_FLAGS "unknown"
#endif
#ifndef LUGRIP_BENCH_BUILD_TYPE
#define LUGRIP_BENCH_BUILD_TYPE "unknown"
#endif

namespace lugrip_bench {

using Clock = std::chrono::steady_clock;
constexpr int kBatch = 16;  // calls per timed batch

inline double ns_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::nano>(b - a).count();
}

inline double seconds_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

struct Stats {
  double median = 0, p99 = 0, worst = 0, mean = 0, best = 0;
  long calls = 0;
  long allocations = 0;
};

// q-quantile of a SORTED vector, linear interpolation between neighbours.
inline double percentile(const std::vector<double>& sorted, double q) {
  if (sorted.empty()) return 0.0;
  const double pos = q * static_cast<double>(sorted.size() - 1);
  const std::size_t i = static_cast<std::size_t>(pos);
  const double f = pos - static_cast<double>(i);
  return i + 1 < sorted.size() ? sorted[i] * (1 - f) + sorted[i + 1] * f : sorted[i];
}

// q-quantile of an unsorted vector, nearest rank (reorders v with nth_element).
inline double percentile_nearest(std::vector<double>& v, double q) {
  if (v.empty()) return 0.0;
  const std::size_t i = std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(i), v.end());
  return v[i];
}

// Median, p99, worst, best and mean of per-call figures; `calls` is the number of calls they cover.
inline Stats summarize(std::vector<double> per_call, long calls) {
  Stats s;
  s.calls = calls;
  if (per_call.empty()) return s;
  std::sort(per_call.begin(), per_call.end());
  s.median = percentile(per_call, 0.5);
  s.p99 = percentile(per_call, 0.99);
  s.worst = per_call.back();
  s.best = per_call.front();
  double sum = 0;
  for (double x : per_call) sum += x;
  s.mean = sum / static_cast<double>(per_call.size());
  return s;
}

// Median cost of an empty timed region (two clock reads) over `samples` tries; subtracted from
// every timed batch or call.
inline double timer_overhead_ns(int samples = 20000) {
  std::vector<double> v(static_cast<std::size_t>(samples));
  for (double& x : v) {
    const auto t0 = Clock::now();
    const auto t1 = Clock::now();
    x = ns_between(t0, t1);
  }
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// step(i) for i in [0, n) in batches of kBatch (a remainder of n below one batch is not timed),
// `passes` times; reset() before an untimed warm-up pass and before every timed pass. Per-call
// figure of a batch: (batch time - overhead_ns, at least 0) / kBatch. Stats::allocations counts
// the allocations over all timed passes (the result vector is reserved before).
template <class Reset, class Step>
Stats time_batched(int n, int passes, double overhead_ns, Reset&& reset, Step&& step) {
  const int batches = n / kBatch;
  std::vector<double> per_call;
  per_call.reserve(static_cast<std::size_t>(batches) * static_cast<std::size_t>(passes));
  reset();
  for (int i = 0; i < n; ++i) step(i);  // warm-up: caches, branch predictors
  const long alloc0 = lugrip_support::g_allocations.load();
  for (int p = 0; p < passes; ++p) {
    reset();
    for (int b = 0; b < batches; ++b) {
      const int i0 = b * kBatch;
      const auto t0 = Clock::now();
      for (int i = i0; i < i0 + kBatch; ++i) step(i);
      const auto t1 = Clock::now();
      per_call.push_back(std::max(0.0, ns_between(t0, t1) - overhead_ns) / kBatch);
    }
  }
  const long alloc1 = lugrip_support::g_allocations.load();
  Stats s = summarize(std::move(per_call), static_cast<long>(batches) * kBatch * passes);
  s.allocations = alloc1 - alloc0;
  return s;
}

// Every call of step(i), i in [0, n), timed alone, `passes` times; reset() before every pass
// (and before an untimed warm-up pass if warm_up). Returns the per-call times in ns (call order,
// overhead_ns subtracted, at least 0).
template <class Reset, class Step>
std::vector<double> time_each_ns(int n, int passes, double overhead_ns, bool warm_up, Reset&& reset, Step&& step) {
  std::vector<double> per_call;
  per_call.reserve(static_cast<std::size_t>(n) * static_cast<std::size_t>(passes));
  if (warm_up) {
    reset();
    for (int i = 0; i < n; ++i) step(i);
  }
  for (int p = 0; p < passes; ++p) {
    reset();
    for (int i = 0; i < n; ++i) {
      const auto t0 = Clock::now();
      step(i);
      const auto t1 = Clock::now();
      per_call.push_back(std::max(0.0, ns_between(t0, t1) - overhead_ns));
    }
  }
  return per_call;
}

// time_each_ns summarised.
template <class Reset, class Step>
Stats time_each(int n, int passes, double overhead_ns, bool warm_up, Reset&& reset, Step&& step) {
  return summarize(time_each_ns(n, passes, overhead_ns, warm_up, reset, step), static_cast<long>(n) * passes);
}

// ---- report headers ----------------------------------------------------------------------------

inline std::string compiler_string() {
#if defined(__clang__)
  return std::string("clang ") + __clang_version__;
#elif defined(__GNUC__)
  return std::string("gcc ") + __VERSION__;
#elif defined(_MSC_VER)
  return "msvc " + std::to_string(_MSC_VER);
#else
  return "unknown";
#endif
}

// The optimisation / ISA / sanitizer macros this translation unit was compiled with.
inline std::string macro_flags() {
  std::string f;
#if defined(__OPTIMIZE__)
  f += "__OPTIMIZE__ ";
#endif
#if defined(__OPTIMIZE_SIZE__)
  f += "__OPTIMIZE_SIZE__ ";
#endif
#if defined(__NO_INLINE__)
  f += "__NO_INLINE__ ";
#endif
#if defined(NDEBUG)
  f += "NDEBUG ";
#endif
#if defined(__FAST_MATH__)
  f += "__FAST_MATH__ ";
#endif
#if defined(__SSE2__)
  f += "__SSE2__ ";
#endif
#if defined(__AVX__)
  f += "__AVX__ ";
#endif
#if defined(__AVX2__)
  f += "__AVX2__ ";
#endif
#if defined(__FMA__)
  f += "__FMA__ ";
#endif
#if defined(__SANITIZE_ADDRESS__)
  f += "__SANITIZE_ADDRESS__ ";
#endif
  f += "__cplusplus=" + std::to_string(__cplusplus);
  return f;
}

// "YYYY-MM-DD HH:MM UTC" now.
inline std::string utc_now_string() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M UTC", &tm);
  return buf;
}

// The first "model name" of /proc/cpuinfo ("unknown CPU" where there is none).
inline std::string cpu_model_string() {
  std::ifstream f("/proc/cpuinfo");
  std::string line;
  while (std::getline(f, line)) {
    if (line.rfind("model name", 0) == 0) {
      const size_t colon = line.find(':');
      if (colon != std::string::npos) return line.substr(line.find_first_not_of(' ', colon + 1));
    }
  }
  return "unknown CPU";
}

// The 1/5/15-minute load averages as "a / b / c" (from /proc/loadavg; "n/a" where unreadable):
// the machines are shared, so a report states the load it was measured under.
inline std::string load_average_string() {
  std::ifstream f("/proc/loadavg");
  double a = 0, b = 0, c = 0;
  if (!(f >> a >> b >> c)) return "n/a";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.2f / %.2f / %.2f", a, b, c);
  return buf;
}

// Backslash-escapes '"' and '\' for a JSON string.
inline std::string json_escape(const std::string& s) {
  std::string r;
  for (char c : s) {
    if (c == '"' || c == '\\') r += '\\';
    r += c;
  }
  return r;
}

}  // namespace lugrip_bench
