#include "lugrip/params.hpp"

#include <cmath>
#include <stdexcept>

#include "lugrip/limit_surface.hpp"
#include "lugrip/status.hpp"

#include "field_checks.hpp"
#include "format.hpp"

namespace lugrip {

bool validate(const ContactParams& p, std::string* message) { return detail::validate_fields(p, message); }

void validate_or_throw(const ContactParams& p) {
  std::string msg;
  if (!validate(p, &msg)) throw std::invalid_argument("invalid ContactParams:\n" + msg);
}

ContactParams table1_params() noexcept {
  ContactParams p;
  p.mu = 0.47;
  p.beta_a = 4.9e9;
  p.sigma0 = 16.66;
  p.sigma_z = 2.0;
  p.delta = 0.0018;
  p.gamma = 0.254;
  p.k = 4.0;
  p.c_max = 1.5;
  return p;
}

ContactParams object_params(const std::string& name) {
  ContactParams p = table1_params();
  if (name == "big_resin_block") { p.mu = 0.85; p.beta_a = 1.24e7; }
  else if (name == "small_resin_block") { p.mu = 0.70; p.beta_a = 1.825e7; }
  else if (name == "plastic_bottle") { p.mu = 0.85; p.beta_a = 1.963e7; }
  else if (name == "aluminium_can") { p.mu = 0.75; p.beta_a = 2.121e7; }
  else
    throw std::invalid_argument("unknown object '" + name +
                                "' (known: big_resin_block, small_resin_block, plastic_bottle, aluminium_can)");
  return p;
}

std::string to_string(const ContactParams& p) { return detail::print_fields(p); }

const char* to_string(Status s) noexcept {
  switch (s) {
    case Status::Ok: return "ok";
    case Status::Saturated: return "saturated: |c~| clipped at c_max";
    case Status::Degenerate: return "degenerate: zero wrench, previous CoR held";
    case Status::NoContact: return "no contact: normal force below threshold";
    case Status::InvalidSample: return "invalid sample: NaN, Inf or out of range";
    case Status::SensorFault: return "sensor fault: too many invalid samples in a row";
    case Status::Reinitialized: return "reinitialized: first valid sample after a reset";
  }
  return "unknown status";
}

}  // namespace lugrip
