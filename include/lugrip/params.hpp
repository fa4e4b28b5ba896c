// lugrip — physical contact parameters (paper Table 1/2) and their validation.
#pragma once

#include <string>

namespace lugrip {

//! Range of ContactParams::static_ratio and kinetic_ratio [-].
constexpr double kMinFrictionRatio = 0.5;
constexpr double kMaxFrictionRatio = 3.0;
//! Upper bound of ContactParams::stribeck_speed [m/s].
constexpr double kMaxStribeckSpeed = 1.0;

//! Physical parameters of one fingertip/object contact (SI units). Units, valid ranges and
//! meanings: the field table, lugrip/settings_fields.hpp (docs/conventions.md prints it).
//! No silent defaults for the physical fields: a default-constructed struct fails validation.
struct ContactParams {
  double mu = 0.0;       //!< friction coefficient of the limit surface [-] (fitted to gross sliding)
  double beta_a = -1.0;  //!< viscous friction per unit area and speed [N s/m^3] (paper prints "Ns/m")
  double sigma0 = 0.0;   //!< micro-asperity (bristle) stiffness [N m/rad]
  double sigma_z = -1.0; //!< micro-asperity damping [N m s/rad]
  double delta = 0.0;    //!< contact-radius law rho = delta f_n^gamma [m/N^gamma]
  double gamma = 0.0;    //!< contact-radius exponent [-]
  double k = 4.0;        //!< pressure exponent p ~ (1-(r/rho)^k)^(1/k) [-]; 4 gives xi = 0.6354;
                         //!< 0 (kEllipticLimitSurface) selects the elliptic limit surface
  double c_max = 1.5;    //!< saturation of the normalized CoR |c~| [-] (paper: 1.5)
  //! Break-away (static) friction over mu, mu_s / mu [-]: the capacity S is judged against in
  //! stick (Stribeck term when > kinetic_ratio). 1 (default, the paper's model) = mu.
  double static_ratio = 1.0;
  //! Sliding (kinetic) friction level over mu, mu_k / mu [-]: the capacity S is judged against
  //! once sliding has started (the lower envelope of the sliding loads in identification).
  //! 1 (default) = mu. With both ratios 1 the observer is the paper's (docs/model.md 7.5).
  double kinetic_ratio = 1.0;
  //! Stribeck speed v_s [m/s]: when > 0, once sliding, the observer's update uses the capacity
  //! g (1 + (static_ratio - 1) exp(-(v / v_s)^2)), v the RMS sliding speed over the patch from
  //! its speed state, so that mu is the sliding friction at speed and a slow slide's higher
  //! friction is not read as speed. 0 (default): the update uses g once sliding (docs/model.md 7.5).
  double stribeck_speed = 0.0;
};

//! Checks every field against its range in the field table. Returns true when valid; otherwise
//! writes one line per bad field ("mu = -1: must be finite, > 0 and <= 10 [-]") into *message
//! (if not null) and returns false.
bool validate(const ContactParams& p, std::string* message);

//! Throws std::invalid_argument with the message of validate() when invalid.
void validate_or_throw(const ContactParams& p);

//! Paper Table 1 (cardboard slider): mu 0.47, beta_A 4.9e9, sigma0 16.66, sigma_z 2,
//! delta 0.0018, gamma 0.254, k = 4.
ContactParams table1_params() noexcept;

//! Table 1 with the object's mu and beta_A from paper Table 2.
//! name: "big_resin_block", "small_resin_block", "plastic_bottle", "aluminium_can".
//! Throws std::invalid_argument for an unknown name.
ContactParams object_params(const std::string& name);

//! Python-assignment style dump at full precision (for bug reports).
std::string to_string(const ContactParams& p);

}  // namespace lugrip
