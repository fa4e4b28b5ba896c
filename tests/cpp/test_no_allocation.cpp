// The real-time path never allocates: global operator new/delete are replaced by counting
// versions, and the count is taken only around the calls under test.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <limits>
#include <new>
#include <random>
#include <vector>

#include "lugrip/contact.hpp"
#include "lugrip/limit_surface.hpp"
#include "lugrip/params.hpp"
#include "lugrip/status.hpp"

namespace {
std::atomic<bool> g_counting{false};
std::atomic<long> g_allocs{0};
std::atomic<long> g_frees{0};

void* counted_alloc(std::size_t n, std::size_t align = 0) noexcept {
  if (g_counting.load(std::memory_order_relaxed)) g_allocs.fetch_add(1, std::memory_order_relaxed);
  if (n == 0) n = 1;
  if (align > alignof(std::max_align_t)) {
    const std::size_t rounded = (n + align - 1) / align * align;
    return std::aligned_alloc(align, rounded);
  }
  return std::malloc(n);
}
void counted_free(void* p) noexcept {
  if (p && g_counting.load(std::memory_order_relaxed)) g_frees.fetch_add(1, std::memory_order_relaxed);
  std::free(p);
}
void* checked(void* p) {
  if (!p) throw std::bad_alloc();
  return p;
}

// Counts allocations and frees between construction and stop().
class AllocationWindow {
 public:
  AllocationWindow() {
    g_allocs = 0;
    g_frees = 0;
    g_counting = true;
  }
  ~AllocationWindow() { g_counting = false; }
  void stop() { g_counting = false; }
  long allocs() const { return g_allocs.load(); }
  long frees() const { return g_frees.load(); }
};
}  // namespace

