#include "lugrip/identification.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <limits>
#include <stdexcept>
#include <string>
#include <thread>

#include "lugrip/detail/rotor_steps.hpp"

#include "field_checks.hpp"
#include "format.hpp"

namespace lugrip {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int N = kIdParams;
constexpr int kMu = static_cast<int>(IdParam::Mu);
constexpr int kBeta = static_cast<int>(IdParam::BetaA);
constexpr int kSigma0 = static_cast<int>(IdParam::Sigma0);
constexpr int kSigmaZ = static_cast<int>(IdParam::SigmaZ);
constexpr int kDelta = static_cast<int>(IdParam::Delta);
constexpr int kGamma = static_cast<int>(IdParam::Gamma);

std::string fmt(double v) { return detail::format_number(v); }

// ------------------------------------------------------------------------------------------
// Forward-mode dual number: value and derivatives with respect to the six parameters. The value
// part follows exactly the arithmetic of double, so the replica reproduces the online values.
// ------------------------------------------------------------------------------------------
struct Dual {
  double v = 0.0;
  std::array<double, N> d{};

  Dual() = default;
  Dual(double value) : v(value) {}  // NOLINT: constants promote implicitly
  static Dual param(double value, int index) {
    Dual r(value);
    r.d[index] = 1.0;
    return r;
  }
};

inline Dual operator-(const Dual& a) {
  Dual r(-a.v);
  for (int i = 0; i < N; ++i) r.d[i] = -a.d[i];
  return r;
}
inline Dual operator+(const Dual& a, const Dual& b) {
  Dual r(a.v + b.v);
  for (int i = 0; i < N; ++i) r.d[i] = a.d[i] + b.d[i];
  return r;
}
inline Dual operator-(const Dual& a, const Dual& b) {
  Dual r(a.v - b.v);
  for (int i = 0; i < N; ++i) r.d[i] = a.d[i] - b.d[i];
  return r;
}
inline Dual operator*(const Dual& a, const Dual& b) {
  Dual r(a.v * b.v);
  for (int i = 0; i < N; ++i) r.d[i] = a.d[i] * b.v + a.v * b.d[i];
  return r;
}
inline Dual operator/(const Dual& a, const Dual& b) {
  const double q = a.v / b.v;
  Dual r(q);
  const double inv = 1.0 / b.v;
  for (int i = 0; i < N; ++i) r.d[i] = (a.d[i] - q * b.d[i]) * inv;
  return r;
}
inline Dual operator+(const Dual& a, double b) {
  Dual r = a;
  r.v = a.v + b;
  return r;
}
inline Dual operator+(double a, const Dual& b) {
  Dual r = b;
  r.v = a + b.v;
  return r;
}
inline Dual operator-(const Dual& a, double b) {
  Dual r = a;
  r.v = a.v - b;
  return r;
}
inline Dual operator-(double a, const Dual& b) {
  Dual r(a - b.v);
  for (int i = 0; i < N; ++i) r.d[i] = -b.d[i];
  return r;
}
inline Dual operator*(const Dual& a, double b) {
  Dual r(a.v * b);
  for (int i = 0; i < N; ++i) r.d[i] = a.d[i] * b;
  return r;
}
inline Dual operator*(double a, const Dual& b) {
  Dual r(a * b.v);
  for (int i = 0; i < N; ++i) r.d[i] = a * b.d[i];
  return r;
}
inline Dual operator/(const Dual& a, double b) {
  Dual r(a.v / b);
  const double inv = 1.0 / b;
  for (int i = 0; i < N; ++i) r.d[i] = a.d[i] * inv;
  return r;
}
inline Dual operator/(double a, const Dual& b) { return Dual(a) / b; }
inline Dual& operator+=(Dual& a, const Dual& b) { return a = a + b; }
inline Dual& operator-=(Dual& a, const Dual& b) { return a = a - b; }

// Scalar functions of the rotor steps (lugrip/detail/rotor_steps.hpp), found by ADL.
inline double scalar_value(const Dual& x) { return x.v; }
inline Dual scalar_fabs(const Dual& x) { return x.v < 0.0 ? -x : x; }
inline Dual scalar_expm1(const Dual& x) {
  Dual r(std::expm1(x.v));
  const double e = std::exp(x.v);
  for (int i = 0; i < N; ++i) r.d[i] = e * x.d[i];
  return r;
}

// Frozen rotor coefficients as duals (RotorCoefficients with T = Dual).
struct DualCoefficients {
  Dual sigma0, sigma_z, sigma_1, g, gain, drive;
};

// The final pass of rotor_advance with the rotor steps of slider_model.cpp (the same templates,
// lugrip/detail/rotor_steps.hpp): projection, then n equal substeps each followed by the
// projection (the adaptive schemes redo a sample from its projected start with the final n).
void advance(Dual& z, Dual& omega, double h, const DualCoefficients& c, Integrator scheme, int n) {
  detail::rotor_project(z, c);
  bool projected = false;
  detail::rotor_fixed_pass(z, omega, h, std::max(n, 1), c, scheme, projected);
}

inline bool scored_status(Status s) {
  return s == Status::Ok || s == Status::Saturated || s == Status::Degenerate || s == Status::Reinitialized;
}

// Parameter derivatives of |c~| = a as the CoR estimator computes it (docs/model.md 5.2-5.4), by the
// implicit-function theorem on the equation whose root the estimator found:
//   inside:  (gamma+1) ln F(a) - ln T(a) = ln s,  s = f^(gamma+1) / t (eq. 13 first line, eq. 14)
//   outside: f - F(a) - 2 xi a (t - T(a)) = 0    (eq. 13 second line)
// with f = |f_t| / (mu f_n), t = |tau| / (mu xi delta f_n^(gamma+1)).
struct CorDerivative {
  std::array<double, N> da{};
};

// ------------------------------------------------------------------------------------------
// One segment: the online Observer for the values, the tangent replica for the derivatives.
// ------------------------------------------------------------------------------------------
struct SegmentWork {
  const IdentificationData* d;
  const IdentificationSettings* s;
  const ContactParams* p;
  bool derivatives;
  double* omega_hat;
};

struct SegmentOut {
  SegmentSums sums;
  std::array<double, N * N> gn{};
  double replica_error = 0.0;
  int64_t reinitialized = 0, diverged = 0, truncated = 0;
};

void run_segment(Observer& obs, const SegmentWork& w, int64_t begin, int64_t end, SegmentOut& out) {
  const IdentificationData& d = *w.d;
  const ObserverSettings& os = w.s->observer;
  const CorSettings& cs = os.cor;
  const ContactParams& p = *w.p;
  const LimitSurface& ls = obs.model().limit_surface();
  const double xi = ls.xi();
  const bool huber = w.s->loss == IdLoss::Huber;
  const double hs = w.s->huber_scale;

  obs.reset();
  const Dual sigma0 = Dual::param(p.sigma0, kSigma0);
  const Dual sigma_z = Dual::param(p.sigma_z, kSigmaZ);
  Dual z, omega;  // replica state (value from the Observer, derivatives propagated)
  // Sensitivity guard: scale of omega in this segment (largest |ground truth|, >= 1e-3 rad/s)
  double omega_ref = 1e-3;
  for (int64_t i = begin; i < end; ++i)
    if (std::isfinite(d.omega[i])) omega_ref = std::max(omega_ref, std::fabs(d.omega[i]));
  const double w_limit = w.s->sensitivity_limit * omega_ref;
  std::array<double, N> da_prev{};  // derivative of |c~| held by the CoR estimator
  double pending = 0.0;
  ObserverOutput o;

  for (int64_t i = begin; i < end; ++i) {
    const double dt_in = i == begin ? 0.0 : d.dt[i];
    const double z_before = obs.z_hat(), w_before = obs.omega_state();
    const Status st = obs.step(ObserverInput{d.f_n[i], d.f_t[i], d.tau[i], dt_in}, o);
    if (w.omega_hat) w.omega_hat[i] = o.omega_state;
    if (st == Status::Reinitialized) ++out.reinitialized;
    if (o.diverged) ++out.diverged;

    if (w.derivatives) {
      const double dt_eff = dt_in == 0.0 ? os.dt : dt_in;
      if (st == Status::InvalidSample || st == Status::SensorFault) {
        pending = std::min(pending + dt_eff, 1.0e9);  // state and derivatives held
      } else if (st == Status::NoContact) {
        z = Dual(0.0);
        omega = Dual(0.0);
        pending = 0.0;
      } else {
        const double h = pending + dt_eff;
        pending = 0.0;
        if (st == Status::Reinitialized) da_prev.fill(0.0);  // CorEstimator reset

        // (1) derivative of a = |c~| (the observer's CoR from the filtered wrench)
        const double f_n = d.f_n[i];
        const double a = std::fabs(o.c_tilde);
        const double sgn = o.c_tilde < 0.0 ? -1.0 : 1.0;
        const double ln_fn = std::log(f_n);
        const double rho = obs.model().rho(f_n);  // bit for bit the CorEstimator's rho
        const double f = std::fabs(o.ft_cor) / (p.mu * f_n);
        const double t = std::fabs(o.tau_cor) / (p.mu * xi * rho * f_n);
        std::array<double, N> da{};
        if (f < cs.zero_force && t < cs.zero_torque) {
          da = da_prev;  // undefined CoR: previous estimate held
        } else if (f < cs.zero_force || !(a < p.c_max) || !(a > 0.0)) {
          da.fill(0.0);  // pure rotation (a = 0) or saturated at c_max
        } else {
          const LsPoint q = ls.eval(a);
          if (o.inside) {
            // d ln s = -gamma dmu/mu + ddelta/delta + ln(f_t/mu) dgamma (f_n cancels)
            const double phi_a = (p.gamma + 1.0) * q.dF / q.F - q.dT / q.T;
            const double ln_ft_mu = std::log(std::fabs(o.ft_cor) / p.mu);
            da[kMu] = -p.gamma / p.mu / phi_a;
            da[kDelta] = 1.0 / p.delta / phi_a;
            da[kGamma] = (ln_ft_mu - std::log(q.F)) / phi_a;
          } else {
            const double h_a = -q.dF - 2.0 * xi * (t - q.T) + 2.0 * xi * a * q.dT;
            const double h_t = -2.0 * xi * a;
            // df = -f dmu/mu; dt = -t (dmu/mu + ddelta/delta + ln f_n dgamma)
            da[kMu] = -(-f / p.mu + h_t * (-t / p.mu)) / h_a;
            da[kDelta] = -(h_t * (-t / p.delta)) / h_a;
            da[kGamma] = -(h_t * (-t * ln_fn)) / h_a;
          }
          if (!(std::isfinite(da[kMu]) && std::isfinite(da[kDelta]) && std::isfinite(da[kGamma]))) da.fill(0.0);
        }
        da_prev = da;

        // (2) g, sigma_1, y, gain as duals: values from the Observer, derivatives by the chain rule
        std::array<double, N> drho{};  // d rho
        drho[kDelta] = rho / p.delta;
        drho[kGamma] = rho * ln_fn;
        const LsPoint q = ls.eval(a);
        const double G = xi * q.T + a * q.F;
        const double dG = xi * q.dT + q.F + a * q.dF;
        DualCoefficients c;
        c.sigma0 = sigma0;
        c.sigma_z = sigma_z;
        c.g = Dual(o.g);
        // friction ratios: in stick the observer's update uses static_ratio times the capacity;
        // once sliding with a Stribeck speed a factor of the speed state (its value taken from
        // the observer's capacity, its dependence on the state and on static_ratio and
        // stribeck_speed not differentiated: the gradient of those is approximate)
        double stick_factor =
            ((p.static_ratio != 1.0 || p.kinetic_ratio != 1.0) && !o.kinetic) ? p.static_ratio : 1.0;
        if (o.kinetic && p.stribeck_speed > 0.0 && p.mu * f_n * rho * G >= os.g_floor)
          stick_factor = o.g / (p.mu * f_n * rho * G);
        if (p.mu * f_n * rho * G >= os.g_floor) {
          const double unit = stick_factor * p.mu * f_n;  // g = unit rho G(a)
          for (int k = 0; k < N; ++k) c.g.d[k] = unit * (drho[k] * G + rho * dG * da[k]);
          c.g.d[kMu] += stick_factor * f_n * rho * G;
        }
        c.sigma_1 = Dual(o.sigma_1);
        {
          const double r2 = rho * rho, a2 = a * a + 0.5;
          for (int k = 0; k < N; ++k)
            c.sigma_1.d[k] = kPi * p.beta_a * (4.0 * r2 * rho * drho[k] * a2 + r2 * r2 * 2.0 * a * da[k]);
          c.sigma_1.d[kBeta] += kPi * r2 * r2 * a2;
        }
        c.drive = Dual(o.y);
        for (int k = 0; k < N; ++k) c.drive.d[k] = -d.f_t[i] * sgn * (da[k] * rho + a * drho[k]);
        c.gain = Dual(o.gain);
        if (os.gain_mode == GainMode::Bandwidth && o.sigma_1 > 0.0) {
          const double l = os.bandwidth / o.sigma_1;
          if (l > os.gain_min && l < os.gain_max)
            for (int k = 0; k < N; ++k) c.gain.d[k] = -l / o.sigma_1 * c.sigma_1.d[k];
        }

        // (3) the state update
        if (st == Status::Reinitialized) {
          Dual zi = c.drive / c.sigma0;
          detail::rotor_project(zi, c);
          z = zi;
          omega = Dual(0.0);
          z.v = o.z_hat;
        } else {
          Dual zz = z, ww = omega;
          if (o.cor_side_flipped) {  // the observer mirrored its state before the update
            zz = Dual(0.0) - zz;
            ww = Dual(0.0) - ww;
          }
          zz.v = o.cor_side_flipped ? -z_before : z_before;
          ww.v = o.cor_side_flipped ? -w_before : w_before;
          advance(zz, ww, h, c, os.integrator, o.substeps);
          const double bound = o.g / p.sigma0;
          out.replica_error = std::max(out.replica_error, std::fabs(ww.v - o.omega_state));
          out.replica_error = std::max(out.replica_error, std::fabs(zz.v - o.z_hat) / bound);
          z = zz;
          omega = ww;
          z.v = o.z_hat;
          omega.v = o.omega_state;
          // Chattering guard: where the discrete map is locally chaotic (omega_hat crossing zero
          // with a huge gain), the pathwise derivative grows without bound although the cost
          // varies smoothly on any finite scale. Restart the sensitivities there as at an
          // initialisation (a truncated gradient; counted in `truncated`).
          double sz = 0.0, sw = 0.0;
          for (int k = 0; k < N; ++k) {
            const double pk = k == kMu ? p.mu : k == kBeta ? p.beta_a : k == kSigma0 ? p.sigma0
                            : k == kSigmaZ ? p.sigma_z : k == kDelta ? p.delta : p.gamma;
            sz = std::max(sz, std::fabs(z.d[k] * pk));
            sw = std::max(sw, std::fabs(omega.d[k] * pk));
          }
          if (!(sw <= w_limit && sz <= w.s->sensitivity_limit * bound)) {
            Dual zi = c.drive / c.sigma0;
            detail::rotor_project(zi, c);
            z.d = zi.d;
            omega.d.fill(0.0);
            ++out.truncated;
          }
        }
      }
    }

    // (4) the residual
    const double target = d.omega[i];
    const double wt = d.weight[i];
    if (!(scored_status(st) && std::isfinite(target) && wt > 0.0)) continue;
    const double r = o.omega_state - target;
    SegmentSums& S = out.sums;
    S.sse += r * r;
    S.weight += wt;
    ++S.count;
    double psi_half = r, irls = 1.0;  // dloss/dr / 2 and the IRLS weight
    if (huber && std::fabs(r) > hs) {
      S.loss += wt * (2.0 * hs * std::fabs(r) - hs * hs);
      psi_half = r > 0.0 ? hs : -hs;
      irls = hs / std::fabs(r);
    } else {
      S.loss += wt * r * r;
    }
    if (w.derivatives) {
      const std::array<double, N>& J = omega.d;
      for (int k = 0; k < N; ++k) S.gradient[k] += wt * 2.0 * psi_half * J[k];
      const double c2 = 2.0 * wt * irls;
      for (int k = 0; k < N; ++k)
        for (int m = k; m < N; ++m) out.gn[k * N + m] += c2 * J[k] * J[m];
    }
  }
}

}  // namespace

