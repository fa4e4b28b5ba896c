#include "lugrip/grasp_controller.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "format.hpp"
#include "lugrip/detail/fast_math.hpp"

namespace lugrip {

namespace {

// Observer values beyond these magnitudes are treated as invalid samples (keeps every internal
// state finite: the C_d filter is stable and the PI error bounded).
constexpr double kMaxSlippage = 1.0e3;
constexpr double kMaxInput = 1.0e6;
constexpr int kCountMax = 1 << 30;  // saturation of the pivot end counter
// Grip probe (mu_probe, docs/controller.md "Friction learned").
constexpr double kProbeMinS = 0.5;        // probes only while S (against the belief) is this high
constexpr double kProbeFall = 0.02;       // ... and not falling by more than this per period
constexpr double kProbeElasticity = 0.5;  // d ln load / d ln f_n at or above: the contact slides
constexpr double kProbeSigmas = 2.0;      // ... beyond this many standard errors of the load
constexpr double kProbeStepDown = 0.7;    // the belief falls by at most 30 % per probe
constexpr double kMuFloor = 0.5;          // ... and never below half the told mu
constexpr double kProbeRise = 0.05;       // a new probe once S exceeds the highest stick answer by this
// Constants of the law that were settings until a randomized campaign showed that changing them
// did not pay (docs/controller.md §0).
constexpr double kFeedforwardSlippage = 0.9;  // S the feed-forward is solved for (the reserve: S = 1)
constexpr double kFeedforwardHorizon = 0.03;  // [s] the trend's extrapolation ahead of the command
constexpr double kFeedforwardTrend = 0.5;     // the trend is used when it asks this much more
// S at or above: the contact slides (below the 0.95 of a translational slide at the CoR clip);
// the slip reflex's threshold and the bound under which a period's load can refute a trend
constexpr double kSlidingSlippage = 0.93;
constexpr int kReflexSamples = 3;             // ... on this many samples of the period
constexpr double kReflexFactor = 1.25;        // ... raises the static part by this factor
constexpr double kOmegaDeadband = 1.0;        // C_d's dead band in the observer's speed resolutions
constexpr double kDynamicCap = kReflexFactor - 1.0;  // with the ceiling, C_d adds at most one reflex step
// Reserve learned from the pushes (docs/controller.md §8): a period-mean load that came and went
// is a push the task may repeat. Both the peak of each finger's load and the excursion learned
// from it forget with this time constant, and this share of the excursion is added to the load
// the floor holds at S = 1 (both chosen on tuning draws, docs/controller.md §8).
constexpr double kReserveHorizon = 10.0;  // [s]
constexpr double kReserveShare = 0.6;
constexpr double kReserveHeld = 0.5;  // learned only while |f_t| is at least this share of its peak
constexpr double kPivotFloorFactor = 1.1;     // pivoting floor factor x max_i |f_t,i| / mu
constexpr int kPivotEndSamples = 3;           // consecutive samples of the pivot's end test
constexpr double kPivotEndFilter = 0.2;       // [s] low-pass on mean |c~| of that test
constexpr double kPivotEndSlippage = 0.99;    // the test counts while max_i S_i is below this
constexpr double kPivotFloorTime = 1.0;       // [s] pivoting ends after this long at the floor
constexpr double kPivotTimeout = 10.0;        // [s] pivoting ends after this long
constexpr double kPivotEndCTilde = 1.0;       // ... or when the low-passed mean |c~| exceeds this (the paper's end)

// Shortest of %.15g / %.17g that reads back exactly.
std::string fmt(double v) { return detail::format_number(v); }

double clamp(double v, double lo, double hi) noexcept { return v < lo ? lo : (v > hi ? hi : v); }

// Severity for the combined sample status.
int severity(Status s) noexcept {
  switch (s) {
    case Status::SensorFault: return 3;
    case Status::InvalidSample: return 2;
    case Status::NoContact: return 1;
    default: return 0;
  }
}

bool finger_valid(const FingerInput& f) noexcept {
  return is_valid(f.status) && std::isfinite(f.omega_hat) && std::fabs(f.omega_hat) <= kMaxInput &&
         std::isfinite(f.slippage) && f.slippage >= 0.0 && f.slippage <= kMaxSlippage &&
         std::isfinite(f.c_tilde) && std::fabs(f.c_tilde) <= kMaxInput && std::isfinite(f.f_t) &&
         std::fabs(f.f_t) <= kMaxInput && std::isfinite(f.omega_resolution) && f.omega_resolution >= 0.0;
}

const GraspControllerSettings& checked(const GraspControllerSettings& s) {
  std::string msg;
  if (!validate(s, &msg)) throw std::invalid_argument("invalid GraspControllerSettings:\n" + msg);
  return s;
}

}  // namespace

// --- settings --------------------------------------------------------------------------------

bool validate(const GraspControllerSettings& s, std::string* message) {
  // Bounds that keep every internal value finite for any input step() accepts (|S| <= 1e3,
  // |omega_hat| <= 1e6); derivation in docs/reliability.md §1.
  constexpr double kRateMin = 1.0e-3, kRateMax = 1.0e9;  // [Hz] sensor_rate
  constexpr int kRatioMax = 1000000;                     // command_ratio
  constexpr double kGainMax = 1.0e9;                     // k_cd [N s/rad], k_p [N], k_i [N/s]
  constexpr double kPoleMin = 1.0e-9, kCornerMax = 1.0e12;  // [rad/s] p_cd, z_cd
  constexpr double kForceMin = 1.0e-6, kForceMax = 1.0e6;   // [N] f_min, f_max, gain_force
  constexpr double kPivotMax = 1.0e3;                    // s_pivot (slippage inputs are <= 1e3)
  constexpr double kSlippageMin = 1.0e-3;                // s_ref
  std::string msg;
  auto bad = [&](const char* name, double v, const std::string& rule) {
    msg += std::string(name) + " = " + fmt(v) + ": " + rule + "\n";
  };
  auto positive = [&](const char* name, double v) {
    if (!(std::isfinite(v) && v > 0.0)) bad(name, v, "must be finite and > 0");
  };
  auto positive_or_inf = [&](const char* name, double v) {
    if (!(v > 0.0)) bad(name, v, "must be > 0 (inf: off)");
  };
  // (lo, hi] or [lo, hi]
  auto within = [&](const char* name, double v, double lo, bool lo_open, double hi, const char* unit) {
    if (!(std::isfinite(v) && (lo_open ? v > lo : v >= lo) && v <= hi))
      bad(name, v, std::string("must be finite, ") + (lo_open ? "> " : ">= ") + fmt(lo) + " and <= " + fmt(hi) + unit);
  };
  within("sensor_rate", s.sensor_rate, kRateMin, false, kRateMax, " [Hz]");
  if (!(s.command_ratio >= 1 && s.command_ratio <= kRatioMax)) bad("command_ratio", s.command_ratio, "must be >= 1 and <= 1000000");
  within("f_min", s.f_min, kForceMin, false, kForceMax, " [N]");
  if (!(std::isfinite(s.f_max) && s.f_max > s.f_min && s.f_max <= kForceMax))
    bad("f_max", s.f_max, "must be finite, > f_min and <= 1e+06 [N]");
  positive_or_inf("max_rate", s.max_rate);
  if (!(std::isfinite(s.reaction_lag) && s.reaction_lag >= 0.0 && s.reaction_lag <= 1.0e3))
    bad("reaction_lag", s.reaction_lag, "must be finite, >= 0 and <= 1000 [s]");
  if (!(s.s_ref >= kSlippageMin && s.s_ref < 1.0)) bad("s_ref", s.s_ref, "must satisfy 1e-03 <= s_ref < 1");
  within("k_p", s.k_p, 0.0, true, kGainMax, " [N]");
  within("k_i", s.k_i, 0.0, true, kGainMax, " [N/s]");
  if (!(s.gain_force == 0.0 || (std::isfinite(s.gain_force) && s.gain_force >= kForceMin && s.gain_force <= kForceMax)))
    bad("gain_force", s.gain_force, "must be 0 (constant gains) or finite, >= 1e-06 and <= 1e+06 [N]");
  within("k_cd", s.k_cd, 0.0, true, kGainMax, " [N s/rad]");
  within("p_cd", s.p_cd, kPoleMin, false, kCornerMax, " [rad/s]");
  if (!(std::isfinite(s.z_cd) && s.z_cd > s.p_cd && s.z_cd <= kCornerMax))
    bad("z_cd", s.z_cd, "must be finite, > p_cd (lag network) and <= 1e+12 [rad/s]");
  if (!(std::isfinite(s.reserve_force) && s.reserve_force >= 0.0 && s.reserve_force <= kForceMax))
    bad("reserve_force", s.reserve_force, "must be finite, >= 0 and <= 1e+06 [N]");
  if (!(std::isfinite(s.reserve_torque) && s.reserve_torque >= 0.0 && s.reserve_torque <= kForceMax))
    bad("reserve_torque", s.reserve_torque, "must be finite, >= 0 and <= 1e+06 [N m]");
  if (!(s.ceiling_factor == 0.0 || (std::isfinite(s.ceiling_factor) && s.ceiling_factor >= 1.0 && s.ceiling_factor <= 1.0e3)))
    bad("ceiling_factor", s.ceiling_factor, "must be 0 (off) or finite, >= 1 and <= 1000");
  if (!(std::isfinite(s.mu_probe) && s.mu_probe >= 0.0 && s.mu_probe <= 0.5))
    bad("mu_probe", s.mu_probe, "must be finite, >= 0 and <= 0.5");
  if (!(std::isfinite(s.s_pivot) && s.s_pivot > 1.0 && s.s_pivot <= kPivotMax))
    bad("s_pivot", s.s_pivot, "must be finite, > 1 and <= 1000");
  positive("tau_pivot", s.tau_pivot);
  if (message) *message = msg;
  return msg.empty();
}

std::string to_string(const GraspControllerSettings& s) {
  auto num = [](double v) { return std::isinf(v) ? std::string("float('inf')") : fmt(v); };
  auto flag = [](bool b) { return std::string(b ? "True" : "False"); };
  return "GraspControllerSettings(sensor_rate=" + num(s.sensor_rate) +
         ", command_ratio=" + std::to_string(s.command_ratio) + ", f_min=" + num(s.f_min) +
         ", f_max=" + num(s.f_max) + ", max_rate=" + num(s.max_rate) + ", reaction_lag=" + num(s.reaction_lag) +
         ", s_ref=" + num(s.s_ref) + ", k_p=" + num(s.k_p) + ", k_i=" + num(s.k_i) +
         ", gain_force=" + num(s.gain_force) +
         ", k_cd=" + num(s.k_cd) + ", p_cd=" + num(s.p_cd) +
         ", z_cd=" + num(s.z_cd) + ", load_floors=" + flag(s.load_floors) +
         ", reserve_force=" + num(s.reserve_force) + ", reserve_torque=" + num(s.reserve_torque) +
         ", ceiling_factor=" + num(s.ceiling_factor) + ", mu_probe=" + num(s.mu_probe) +
         ", s_pivot=" + num(s.s_pivot) + ", tau_pivot=" + num(s.tau_pivot) + ")";
}

GraspControllerSettings paper_settings() noexcept {
  GraspControllerSettings s;
  s.k_i = 10.0;
  s.gain_force = 0.0;
  s.load_floors = false;
  s.reaction_lag = 0.0;
  s.ceiling_factor = 0.0;
  s.mu_probe = 0.0;
  return s;
}

const char* to_string(ControllerMode m) noexcept {
  switch (m) {
    case ControllerMode::SlippingAvoidance: return "slipping avoidance";
    case ControllerMode::Pivoting: return "pivoting";
  }
  return "unknown";
}

const char* to_string(PivotEnd e) noexcept {
  switch (e) {
    case PivotEnd::None: return "none";
    case PivotEnd::CorThreshold: return "mean |c~| above the threshold";
    case PivotEnd::Timeout: return "timeout";
    case PivotEnd::Requested: return "slipping avoidance requested";
    case PivotEnd::AtFloor: return "held at the floor";
  }
  return "unknown";
}

// --- C_d -------------------------------------------------------------------------------------

LagFilter::LagFilter(double k, double z, double p, double sample_time) noexcept {
  const double K = 2.0 / sample_time;  // s = K (1 - z^-1) / (1 + z^-1)
  b0_ = k * (K + z) / (K + p);
  b1_ = k * (z - K) / (K + p);
  a1_ = (p - K) / (K + p);
}

// --- controller ------------------------------------------------------------------------------

GraspController::GraspController(const ContactParams& params, const GraspControllerSettings& settings)
    : GraspController(ContactModel(params), settings) {}

GraspController::GraspController(const ContactModel& model, const GraspControllerSettings& settings)
    : s_(checked(settings)), solver_(model) {
  const ContactParams& params = model.params();
  mu_ = mu0_ = params.mu;
  gamma_ = params.gamma;
  dt_ = 1.0 / s_.sensor_rate;
  t_cmd_ = s_.command_ratio * dt_;
  pivot_decay_ = std::exp(-t_cmd_ / s_.tau_pivot);
  pivot_c_alpha_ = 1.0 - std::exp(-dt_ / kPivotEndFilter);
  reserve_decay_ = std::exp(-t_cmd_ / kReserveHorizon);
  for (auto& f : cd_) f = LagFilter(s_.k_cd, s_.z_cd, s_.p_cd, dt_);
  reset(s_.f_min);
}

void GraspController::reset(double current_force) noexcept {
  mode_ = ControllerMode::SlippingAvoidance;
  request_ = Request::None;
  init_static_ = true;
  phase_ = 0;
  command_ = std::isfinite(current_force) ? clamp(current_force, s_.f_min, s_.f_max) : s_.f_min;
  integrator_ = 0.0;
  pivot_state_ = command_;
  pivot_samples_ = 0;
  pivot_count_ = 0;
  pivot_at_floor_ = false;
  pivot_floor_samples_ = 0;
  pivot_c_init_ = true;
  last_f_t_ = 0.0;
  last_kp_ = last_e_ = 0.0;
  clear_period();
  f_est_ = command_;
  trend_lift_ = trend_force_ = 0.0;
  reflex_armed_ = false;
  learned_ft_.fill(0.0);
  learned_tau_.fill(0.0);
  peak_valid_.fill(false);
  reset_probe();
  mu_ = mu0_;
  solver_.set_mu(mu_);
  reset_dynamic();
  last_ = GraspControllerOutput();
  last_.force = command_;
  last_.static_force = command_;
  last_.floor = s_.f_min;
  last_.mu_belief = mu_;
}

void GraspController::reset_probe() noexcept {
  probe_left_ = 0;
  probe_wait_ = 0;
  probe_s_ = prev_s_ = probe_f_ = 0.0;
  probe_base_ = 0.0;
  probe_slip_ = false;
  probe_disturbed_ = false;
  prev_load_ = {};
}

void GraspController::reset_dynamic() noexcept {
  for (auto& f : cd_) f.reset();
  peak_ = 0.0;
}

void GraspController::request_pivoting() noexcept { request_ = Request::Pivot; }
void GraspController::request_slipping_avoidance() noexcept { request_ = Request::Avoid; }

void GraspController::set_dynamic_enabled(bool enabled) noexcept {
  if (enabled && !dynamic_) reset_dynamic();
  dynamic_ = enabled;
}

void GraspController::set_settings(const GraspControllerSettings& settings) {
  checked(settings);
  if (settings.sensor_rate != s_.sensor_rate || settings.command_ratio != s_.command_ratio ||
      settings.k_cd != s_.k_cd || settings.p_cd != s_.p_cd || settings.z_cd != s_.z_cd)
    throw std::invalid_argument(
        "GraspController::set_settings: sensor_rate, command_ratio, k_cd, p_cd and z_cd are fixed "
        "at construction");
  s_ = settings;
  pivot_decay_ = std::exp(-t_cmd_ / s_.tau_pivot);
  command_ = clamp(command_, s_.f_min, s_.f_max);
  last_.force = command_;
}

bool GraspController::set_mu(double mu) noexcept {
  if (!solver_.set_mu(mu)) return false;
  mu_ = mu0_ = mu;
  last_.mu_belief = mu_;
  reset_probe();
  return true;
}

void GraspController::set_contact_model(const ContactModel& model) {
  solver_ = StaticForceSolver(model);
  mu_ = mu0_ = model.params().mu;
  last_.mu_belief = mu_;
  reset_probe();
  gamma_ = model.params().gamma;
}

void GraspController::end_pivot(PivotEnd why, GraspControllerOutput& out) noexcept {
  mode_ = ControllerMode::SlippingAvoidance;
  init_static_ = true;  // PI integrator = last command - k_p e at the next command
  reset_dynamic();      // C_d restarts from rest
  pivot_count_ = 0;
  peak_valid_.fill(false);  // the load after the pivot is not a push
  out.pivot_finished = true;
  out.pivot_end = why;
}

Status GraspController::step(const GraspControllerInput& in, GraspControllerOutput& out) noexcept {
  out.pivot_finished = false;
  out.pivot_end = PivotEnd::None;
  out.command_issued = false;

  // Mode requests latched since the last call.
  if (request_ == Request::Pivot && mode_ == ControllerMode::SlippingAvoidance) {
    mode_ = ControllerMode::Pivoting;
    init_static_ = true;  // the filter starts from the last command
    pivot_samples_ = 0;
    pivot_count_ = 0;
    pivot_at_floor_ = false;
    pivot_floor_samples_ = 0;
    pivot_c_init_ = true;
    peak_ = 0.0;
    probe_left_ = 0;
    peak_valid_.fill(false);  // the pivot changes the load: no push
  } else if (request_ == Request::Avoid && mode_ == ControllerMode::Pivoting) {
    end_pivot(PivotEnd::Requested, out);
  }
  request_ = Request::None;

  // Per-finger checks, C_d at the sensor rate, combination (docs/model.md 9.8).
  const bool dynamic = mode_ == ControllerMode::SlippingAvoidance && dynamic_;
  bool any_present = false, valid = true;
  Status worst = Status::Ok;
  double slip = 0.0, c_sum = 0.0, f_t_max = 0.0;
  int n_valid = 0;
  for (int i = 0; i < kMaxFingers; ++i) {
    const FingerInput& f = in.fingers[i];
    if (!f.present) {
      cd_[i].reset();
      out.dynamic_sample[i] = 0.0;
      continue;
    }
    any_present = true;
    if (!finger_valid(f)) {
      valid = false;
      // NoContact and SensorFault are forwarded; a usable status with bad numbers, an
      // InvalidSample or a code outside the enum is an invalid sample.
      const Status s = (f.status == Status::NoContact || f.status == Status::SensorFault)
                           ? f.status
                           : Status::InvalidSample;
      if (severity(s) > severity(worst)) worst = s;
      out.dynamic_sample[i] = cd_[i].output();  // state held, sample not filtered
      continue;
    }
    // S against the believed mu in slipping avoidance; the pivoting law and its end test keep
    // the observers' S (their reference S-bar_p > 1 is the observers' scale).
    slip = std::max(slip, mode_ == ControllerMode::SlippingAvoidance ? f.slippage * (mu0_ / mu_) : f.slippage);
    c_sum += std::fabs(f.c_tilde);
    f_t_max = std::max(f_t_max, std::fabs(f.f_t));
    ++n_valid;
    if (std::isfinite(f.tau) && std::fabs(f.tau) <= kMaxInput) {  // load for the static floor
      const double k = n_load_[i];
      sum_f_t_[i] += std::fabs(f.f_t);
      sum_ft2_[i] += f.f_t * f.f_t;
      sum_tau2_[i] += f.tau * f.tau;
      if (std::isfinite(f.f_n) && f.f_n > 0.0 && f.f_n <= kMaxInput) sum_f_n_[i] += f.f_n;
      else fn_ok_[i] = false;
      sum_tau_[i] += f.tau;
      sum_kf_[i] += k * std::fabs(f.f_t);
      sum_kt_[i] += k * f.tau;
      sum_k_[i] += k;
      sum_kk_[i] += k * k;
      ++n_load_[i];
    }
    if (dynamic) {
      // C_d sees sign(w) max(0, |w| - band), band = the observer's speed resolution: below it
      // omega_hat is sensor noise seen through 1 / sigma_1, which |C_d .| would rectify into a
      // noise-driven force.
      const double band = kOmegaDeadband * f.omega_resolution;
      const double y = cd_[i].step(std::copysign(std::max(0.0, std::fabs(f.omega_hat) - band), f.omega_hat));
      peak_ = std::max(peak_, std::fabs(y));
      out.dynamic_sample[i] = y;
    } else {
      out.dynamic_sample[i] = 0.0;
    }
  }
  if (!any_present) {
    valid = false;
    worst = Status::NoContact;
  }
  if (valid) {
    last_f_t_ = f_t_max;
    peak_s_ = std::max(peak_s_, slip);
    sum_s_ += slip;
    ++n_s_;
    if (slip >= kSlidingSlippage) ++count_s_;
    if (count_s_ >= kReflexSamples) reflex_armed_ = true;
  }
  out.status = valid ? Status::Ok : worst;
  out.mean_c_tilde = n_valid > 0 ? c_sum / n_valid : 0.0;

  // End of the pivoting manoeuvre, tested at every sensor sample.
  if (mode_ == ControllerMode::Pivoting) {
    ++pivot_samples_;
    // With pivot_end_at_floor the criterion counts only once the force cannot fall further, on
    // the low-passed mean |c~|: a swing through the vertical passes |c~| > 1 for a few samples
    // while the torque reverses (docs/controller.md).
    if (valid) {
      pivot_c_filtered_ = pivot_c_init_ ? out.mean_c_tilde
                                        : pivot_c_filtered_ + pivot_c_alpha_ * (out.mean_c_tilde - pivot_c_filtered_);
      pivot_c_init_ = false;
    }
    const bool settled = pivot_at_floor_ && slip < kPivotEndSlippage;
    if (valid && settled && pivot_c_filtered_ > kPivotEndCTilde)
      pivot_count_ = pivot_count_ < kCountMax ? pivot_count_ + 1 : pivot_count_;
    else
      pivot_count_ = 0;
    pivot_floor_samples_ = pivot_at_floor_ && pivot_floor_samples_ < kCountMax ? pivot_floor_samples_ + 1 : 0;
    if (pivot_count_ >= kPivotEndSamples)
      end_pivot(PivotEnd::CorThreshold, out);
    else if (static_cast<double>(pivot_floor_samples_) * dt_ >= kPivotFloorTime)
      end_pivot(PivotEnd::AtFloor, out);
    else if (static_cast<double>(pivot_samples_) * dt_ >= kPivotTimeout)
      end_pivot(PivotEnd::Timeout, out);
  }
  out.pivot_time = mode_ == ControllerMode::Pivoting ? static_cast<double>(pivot_samples_) * dt_ : 0.0;

  // Hold suppresses the command; any other code than Now and Hold is the clock's.
  const bool now = in.command == CommandTiming::Now, hold = in.command == CommandTiming::Hold;
  const bool due = now || (!hold && phase_ == 0);
  if (due) {
    // The PI's S: the mean over the command period (anti-aliasing; the call's own when none was valid).
    issue_command(valid, n_s_ > 0 ? sum_s_ / n_s_ : slip);
    out.command_issued = true;
    if (now) phase_ = 0;  // the clock restarts at this command
  }
  phase_ = phase_ + 1 >= s_.command_ratio ? 0 : phase_ + 1;

  out.force = last_.force;
  out.static_force = last_.static_force;
  out.dynamic_force = last_.dynamic_force;
  out.floor = last_.floor;
  out.slippage = last_.slippage;
  out.error = last_.error;
  out.integrator = last_.integrator;
  out.gain_p = last_.gain_p;
  out.gain_i = last_.gain_i;
  out.feedforward_force = last_.feedforward_force;
  out.reserve_force = last_.reserve_force;
  out.reserve_torque = last_.reserve_torque;
  out.reflex = last_.reflex;
  out.peak_slippage = last_.peak_slippage;
  out.mu_belief = last_.mu_belief;
  out.ceiling = last_.ceiling;
  out.probing = last_.probing;
  out.probe_slip = last_.probe_slip;
  out.saturated = last_.saturated;
  out.rate_limited = last_.rate_limited;
  out.held = last_.held;
  out.dynamic_peak = peak_;
  out.mode = mode_;
  return out.status;
}

void GraspController::issue_command(bool valid, double slip) noexcept {
  GraspControllerOutput& c = last_;
  const double pivot_floor =
      std::min(std::max(s_.f_min, kPivotFloorFactor * last_f_t_ / mu_), s_.f_max);
  const double floor = mode_ == ControllerMode::Pivoting ? pivot_floor : s_.f_min;
  c.floor = floor;
  c.saturated = false;
  c.rate_limited = false;

  c.feedforward_force = 0.0;
  c.peak_slippage = peak_s_;
  c.reflex = false;
  const double lag = s_.reaction_lag > 0.0 ? std::exp(-t_cmd_ / s_.reaction_lag) : 0.0;

  if (!valid) {  // safe command: hold (or raise), never below the floor; restart bumplessly
    double f = std::max(command_, floor);
    probe_left_ = 0;  // a probe under way is abandoned
    prev_load_ = {};
    if (mode_ == ControllerMode::SlippingAvoidance) {
      // Raise-only reactions from the valid fingers' samples of the period.
      double n_slope = 1.0;
      double lift = std::min(reaction_floor(n_slope, c), s_.f_max);
      if (lift > f_est_ && lag > 0.0) lift += (lift - f_est_) * lag / (1.0 - lag);
      f = std::max(f, std::min(lift, command_ + s_.max_rate * t_cmd_));
    }
    command_ = clamp(f, s_.f_min, s_.f_max);
    f_est_ = command_ + (f_est_ - command_) * lag;
    init_static_ = true;
    peak_ = 0.0;
    clear_period();
    c.force = command_;
    c.held = true;
    c.probing = false;
    c.mu_belief = mu_;
    return;
  }
  c.held = false;

  double f_ns, f_nd = 0.0, e;
  double hi = s_.f_max;  // ceiling of the command (ceiling_factor)
  c.ceiling = hi;
  bool reacting = false;  // the feed-forward or the reflex lifted the static part
  if (mode_ == ControllerMode::SlippingAvoidance) {
    // Floor of the static part: feed-forward of the measured load (and the task's reserve), slip reflex.
    // The grip probe's answer first: a slip it finds lowers the belief, which the floors use.
    probe_evaluate();
    double n_slope = 1.0;
    const double lift = reaction_floor(n_slope, c);
    const bool probe_started = probe_start(slip, c.reflex || lift > std::min(last_.static_force, command_));
    clear_period();
    // PI on e = S - s_ref: e > 0 (closer to slip than wanted) raises the force (docs/model.md 9.4).
    e = slip - s_.s_ref;
    double k_p, k_i;
    if (s_.gain_force > 0.0) {  // loop gain k |dS/df_n| independent of the force (docs/controller.md)
      const double scale = command_ / (n_slope * s_.gain_force);
      k_p = s_.k_p * scale;
      k_i = s_.k_i * scale;
    } else {
      k_p = s_.k_p;
      k_i = s_.k_i;
    }
    if (init_static_) {  // bumpless (re)start from the last command
      integrator_ = command_ - k_p * e;
      init_static_ = false;
    } else {
      if (s_.gain_force > 0.0) integrator_ += (last_kp_ - k_p) * last_e_;  // gain change without a jump of f_ns
      // The trend's lift that the period's load did not confirm; only a sticking contact's
      // load can refute it (while sliding, f_t is capped at mu f_n).
      if (trend_lift_ > 0.0 && c.peak_slippage < kSlidingSlippage)
        integrator_ -= std::min(trend_lift_, std::max(0.0, trend_force_ - floor_measured_));
    }
    trend_lift_ = 0.0;
    const double u = k_p * e + integrator_;
    // Ceiling: the grip the measured load needs at S = 1, times ceiling_factor (while the
    // contact slides its load is its friction, and this is the grip it slides at). It caps
    // raises only: never below the last command (lowering is the PI's).
    // The need is also read from S itself (S ~ 1/f_n: the grip at S = 1 is ~ f S), so a load
    // given without its torque, or an S the load does not explain, never lowers the ceiling.
    hi = s_.f_max;
    const double need = std::max(ceiling_load_, f_est_ * slip);
    if (s_.ceiling_factor > 0.0 && need > 0.0)
      hi = clamp(std::max(s_.ceiling_factor * need, command_), s_.f_min, s_.f_max);
    c.ceiling = hi;
    const double lo = clamp(lift, s_.f_min, hi);
    f_ns = clamp(u, lo, hi);
    if (f_ns != u) {
      if (u < lo && lo > s_.f_min) {
        reacting = true;
        integrator_ = f_ns - k_p * e;  // the floor lifted the PI: restart it there
        // the part the trend added beyond the measured load's floor, checked at the next command
        trend_lift_ = f_ns - clamp(std::max(u, floor_measured_), s_.f_min, f_ns);
        trend_force_ = f_ns;
      } else {
        c.saturated = true;
        integrator_ = f_ns - k_p * e;  // back-calculation anti-windup, static part only
      }
    }
    // The grip probe raises the static part above the PI's for two periods; the integrator
    // does not see them (a probe is not the load's demand).
    if (probe_started) probe_base_ = f_ns;
    const bool probing = probe_left_ > 0;
    // A reaction during the probe (the reflex moved the grip) spoils its answer.
    if (probing && !probe_started && c.reflex) probe_disturbed_ = true;
    c.probing = probing;
    if (probing) {  // the probe is a measurement: it may exceed the ceiling by its own size
      hi = std::min(std::max(hi, probe_base_ * (1.0 + s_.mu_probe)), s_.f_max);
      f_ns = std::min(std::max(f_ns, probe_base_ * (1.0 + s_.mu_probe)), hi);
    }
    else integrator_ += k_i * t_cmd_ * e;  // forward Euler
    last_kp_ = k_p;
    last_e_ = e;
    c.gain_p = k_p;
    c.gain_i = k_i;
    if (dynamic_) {
      const double head_room = hi - f_ns;
      // With the ceiling on, the dynamic part adds at most kDynamicCap of the static part: it
      // answers a slip's speed, not the load, and a lift-off's transfer slip would otherwise
      // spike the grip to several times what the load needs.
      const double cap = s_.ceiling_factor > 0.0 ? std::min(head_room, kDynamicCap * f_ns) : head_room;
      f_nd = clamp(peak_, 0.0, cap);
      if (peak_ > head_room) c.saturated = true;
    }
  } else {
    // tau_p df/dt = -f + k_p (S - s_pivot) (the filter gain k_f = k_p, docs/model.md 9.6), exact
    // discretisation at the command rate; output is
    // the state before the update, so the first pivoting command equals the last command.
    clear_period();
    c.probing = false;
    c.gain_p = c.gain_i = 0.0;
    e = slip - s_.s_pivot;
    if (init_static_) {
      pivot_state_ = command_;
      init_static_ = false;
    }
    pivot_state_ = clamp(pivot_state_, floor, s_.f_max);
    f_ns = pivot_state_;
    pivot_state_ = pivot_decay_ * pivot_state_ + (1.0 - pivot_decay_) * s_.k_p * e;
    pivot_at_floor_ = pivot_state_ <= floor;  // the filter wants to go below the floor
    pivot_state_ = clamp(pivot_state_, floor, s_.f_max);
  }
  peak_ = 0.0;

  double target = f_ns + f_nd;
  // Reaction through the gripper's lag: overshoot so the force reaches the target in one period.
  if (reacting && lag > 0.0 && target > f_est_)
    target = std::min(target + (std::min(target, s_.f_max) - f_est_) * lag / (1.0 - lag), hi);
  double f = clamp(target, command_ - s_.max_rate * t_cmd_, command_ + s_.max_rate * t_cmd_);
  c.rate_limited = f != target;
  f = clamp(std::max(f, floor), s_.f_min, s_.f_max);
  command_ = f;
  f_est_ = command_ + (f_est_ - command_) * lag;

  c.force = f;
  c.mu_belief = mu_;
  c.probe_slip = probe_slip_;
  probe_slip_ = false;
  c.static_force = f_ns;
  c.dynamic_force = f_nd;
  c.slippage = slip;
  c.error = e;
  c.integrator = integrator_;
}

void GraspController::clear_period() noexcept {
  sum_f_t_.fill(0.0);
  sum_f_n_.fill(0.0);
  sum_ft2_.fill(0.0);
  sum_tau2_.fill(0.0);
  fn_ok_.fill(true);
  sum_tau_.fill(0.0);
  sum_kf_.fill(0.0);
  sum_kt_.fill(0.0);
  sum_k_.fill(0.0);
  sum_kk_.fill(0.0);
  n_load_.fill(0);
  peak_s_ = sum_s_ = 0.0;
  n_s_ = 0;
  count_s_ = 0;
  reflex_armed_ = false;
}

GraspController::PeriodLoad GraspController::period_load(int i) const noexcept {
  PeriodLoad l;
  if (n_load_[i] == 0 || !fn_ok_[i]) return l;
  const double n = n_load_[i];
  l.n = n_load_[i];
  l.fn = sum_f_n_[i] / n;
  l.ft = sum_f_t_[i] / n;
  l.tau = sum_tau_[i] / n;
  // Noise: the residual variance about the period's least-squares line (a load ramp within
  // the period is no noise).
  const double sxx = sum_kk_[i] - sum_k_[i] * sum_k_[i] / n;
  if (n > 2.0 && sxx > 0.0) {
    const double sff = sum_ft2_[i] - sum_f_t_[i] * sum_f_t_[i] / n;
    const double stt = sum_tau2_[i] - sum_tau_[i] * sum_tau_[i] / n;
    const double sxf = sum_kf_[i] - sum_k_[i] * sum_f_t_[i] / n;
    const double sxt = sum_kt_[i] - sum_k_[i] * sum_tau_[i] / n;
    l.var_ft = std::max(0.0, (sff - sxf * sxf / sxx) / (n - 2.0));
    l.var_tau = std::max(0.0, (stt - sxt * sxt / sxx) / (n - 2.0));
  }
  return l;
}

void GraspController::probe_evaluate() noexcept {
  if (probe_left_ <= 0) return;
  --probe_left_;
  if (probe_left_ == 1) {  // the probe's second period: kept for the answer
    for (int i = 0; i < kMaxFingers; ++i) probe_a_[i] = period_load(i);
    return;
  }
  if (probe_left_ > 0) return;
  if (probe_disturbed_) {  // the load moved during the probe: no answer
    probe_disturbed_ = false;
    probe_wait_ = kProbeGapMin;
    return;
  }
  // End of a probe: the mean of its last two periods against the mean of the two periods
  // before it. Elasticity E = d ln(load) / d ln(f_n) of each finger's dominant load component
  // (a twist's divided by 1 + gamma): ~0 for a sticking contact, ~1 for a sliding one.
  const double x_min = 0.25 * s_.mu_probe;
  bool slip = false, answered = false;
  double r_slip = 0.0;
  for (int i = 0; i < kMaxFingers; ++i) {
    const PeriodLoad a = ref_a_[i], b = ref_b_[i], c = probe_a_[i], d = period_load(i);
    if (a.n < 3 || b.n < 3 || c.n < 3 || d.n < 3) continue;
    const double fn0 = 0.5 * (a.fn + b.fn), fn1 = 0.5 * (c.fn + d.fn);
    if (!(fn0 > 0.0 && fn1 > 0.0)) continue;
    const double x = std::log(fn1 / fn0);
    if (!(x >= x_min)) continue;  // the gripper did not follow the probe (range, rate)
    const double ft0 = 0.5 * (a.ft + b.ft), tau0 = 0.5 * (a.tau + b.tau);
    const double util_t = ft0 / (mu_ * fn0);
    const double tmax = solver_.model().tau_max(fn0);
    const double util_r = tmax > 0.0 ? std::fabs(tau0) / tmax : 0.0;
    double y, sd;
    if (util_t >= util_r) {
      const double ft1 = 0.5 * (c.ft + d.ft);
      if (!(ft0 > 0.0 && ft1 > 0.0)) continue;
      y = std::log(ft1 / ft0);
      // standard error of the log ratio of the two four-period means
      sd = 0.5 * std::sqrt(a.var_ft / a.n + b.var_ft / b.n + c.var_ft / c.n + d.var_ft / d.n) *
           std::sqrt(1.0 / (ft0 * ft0) + 1.0 / (ft1 * ft1));
    } else {
      const double tau1 = 0.5 * (c.tau + d.tau);
      if (!(tau0 * tau1 > 0.0)) continue;
      const double k = 1.0 + gamma_;
      y = std::log(tau1 / tau0) / k;
      sd = 0.5 * std::sqrt(a.var_tau / a.n + b.var_tau / b.n + c.var_tau / c.n + d.var_tau / d.n) *
           std::sqrt(1.0 / (tau0 * tau0) + 1.0 / (tau1 * tau1)) / k;
    }
    if (!std::isfinite(y) || !std::isfinite(sd)) continue;
    answered = true;
    const double band = kProbeSigmas * sd;
    if (y >= kProbeElasticity * x + band) {
      slip = true;
      // The friction the contact slid at: S_static against mu = 1 of the load before the probe
      // and during it (both are the friction while it slides; the larger errs on the safe side
      // of a load that was still rising).
      const double s0 = solver_.slippage(fn0, ft0, tau0);
      const double s1 = solver_.slippage(fn1, 0.5 * (c.ft + d.ft), 0.5 * (c.tau + d.tau));
      if (std::isfinite(s0)) r_slip = std::max(r_slip, s0 * mu_);
      if (std::isfinite(s1)) r_slip = std::max(r_slip, s1 * mu_);
    }
  }
  if (slip && r_slip > 0.0) {
    const double next = std::max({r_slip, kProbeStepDown * mu_, kMuFloor * mu0_});
    if (next < mu_) {
      mu_ = next;
      solver_.set_mu(mu_);
    }
    probe_slip_ = true;
    reflex_armed_ = true;  // a confirmed slip: the reflex raises the static part now
    probe_s_ = probe_f_ = 0.0;  // stick is proven again from the start
  } else if (answered) {
    // Stick proven up to the S before the probe, at the grip of then: the next probe waits
    // until S rises above it, or the grip has fallen below it (a slide keeps S flat while the
    // PI lowers the grip; a sticking contact's S rises).
    probe_s_ = std::max(probe_s_, probe_ref_s_);
    probe_f_ = probe_base_;
  }
  probe_wait_ = kProbeGapMin;
}

bool GraspController::probe_start(double slip_mean, bool reacting) noexcept {
  const double prev = prev_s_;
  prev_s_ = slip_mean;
  std::array<PeriodLoad, kMaxFingers> now{};
  for (int i = 0; i < kMaxFingers; ++i) now[i] = period_load(i);
  const std::array<PeriodLoad, kMaxFingers> before = prev_load_;
  prev_load_ = now;
  if (s_.mu_probe <= 0.0 || probe_left_ > 0) return false;
  if (probe_wait_ > 0) {
    --probe_wait_;
    return false;
  }
  if (reacting || !(slip_mean >= kProbeMinS) || slip_mean < prev - kProbeFall) return false;
  if (probe_s_ > 0.0 && slip_mean < probe_s_ + kProbeRise &&
      std::min(last_.static_force, command_) > (1.0 - s_.mu_probe) * probe_f_)
    return false;  // stick proven there
  bool any = false;
  for (int i = 0; i < kMaxFingers; ++i) {
    ref_a_[i] = before[i];
    ref_b_[i] = now[i];
    any = any || (before[i].n >= 3 && now[i].n >= 3);
  }
  if (!any) return false;
  probe_ref_s_ = slip_mean;
  probe_disturbed_ = false;
  probe_left_ = 3;
  return true;
}

double GraspController::reaction_floor(double& slope_exponent, GraspControllerOutput& c) noexcept {
  double lift = static_floor(slope_exponent);
  c.feedforward_force = lift;
  c.reserve_force = reserve_force_;
  c.reserve_torque = reserve_torque_;
  if (s_.load_floors && reflex_armed_) {
    // On the grip the contact slid at: the static part (a transient f_nd would otherwise be
    // multiplied into f_ns), or the measured f_n when the gripper has not reached it yet (a
    // raise still on its way is not a grip that failed; compounding the command while the
    // force lags would overshoot the load several times).
    double base = std::min(last_.static_force, command_);
    double fn_meas = 0.0;
    for (int i = 0; i < kMaxFingers; ++i) fn_meas = std::max(fn_meas, period_load(i).fn);
    if (fn_meas > 0.0) base = std::min(base, fn_meas);
    const double reflex = kReflexFactor * base;
    lift = std::max(lift, reflex);
    floor_measured_ = std::max(floor_measured_, reflex);
    c.reflex = true;
  }
  return lift;
}

double GraspController::static_floor(double& slope_exponent) noexcept {
  // Per finger: the mean load of the last command period; the feed-forward force is the larger
  // static grasp force, the slope exponent that of the finger nearest to slip at the command.
  constexpr double kStep = 1.1;  // relative force step of the slope's finite difference
  double force = 0.0, s_max = -1.0;
  slope_exponent = 1.0;
  // Mean-load force of each finger and the grasp's (the largest): the trend test's reference.
  // Each finger's mean load: its map (one evaluation) serves the feed-forward, the ceiling and
  // the slope.
  std::array<double, kMaxFingers> f_mean{};
  std::array<StaticLoadMap, kMaxFingers> maps{};
  double f_grasp = 0.0;
  for (int i = 0; i < kMaxFingers; ++i) {
    if (n_load_[i] == 0) continue;
    const double ft = sum_f_t_[i] / n_load_[i], tau = sum_tau_[i] / n_load_[i];
    if (s_.load_floors || s_.ceiling_factor > 0.0 || s_.gain_force > 0.0) maps[i] = solver_.map(ft, tau);
    if (!s_.load_floors) continue;
    f_mean[i] = solver_.force(maps[i], ft, tau, kFeedforwardSlippage);
    if (std::isfinite(f_mean[i])) f_grasp = std::max(f_grasp, f_mean[i]);
  }
  floor_measured_ = f_grasp;
  ceiling_load_ = 0.0;
  reserve_force_ = reserve_torque_ = 0.0;
  for (int i = 0; i < kMaxFingers; ++i) {
    if (n_load_[i] == 0) continue;
    const double n = n_load_[i];
    const double ft = sum_f_t_[i] / n, tau = sum_tau_[i] / n;
    double load_ft = ft, load_tau = tau;  // the load the feed-forward answers (mean or trend)
    StaticLoadMap load_map = maps[i];  // its map
    if (s_.load_floors) {
      double f = f_mean[i];
      const double f_ref = f_grasp;  // a light finger's extrapolated noise is no edge
      const double den = n * sum_kk_[i] - sum_k_[i] * sum_k_[i];
      if (n_load_[i] >= 3 && den > 0.0 && std::isfinite(f)) {
        // Least-squares trend of the period's load, extrapolated from the last sample's index
        // by the horizon.
        const double k_mean = sum_k_[i] / n;
        const double ahead = (n - 1.0 - k_mean) + kFeedforwardHorizon / dt_;
        const double slope_f = (n * sum_kf_[i] - sum_k_[i] * sum_f_t_[i]) / den;
        const double slope_t = (n * sum_kt_[i] - sum_k_[i] * sum_tau_[i]) / den;
        const double x_ft = std::max(0.0, ft + slope_f * ahead), x_tau = tau + slope_t * ahead;
        const StaticLoadMap x_map = solver_.map(x_ft, x_tau);
        const double fx = solver_.force(x_map, x_ft, x_tau, kFeedforwardSlippage);
        if (std::isfinite(fx) && fx > (1.0 + kFeedforwardTrend) * f_ref) {
          f = fx;
          load_ft = x_ft;
          load_tau = x_tau;
          load_map = x_map;
        }
      }
      if (std::isfinite(f)) force = std::max(force, f);
    }
    if (s_.ceiling_factor > 0.0) {  // the grip this load needs at S = 1
      const double f = solver_.force(load_map, load_ft, load_tau, 1.0);
      if (std::isfinite(f)) ceiling_load_ = std::max(ceiling_load_, f);
    }
    if (s_.load_floors) {  // the pushes seen: the part of the load that came and went
      const double at = std::fabs(tau);
      if (!peak_valid_[i]) {
        peak_ft_[i] = ft;
        peak_tau_[i] = at;
        peak_valid_[i] = true;
      }
      peak_ft_[i] = std::max(peak_ft_[i], ft);
      peak_tau_[i] = std::max(peak_tau_[i], at);
      // only while the finger still carries half its peak tangential load: a load that falls to
      // nothing is a release, not a push
      const bool held = ft >= kReserveHeld * peak_ft_[i];
      learned_ft_[i] = std::max(learned_ft_[i] * reserve_decay_, held ? peak_ft_[i] - ft : 0.0);
      learned_tau_[i] = std::max(learned_tau_[i] * reserve_decay_, held ? peak_tau_[i] - at : 0.0);
      peak_ft_[i] = ft + (peak_ft_[i] - ft) * reserve_decay_;
      peak_tau_[i] = at + (peak_tau_[i] - at) * reserve_decay_;
    }
    // Reserve: the task's stated envelope or the pushes learned, the larger; the static force of
    // the load with the reserve added, at S = 1.
    const double r_f = std::max(s_.reserve_force, kReserveShare * learned_ft_[i]);
    const double r_t = std::max(s_.reserve_torque, kReserveShare * learned_tau_[i]);
    reserve_force_ = std::max(reserve_force_, r_f);
    reserve_torque_ = std::max(reserve_torque_, r_t);
    if (r_f > 0.0 || r_t > 0.0) {
      const double f = solver_.force(std::fabs(ft) + r_f, std::fabs(tau) + r_t, 1.0);
      if (std::isfinite(f)) force = std::max(force, f);
      if (std::isfinite(f)) ceiling_load_ = std::max(ceiling_load_, f);
    }
    if (s_.gain_force > 0.0) {
      // the map is exact at S <= 1 (inside the LS or at the clip); beyond, the estimator itself
      double s0 = maps[i].slippage(command_), s1 = maps[i].slippage(kStep * command_);
      if (!(s0 <= 1.0 && s1 <= 1.0)) {
        s0 = solver_.slippage(command_, ft, tau);
        s1 = solver_.slippage(kStep * command_, ft, tau);
      }
      if (std::isfinite(s0) && std::isfinite(s1) && s0 > 0.0 && s1 > 0.0 && s0 > s_max) {
        s_max = s0;
        slope_exponent = clamp(std::log(s0 / s1) / std::log(kStep), 1.0, 1.0 + gamma_);
      }
    }
  }
  return force;
}

// --- static grasp force ----------------------------------------------------------------------

namespace {
CorSettings static_cor_settings() {
  CorSettings s;
  s.f_n_min = 1.0e-12;  // evaluate the static map at any positive force
  s.force_limit = 1.0e12;
  s.torque_limit = 1.0e12;
  return s;
}
}  // namespace

StaticForceSolver::StaticForceSolver(const ContactModel& model) : est_(model, static_cor_settings()) {}
StaticForceSolver::StaticForceSolver(const ContactParams& params) : est_(params, static_cor_settings()) {}

double StaticForceSolver::evaluate(double f_n, double f_t, double tau, CorOutput& o) noexcept {
  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  if (!(std::isfinite(f_n) && f_n > 0.0 && std::isfinite(f_t) && std::isfinite(tau))) return nan;
  // No history: the estimator is never committed to (its held estimate stays the reset one), so
  // a tau below the zero threshold takes the default side.
  est_.evaluate(CorInput{f_n, std::fabs(f_t), tau}, o);
  if (!is_valid(o.status) || !(o.g > 0.0)) return nan;
  // |tau - c f_t| = |tau| + |c| f_t (tau and c have opposite signs, docs/model.md 6). Equal to |y| of
  // the estimator except for a torque below its zero threshold, whose sign it holds from history.
  return (std::fabs(tau) + std::fabs(o.c) * std::fabs(f_t)) / o.g;
}

double StaticForceSolver::slippage(double f_n, double f_t, double tau, double* c_tilde) noexcept {
  CorOutput o;
  const double s = evaluate(f_n, f_t, tau, o);
  if (c_tilde && std::isfinite(s)) *c_tilde = std::fabs(o.c_tilde);
  return s;
}

namespace {
// The map of the load (f_t, tau) through one evaluation o of the estimator at f_n: S = A + B
// there, A = |tau| / g, B = |c| |f_t| / g.
StaticLoadMap map_through(double f_n, double f_t, double tau, double pw, const CorOutput& o) noexcept {
  StaticLoadMap m;
  m.f0 = f_n;
  m.pw = pw;
  m.a = std::fabs(tau) / o.g;
  m.b = std::fabs(o.c) * std::fabs(f_t) / o.g;
  m.valid = true;
  return m;
}

// The forces [N] at which the load alone reaches S = s: its translation (|f_t| = s mu f_n) and
// its torsion (|tau| = s tau_max(f_n)), each without the other.
struct PureLoadForces {
  double translation, torsion;
};
PureLoadForces pure_load_forces(const ContactModel& model, double ft, double tau, double s) noexcept {
  const ContactParams& p = model.params();
  return {ft / (p.mu * s),
          std::pow(std::fabs(tau) / (p.mu * model.xi() * p.delta * s), 1.0 / (1.0 + p.gamma))};
}
}  // namespace

StaticLoadMap StaticForceSolver::map(double f_t, double tau) noexcept {
  StaticLoadMap m;
  const double ft = std::fabs(f_t);
  if (!(std::isfinite(ft) && std::isfinite(tau)) || (ft == 0.0 && tau == 0.0)) return m;
  const ContactParams& p = est_.model().params();
  const double pw = 1.0 + p.gamma;
  // 1.25 (translation + torsion) at S = 1 puts the load inside the diamond |f~_t| + |tau~| <= 0.8, so
  // inside the (convex) LS, where |c~| is the one of every root at S <= 1
  const PureLoadForces pure = pure_load_forces(est_.model(), ft, tau, 1.0);
  const double f0 = 1.25 * (pure.translation + pure.torsion);
  CorOutput& o = scratch_;
  const double s0 = evaluate(f0, ft, tau, o);
  if (!(std::isfinite(s0) && s0 > 0.0)) return m;
  m = map_through(f0, ft, tau, pw, o);
  m.inside = true;
  return m;
}

bool StaticForceSolver::general_branch(double f_n, double ft, double tau) const noexcept {
  // Conservative ranges (a false answer only costs the checking evaluation): with f_n in
  // [1e-6, 1e9] N, |tau| >= 1e-200 N m, mu xi delta >= 1e-100 and beta_A <= 1e250 the
  // estimator's normalised load, sigma, g, c, sigma_1 and y are finite and nonzero (rho =
  // delta f_n^gamma < 1e3 m), and its input limits (1e12) hold; then the branch: |f~_t| computed
  // as the estimator computes it, at or above its zero threshold (below: a pure torsion, |c~| =
  // 0, whatever the map says).
  const CorSettings& cs = est_.settings();
  const ContactParams& p = est_.model().params();
  const double at = std::fabs(tau);
  return f_n >= 1.0e-6 && f_n <= 1.0e9 && at >= 1.0e-200 && at <= cs.torque_limit && ft <= cs.force_limit &&
         p.mu * est_.model().xi() * p.delta >= 1.0e-100 && p.beta_a <= 1.0e250 &&
         std::fabs(ft / (p.mu * f_n)) >= cs.zero_force;
}

double StaticForceSolver::force(const StaticLoadMap& map, double f_t, double tau, double s_ref) noexcept {
  if (map.valid && map.inside && s_ref > 0.0 && s_ref <= 1.0 && std::isfinite(f_t) && std::isfinite(tau)) {
    const double ft = std::fabs(f_t);
    // solve()'s first root, the one its check would accept
    const double f = map.root(s_ref);
    if (std::isfinite(f) && general_branch(f, ft, tau) && general_branch(map.f0, ft, tau)) return f;
  }
  return solve(map, f_t, tau, s_ref).force;
}

double StaticForceSolver::force(double f_t, double tau, double s_ref) noexcept {
  if (std::isfinite(f_t) && std::isfinite(tau) && s_ref > 0.0 && s_ref <= 1.0 && (f_t != 0.0 || tau != 0.0))
    return force(map(f_t, tau), f_t, tau, s_ref);
  return solve(f_t, tau, s_ref).force;
}

double StaticLoadMap::slippage(double f_n) const noexcept {
  if (!(valid && f_n > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  const double x = f0 / f_n;
  return (a > 0.0 ? a * detail::fast_pow_pos(x, pw) : 0.0) + b * x;
}

double StaticLoadMap::root(double s_ref) const noexcept {
  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  if (!(valid && s_ref > 0.0)) return nan;
  // x = f0 / f: each term alone reaches s_ref at or beyond the root; Newton's method on the
  // convex, increasing A x^pw + B x - s_ref from there converges monotonically.
  double x = std::numeric_limits<double>::infinity();
  if (a > 0.0) x = detail::fast_pow_pos(s_ref / a, 1.0 / pw);
  if (b > 0.0) x = std::min(x, s_ref / b);
  if (!(std::isfinite(x) && x > 0.0)) return nan;
  for (int i = 0; i < 60; ++i) {
    const double ax = a > 0.0 ? a * detail::fast_pow_pos(x, pw) : 0.0;
    const double dx = (ax + b * x - s_ref) * x / (pw * ax + b * x);
    x -= dx;
    if (!(x > 0.0) || std::fabs(dx) <= 1e-15 * x) break;
  }
  return std::isfinite(x) && x > 0.0 ? f0 / x : nan;
}

StaticForceResult StaticForceSolver::solve(double f_t, double tau, double s_ref) noexcept {
  if (std::isfinite(f_t) && std::isfinite(tau) && s_ref > 0.0 && s_ref <= 1.0 && (f_t != 0.0 || tau != 0.0)) {
    const StaticLoadMap m = map(f_t, tau);
    StaticForceResult r = solve(m, f_t, tau, s_ref);
    ++r.iterations;  // the map's evaluation
    return r;
  }
  return solve(StaticLoadMap{}, f_t, tau, s_ref);
}

StaticForceResult StaticForceSolver::solve(const StaticLoadMap& map, double f_t, double tau, double s_ref) noexcept {
  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  constexpr int kMaxExpand = 120, kMaxRefine = 100;
  StaticForceResult r;
  if (!(std::isfinite(f_t) && std::isfinite(tau) && s_ref > 0.0 && s_ref <= 1.0)) {
    r.force = r.c_tilde = r.slippage = nan;
    return r;
  }
  const double ft = std::fabs(f_t);
  if (ft == 0.0 && tau == 0.0) {  // no load: no force needed
    r.converged = true;
    return r;
  }
  // The map in closed form (the map's root), checked by one evaluation; a check that fails
  // (a zero threshold of the estimator crossed, a degenerate load) gives a new map from that
  // evaluation, twice at most, then the bracket below takes over from there.
  double start = 0.0;
  StaticLoadMap m = map;
  for (int pass = 0; pass < 3 && m.valid; ++pass) {
    const double f = m.root(s_ref);
    if (!(std::isfinite(f) && f > 0.0)) break;
    ++r.iterations;
    CorOutput& o = scratch_;
    const double s = evaluate(f, ft, tau, o);
    if (!(std::isfinite(s) && s > 0.0)) break;
    start = f;
    // S at the LS itself (s_ref = 1) is computed by either branch of the estimator, which agree
    // to its own tolerance: the check allows 1e-10 (the force to ~1e-10 relative)
    if (std::fabs(s - s_ref) <= 1e-10 * s_ref) {
      r.force = f;
      r.slippage = s;
      r.c_tilde = std::fabs(o.c_tilde);
      r.converged = true;
      return r;
    }
    m = map_through(f, ft, tau, m.pw, o);
  }
  if (!(start > 0.0)) {  // no map: the larger of the pure-translation and pure-torsion forces at s_ref
    const PureLoadForces pure = pure_load_forces(est_.model(), ft, tau, s_ref);
    start = std::max(pure.translation, pure.torsion);
  }
  // Residual in logs: S_static decreases with f_n, roughly as a power law.
  const double log_ref = std::log(s_ref);
  auto residual = [&](double x) {
    ++r.iterations;
    const double s = slippage(std::exp(x), ft, tau);
    return std::isfinite(s) && s > 0.0 ? std::log(s) - log_ref : nan;
  };
  double lo = std::log(start), hi = lo;
  double r_lo = residual(lo), r_hi = r_lo;
  if (!std::isfinite(r_lo)) {
    r.force = r.c_tilde = r.slippage = nan;
    return r;
  }
  constexpr double kStep = 0.6931471805599453;  // log 2
  for (int i = 0; r_hi > 0.0 && i < kMaxExpand; ++i) {
    lo = hi;
    r_lo = r_hi;
    hi += kStep;
    r_hi = residual(hi);
  }
  for (int i = 0; r_lo < 0.0 && i < kMaxExpand; ++i) {
    hi = lo;
    r_hi = r_lo;
    lo -= kStep;
    r_lo = residual(lo);
  }
  double x = r_lo == 0.0 ? lo : hi;
  bool converged = r_lo == 0.0 || r_hi == 0.0;
  if (!converged && r_lo > 0.0 && r_hi < 0.0) {
    // Illinois (regula falsi with halving of the retained end) on [lo, hi].
    int side = 0;
    for (int i = 0; i < kMaxRefine; ++i) {
      x = (lo * r_hi - hi * r_lo) / (r_hi - r_lo);
      const double rx = residual(x);
      if (!std::isfinite(rx)) break;
      if (rx > 0.0) {
        lo = x;
        r_lo = rx;
        if (side == 1) r_hi *= 0.5;
        side = 1;
      } else {
        hi = x;
        r_hi = rx;
        if (side == -1) r_lo *= 0.5;
        side = -1;
      }
      if (std::fabs(rx) <= 1e-14 || hi - lo <= 1e-12) {
        converged = true;
        break;
      }
    }
  }
  r.force = std::exp(x);
  r.slippage = slippage(r.force, ft, tau, &r.c_tilde);
  r.converged = converged;
  return r;
}

double static_grasp_force(const ContactParams& params, double f_t, double tau, double s_ref) {
  if (!(s_ref > 0.0 && s_ref <= 1.0))
    throw std::invalid_argument("static_grasp_force: s_ref = " + fmt(s_ref) + ": must satisfy 0 < s_ref <= 1");
  if (!(std::isfinite(f_t) && std::isfinite(tau)))
    throw std::invalid_argument("static_grasp_force: f_t = " + fmt(f_t) + ", tau = " + fmt(tau) + ": must be finite");
  StaticForceSolver solver(params);
  const StaticForceResult r = solver.solve(f_t, tau, s_ref);
  // The solver evaluates the static map between 1e-12 N and 1e12 N (its CoR settings); a load
  // whose force lies outside gives no finite answer.
  if (!std::isfinite(r.force))
    throw std::invalid_argument("static_grasp_force: load f_t = " + fmt(f_t) + " N, tau = " + fmt(tau) +
                                " N m: the static force is outside the range the solver covers (1e-12 to 1e12 N)");
  return r.force;
}

}  // namespace lugrip
