// Shared helpers of the lugrip._core binding files: array types, validation messages and the
// per-object thread guard.
#pragma once

#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

#include <atomic>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>

namespace lugrip_bind {

namespace nb = nanobind;

using In1 = nb::ndarray<const double, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
template <class T>
using Out1 = nb::ndarray<nb::numpy, T, nb::ndim<1>>;

//! New 1-D numpy array of n elements owned by a capsule.
template <class T>
Out1<T> new_array(size_t n) {
  T* data = new T[n > 0 ? n : 1];
  nb::capsule owner(data, [](void* p) noexcept { delete[] static_cast<T*>(p); });
  return Out1<T>(data, {n}, owner);
}

inline void same_size(const In1& a, const In1& b) {
  if (a.shape(0) != b.shape(0)) throw std::invalid_argument("arrays must have the same length");
}

//! Applies fn elementwise over one array (GIL released).
template <class Fn>
Out1<double> map1(const In1& x, Fn&& fn) {
  const size_t n = x.shape(0);
  auto out = new_array<double>(n);
  const double* px = x.data();
  double* po = out.data();
  {
    nb::gil_scoped_release release;
    for (size_t i = 0; i < n; ++i) po[i] = fn(px[i]);
  }
  return out;
}

template <class Fn>
Out1<double> map2(const In1& x, const In1& y, Fn&& fn) {
  same_size(x, y);
  const size_t n = x.shape(0);
  auto out = new_array<double>(n);
  const double *px = x.data(), *py = y.data();
  double* po = out.data();
  {
    nb::gil_scoped_release release;
    for (size_t i = 0; i < n; ++i) po[i] = fn(px[i], py[i]);
  }
  return out;
}

//! validate(x, &msg) as a function returning the message ("" when valid).
template <class T>
std::string validation_message(const T& x) {
  std::string msg;
  validate(x, &msg);
  return msg;
}

//! The first thread that uses a stateful object owns it; any other thread gets RuntimeError.
//! The C++ objects are not thread-safe and the batch calls release the GIL, so without this a
//! second thread would interleave its samples with the first one's.
class ThreadGuard {
 public:
  ThreadGuard() = default;
  ThreadGuard(const ThreadGuard&) noexcept {}  // a copy starts without an owner
  ThreadGuard& operator=(const ThreadGuard&) noexcept { return *this; }

  void check(const char* type) {
    const std::thread::id me = std::this_thread::get_id();
    std::thread::id current = owner_.load(std::memory_order_acquire);
    if (current == me) return;
    if (current == std::thread::id() && owner_.compare_exchange_strong(current, me)) return;
    throw std::runtime_error(std::string(type) +
                             " belongs to the thread that first used it; create one object per thread");
  }

 private:
  std::atomic<std::thread::id> owner_{};
};

//! A core object with its thread guard; bound under the core type's name.
template <class T>
struct Guarded : T {
  template <class... A>
  explicit Guarded(A&&... a) : T(std::forward<A>(a)...) {}
  ThreadGuard guard;
};

}  // namespace lugrip_bind