bool validate(const IdentificationSettings& s, std::string* message) { return detail::validate_fields(s, message); }

std::string to_string(const IdentificationSettings& s) { return detail::print_fields(s); }

bool validate(const IdentificationData& d, std::string* message) {
  std::string msg;
  const size_t n = d.f_n.size();
  auto same = [&](const char* name, const std::vector<double>& v) {
    if (v.size() != n)
      msg += std::string(name) + " has " + std::to_string(v.size()) + " samples, f_n has " + std::to_string(n) + "\n";
  };
  same("f_t", d.f_t);
  same("tau", d.tau);
  same("dt", d.dt);
  same("omega", d.omega);
  same("weight", d.weight);
  const auto& s = d.segment_start;
  if (s.size() < 2 || s.front() != 0 || s.back() != static_cast<int64_t>(n)) {
    msg += "segment_start must start with 0, end with the sample count (" + std::to_string(n) +
           ") and hold at least one segment\n";
  } else {
    for (size_t j = 1; j < s.size(); ++j)
      if (!(s[j] > s[j - 1])) {
        msg += "segment_start[" + std::to_string(j) + "] = " + std::to_string(s[j]) +
               ": segment starts must increase strictly (no empty segment)\n";
        break;
      }
  }
  if (msg.empty()) {
    for (size_t i = 0; i < n; ++i) {
      if (!(std::isfinite(d.dt[i]) && d.dt[i] >= 0.0)) {
        msg += "dt[" + std::to_string(i) + "] = " + fmt(d.dt[i]) + ": must be finite and >= 0 [s]\n";
        break;
      }
    }
    for (size_t i = 0; i < n; ++i) {
      if (!(std::isfinite(d.weight[i]) && d.weight[i] >= 0.0)) {
        msg += "weight[" + std::to_string(i) + "] = " + fmt(d.weight[i]) + ": must be finite and >= 0\n";
        break;
      }
    }
  }
  if (message) *message = msg;
  return msg.empty();
}

