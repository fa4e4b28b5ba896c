// Closed-loop grasp simulation: plant, two sensors, two observers, controller or baseline.
#include "lugrip/closed_loop.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "format.hpp"

namespace lugrip {

namespace {

std::string num(double v) { return detail::format_number(v); }

// Prefixes every line of a sub-validator's message.
void append_prefixed(std::string& msg, const std::string& sub, const char* prefix) {
  std::istringstream lines(sub);
  for (std::string line; std::getline(lines, line);)
    if (!line.empty()) msg += std::string(prefix) + line + "\n";
}

bool close_rel(double a, double b) { return std::fabs(a - b) <= 1e-9 * std::max(std::fabs(a), std::fabs(b)); }

double clampd(double v, double lo, double hi) noexcept { return v < lo ? lo : (v > hi ? hi : v); }

const ClosedLoopConfig& checked(const ClosedLoopConfig& c) {
  std::string msg;
  if (!validate(c, &msg)) throw std::invalid_argument("invalid ClosedLoopConfig:\n" + msg);
  return c;
}

ClosedLoopConfig sorted(ClosedLoopConfig c) {
  std::stable_sort(c.schedule.begin(), c.schedule.end(),
                   [](const ModeEvent& a, const ModeEvent& b) { return a.time < b.time; });
  return c;
}

}  // namespace

const char* to_string(ControllerKind k) noexcept {
  switch (k) {
    case ControllerKind::Lugrip: return "lugrip";
    case ControllerKind::ConstantForce: return "constant_force";
    case ControllerKind::FrictionCone: return "friction_cone";
  }
  return "unknown";
}

const char* to_string(ModeAction a) noexcept {
  switch (a) {
    case ModeAction::Pivot: return "pivot";
    case ModeAction::SlippingAvoidance: return "slipping_avoidance";
    case ModeAction::DynamicOn: return "dynamic_on";
    case ModeAction::DynamicOff: return "dynamic_off";
  }
  return "unknown";
}

const char* to_string(FaultKind k) noexcept {
  switch (k) {
    case FaultKind::Dropout: return "dropout";
    case FaultKind::NanBurst: return "nan_burst";
    case FaultKind::Spike: return "spike";
    case FaultKind::BiasDrift: return "bias_drift";
    case FaultKind::Saturation: return "saturation";
    case FaultKind::Stuck: return "stuck";
    case FaultKind::Dead: return "dead";
    case FaultKind::ContactLoss: return "contact_loss";
    case FaultKind::ActuatorLag: return "actuator_lag";
    case FaultKind::ActuatorSaturation: return "actuator_saturation";
  }
  return "unknown";
}

namespace {
bool finite_ge0(double v) { return std::isfinite(v) && v >= 0.0; }
void validate_fault(const FaultSpec& f, const std::string& p, std::string& msg) {
  const int kind = static_cast<int>(f.kind);
  if (kind < 0 || kind > 9) msg += p + "kind = " + std::to_string(kind) + ": unknown fault kind\n";
  if (f.finger < -1 || f.finger > 1) msg += p + "finger = " + std::to_string(f.finger) + ": must be 0, 1 or -1 (both)\n";
  if (!(finite_ge0(f.t_start) && f.t_start <= 1e9)) msg += p + "t_start = " + num(f.t_start) + ": must be in [0, 1e9] [s]\n";
  if (!(f.duration > 0.0) || std::isnan(f.duration)) msg += p + "duration = " + num(f.duration) + ": must be > 0 [s]\n";
  if (f.burst < 1) msg += p + "burst = " + std::to_string(f.burst) + ": must be >= 1 [samples]\n";
  if (f.every != 0 && f.every < f.burst)
    msg += p + "every = " + std::to_string(f.every) + ": must be 0 (continuous) or >= burst [samples]\n";
  if (!(std::isfinite(f.force) && std::fabs(f.force) <= 1e6)) msg += p + "force = " + num(f.force) + ": must be finite, |force| <= 1e6 [N]\n";
  if (!(std::isfinite(f.torque) && std::fabs(f.torque) <= 1e4)) msg += p + "torque = " + num(f.torque) + ": must be finite, |torque| <= 1e4 [N m]\n";
  if (!(std::isfinite(f.force_rate) && std::fabs(f.force_rate) <= 1e6)) msg += p + "force_rate = " + num(f.force_rate) + ": must be finite, |force_rate| <= 1e6 [N/s]\n";
  if (!(std::isfinite(f.torque_rate) && std::fabs(f.torque_rate) <= 1e4)) msg += p + "torque_rate = " + num(f.torque_rate) + ": must be finite, |torque_rate| <= 1e4 [N m/s]\n";
  if (!(finite_ge0(f.time_constant) && f.time_constant <= 1e3)) msg += p + "time_constant = " + num(f.time_constant) + ": must be in [0, 1000] [s]\n";
  if ((f.kind == FaultKind::Saturation || f.kind == FaultKind::ActuatorSaturation) && !(f.force >= 0.0))
    msg += p + "force = " + num(f.force) + ": a saturation limit must be >= 0 [N]\n";
  if (f.kind == FaultKind::Saturation && !(f.torque >= 0.0))
    msg += p + "torque = " + num(f.torque) + ": a saturation limit must be >= 0 [N m]\n";
}
}  // namespace

bool validate(const std::vector<FaultSpec>& faults, std::string* message) {
  std::string msg;
  if (faults.size() > static_cast<size_t>(kMaxFaults))
    msg += "faults: " + std::to_string(faults.size()) + " faults, at most " + std::to_string(kMaxFaults) + "\n";
  for (size_t i = 0; i < faults.size(); ++i) validate_fault(faults[i], "faults[" + std::to_string(i) + "].", msg);
  if (message) *message = msg;
  return msg.empty();
}

bool validate(const ClosedLoopConfig& c, std::string* message) {
  std::string msg, sub;
  if (!validate(c.plant, &sub)) append_prefixed(msg, sub, "plant.");
  if (!validate(c.observer, &sub)) append_prefixed(msg, sub, "observer.");
  if (c.estimator && !validate(*c.estimator, &sub)) append_prefixed(msg, sub, "estimator.");
  if (!validate(c.controller, &sub)) append_prefixed(msg, sub, "controller.");
  const double fs = c.plant.sensor.rate;
  if (std::isfinite(fs) && fs > 0.0) {
    if (!close_rel(c.observer.dt * fs, 1.0))
      msg += "observer.dt = " + num(c.observer.dt) + ": must equal 1 / plant.sensor.rate = " + num(1.0 / fs) + "\n";
    if (!close_rel(c.controller.sensor_rate, fs))
      msg += "controller.sensor_rate = " + num(c.controller.sensor_rate) + ": must equal plant.sensor.rate = " +
             num(fs) + "\n";
    const double fc = c.plant.actuator.command_rate;
    if (!close_rel(c.controller.command_ratio * fc, fs))
      msg += "controller.command_ratio = " + std::to_string(c.controller.command_ratio) +
             ": must equal plant.sensor.rate / plant.actuator.command_rate = " + num(fs / fc) + "\n";
  }
  const int kind = static_cast<int>(c.kind);
  if (kind < 0 || kind > 2) msg += "kind = " + std::to_string(kind) + ": unknown controller kind\n";
  if (!(std::isfinite(c.controller_start) && c.controller_start >= 0.0))
    msg += "controller_start = " + num(c.controller_start) + ": must be finite and >= 0 [s]\n";
  if (!(std::isfinite(c.constant_force) && c.constant_force >= 0.0))
    msg += "constant_force = " + num(c.constant_force) + ": must be finite and >= 0 [N]\n";
  if (!(c.cone_margin > 0.0 && c.cone_margin <= 1.0))
    msg += "cone_margin = " + num(c.cone_margin) + ": must satisfy 0 < cone_margin <= 1\n";
  if (!(std::isfinite(c.cone_release_rate) && c.cone_release_rate >= 0.0))
    msg += "cone_release_rate = " + num(c.cone_release_rate) + ": must be finite and >= 0 [N/s]\n";
  for (size_t i = 0; i < c.schedule.size(); ++i) {
    const ModeEvent& e = c.schedule[i];
    const std::string f = "schedule[" + std::to_string(i) + "].";
    if (!std::isfinite(e.time)) msg += f + "time = " + num(e.time) + ": must be finite [s]\n";
    const int a = static_cast<int>(e.action);
    if (a < 0 || a > 3) msg += f + "action = " + std::to_string(a) + ": unknown action\n";
  }
  if (!validate(c.faults, &sub)) msg += sub;
  if (c.stuck_samples < 0)
    msg += "stuck_samples = " + std::to_string(c.stuck_samples) + ": must be >= 0 (0: off) [samples]\n";
  if (message) *message = msg;
  return msg.empty();
}

// --- log -------------------------------------------------------------------------------------

void ClosedLoopLog::reserve(size_t n) {
  for (auto* v : {&t, &command, &static_force, &dynamic_force, &f_n, &slip_x, &slip_y, &slip, &rotation,
                  &theta, &cog_x, &cog_y, &gripper_y, &ext_fx, &ext_fy, &ext_tau})
    v->reserve(n);
  for (int i = 0; i < 2; ++i) {
    for (auto* v : {&f_n_meas[i], &f_t_meas[i], &tau_meas[i], &f_t_true[i], &tau_true[i], &omega_hat[i],
                    &slippage[i], &c_tilde[i], &omega_true[i], &c_tilde_true[i]})
      v->reserve(n);
    observer_status[i].reserve(n);
  }
  mode.reserve(n);
  pivot_end.reserve(n);
  for (auto* v : {&command_issued, &pivot_finished, &supported, &dropped, &finite, &fault_active}) v->reserve(n);
  status.reserve(n);
  actuator_command.reserve(n);
  mu_belief.reserve(n);
}

void ClosedLoopLog::append(const ClosedLoopSample& s) {
  t.push_back(s.t);
  command.push_back(s.command);
  static_force.push_back(s.static_force);
  dynamic_force.push_back(s.dynamic_force);
  f_n.push_back(s.f_n);
  for (int i = 0; i < 2; ++i) {
    f_n_meas[i].push_back(s.f_n_meas[i]);
    f_t_meas[i].push_back(s.f_t_meas[i]);
    tau_meas[i].push_back(s.tau_meas[i]);
    f_t_true[i].push_back(s.f_t_true[i]);
    tau_true[i].push_back(s.tau_true[i]);
    omega_hat[i].push_back(s.omega_hat[i]);
    slippage[i].push_back(s.slippage[i]);
    c_tilde[i].push_back(s.c_tilde[i]);
    omega_true[i].push_back(s.omega_true[i]);
    c_tilde_true[i].push_back(s.c_tilde_true[i]);
    observer_status[i].push_back(s.observer_status[i]);
  }
  slip_x.push_back(s.slip_x);
  slip_y.push_back(s.slip_y);
  slip.push_back(s.slip);
  rotation.push_back(s.rotation);
  theta.push_back(s.theta);
  cog_x.push_back(s.cog_x);
  cog_y.push_back(s.cog_y);
  gripper_y.push_back(s.gripper_y);
  ext_fx.push_back(s.ext_fx);
  ext_fy.push_back(s.ext_fy);
  ext_tau.push_back(s.ext_tau);
  mode.push_back(s.mode);
  pivot_end.push_back(s.pivot_end);
  command_issued.push_back(s.command_issued);
  pivot_finished.push_back(s.pivot_finished);
  supported.push_back(s.supported);
  dropped.push_back(s.dropped);
  finite.push_back(s.finite);
  status.push_back(s.status);
  fault_active.push_back(s.fault_active);
  actuator_command.push_back(s.actuator_command);
  mu_belief.push_back(s.mu_belief);
}

// --- loop ------------------------------------------------------------------------------------

namespace {
SlipControlSettings slip_settings(const ClosedLoopConfig& c) {
  SlipControlSettings s;
  s.observer = c.observer;
  s.controller = c.controller;
  s.fingers = 2;
  s.stuck_samples = c.stuck_samples;
  s.healthy_finger_fallback = c.healthy_finger_fallback;
  return s;
}
// The plant's contact model (tables shared by copy) or one built from the estimator parameters.
SlipControl make_slip_control(const ClosedLoopConfig& c, const GraspPlant& plant) {
  return c.estimator ? SlipControl(*c.estimator, slip_settings(c)) : SlipControl(plant.contact_model(), slip_settings(c));
}
}  // namespace

ClosedLoop::ClosedLoop(const ClosedLoopConfig& config)
    : cfg_(sorted(checked(config))),
      plant_(cfg_.plant),
      sc_(make_slip_control(cfg_, plant_)),
      faults_(cfg_.faults, 1.0 / cfg_.plant.sensor.rate) {
  dt_ = 1.0 / cfg_.plant.sensor.rate;
  ratio_ = cfg_.controller.command_ratio;
  reset();
}

void ClosedLoop::reset() noexcept {
  plant_.reset();
  command_ = plant_.state().f_cmd;
  sc_.reset(command_);
  sout_ = SlipControlOutput();
  sout_.force = command_;
  sout_.controller.force = command_;
  sout_.controller.static_force = command_;
  n_ = 0;
  next_event_ = 0;
  started_ = false;
  cone_fn_sum_ = {0.0, 0.0};
  cone_ft_sum_ = {0.0, 0.0};
  cone_count_ = 0;
  faults_.reset(command_);
}

FaultInjector::FaultInjector(const std::vector<FaultSpec>& faults, double sample_period) : faults_(faults) {
  std::string msg;
  if (!validate(faults, &msg)) throw std::invalid_argument("invalid faults:\n" + msg);
  if (!(sample_period >= 1e-9 && sample_period <= 1e3))
    throw std::invalid_argument("FaultInjector: sample_period = " + num(sample_period) + ": must be in [1e-9, 1e3] [s]");
  dt_ = sample_period;
  reset();
}

void FaultInjector::reset(double command) noexcept {
  last_ = {};
  frozen_ = {};
  was_active_ = {};
  lag_state_ = command;
  last_actuator_ = command;
  lag_init_ = false;
}

// First sample of a fault's window: the smallest n with n dt >= t_start - dt / 2.
int64_t FaultInjector::first_sample(const FaultSpec& f) const noexcept {
  return static_cast<int64_t>(std::ceil(f.t_start / dt_ - 0.5));
}

bool FaultInjector::on(const FaultSpec& f, int64_t n) const noexcept {
  const int64_t k0 = first_sample(f);
  if (n < k0) return false;
  const double t = static_cast<double>(n) * dt_;
  if (t >= f.t_start + f.duration - 0.5 * dt_) return false;
  if (f.every <= 0) return true;
  return (n - k0) % f.every < f.burst;
}

bool FaultInjector::sensors(int64_t n, std::array<FingerWrench, kMaxFingers>& fingers) noexcept {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  bool any = false;
  const int count = static_cast<int>(std::min(faults_.size(), static_cast<size_t>(kMaxFaults)));
  for (int k = 0; k < count; ++k) {
    const FaultSpec& f = faults_[k];
    if (f.kind == FaultKind::ActuatorLag || f.kind == FaultKind::ActuatorSaturation) continue;
    const bool active = on(f, n);
    const bool onset = active && !was_active_[k];
    was_active_[k] = active;
    if (!active) continue;
    any = true;
    const double t_rel = static_cast<double>(n) * dt_ - f.t_start;
    const int64_t burst_index = f.every > 0 ? (n - first_sample(f)) / f.every : 0;
    for (int i = 0; i < 2; ++i) {
      if (f.finger >= 0 && f.finger != i) continue;
      FingerWrench& w = fingers[i];
      switch (f.kind) {
        case FaultKind::Dropout: w = last_[i]; break;
        case FaultKind::NanBurst: w = FingerWrench{nan, nan, nan, nan}; break;
        case FaultKind::Spike: {
          const double sign = burst_index % 2 == 0 ? 1.0 : -1.0;
          w.f_x += sign * f.force;
          w.f_y += sign * f.force;
          w.tau += sign * f.torque;
          break;
        }
        case FaultKind::BiasDrift:
          w.f_x += f.force_rate * t_rel;
          w.f_y += f.force_rate * t_rel;
          w.tau += f.torque_rate * t_rel;
          break;
        case FaultKind::Saturation:
          w.f_x = clampd(w.f_x, -f.force, f.force);
          w.f_y = clampd(w.f_y, -f.force, f.force);
          w.tau = clampd(w.tau, -f.torque, f.torque);
          break;
        case FaultKind::Stuck:
          if (onset) frozen_[i] = last_[i];
          w = frozen_[i];
          break;
        case FaultKind::Dead:
        case FaultKind::ContactLoss: w = FingerWrench{}; break;
        default: break;
      }
    }
  }
  // Dropout repeats what was delivered (a NaN burst leaves the last finite sample in place).
  for (int i = 0; i < 2; ++i) {
    const FingerWrench& w = fingers[i];
    if (std::isfinite(w.f_n) && std::isfinite(w.f_x) && std::isfinite(w.f_y) && std::isfinite(w.tau)) last_[i] = w;
  }
  return any;
}

double FaultInjector::actuator(int64_t n, double command, bool& active) noexcept {
  double f = command;
  const int count = static_cast<int>(std::min(faults_.size(), static_cast<size_t>(kMaxFaults)));
  bool lagged = false;
  for (int k = 0; k < count; ++k) {
    const FaultSpec& fs = faults_[k];
    if (fs.kind != FaultKind::ActuatorLag && fs.kind != FaultKind::ActuatorSaturation) continue;
    if (!on(fs, n)) continue;
    active = true;
    if (fs.kind == FaultKind::ActuatorSaturation) {
      f = std::min(f, fs.force);
    } else if (fs.time_constant > 0.0) {
      // exact discretisation of a first-order lag over one sample, started at the last output
      if (!lag_init_) lag_state_ = last_actuator_;
      lag_init_ = true;
      lagged = true;
      const double a = std::exp(-dt_ / fs.time_constant);
      lag_state_ = a * lag_state_ + (1.0 - a) * f;
      f = lag_state_;
    }
  }
  if (!lagged) lag_init_ = false;
  last_actuator_ = f;
  return f;
}

void ClosedLoop::apply_events(double t) noexcept {
  // Half a sample of tolerance: an event at t is applied at the sample taken at t.
  while (next_event_ < cfg_.schedule.size() && cfg_.schedule[next_event_].time <= t + 0.5 * dt_) {
    if (cfg_.kind == ControllerKind::Lugrip) {
      switch (cfg_.schedule[next_event_].action) {
        case ModeAction::Pivot: sc_.request_pivoting(); break;
        case ModeAction::SlippingAvoidance: sc_.request_slipping_avoidance(); break;
        case ModeAction::DynamicOn: sc_.set_dynamic_enabled(true); break;
        case ModeAction::DynamicOff: sc_.set_dynamic_enabled(false); break;
      }
    }
    ++next_event_;
  }
}

void ClosedLoop::cone_command() noexcept {
  const GraspControllerSettings& s = cfg_.controller;
  const double mu = cfg_.estimator.value_or(cfg_.plant.contact).mu, margin = cfg_.cone_margin;
  const double T = ratio_ * dt_;
  double u = 0.0, ft_max = 0.0;
  for (int i = 0; i < 2; ++i) {
    const double fn = cone_fn_sum_[i] / cone_count_, ft = cone_ft_sum_[i] / cone_count_;
    if (fn > 0.0 && std::isfinite(fn) && std::isfinite(ft)) u = std::max(u, ft / (mu * fn));
    if (std::isfinite(ft)) ft_max = std::max(ft_max, ft);
  }
  const double required = ft_max / (mu * margin);
  double target = command_;
  if (u >= margin) target = std::max(command_, required);
  else if (cfg_.cone_release_rate > 0.0) target = std::max(required, command_ - cfg_.cone_release_rate * T);
  const double f = clampd(target, command_ - s.max_rate * T, command_ + s.max_rate * T);
  command_ = clampd(f, s.f_min, s.f_max);
  cone_fn_sum_ = {0.0, 0.0};
  cone_ft_sum_ = {0.0, 0.0};
  cone_count_ = 0;
}

Status ClosedLoop::step(ClosedLoopSample& out) noexcept {
  const double t = static_cast<double>(n_) * dt_;
  apply_events(t);
  const bool tick = n_ % ratio_ == 0;
  if (!started_ && tick && t >= cfg_.controller_start - 0.5 * dt_) {
    started_ = true;
    if (cfg_.kind == ControllerKind::Lugrip) sc_.reset(command_);
    if (cfg_.kind == ControllerKind::FrictionCone) command_ = cfg_.controller.f_min;  // starts at the floor
  }

  // The observers run on every sample; the controller only while the lugrip law is active.
  SlipControlInput sin;
  for (int i = 0; i < 2; ++i) {
    const FingerSample& s = plant_.sensor_sample(i);
    sin.fingers[i] = FingerWrench{s.f_n, s.f_x, s.f_y, s.tau};
  }
  bool fault = faults_.empty() ? false : faults_.sensors(n_, sin.fingers);
  const bool lugrip_active = started_ && cfg_.kind == ControllerKind::Lugrip;
  const Status status = lugrip_active ? sc_.step(sin, sout_) : sc_.observe(sin, sout_);
  for (int i = 0; i < 2; ++i) {
    const FingerSample& s = plant_.sensor_sample(i);
    const ObserverOutput& o = sout_.fingers[i];
    const FingerWrench& w = sin.fingers[i];  // what the observers received
    out.f_n_meas[i] = w.f_n;
    out.f_t_meas[i] = planar_norm(w.f_x, w.f_y);
    out.tau_meas[i] = w.tau;
    out.f_t_true[i] = planar_norm(s.true_f_x, s.true_f_y);
    out.tau_true[i] = s.true_tau;
    out.omega_hat[i] = o.omega_hat;
    out.slippage[i] = o.S;
    out.c_tilde[i] = o.c_tilde;
    out.omega_true[i] = s.omega;
    out.c_tilde_true[i] = s.c_tilde;
    out.observer_status[i] = static_cast<int>(o.status);
  }

  out.command_issued = false;
  out.pivot_finished = false;
  out.pivot_end = 0;
  if (started_) {
    switch (cfg_.kind) {
      case ControllerKind::Lugrip:
        command_ = sout_.force;
        out.command_issued = sout_.controller.command_issued;
        out.pivot_finished = sout_.controller.pivot_finished;
        out.pivot_end = static_cast<int>(sout_.controller.pivot_end);
        break;
      case ControllerKind::ConstantForce:
        if (tick) {
          command_ = cfg_.constant_force;
          out.command_issued = true;
        }
        break;
      case ControllerKind::FrictionCone:
        for (int i = 0; i < 2; ++i) {
          cone_fn_sum_[i] += out.f_n_meas[i];
          cone_ft_sum_[i] += out.f_t_meas[i];
        }
        ++cone_count_;
        if (tick) {
          cone_command();
          out.command_issued = true;
        }
        break;
    }
  }
  const double actuator = faults_.empty() ? command_ : faults_.actuator(n_, command_, fault);
  plant_.set_command(actuator);

  const PlantState& st = plant_.state();
  out.index = n_;
  out.t = t;
  out.command = command_;
  out.actuator_command = actuator;
  out.mu_belief = cfg_.kind == ControllerKind::Lugrip ? sc_.controller().mu_belief() : sc_.controller().mu();
  out.status = static_cast<int>(status);
  out.fault_active = fault;
  const bool lugrip = cfg_.kind == ControllerKind::Lugrip && started_;
  out.static_force = lugrip ? sout_.controller.static_force : command_;
  out.dynamic_force = lugrip ? sout_.controller.dynamic_force : 0.0;
  out.mode = lugrip ? static_cast<int>(sout_.controller.mode) : 0;
  out.f_n = st.f_n;
  out.slip_x = st.slip_x;
  out.slip_y = st.slip_y;
  out.slip = cfg_.plant.model == PlantModel::Patch ? planar_norm(st.slip_x, st.slip_y) : st.max_slip;
  out.rotation = st.slip_angle;
  out.theta = st.theta;
  out.cog_x = st.x;
  out.cog_y = st.y;
  out.gripper_y = st.gripper_y;
  out.ext_fx = st.ext_fx;
  out.ext_fy = st.ext_fy;
  out.ext_tau = st.ext_tau;
  out.supported = st.supported;
  out.dropped = st.dropped;
  bool ok = std::isfinite(out.command) && std::isfinite(out.static_force) && std::isfinite(out.dynamic_force) &&
            std::isfinite(out.f_n) && std::isfinite(out.slip) && std::isfinite(out.theta);
  ok = ok && std::isfinite(out.actuator_command);
  for (int i = 0; i < 2; ++i)
    ok = ok && (fault || (std::isfinite(out.f_n_meas[i]) && std::isfinite(out.f_t_meas[i]) && std::isfinite(out.tau_meas[i]))) &&
         std::isfinite(out.omega_hat[i]) && std::isfinite(out.slippage[i]) && std::isfinite(out.c_tilde[i]) &&
         std::isfinite(out.f_t_true[i]) && std::isfinite(out.tau_true[i]);
  out.finite = ok;

  plant_.advance_sample();
  ++n_;
  return status;
}

void ClosedLoop::run(int64_t samples, ClosedLoopLog& log) {
  if (samples <= 0) return;
  log.reserve(log.size() + static_cast<size_t>(samples));
  ClosedLoopSample s;
  for (int64_t k = 0; k < samples; ++k) {
    step(s);
    log.append(s);
  }
}

}  // namespace lugrip
