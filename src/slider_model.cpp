#include "lugrip/slider_model.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <stdexcept>
#include <string>

#include "lugrip/detail/rotor_steps.hpp"

#include "field_checks.hpp"

namespace lugrip {

const char* to_string(Integrator i) noexcept {
  const int k = static_cast<int>(i);
  return k >= 0 && k < static_cast<int>(std::size(kIntegratorNames)) ? kIntegratorNames[k] : "unknown";
}

// The integrators themselves: lugrip/detail/rotor_steps.hpp (shared with the identification's
// forward sensitivities), instantiated here for double.
void rotor_step_implicit(double& z, double& omega, double h, const RotorCoefficients& c) noexcept {
  detail::rotor_implicit(z, omega, h, c);
}

void rotor_step_rk4(double& z, double& omega, double h, const RotorCoefficients& c) noexcept {
  detail::rotor_rk4(z, omega, h, c);
}

void rotor_step_rosenbrock(double& z, double& omega, double h, const RotorCoefficients& c) noexcept {
  detail::rotor_rosenbrock(z, omega, h, c);
}

double rotor_stiffness(double omega, const RotorCoefficients& c) noexcept {
  return std::max(c.gain * (c.sigma_z + c.sigma_1), c.sigma0 * std::fabs(omega) / c.g);
}

namespace {
// rosenbrock_rate(), inline in rotor_advance's adaptive rule (two calls per sample)
inline double rosenbrock_rate_inline(double z, double omega, double h, const RotorCoefficients& c) noexcept {
  const double a = c.sigma0 * std::fabs(omega) / c.g;  // bristle rate -d zdot / dz
  // The omega mode: decoupled at the rate gain sigma_1 once z saturates, weighted by the share
  // min(1, h a) of the step in that regime; scaled so that h_sub gain sigma_1 <= kRosenbrockOmegaStep.
  const double r_omega =
      (kRosenbrockRate / kRosenbrockOmegaStep) * c.gain * c.sigma_1 * std::min(1.0, h * a);
  if (h * a >= kRosenbrockStiff) return r_omega;  // z transient over within 1/50 of h
  const double sgn = omega > 0.0 ? 1.0 : (omega < 0.0 ? -1.0 : 0.0);
  // Distance of z from its sliding steady state sgn g / sigma0, in units of g / sigma0 (0..2).
  const double b = std::min(2.0, std::max(0.0, 1.0 - c.sigma0 * z * sgn / c.g));
  return std::max(a * b, r_omega);
}
}  // namespace

double rosenbrock_rate(double z, double omega, double h, const RotorCoefficients& c) noexcept {
  return rosenbrock_rate_inline(z, omega, h, c);
}

namespace {
// Substeps that keep h_sub * rate <= target; the sample is redone with more substeps when the
// largest rate seen during it violates h_sub * rate <= limit (the rate grows at slip onset).
template <class Step, class Rate, class StartRate, class OnN>
int adaptive(double& z, double& omega, double h, const RotorCoefficients& c, int n_min, int max_substeps,
             double target, double limit, Step step, Rate rate, StartRate start_rate, OnN on_n, bool& projected,
             bool& cap_hit) noexcept {
  const double z0 = z, w0 = omega;
  // A rate that puts h r / target on a whole number (the omega mode at the bandwidth gain: h B
  // = 6) must not flip between n and n + 1 with the rounding of h or of the parameters (a time
  // stamp near 8 s carries 1e-12 relative error in its difference): the identification's
  // derivative holds each sample's substep count fixed, and equal data must give equal counts.
  auto needed = [&](double r) {
    const double m = std::ceil(h * r / target * (1.0 - 1e-9));
    return m < static_cast<double>(max_substeps) ? std::max(n_min, static_cast<int>(m)) : max_substeps;
  };
  int n = needed(start_rate(z, omega));
  for (int attempt = 0; attempt < 8; ++attempt) {
    z = z0;
    omega = w0;
    on_n(n);
    double r_max = 0.0;
    detail::rotor_substeps(z, omega, h, n, c, step, rate, projected, r_max);
    const double hs = h / n;
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
  bool projected = detail::rotor_project(z, c);
  bool cap_hit = false;
  int n = n_min;
  if (scheme == Integrator::Rk4Adaptive) {
    // docs/model.md 7.4: n = ceil(h Lambda / 2), re-checked against the RK4 stability limit.
    const auto stiffness = [&](double, double w) { return rotor_stiffness(w, c); };
    n = adaptive(z, omega, h, c, n_min, max_substeps, 2.0, kRk4StabilityLimit, detail::RotorRk4(), stiffness,
                 stiffness, [](int) {}, projected, cap_hit);
  } else if (scheme == Integrator::Rosenbrock) {
    // L-stable: no substeps for stability; the bristle transient and, while sliding, the omega
    // mode are resolved where one step would not (rosenbrock_rate). A substep whose stage or end
    // omega has another sign than at its start crossed the kink of |omega|, where the
    // linearisation does not hold: it is rated at the full reversal rate 2 sigma0 |omega|max / g
    // (or the omega mode's, if larger), which refines it.
    struct Probe {
      double w_start = 0.0, w_stage = 0.0;
    } probe;
    const auto step = [&probe](double& zz, double& w, double hs, const RotorCoefficients& cc) {
      probe.w_start = w;
      detail::rotor_rosenbrock(zz, w, hs, cc, &probe.w_stage);
    };
    const auto sign = [](double x) { return x > 0.0 ? 1.0 : (x < 0.0 ? -1.0 : 0.0); };
    double hs_now = h / n;
    const auto rate = [&](double zz, double w) {
      const double s0 = sign(probe.w_start);
      if (sign(probe.w_stage) != s0 || sign(w) != s0) {
        const double wm = std::max(std::fabs(probe.w_start), std::max(std::fabs(probe.w_stage), std::fabs(w)));
        return std::max(2.0 * c.sigma0 * wm / c.g, rosenbrock_rate_inline(zz, w, hs_now, c));
      }
      return rosenbrock_rate_inline(zz, w, hs_now, c);
    };
    n = adaptive(z, omega, h, c, n_min, max_substeps, kRosenbrockRate, 2.0 * kRosenbrockRate, step, rate,
                 [&](double zz, double w) { return rosenbrock_rate_inline(zz, w, h, c); },
                 [&](int m) { hs_now = h / m; }, projected, cap_hit);
  } else {
    detail::rotor_fixed_pass(z, omega, h, n, c, scheme, projected);
  }
  if (substeps) *substeps = n;
  if (capped) *capped = cap_hit;
  return projected;
}

bool validate(const SliderSettings& s, std::string* message) { return detail::validate_fields(s, message); }

std::string to_string(const SliderSettings& s) { return detail::print_fields(s); }

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
