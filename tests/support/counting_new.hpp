// Replaces the global operator new/delete with versions that count every allocation, for the
// "step() never allocates" tests and the benchmarks' allocation reports.
// Include from exactly one translation unit of a binary; read g_allocations around the calls
// under test.
#pragma once

#include <atomic>
#include <cstdlib>
#include <new>

namespace lugrip_support {
inline std::atomic<long> g_allocations{0};
}  // namespace lugrip_support

void* operator new(std::size_t n) {
  lugrip_support::g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) { return operator new(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
