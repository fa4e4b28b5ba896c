// lugrip — the one implementation of the rotor integrators (docs/model.md 7.1 and 7.4), templated on
// the scalar type. Instantiated with double by slider_model.cpp (rotor_step_*, rotor_advance: the
// plant, the observer) and with the forward-mode dual numbers of identification.cpp, whose value
// part repeats the double arithmetic operation for operation, so the identification's tangent
// replica reproduces the online observer's values bit for bit while it propagates the parameter
// derivatives. Not part of the public API (the public entry points are in slider_model.hpp).
//
// Requirements on a scalar type T other than double: default-constructible, copyable; +, -, *, /
// with T and double (either side), unary -, -=, +=; T(double); and, by argument-dependent lookup,
//   double scalar_value(const T&)  (the value; comparisons and branches use it),
//   T scalar_fabs(const T&), T scalar_expm1(const T&).
// A coefficient type C has the members sigma0, sigma_z, sigma_1, g, gain, drive of type T (for
// T = double: RotorCoefficients). h is always a double: the step length has no derivative.
// No allocation, no exceptions, no I/O.
#pragma once

#include <algorithm>
#include <cmath>

#include "lugrip/slider_model.hpp"

namespace lugrip {
namespace detail {

inline double scalar_fabs(double x) noexcept { return std::fabs(x); }
inline double scalar_expm1(double x) noexcept { return std::expm1(x); }

//! Right-hand side of eqs. 1-2 (see RotorCoefficients) at (z, w).
template <class T, class C>
inline void rotor_rhs(const T& z, const T& w, const C& c, T& dz, T& dw) noexcept {
  dz = rotor_zdot(z, w, c.sigma0, c.g);
  dw = c.gain * (c.drive - c.sigma0 * z - c.sigma_z * dz - c.sigma_1 * w);
}

//! Projection |z| <= g / sigma0 (docs/model.md 7.1); returns whether it was active.
template <class T, class C>
inline bool rotor_project(T& z, const C& c) noexcept {
  const T bound = c.g / c.sigma0;
  if (scalar_value(z) > scalar_value(bound)) {
    z = bound;
    return true;
  }
  if (scalar_value(z) < -scalar_value(bound)) {
    z = -bound;
    return true;
  }
  return false;
}

//! Integrator::Implicit, one step of length h.
template <class T, class C>
inline void rotor_implicit(T& z, T& omega, double h, const C& c) noexcept {
  // z: exact solution of zdot = omega_{n+1} - a z for the decay a frozen at |omega_n|;
  // omega: backward Euler with the average zdot of the step, linear in omega_{n+1}.
  const T ah = c.sigma0 / c.g * scalar_fabs(omega) * h;
  const T one_minus_e = -scalar_expm1(-ah);                           // 1 - E
  const T phi = scalar_value(ah) > 1e-12 ? one_minus_e / ah : T(1.0);  // (1 - E)/(a h) -> 1
  const T e = 1.0 - one_minus_e;
  const T hk = h * c.gain;
  const T rhs = omega + hk * (c.drive - c.sigma0 * e * z) + c.gain * c.sigma_z * one_minus_e * z;
  const T den = 1.0 + hk * (c.sigma_1 + phi * (c.sigma_z + c.sigma0 * h));
  const T w1 = rhs / den;
  z = e * z + h * phi * w1;
  omega = w1;
}

//! Classical RK4, one step of length h.
template <class T, class C>
inline void rotor_rk4(T& z, T& omega, double h, const C& c) noexcept {
  T k1z, k1w, k2z, k2w, k3z, k3w, k4z, k4w;
  rotor_rhs(z, omega, c, k1z, k1w);
  rotor_rhs(z + 0.5 * h * k1z, omega + 0.5 * h * k1w, c, k2z, k2w);
  rotor_rhs(z + 0.5 * h * k2z, omega + 0.5 * h * k2w, c, k3z, k3w);
  rotor_rhs(z + h * k3z, omega + h * k3w, c, k4z, k4w);
  z += h / 6.0 * (k1z + 2.0 * k2z + 2.0 * k3z + k4z);
  omega += h / 6.0 * (k1w + 2.0 * k2w + 2.0 * k3w + k4w);
}

//! Integrator::Rosenbrock, one ROS2 step of length h; *stage_omega (when given) receives the
//! omega of the second stage's evaluation point (the adaptive rule checks its sign).
template <class T, class C>
inline void rotor_rosenbrock(T& z, T& omega, double h, const C& c, double* stage_omega = nullptr) noexcept {
  // ROS2 (Verwer et al. 1999): (I - gamma h J) k1 = f(x); (I - gamma h J) k2 = f(x + h k1) - 2 k1;
  // x += h (3 k1 + k2) / 2. J is exact (sign(0) = 0); det(I - gamma h J) >= 1 for |z| <= g/sigma0.
  constexpr double gam = 1.7071067811865475244;
  const double sgn = scalar_value(omega) > 0.0 ? 1.0 : (scalar_value(omega) < 0.0 ? -1.0 : 0.0);
  const T a = c.sigma0 * scalar_fabs(omega) / c.g;  // -d zdot / dz
  const T b = 1.0 - c.sigma0 * z * sgn / c.g;       // d zdot / d omega
  const double gh = gam * h;
  const T m11 = 1.0 + gh * a, m12 = -gh * b;
  const T m21 = gh * c.gain * (c.sigma0 - c.sigma_z * a), m22 = 1.0 + gh * c.gain * (c.sigma_1 + c.sigma_z * b);
  const T inv_det = 1.0 / (m11 * m22 - m12 * m21);
  T f1z, f1w;
  rotor_rhs(z, omega, c, f1z, f1w);
  const T k1z = (m22 * f1z - m12 * f1w) * inv_det;
  const T k1w = (m11 * f1w - m21 * f1z) * inv_det;
  T f2z, f2w;
  const T w_stage = omega + h * k1w;
  if (stage_omega) *stage_omega = scalar_value(w_stage);
  rotor_rhs(z + h * k1z, w_stage, c, f2z, f2w);
  f2z -= 2.0 * k1z;
  f2w -= 2.0 * k1w;
  const T k2z = (m22 * f2z - m12 * f2w) * inv_det;
  const T k2w = (m11 * f2w - m21 * f2z) * inv_det;
  z += h * (1.5 * k1z + 0.5 * k2z);
  omega += h * (1.5 * k1w + 0.5 * k2w);
}

//! The step functions as function objects (template arguments of rotor_substeps).
struct RotorImplicit {
  template <class T, class C>
  void operator()(T& z, T& omega, double h, const C& c) const noexcept { rotor_implicit(z, omega, h, c); }
};
struct RotorRk4 {
  template <class T, class C>
  void operator()(T& z, T& omega, double h, const C& c) const noexcept { rotor_rk4(z, omega, h, c); }
};
struct RotorRosenbrock {
  template <class T, class C>
  void operator()(T& z, T& omega, double h, const C& c) const noexcept { rotor_rosenbrock(z, omega, h, c); }
};
//! Rate that is never tracked (the fixed-substep passes).
struct NoRate {
  template <class T>
  double operator()(const T&, const T&) const noexcept { return 0.0; }
};

//! n equal substeps of h / n with `step`, each followed by the projection, whose activity is
//! written to `projected` (untouched when n < 1); after each, r_max = max(r_max, rate(z, omega)).
template <class T, class C, class Step, class Rate>
inline void rotor_substeps(T& z, T& omega, double h, int n, const C& c, Step step, Rate rate, bool& projected,
                           double& r_max) noexcept {
  const double hs = h / n;
  for (int i = 0; i < n; ++i) {
    step(z, omega, hs, c);
    projected = rotor_project(z, c);
    r_max = std::max(r_max, rate(z, omega));
  }
}

//! rotor_substeps with the step of `scheme` (Rk4Adaptive: RK4; any value that is not Rk4,
//! Rk4Adaptive or Rosenbrock: Implicit). This is the whole sample for Implicit and Rk4, and the
//! final pass of the adaptive schemes once their n is known.
template <class T, class C>
inline void rotor_fixed_pass(T& z, T& omega, double h, int n, const C& c, Integrator scheme, bool& projected) noexcept {
  double unused = 0.0;
  if (scheme == Integrator::Rk4 || scheme == Integrator::Rk4Adaptive)
    rotor_substeps(z, omega, h, n, c, RotorRk4(), NoRate(), projected, unused);
  else if (scheme == Integrator::Rosenbrock)
    rotor_substeps(z, omega, h, n, c, RotorRosenbrock(), NoRate(), projected, unused);
  else
    rotor_substeps(z, omega, h, n, c, RotorImplicit(), NoRate(), projected, unused);
}

}  // namespace detail
}  // namespace lugrip
