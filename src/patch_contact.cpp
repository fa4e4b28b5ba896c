// Distributed fingertip contact (PatchContact) and the deterministic normal RNG of the plant.
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "lugrip/grasp_plant.hpp"
#include "lugrip/limit_surface.hpp"
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
  if (p_.k == kEllipticLimitSurface)
    throw std::invalid_argument("PatchContact: k = 0 (the elliptic limit surface) has no pressure "
                                "distribution; the patch needs a pressure exponent >= 0.5");
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
    // projection onto the saturation disc |z| <= z_max(|v|) (docs/model.md 7.1, per cell)
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
// NormalRng: xoshiro256++ (Blackman & Vigna; next_u64() in the header) seeded by splitmix64, and
// a 256-layer ziggurat (Marsaglia & Tsang, J. Stat. Softw. 5(8), 2000) for normal().
//
// Why the ziggurat: it is exact (the density is covered by 256 layers of equal area v; a layer is
// picked uniformly, a point uniform in it is accepted when it lies under exp(-x^2/2), and the
// base layer's overhang beyond r is replaced by an exact sample of the tail) and 98.5 % of the
// draws take the fast path: one 64-bit draw, an integer compare and one multiplication (inlined:
// ~14 instructions besides the ~19 of xoshiro256++; 38 per normal on average in a loop against 89
// for the polar method with its log, sqrt, division and 21 % rejection; 2.7 ns against 13 ns).
// Doornik (2005) showed that the original code is correlated because it takes the layer index
// from the low bits of the same 32-bit integer that makes the abscissa (his ZIGNOR draws them
// separately); here the index (bits 0-7), the sign (bit 8) and the abscissa (bits 12-63, 52 bits)
// are disjoint bits of one xoshiro256++ output (whose low bits, unlike xoshiro256+'s, pass the
// statistical test batteries), so they are independent at the cost of one draw. The wedge test
// and the tail use fresh draws.
//
// Layers (x_0 = r > x_1 > ... > x_255 = 0, f(x) = exp(-x^2/2)):
//   layer 0   : [0, r] x [0, f(r)] plus the tail x > r, area v = r f(r) + int_r^inf f; it is
//               sampled as a rectangle of pseudo-width v / f(r), the part beyond r going to the
//               tail;
//   layer i>=1: [0, x_{i-1}] x [f(x_{i-1}), f(x_i)], with f(x_i) = f(x_{i-1}) + v / x_{i-1};
//   r solves x_254 (1 - f(x_254)) = v (the top layer ends at the peak): r = 3.6541528853610088,
//   v = 0.0049286732339746553.
// The tables were generated once with mpmath at 80 significant digits (bisection on r to 1e-80,
// then the recursion above) and are pasted as exact hexadecimal literals, so every platform uses
// the same bits:
//   width_0 = v / f(r), width_i = x_{i-1};  w_i = width_i * 2^-52 rounded to double;
//   k_i = floor(x_i / width_i * 2^52) (a < k_i  <=>  a w_i < x_i: the point is inside the ziggurat
//   core, under the curve; floor makes the test conservative, the wedge test takes the rest);
//   kZigF[i] = f(x_i) rounded to double (kZigF[255] = 1).
// Sequence reproducibility: the fast path and the wedge abscissa use only integer operations and
// one IEEE multiplication, so they are bit-identical everywhere; the wedge decision compares with
// std::exp and the tail (2.6e-4 of the draws) uses std::log, whose last bit may differ between C
// libraries.

