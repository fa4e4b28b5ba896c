#include "lugrip/slider_model.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace lugrip {

const char* to_string(Integrator i) noexcept {
  switch (i) {
    case Integrator::Implicit: return "implicit";
    case Integrator::Rk4: return "rk4";
    case Integrator::Rk4Adaptive: return "rk4_adaptive";
    case Integrator::Rosenbrock: return "rosenbrock";
  }
  return "unknown";
}

void rotor_step_implicit(double& z, double& omega, double h, const RotorCoefficients& c) noexcept {
  // z: exact solution of zdot = omega_{n+1} - a z for the decay a frozen at |omega_n|;
  // omega: backward Euler with the average zdot of the step, linear in omega_{n+1}.
  const double ah = c.sigma0 / c.g * std::fabs(omega) * h;
  const double one_minus_e = -std::expm1(-ah);            // 1 - E
  const double phi = ah > 1e-12 ? one_minus_e / ah : 1.0;  // (1 - E)/(a h) -> 1
  const double e = 1.0 - one_minus_e;
  const double hk = h * c.gain;
  const double rhs = omega + hk * (c.drive - c.sigma0 * e * z) + c.gain * c.sigma_z * one_minus_e * z;
  const double den = 1.0 + hk * (c.sigma_1 + phi * (c.sigma_z + c.sigma0 * h));
  const double w1 = rhs / den;
  z = e * z + h * phi * w1;
  omega = w1;
}

namespace {
inline void rotor_rhs(double z, double w, const RotorCoefficients& c, double& dz, double& dw) noexcept {
  dz = lugre_zdot(z, w, c.sigma0, c.g);
  dw = c.gain * (c.drive - c.sigma0 * z - c.sigma_z * dz - c.sigma_1 * w);
}

inline bool project(double& z, const RotorCoefficients& c) noexcept {
  const double bound = c.g / c.sigma0;
  if (z > bound) { z = bound; return true; }
  if (z < -bound) { z = -bound; return true; }
  return false;
}
}  // namespace

void rotor_step_rk4(double& z, double& omega, double h, const RotorCoefficients& c) noexcept {
  double k1z, k1w, k2z, k2w, k3z, k3w, k4z, k4w;
  rotor_rhs(z, omega, c, k1z, k1w);
  rotor_rhs(z + 0.5 * h * k1z, omega + 0.5 * h * k1w, c, k2z, k2w);
  rotor_rhs(z + 0.5 * h * k2z, omega + 0.5 * h * k2w, c, k3z, k3w);
  rotor_rhs(z + h * k3z, omega + h * k3w, c, k4z, k4w);
  z += h / 6.0 * (k1z + 2.0 * k2z + 2.0 * k3z + k4z);
  omega += h / 6.0 * (k1w + 2.0 * k2w + 2.0 * k3w + k4w);
}

void rotor_step_rosenbrock(double& z, double& omega, double h, const RotorCoefficients& c) noexcept {
  // ROS2 (Verwer et al. 1999): (I - gamma h J) k1 = f(x); (I - gamma h J) k2 = f(x + h k1) - 2 k1;
  // x += h (3 k1 + k2) / 2. J is exact (sign(0) = 0); det(I - gamma h J) >= 1 for |z| <= g/sigma0.
  constexpr double gam = 1.7071067811865475244;
  const double sgn = omega > 0.0 ? 1.0 : (omega < 0.0 ? -1.0 : 0.0);
  const double a = c.sigma0 * std::fabs(omega) / c.g;   // -d zdot / dz
  const double b = 1.0 - c.sigma0 * z * sgn / c.g;      // d zdot / d omega
  const double gh = gam * h;
  const double m11 = 1.0 + gh * a, m12 = -gh * b;
  const double m21 = gh * c.gain * (c.sigma0 - c.sigma_z * a), m22 = 1.0 + gh * c.gain * (c.sigma_1 + c.sigma_z * b);
  const double inv_det = 1.0 / (m11 * m22 - m12 * m21);
  double f1z, f1w;
  rotor_rhs(z, omega, c, f1z, f1w);
  const double k1z = (m22 * f1z - m12 * f1w) * inv_det;
  const double k1w = (m11 * f1w - m21 * f1z) * inv_det;
  double f2z, f2w;
  rotor_rhs(z + h * k1z, omega + h * k1w, c, f2z, f2w);
  f2z -= 2.0 * k1z;
  f2w -= 2.0 * k1w;
  const double k2z = (m22 * f2z - m12 * f2w) * inv_det;
  const double k2w = (m11 * f2w - m21 * f2z) * inv_det;
  z += h * (1.5 * k1z + 0.5 * k2z);
  omega += h * (1.5 * k1w + 0.5 * k2w);
}

