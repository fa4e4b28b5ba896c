// lugrip — the settings a user sets, each field described once: name, unit, valid range, one
// doc line (the default is the struct's own initialiser). validate() and to_string() of these
// structs, the Python bindings (`fields`, `params`, `rules`), the parameter-file loader, the fuzz
// campaign and the documentation tables (docs/conventions.md, README.md; lugrip._field_docs)
// iterate over these tables. Bounds that involve another field are Rule entries.
#pragma once

#include <cmath>
#include <tuple>

#include "lugrip/contact.hpp"
#include "lugrip/detail/field_table.hpp"
#include "lugrip/grasp_controller_fields.hpp"
#include "lugrip/identification.hpp"
#include "lugrip/limit_surface.hpp"
#include "lugrip/observer.hpp"
#include "lugrip/params.hpp"
#include "lugrip/slider_model.hpp"
#include "lugrip/slip_control.hpp"

namespace lugrip {

//! Names of the enumerations' values, indexed by value (the parameter files' spelling).
inline constexpr const char* kIntegratorNames[] = {"implicit", "rk4", "rk4_adaptive", "rosenbrock"};
inline constexpr const char* kGainModeNames[] = {"fixed", "bandwidth"};
inline constexpr const char* kIdLossNames[] = {"squared", "huber"};

//! FieldTable<S>::name, ::fields (Field or Param entries, in the struct's order) and ::rules.
template <class S>
struct FieldTable;

template <>
struct FieldTable<ContactParams> {
  using S = ContactParams;
  static constexpr const char* name = "ContactParams";
  static constexpr auto fields = std::make_tuple(
      detail::param("mu", &S::mu, "-", detail::gt(0.0), detail::le(10.0),
                    "friction coefficient of the limit surface (fitted to gross sliding)"),
      detail::param("beta_a", &S::beta_a, "N s/m^3", detail::ge(0.0), detail::none(),
                    "viscous friction per unit area and speed (the paper prints Ns/m)"),
      detail::param("sigma0", &S::sigma0, "N m/rad", detail::ge(1e-12), detail::none(),
                    "micro-asperity (bristle) stiffness; the lower bound keeps g / sigma0 finite"),
      detail::param("sigma_z", &S::sigma_z, "N m s/rad", detail::ge(0.0), detail::none(),
                    "micro-asperity (bristle) damping"),
      detail::param("delta", &S::delta, "m/N^gamma", detail::gt(0.0), detail::lt(1.0),
                    "contact-radius law rho = delta f_n^gamma"),
      detail::param("gamma", &S::gamma, "-", detail::gt(0.0), detail::lt(1.0 / 3.0, "1/3"),
                    "contact-radius exponent"),
      detail::param("k", &S::k, "-", detail::ge(kMinPressureExponent),
                    detail::le(std::numeric_limits<double>::infinity()),
                    "pressure exponent p ~ (1 - (r/rho)^k)^(1/k): 2 Hertz, 4 the paper, inf uniform")
          .or_value(kEllipticLimitSurface, "0 (the elliptic limit surface, docs/model.md 3.5)"),
      detail::param("c_max", &S::c_max, "-", detail::gt(0.0), detail::le(1.0e3),
                    "saturation of the normalized CoR |c~| (paper: 1.5)"),
      detail::param("static_ratio", &S::static_ratio, "-", detail::ge(kMinFrictionRatio), detail::le(kMaxFrictionRatio),
                    "break-away friction over mu, mu_s / mu: S's capacity in stick (1: the paper)"),
      detail::param("kinetic_ratio", &S::kinetic_ratio, "-", detail::ge(kMinFrictionRatio),
                    detail::le(kMaxFrictionRatio),
                    "sliding friction level over mu, mu_k / mu: S's capacity once sliding (1: the paper)"),
      detail::param("stribeck_speed", &S::stribeck_speed, "m/s", detail::ge(0.0), detail::le(kMaxStribeckSpeed),
                    "Stribeck speed of the sliding update's capacity, falling from static_ratio g at rest to g "
                    "at speed (0: none, the update uses g once sliding)"));
  static constexpr auto rules = std::make_tuple(detail::Rule<S>{
      "static_ratio", [](const S& p) { return p.static_ratio; },
      [](const S& p) {
        const auto in = [](double r) { return r >= kMinFrictionRatio && r <= kMaxFrictionRatio; };
        return !(in(p.static_ratio) && in(p.kinetic_ratio)) || p.static_ratio >= p.kinetic_ratio;
      },
      "must be >= kinetic_ratio (static friction is not below kinetic)"});
};

template <>
struct FieldTable<CorSettings> {
  using S = CorSettings;
  static constexpr const char* name = "CorSettings";
  static constexpr auto fields = std::make_tuple(
      detail::param("f_n_min", &S::f_n_min, "N", detail::gt(0.0), detail::none(),
                    "below this normal force the sample is NoContact (paper's code: 0.03)"),
      detail::param("force_limit", &S::force_limit, "N", detail::gt(0.0), detail::none(),
                    "|f_n| or |f_t| above this: InvalidSample (sensor range)"),
      detail::param("torque_limit", &S::torque_limit, "N m", detail::gt(0.0), detail::none(),
                    "|tau| above this: InvalidSample (sensor range)"),
      detail::param("zero_force", &S::zero_force, "-", detail::gt(0.0), detail::none(),
                    "|f~_t| below this counts as zero: pure rotation, c~ = 0"),
      detail::param("zero_torque", &S::zero_torque, "-", detail::gt(0.0), detail::none(),
                    "|tau~| below this counts as zero: |c~| = c_max, previous side kept"));
  static constexpr auto rules = std::tuple<>();
};

namespace detail {
constexpr bool within(double v, double lo, double hi) { return v > lo && v <= hi; }
inline bool cor_valid(const ObserverSettings& s) { return validate(s.cor, nullptr); }
}  // namespace detail

template <>
struct FieldTable<ObserverSettings> {
  using S = ObserverSettings;
  static constexpr const char* name = "ObserverSettings";
  static constexpr auto fields = std::make_tuple(
      detail::param("dt", &S::dt, "s", detail::ge(1e-9), detail::le(10.0),
                    "nominal sample period, used when ObserverInput::dt == 0"),
      detail::choice("integrator", &S::integrator, kIntegratorNames, "discretisation (Integrator)"),
      detail::choice("gain_mode", &S::gain_mode, kGainModeNames,
                     "observer gain: fixed (gain) or bandwidth (bandwidth / sigma_1, clipped)"),
      detail::param("gain", &S::gain, "1/(kg m^2)", detail::gt(0.0), detail::le(1e15), "l in fixed mode"),
      detail::param("bandwidth", &S::bandwidth, "1/s", detail::gt(0.0), detail::le(1e9),
                    "B = l sigma_1 in bandwidth mode: the sliding convergence rate"),
      detail::param("gain_min", &S::gain_min, "1/(kg m^2)", detail::gt(0.0), detail::le(1e15),
                    "lower clip of l in bandwidth mode"),
      detail::param("gain_max", &S::gain_max, "1/(kg m^2)", detail::gt(0.0), detail::le(1e15),
                    "upper clip of l in bandwidth mode"),
      detail::param("g_floor", &S::g_floor, "N m", detail::gt(0.0), detail::le(1.0), "lower bound on g"),
      detail::param("torque_cutoff", &S::torque_cutoff, "Hz", detail::ge(0.0), detail::le(1e9),
                    "first-order low-pass of the torque used for the CoR only (0: off); y uses the raw torque"),
      detail::flag("filter_force", &S::filter_force,
                   "also low-pass f_t for the CoR, so a proportional load ramp keeps its CoR"),
      detail::param("cor_sign_sigmas", &S::cor_sign_sigmas, "-", detail::ge(0.0), detail::le(1e3),
                    "CoR side hysteresis: the side changes when the filtered torque exceeds this many "
                    "standard deviations of its noise with the other sign"),
      detail::param("max_invalid", &S::max_invalid, "samples", detail::ge(1), detail::le(1000000),
                    "consecutive invalid samples before SensorFault"),
      detail::param("max_dt_gap", &S::max_dt_gap, "s", detail::gt(0.0), detail::le(10.0),
                    "longer gaps re-initialise instead of being integrated across"),
      detail::param("torque_noise", &S::torque_noise, "N m", detail::ge(0.0), detail::none(),
                    "torque noise std of the sensor (omega_resolution, CoR side hysteresis)"),
      detail::param("resolution_max", &S::resolution_max, "rad/s", detail::gt(0.0), detail::le(1e6),
                    "speed_observable when omega_resolution <= this"),
      detail::param("omega_limit", &S::omega_limit, "rad/s", detail::gt(0.0), detail::le(1e6),
                    "divergence guard: a larger |omega_hat| re-initialises"),
      detail::param("substeps", &S::substeps, "-", detail::ge(1), detail::none(),
                    "(minimum) equal substeps per sample, every scheme"),
      detail::param("max_substeps", &S::max_substeps, "-", detail::ge(1), detail::le(kMaxObserverSubsteps),
                    "cap of adaptive substeps (rk4_adaptive, rosenbrock) per sample"),
      detail::nested("cor", &S::cor, "CoR estimator settings (CorSettings), narrower inside an observer"));
  static constexpr auto rules = std::make_tuple(
      detail::Rule<S>{"gain_max", [](const S& s) { return s.gain_max; },
                      [](const S& s) {
                        return !(detail::within(s.gain_min, 0.0, 1e15) && detail::within(s.gain_max, 0.0, 1e15)) ||
                               s.gain_min <= s.gain_max;
                      },
                      "must be >= gain_min"},
      detail::Rule<S>{"max_dt_gap", [](const S& s) { return s.max_dt_gap; },
                      [](const S& s) { return !(s.max_dt_gap < s.dt); },
                      "must be >= dt [s]"},
      detail::Rule<S>{"torque_noise", [](const S& s) { return s.torque_noise; },
                      [](const S& s) {
                        return !(std::isfinite(s.cor.torque_limit) && s.cor.torque_limit > 0.0) ||
                               !(s.torque_noise > s.cor.torque_limit);
                      },
                      "must be <= cor.torque_limit [N m]"},
      detail::Rule<S>{"resolution_max", [](const S& s) { return s.resolution_max; },
                      [](const S& s) { return !detail::within(s.omega_limit, 0.0, 1e6) || !(s.resolution_max > s.omega_limit); },
                      "must be <= omega_limit [rad/s]"},
      detail::Rule<S>{"max_substeps", [](const S& s) { return static_cast<double>(s.max_substeps); },
                      [](const S& s) {
                        return !(s.substeps >= 1 && s.max_substeps >= 1 && s.max_substeps <= kMaxObserverSubsteps) ||
                               s.substeps <= s.max_substeps;
                      },
                      "must be >= substeps"},
      // Narrower than the estimator alone accepts: keeps |y|, g / sigma0 and v_slip finite.
      detail::Rule<S>{"cor.f_n_min", [](const S& s) { return s.cor.f_n_min; },
                      [](const S& s) { return !detail::cor_valid(s) || s.cor.f_n_min >= kMinContactForce; },
                      "must be >= 1e-06 [N] in an observer"},
      detail::Rule<S>{"cor.force_limit", [](const S& s) { return s.cor.force_limit; },
                      [](const S& s) { return !detail::cor_valid(s) || s.cor.force_limit <= kMaxForceLimit; },
                      "must be <= 1e+09 [N] in an observer"},
      detail::Rule<S>{"cor.torque_limit", [](const S& s) { return s.cor.torque_limit; },
                      [](const S& s) { return !detail::cor_valid(s) || s.cor.torque_limit <= kMaxForceLimit; },
                      "must be <= 1e+09 [N m] in an observer"},
      detail::Rule<S>{"cor.f_n_min", [](const S& s) { return s.cor.f_n_min; },
                      [](const S& s) {
                        return !(detail::cor_valid(s) && s.cor.f_n_min >= kMinContactForce && s.cor.force_limit <= kMaxForceLimit) ||
                               s.cor.f_n_min < s.cor.force_limit;
                      },
                      "must be < cor.force_limit"});
};

template <>
struct FieldTable<SliderSettings> {
  using S = SliderSettings;
  static constexpr const char* name = "SliderSettings";
  static constexpr auto fields = std::make_tuple(
      detail::choice("integrator", &S::integrator, kIntegratorNames,
                     "discretisation of the slider (rk4 only stable for slow, non-stiff cases)"),
      detail::param("max_substep", &S::max_substep, "s", detail::gt(0.0), detail::none(),
                    "every step() takes at least ceil(dt / max_substep) equal substeps"),
      detail::param("max_substeps", &S::max_substeps, "-", detail::ge(1), detail::none(),
                    "cap on substeps per step()"),
      detail::param("g_floor", &S::g_floor, "N m", detail::gt(0.0), detail::none(), "lower bound on g (tiny f_n)"));
  static constexpr auto rules = std::tuple<>();
};

template <>
struct FieldTable<IdentificationSettings> {
  using S = IdentificationSettings;
  static constexpr const char* name = "IdentificationSettings";
  static constexpr auto fields = std::make_tuple(
      detail::nested("observer", &S::observer,
                     "the online observer's settings: the cost runs exactly this observer (ObserverSettings)"),
      detail::choice("loss", &S::loss, kIdLossNames, "loss of the residuals (IdLoss)"),
      detail::param("huber_scale", &S::huber_scale, "rad/s", detail::gt(0.0), detail::none(),
                    "residual where the Huber loss turns linear"),
      detail::param("threads", &S::threads, "-", detail::ge(0), detail::none(),
                    "worker threads over segments (0: all cores)"),
      detail::param("sensitivity_limit", &S::sensitivity_limit, "-", detail::gt(0.0), detail::none(),
                    "chattering guard: a state sensitivity beyond this many times its scale (per unit "
                    "log-parameter; omega: the segment's largest |omega|, z: g / sigma0) restarts the "
                    "sensitivities"));
  static constexpr auto rules = std::tuple<>();
};

template <>
struct FieldTable<SlipControlSettings> {
  using S = SlipControlSettings;
  static constexpr const char* name = "SlipControlSettings";
  static constexpr auto fields = std::make_tuple(
      detail::nested("observer", &S::observer, "settings of each finger's observer (ObserverSettings)"),
      detail::nested("controller", &S::controller, "settings of the grasp controller (GraspControllerSettings)"),
      detail::param("fingers", &S::fingers, "-", detail::ge(1), detail::le(2), "fingertips measured"),
      detail::param("stuck_samples", &S::stuck_samples, "samples", detail::ge(0), detail::none(),
                    "a wrench repeated bit for bit this many samples is SensorFault (0: off)"),
      detail::flag("healthy_finger_fallback", &S::healthy_finger_fallback,
                   "one finger without a valid estimate: the other drives the command (off: hold)"));
  static constexpr auto rules = std::make_tuple(detail::Rule<S>{
      "observer.dt", [](const S& s) { return s.observer.dt; },
      [](const S& s) {
        const double fs = s.controller.sensor_rate, dt = s.observer.dt;
        return !(std::isfinite(fs) && fs > 0.0 && std::isfinite(dt) && dt > 0.0) || std::fabs(dt * fs - 1.0) <= 1e-9;
      },
      "must equal 1 / controller.sensor_rate", [](const S& s) { return 1.0 / s.controller.sensor_rate; }});
};

//! The grasp controller's table as it stands (grasp_controller_fields.hpp); its validate() and
//! to_string() are its own.
template <>
struct FieldTable<GraspControllerSettings> {
  static constexpr const char* name = "GraspControllerSettings";
  static constexpr auto fields = grasp_controller_fields;
  static constexpr auto rules = std::tuple<>();
};

}  // namespace lugrip
