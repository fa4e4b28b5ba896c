#include "lugrip/contact.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "field_checks.hpp"
#include "format.hpp"
#include "lugrip/detail/fast_math.hpp"

namespace lugrip {

namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr int kInvHalf = 200;   // inverse table: a = 10^((j - 200)/50), j = 0..400
constexpr int kMaxIter = 60;
constexpr int kInvTable = ContactModel::kInverseIntervals;

// Safeguarded Newton for a root of fn bracketed by [lo, hi] (fn(lo), fn(hi) of opposite signs;
// `increasing` tells which side is which). A Newton step leaving the bracket is replaced by
// bisection, so it always converges; at most max_iter evaluations, counted in *iterations.
template <class Fn>
double bracketed_newton(Fn&& fn, double a, double lo, double hi, bool increasing, double x_rel,
                        double x_abs, double f_tol, int max_iter, int* iterations) {
  for (int it = 1; it <= max_iter; ++it) {
    if (iterations) *iterations = it;
    double d = 0.0;
    const double v = fn(a, d);
    if (std::fabs(v) <= f_tol) return a;
    if ((v > 0.0) == increasing) hi = a; else lo = a;
    const double tol = x_abs + x_rel * std::fabs(a);
    double next = a - v / d;
    if (next > lo && next < hi) {
      if (std::fabs(next - a) <= tol) return next;
    } else {
      next = 0.5 * (lo + hi);
    }
    if (hi - lo <= tol) return next;
    a = next;
  }
  return a;
}

const ContactParams& checked(const ContactParams& p) {
  validate_or_throw(p);
  return p;
}

// delta f_n^gamma, written out where the CoR estimate needs it (the compiler keeps the member
// function an out-of-line call there)
inline double contact_radius(const ContactParams& p, double f_n) noexcept {
  return p.delta * detail::fast_pow_pos(f_n, p.gamma);
}
}  // namespace

ContactModel::ContactModel(const ContactParams& params) : p_(checked(params)), ls_(params.k) {
  // Bracketed Newton inversion of log sigma_LS on a log-spaced grid of a (construction only),
  // then a uniform table of log a against log sigma with Hermite slopes for the run time.
  const int n = 2 * kInvHalf + 1;
  std::vector<double> grid_a(n), grid_s(n);
  const double gp1 = p_.gamma + 1.0;
  for (int j = 0; j < n; ++j) {
    const double a = std::pow(10.0, static_cast<double>(j - kInvHalf) / 50.0);
    const LsPoint q = ls_.eval(a);
    grid_a[j] = a;
    grid_s[j] = gp1 * std::log(q.F) - std::log(q.T);
    if (j > 0 && !(grid_s[j] > grid_s[j - 1]))
      throw std::logic_error("ContactModel: sigma_LS is not increasing at a = " + detail::format_number(a));
  }
  inv_s0_ = grid_s.front();
  inv_s1_ = grid_s.back();
  inv_.assign(3 * (kInvTable + 1), 0.0);
  const double hs = (inv_s1_ - inv_s0_) / kInvTable;
  for (int i = 0; i <= kInvTable; ++i) {
    const double target = i == kInvTable ? inv_s1_ : inv_s0_ + i * hs;
    const auto it = std::upper_bound(grid_s.begin(), grid_s.end(), target);
    const int j = std::min(std::max(static_cast<int>(it - grid_s.begin()) - 1, 0), n - 2);
    auto phi = [&](double a, double& d) {
      const LsPoint q = ls_.eval(a);
      d = gp1 * q.dF / q.F - q.dT / q.T;
      return gp1 * std::log(q.F) - std::log(q.T) - target;
    };
    const double lo = grid_a[j], hi = grid_a[j + 1];
    const double a = bracketed_newton(phi, std::sqrt(lo * hi), lo, hi, true, 1e-15, 0.0, 1e-15, 200, nullptr);
    const LsPoint q = ls_.eval(a);
    // d(log a)/d(log sigma) = 1 / (a dphi/da)
    const double slope = 1.0 / (a * (gp1 * q.dF / q.F - q.dT / q.T));
    inv_[3 * i] = std::log(a);
    inv_[3 * i + 1] = slope * hs;
    inv_[3 * i + 2] = a;
  }
}

bool ContactModel::set_mu(double mu) noexcept {
  if (!(std::isfinite(mu) && mu > 0.0 && mu <= 10.0)) return false;  // the range validate() accepts
  p_.mu = mu;
  return true;
}

