// Planar grasp simulator: object dynamics, actuator, sensors, disturbances, drop detection.
#include "lugrip/grasp_plant.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

#include "lugrip/slider_model.hpp"

#include "format.hpp"

namespace lugrip {

namespace {
constexpr double kPi = 3.14159265358979323846;

bool finite(double x) { return std::isfinite(x); }

// n when x / y is (numerically) the positive integer n, else 0.
long integer_ratio(double x, double y) {
  if (!(finite(x) && finite(y) && x > 0.0 && y > 0.0)) return 0;
  const double r = x / y;
  const double n = std::round(r);
  if (n < 1.0 || n > 1e9 || std::fabs(r - n) > 1e-9 * n) return 0;
  return static_cast<long>(n);
}

std::string num(double v) { return detail::format_number(v); }

const PlantConfig& checked(const PlantConfig& c) {
  std::string msg;
  if (!validate(c, &msg)) throw std::invalid_argument("invalid PlantConfig:\n" + msg);
  return c;
}

inline double clampd(double x, double lo, double hi) { return x < lo ? lo : (x > hi ? hi : x); }
}  // namespace

const char* to_string(PlantModel m) noexcept {
  switch (m) {
    case PlantModel::Patch: return "patch";
    case PlantModel::Lumped: return "lumped";
  }
  return "unknown";
}

const char* to_string(PulseShape s) noexcept {
  switch (s) {
    case PulseShape::Rectangular: return "rectangular";
    case PulseShape::HalfSine: return "half_sine";
    case PulseShape::Ramp: return "ramp";
    case PulseShape::Triangle: return "triangle";
  }
  return "unknown";
}

bool validate(const PlantConfig& c, std::string* message) {
  std::string msg, sub;
  if (!validate(c.contact, &sub)) {
    std::istringstream lines(sub);
    for (std::string line; std::getline(lines, line);)
      if (!line.empty()) msg += "contact." + line + "\n";
  }
  auto need = [&](bool ok, const std::string& field, double value, const char* rule) {
    if (!ok) msg += field + " = " + num(value) + ": " + rule + "\n";
  };
  need(c.model == PlantModel::Patch || c.model == PlantModel::Lumped, "model", static_cast<int>(c.model), "unknown model");
  const ObjectConfig& o = c.object;
  need(finite(o.mass) && o.mass > 0.0, "object.mass", o.mass, "must be finite and > 0 [kg]");
  need(finite(o.inertia) && o.inertia > 0.0, "object.inertia", o.inertia, "must be finite and > 0 [kg m^2]");
  need(finite(o.cog_x), "object.cog_x", o.cog_x, "must be finite [m]");
  need(finite(o.cog_y), "object.cog_y", o.cog_y, "must be finite [m]");
  need(finite(o.theta0), "object.theta0", o.theta0, "must be finite [rad]");
  const ActuatorConfig& a = c.actuator;
  need(finite(a.f_max) && a.f_max > 0.0, "actuator.f_max", a.f_max, "must be finite and > 0 [N]");
  need(finite(a.f_init) && a.f_init >= 0.0 && a.f_init <= a.f_max, "actuator.f_init", a.f_init, "must be in [0, f_max] [N]");
  need(finite(a.time_constant) && a.time_constant >= 0.0, "actuator.time_constant", a.time_constant, "must be finite and >= 0 [s]");
  need(a.rate_limit > 0.0, "actuator.rate_limit", a.rate_limit, "must be > 0 (inf allowed) [N/s]");
  need(finite(c.rate) && c.rate > 0.0, "rate", c.rate, "must be finite and > 0 [Hz]");
  need(integer_ratio(c.rate, a.command_rate) > 0, "actuator.command_rate", a.command_rate,
       "must divide the plant rate (rate / command_rate a positive integer) [Hz]");
  const SensorConfig& s = c.sensor;
  need(integer_ratio(c.rate, s.rate) > 0, "sensor.rate", s.rate,
       "must divide the plant rate (rate / sensor.rate a positive integer) [Hz]");
  need(finite(s.force_noise) && s.force_noise >= 0.0, "sensor.force_noise", s.force_noise, "must be finite and >= 0 [N]");
  need(finite(s.torque_noise) && s.torque_noise >= 0.0, "sensor.torque_noise", s.torque_noise, "must be finite and >= 0 [N m]");
  need(finite(s.force_resolution) && s.force_resolution >= 0.0, "sensor.force_resolution", s.force_resolution, "must be finite and >= 0 [N]");
  need(finite(s.torque_resolution) && s.torque_resolution >= 0.0, "sensor.torque_resolution", s.torque_resolution, "must be finite and >= 0 [N m]");
  need(finite(s.filter_time_constant) && s.filter_time_constant >= 0.0, "sensor.filter_time_constant", s.filter_time_constant, "must be finite and >= 0 [s]");
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 4; ++j)
      need(finite(s.bias[i][j]), "sensor.bias[" + std::to_string(i) + "][" + std::to_string(j) + "]", s.bias[i][j], "must be finite");
  const PatchSettings& p = c.patch;
  need(p.rings >= 1 && p.rings <= 200, "patch.rings", p.rings, "must be in [1, 200]");
  need(finite(p.bristle_stiffness) && p.bristle_stiffness > 0.0, "patch.bristle_stiffness", p.bristle_stiffness, "must be finite and > 0 [1/m]");
  need(finite(p.bristle_damping) && p.bristle_damping >= 0.0, "patch.bristle_damping", p.bristle_damping, "must be finite and >= 0 [s]");
  need(finite(p.static_ratio) && p.static_ratio >= 1.0, "patch.static_ratio", p.static_ratio, "must be finite and >= 1");
  need(finite(p.stribeck_velocity) && p.stribeck_velocity > 0.0, "patch.stribeck_velocity", p.stribeck_velocity, "must be finite and > 0 [m/s]");
  const DropConfig& d = c.drop;
  need(d.slip_limit > 0.0, "drop.slip_limit", d.slip_limit, "must be > 0 (inf allowed) [m]");
  need(d.rotation_limit > 0.0, "drop.rotation_limit", d.rotation_limit, "must be > 0 (inf allowed) [rad]");
  need(finite(d.contact_force_min) && d.contact_force_min >= 0.0, "drop.contact_force_min", d.contact_force_min, "must be finite and >= 0 [N]");
  need(finite(c.gravity) && c.gravity >= 0.0, "gravity", c.gravity, "must be finite and >= 0 [m/s^2]");
  need(c.substeps >= 1 && c.substeps <= 1000, "substeps", c.substeps, "must be in [1, 1000]");
  for (size_t i = 0; i < c.moves.size(); ++i) {
    const GripperMove& m = c.moves[i];
    const std::string f = "moves[" + std::to_string(i) + "].";
    need(finite(m.t_start), f + "t_start", m.t_start, "must be finite [s]");
    need(finite(m.duration) && m.duration > 0.0, f + "duration", m.duration, "must be finite and > 0 [s]");
    need(finite(m.dx), f + "dx", m.dx, "must be finite [m]");
    need(finite(m.dy), f + "dy", m.dy, "must be finite [m]");
  }
  for (size_t i = 0; i < c.disturbances.size(); ++i) {
    const Disturbance& q = c.disturbances[i];
    const std::string f = "disturbances[" + std::to_string(i) + "].";
    need(finite(q.t_start), f + "t_start", q.t_start, "must be finite [s]");
    need(finite(q.duration) && q.duration > 0.0, f + "duration", q.duration, "must be finite and > 0 [s]");
    const int sh = static_cast<int>(q.shape);
    need(sh >= 0 && sh <= 3, f + "shape", sh, "unknown pulse shape");
    need(finite(q.force_x) && finite(q.force_y) && finite(q.torque), f + "force/torque",
         q.force_x + q.force_y + q.torque, "must be finite");
    need(finite(q.point_x) && finite(q.point_y), f + "point", q.point_x + q.point_y, "must be finite [m]");
  }
  if (message) *message = msg;
  return msg.empty();
}