const NormalRng::Layer NormalRng::kZigLayers[256] = {
    {4208095142473573, 0x1.f493b7815d982p-51}, {4251099761679433, 0x1.d3bb48209ad33p-51},
    {4335125104963628, 0x1.b981f3878fdb0p-51}, {4373832704204283, 0x1.a8fdc78947759p-51},
    {4396496531309975, 0x1.9cbee014057aap-51}, {4411517007702131, 0x1.92ee0946f4496p-51},
    {4422264825074739, 0x1.8ab0fbfaa7c14p-51}, {4430368316897337, 0x1.839030529f233p-51},
    {4436714892174060, 0x1.7d42df4d6ce8bp-51}, {4441831266659618, 0x1.7799556090672p-51},
    {4446050695647665, 0x1.72728f05f7a33p-51}, {4449594783440798, 0x1.6db6b8d09e231p-51},
    {4452616884242348, 0x1.69540be9fe5c2p-51}, {4455226650325009, 0x1.653ce7b006aeap-51},
    {4457504658253067, 0x1.61669cf861e4bp-51}, {4459511507635972, 0x1.5dc8a243ad0fep-51},
    {4461293691124341, 0x1.5a5c08b718dd9p-51}, {4462887501169282, 0x1.571b1a94ae41cp-51},
    {4464321701199634, 0x1.54011523a7e43p-51}, {4465619395558397, 0x1.5109f53e9ac42p-51},
    {4466799366045354, 0x1.4e3250dcd8903p-51}, {4467877045039530, 0x1.4b7739d6b5a28p-51},
    {4468865235838895, 0x1.48d62759c43bdp-51}, {4469774653883156, 0x1.464ce44a73a16p-51},
    {4470614338917719, 0x1.43d9815545e94p-51}, {4471391972746493, 0x1.417a49cb9e5dbp-51},
    {4472114126959003, 0x1.3f2dbaa60f475p-51}, {4472786458058295, 0x1.3cf27b31704a6p-51},
    {4473413862618199, 0x1.3ac7570ae88fap-51}, {4474000601739904, 0x1.38ab39256410ap-51},
    {4474550401693506, 0x1.369d27a33a840p-51}, {4475066535915645, 0x1.349c405ae12a3p-51},
    {4475551892286424, 0x1.32a7b5e68a4a3p-51}, {4476009028690433, 0x1.30becd256aeeep-51},
    {4476440219183781, 0x1.2ee0db1a978f5p-51}, {4476847492576191, 0x1.2d0d43196db97p-51},
    {4477232664848703, 0x1.2b437532a0a53p-51}, {4477597366530538, 0x1.2982ecd770e78p-51},
    {4477943065929958, 0x1.27cb2faa8592ep-51}, {4478271088936406, 0x1.261bcc77658e0p-51},
    {4478582635972392, 0x1.24745a4ac9c24p-51}, {4478878796564387, 0x1.22d477a6fd3efp-51},
    {4479160561915450, 0x1.213bc9d04cc82p-51}, {4479428835793398, 0x1.1fa9fc2e2d901p-51},
    {4479684443993061, 0x1.1e1ebfbe4ae39p-51}, {4479928142586662, 0x1.1c99ca971a695p-51},
    {4480160625140310, 0x1.1b1ad777f2f8fp-51}, {4480382529045224, 0x1.19a1a564eebadp-51},
    {4480594441088331, 0x1.182df74d21262p-51}, {4480796902367134, 0x1.16bf93b9deef5p-51},
    {4480990412637506, 0x1.1556448602e3dp-51}, {4481175434169564, 0x1.13f1d69c4096fp-51},
    {4481352395175569, 0x1.129219bbb5d37p-51}, {4481521692864464, 0x1.1136e04207043p-51},
    {4481683696169780, 0x1.0fdffefa69fb8p-51}, {4481838748191073, 0x1.0e8d4cf116594p-51},
    {4481987168383485, 0x1.0d3ea34aa3d32p-51}, {4482129254525304, 0x1.0bf3dd1eed449p-51},
    {4482265284489408, 0x1.0aacd7571c0c5p-51}, {4482395517841076, 0x1.0969708e8a255p-51},
    {4482520197281720, 0x1.082988f632e18p-51}, {4482639549955635, 0x1.06ed023a72669p-51},
    {4482753788634691, 0x1.05b3bf6adb37ep-51}, {4482863112794071, 0x1.047da4e3ef5c7p-51},
    {4482967709590562, 0x1.034a983a902abp-51}, {4483067754753535, 0x1.021a8028fc947p-51},
    {4483163413397546, 0x1.00ed447d3a075p-51}, {4483254840764470, 0x1.ff859c118f60bp-52},
    {4483342182902156, 0x1.fd360d22fe785p-52}, {4483425577285833, 0x1.faebb187122bfp-52},
    {4483505153387763, 0x1.f8a6604899782p-52}, {4483581033200083, 0x1.f665f20c90168p-52},
    {4483653331715197, 0x1.f42a40fb74d6dp-52}, {4483722157367660, 0x1.f1f328ac25321p-52},
    {4483787612441035, 0x1.efc086101eca9p-52}, {4483849793442887, 0x1.ed9237610a73ap-52},
    {4483908791450713, 0x1.eb681c0f76f08p-52}, {4483964692431364, 0x1.e94214b2abf09p-52},
    {4484017577536215, 0x1.e72002f97fe23p-52}, {4484067523374159, 0x1.e501c99c1d186p-52},
    {4484114602264270, 0x1.e2e74c4ea46f3p-52}, {4484158882469813, 0x1.e0d06fb49d219p-52},
    {4484200428415112, 0x1.debd195522e34p-52}, {4484239300886655, 0x1.dcad2f8fc490cp-52},
    {4484275557219678, 0x1.daa0999206e6ep-52}, {4484309251471359, 0x1.d8973f4d7fba4p-52},
    {4484340434581639, 0x1.d691096e7f123p-52}, {4484369154522620, 0x1.d48de1533c647p-52},
    {4484395456437369, 0x1.d28db1037ef20p-52}, {4484419382768917, 0x1.d0906328b8f6ep-52},
    {4484440973380153, 0x1.ce95e3068e037p-52}, {4484460265665251, 0x1.cc9e1c73bd690p-52},
    {4484477294653230, 0x1.caa8fbd36a2abp-52}, {4484492093104164, 0x1.c8b66e0eba617p-52},
    {4484504691598553, 0x1.c6c6608ec8705p-52}, {4484515118620290, 0x1.c4d8c136e0d1dp-52},
    {4484523400633636, 0x1.c2ed7e5f07a2dp-52}, {4484529562154579, 0x1.c10486cec16a0p-52},
    {4484533625816925, 0x1.bf1dc9b81ae82p-52}, {4484535612433423, 0x1.bd3936b2ec0a2p-52},
    {4484535541052219, 0x1.bb56bdb85256ep-52}, {4484533429008906, 0x1.b9764f1e5f73dp-52},
    {4484529291974393, 0x1.b797db93f8928p-52}, {4484523143998833, 0x1.b5bb541ce3d04p-52},
    {4484514997551787, 0x1.b3e0aa0e00c01p-52}, {4484504863558830, 0x1.b207cf09a985cp-52},
    {4484492751434739, 0x1.b030b4fc3a11bp-52}, {4484478669113435, 0x1.ae5b4e18bb338p-52},
    {4484462623074795, 0x1.ac878cd5af5cfp-52}, {4484444618368474, 0x1.aab563e9ff10ap-52},
    {4484424658634833, 0x1.a8e4c64a0313fp-52}, {4484402746123074, 0x1.a715a724aa9a7p-52},
    {4484378881706674, 0x1.a547f9e0bbb8bp-52}, {4484353064896185, 0x1.a37bb21a2c85ep-52},
    {4484325293849473, 0x1.a1b0c39f93696p-52}, {4484295565379450, 0x1.9fe7226fad24dp-52},
    {4484263874959344, 0x1.9e1ec2b6f7414p-52}, {4484230216725549, 0x1.9c5798cd5d92ep-52},
    {4484194583478081, 0x1.9a919933f99c1p-52}, {4484156966678662, 0x1.98ccb892e2a33p-52},
    {4484117356446451, 0x1.9708ebb70d5efp-52}, {4484075741551420, 0x1.954627903a28bp-52},
    {4484032109405371, 0x1.9384612ef0afep-52}, {4483986446050596, 0x1.91c38dc288349p-52},
    {4483938736146143, 0x1.9003a2973b591p-52}, {4483888962951686, 0x1.8e44951446a28p-52},
    {4483837108308932, 0x1.8c865aba10c9dp-52}, {4483783152620563, 0x1.8ac8e9205c044p-52},
    {4483727074826623, 0x1.890c35f47f72ep-52}, {4483668852378322, 0x1.875036f7a7ec7p-52},
    {4483608461209170, 0x1.8594e1fd1f5bep-52}, {4483545875703378, 0x1.83da2ce899f16p-52},
    {4483481068661427, 0x1.82200dac88677p-52}, {4483414011262724, 0x1.80667a486ea1fp-52},
    {4483344673025224, 0x1.7ead68c73dee7p-52}, {4483273021761921, 0x1.7cf4cf3db22fcp-52},
    {4483199023534056, 0x1.7b3ca3c8b140ap-52}, {4483122642600924, 0x1.7984dc8babd94p-52},
    {4483043841366125, 0x1.77cd6faeff44ap-52}, {4482962580320076, 0x1.7616535e57320p-52},
    {4482878817978627, 0x1.745f7dc70eeddp-52}, {4482792510817576, 0x1.72a8e516914c7p-52},
    {4482703613202871, 0x1.70f27f78b68ecp-52}, {4482612077316275, 0x1.6f3c43161f856p-52},
    {4482517853076245, 0x1.6d8626128d354p-52}, {4482420888053758, 0x1.6bd01e8b343bdp-52},
    {4482321127382800, 0x1.6a1a22950b2b3p-52}, {4482218513665204, 0x1.6864283b13139p-52},
    {4482112986869492, 0x1.66ae257c99674p-52}, {4482004484223382, 0x1.64f8104b7260dp-52},
    {4481892940099539, 0x1.6341de8a2b0a4p-52}, {4481778285894164, 0x1.618b860a31fc5p-52},
    {4481660449897960, 0x1.5fd4fc89f5e39p-52}, {4481539357158973, 0x1.5e1e37b2f8cd4p-52},
    {4481414929336783, 0x1.5c672d17d733fp-52}, {4481287084547452, 0x1.5aafd23241b5ap-52},
    {4481155737198611, 0x1.58f81c60e8515p-52}, {4481020797814009, 0x1.574000e555f79p-52},
    {4480882172846772, 0x1.558774e1bb2c9p-52}, {4480739764480586, 0x1.53ce6d56a6650p-52},
    {4480593470417938, 0x1.5214df20a8b5cp-52}, {4480443183654460, 0x1.505abef5e5563p-52},
    {4480288792238367, 0x1.4ea001638a606p-52}, {4480130179013871, 0x1.4ce49acb311ddp-52},
    {4479967221347353, 0x1.4b287f602415ep-52}, {4479799790834988, 0x1.496ba32488f30p-52},
    {4479627752990372, 0x1.47adf9e66c338p-52}, {4479450966910587, 0x1.45ef773cac75ep-52},
    {4479269284918997, 0x1.44300e83c30a6p-52}, {4479082552182885, 0x1.426fb2da6745fp-52},
    {4478890606303905, 0x1.40ae571e09e76p-52}, {4478693276879082, 0x1.3eebede725a85p-52},
    {4478490385029916, 0x1.3d28698561de3p-52}, {4478281742896886, 0x1.3b63bbfb83d06p-52},
    {4478067153096380, 0x1.399dd6fb2b267p-52}, {4477846408136804, 0x1.37d6abe05586cp-52},
    {4477619289790267, 0x1.360e2baca52d7p-52}, {4477385568415884, 0x1.3444470265ea4p-52},
    {4477145002230338, 0x1.3278ee1f4b933p-52}, {4476897336520865, 0x1.30ac10d6e48dap-52},
    {4476642302795321, 0x1.2edd9e8cba990p-52}, {4476379617863425, 0x1.2d0d862e1b855p-52},
    {4476108982842610, 0x1.2b3bb62b82edbp-52}, {4475830082081194, 0x1.29681c719d71dp-52},
    {4475542581990776, 0x1.2792a661dd381p-52}, {4475246129778807, 0x1.25bb40ca96bfep-52},
    {4474940352071305, 0x1.23e1d7de9c322p-52}, {4474624853414418, 0x1.2206572c4c6ecp-52},
    {4474299214642295, 0x1.2028a9940a0a3p-52}, {4473962991097124, 0x1.1e48b93e0d431p-52},
    {4473615710685531, 0x1.1c666f8f82acfp-52}, {4473256871753524, 0x1.1a81b51ee6d8bp-52},
    {4472885940759934, 0x1.189a71a78da37p-52}, {4472502349725738, 0x1.16b08bfc42020p-52},
    {4472105493433674, 0x1.14c3e9f8e9143p-52}, {4471694726349190, 0x1.12d4707310fc1p-52},
    {4471269359229841, 0x1.10e20329515f1p-52}, {4470828655385769, 0x1.0eec84b16086fp-52},
    {4470371826548632, 0x1.0cf3d664bcc83p-52}, {4469898028300363, 0x1.0af7d84bc6116p-52},
    {4469406355006040, 0x1.08f869071f40fp-52}, {4468895834186993, 0x1.06f565b72a014p-52},
    {4468365420260670, 0x1.04eea9e16a5ffp-52}, {4467813987562542, 0x1.02e40f5398f9dp-52},
    {4467240322552142, 0x1.00d56e04234eep-52}, {4466643115089763, 0x1.fd8537dfa2eb1p-53},
    {4466020948651919, 0x1.f956d9e87d7b2p-53}, {4465372289331869, 0x1.f51f654d8f68cp-53},
    {4464695473445501, 0x1.f0de784f0622ap-53}, {4463988693531856, 0x1.ec93abdf982d2p-53},
    {4463249982500383, 0x1.e83e9337a6f04p-53}, {4462477195632267, 0x1.e3debb5d2ee02p-53},
    {4461667990089170, 0x1.df73aa9f17656p-53}, {4460819801517195, 0x1.dafce0023b8c8p-53},
    {4459929817254120, 0x1.d679d29e41f14p-53}, {4458994945550386, 0x1.d1e9f0e80b74bp-53},
    {4458011780094444, 0x1.cd4c9fe72268fp-53}, {4456976558985042, 0x1.c8a13a5323b66p-53},
    {4455885117109369, 0x1.c3e70f9594ef8p-53}, {4454732830656798, 0x1.bf1d62abf8239p-53},
    {4453514552210512, 0x1.ba4368e529f40p-53}, {4452224534496485, 0x1.b558487427a2fp-53},
    {4450856340408624, 0x1.b05b16d136ca2p-53}, {4449402736340121, 0x1.ab4ad6e101636p-53},
    {4447855565093316, 0x1.a62676d77cd5fp-53}, {4446205593658138, 0x1.a0eccdca4a731p-53},
    {4444442329865861, 0x1.9b9c98e38c54dp-53}, {4442553800234660, 0x1.96347822c1ef0p-53},
    {4440526279077424, 0x1.90b2ea94ecf9ep-53}, {4438343955930065, 0x1.8b1649e7b769fp-53},
    {4435988524278344, 0x1.855cc53430a7dp-53}, {4433438668975191, 0x1.7f845ad46f549p-53},
    {4430669422005229, 0x1.798ad10b32a7ep-53}, {4427651345409292, 0x1.736dad346f8adp-53},
    {4424349484777079, 0x1.6d2a292000576p-53}, {4420722014516421, 0x1.66bd261a37c44p-53},
    {4416718463613198, 0x1.60231cfd97ef1p-53}, {4412277362218203, 0x1.59580a707ce9cp-53},
    {4407323076021240, 0x1.52575621ad379p-53}, {4401761481783922, 0x1.4b1bb363dfeadp-53},
    {4395473957549320, 0x1.439ef8dff9b5ap-53}, {4388308869042394, 0x1.3bd9ec1a2b134p-53},
    {4380069246215645, 0x1.33c3fc05791fap-53}, {4370494503737298, 0x1.2b52e3863d885p-53},
    {4359232558744731, 0x1.227a28f7a1afap-53}, {4345795907393188, 0x1.192a69741367dp-53},
    {4329489775174550, 0x1.0f5053b025d4ap-53}, {4309289223136603, 0x1.04d32278ebbb4p-53},
    {4283617341590295, 0x1.f32482d4cd5d0p-54}, {4249917568205995, 0x1.dac2f5a747281p-54},
    {4203757248105144, 0x1.c004d2f386207p-54}, {4136731738896254, 0x1.a230c2e4cd0cbp-54},
    {4030768804392684, 0x1.801fce82fa71ap-54}, {3838760076542278, 0x1.57cb938443b71p-54},
    {3387314423973558, 0x1.250af3c2c5bc6p-54}, {0, 0x1.b8d0be3fdf702p-55},
};