IdentificationProblem::IdentificationProblem(IdentificationData data, const IdentificationSettings& settings)
    : d_(std::move(data)), s_(settings) {
  std::string msg, msg2;
  const bool ok_s = validate(s_, &msg);
  const bool ok_d = validate(d_, &msg2);
  if (!ok_s || !ok_d) throw std::invalid_argument("invalid identification problem:\n" + msg + msg2);
}

IdentificationEval IdentificationProblem::evaluate(const ContactParams& params, bool derivatives,
                                                   double* omega_hat) const {
  const ContactModel model(params);  // validates; tables depend on k and gamma
  const int64_t n_seg = static_cast<int64_t>(segments());
  std::vector<SegmentOut> outs(static_cast<size_t>(n_seg));
  const SegmentWork work{&d_, &s_, &model.params(), derivatives, omega_hat};

  int threads = s_.threads > 0 ? s_.threads : static_cast<int>(std::thread::hardware_concurrency());
  threads = static_cast<int>(std::max<int64_t>(1, std::min<int64_t>(threads, n_seg)));
  std::atomic<int64_t> next{0};
  auto worker = [&]() {
    Observer obs(model, s_.observer);
    for (int64_t j = next.fetch_add(1); j < n_seg; j = next.fetch_add(1))
      run_segment(obs, work, d_.segment_start[j], d_.segment_start[j + 1], outs[j]);
  };
  if (threads == 1) {
    worker();
  } else {
    std::vector<std::thread> pool;
    std::vector<std::exception_ptr> errors(threads);
    pool.reserve(threads);
    for (int t = 0; t < threads; ++t)
      pool.emplace_back([&, t]() {
        try {
          worker();
        } catch (...) {
          errors[t] = std::current_exception();
          next.store(n_seg);
        }
      });
    for (auto& th : pool) th.join();
    for (auto& e : errors)
      if (e) std::rethrow_exception(e);
  }

  IdentificationEval ev;
  ev.segments.resize(static_cast<size_t>(n_seg));
  double loss = 0.0;
  std::array<double, N> grad{};
  std::array<double, N * N> gn{};
  for (int64_t j = 0; j < n_seg; ++j) {
    const SegmentOut& o = outs[j];
    ev.segments[j] = o.sums;
    loss += o.sums.loss;
    ev.weight_sum += o.sums.weight;
    ev.scored += o.sums.count;
    for (int k = 0; k < N; ++k) grad[k] += o.sums.gradient[k];
    for (int k = 0; k < N * N; ++k) gn[k] += o.gn[k];
    ev.replica_error = std::max(ev.replica_error, o.replica_error);
    ev.reinitialized += o.reinitialized;
    ev.diverged += o.diverged;
    ev.truncated += o.truncated;
  }
  if (ev.weight_sum > 0.0) {
    ev.cost = loss / ev.weight_sum;
    for (int k = 0; k < N; ++k) ev.gradient[k] = grad[k] / ev.weight_sum;
    for (int k = 0; k < N; ++k)
      for (int m = k; m < N; ++m) ev.gauss_newton[k * N + m] = ev.gauss_newton[m * N + k] = gn[k * N + m] / ev.weight_sum;
  } else {
    ev.cost = std::numeric_limits<double>::quiet_NaN();
  }
  if (!derivatives) {
    ev.gradient.fill(0.0);
    ev.gauss_newton.fill(0.0);
  }
  return ev;
}

}  // namespace lugrip