double rotor_stiffness(double omega, const RotorCoefficients& c) noexcept {
  return std::max(c.gain * (c.sigma_z + c.sigma_1), c.sigma0 * std::fabs(omega) / c.g);
}

namespace {
// Substeps that keep h_sub * rate <= target; the sample is redone with more substeps when the
// largest rate seen during it violates h_sub * rate <= limit (the rate grows at slip onset).
template <class Step, class Rate>
int adaptive(double& z, double& omega, double h, const RotorCoefficients& c, int n_min, int max_substeps,
             double target, double limit, Step&& step, Rate&& rate, bool& projected, bool& cap_hit) noexcept {
  const double z0 = z, w0 = omega;
  auto needed = [&](double r) {
    const double m = std::ceil(h * r / target);
    return m < static_cast<double>(max_substeps) ? std::max(n_min, static_cast<int>(m)) : max_substeps;
  };
  int n = needed(rate(omega));
  for (int attempt = 0; attempt < 8; ++attempt) {
    z = z0;
    omega = w0;
    const double hs = h / n;
    double r_max = 0.0;
    for (int i = 0; i < n; ++i) {
      step(z, omega, hs, c);
      projected = project(z, c);
      r_max = std::max(r_max, rate(omega));
    }
    if (hs * r_max <= limit || !(r_max == r_max)) break;
    if (n >= max_substeps) { cap_hit = true; break; }
    n = std::max(n + 1, needed(r_max));
  }
  return n;
}
}  // namespace

bool rotor_advance(double& z, double& omega, double h, const RotorCoefficients& c, Integrator scheme,
                   int n_min, int max_substeps, int* substeps, bool* capped) noexcept {
  n_min = std::max(1, std::min(n_min, max_substeps));
  bool projected = project(z, c);
  bool cap_hit = false;
  int n = n_min;
  if (scheme == Integrator::Rk4Adaptive) {
    // MODEL.md 7.4: n = ceil(h Lambda / 2), re-checked against the RK4 stability limit.
    n = adaptive(z, omega, h, c, n_min, max_substeps, 2.0, kRk4StabilityLimit, rotor_step_rk4,
                 [&](double w) { return rotor_stiffness(w, c); }, projected, cap_hit);
  } else if (scheme == Integrator::Rosenbrock) {
    // L-stable: the linear modes need no substeps; the nonlinear bristle rate a = sigma0 |w| / g
    // (the Jacobian changes within the step) is resolved for accuracy.
    n = adaptive(z, omega, h, c, n_min, max_substeps, kRosenbrockRate, 2.0 * kRosenbrockRate,
                 rotor_step_rosenbrock, [&](double w) { return c.sigma0 * std::fabs(w) / c.g; },
                 projected, cap_hit);
  } else {
    const double hs = h / n;
    for (int i = 0; i < n; ++i) {
      if (scheme == Integrator::Rk4) rotor_step_rk4(z, omega, hs, c);
      else rotor_step_implicit(z, omega, hs, c);
      projected = project(z, c);
    }
  }
  if (substeps) *substeps = n;
  if (capped) *capped = cap_hit;
  return projected;
}