const double NormalRng::kZigF[256] = {
    0x1.4a605b6b9f70dp-10, 0x1.55f9f43c1b070p-9, 0x1.08a1f03b0b205p-8, 0x1.69ea8d90cb864p-8,
    0x1.ce160f8ec683cp-8, 0x1.1a59229952f95p-7, 0x1.4eb96421acfe7p-7, 0x1.841040d8da47ep-7,
    0x1.ba48d274f8fb3p-7, 0x1.f152a4f72dd53p-7, 0x1.149033460301ap-6, 0x1.30d388dab5e1ap-6,
    0x1.4d6eaf2fbb067p-6, 0x1.6a5daf40bbf87p-6, 0x1.879d1b600c10bp-6, 0x1.a529f4e22ebf4p-6,
    0x1.c301983cd0912p-6, 0x1.e121adb828c69p-6, 0x1.ff881d718a5b5p-6, 0x1.0f1982e968009p-5,
    0x1.1e9059f1f6ab6p-5, 0x1.2e27ce83df495p-5, 0x1.3ddf2ce98eec7p-5, 0x1.4db5d0e11275cp-5,
    0x1.5dab23cf2add1p-5, 0x1.6dbe9b398d062p-5, 0x1.7defb77af271cp-5, 0x1.8e3e02a68b5a9p-5,
    0x1.9ea90f9295561p-5, 0x1.af30790385f6fp-5, 0x1.bfd3e0f282a2cp-5, 0x1.d092efeadf162p-5,
    0x1.e16d547b25185p-5, 0x1.f262c2b6c6e33p-5, 0x1.01b979e30e496p-4, 0x1.0a4ed2c159622p-4,
    0x1.12f14d0f2179dp-4, 0x1.1ba0cbe97897ep-4, 0x1.245d344dd0d8fp-4, 0x1.2d266cf9b310dp-4,
    0x1.35fc5e4d93e69p-4, 0x1.3edef23269a81p-4, 0x1.47ce1401b2212p-4, 0x1.50c9b06fa2babp-4,
    0x1.59d1b5774669dp-4, 0x1.62e6124854d10p-4, 0x1.6c06b73694a46p-4, 0x1.753395aaa116dp-4,
    0x1.7e6ca013eefccp-4, 0x1.87b1c9dbf2846p-4, 0x1.9103075a4a09fp-4, 0x1.9a604dc9d5b0bp-4,
    0x1.a3c9933ea627bp-4, 0x1.ad3ece9caf627p-4, 0x1.b6bff78f2e228p-4, 0x1.c04d0680b100ap-4,
    0x1.c9e5f493b7404p-4, 0x1.d38abb9bd91dcp-4, 0x1.dd3b56176e88bp-4, 0x1.e6f7bf29aa546p-4,
    0x1.f0bff29520e16p-4, 0x1.fa93ecb6b222bp-4, 0x1.0239d54067d29p-3, 0x1.072f94bb8bf84p-3,
    0x1.0c2b33d5209b9p-3, 0x1.112cb1da26eb8p-3, 0x1.16340e5a82d62p-3, 0x1.1b41492757d42p-3,
    0x1.2054625183c34p-3, 0x1.256d5a2835eb6p-3, 0x1.2a8c3137a071bp-3, 0x1.2fb0e847c2a65p-3,
    0x1.34db805b4ab89p-3, 0x1.3a0bfaae8d7eep-3, 0x1.3f4258b6931afp-3, 0x1.447e9c20375d6p-3,
    0x1.49c0c6cf5ce30p-3, 0x1.4f08dade31fc6p-3, 0x1.5456da9c8683bp-3, 0x1.59aac88f31d74p-3,
    0x1.5f04a76f88400p-3, 0x1.64647a2adf1a4p-3, 0x1.69ca43e21f261p-3, 0x1.6f3607e964719p-3,
    0x1.74a7c9c7ab5a8p-3, 0x1.7a1f8d368a323p-3, 0x1.7f9d5621f7174p-3, 0x1.852128a819a38p-3,
    0x1.8aab09192815ap-3, 0x1.903afbf74fa68p-3, 0x1.95d105f6a7c27p-3, 0x1.9b6d2bfd2fe5ap-3,
    0x1.a10f7322d7e3cp-3, 0x1.a6b7e0b19267cp-3, 0x1.ac667a2571805p-3, 0x1.b21b452ccd13ap-3,
    0x1.b7d647a8731abp-3, 0x1.bd9787abe18a2p-3, 0x1.c35f0b7d89d46p-3, 0x1.c92cd9971df52p-3,
    0x1.cf00f8a5e6fcap-3, 0x1.d4db6f8b2514cp-3, 0x1.dabc455c79006p-3, 0x1.e0a3816457181p-3,
    0x1.e6912b2283cd9p-3, 0x1.ec854a4c99c3ep-3, 0x1.f27fe6ce998ccp-3, 0x1.f88108cb8322fp-3,
    0x1.fe88b89df93bcp-3, 0x1.024b7f6c7747ap-2, 0x1.0555f2242e9d4p-2, 0x1.0863b8f904331p-2,
    0x1.0b74d88b242d4p-2, 0x1.0e895598709bdp-2, 0x1.11a134fcf241dp-2, 0x1.14bc7bb34ee63p-2,
    0x1.17db2ed5454e5p-2, 0x1.1afd539c2f04cp-2, 0x1.1e22ef6188113p-2, 0x1.214c079f7cc9cp-2,
    0x1.2478a1f17de86p-2, 0x1.27a8c414db11bp-2, 0x1.2adc73e963fdap-2, 0x1.2e13b77210764p-2,
    0x1.314e94d5af62dp-2, 0x1.348d125f9d19cp-2, 0x1.37cf368081376p-2, 0x1.3b1507cf143acp-2,
    0x1.3e5e8d08ed2d8p-2, 0x1.41abcd1357a18p-2, 0x1.44fccefc324fcp-2, 0x1.485199fad6ad4p-2,
    0x1.4baa357109ca2p-2, 0x1.4f06a8ebf6d91p-2, 0x1.5266fc2533beap-2, 0x1.55cb3703d00fdp-2,
    0x1.5933619d6eebcp-2, 0x1.5c9f84376c241p-2, 0x1.600fa7480d2c6p-2, 0x1.6383d377be513p-2,
    0x1.66fc11a25cbdfp-2, 0x1.6a786ad88de1ep-2, 0x1.6df8e86124ca6p-2, 0x1.717d93ba96148p-2,
    0x1.7506769c7b1e8p-2, 0x1.78939af9252e6p-2, 0x1.7c250aff414acp-2, 0x1.7fbad11b8d90dp-2,
    0x1.8354f7faa0dd5p-2, 0x1.86f38a8ac5ab2p-2, 0x1.8a9693fde9185p-2, 0x1.8e3e1fcb9f113p-2,
    0x1.91ea39b33cb13p-2, 0x1.959aedbe09f8fp-2, 0x1.995048418c0c3p-2, 0x1.9d0a55e1e93dcp-2,
    0x1.a0c923946843bp-2, 0x1.a48cbea20c04bp-2, 0x1.a85534aa4d87dp-2, 0x1.ac2293a5f5a9ap-2,
    0x1.aff4e9ea18550p-2, 0x1.b3cc462b331c8p-2, 0x1.b7a8b78071319p-2, 0x1.bb8a4d6716d8fp-2,
    0x1.bf7117c616a14p-2, 0x1.c35d26f1d2cb5p-2, 0x1.c74e8bb00d7c3p-2, 0x1.cb45573c0a843p-2,
    0x1.cf419b4ae5b69p-2, 0x1.d3436a102107bp-2, 0x1.d74ad6426de2dp-2, 0x1.db57f320b56abp-2,
    0x1.df6ad47763a03p-2, 0x1.e3838ea5f9b7ep-2, 0x1.e7a236a4ec3bfp-2, 0x1.ebc6e20bd1f4fp-2,
    0x1.eff1a717e8f8ep-2, 0x1.f4229cb2f7aecp-2, 0x1.f859da7a900c4p-2, 0x1.fc9778c7bbd9bp-2,
    0x1.006dc85b8cac2p-1, 0x1.02931e18b8228p-1, 0x1.04bbcafa63f2bp-1, 0x1.06e7dccf03c33p-1,
    0x1.091761d995d7dp-1, 0x1.0b4a68d70d9abp-1, 0x1.0d8101041429cp-1, 0x1.0fbb3a232590fp-1,
    0x1.11f9248311f34p-1, 0x1.143ad105ea998p-1, 0x1.16805128639d6p-1, 0x1.18c9b709b3c4dp-1,
    0x1.1b171573fd10ep-1, 0x1.1d687fe549966p-1, 0x1.1fbe0a992961dp-1, 0x1.2217ca92ff7eep-1,
    0x1.2475d5a90db80p-1, 0x1.26d84290504e9p-1, 0x1.293f28e93cd11p-1, 0x1.2baaa14d79545p-1,
    0x1.2e1ac55ea3beap-1, 0x1.308fafd6438ebp-1, 0x1.33097c9703a32p-1, 0x1.358848bf550e6p-1,
    0x1.380c32bda00d2p-1, 0x1.3a955a662cd0bp-1, 0x1.3d23e10af31a1p-1, 0x1.3fb7e99585b7fp-1,
    0x1.425198a355fe0p-1, 0x1.44f114a493676p-1, 0x1.479685fdf500fp-1, 0x1.4a42172dc5276p-1,
    0x1.4cf3f4f494ebep-1, 0x1.4fac4e820b665p-1, 0x1.526b55a656cd3p-1, 0x1.55313f08d9e44p-1,
    0x1.57fe4264c8d8cp-1, 0x1.5ad29acc85c85p-1, 0x1.5dae86f4aff66p-1, 0x1.6092498802661p-1,
    0x1.637e298550c15p-1, 0x1.667272a92e320p-1, 0x1.696f75e513b26p-1, 0x1.6c7589e635a86p-1,
    0x1.6f850baea7aebp-1, 0x1.729e5f43f6d0ep-1, 0x1.75c1f0770d852p-1, 0x1.78f033ca0b0d2p-1,
    0x1.7c29a779c6855p-1, 0x1.7f6ed4b20e2c8p-1, 0x1.82c050f56cf6bp-1, 0x1.861ebfc37bca8p-1,
    0x1.898ad48badefep-1, 0x1.8d0554fe60aa4p-1, 0x1.908f1bd31714bp-1, 0x1.94291c21b7a43p-1,
    0x1.97d4657617abep-1, 0x1.9b9228d24067ep-1, 0x1.9f63bee651fd5p-1, 0x1.a34aafdf5af0cp-1,
    0x1.a748bd550c9dep-1, 0x1.ab5fef17a2502p-1, 0x1.af92a3f6ce8a0p-1, 0x1.b3e3a8234dd0ep-1,
    0x1.b85653a8ff54fp-1, 0x1.bceeb4ee1dc7fp-1, 0x1.c1b1cd9eebae7p-1, 0x1.c6a5ecea9787cp-1,
    0x1.cbd33a8a72de8p-1, 0x1.d144978a119d9p-1, 0x1.d70920657bcefp-1, 0x1.dd36fa704de92p-1,
    0x1.e3f11e027f074p-1, 0x1.eb7545b6ca912p-1, 0x1.f446ac979f084p-1, 0x1.0000000000000p+0,
};

