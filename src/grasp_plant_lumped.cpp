// Grasp plant, lumped contact: the slider of eqs. 1-2 about the CoR of the quasi-static load.
#include "lugrip/grasp_plant.hpp"

#include <algorithm>
#include <cmath>

#include "lugrip/slider_model.hpp"

namespace lugrip {

// One step of the lumped slider (eqs. 1-2) about the CoR of the current quasi-static load.
void GraspPlant::substep_lumped(double h, double t0) noexcept {
  const double t1 = t0 + h;
  const ObjectConfig& o = cfg_.object;
  const double m = o.mass, g = cfg_.gravity;
  double gx0, gy0, gvx0, gvy0, gx1, gy1, gvx1, gvy1;
  gripper_at(t0, gx0, gy0, gvx0, gvy0);
  gripper_at(t1, gx1, gy1, gvx1, gvy1);
  const double agx = (gvx1 - gvx0) / h, agy = (gvy1 - gvy0) / h;
  // No translation: the object point at the grasp point stays there, r = R(theta) cog.
  double c, s;
  trig(th_, c, s);
  double efx, efy, etau;
  disturbance_cs(t1, c, s, efx, efy, etau);
  efx += ext_fx_;
  efy += ext_fy_;
  etau += ext_tau_;
  st_.ext_fx = efx;
  st_.ext_fy = efy;
  st_.ext_tau = etau;

  const double rx = c * o.cog_x - s * o.cog_y, ry = s * o.cog_x + c * o.cog_y;
  const double I_O = o.inertia + m * (rx * rx + ry * ry);
  // Load on the object other than friction (gravity, gripper acceleration, pushes).
  const double Lx = -m * agx + efx, Ly = -m * (g + agy) + efy;
  const double tauL = etau + rx * Ly - ry * Lx;  // about the grasp point

  if (supported_) {
    const bool lifting = gvy1 > 0.0 || gy1 > support_y_ - ry;
    if (!lifting) {
      om_ = 0.0;
      lumped_z_ = 0.0;
      pad_ = PadWrench();
      Vx_ = -gvx1;
      Vy_ = -gvy1;
      rx_ = rx;
      ry_ = ry;
      vx_ = -gvx1;
      vy_ = -gvy1;
      return;
    }
    supported_ = false;
  }

  // Per finger: friction force balances half the load (no translation); its torque is the state.
  const double Ffx = -0.5 * Lx, Ffy = -0.5 * Ly;
  const double f_t = std::sqrt(Ffx * Ffx + Ffy * Ffy);
  const double f_n = f_act_;
  double tau_o;  // friction torque on the object about the grasp point, per finger
  double c_cor = 0.0;
  if (f_n > 1e-9) {
    // CoR of the quasi-static friction wrench (f_t, -tau_L/2) in the slider frame (y along f_t).
    CorOutput& co = cor_out_;
    const Status cs = cor_.step(CorInput{f_n, f_t, -0.5 * tauL}, co);
    const double ct = co.c_tilde;
    // A fresh estimate carries rho, sigma_1 and g at this f_n and c~, computed by the same
    // expressions as ContactModel::rho / sigma_1 / g (bit-identical); a held one (f_n below the
    // estimator's contact threshold) does not.
    const bool fresh = cs == Status::Ok || cs == Status::Saturated || cs == Status::Degenerate;
    if (fresh) {
      rho_fn_ = f_n;
      rho_ = co.rho;
      rho_ok_ = true;
    }
    const double rho = rho_at(f_n);
    c_cor = ct * rho;
    RotorCoefficients rc;
    rc.sigma0 = cfg_.contact.sigma0;
    rc.sigma_z = cfg_.contact.sigma_z;
    rc.sigma_1 = fresh ? co.sigma_1 : model_.sigma_1(f_n, ct);
    rc.g = std::max(fresh ? co.g : model_.g(f_n, ct), 1e-12);
    rc.gain = 2.0 / I_O;
    rc.drive = 0.5 * tauL + c_cor * f_t;
    double z = lumped_z_, w = om_;
    rotor_advance(z, w, h, rc, Integrator::Implicit, 1, 1, nullptr, nullptr);
    lumped_z_ = z;
    om_ = w;
    const double zdot = lugre_zdot(z, w, rc.sigma0, rc.g);
    const double y = rc.sigma0 * z + rc.sigma_z * zdot + rc.sigma_1 * w;  // about the CoR
    tau_o = -y + c_cor * f_t;
  } else {  // no contact: free rotation about the grasp point
    lumped_z_ = 0.0;
    om_ += h * tauL / I_O;
    tau_o = 0.0;
  }
  lumped_c_ = c_cor;
  th_ += h * om_;
  // Implied velocity of the object point at the pad centre for a rotation about the CoR:
  // V = omega z x (0 - p_C), p_C = c x_hat, x_hat = y_hat x z (y_hat along the friction force).
  double yhx = 0.0, yhy = 0.0;
  if (f_t > 0.0) {
    yhx = Ffx / f_t;
    yhy = Ffy / f_t;
  }
  // x_hat = (yhy, -yhx); z x p_C = c (yhx, yhy)  ->  V = -omega c y_hat
  Vx_ = -om_ * c_cor * yhx;
  Vy_ = -om_ * c_cor * yhy;
  lumped_slip_ += h * std::fabs(om_ * c_cor);
  double c1, s1;
  trig(th_, c1, s1);
  rx_ = c1 * o.cog_x - s1 * o.cog_y;
  ry_ = s1 * o.cog_x + c1 * o.cog_y;
  vx_ = -om_ * ry_;  // CoG velocity relative to the gripper (rotation about the grasp point)
  vy_ = om_ * rx_;
  if (f_n > 1e-9) {
    pad_.fx = Ffx;
    pad_.fy = Ffy;
    pad_.tau = tau_o;
  } else {
    pad_ = PadWrench();
  }
}

// Wrench object -> fingertip i in its sensor frame: (f_n, f_x, f_y, tau).

}  // namespace lugrip
