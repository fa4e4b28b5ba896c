// libFuzzer target over the campaign of campaign.hpp: the fuzzer's bytes choose the component,
// its settings (edges of validity and hostile values) and every sample. A broken promise
// aborts with the description of the check, so libFuzzer keeps the input as a crash.
// Allocation counting is left to the seeded driver (the sanitizers own operator new here).
//
//   cmake -S . -B build/fuzz -DCMAKE_CXX_COMPILER=clang++ -DLUGRIP_FUZZ=ON
//   cmake --build build/fuzz --target lugrip_fuzz
//   build/fuzz/tests/fuzz/lugrip_fuzz -max_total_time=600 -max_len=4096
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "campaign.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static lugrip_fuzz::Campaign campaign;
  lugrip_fuzz::Stats st;
  lugrip_fuzz::Source src(data, size);
  campaign.run_case(src, 512, st);
  if (st.failures() > 0) {
    std::fprintf(stderr, "lugrip_fuzz: %s\n", st.first_failure.c_str());
    std::abort();
  }
  return 0;
}