namespace {
constexpr double kZigR = 0x1.d3bb48209ad33p+1;  // r = 3.6541528853610088, x_0

inline uint64_t splitmix64(uint64_t& x) noexcept {
  uint64_t z = (x += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}
}  // namespace

void NormalRng::seed_with(uint64_t seed) noexcept {
  uint64_t x = seed;
  for (auto& s : s_) s = splitmix64(x);
}

double NormalRng::normal_slow(uint64_t u) noexcept {
  for (;;) {
    const unsigned i = static_cast<unsigned>(u & 0xFF);
    const int64_t a = static_cast<int64_t>(u >> 12);
    const double sign = (u & 0x100) != 0 ? -1.0 : 1.0;
    if (a < kZigLayers[i].k) return sign * (static_cast<double>(a) * kZigLayers[i].w);
    if (i == 0) {
      // Tail x > r (Marsaglia 1964): t ~ Exp(r), accepted with probability exp(-t^2 / 2), gives
      // r + t with density proportional to exp(-(r + t)^2 / 2). Uniforms in (0, 1]: log is finite.
      double t, e;
      do {
        t = -std::log(static_cast<double>((next_u64() >> 11) + 1) * 0x1.0p-53) / kZigR;
        e = -std::log(static_cast<double>((next_u64() >> 11) + 1) * 0x1.0p-53);
      } while (e + e < t * t);
      return sign * (kZigR + t);
    }
    // Wedge of layer i: x in [x_i, x_{i-1}); a height uniform in [f(x_{i-1}), f(x_i)] under f(x)
    // accepts it. Otherwise start afresh with a new layer.
    const double x = static_cast<double>(a) * kZigLayers[i].w;
    const double y = kZigF[i - 1] + uniform() * (kZigF[i] - kZigF[i - 1]);
    if (y < std::exp(-0.5 * x * x)) return sign * x;
    u = next_u64();
  }
}

}  // namespace lugrip