double ContactModel::rho(double f_n) const noexcept { return contact_radius(p_, f_n); }
double ContactModel::ft_max(double f_n) const noexcept { return p_.mu * f_n; }
double ContactModel::tau_max(double f_n) const noexcept {
  return p_.mu * ls_.xi() * p_.delta * std::pow(f_n, p_.gamma + 1.0);
}
double ContactModel::viscous_ratio(double f_n) const noexcept {
  return kPi * p_.delta * p_.delta * p_.delta * p_.beta_a * std::pow(f_n, 3.0 * p_.gamma - 1.0) / p_.mu;
}
double ContactModel::sigma_1(double f_n, double c_tilde) const noexcept {
  const double r = rho(f_n), r2 = r * r;
  return kPi * p_.beta_a * r2 * r2 * (c_tilde * c_tilde + 0.5);
}
double ContactModel::g(double f_n, double c_tilde) const noexcept {
  return p_.mu * f_n * rho(f_n) * ls_.G(c_tilde);
}

double ContactModel::invert_sigma(double s, int* iterations) const noexcept {
  if (iterations) *iterations = 0;
  s = std::fabs(s);
  if (!(s > 0.0)) return std::isnan(s) ? s : 0.0;
  if (std::isinf(s)) return s;
  const double gp1 = p_.gamma + 1.0;
  const double target = detail::fast_log(s);
  if (target >= inv_s1_) return ls_.tail_torque() * s;  // sigma_LS ~ a / A_tau (a > 1e4)
  double lo, hi, a;
  if (target <= inv_s0_) {  // a < 1e-4: sigma_LS ~ (s_k a)^(gamma+1)
    lo = 0.0;
    hi = inv_[2];
    a = std::min(std::pow(s, 1.0 / gp1) / ls_.small_slope(), hi);
  } else {  // Hermite interpolation of log a in log sigma, bracketed by the two nodes
    const double x = (target - inv_s0_) / (inv_s1_ - inv_s0_) * kInvTable;
    int i = static_cast<int>(x);
    i = i >= kInvTable ? kInvTable - 1 : i;
    const double t = x - i, t2 = t * t, omt = 1.0 - t;
    const double h00 = (1.0 + 2.0 * t) * omt * omt, h10 = t * omt * omt, h11 = t2 * (t - 1.0);
    const double* r = &inv_[3 * i];
    const double la = h00 * r[0] + h10 * r[1] + (1.0 - h00) * r[3] + h11 * r[4];
    lo = r[2];
    hi = r[5];
    a = std::min(std::max(detail::fast_exp(la), lo), hi);
  }
  // The Hermite table alone is accurate to ~3e-10 relative except in the intervals around the
  // rim (a ~ 1), where the curves have a curvature feature (measured 2e-7): polish there, and
  // in the tails, by bracketed Newton.
  if (lo > 1.1 || hi < 0.9) {
    if (target > inv_s0_) return a;
  }
  auto phi = [&](double x, double& d) {
    const LsPoint q = ls_.eval(x);
    d = gp1 * q.dF / q.F - q.dT / q.T;
    return gp1 * std::log(q.F) - std::log(q.T) - target;
  };
  a = bracketed_newton(phi, a, lo, hi, true, 1e-9, 0.0, 1e-12, kMaxIter, iterations);
  return a;
}

double ContactModel::solve_outside(double f, double t, int* iterations, double guess,
                                   LsPoint* point) const noexcept {
  const double xi2 = 2.0 * ls_.xi();
  const double c_max = p_.c_max;
  LsPoint last;
  double last_a = -1.0;
  auto h = [&](double a, double& dh) {
    const LsPoint q = ls_.eval(a);
    last = q;
    last_a = a;
    dh = -q.dF - xi2 * (t - q.T) + xi2 * a * q.dT;
    return f - q.F - xi2 * a * (t - q.T);
  };
  double dummy;
  const double h_hi = h(c_max, dummy);
  if (h_hi > 0.0) {  // root beyond the clip
    if (iterations) *iterations = 1;
    if (point) *point = last;
    return c_max;
  }
  const double h_lo = f;  // h(0) = f >= 0
  double a = (guess > 0.0 && guess < c_max) ? guess : (h_lo - h_hi > 0.0 ? c_max * h_lo / (h_lo - h_hi) : 0.5 * c_max);
  a = bracketed_newton(h, a, 0.0, c_max, false, 0.0, 1e-13, 1e-14, kMaxIter, iterations);
  if (iterations) *iterations += 1;
  if (point) *point = (a == last_a) ? last : ls_.eval(a);
  return a;
}

