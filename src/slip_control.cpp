// SlipControl: per-finger Observer -> GraspController, statuses forwarded.
#include "lugrip/slip_control.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "field_checks.hpp"
#include "format.hpp"

namespace lugrip {

namespace {

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

bool validate(const SlipControlSettings& s, std::string* message) { return detail::validate_fields(s, message); }

std::string to_string(const SlipControlSettings& s) { return detail::print_fields(s); }

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
    if (s_.stuck_samples > 0) {
      const FingerWrench& p = prev_[i];
      // bit-identical repeats only (NaN never compares equal: those are InvalidSample already)
      const bool same = w.f_n == p.f_n && w.f_x == p.f_x && w.f_y == p.f_y && w.tau == p.tau;
      repeats_[i] = same ? (repeats_[i] < s_.stuck_samples ? repeats_[i] + 1 : repeats_[i]) : 0;
      prev_[i] = w;
      if (repeats_[i] >= s_.stuck_samples && is_valid(o.status)) o.status = Status::SensorFault;
    }
    FingerInput& f = cin_.fingers[i];
    // the controller's C_d takes the observer's state, as before the observer gated its reported
    // omega_hat where the speed is not in the data (the controller has the resolution beside it)
    f.omega_hat = o.omega_state;
    f.omega_resolution = o.omega_resolution;
    f.slippage = o.S;
    f.c_tilde = o.c_tilde;
    f.f_t = oin.f_t;
    f.tau = oin.tau;
    f.f_n = oin.f_n;
    f.status = o.status;
    if (!is_valid(o.status) && (worst == Status::Ok || static_cast<int>(o.status) > static_cast<int>(worst)))
      worst = o.status;
  }
  return worst;
}

Status SlipControl::step(const SlipControlInput& in, SlipControlOutput& out) noexcept {
  const Status worst = observe(in, out);
  int faulty = -1, n_faulty = 0;
  if (s_.healthy_finger_fallback && s_.fingers == 2)
    for (int i = 0; i < 2; ++i)
      if (!is_valid(cin_.fingers[i].status)) {
        faulty = i;
        ++n_faulty;
      }
  if (n_faulty == 1) cin_.fingers[faulty].present = false;  // this cycle only
  cin_.command = in.command;
  ctrl_.step(cin_, out.controller);
  if (n_faulty == 1) cin_.fingers[faulty].present = true;
  out.force = out.controller.force;
  out.status = out.controller.status;
  if (n_faulty == 1 && out.status == Status::Ok) out.status = worst;
  return out.status;
}

void SlipControl::reset(double force) noexcept {
  for (auto& o : obs_) o.reset();
  ctrl_.reset(force);
  prev_ = {};
  repeats_ = {};
}

bool SlipControl::set_mu(double mu) noexcept {
  if (!ctrl_.set_mu(mu)) return false;
  for (auto& o : obs_) {
    o.set_mu(mu);
    o.reset();
  }
  return true;
}

}  // namespace lugrip