void* operator new(std::size_t n) { return checked(counted_alloc(n)); }
void* operator new[](std::size_t n) { return checked(counted_alloc(n)); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept { return counted_alloc(n); }
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept { return counted_alloc(n); }
void* operator new(std::size_t n, std::align_val_t a) { return checked(counted_alloc(n, static_cast<std::size_t>(a))); }
void* operator new[](std::size_t n, std::align_val_t a) { return checked(counted_alloc(n, static_cast<std::size_t>(a))); }
void* operator new(std::size_t n, std::align_val_t a, const std::nothrow_t&) noexcept {
  return counted_alloc(n, static_cast<std::size_t>(a));
}
void* operator new[](std::size_t n, std::align_val_t a, const std::nothrow_t&) noexcept {
  return counted_alloc(n, static_cast<std::size_t>(a));
}
void operator delete(void* p) noexcept { counted_free(p); }
void operator delete[](void* p) noexcept { counted_free(p); }
void operator delete(void* p, std::size_t) noexcept { counted_free(p); }
void operator delete[](void* p, std::size_t) noexcept { counted_free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { counted_free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { counted_free(p); }
void operator delete(void* p, std::align_val_t) noexcept { counted_free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { counted_free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { counted_free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { counted_free(p); }

namespace {

using namespace lugrip;

// Called through a volatile pointer so the compiler cannot elide the allocation.
void* (*volatile g_raw_new)(std::size_t) = &::operator new;
void (*volatile g_raw_delete)(void*) noexcept = &::operator delete;

struct Sample {
  double f_n, f_t, tau;
};

std::vector<Sample> make_samples(const ContactModel& m, int n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  std::vector<Sample> out;
  out.reserve(n);
  for (int i = 0; i < n; ++i) {
    const double f_n = std::pow(10.0, -1.0 + 2.5 * u(rng));
    Sample s{f_n, (u(rng) < 0.5 ? -1 : 1) * m.ft_max(f_n) * 2.0 * u(rng),
             (u(rng) < 0.5 ? -1 : 1) * m.tau_max(f_n) * 2.0 * u(rng)};
    switch (i % 10) {
      case 0: s.f_n = nan; break;                  // invalid
      case 1: s.tau = inf; break;                  // invalid
      case 2: s.f_n = 0.001 * u(rng); break;       // no contact
      case 3: s.f_t = 0.0, s.tau = 0.0; break;     // degenerate
      case 4: s.tau = 0.0; break;                  // pure translation (saturated)
      case 5: s.f_t = 1e300; break;                // out of range
      default: break;                              // inside or outside the LS
    }
    out.push_back(s);
  }
  return out;
}

}  // namespace

TEST(NoAllocation, CounterSeesAllocations) {
  // The harness itself works: a real allocation inside the window is counted.
  AllocationWindow w;
  void* p = g_raw_new(64);
  g_raw_delete(p);
  std::vector<double>* v = new std::vector<double>(100);
  delete v;
  w.stop();
  EXPECT_GE(w.allocs(), 3);
  EXPECT_GE(w.frees(), 3);
}

TEST(NoAllocation, CorEstimatorStep) {
  const ContactParams p = table1_params();
  CorEstimator est(p);  // allocates (tables), outside the window
  const std::vector<Sample> samples = make_samples(est.model(), 100000, 42);
  CorOutput out;
  long statuses[8] = {0};
  double checksum = 0.0;
  {
    AllocationWindow w;
    for (const Sample& s : samples) {
      const Status st = est.step(CorInput{s.f_n, s.f_t, s.tau}, out);
      ++statuses[static_cast<int>(st)];
      checksum += out.c_tilde + out.g;
    }
    est.reset();
    est.step(CorInput{1.0, 0.1, 1e-4}, out);
    (void)to_string(out.status);
    w.stop();
    EXPECT_EQ(w.allocs(), 0) << "operator new called inside CorEstimator::step";
    EXPECT_EQ(w.frees(), 0);
  }
  EXPECT_TRUE(std::isfinite(checksum));
  // The samples reached every branch: ok, saturated, degenerate, no contact, invalid.
  EXPECT_GT(statuses[static_cast<int>(Status::Ok)], 10000);
  EXPECT_GT(statuses[static_cast<int>(Status::Saturated)], 1000);
  EXPECT_GT(statuses[static_cast<int>(Status::Degenerate)], 1000);
  EXPECT_GT(statuses[static_cast<int>(Status::NoContact)], 1000);
  EXPECT_GT(statuses[static_cast<int>(Status::InvalidSample)], 1000);
}

TEST(NoAllocation, ModelAndLimitSurfaceQueries) {
  const ContactParams p = object_params("plastic_bottle");
  const ContactModel m(p);
  const LimitSurface& ls = m.limit_surface();
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double> a(20000);
  for (double& x : a) x = std::pow(10.0, -4.0 + 8.0 * u(rng));
  double sum = 0.0;
  int it = 0;
  {
    AllocationWindow w;
    for (double x : a) {
      const LsPoint q = ls.eval(x);
      sum += q.F + q.T + q.dF + q.dT + ls.G(x) + ls.ft_star(-x) + ls.tau_star(x) + ls.dft_star(x) +
             ls.dtau_star(x) + ls.sigma_ls(x, p.gamma);
      sum += m.invert_sigma(x, &it) + m.solve_outside(1.0 + x, 0.5 + x, &it);
      sum += m.rho(x) + m.ft_max(x) + m.tau_max(x) + m.viscous_ratio(x) + m.sigma_1(x, 0.3) + m.g(x, 1.2);
      double f_t, tau;
      m.wrench_at(2.0, std::fmin(x, 1.4), (u(rng) - 0.5) * 0.05, f_t, tau);
      sum += f_t + tau;
    }
    w.stop();
    EXPECT_EQ(w.allocs(), 0);
    EXPECT_EQ(w.frees(), 0);
  }
  EXPECT_TRUE(std::isfinite(sum));
}

TEST(NoAllocation, EstimatorFromSharedModel) {
  const ContactModel m(table1_params());
  CorEstimator est(m);  // copies the tables: allowed, before the window
  const std::vector<Sample> samples = make_samples(m, 20000, 9);
  CorOutput out;
  AllocationWindow w;
  for (const Sample& s : samples) est.step(CorInput{s.f_n, s.f_t, s.tau}, out);
  w.stop();
  EXPECT_EQ(w.allocs(), 0);
}
