// Grasp plant, distributed contact: the implicit object step on two PatchContact pads.
#include "lugrip/grasp_plant.hpp"

#include <algorithm>
#include <cmath>

namespace lugrip {

namespace {
bool finite(double x) { return std::isfinite(x); }
}  // namespace

namespace {
// Rigid motion of a point p of the object over h under the constant twist (V at the pad centre,
// omega): p' = R(h omega) p + h (S V + C z x V), S = sin(d)/d, C = (1 - cos d)/d, d = h omega
// (exact; the exponential map of the twist).
inline void twist_map(double& px, double& py, double Vx, double Vy, double omega, double h) noexcept {
  const double d = h * omega;
  const double cd = std::cos(d), sd = std::sin(d);
  double S, C;
  if (std::fabs(d) < 1e-4) {
    S = 1.0 - d * d / 6.0;
    C = 0.5 * d;
  } else {
    S = sd / d;
    C = (1.0 - cd) / d;
  }
  const double nx = cd * px - sd * py + h * (S * Vx - C * Vy);
  const double ny = sd * px + cd * py + h * (S * Vy + C * Vx);
  px = nx;
  py = ny;
}
}  // namespace

// One implicit step of the 3-DOF object on the two pads (docs/model.md 10.1 (b)).
// State: CoG velocity v and omega (momentum), slip u of the object point that was at the pad
// centre, angle theta; the CoG is at r = u + R(theta) cog. Unknowns q' = (V', omega'), the twist of
// the object relative to the gripper (V' = velocity of the object point at the pad centre, i.e. the
// slip velocity the pads see), with v' = V' + omega' z x r~, r~ the CoG at the end of the step
// predicted with the previous twist. About the pad centre the system is (M_O(r~)/h + D) q' = rhs
// with the rigid-body mass matrix M_O and the SPD damping D of the linearised pads: SPD for any
// state. Momentum is integrated exactly (v' = v + h F / m) and the configuration by the exact
// rigid motion of the twist, so the slip u is exactly what the pads integrated.
void GraspPlant::substep_patch(double h, double t0) noexcept {
  const double t1 = t0 + h;
  const ObjectConfig& o = cfg_.object;
  const double m = o.mass, I = o.inertia, g = cfg_.gravity;
  double gx0, gy0, gvx0, gvy0, gx1, gy1, gvx1, gvy1;
  gripper_at(t0, gx0, gy0, gvx0, gvy0);
  gripper_at(t1, gx1, gy1, gvx1, gvy1);
  const double agx = (gvx1 - gvx0) / h, agy = (gvy1 - gvy0) / h;  // exact velocity increment
  double efx, efy, etau;
  double c0, s0;
  trig(th_, c0, s0);
  disturbance_cs(t1, c0, s0, efx, efy, etau);
  efx += ext_fx_;
  efy += ext_fy_;
  etau += ext_tau_;
  st_.ext_fx = efx;
  st_.ext_fy = efy;
  st_.ext_tau = etau;

  PatchContact::Linear L;
  patch_.prepare(f_act_, Vx_, Vy_, om_, h, L);
  // Both pads (symmetric): twice one pad. Affine in q' = (V', omega'):
  //   F = A_F - B0 V' - omega' z x B1,   tau_O = A_tau - B1 x V' - omega' B2   (about the pad centre)
  const double B0 = 2.0 * L.b0, B1x = 2.0 * L.b1x, B1y = 2.0 * L.b1y, B2 = 2.0 * L.b2;
  const double AFx = 2.0 * L.a_fx, AFy = 2.0 * L.a_fy, AT = 2.0 * L.a_tau;

  double nVx, nVy, nom;
  bool free_motion = true;
  if (supported_) {
    // At rest in the world: V' = -v_gripper, omega' = 0. Lift off when the contacts pull up more
    // than gravity and the disturbance push down.
    nVx = -gvx1;
    nVy = -gvy1;
    nom = 0.0;
    const double Fy = AFy - B0 * nVy;
    if (Fy - m * g + efy > 0.0) {
      supported_ = false;
    } else {
      free_motion = false;
    }
  }
  if (free_motion) {
    double qx = rx_, qy = ry_;  // r~
    twist_map(qx, qy, Vx_, Vy_, om_, h);
    // force:  a V' + b omega' = p,   p = m v/h + A_F + m (g - a_g) + F_ext
    // moment about the pad centre: b.V' + c omega' = s
    const double a = m / h + B0;
    const double b1 = -m / h * qy - B1y, b2 = m / h * qx + B1x;
    const double c = (I + m * (qx * qx + qy * qy)) / h + B2;
    const double lx = m * vx_ / h - m * agx + efx, ly = m * vy_ / h - m * (g + agy) + efy;
    const double p1 = lx + AFx, p2 = ly + AFy;
    const double s3 = I * om_ / h + AT + etau + (qx * ly - qy * lx);
    const double S = c - (b1 * b1 + b2 * b2) / a;  // > 0 (SPD)
    nom = (s3 - (b1 * p1 + b2 * p2) / a) / S;
    nVx = (p1 - b1 * nom) / a;
    nVy = (p2 - b2 * nom) / a;
    if (!(finite(nom) && finite(nVx) && finite(nVy))) {  // only on overflow of absurd inputs
      nom = 0.0;
      nVx = -gvx1;
      nVy = -gvy1;
    }
    vx_ = nVx - nom * qy;
    vy_ = nVy + nom * qx;
  } else {
    vx_ = nVx;
    vy_ = nVy;
  }
  patch_.finish(nVx, nVy, nom, pad_);
  Vx_ = nVx;
  Vy_ = nVy;
  om_ = nom;
  twist_map(ux_, uy_, nVx, nVy, nom, h);
  th_ += h * nom;
  double cth, sth;
  trig(th_, cth, sth);
  rx_ = ux_ + cth * o.cog_x - sth * o.cog_y;
  ry_ = uy_ + sth * o.cog_x + cth * o.cog_y;
  // Landing on the support (inelastic).
  if (cfg_.support && !supported_ && gy1 + ry_ < support_y_ && gvy1 + vy_ < 0.0) {
    supported_ = true;
    uy_ += support_y_ - (gy1 + ry_);
    ry_ = support_y_ - gy1;
    vx_ = Vx_ = -gvx1;
    vy_ = Vy_ = -gvy1;
    om_ = 0.0;
  }
}

}  // namespace lugrip