// ---------------------------------------------------------------------------------------------

GraspPlant::GraspPlant(const PlantConfig& config)
    : cfg_(checked(config)),
      model_(cfg_.contact),
      patch_(cfg_.contact, cfg_.patch),
      cor_(model_) {
  h_ = 1.0 / cfg_.rate;
  steps_per_sample_ = static_cast<int>(integer_ratio(cfg_.rate, cfg_.sensor.rate));
  steps_per_command_ = static_cast<int>(integer_ratio(cfg_.rate, cfg_.actuator.command_rate));
  act_decay_ = cfg_.actuator.time_constant > 0.0 ? std::exp(-h_ / cfg_.actuator.time_constant) : 0.0;
  const double tf = cfg_.sensor.filter_time_constant;
  filt_alpha_ = tf > 0.0 ? -std::expm1(-h_ / tf) : 1.0;
  reset();
}

void GraspPlant::trig(double th, double& c, double& s) noexcept {
  if (!(trig_ok_ && th == trig_th_)) {  // NaN never hits (NaN != NaN)
    trig_c_ = std::cos(th);
    trig_s_ = std::sin(th);
    trig_th_ = th;
    trig_ok_ = true;
  }
  c = trig_c_;
  s = trig_s_;
}

double GraspPlant::rho_at(double f_n) noexcept {
  if (!(rho_ok_ && f_n == rho_fn_)) {
    rho_ = model_.rho(f_n);
    rho_fn_ = f_n;
    rho_ok_ = true;
  }
  return rho_;
}