bool validate(const SliderSettings& s, std::string* message) {
  std::string msg;
  if (!(s.integrator == Integrator::Implicit || s.integrator == Integrator::Rk4 ||
        s.integrator == Integrator::Rk4Adaptive || s.integrator == Integrator::Rosenbrock))
    msg += "integrator = " + std::to_string(static_cast<int>(s.integrator)) + ": unknown scheme\n";
  if (!(std::isfinite(s.max_substep) && s.max_substep > 0.0))
    msg += "max_substep = " + std::to_string(s.max_substep) + ": must be finite and > 0 [s]\n";
  if (!(s.max_substeps >= 1))
    msg += "max_substeps = " + std::to_string(s.max_substeps) + ": must be >= 1\n";
  if (!(std::isfinite(s.g_floor) && s.g_floor > 0.0))
    msg += "g_floor = " + std::to_string(s.g_floor) + ": must be finite and > 0 [N m]\n";
  if (message) *message = msg;
  return msg.empty();
}

namespace {
const SliderSettings& checked(const SliderSettings& s) {
  std::string msg;
  if (!validate(s, &msg)) throw std::invalid_argument("invalid SliderSettings:\n" + msg);
  return s;
}
double checked_inertia(double J) {
  if (!(std::isfinite(J) && J > 0.0))
    throw std::invalid_argument("SliderModel: J = " + std::to_string(J) + ": must be finite and > 0 [kg m^2]");
  return J;
}
}  // namespace

SliderModel::SliderModel(const ContactParams& params, double J, const SliderSettings& settings)
    : model_(params), s_(checked(settings)), J_(checked_inertia(J)) {}

SliderModel::SliderModel(const ContactModel& model, double J, const SliderSettings& settings)
    : model_(model), s_(checked(settings)), J_(checked_inertia(J)) {}

void SliderModel::reset(double z, double omega) noexcept {
  z_ = std::isfinite(z) ? z : 0.0;
  omega_ = std::isfinite(omega) ? omega : 0.0;
  last_ = SliderOutput();
}

Status SliderModel::step(const SliderInput& in, SliderOutput& out) noexcept {
  const bool ok = std::isfinite(in.f_n) && in.f_n > 0.0 && std::isfinite(in.c_tilde) &&
                  std::isfinite(in.tau_e) && std::isfinite(in.dt) && in.dt > 0.0;
  if (!ok) {
    out = last_;
    out.substeps = 0;
    return out.status = Status::InvalidSample;
  }
  const ContactParams& p = model_.params();
  RotorCoefficients c;
  c.sigma0 = p.sigma0;
  c.sigma_z = p.sigma_z;
  c.sigma_1 = model_.sigma_1(in.f_n, in.c_tilde);
  c.g = std::max(model_.g(in.f_n, in.c_tilde), s_.g_floor);
  c.gain = 1.0 / J_;
  c.drive = in.tau_e;
  const double m = std::ceil(in.dt / s_.max_substep);
  const int n_fixed = m < static_cast<double>(s_.max_substeps) ? std::max(1, static_cast<int>(m)) : s_.max_substeps;
  double z = z_, w = omega_;
  int used = 0;
  const bool projected = rotor_advance(z, w, in.dt, c, s_.integrator, n_fixed, s_.max_substeps, &used, nullptr);
  if (!(std::isfinite(z) && std::isfinite(w))) {  // only reachable with an unstable Rk4 choice
    out = last_;
    out.substeps = used;
    return out.status = Status::InvalidSample;
  }
  z_ = z;
  omega_ = w;
  SliderOutput r;
  r.z = z;
  r.omega = w;
  r.zdot = lugre_zdot(z, w, c.sigma0, c.g);
  r.g = c.g;
  r.sigma_1 = c.sigma_1;
  r.dry_torque = c.sigma0 * z + c.sigma_z * r.zdot;
  r.friction_torque = r.dry_torque + c.sigma_1 * w;
  r.slip = c.sigma0 * std::fabs(z) / c.g;
  r.substeps = used;
  r.projected = projected;
  r.status = Status::Ok;
  last_ = r;
  out = r;
  return r.status;
}

}  // namespace lugrip
