// lugrip — the normalized limit surface of a soft circular contact (paper eqs. 3-6, Fig. 3).
#pragma once

#include <vector>

namespace lugrip {

//! Smallest supported pressure exponent. Below it the pressure is a sharp central peak
//! (xi -> 0) that the fixed-size tables cannot resolve to 1e-6.
inline constexpr double kMinPressureExponent = 0.5;

//! The value of ContactParams::k that selects the elliptic limit surface instead of a pressure
//! law: (f~_t)^2 + (tau~)^2 = 1 in the normalized plane (f_t/(mu f_n), tau/tau_max), the shape
//! of a point contact on an elliptic friction cone (MuJoCo condim 4). No pressure of the family
//! below produces it. Its curves have the closed form f~ = u/sqrt(1+u^2), tau~ = 1/sqrt(1+u^2),
//! u = |c~|/xi (the maximum-dissipation point for the CoR at c~); docs/model.md section 3.5.
inline constexpr double kEllipticLimitSurface = 0.0;

//! Torsional shape factor of the elliptic limit surface, a convention (the ellipse fixes only
//! the product xi rho): the paper's pad value xi(4), so that tau_max = mu xi rho f_n keeps its
//! meaning and rho = delta f_n^gamma stays the contact radius of a pad whose torsional capacity
//! was set from the paper's k = 4.
inline constexpr double kEllipseShapeFactor = 0.6354098135954843;

//! Torsional shape factor xi(k) = (3/4) Gamma(3/k)^2 / (Gamma(2/k) Gamma(4/k)), so that
//! tau_max = mu xi rho f_n. xi(2) = 3 pi/16, xi(4) = 0.6354098, xi(inf) = 2/3.
//! k must be > 0 (std::numeric_limits<double>::infinity() for a uniform pressure), or
//! kEllipticLimitSurface (returns kEllipseShapeFactor).
double shape_factor(double k);

//! Magnitudes of the normalized LS at a = |c~| and their derivatives d/da.
struct LsPoint {
  double F = 0.0;   //!< |f~*_tLS(a)|, increases 0 -> 1
  double T = 1.0;   //!< tau~*_LS(a), decreases 1 -> 0
  double dF = 0.0;  //!< dF/da >= 0
  double dT = 0.0;  //!< dT/da <= 0 (equals -(a/xi) dF/da: maximum dissipation)
};

//! The normalized limit-surface curves f~*_tLS(c~) and tau~*_LS(c~) for a pressure
//! p(r) = p0 (1 - (r/rho)^k)^(1/k) on the contact disc (docs/model.md section 3).
//!
//! Construction integrates the curves with Gauss-Jacobi / Gauss-Legendre quadrature of the
//! 1-D reduction (CoR-centred chords) on two tables, a in [0, 1] and u = 1/a in [0, 1], values
//! and exact derivatives at every node; evaluation is cubic Hermite interpolation: constant
//! time, no allocation, C1 everywhere, exact at c~ = 0 and c~ -> inf. Absolute error <= 1e-6
//! (tests against an independent quadrature for k = 1.5, 2, 3, 4, 6, 8, inf; about 1e-7 or
//! better). For k not an even integer the chords are split at the point nearest the disc
//! centre, where the pressure has a |r|^k cusp.
//!
//! Sign convention (docs/model.md 3.2): f~* is odd with the sign opposite to c~, tau~* is even
//! and positive.
class LimitSurface {
 public:
  //! k: pressure exponent, >= kMinPressureExponent (0.5), may be +infinity; or
  //! kEllipticLimitSurface (0) for the ellipse, evaluated in closed form (no tables). Throws
  //! std::invalid_argument otherwise.
  explicit LimitSurface(double k = 4.0, int intervals = 0);

  double k() const noexcept { return k_; }
  bool elliptic() const noexcept { return elliptic_; }
  double xi() const noexcept { return xi_; }

  //! Magnitudes and derivatives at a = |c~| (a < 0 is treated as |a|; NaN gives NaN).
  LsPoint eval(double a) const noexcept;
  double F(double a) const noexcept { return eval(a).F; }
  double T(double a) const noexcept { return eval(a).T; }
  //! Normalized torque capacity about the CoR, G(a) = xi T(a) + a F(a); g = mu f_n rho G.
  double G(double a) const noexcept;

  //! Signed curves of the paper: f~*_tLS(c~) = -sign(c~) F(|c~|), tau~*_LS(c~) = T(|c~|).
  double ft_star(double c_tilde) const noexcept;
  double tau_star(double c_tilde) const noexcept;
  double dft_star(double c_tilde) const noexcept;   //!< d f~*/d c~ (even, <= 0)
  double dtau_star(double c_tilde) const noexcept;  //!< d tau~*/d c~ (odd)

  //! sigma_LS(a) = F(a)^(gamma+1) / T(a), the map inverted by the CoR estimator (eq. 13).
  double sigma_ls(double a, double gamma) const noexcept;

  //! Asymptotic constants: F ~ s a (a -> 0); F ~ 1 - A_f/a^2, T ~ A_tau/a (a -> inf).
  double small_slope() const noexcept { return s_k_; }
  double tail_force() const noexcept { return a_f_; }
  double tail_torque() const noexcept { return a_tau_; }

  //! Direct (slow) quadrature at one point, bypassing the tables; for tests (the closed form
  //! for the ellipse).
  LsPoint integrate(double a) const;

  int intervals() const noexcept { return n_; }

 private:
  double k_, xi_, p_k_, m_k_, s_k_, a_f_, a_tau_;
  int n_;
  bool elliptic_ = false;  // k == kEllipticLimitSurface: closed-form ellipse
  std::vector<double> gj_x_, gj_w_;  // Gauss-Jacobi (alpha = beta = 1/k) on [-1, 1]
  std::vector<double> half_x_, half_w_;  // half-chord rule: y = s^2 and weights (alpha = 1/k)
  bool split_chords_ = false;  // k not an even integer: |r|^k has a cusp at the disc centre
  std::vector<double> gl_x_, gl_w_;  // Gauss-Legendre on [-1, 1] (outer integral)
  std::vector<double> near_x_, near_w_;  // finer outer rule for nodes near the rim
  std::vector<double> inner_;  // (n+1) x 4: F, h dF/da, T, h dT/da at a = i/n (h = 1/n)
  std::vector<double> outer_;  // (n+1) x 4: F, h dF/du, T, h dT/du at u = 1/a = i/n

  LsPoint quad(double a, const std::vector<double>& ox, const std::vector<double>& ow) const;
};

}  // namespace lugrip