void GraspPlant::gripper_at(double t, double& x, double& y, double& vx, double& vy) const noexcept {
  x = y = vx = vy = 0.0;
  for (const GripperMove& m : cfg_.moves) {
    const double s = (t - m.t_start) / m.duration;
    double pos, vel;
    if (s <= 0.0) {
      pos = vel = 0.0;
    } else if (s >= 1.0) {
      pos = 1.0;
      vel = 0.0;
    } else {  // minimum jerk: 10 s^3 - 15 s^4 + 6 s^5
      const double s2 = s * s;
      pos = s2 * s * (10.0 - 15.0 * s + 6.0 * s2);
      vel = 30.0 * s2 * (1.0 - 2.0 * s + s2) / m.duration;
    }
    x += m.dx * pos;
    y += m.dy * pos;
    vx += m.dx * vel;
    vy += m.dy * vel;
  }
}

namespace {
// Sum of the active pulses at t; cs(c, s) gives cos and sin of the object angle (only called
// when a pulse is active).
template <class Trig>
void sum_pulses(const std::vector<Disturbance>& ds, double t, Trig&& cs, double& fx, double& fy, double& tau) noexcept {
  fx = fy = tau = 0.0;
  double c = 1.0, s = 0.0;
  bool have_cs = false;
  for (const Disturbance& d : ds) {
    const double u = (t - d.t_start) / d.duration;
    if (!(u >= 0.0 && u < 1.0)) continue;
    if (!have_cs) {
      cs(c, s);
      have_cs = true;
    }
    double a = 0.0;
    switch (d.shape) {
      case PulseShape::Rectangular: a = 1.0; break;
      case PulseShape::HalfSine: a = std::sin(kPi * u); break;
      case PulseShape::Ramp: a = u; break;
      case PulseShape::Triangle: a = 1.0 - std::fabs(2.0 * u - 1.0); break;
    }
    const double px = c * d.point_x - s * d.point_y, py = s * d.point_x + c * d.point_y;
    const double qx = a * d.force_x, qy = a * d.force_y;
    fx += qx;
    fy += qy;
    tau += a * d.torque + px * qy - py * qx;
  }
}
}  // namespace

void GraspPlant::disturbance_at(double t, double theta, double& fx, double& fy, double& tau) const noexcept {
  sum_pulses(cfg_.disturbances, t, [theta](double& c, double& s) { c = std::cos(theta); s = std::sin(theta); },
             fx, fy, tau);
}

void GraspPlant::disturbance_cs(double t, double c, double s, double& fx, double& fy, double& tau) const noexcept {
  sum_pulses(cfg_.disturbances, t, [c, s](double& cc, double& ss) { cc = c; ss = s; }, fx, fy, tau);
}

void GraspPlant::reset() noexcept {
  const ObjectConfig& o = cfg_.object;
  th_ = o.theta0;
  rx_ = std::cos(th_) * o.cog_x - std::sin(th_) * o.cog_y;
  ry_ = std::sin(th_) * o.cog_x + std::cos(th_) * o.cog_y;
  ux_ = uy_ = Vx_ = Vy_ = 0.0;
  vx_ = vy_ = om_ = 0.0;
  f_act_ = f_held_ = f_cmd_ = cfg_.actuator.f_init;
  double gx, gy, gvx, gvy;
  gripper_at(0.0, gx, gy, gvx, gvy);
  support_y_ = gy + ry_;
  supported_ = cfg_.support;
  ext_fx_ = ext_fy_ = ext_tau_ = 0.0;
  pad_ = PadWrench();
  lumped_z_ = lumped_c_ = lumped_slip_ = 0.0;
  patch_.reset();
  cor_.reset();
  trig_ok_ = rho_ok_ = false;
  cmd_phase_ = sample_phase_ = 0;
  sample_index_ = 0;
  for (int i = 0; i < 2; ++i) rng_[i].seed_with(cfg_.seed * 0x9E3779B97F4A7C15ULL + static_cast<uint64_t>(i + 1));
  st_ = PlantState();
  report_state();
  for (int i = 0; i < 2; ++i) {
    double w[4];
    true_wrench(i, w);
    for (int j = 0; j < 4; ++j) filt_[i][j] = w[j];
  }
  update_drop();
  take_sample();
}