double ContactModel::solve_outside_beyond(double f, double t, double a_limit, int* iterations) const noexcept {
  const double xi2 = 2.0 * ls_.xi();
  auto h = [&](double a, double& dh) {
    const LsPoint q = ls_.eval(a);
    dh = -q.dF - xi2 * (t - q.T) + xi2 * a * q.dT;
    return f - q.F - xi2 * a * (t - q.T);
  };
  // h(c_max) > 0 and h -> -inf (t > 0): expand the bracket by factors of 4, then Newton in it.
  double lo = p_.c_max, hi = p_.c_max, d = 0.0;
  int evals = 0;
  double v_hi = 1.0;
  while (v_hi > 0.0) {
    if (hi >= a_limit) {
      if (iterations) *iterations = evals;
      return a_limit;
    }
    lo = hi;
    hi = std::min(4.0 * hi, a_limit);
    v_hi = h(hi, d);
    ++evals;
  }
  int it = 0;
  const double a = bracketed_newton(h, 0.5 * (lo + hi), lo, hi, false, 1e-10, 0.0, 1e-14, kMaxIter, &it);
  if (iterations) *iterations = evals + it;
  return a;
}

void ContactModel::wrench_at(double f_n, double c_tilde, double y, double& f_t, double& tau) const noexcept {
  const double a = std::fabs(c_tilde), sign = y < 0.0 ? -1.0 : 1.0;
  const double rho_n = rho(f_n), unit = p_.mu * f_n * rho_n;  // g = unit * G(a)
  const double xi = ls_.xi();
  const LsPoint q = ls_.eval(a);
  const double G = xi * q.T + a * q.F;
  const double r = std::fabs(y) / unit;
  if (r > G) {  // sliding: LS point plus viscous excess lambda (2 xi a, 1)
    const double lambda = (r - G) / (xi * (1.0 + 2.0 * a * a));
    f_t = p_.mu * f_n * (q.F + 2.0 * xi * a * lambda);
    tau = sign * p_.mu * xi * rho_n * f_n * (q.T + lambda);
    return;
  }
  // Inside: virtual normal force u f_n with a F u + xi T u^(gamma+1) = r, u in [0, 1].
  auto phi = [&](double u, double& d) {
    const double up = std::pow(u, p_.gamma);
    d = a * q.F + (p_.gamma + 1.0) * xi * q.T * up;
    return a * q.F * u + xi * q.T * up * u - r;
  };
  const double u = r <= 0.0 ? 0.0 : bracketed_newton(phi, r / G, 0.0, 1.0, true, 1e-15, 0.0, 1e-16, kMaxIter, nullptr);
  f_t = p_.mu * f_n * u * q.F;
  tau = sign * p_.mu * xi * rho_n * f_n * std::pow(u, p_.gamma + 1.0) * q.T;
}

bool validate(const CorSettings& s, std::string* message) { return detail::validate_fields(s, message); }

std::string to_string(const CorSettings& s) { return detail::print_fields(s); }

namespace {
const CorSettings& checked(const CorSettings& s) {
  std::string msg;
  if (!validate(s, &msg)) throw std::invalid_argument("invalid CorSettings:\n" + msg);
  return s;
}
}  // namespace

CorEstimator::CorEstimator(const ContactParams& params, const CorSettings& settings)
    : model_(params), s_(checked(settings)) {
  reset();
}

CorEstimator::CorEstimator(const ContactModel& model, const CorSettings& settings)
    : model_(model), s_(checked(settings)) {
  reset();
}

void CorEstimator::reset() noexcept {
  last_ = CorOutput();
  last_.status = Status::NoContact;
}

Status CorEstimator::step(const CorInput& in, CorOutput& out) noexcept {
  const Status st = evaluate(in, out);
  commit(out);
  return st;
}

void CorEstimator::commit(const CorOutput& out) noexcept {
  if (is_valid(out.status)) last_ = out;
}

