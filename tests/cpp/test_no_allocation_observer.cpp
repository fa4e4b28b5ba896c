// Observer::step, SliderModel::step and reset never allocate: this binary
// replaces the global allocation functions with counting ones and counts only inside a window
// around the real-time calls.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <limits>
#include <new>
#include <random>

#include "lugrip/observer.hpp"
#include "lugrip/slider_model.hpp"

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

struct CountingWindow {
  CountingWindow() {
    allocations = 0;
    counting = true;
  }
  ~CountingWindow() { counting = false; }
  long count() const { return allocations.load(); }
};
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

TEST(NoAllocationObserver, CounterSeesAllocations) {
  // The replacement is active: a heap allocation inside the window is counted.
  CountingWindow w;
  int* p = new int(3);
  const long n = w.count();
  delete p;
  EXPECT_GE(n, 1);
}

TEST(NoAllocationObserver, StepAndResetOverEveryBranch) {
  // 1e5 steps per scheme: sliding, stick, slip onset, NaN/Inf, no contact, negative f_n,
  // sensor fault, dt gaps, zero wrench, RK4 divergence guard, and reset().
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  for (Integrator scheme : {Integrator::Rosenbrock, Integrator::Implicit, Integrator::Rk4, Integrator::Rk4Adaptive}) {
    ObserverSettings st;
    st.integrator = scheme;
    st.max_invalid = 5;
    if (scheme == Integrator::Rk4) st.gain_mode = GainMode::Fixed;
    Observer obs(table1_params(), st);
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    ObserverOutput out;
    long statuses[7] = {0, 0, 0, 0, 0, 0, 0};
    long diverged = 0;
    CountingWindow w;
    for (int i = 0; i < 100000; ++i) {
      const int phase = (i / 500) % 10;
      ObserverInput in{phase < 5 ? 0.2 + 5.0 * u(rng) : 2.0, 0.2 * u(rng), (phase == 3 ? 5e-2 : 2e-4) * (u(rng) - 0.3), 0.002};
      switch (i % 97) {
        case 5: in.f_n = nan; break;
        case 17: in.tau = inf; break;
        case 29: in.f_n = 0.0; break;
        case 41: in.f_n = -1.0; break;
        case 53: in.dt = 0.3; break;
        case 61: in.f_t = 0.0; in.tau = 0.0; break;
        case 71: in.dt = -1.0; break;
        case 83:
          for (int k = 0; k < 6; ++k) {
            obs.step(ObserverInput{nan, nan, nan, nan}, out);
            ++statuses[static_cast<int>(out.status)];
          }
          break;
        default: break;
      }
      if (i % 9973 == 0) obs.reset();
      obs.step(in, out);
      ++statuses[static_cast<int>(out.status)];
      diverged += out.diverged;
    }
    EXPECT_EQ(w.count(), 0) << to_string(scheme);
    for (Status s : {Status::Ok, Status::NoContact, Status::InvalidSample, Status::SensorFault, Status::Reinitialized})
      EXPECT_GT(statuses[static_cast<int>(s)], 0) << to_string(scheme) << " never hit " << to_string(s);
    if (scheme == Integrator::Rk4) EXPECT_GT(diverged, 0);  // the guard branch ran too
  }
}

TEST(NoAllocationObserver, SliderModelStep) {
  SliderModel sim(table1_params(), 1e-4);
  SliderOutput out;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CountingWindow w;
  for (int i = 0; i < 20000; ++i) {
    const double load = (i % 1000) * 3e-3;
    sim.step(SliderInput{i % 101 == 0 ? nan : 2.0, 0.5, load * 1e-3, 0.002}, out);
    if (i % 5000 == 0) sim.reset();
  }
  EXPECT_EQ(w.count(), 0);
}
