// lugrip — offline identification (paper eqs. 32-33, docs/model.md 8): cost and exact gradient of the
// observer's velocity error over many sliding maneuvers.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "lugrip/observer.hpp"
#include "lugrip/params.hpp"

namespace lugrip {

//! Index of an identified parameter in gradients and matrices (the order of ContactParams).
enum class IdParam : int { Mu = 0, BetaA = 1, Sigma0 = 2, SigmaZ = 3, Delta = 4, Gamma = 5 };
//! Number of identified parameters: mu, beta_a, sigma0, sigma_z, delta, gamma.
constexpr int kIdParams = 6;

//! Loss applied to each velocity residual r = omega_hat - omega.
enum class IdLoss : int {
  Squared = 0,  //!< r^2 (eq. 32)
  //! r^2 for |r| <= s, 2 s |r| - s^2 beyond (s = huber_scale): outliers pull linearly.
  Huber = 1,
};

//! Settings of the identification cost (defaults in one place).
//!
//! Units, ranges and meanings: the field table, lugrip/settings_fields.hpp.
struct IdentificationSettings {
  ObserverSettings observer;
  IdLoss loss = IdLoss::Squared;
  double huber_scale = 0.05;
  int threads = 0;
  double sensitivity_limit = 100.0;
};

//! Checks every field (and the nested observer settings); one line per bad field in *message.
bool validate(const IdentificationSettings& s, std::string* message);
//! "IdentificationSettings(observer=ObserverSettings(...), ...)" at full precision.
std::string to_string(const IdentificationSettings& s);

//! Samples of many independent segments (maneuvers, or the gap-free stretches of a maneuver),
//! concatenated. The observer restarts at every segment start and is never integrated across
//! two segments.
//!
//! Per sample: f_n [N], f_t [N] (in-plane magnitude), tau [N m] (the sensor's wrench, docs/model.md
//! 7.2), dt [s] since the previous sample (0: the nominal observer dt; ignored at a segment
//! start), omega the ground-truth slip velocity [rad/s] (NaN: unknown, not scored) and weight
//! (>= 0, finite; 0: not scored). segment_start holds the first sample of each segment followed
//! by the total sample count: 0 = s_0 < s_1 < ... < s_m = n.
struct IdentificationData {
  std::vector<double> f_n, f_t, tau, dt, omega, weight;
  std::vector<int64_t> segment_start;
};

//! Checks sizes, segment boundaries, finite dt and weights; one line per problem in *message.
bool validate(const IdentificationData& d, std::string* message);

//! Sums of one segment at one parameter point (scored samples only).
struct SegmentSums {
  double sse = 0.0;        //!< sum of r^2 (unweighted) [rad^2/s^2]
  double loss = 0.0;       //!< sum of weight * loss(r)
  double weight = 0.0;     //!< sum of weights
  int64_t count = 0;       //!< scored samples
  std::array<double, kIdParams> gradient{};  //!< sum of weight * dloss/dP (natural units)
};

//! Result of one evaluation. Derivatives are with respect to the natural parameters
//! (mu, beta_a [N s/m^3], sigma0 [N m/rad], sigma_z [N m s/rad], delta [m/N^gamma], gamma).
struct IdentificationEval {
  double cost = 0.0;         //!< sum(w loss(r)) / sum(w) over scored samples (eq. 32 for Squared, w = 1)
  double weight_sum = 0.0;   //!< sum(w)
  int64_t scored = 0;        //!< samples with a valid observer output, finite omega and w > 0
  std::array<double, kIdParams> gradient{};  //!< d cost / dP
  //! Gauss-Newton matrix 2 sum(w v J J^T) / sum(w), row-major 6x6, J = d omega_hat / dP, v the
  //! IRLS weight of the loss (1 for Squared, min(1, s/|r|) for Huber).
  std::array<double, kIdParams * kIdParams> gauss_newton{};
  std::vector<SegmentSums> segments;  //!< per segment, in data order
  //! Largest difference between the online Observer's state and the tangent replica's value part
  //! (omega in rad/s, z relative to its bound g/sigma0): ~1e-15 when the gradient is the exact
  //! derivative of the online discretisation; larger means the replica is out of date.
  double replica_error = 0.0;
  int64_t reinitialized = 0;  //!< samples with status Reinitialized (segment starts, divergence guard, gaps)
  int64_t diverged = 0;       //!< samples where the observer's divergence guard fired
  //! Samples where the chattering guard restarted the sensitivities (settings.sensitivity_limit):
  //! there the observer's discrete map is locally chaotic and the gradient is truncated, not exact.
  int64_t truncated = 0;
};

//! The identification cost of docs/model.md 8.1 over a fixed data set:
//!
//!   C(P) = sum_n w_n loss(omega_hat_n(P) - omega_n) / sum_n w_n,
//!
//! with omega_hat from the online Observer (same CoR estimate, filters, gain rule, integrator and
//! substeps; one Observer per worker thread, reset at every segment start). The gradient is exact:
//! forward sensitivities of the discretised observer (dual numbers through the integrator step,
//! implicit-function derivatives of the CoR root finding), propagated along the Observer's own
//! trajectory. Where that map is locally chaotic (the observer chatters as omega_hat crosses zero
//! with a very large gain, e.g. l = B/sigma_1 ~ 1e5 with Table 2 viscous friction), pathwise
//! derivatives grow without bound; a guard then restarts them (IdentificationEval::truncated).
//! Segments are distributed over threads; sums are formed per segment and added in
//! data order, so the result does not depend on the thread count.
//!
//! Not real-time code: evaluate() allocates and starts threads.
class IdentificationProblem {
 public:
  //! Validates data and settings (std::invalid_argument, one line per problem); takes the data.
  IdentificationProblem(IdentificationData data, const IdentificationSettings& settings);

  //! Cost at `params` (validated; std::invalid_argument otherwise). With `derivatives` also the
  //! gradient and the Gauss-Newton matrix. `omega_hat` (null or n entries) receives the observer
  //! output of every sample.
  IdentificationEval evaluate(const ContactParams& params, bool derivatives, double* omega_hat = nullptr) const;

  std::size_t samples() const noexcept { return d_.f_n.size(); }
  std::size_t segments() const noexcept { return d_.segment_start.empty() ? 0 : d_.segment_start.size() - 1; }
  const IdentificationData& data() const noexcept { return d_; }
  const IdentificationSettings& settings() const noexcept { return s_; }

 private:
  IdentificationData d_;
  IdentificationSettings s_;
};

}  // namespace lugrip