void GraspPlant::report_state() noexcept {
  double gx, gy, gvx, gvy;
  gripper_at(st_.t, gx, gy, gvx, gvy);
  st_.f_cmd = f_cmd_;
  st_.f_held = f_held_;
  st_.f_n = f_act_;
  st_.gripper_x = gx;
  st_.gripper_y = gy;
  st_.gripper_vx = gvx;
  st_.gripper_vy = gvy;
  st_.x = rx_;
  st_.y = ry_;
  st_.vx = vx_;
  st_.vy = vy_;
  st_.theta = th_;
  st_.omega = om_;
  st_.contact_fx = 2.0 * pad_.fx;
  st_.contact_fy = 2.0 * pad_.fy;
  st_.contact_tau = 2.0 * pad_.tau;  // pad wrench about the pad centre = grasp point
  st_.supported = supported_;
}

void GraspPlant::set_command(double f_cmd) noexcept {
  if (std::isnan(f_cmd)) return;
  f_cmd_ = clampd(f_cmd, 0.0, cfg_.actuator.f_max);
  st_.f_cmd = f_cmd_;
}

void GraspPlant::set_external(double fx, double fy, double torque) noexcept {
  ext_fx_ = finite(fx) ? fx : 0.0;
  ext_fy_ = finite(fy) ? fy : 0.0;
  ext_tau_ = finite(torque) ? torque : 0.0;
}

bool GraspPlant::step() noexcept {
  const int64_t n = st_.steps;
  const double t0 = static_cast<double>(n) * h_;
  // Actuator: ZOH of the command at the command ticks, saturation, first-order lag, rate limit.
  if (cmd_phase_ == 0) f_held_ = f_cmd_;  // n % steps_per_command_ == 0
  if (++cmd_phase_ == steps_per_command_) cmd_phase_ = 0;
  const ActuatorConfig& a = cfg_.actuator;
  const double target = clampd(f_held_, 0.0, a.f_max);
  double f = a.time_constant > 0.0 ? target + (f_act_ - target) * act_decay_ : target;
  const double dmax = a.rate_limit * h_;
  f = clampd(f, f_act_ - dmax, f_act_ + dmax);
  f_act_ = clampd(f, 0.0, a.f_max);

  const int ns = cfg_.substeps;
  const double hs = h_ / ns;
  for (int k = 0; k < ns; ++k) {
    const double ts = t0 + k * hs;
    if (cfg_.model == PlantModel::Patch) substep_patch(hs, ts);
    else substep_lumped(hs, ts);
  }

  st_.steps = n + 1;
  st_.t = static_cast<double>(n + 1) * h_;
  // Sensor anti-alias low-pass (continuous-time first order, exact for a held input).
  const double alpha = filt_alpha_;
  for (int i = 0; i < 2; ++i) {
    double w[4];
    true_wrench(i, w);
    for (int j = 0; j < 4; ++j) filt_[i][j] += alpha * (w[j] - filt_[i][j]);
  }
  report_state();
  update_drop();
  if (++sample_phase_ == steps_per_sample_) {  // (n + 1) % steps_per_sample_ == 0
    sample_phase_ = 0;
    take_sample();
    return true;
  }
  return false;
}

Status GraspPlant::step(const PlantInput& in, PlantOutput& out) noexcept {
  const bool valid = !std::isnan(in.command);
  if (valid) set_command(in.command);
  advance_sample();
  out.state = st_;
  out.fingers = sample_;
  return valid ? Status::Ok : Status::InvalidSample;
}

int64_t GraspPlant::advance_sample() noexcept {
  while (!step()) {
  }
  return sample_[0].index;
}