Status CorEstimator::evaluate(const CorInput& in, CorOutput& out) const noexcept {
  const bool finite = std::isfinite(in.f_n) && std::isfinite(in.f_t) && std::isfinite(in.tau);
  if (!finite || std::fabs(in.f_n) > s_.force_limit || std::fabs(in.f_t) > s_.force_limit ||
      std::fabs(in.tau) > s_.torque_limit) {
    out = last_;
    out.iterations = 0;
    return out.status = Status::InvalidSample;
  }
  if (!(in.f_n >= s_.f_n_min)) {
    out = last_;
    out.iterations = 0;
    return out.status = Status::NoContact;
  }
  const ContactParams& p = model_.params();
  const LimitSurface& ls = model_.limit_surface();
  const double f_n = in.f_n;
  const double rho = contact_radius(p, f_n);
  const double ft_t = in.f_t / (p.mu * f_n);
  const double tau_t = in.tau / (p.mu * ls.xi() * rho * f_n);
  // A normal force so small (f_n_min set near 0) that f_t,max or tau_max underflows cannot be
  // normalized: treat it like any other unusable sample instead of returning Inf/NaN.
  if (!(std::isfinite(ft_t) && std::isfinite(tau_t))) {
    out = last_;
    out.iterations = 0;
    return out.status = Status::InvalidSample;
  }
  const double f = std::fabs(ft_t), t = std::fabs(tau_t);
  const double prev = last_.c_tilde;
  const double prev_unclipped = last_.c_tilde_unclipped;

  // The result is assembled in locals and written field by field to last_ and out (no
  // zero-initialised temporary, no struct copy through the stack).
  const double f_pow = f * detail::fast_pow_pos(f, p.gamma);  // |f~_t|^(gamma+1)
  // |sigma| overflows for a denormal torque: report it as the largest finite value, like t = 0.
  // (f_pow / t is >= 0, never NaN: the comparison is std::fmin without its library call)
  const double ratio = t > 0.0 ? f_pow / t : 0.0;
  const double sigma = t > 0.0 ? std::copysign(ratio < std::numeric_limits<double>::max() ? ratio
                                                                                           : std::numeric_limits<double>::max(),
                                               in.tau)
                               : (f > 0.0 ? std::numeric_limits<double>::max() : 0.0);
  double a = 0.0, sign = 1.0;
  double a_free = 0.0;        // |c~| before the clip
  LsPoint point;              // LS point at the final a when a branch already evaluated it
  double point_a = -1.0;
  Status status = Status::Ok;
  int iters = 0;
  bool inside;
  if (f < s_.zero_force && t < s_.zero_torque) {  // no wrench: the CoR is undefined
    a = std::fabs(prev);
    a_free = std::max(std::fabs(prev_unclipped), a);
    sign = prev < 0.0 ? -1.0 : 1.0;
    inside = true;
    status = Status::Degenerate;
  } else if (f < s_.zero_force) {  // pure torque: rotation about the patch centre
    a = 0.0;
    inside = t < 1.0;
  } else {
    const bool no_torque = t < s_.zero_torque;
    const double a_sigma = t > 0.0 ? model_.invert_sigma(ratio, &iters)
                                   : std::numeric_limits<double>::infinity();
    const LsPoint q = ls.eval(a_sigma);
    inside = f * f + t * t < q.F * q.F + q.T * q.T;
    if (inside) {
      a = a_sigma;
      a_free = a_sigma;
      point = q;
    } else {
      int it2 = 0;
      a = model_.solve_outside(f, t, &it2, a_sigma, &point);
      iters += it2;
      a_free = a;
      if (a >= p.c_max) {  // the root lies at or past the clip: find it there too
        int it3 = 0;
        a_free = std::max(model_.solve_outside_beyond(f, t, kCTildeUnclippedMax, &it3), p.c_max);
        iters += it3;
      }
    }
    point_a = a;
    if (no_torque)  // sign of a torque below the noise: hold the previous side (hysteresis)
      sign = prev < 0.0 ? -1.0 : 1.0;
    else
      sign = -(in.f_t < 0.0 ? -1.0 : 1.0) * (in.tau < 0.0 ? -1.0 : 1.0);
  }
  bool saturated = false;
  if (a >= p.c_max) {
    saturated = a > p.c_max || status != Status::Degenerate;
    a = p.c_max;
    if (status == Status::Ok) status = Status::Saturated;
  }
  const double c_tilde = sign * a;
  const double c_tilde_unclipped = sign * std::max(std::min(a_free, kCTildeUnclippedMax), a);
  const double c = c_tilde * rho;
  const LsPoint q = (a == point_a) ? point : ls.eval(a);
  const double r2 = rho * rho;
  const double g = p.mu * f_n * rho * (ls.xi() * q.T + a * q.F);
  const double sigma_1 = kPi * p.beta_a * r2 * r2 * (c_tilde * c_tilde + 0.5);
  const double y = in.tau - c * in.f_t;
  // Overflow guard for settings/parameters at the edge of their valid ranges (e.g. force_limit
  // near DBL_MAX makes c f_t overflow, beta_a near 1e300 makes sigma_1 overflow): outputs stay
  // finite, the sample is reported as unusable and the previous estimate is held.
  if (!(std::isfinite(c) && std::isfinite(g) && std::isfinite(sigma_1) && std::isfinite(y))) {
    out = last_;
    out.iterations = iters;
    return out.status = Status::InvalidSample;
  }
  auto fill = [&](CorOutput& o) {
    o.c_tilde_unclipped = c_tilde_unclipped;
    o.c_tilde = c_tilde;
    o.c = c;
    o.ft_tilde = ft_t;
    o.tau_tilde = tau_t;
    o.sigma = sigma;
    o.rho = rho;
    o.g = g;
    o.sigma_1 = sigma_1;
    o.y = y;
    o.inside = inside;
    o.saturated = saturated;
    o.iterations = iters;
    o.status = status;
  };
  fill(out);
  return status;
}

}  // namespace lugrip
