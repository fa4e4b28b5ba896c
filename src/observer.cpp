#include "lugrip/observer.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <stdexcept>
#include <string>

#include "field_checks.hpp"
#include "format.hpp"

#if defined(__GNUC__)
#define LUGRIP_OBSERVER_INLINE __attribute__((always_inline))
#else
#define LUGRIP_OBSERVER_INLINE
#endif

namespace lugrip {

namespace {
constexpr double kTwoPi = 6.28318530717958647692;

const ObserverSettings& checked(const ObserverSettings& s) {
  std::string msg;
  if (!validate(s, &msg)) throw std::invalid_argument("invalid ObserverSettings:\n" + msg);
  return s;
}

inline double clip(double v, double bound) noexcept { return v > bound ? bound : (v < -bound ? -bound : v); }
}  // namespace

const char* to_string(GainMode m) noexcept {
  const int k = static_cast<int>(m);
  return k >= 0 && k < static_cast<int>(std::size(kGainModeNames)) ? kGainModeNames[k] : "unknown";
}

bool validate(const ObserverSettings& s, std::string* message) { return detail::validate_fields(s, message); }

std::string to_string(const ObserverSettings& s) { return detail::print_fields(s); }

namespace {
// Hysteresis band: cor_sign_sigmas standard deviations of white torque noise after the
// first-order low-pass at the nominal rate (variance ratio alpha / (2 - alpha)).
// Coefficient of the first-order low-pass of the CoR inputs over a step h.
double filter_alpha(const ObserverSettings& s, double h) {
  return s.torque_cutoff > 0.0 ? -std::expm1(-kTwoPi * s.torque_cutoff * h) : 1.0;
}
double sign_band(const ObserverSettings& s) {
  const double alpha = filter_alpha(s, s.dt);
  return s.cor_sign_sigmas * s.torque_noise * std::sqrt(alpha / (2.0 - alpha));
}
}  // namespace

Observer::Observer(const ContactParams& params, const ObserverSettings& settings)
    : cor_(params, checked(settings).cor),
      s_(settings),
      sign_band_(sign_band(settings)),
      alpha_dt_(filter_alpha(settings, settings.dt)) {
  reset();
}

Observer::Observer(const ContactModel& model, const ObserverSettings& settings)
    : cor_(model, checked(settings).cor),
      s_(settings),
      sign_band_(sign_band(settings)),
      alpha_dt_(filter_alpha(settings, settings.dt)) {
  reset();
}

void Observer::reset() noexcept {
  cor_.reset();
  z_ = 0.0;
  omega_ = 0.0;
  tau_f_ = 0.0;
  ft_f_ = 0.0;
  cor_sign_ = 1.0;
  pending_ = 0.0;
  invalid_run_ = 0;
  need_init_ = true;
  kinetic_ = false;
  last_ = ObserverOutput();
}

Status Observer::reject(double dt, ObserverOutput& out) noexcept {
  // State untouched; the skipped time is integrated with the next valid sample (or, beyond
  // max_dt_gap, causes a re-initialisation).
  pending_ = std::min(pending_ + dt, 1.0e9);
  if (invalid_run_ < s_.max_invalid) ++invalid_run_;
  out = last_;
  out.substeps = 0;
  out.cor_iterations = 0;
  out.diverged = false;
  out.substeps_capped = false;
  if (invalid_run_ >= s_.max_invalid) {
    need_init_ = true;
    return out.status = Status::SensorFault;
  }
  return out.status = Status::InvalidSample;
}

namespace {
// omega_object and v_slip from omega_hat about the clipped CoR (a = |c~|) and the unclipped
// estimate a_u >= a (ObserverOutput, header).
inline void unclipped_slip(double omega_hat, double a, double a_u, double rho, double& omega_object,
                           double& v_slip) noexcept {
  if (!(a_u > a)) {
    omega_object = omega_hat;
    v_slip = std::fabs(omega_hat) * a * rho;
    return;
  }
  const double k = a * a + 0.5;
  omega_object = omega_hat * (k / (a * a_u + 0.5));
  v_slip = std::fabs(omega_hat) * rho * (k / (a + 0.5 / a_u));
}
}  // namespace

Status Observer::step(const ObserverInput& in, ObserverOutput& out) noexcept {
  const CorSettings& cs = s_.cor;
  const double dt = in.dt == 0.0 ? s_.dt : in.dt;
  const bool dt_ok = std::isfinite(dt) && dt > 0.0;
  const bool valid = dt_ok && std::isfinite(in.f_n) && std::isfinite(in.f_t) && std::isfinite(in.tau) &&
                     std::fabs(in.f_n) <= cs.force_limit && std::fabs(in.f_t) <= cs.force_limit &&
                     std::fabs(in.tau) <= cs.torque_limit;
  if (!valid) return reject(dt_ok ? dt : s_.dt, out);
  const double h = pending_ + dt;

  if (!(in.f_n >= cs.f_n_min)) {  // contact lost: forget the state, show it
    invalid_run_ = 0;
    pending_ = 0.0;
    need_init_ = true;
    ObserverOutput r = last_;
    r.omega_hat = 0.0;
    r.omega_state = 0.0;
    r.kinetic = false;
    r.z_hat = 0.0;
    r.S = 0.0;
    r.y = 0.0;
    r.omega_object = 0.0;
    r.v_slip = 0.0;
    r.projected = r.diverged = r.substeps_capped = false;
    r.substeps = 0;
    r.cor_iterations = 0;
    r.status = Status::NoContact;
    last_ = r;
    out = r;
    return r.status;
  }
  // Everything below is computed in locals and committed only when the sample is usable: a
  // sample whose CoR or outputs cannot be computed (InvalidSample) leaves the state as it was.
  const bool init = need_init_ || h > s_.max_dt_gap;

  // (1) CoR from the low-pass filtered torque with sign hysteresis; raw torque for y.
  bool flipped = false;
  double tau_f, ft_f, side = cor_sign_, z0 = z_, w0 = omega_;
  if (init) {
    tau_f = in.tau;
    ft_f = in.f_t;
    side = in.tau < 0.0 ? -1.0 : 1.0;
  } else {
    // at the nominal period the coefficient computed at construction (the same value)
    const double alpha = h == s_.dt ? alpha_dt_ : filter_alpha(s_, h);
    tau_f = tau_f_ + alpha * (in.tau - tau_f_);
    ft_f = ft_f_ + alpha * (in.f_t - ft_f_);
    if (std::fabs(tau_f) > sign_band_) {
      const double next = tau_f < 0.0 ? -1.0 : 1.0;
      // The CoR changes side: the torque about it, y = tau - c f_t, changes sign with c (for a
      // translation-dominated load almost entirely). The state is the friction about the CoR, so
      // mirror it: S stays continuous instead of dropping to 0 while z_hat crosses zero.
      if (next != side) {
        z0 = -z0;
        w0 = -w0;
        flipped = true;
      }
      side = next;
    }
  }
  const double tau_cor = std::copysign(std::fabs(tau_f), side);
  CorOutput& co = co_;  // every field is written by evaluate()
  const double ft_cor = s_.filter_force ? ft_f : in.f_t;
  if (init) cor_.reset();  // a twin that never saw a rejected sample re-initialises here too
  const Status cor_status = cor_.evaluate(CorInput{in.f_n, ft_cor, tau_cor}, co);
  if (!is_valid(cor_status)) return reject(dt, out);

  // (2) g, sigma_1, y at this sample.
  const ContactParams& p = cor_.model().params();
  RotorCoefficients rc;
  rc.sigma0 = p.sigma0;
  rc.sigma_z = p.sigma_z;
  rc.sigma_1 = co.sigma_1;
  rc.g = std::max(co.g, s_.g_floor);
  // Friction ratios (static_ratio, kinetic_ratio not both 1, docs/model.md 7.5): in stick the
  // update and S use the static capacity static_ratio g; once the friction about the CoR has
  // reached kBreakawayLevel of the sliding level kinetic_ratio g (a slip could now be under way
  // and would not stop), the update uses g and S that sliding level, until the friction falls
  // below kStickRelease of it. The mode of a sample is decided from the state it
  // starts from, so one capacity holds over the whole update.
  const bool ratios = p.static_ratio != 1.0 || p.kinetic_ratio != 1.0;
  bool kinetic = false;
  double s_capacity = 1.0;  // S's capacity over the update's g
  if (ratios) {
    if (!init) {
      const double load = p.sigma0 * std::fabs(z0) / rc.g;  // friction about the CoR over g
      kinetic = load >= (kinetic_ ? kStickRelease : kBreakawayLevel) * p.kinetic_ratio;
    }
    if (kinetic) {
      s_capacity = p.kinetic_ratio;
      if (p.stribeck_speed > 0.0) {
        // Stribeck capacity: from static_ratio g at rest to g at speed, with the RMS sliding
        // speed over the patch from the speed state at the start of the sample (restated about
        // the unclipped CoR, as omega_object); S stays judged against kinetic_ratio g
        double w_obj = 0.0, v_unused = 0.0;
        const double a_u = std::fabs(co.c_tilde_unclipped);
        unclipped_slip(w0, std::fabs(co.c_tilde), a_u, co.rho, w_obj, v_unused);
        const double v = std::fabs(w_obj) * co.rho * std::sqrt(a_u * a_u + 0.5) / p.stribeck_speed;
        const double factor = 1.0 + (p.static_ratio - 1.0) * std::exp(-v * v);
        rc.g *= factor;
        s_capacity /= factor;
      }
    } else {
      rc.g *= p.static_ratio;
    }
  }
  rc.drive = in.tau - co.c * in.f_t;
  if (s_.gain_mode == GainMode::Fixed) {
    rc.gain = s_.gain;
  } else {
    const double l = co.sigma_1 > 0.0 ? s_.bandwidth / co.sigma_1 : s_.gain_max;
    rc.gain = std::min(std::max(l, s_.gain_min), s_.gain_max);
  }
  const double bound = rc.g / rc.sigma0;

  // (3)-(4) update and projection, or (re)initialisation.
  bool projected = false, diverged = false, capped = false;
  int substeps = 0;
  Status status = cor_status;
  double z = z0, w = w0;
  if (init) {
    z = clip(rc.drive / rc.sigma0, bound);
    w = 0.0;
    status = Status::Reinitialized;
  } else {
    projected = rotor_advance(z, w, h, rc, s_.integrator, s_.substeps, s_.max_substeps, &substeps, &capped);
    if (!(std::isfinite(z) && std::isfinite(w) && std::fabs(w) <= s_.omega_limit)) {
      diverged = true;
      projected = false;
      z = clip(rc.drive / rc.sigma0, bound);
      w = 0.0;
      status = Status::Reinitialized;
    }
  }
  const double S = std::min(p.sigma0 * std::fabs(z) / (ratios ? s_capacity * rc.g : rc.g), 1.0);
  const double omega_resolution =
      co.sigma_1 > 0.0 ? std::min(s_.torque_noise / co.sigma_1, std::numeric_limits<double>::max())
                       : (s_.torque_noise > 0.0 ? std::numeric_limits<double>::max() : 0.0);
  const bool observable = omega_resolution <= s_.resolution_max;
  // omega_hat is reported up to kOmegaReportFactor x resolution_max, 0 beyond (header)
  const bool report = omega_resolution <= kOmegaReportFactor * s_.resolution_max;
  double omega_object = 0.0, v_slip = 0.0;
  unclipped_slip(w, std::fabs(co.c_tilde), std::fabs(co.c_tilde_unclipped), co.rho, omega_object, v_slip);
  if (!(std::isfinite(z) && std::isfinite(S) && std::isfinite(rc.drive) && std::isfinite(bound) &&
        std::isfinite(rc.gain) && std::isfinite(omega_object) && std::isfinite(v_slip)))
    return reject(dt, out);

  // Commit.
  cor_.commit(co);
  z_ = z;
  omega_ = w;
  tau_f_ = tau_f;
  ft_f_ = ft_f;
  cor_sign_ = side;
  pending_ = 0.0;
  invalid_run_ = 0;
  need_init_ = false;
  kinetic_ = kinetic && status != Status::Reinitialized;
  // Written field by field to last_ and out, inline (no zero-initialised temporary, no struct
  // copy: the compiler makes that a byte-wise string move).
  auto fill = [&](ObserverOutput& r) LUGRIP_OBSERVER_INLINE {
    r.omega_hat = report ? omega_ : 0.0;
    r.omega_state = omega_;
    r.kinetic = kinetic_;
    r.z_hat = z_;
    r.S = S;
    r.c_tilde = co.c_tilde;
    r.c = co.c;
    r.g = rc.g;
    r.sigma_1 = co.sigma_1;
    r.y = rc.drive;
    r.tau_cor = tau_cor;
    r.ft_cor = ft_cor;
    r.gain = rc.gain;
    r.omega_resolution = omega_resolution;
    r.speed_observable = observable;
    r.inside = co.inside;
    r.saturated = co.saturated;
    r.projected = projected;
    r.cor_side_flipped = flipped;
    r.diverged = diverged;
    r.substeps_capped = capped;
    r.substeps = substeps;
    r.cor_iterations = co.iterations;
    r.status = status;
    r.c_tilde_unclipped = co.c_tilde_unclipped;
    r.omega_object = report ? omega_object : 0.0;
    r.v_slip = report ? v_slip : 0.0;
  };
  fill(last_);
  fill(out);
  return status;
}

}  // namespace lugrip

#undef LUGRIP_OBSERVER_INLINE