void GraspPlant::true_wrench(int finger, double out[4]) const noexcept {
  out[0] = f_act_;
  if (finger == 0) {
    out[1] = -pad_.fx;
    out[2] = -pad_.fy;
    out[3] = -pad_.tau;
  } else {
    out[1] = pad_.fx;
    out[2] = -pad_.fy;
    out[3] = pad_.tau;
  }
}

void GraspPlant::take_sample() noexcept {
  const int64_t index = sample_index_++;  // st_.steps / steps_per_sample_
  const SensorConfig& sc = cfg_.sensor;
  const ObjectConfig& o = cfg_.object;
  // displacement of the object point that was at the grasp point: u = r - R(theta) cog
  const double ux = ux_, uy = uy_;  // zero for the lumped plant
  const double rho = f_act_ > 0.0 ? rho_at(f_act_) : 0.0;
  // |CoR - pad centre| / rho of the relative motion
  double a;
  if (cfg_.model == PlantModel::Lumped) {
    a = rho > 0.0 ? std::min(std::fabs(lumped_c_) / rho, 1e3) : 0.0;
  } else {
    const double vnorm = std::hypot(Vx_, Vy_);
    if (rho <= 0.0 || (vnorm == 0.0 && om_ == 0.0)) a = 0.0;
    else if (vnorm >= 1e3 * rho * std::fabs(om_)) a = 1e3;
    else a = vnorm / (rho * std::fabs(om_));
  }
  for (int i = 0; i < 2; ++i) {
    FingerSample& f = sample_[i];
    const double sgn = i == 0 ? 1.0 : -1.0;  // x_i and z_i flip for finger 1
    double w[4];
    true_wrench(i, w);
    f.index = index;
    f.t = st_.t;
    f.true_f_n = w[0];
    f.true_f_x = w[1];
    f.true_f_y = w[2];
    f.true_tau = w[3];
    double meas[4];
    for (int j = 0; j < 4; ++j) {
      const double sd = j == 3 ? sc.torque_noise : sc.force_noise;
      const double q = j == 3 ? sc.torque_resolution : sc.force_resolution;
      double v = filt_[i][j] + sc.bias[i][j] + sd * rng_[i].normal();
      if (q > 0.0) v = q * std::round(v / q);
      meas[j] = v;
    }
    f.f_n = meas[0];
    f.f_x = meas[1];
    f.f_y = meas[2];
    f.tau = meas[3];
    f.slip_x = sgn * ux;
    f.slip_y = uy;
    f.slip_angle = sgn * (th_ - o.theta0);
    f.slip_vx = sgn * Vx_;
    f.slip_vy = Vy_;
    f.omega = sgn * om_;
    const double wi = sgn * om_;
    f.c_tilde = wi > 0.0 ? -a : a;
    f.rho = rho;
  }
}

void GraspPlant::update_drop() noexcept {
  const ObjectConfig& o = cfg_.object;
  st_.slip_x = ux_;
  st_.slip_y = uy_;
  const double slip = cfg_.model == PlantModel::Patch ? std::hypot(ux_, uy_) : lumped_slip_;
  st_.slip_angle = th_ - o.theta0;
  st_.max_slip = std::max(st_.max_slip, slip);
  st_.max_rotation = std::max(st_.max_rotation, std::fabs(st_.slip_angle));
  int reason = 0;
  if (slip > cfg_.drop.slip_limit) reason |= 1;
  if (std::fabs(st_.slip_angle) > cfg_.drop.rotation_limit) reason |= 2;
  if (f_act_ < cfg_.drop.contact_force_min && !supported_) reason |= 4;
  if (reason) {
    if (!st_.dropped) st_.drop_time = st_.t;
    st_.dropped = true;
    st_.drop_reason |= reason;
  }
}

double GraspPlant::energy() const noexcept {
  const ObjectConfig& o = cfg_.object;
  double gx, gy, gvx, gvy;
  gripper_at(st_.t, gx, gy, gvx, gvy);
  const double wx = gvx + vx_, wy = gvy + vy_;
  const double kin = 0.5 * o.mass * (wx * wx + wy * wy) + 0.5 * o.inertia * om_ * om_;
  const double pot = o.mass * cfg_.gravity * (gy + ry_);
  const double el = cfg_.model == PlantModel::Patch ? 2.0 * patch_.bristle_energy()
                                                     : cfg_.contact.sigma0 * lumped_z_ * lumped_z_;
  return kin + pot + el;
}

}  // namespace lugrip
