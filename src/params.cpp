#include "lugrip/params.hpp"

#include <cmath>
#include <stdexcept>

#include "lugrip/limit_surface.hpp"
#include "lugrip/status.hpp"

#include "format.hpp"

namespace lugrip {

namespace {
// Shortest decimal that reads back as the same double (0.4, not 0.40000000000000002).
std::string fmt(double v) { return detail::format_number(v); }
}  // namespace

bool validate(const ContactParams& p, std::string* message) {
  std::string msg;
  auto bad = [&](const char* name, double v, const char* rule) {
    msg += std::string(name) + " = " + fmt(v) + ": " + rule + "\n";
  };
  if (!(std::isfinite(p.mu) && p.mu > 0.0 && p.mu <= 10.0)) bad("mu", p.mu, "must be finite, > 0 and <= 10");
  if (!(std::isfinite(p.beta_a) && p.beta_a >= 0.0)) bad("beta_a", p.beta_a, "must be finite and >= 0 [N s/m^3]");
  // >= 1e-12 keeps the bristle state g/sigma0 finite for every g a sensor range allows (1e17 N m)
  if (!(std::isfinite(p.sigma0) && p.sigma0 >= 1e-12)) bad("sigma0", p.sigma0, "must be finite and >= 1e-12 [N m/rad]");
  if (!(std::isfinite(p.sigma_z) && p.sigma_z >= 0.0)) bad("sigma_z", p.sigma_z, "must be finite and >= 0 [N m s/rad]");
  if (!(std::isfinite(p.delta) && p.delta > 0.0 && p.delta < 1.0)) bad("delta", p.delta, "must be finite, > 0 and < 1 [m/N^gamma]");
  if (!(p.gamma > 0.0 && p.gamma < 1.0 / 3.0)) bad("gamma", p.gamma, "must satisfy 0 < gamma < 1/3");
  if (!(p.k >= kMinPressureExponent || p.k == kEllipticLimitSurface))
    bad("k", p.k, "must be >= 0.5 (inf for uniform pressure) or 0 (elliptic limit surface)");
  if (!(std::isfinite(p.c_max) && p.c_max > 0.0 && p.c_max <= 1.0e3)) bad("c_max", p.c_max, "must be finite, > 0 and <= 1000");
  if (!(std::isfinite(p.static_ratio) && p.static_ratio >= kMinFrictionRatio && p.static_ratio <= kMaxFrictionRatio))
    bad("static_ratio", p.static_ratio, "must be finite, >= 0.5 and <= 3 (mu_s / mu)");
  if (!(std::isfinite(p.kinetic_ratio) && p.kinetic_ratio >= kMinFrictionRatio && p.kinetic_ratio <= kMaxFrictionRatio))
    bad("kinetic_ratio", p.kinetic_ratio, "must be finite, >= 0.5 and <= 3 (mu_k / mu)");
  else if (!(p.static_ratio >= p.kinetic_ratio))
    bad("static_ratio", p.static_ratio, "must be >= kinetic_ratio (static friction is not below kinetic)");
  if (message) *message = msg;
  return msg.empty();
}

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

std::string to_string(const ContactParams& p) {
  return "ContactParams(mu=" + fmt(p.mu) + ", beta_a=" + fmt(p.beta_a) + ", sigma0=" + fmt(p.sigma0) +
         ", sigma_z=" + fmt(p.sigma_z) + ", delta=" + fmt(p.delta) + ", gamma=" + fmt(p.gamma) +
         ", k=" + (std::isinf(p.k) ? std::string("float('inf')") : fmt(p.k)) + ", c_max=" + fmt(p.c_max) +
         ", static_ratio=" + fmt(p.static_ratio) + ", kinetic_ratio=" + fmt(p.kinetic_ratio) + ")";
}

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
