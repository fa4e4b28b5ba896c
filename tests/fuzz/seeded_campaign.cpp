// Seeded adversarial campaign (campaign.hpp) for machines without clang/libFuzzer; ctest runs a
// short one. Replaces the global operator new to count allocations inside step().
//
//   lugrip_fuzz_campaign [--samples N] [--seed S] [--case-samples M] [--json]
//
// Prints one summary line (--json: one JSON object) and the first failing case; exit 1 when
// any check failed.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "campaign.hpp"
#ifndef LUGRIP_FUZZ_NO_COUNTING_NEW
#include "counting_new.hpp"
#endif

namespace {
#ifndef LUGRIP_FUZZ_NO_COUNTING_NEW
long allocations() { return lugrip_support::g_allocations.load(std::memory_order_relaxed); }
#else
long allocations() { return 0; }
#endif

bool parse_long(const char* text, long& out) {
  char* end = nullptr;
  const long v = std::strtol(text, &end, 10);
  if (end == text || *end != '\0' || v <= 0) return false;
  out = v;
  return true;
}
}  // namespace

int main(int argc, char** argv) {
  long samples = 1000000, seed = 1, case_samples = 2000;
  bool json = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--json") {
      json = true;
      continue;
    }
    long* target = a == "--samples" ? &samples : a == "--seed" ? &seed : a == "--case-samples" ? &case_samples : nullptr;
    if (!target || i + 1 >= argc || !parse_long(argv[i + 1], *target)) {
      std::fprintf(stderr, "usage: %s [--samples N] [--seed S] [--case-samples M] [--json] (positive integers)\n",
                   argv[0]);
      return 2;
    }
    ++i;
  }
  const auto t0 = std::chrono::steady_clock::now();
  lugrip_fuzz::Campaign campaign(&allocations);
  lugrip_fuzz::Stats st;
  lugrip_fuzz::Source src(static_cast<uint64_t>(seed));
  while (st.samples < samples) {
    // case lengths from 1 to 2 case_samples: short cases draw more settings
    const int n = 1 + static_cast<int>(src.u64() % static_cast<uint64_t>(2 * case_samples));
    campaign.run_case(src, n, st);
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (json)
    std::printf(
        "{\"seed\": %ld, \"samples\": %ld, \"cases\": %ld, \"cases_cor\": %ld, \"cases_observer\": %ld, "
        "\"cases_controller\": %ld, \"cases_slip_control\": %ld, \"settings_rejected\": %ld, "
        "\"samples_rejected\": %ld, \"non_finite\": %ld, \"out_of_range\": %ld, \"twin_mismatch\": %ld, "
        "\"not_held\": %ld, \"ctor_mismatch\": %ld, \"allocations\": %ld, \"unknown_status_ok\": %ld, "
        "\"seconds\": %.2f}\n",
        seed, st.samples, st.cases, st.per_component[0], st.per_component[1], st.per_component[2], st.per_component[3],
        st.settings_rejected, st.rejected_samples, st.non_finite, st.out_of_range, st.twin_mismatch, st.not_held,
        st.ctor_mismatch, st.allocations, st.unknown_status_ok, seconds);
  else
    std::printf(
        "seed %ld: %ld samples in %ld cases (cor %ld, observer %ld, controller %ld, slip_control %ld), "
        "%ld settings rejected by validate(), %ld samples rejected by the components; "
        "non-finite %ld, out of range %ld, twin mismatches %ld, commands lowered on bad input %ld, "
        "constructor/validate mismatches %ld, allocations in step() %ld; "
        "out-of-enum finger status reported Ok %ld; %.1f s\n",
        seed, st.samples, st.cases, st.per_component[0], st.per_component[1], st.per_component[2], st.per_component[3],
        st.settings_rejected, st.rejected_samples, st.non_finite, st.out_of_range, st.twin_mismatch, st.not_held,
        st.ctor_mismatch, st.allocations, st.unknown_status_ok, seconds);
  if (st.failures() > 0) {
    std::printf("FAILED: first failure: %s\n", st.first_failure.c_str());
    return 1;
  }
  return 0;
}
