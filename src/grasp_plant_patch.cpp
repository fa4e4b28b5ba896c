// Distributed fingertip contact (PatchContact) and the deterministic normal RNG of the plant.
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "lugrip/grasp_plant.hpp"
#include "quadrature.hpp"

namespace lugrip {

namespace {
constexpr double kPi = 3.14159265358979323846;

// Normalised pressure (1 - r^k)^(1/k) on the unit disc (k = inf: uniform).
double unit_pressure(double r, double k) {
  if (r >= 1.0) return 0.0;
  if (std::isinf(k)) return 1.0;
  return std::pow(1.0 - std::pow(r, k), 1.0 / k);
}

// Integrals W = int p(r) r dr and Q = int p(r) r^2 dr over [ra, rb], accurate also on the ring
// touching the rim, where p ~ (1 - r)^(1/k): there r = 1 - (1 - ra) s^m with m = max(k, 1)
// makes the integrand smooth in s.
void ring_integrals(double ra, double rb, double k, double& W, double& Q) {
  if (std::isinf(k)) {
    W = 0.5 * (rb * rb - ra * ra);
    Q = (rb * rb * rb - ra * ra * ra) / 3.0;
    return;
  }
  std::vector<double> x, w;
  detail::gauss_gegenbauer(48, 0.0, x, w);
  W = Q = 0.0;
  if (rb < 1.0) {
    const double c = 0.5 * (ra + rb), hw = 0.5 * (rb - ra);
    for (size_t i = 0; i < x.size(); ++i) {
      const double r = c + hw * x[i];
      const double p = unit_pressure(r, k) * r * hw * w[i];
      W += p;
      Q += p * r;
    }
    return;
  }
  const double m = std::max(k, 1.0), L = 1.0 - ra;
  for (size_t i = 0; i < x.size(); ++i) {
    const double s = 0.5 * (x[i] + 1.0);
    const double r = 1.0 - L * std::pow(s, m);
    const double drds = L * m * std::pow(s, m - 1.0);
    const double p = unit_pressure(r, k) * r * drds * 0.5 * w[i];
    W += p;
    Q += p * r;
  }
}
}  // namespace

// ---------------------------------------------------------------------------------------------
// PatchContact

PatchContact::PatchContact(const ContactParams& params, const PatchSettings& settings)
    : p_(params), s_(settings) {
  validate_or_throw(p_);
  if (!(s_.rings >= 1 && s_.rings <= 200))
    throw std::invalid_argument("PatchSettings.rings = " + std::to_string(s_.rings) + ": must be in [1, 200]");
  if (!(std::isfinite(s_.bristle_stiffness) && s_.bristle_stiffness > 0.0))
    throw std::invalid_argument("PatchSettings.bristle_stiffness: must be finite and > 0 [1/m]");
  if (!(std::isfinite(s_.bristle_damping) && s_.bristle_damping >= 0.0))
    throw std::invalid_argument("PatchSettings.bristle_damping: must be finite and >= 0 [s]");
  if (!(std::isfinite(s_.static_ratio) && s_.static_ratio >= 1.0))
    throw std::invalid_argument("PatchSettings.static_ratio: must be finite and >= 1");
  if (!(std::isfinite(s_.stribeck_velocity) && s_.stribeck_velocity > 0.0))
    throw std::invalid_argument("PatchSettings.stribeck_velocity: must be finite and > 0 [m/s]");

  const int nr = s_.rings;
  double total = 0.0;
  for (int i = 0; i < nr; ++i) {
    const double ra = static_cast<double>(i) / nr, rb = static_cast<double>(i + 1) / nr;
    double W = 0.0, Q = 0.0;
    ring_integrals(ra, rb, p_.k, W, Q);
    const double rc = W > 0.0 ? Q / W : 0.5 * (ra + rb);  // pressure centroid radius
    // ~square cells: sectors ~ ring circumference / ring width, staggered by half a sector.
    const int ns = std::max(3, static_cast<int>(std::lround(kPi * (2.0 * i + 1.0))));
    const double off = (i % 2) ? 0.5 : 0.0;
    for (int j = 0; j < ns; ++j) {
      const double a = 2.0 * kPi * (j + off) / ns;
      ux_.push_back(rc * std::cos(a));
      uy_.push_back(rc * std::sin(a));
      w_.push_back(W / ns);
    }
    total += W;
  }
  m2_ = 0.0;
  for (size_t j = 0; j < w_.size(); ++j) {
    w_[j] /= total;
    m2_ += w_[j] * (ux_[j] * ux_[j] + uy_[j] * uy_[j]);
  }
  const size_t n = w_.size();
  zx_.assign(n, 0.0);
  zy_.assign(n, 0.0);
  e_.assign(n, 1.0);
  phi_.assign(n, 1.0);
  kappa_ = s_.bristle_stiffness;
  zmax_c_ = p_.mu / kappa_;
  mu_ratio_ = s_.static_ratio;
  inv_vs2_ = 1.0 / (s_.stribeck_velocity * s_.stribeck_velocity);
}

void PatchContact::reset() noexcept {
  std::fill(zx_.begin(), zx_.end(), 0.0);
  std::fill(zy_.begin(), zy_.end(), 0.0);
  std::fill(e_.begin(), e_.end(), 1.0);
  std::fill(phi_.begin(), phi_.end(), 1.0);
  f_n_ = rho_ = h_ = 0.0;
}

inline double PatchContact::zmax(double speed) const noexcept {
  if (mu_ratio_ == 1.0) return zmax_c_;
  return zmax_c_ * (1.0 + (mu_ratio_ - 1.0) * std::exp(-speed * speed * inv_vs2_));
}

void PatchContact::prepare(double f_n, double vx, double vy, double omega, double h, Linear& lin) noexcept {
  f_n_ = (std::isfinite(f_n) && f_n > 0.0) ? f_n : 0.0;
  rho_ = f_n_ > 0.0 ? p_.delta * std::pow(f_n_, p_.gamma) : 0.0;
  h_ = h;
  const double td = s_.bristle_damping;
  const double rho = rho_;
  double sax = 0.0, say = 0.0, sat = 0.0, sb0 = 0.0, sb1x = 0.0, sb1y = 0.0, sb2 = 0.0;
  const size_t n = w_.size();
  for (size_t j = 0; j < n; ++j) {
    const double sx = rho * ux_[j], sy = rho * uy_[j];
    const double cvx = vx - omega * sy, cvy = vy + omega * sx;
    const double sp = std::sqrt(cvx * cvx + cvy * cvy);
    // Exact bristle relaxation for the frozen rate lambda = |v| / z_max over h:
    // z' = e z + h phi v,  e = exp(-lambda h),  phi = (1 - e) / (lambda h).
    const double x = sp * h / zmax(sp);
    double e, phi;
    if (x < 1e-5) {
      e = 1.0 - x;
      phi = 1.0 - 0.5 * x;
    } else if (x > 60.0) {
      e = 0.0;
      phi = 1.0 / x;
    } else {
      e = std::exp(-x);
      phi = (1.0 - e) / x;
    }
    e_[j] = e;
    phi_[j] = phi;
    // f_j = -k_j (z' + t_d (z' - z)/h) = A_j - B_j v',  k_j = kappa f_n w_j
    const double ca = w_[j] * (e + td * (e - 1.0) / h);
    const double ax = -ca * zx_[j], ay = -ca * zy_[j];
    sax += ax;
    say += ay;
    sat += sx * ay - sy * ax;
    const double cb = w_[j] * phi;
    sb0 += cb;
    sb1x += cb * sx;
    sb1y += cb * sy;
    sb2 += cb * (sx * sx + sy * sy);
  }
  const double K = kappa_ * f_n_;
  const double KB = K * (h + td);
  const double visc = p_.beta_a * kPi * rho * rho;  // viscous stress integrated over the disc
  lin.a_fx = K * sax;
  lin.a_fy = K * say;
  lin.a_tau = K * sat;
  lin.b0 = KB * sb0 + visc;
  lin.b1x = KB * sb1x;
  lin.b1y = KB * sb1y;
  lin.b2 = KB * sb2 + 0.5 * visc * rho * rho;
}

void PatchContact::finish(double vx, double vy, double omega, PadWrench& wr) noexcept {
  const double h = h_, td = s_.bristle_damping, rho = rho_;
  const size_t n = w_.size();
  if (!(f_n_ > 0.0) || !(h > 0.0)) {  // no contact: the bristles are relaxed
    std::fill(zx_.begin(), zx_.end(), 0.0);
    std::fill(zy_.begin(), zy_.end(), 0.0);
    wr = PadWrench();
    return;
  }
  double fx = 0.0, fy = 0.0, tz = 0.0;
  const bool stribeck = mu_ratio_ != 1.0;
  const double zc2 = zmax_c_ * zmax_c_;
  for (size_t j = 0; j < n; ++j) {
    const double sx = rho * ux_[j], sy = rho * uy_[j];
    const double cvx = vx - omega * sy, cvy = vy + omega * sx;
    double nzx = e_[j] * zx_[j] + h * phi_[j] * cvx;
    double nzy = e_[j] * zy_[j] + h * phi_[j] * cvy;
    // projection onto the saturation disc |z| <= z_max(|v|) (MODEL.md 7.1, per cell)
    const double n2 = nzx * nzx + nzy * nzy;
    double zb2 = zc2;
    if (stribeck) {
      const double zb = zmax(std::sqrt(cvx * cvx + cvy * cvy));
      zb2 = zb * zb;
    }
    if (n2 > zb2) {
      const double s = std::sqrt(zb2 / n2);
      nzx *= s;
      nzy *= s;
    }
    const double gx = -w_[j] * (nzx + td * (nzx - zx_[j]) / h);
    const double gy = -w_[j] * (nzy + td * (nzy - zy_[j]) / h);
    zx_[j] = nzx;
    zy_[j] = nzy;
    fx += gx;
    fy += gy;
    tz += sx * gy - sy * gx;
  }
  const double K = kappa_ * f_n_;
  const double visc = p_.beta_a * kPi * rho * rho;
  wr.fx = K * fx - visc * vx;
  wr.fy = K * fy - visc * vy;
  wr.tau = K * tz - 0.5 * visc * rho * rho * omega;
}

void PatchContact::advance(double f_n, double vx, double vy, double omega, double h, PadWrench& w) noexcept {
  Linear lin;
  prepare(f_n, vx, vy, omega, h, lin);
  finish(vx, vy, omega, w);
}

double PatchContact::bristle_energy() const noexcept {
  double s = 0.0;
  for (size_t j = 0; j < w_.size(); ++j) s += w_[j] * (zx_[j] * zx_[j] + zy_[j] * zy_[j]);
  return 0.5 * kappa_ * f_n_ * s;
}

// ---------------------------------------------------------------------------------------------
// NormalRng: xoshiro256++ seeded by splitmix64; polar Box-Muller.

namespace {
inline uint64_t splitmix64(uint64_t& x) noexcept {
  uint64_t z = (x += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}
inline uint64_t rotl(uint64_t x, int k) noexcept { return (x << k) | (x >> (64 - k)); }
}  // namespace

void NormalRng::seed_with(uint64_t seed) noexcept {
  uint64_t x = seed;
  for (auto& s : s_) s = splitmix64(x);
  has_spare_ = false;
  spare_ = 0.0;
}

uint64_t NormalRng::next_u64() noexcept {
  const uint64_t result = rotl(s_[0] + s_[3], 23) + s_[0];
  const uint64_t t = s_[1] << 17;
  s_[2] ^= s_[0];
  s_[3] ^= s_[1];
  s_[1] ^= s_[2];
  s_[0] ^= s_[3];
  s_[2] ^= t;
  s_[3] = rotl(s_[3], 45);
  return result;
}

double NormalRng::uniform() noexcept { return static_cast<double>(next_u64() >> 11) * 0x1.0p-53; }

double NormalRng::normal() noexcept {
  if (has_spare_) {
    has_spare_ = false;
    return spare_;
  }
  double u, v, s;
  do {
    u = 2.0 * uniform() - 1.0;
    v = 2.0 * uniform() - 1.0;
    s = u * u + v * v;
  } while (s >= 1.0 || s == 0.0);
  const double f = std::sqrt(-2.0 * std::log(s) / s);
  spare_ = v * f;
  has_spare_ = true;
  return u * f;
}

}  // namespace lugrip
