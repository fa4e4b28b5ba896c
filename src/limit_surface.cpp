#include "lugrip/limit_surface.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "quadrature.hpp"

namespace lugrip {

namespace {

constexpr double kPi = 3.14159265358979323846;

// log B(x, y)
double log_beta(double x, double y) { return std::lgamma(x) + std::lgamma(y) - std::lgamma(x + y); }

// Cubic Hermite interpolation of two curves on [0, 1] with n uniform intervals; row i of
// `tab` holds (value, h * slope) of curve 0 then of curve 1 at node i (h = 1/n).
inline void hermite(const double* tab, int n, double x, double& v0, double& d0, double& v1,
                    double& d1) noexcept {
  const double s = x * n;
  int i = static_cast<int>(s);
  i = i >= n ? n - 1 : (i < 0 ? 0 : i);
  const double t = s - i, t2 = t * t, omt = 1.0 - t;
  const double h00 = (1.0 + 2.0 * t) * omt * omt, h10 = t * omt * omt;
  const double h01 = 1.0 - h00, h11 = t2 * (t - 1.0);
  const double g00 = 6.0 * (t2 - t), g10 = 3.0 * t2 - 4.0 * t + 1.0, g11 = 3.0 * t2 - 2.0 * t;
  const double* a = tab + 4 * i;
  const double* b = a + 4;
  const double dn = static_cast<double>(n);
  v0 = h00 * a[0] + h10 * a[1] + h01 * b[0] + h11 * b[1];
  d0 = (g00 * (a[0] - b[0]) + g10 * a[1] + g11 * b[1]) * dn;
  v1 = h00 * a[2] + h10 * a[3] + h01 * b[2] + h11 * b[3];
  d1 = (g00 * (a[2] - b[2]) + g10 * a[3] + g11 * b[3]) * dn;
}

// The elliptic limit surface at a = |c~| >= 0 (finite): u = a / xi_E, F = u / sqrt(1 + u^2),
// T = 1 / sqrt(1 + u^2); dT/da = -(a / xi_E) dF/da as for every maximum-dissipation LS.
inline LsPoint ellipse_point(double a) noexcept {
  const double u = a / kEllipseShapeFactor, s = 1.0 / std::sqrt(1.0 + u * u), s3 = s * s * s;
  LsPoint r;
  r.F = u * s;
  r.T = s;
  r.dF = s3 / kEllipseShapeFactor;
  r.dT = -u * s3 / kEllipseShapeFactor;
  return r;
}

}  // namespace

double shape_factor(double k) {
  if (k == kEllipticLimitSurface) return kEllipseShapeFactor;
  if (!(k > 0.0)) throw std::invalid_argument("shape_factor: k must be > 0");
  if (std::isinf(k)) return 2.0 / 3.0;
  // xi = B(3/k, 1+1/k) / B(2/k, 1+1/k)
  return std::exp(log_beta(3.0 / k, 1.0 + 1.0 / k) - log_beta(2.0 / k, 1.0 + 1.0 / k));
}

LimitSurface::LimitSurface(double k, int intervals) : k_(k), n_(intervals > 0 ? intervals : 256) {
  if (std::isnan(k) || !(k >= kMinPressureExponent || k == kEllipticLimitSurface))
    throw std::invalid_argument("LimitSurface: k = " + std::to_string(k) +
                                ": the pressure exponent must be >= 0.5 (inf for uniform pressure, "
                                "0 for the elliptic limit surface)");
  if (n_ < 16 || n_ > 100000) throw std::invalid_argument("LimitSurface: intervals must be in [16, 1e5]");
  xi_ = shape_factor(k);
  if (k == kEllipticLimitSurface) {  // F ~ a/xi; F ~ 1 - xi^2/(2 a^2), T ~ xi/a
    elliptic_ = true;
    p_k_ = m_k_ = 0.0;
    s_k_ = 1.0 / xi_;
    a_f_ = 0.5 * xi_ * xi_;
    a_tau_ = xi_;
    return;
  }
  if (std::isinf(k)) {
    p_k_ = kPi;
    m_k_ = 2.0 * kPi / 3.0;
    s_k_ = 1.0;
    a_f_ = 1.0 / 8.0;
    a_tau_ = 3.0 / 8.0;
  } else {
    const double b1 = log_beta(1.0 / k, 1.0 + 1.0 / k), b2 = log_beta(2.0 / k, 1.0 + 1.0 / k);
    const double b3 = log_beta(3.0 / k, 1.0 + 1.0 / k), b4 = log_beta(4.0 / k, 1.0 + 1.0 / k);
    p_k_ = 2.0 * kPi / k * std::exp(b2);
    m_k_ = 2.0 * kPi / k * std::exp(b3);
    s_k_ = 0.5 * std::exp(b1 - b2);
    a_f_ = 0.25 * std::exp(b4 - b2);
    a_tau_ = 0.5 * std::exp(b4 - b3);
  }
  const double alpha = std::isinf(k) ? 0.0 : 1.0 / k;
  detail::gauss_gegenbauer(16, alpha, gj_x_, gj_w_);
  // For k not an even integer, (1 - r^k) has a cusp |r|^k where a chord passes the disc centre;
  // those chords are split at their midpoint (the point nearest the centre) and each half is
  // integrated with y = s^2 (which smooths the cusp) and the one-sided rim weight (1 - s)^(1/k).
  split_chords_ = !std::isinf(k) && !(k == std::floor(k) && std::fmod(k, 2.0) == 0.0);
  if (split_chords_) {  // store y = s^2 and the node's full weight in half_x_, half_w_
    detail::gauss_jacobi(8, alpha, 0.0, half_x_, half_w_);
    for (size_t j = 0; j < half_x_.size(); ++j) {
      const double s = 0.5 * (1.0 + half_x_[j]), y = s * s;
      half_w_[j] *= std::pow(2.0, -alpha) * s * std::pow((1.0 + s) * (1.0 + y), alpha);
      half_x_[j] = y;
    }
  }
  detail::gauss_gegenbauer(48, 0.0, gl_x_, gl_w_);
  detail::gauss_gegenbauer(160, 0.0, near_x_, near_w_);

  inner_.assign(4 * (n_ + 1), 0.0);
  outer_.assign(4 * (n_ + 1), 0.0);
  for (int i = 0; i <= n_; ++i) {
    const double a = static_cast<double>(i) / n_;
    const bool near_rim = a > 0.85;
    const LsPoint q = i == 0 ? LsPoint{0.0, 1.0, s_k_, 0.0}
                             : quad(a, near_rim ? near_x_ : gl_x_, near_rim ? near_w_ : gl_w_);
    double* r = &inner_[4 * i];
    r[0] = q.F;
    r[1] = q.dF / n_;
    r[2] = q.T;
    r[3] = q.dT / n_;
  }
  for (int i = 0; i <= n_; ++i) {
    const double u = static_cast<double>(i) / n_;
    double* r = &outer_[4 * i];
    if (i == 0) {  // a -> inf: F = 1 - A_f u^2, T = A_tau u
      r[0] = 1.0;
      r[1] = 0.0;
      r[2] = 0.0;
      r[3] = a_tau_ / n_;
      continue;
    }
    const double a = 1.0 / u;
    const bool near_rim = u > 0.85;
    const LsPoint q = quad(a, near_rim ? near_x_ : gl_x_, near_rim ? near_w_ : gl_w_);
    // d/du = -a^2 d/da
    r[0] = q.F;
    r[1] = -a * a * q.dF / n_;
    r[2] = q.T;
    r[3] = -a * a * q.dT / n_;
  }
}

LsPoint LimitSurface::integrate(double a) const {
  a = std::fabs(a);
  if (a == 0.0) return LsPoint{0.0, 1.0, s_k_, 0.0};
  if (std::isinf(a)) return LsPoint{1.0, 0.0, 0.0, 0.0};
  if (elliptic_) return ellipse_point(a);
  std::vector<double> x, w;
  detail::gauss_gegenbauer(400, 0.0, x, w);
  return quad(a, x, w);
}

// One point of the curves by the CoR-centred chord reduction (docs/model.md 3.3, method A, with
// the chords taken whole through the CoR so every inner integrand is smooth):
//   F = -(2/P_k) int cos(phi) I1,  T = (2/M_k) int (I2 + a cos(phi) I1),
//   dF/da = (2/P_k) int sin(phi)^2 I0,  I_m(phi) = int_chord p t^m dt,  phi in [0, pi/2].
// For a > 1 the outer variable is psi with sin(phi) = sin(psi)/a (chord half-length cos psi).
LsPoint LimitSurface::quad(double a, const std::vector<double>& ox, const std::vector<double>& ow) const {
  const bool uniform = std::isinf(k_);
  const double lexp = uniform ? 1.0 : 1.0 + 2.0 / k_;
  const double half_k = 0.5 * k_, inv_k = uniform ? 0.0 : 1.0 / k_;
  const bool hertz = (k_ == 2.0);
  const int even_k = (!uniform && !split_chords_ && k_ <= 64.0) ? static_cast<int>(k_) : 0;
  double sf = 0.0, st = 0.0, sd = 0.0;
  const int no = static_cast<int>(ox.size()), ni = static_cast<int>(gj_x_.size());
  for (int io = 0; io < no; ++io) {
    const double v = 0.25 * kPi * (1.0 + ox[io]);
    double wphi = 0.25 * kPi * ow[io];
    double cphi, sphi, half;
    if (a <= 1.0) {
      cphi = std::cos(v);
      sphi = std::sin(v);
      half = std::sqrt(std::fmax(0.0, 1.0 - a * a * sphi * sphi));
    } else {
      const double cpsi = std::cos(v);
      sphi = std::sin(v) / a;
      cphi = std::sqrt(std::fmax(0.0, 1.0 - sphi * sphi));
      half = cpsi;
      if (cphi <= 0.0) continue;
      wphi *= cpsi / (a * cphi);
    }
    if (half <= 0.0) continue;
    const double mid = -a * cphi;
    double i0 = 0.0, i1 = 0.0, i2 = 0.0;
    auto q_of = [&](double t) {  // (h_k(r^2))^(1/k) at chord position t
      if (uniform || hertz) return 1.0;
      double u = a * a + 2.0 * a * t * cphi + t * t;  // r^2 along the chord
      u = std::fmin(std::fmax(u, 0.0), 1.0);
      if (even_k > 0) {  // h_k(u) = 1 + u + ... + u^(k/2 - 1)
        double h = 1.0;
        for (int i = 1; i < even_k / 2; ++i) h = 1.0 + u * h;
        return even_k == 4 ? std::sqrt(std::sqrt(h)) : std::pow(h, inv_k);
      }
      const double om = 1.0 - u;
      const double h = om < 1e-14 ? half_k : -std::expm1(half_k * std::log(u)) / om;
      return std::pow(h, inv_k);
    };
    if (split_chords_) {
      for (size_t j = 0; j < half_x_.size(); ++j) {
        for (double side : {-1.0, 1.0}) {
          const double t = mid + side * half * half_x_[j];
          const double wq = half_w_[j] * q_of(t);
          i0 += wq;
          i1 += wq * t;
          i2 += wq * t * t;
        }
      }
    } else {
      for (int j = 0; j < ni; ++j) {
        const double t = mid + half * gj_x_[j];
        const double wq = gj_w_[j] * q_of(t);
        i0 += wq;
        i1 += wq * t;
        i2 += wq * t * t;
      }
    }
    const double lf = std::pow(half, lexp);
    i0 *= lf;
    i1 *= lf;
    i2 *= lf;
    sf += wphi * cphi * i1;
    st += wphi * (i2 + a * cphi * i1);
    sd += wphi * sphi * sphi * i0;
  }
  LsPoint r;
  r.F = -2.0 / p_k_ * sf;
  r.T = 2.0 / m_k_ * st;
  r.dF = 2.0 / p_k_ * sd;
  r.dT = -(a / xi_) * r.dF;
  return r;
}

LsPoint LimitSurface::eval(double a) const noexcept {
  LsPoint r;
  a = std::fabs(a);
  if (std::isnan(a)) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    return LsPoint{nan, nan, nan, nan};
  }
  if (elliptic_) return std::isinf(a) ? LsPoint{1.0, 0.0, 0.0, 0.0} : ellipse_point(a);
  if (a <= 1.0) {
    hermite(inner_.data(), n_, a, r.F, r.dF, r.T, r.dT);
    return r;
  }
  if (std::isinf(a)) return LsPoint{1.0, 0.0, 0.0, 0.0};
  const double u = 1.0 / a;
  double dFu, dTu;
  hermite(outer_.data(), n_, u, r.F, dFu, r.T, dTu);
  r.dF = -u * u * dFu;
  r.dT = -u * u * dTu;
  return r;
}

double LimitSurface::G(double a) const noexcept {
  const LsPoint p = eval(a);
  a = std::fabs(a);
  if (std::isinf(a)) return a;
  return xi_ * p.T + a * p.F;
}

double LimitSurface::ft_star(double c) const noexcept {
  const double f = eval(c).F;
  return c > 0.0 ? -f : (c < 0.0 ? f : 0.0 * f);
}
double LimitSurface::tau_star(double c) const noexcept { return eval(c).T; }
double LimitSurface::dft_star(double c) const noexcept { return -eval(c).dF; }
double LimitSurface::dtau_star(double c) const noexcept {
  const double d = eval(c).dT;
  return c < 0.0 ? -d : d;
}

double LimitSurface::sigma_ls(double a, double gamma) const noexcept {
  const LsPoint p = eval(a);
  return std::pow(p.F, gamma + 1.0) / p.T;
}

}  // namespace lugrip
