// SlipControl: per-finger Observer -> GraspController, statuses forwarded.
#include "lugrip/slip_control.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "format.hpp"

namespace lugrip {

namespace {

void append_prefixed(std::string& msg, const std::string& sub, const char* prefix) {
  std::istringstream lines(sub);
  for (std::string line; std::getline(lines, line);)
    if (!line.empty()) msg += std::string(prefix) + line + "\n";
}

const SlipControlSettings& checked(const SlipControlSettings& s) {
  std::string msg;
  if (!validate(s, &msg)) throw std::invalid_argument("invalid SlipControlSettings:\n" + msg);
  return s;
}

const ContactParams& checked(const ContactParams& p) {
  validate_or_throw(p);
  return p;
}

}  // namespace

bool validate(const SlipControlSettings& s, std::string* message) {
  std::string msg, sub;
  if (!validate(s.observer, &sub)) append_prefixed(msg, sub, "observer.");
  if (!validate(s.controller, &sub)) append_prefixed(msg, sub, "controller.");
  if (s.fingers != 1 && s.fingers != 2)
    msg += "fingers = " + std::to_string(s.fingers) + ": must be 1 or 2\n";
  const double fs = s.controller.sensor_rate, dt = s.observer.dt;
  if (std::isfinite(fs) && fs > 0.0 && std::isfinite(dt) && dt > 0.0 &&
      !(std::fabs(dt * fs - 1.0) <= 1e-9))
    msg += "observer.dt = " + detail::format_number(dt) + ": must equal 1 / controller.sensor_rate = " +
           detail::format_number(1.0 / fs) + " [s]\n";
  if (message) *message = msg;
  return msg.empty();
}

SlipControl::SlipControl(const ContactParams& params, const SlipControlSettings& settings)
    : SlipControl(ContactModel(checked(params)), settings) {}

SlipControl::SlipControl(const ContactModel& model, const SlipControlSettings& settings)
    : s_(checked(settings)),
      obs_{Observer(model, s_.observer), Observer(model, s_.observer)},
      ctrl_(model, s_.controller) {
  for (int i = 0; i < kMaxFingers; ++i) cin_.fingers[i].present = i < s_.fingers;
}

Status SlipControl::observe(const SlipControlInput& in, SlipControlOutput& out) noexcept {
  Status worst = Status::Ok;
  for (int i = 0; i < s_.fingers; ++i) {
    const FingerWrench& w = in.fingers[i];
    const ObserverInput oin = ObserverInput::from_force_vector(w.f_n, w.f_x, w.f_y, w.tau, in.dt);
    ObserverOutput& o = out.fingers[i];
    obs_[i].step(oin, o);
    FingerInput& f = cin_.fingers[i];
    f.omega_hat = o.omega_hat;
    f.omega_resolution = o.omega_resolution;
    f.slippage = o.S;
    f.c_tilde = o.c_tilde;
    f.f_t = oin.f_t;
    f.tau = oin.tau;
    f.status = o.status;
    if (!is_valid(o.status) && (worst == Status::Ok || static_cast<int>(o.status) > static_cast<int>(worst)))
      worst = o.status;
  }
  return worst;
}

Status SlipControl::step(const SlipControlInput& in, SlipControlOutput& out) noexcept {
  observe(in, out);
  ctrl_.step(cin_, out.controller);
  out.force = out.controller.force;
  out.status = out.controller.status;
  return out.status;
}

void SlipControl::reset(double force) noexcept {
  for (auto& o : obs_) o.reset();
  ctrl_.reset(force);
}

void SlipControl::set_mu(double mu) {
  ContactParams p = params();
  p.mu = mu;
  validate_or_throw(p);
  const ContactModel model(p);
  ctrl_.set_contact_model(model);
  for (auto& o : obs_) o = Observer(model, s_.observer);
}

}  // namespace lugrip
