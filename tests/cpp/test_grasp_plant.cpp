// Grasp simulator: distributed contact vs the limit surface (docs/model.md 3, 5.1), object dynamics
// (hold, slip, fall, pendulum), actuator ZOH/lag, sensor noise, determinism, robustness.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "lugrip/grasp_plant.hpp"
#include "lugrip/limit_surface.hpp"

using namespace lugrip;

namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr double kG = 9.81;

ContactParams resin() { return object_params("big_resin_block"); }

// Steady rotation about the CoR at c~ rho along the direction `dir` (angle in the pad plane) with
// rate omega; returns the normalised wrench of the pad on the object in the frame whose y axis is
// the friction force: (f_t / (mu f_n), tau / tau_max) and the signed c~ in that frame.
struct Normalised {
  double ft, tau, c_tilde;
};
Normalised steady_rotation(PatchContact& pc, const ContactParams& p, double f_n, double c_tilde,
                           double omega, double dir, double duration = 0.3, double h = 0.01) {
  // The exponential bristle update is exact for a constant velocity, so a coarse step is exact.
  const double rho = p.delta * std::pow(f_n, p.gamma);
  const double cx = c_tilde * rho * std::cos(dir), cy = c_tilde * rho * std::sin(dir);
  // velocity of the object point at the pad centre: omega z x (0 - C)
  const double vx = omega * cy, vy = -omega * cx;
  PadWrench w;
  const int n = static_cast<int>(duration / h);
  for (int i = 0; i < n; ++i) pc.advance(f_n, vx, vy, omega, h, w);
  const double ft = std::hypot(w.fx, w.fy);
  // model frame: y along the friction force, x = y x z; CoR coordinate along x
  double c_signed = 0.0;
  if (ft > 0.0) {
    const double yx = w.fx / ft, yy = w.fy / ft;
    const double xx = yy, xy = -yx;
    c_signed = (cx * xx + cy * xy) / rho;
  }
  const double xi = shape_factor(p.k);
  return {ft / (p.mu * f_n), w.tau / (p.mu * xi * rho * f_n), c_signed};
}

PlantConfig base_config(double mass = 0.1, double f_n = 5.0) {
  PlantConfig c;
  c.contact = resin();
  c.object.mass = mass;
  c.object.inertia = mass * 1e-3;  // radius of gyration ~3 cm
  c.actuator.f_init = f_n;
  c.sensor.force_noise = 0.0;
  c.sensor.torque_noise = 0.0;
  return c;
}

double tau_max(const ContactParams& p, double f_n) {
  return p.mu * shape_factor(p.k) * p.delta * std::pow(f_n, p.gamma + 1.0);
}
}  // namespace

// ---------------------------------------------------------------------------------------------
// PatchContact

TEST(PatchContact, GridLoadSharesAndTorsionalMoment) {
  PatchContact pc(resin(), PatchSettings());
  EXPECT_EQ(pc.cells(), 314);  // 10 rings of ~square cells
  // Independent midpoint quadrature of int p r^3 dr / int p r dr for k = 4 (rim error ~ N^-1.25).
  const int n = 2000000;
  double num = 0.0, den = 0.0;
  for (int i = 0; i < n; ++i) {
    const double r = (i + 0.5) / n;
    const double p = std::pow(1.0 - std::pow(r, 4.0), 0.25);
    num += p * r * r * r;
    den += p * r;
  }
  // moment2 uses the pressure-centroid radius of each ring, so it is slightly below the exact
  // second moment (by the in-ring variance of r): within 0.5 %.
  EXPECT_NEAR(pc.moment2(), num / den, 0.005 * num / den);
  EXPECT_LT(pc.moment2(), num / den);
}

TEST(PatchContact, PureRotationGivesTauMaxExactly) {
  // Ring radii are the pressure centroids, so pure rotation gives tau_max = mu xi rho f_n to
  // quadrature accuracy, for any ring count and for k = 2, 4, inf.
  for (double k : {2.0, 4.0, std::numeric_limits<double>::infinity()}) {
    for (int rings : {3, 10}) {
      ContactParams p = resin();
      p.beta_a = 0.0;
      p.k = k;
      PatchSettings s;
      s.rings = rings;
      PatchContact pc(p, s);
      const Normalised r = steady_rotation(pc, p, 5.0, 0.0, 1.0, 0.0);
      EXPECT_NEAR(r.tau, -1.0, 1e-9) << "k " << k << " rings " << rings;
      EXPECT_NEAR(r.ft, 0.0, 1e-9);
    }
  }
}

TEST(PatchContact, ReproducesTheLimitSurfaceWithinOnePercent) {
  // Steady sliding about c~: the cell sum of saturated bristles is a quadrature of the LS
  // integrals (docs/model.md 3.1). Compared with LimitSurface(k = 4) for CoRs along several directions
  // of the pad (the grid is not rotation invariant) and both signs of omega.
  ContactParams p = resin();
  p.beta_a = 0.0;
  const LimitSurface ls(4.0);
  const double f_n = 5.0;
  double worst = 0.0;
  for (double ct : {0.0, 0.1, 0.25, 0.5, 0.75, 1.0, 1.5, 2.0, 5.0}) {
    for (double dir : {0.0, 0.3, 1.1, 2.0}) {
      for (double omega : {2.0, -2.0}) {
        PatchContact pc(p, PatchSettings());
        const Normalised r = steady_rotation(pc, p, f_n, ct, omega, dir);
        // docs/model.md 3.1 / eqs. 5-6: f_t = -sign(omega) f~*(c~) f_tmax, tau = -sign(omega) tau~* tau_max
        const double sgn = omega > 0 ? 1.0 : -1.0;
        const double c_signed = r.c_tilde >= 0.0 ? ct : -ct;
        const double ft_ls = -sgn * ls.ft_star(c_signed);
        const double tau_ls = -sgn * ls.tau_star(c_signed);
        EXPECT_NEAR(std::fabs(r.c_tilde), ct, 1e-4);  // the force is ~normal to the CoR direction
        if (ct > 0.0) {
          EXPECT_GT(ft_ls, 0.0);  // friction frame: f_t >= 0 (docs/model.md 1.2)
          EXPECT_EQ(r.c_tilde > 0, omega > 0);  // sign(c) = sign(omega) (docs/model.md 1.3)
        }
        const double err = std::hypot(r.ft - ft_ls, r.tau - tau_ls) / std::hypot(ft_ls, tau_ls);
        worst = std::max(worst, err);
        EXPECT_LT(err, 0.01) << "c~ " << ct << " dir " << dir << " omega " << omega;
        EXPECT_NEAR(r.ft, ft_ls, 0.005);
        EXPECT_NEAR(r.tau, tau_ls, 0.005);
      }
    }
  }
  EXPECT_GT(worst, 1e-5);  // a quadrature, not the table itself
}

TEST(PatchContact, MoreCellsReproduceTheLimitSurfaceBetter) {
  ContactParams p = resin();
  p.beta_a = 0.0;
  const LimitSurface ls(4.0);
  auto rms_error = [&](int rings) {
    double s = 0.0;
    int n = 0;
    for (double ct : {0.1, 0.25, 0.5, 0.75, 1.0, 1.25, 1.5, 2.0, 3.0}) {
      for (double dir : {0.0, 0.7, 1.6}) {
        PatchSettings st;
        st.rings = rings;
        PatchContact pc(p, st);
        const Normalised r = steady_rotation(pc, p, 2.0, ct, 1.0, dir);
        s += std::pow(r.ft - (-ls.ft_star(r.c_tilde)), 2) + std::pow(r.tau + ls.tau_star(r.c_tilde), 2);
        n += 2;
      }
    }
    return std::sqrt(s / n);
  };
  const double e6 = rms_error(6), e10 = rms_error(10), e20 = rms_error(20);
  EXPECT_LT(e10, e6);
  EXPECT_LT(e20, 0.5 * e10);
  EXPECT_LT(e20, 1e-3);
}

TEST(PatchContact, ViscousExtensionMatchesEquations7To10) {
  // Table 2 (beta_A = 1.24e7) and Table 1 (4.9e9, viscous-dominated) values.
  const LimitSurface ls(4.0);
  const double xi = ls.xi();
  for (double beta : {1.24e7, 4.9e9}) {
    for (double ct : {0.0, 0.3, 1.0, 2.5}) {
      const double f_n = 5.0, omega = 0.5;
      ContactParams p = resin();
      p.beta_a = beta;
      ContactParams dry = p;
      dry.beta_a = 0.0;
      PatchContact pv(p, PatchSettings()), pd(dry, PatchSettings());
      const double rho = p.delta * std::pow(f_n, p.gamma);
      const Normalised v = steady_rotation(pv, p, f_n, ct, omega, 0.4);
      const Normalised d = steady_rotation(pd, dry, f_n, ct, omega, 0.4);
      // Excess over the dry contact = eqs. 7-8 (normalised): f_tv = pi beta rho^2 omega c,
      // tau_v = -(pi/2) beta rho^4 omega. The dry run has the same kinematics, hence the same
      // bristles; the excess is exact up to rounding.
      const double c = ct * rho;
      const double ftv = kPi * beta * rho * rho * omega * c / (p.mu * f_n);
      const double tauv = -0.5 * kPi * beta * std::pow(rho, 4) * omega / tau_max(p, f_n);
      // both contributions along the same friction frame only when the viscous force is along
      // the dry one, which holds for this kinematics (CoR on the frame's x axis)
      EXPECT_NEAR(v.ft - d.ft, ftv, 1e-9 * (1.0 + std::fabs(ftv)));
      EXPECT_NEAR(v.tau - d.tau, tauv, 1e-9 * (1.0 + std::fabs(tauv)));
      // Total vs eqs. 9-10: f~_t = -sign(w) f~*(c~) + K w c~, tau~ = -sign(w) tau~* - K w/(2 xi)
      const double K = kPi * std::pow(p.delta, 3) * beta * std::pow(f_n, 3 * p.gamma - 1) / p.mu;
      const double ft_pred = -ls.ft_star(ct) + K * omega * ct;
      const double tau_pred = -ls.tau_star(ct) - K * omega / (2.0 * xi);
      EXPECT_LT(std::hypot(v.ft - ft_pred, v.tau - tau_pred) / std::hypot(ft_pred, tau_pred), 0.01)
          << "beta " << beta << " c~ " << ct;
    }
  }
}

TEST(PatchContact, StickStiffnessIsKappaTimesLoad) {
  ContactParams p = resin();
  p.beta_a = 0.0;
  PatchSettings s;
  s.bristle_damping = 0.0;
  const double f_n = 3.0, kappa = s.bristle_stiffness;
  const double rho = p.delta * std::pow(f_n, p.gamma);
  {  // translation by 1 % of the breakaway deflection mu/kappa
    PatchContact pc(p, s);
    PadWrench w;
    const double d = 0.01 * p.mu / kappa, h = 1e-4;
    for (int i = 0; i < 100; ++i) pc.advance(f_n, d / (100 * h), 0.0, 0.0, h, w);
    EXPECT_NEAR(w.fx / (-kappa * f_n * d), 1.0, 0.01);
    EXPECT_NEAR(w.fy, 0.0, 1e-12);
  }
  {  // rotation: torsional stiffness kappa f_n rho^2 moment2
    PatchContact pc(p, s);
    PadWrench w;
    const double a = 0.01 * p.mu / kappa / rho, h = 1e-4;
    for (int i = 0; i < 100; ++i) pc.advance(f_n, 0.0, 0.0, a / (100 * h), h, w);
    EXPECT_NEAR(w.tau / (-kappa * f_n * rho * rho * pc.moment2() * a), 1.0, 0.01);
  }
}

TEST(PatchContact, StribeckGivesStaticAboveCoulomb) {
  ContactParams p = resin();
  p.beta_a = 0.0;
  PatchSettings s;
  s.static_ratio = 1.3;
  s.stribeck_velocity = 1e-3;
  PatchContact pc(p, s);
  const double f_n = 2.0, h = 1e-4;
  double peak = 0.0;
  PadWrench w;
  // slow translation (0.1 mm/s): breakaway near mu_s f_n
  for (int i = 0; i < 2000; ++i) {
    pc.advance(f_n, 1e-4, 0.0, 0.0, h, w);
    peak = std::max(peak, -w.fx);
  }
  EXPECT_NEAR(peak / (p.mu * f_n), 1.3, 0.02);
  // fast sliding (5 cm/s): Coulomb
  for (int i = 0; i < 200; ++i) pc.advance(f_n, 0.05, 0.0, 0.0, h, w);
  EXPECT_NEAR(-w.fx / (p.mu * f_n), 1.0, 1e-6);
}

TEST(PatchContact, NoNormalForceNoFriction) {
  PatchContact pc(resin(), PatchSettings());
  PadWrench w;
  for (int i = 0; i < 100; ++i) pc.advance(5.0, 0.01, 0.0, 0.3, 1e-3, w);
  EXPECT_GT(std::fabs(w.fx), 1.0);
  pc.advance(0.0, 0.01, 0.0, 0.3, 1e-3, w);
  EXPECT_EQ(w.fx, 0.0);
  EXPECT_EQ(w.fy, 0.0);
  EXPECT_EQ(w.tau, 0.0);
  EXPECT_EQ(pc.bristle_energy(), 0.0);
  // re-contact starts from relaxed bristles: the first step's force is far below mu f_n
  pc.advance(5.0, 0.0, 0.0, 0.0, 1e-3, w);
  EXPECT_LT(std::hypot(w.fx, w.fy), 1e-9);
}

// ---------------------------------------------------------------------------------------------
// GraspPlant: validation, frames, dynamics

TEST(GraspPlant, ValidationNamesEveryBadField) {
  PlantConfig c = base_config();
  c.object.mass = -1.0;
  c.rate = 1234.0;  // not a multiple of 500 Hz / 50 Hz
  c.patch.static_ratio = 0.5;
  c.moves.push_back(GripperMove{0.0, 0.0, 0.0, 0.1});
  std::string msg;
  EXPECT_FALSE(validate(c, &msg));
  for (const char* f : {"object.mass", "sensor.rate", "actuator.command_rate", "patch.static_ratio", "moves[0].duration"})
    EXPECT_NE(msg.find(f), std::string::npos) << f << "\n" << msg;
  EXPECT_THROW(GraspPlant{c}, std::invalid_argument);
  PlantConfig empty;  // no physical defaults
  EXPECT_FALSE(validate(empty, nullptr));
  EXPECT_TRUE(validate(base_config(), &msg)) << msg;
}

TEST(GraspPlant, StickHoldsALightObjectAndSensorsReadHalfTheLoad) {
  PlantConfig c = base_config(0.05, 5.0);
  c.object.cog_x = 0.01;  // 10 mm lever: torque m g d
  GraspPlant plant(c);
  for (int i = 0; i < 1000; ++i) plant.step();
  const double th1 = plant.state().theta;
  const double y1 = plant.state().slip_y;
  for (int i = 0; i < 1000; ++i) plant.step();  // 2 s in all
  const PlantState& st = plant.state();
  EXPECT_LT(st.max_slip, 1e-5);  // < 0.01 mm, including the bristle (pre-sliding) deflection
  // elastic pre-sliding rotation only: 2.45 N mm / (kappa f_n rho^2 moment2 = 16.8 N m/rad) per
  // pad plus partial slip of the outer cells, and no creep
  EXPECT_LT(st.max_rotation, 1e-3);
  EXPECT_LT(std::fabs(st.theta - th1), 1e-8);
  EXPECT_LT(std::fabs(st.slip_y - y1), 1e-10);
  EXPECT_FALSE(st.dropped);
  const double W = 0.05 * kG, T = 0.05 * kG * 0.01;
  const FingerSample& s0 = plant.sensor_sample(0);
  const FingerSample& s1 = plant.sensor_sample(1);
  EXPECT_NEAR(s0.true_f_y, -W / 2, 1e-6 * W);  // the object pulls both pads down
  EXPECT_NEAR(s1.true_f_y, -W / 2, 1e-6 * W);
  EXPECT_NEAR(s0.true_f_x, 0.0, 1e-9);
  // gravity turns the object clockwise (-Z); the pads resist with +Z on the object, the object
  // turns pad 0 (z_0 = +Z) by -Z and pad 1 (z_1 = -Z) by -Z = +z_1
  EXPECT_NEAR(s0.true_tau, -T / 2, 1e-6 * T);
  EXPECT_NEAR(s1.true_tau, T / 2, 1e-6 * T);
  EXPECT_EQ(s0.f_n, 5.0);
  EXPECT_NEAR(st.contact_fy, W, 1e-6 * W);
}

TEST(GraspPlant, SlipsAndDropsWellBelowTheStaticForce) {
  PlantConfig c = base_config(0.1, 0.05);  // static requirement m g / (2 mu) = 0.58 N
  GraspPlant plant(c);
  double t_drop = -1.0;
  for (int i = 0; i < 2000; ++i) {
    plant.step();
    if (plant.state().dropped && t_drop < 0) t_drop = plant.state().t;
  }
  const PlantState& st = plant.state();
  EXPECT_TRUE(st.dropped);
  EXPECT_EQ(st.drop_reason & 1, 1);
  EXPECT_GT(t_drop, 0.0);
  EXPECT_LT(st.slip_y, -5e-3);  // downwards
  EXPECT_NEAR(st.slip_x, 0.0, 1e-9);
  const FingerSample& s = plant.sensor_sample(0);
  EXPECT_LT(s.slip_vy, 0.0);
  EXPECT_NEAR(std::fabs(s.c_tilde), 1e3, 1e-9);  // pure translation
  // sliding: friction = mu f_n (dry) + viscous beta pi rho^2 v per pad
  const ContactParams p = c.contact;
  const double rho = p.delta * std::pow(0.05, p.gamma);
  const double pad_force = p.mu * 0.05 + p.beta_a * kPi * rho * rho * std::fabs(s.slip_vy);
  EXPECT_NEAR(-s.true_f_y, pad_force, 0.01 * pad_force);
}

TEST(GraspPlant, FreeFallWithZeroGripAcceleratesAtG) {
  PlantConfig c = base_config(0.2, 0.0);
  c.moves.push_back(GripperMove{0.1, 0.4, 0.0, 0.05});  // the gripper lifts meanwhile
  GraspPlant plant(c);
  for (int i = 0; i < 300; ++i) plant.step();
  const PlantState& st = plant.state();
  const double t = st.t;
  // world velocity of the CoG = gripper + relative: exactly -g t (implicit Euler of a constant force)
  EXPECT_NEAR(st.gripper_vy + st.vy, -kG * t, 1e-9);
  // world position: first order in h
  EXPECT_NEAR(st.gripper_y + st.y, -0.5 * kG * t * t, kG * t * plant.dt());
  EXPECT_TRUE(st.dropped);
  EXPECT_EQ(st.drop_reason & 4, 4);  // contact lost
  EXPECT_EQ(plant.sensor_sample(0).true_f_y, 0.0);
}

TEST(GraspPlant, PendulumPivotWhenTheForceIsLowered) {
  // 50 g, CoG 4 cm to the side: the object swings down toward hanging vertically (theta -> -90
  // deg) about the grasp axis and stops where the gravity torque falls inside the capacity.
  PlantConfig c = base_config(0.05, 8.0);
  c.object.cog_x = 0.04;
  c.object.inertia = 0.05 * 0.04 * 0.04 / 3.0;
  c.drop.rotation_limit = std::numeric_limits<double>::infinity();
  c.actuator.time_constant = 0.05;
  GraspPlant plant(c);
  for (int i = 0; i < 200; ++i) plant.step();
  EXPECT_LT(plant.state().max_rotation, 2e-3);  // 8 N holds 19.6 N mm (2 tau_max = 26 N mm)
  plant.set_command(2.0);                       // 2 tau_max(2 N) = 4.8 N mm
  double prev = plant.state().theta;
  bool monotone = true;
  for (int i = 0; i < 300; ++i) {
    plant.step();
    monotone = monotone && plant.state().theta <= prev + 1e-9;
    prev = plant.state().theta;
  }
  EXPECT_TRUE(monotone);
  for (int i = 0; i < 1500; ++i) plant.step();
  const PlantState& st = plant.state();
  EXPECT_LT(st.theta, -50.0 * kPi / 180.0);
  EXPECT_GT(st.theta, -130.0 * kPi / 180.0);
  EXPECT_NEAR(st.omega, 0.0, 1e-3);  // stopped
  // stopped where the gravity torque is inside the torsional capacity of both pads
  EXPECT_LT(0.05 * kG * std::fabs(st.x), 2.0 * tau_max(c.contact, 2.0) * 1.001);
  EXPECT_TRUE(st.dropped == false || (st.drop_reason & 2) == 0);
}

TEST(GraspPlant, SteadyTorsionalSlidingMatchesViscousExtension) {
  // No gravity, pure external torque above the capacity of both pads: steady rotation about the
  // pad centre with 2 (tau_max + (pi/2) beta rho^4 omega) = tau_e (eqs. 4, 8).
  PlantConfig c = base_config(0.1, 5.0);
  c.gravity = 0.0;
  c.contact.beta_a = 4.9e8;
  c.drop.rotation_limit = std::numeric_limits<double>::infinity();
  const ContactParams& p = c.contact;
  const double tm = tau_max(p, 5.0), rho = p.delta * std::pow(5.0, p.gamma);
  const double tau_e = 3.0 * tm;
  c.disturbances.push_back(Disturbance{0.0, 10.0, PulseShape::Rectangular, 0.0, 0.0, tau_e, 0.0, 0.0});
  GraspPlant plant(c);
  for (int i = 0; i < 3000; ++i) plant.step();
  const double omega = (tau_e / 2.0 - tm) / (0.5 * kPi * p.beta_a * std::pow(rho, 4));
  EXPECT_NEAR(plant.state().omega, omega, 0.01 * omega);
  EXPECT_LT(plant.state().max_slip, 1e-6);  // rotation about the pad centre, no translation
  EXPECT_NEAR(plant.sensor_sample(0).omega, omega, 0.01 * omega);
  EXPECT_NEAR(plant.sensor_sample(1).omega, -omega, 0.01 * omega);
  EXPECT_NEAR(plant.sensor_sample(0).c_tilde, 0.0, 1e-3);
  // the sensors read the friction torque with the sign of their slip rate (docs/model.md 7.2)
  EXPECT_NEAR(plant.sensor_sample(0).true_tau, tau_e / 2.0, 1e-3 * tau_e);
  EXPECT_NEAR(plant.sensor_sample(1).true_tau, -tau_e / 2.0, 1e-3 * tau_e);
}

TEST(GraspPlant, SupportHoldsUntilTheLiftAndAWeakGripLeavesTheObjectBehind) {
  for (double f_n : {5.0, 0.2}) {
    PlantConfig c = base_config(0.2, f_n);  // static requirement 1.15 N
    // With Table 2's beta_A the viscous drag of a 9 cm/s lift alone would carry the object
    // (beta pi rho^2 v = 5 N per pad at 0.2 N); make it negligible to test the dry grip.
    c.contact.beta_a = 1e5;
    c.support = true;
    c.moves.push_back(GripperMove{0.5, 1.0, 0.0, 0.05});
    GraspPlant plant(c);
    for (int i = 0; i < 450; ++i) plant.step();
    EXPECT_TRUE(plant.state().supported);
    EXPECT_LT(plant.state().max_slip, 1e-9);
    for (int i = 0; i < 1550; ++i) plant.step();
    const PlantState& st = plant.state();
    EXPECT_NEAR(st.gripper_y, 0.05, 1e-12);
    if (f_n > 1.0) {
      EXPECT_FALSE(st.supported);
      EXPECT_LT(st.max_slip, 2e-5);
      EXPECT_NEAR(st.gripper_y + st.y, 0.05, 2e-5);  // lifted with the gripper
      EXPECT_FALSE(st.dropped);
    } else {
      EXPECT_TRUE(st.supported);  // stayed on the table
      EXPECT_NEAR(st.gripper_y + st.y, 0.0, 1e-9);
      EXPECT_NEAR(st.slip_y, -0.05, 1e-9);
      EXPECT_TRUE(st.dropped);
    }
  }
}

TEST(GraspPlant, ActuatorZeroOrderHoldLagRateLimitAndSaturation) {
  PlantConfig c = base_config(0.1, 2.0);
  c.actuator.time_constant = 0.03;
  c.actuator.rate_limit = std::numeric_limits<double>::infinity();
  c.actuator.f_max = 40.0;
  GraspPlant plant(c);
  EXPECT_EQ(plant.steps_per_command(), 20);
  for (int i = 0; i < 5; ++i) plant.step();  // t = 5 ms, between ticks
  plant.set_command(12.0);
  for (int i = 0; i < 15; ++i) plant.step();  // up to t = 20 ms: still holding 2 N
  EXPECT_EQ(plant.state().f_held, 2.0);
  EXPECT_NEAR(plant.state().f_n, 2.0, 1e-12);
  for (int i = 0; i < 30; ++i) plant.step();  // latched at 20 ms, 30 ms later: one time constant
  EXPECT_EQ(plant.state().f_held, 12.0);
  EXPECT_NEAR(plant.state().f_n, 12.0 - 10.0 * std::exp(-1.0), 1e-9);
  // saturation and invalid commands
  plant.set_command(1e9);
  EXPECT_EQ(plant.state().f_cmd, 40.0);
  plant.set_command(std::nan(""));
  EXPECT_EQ(plant.state().f_cmd, 40.0);
  plant.set_command(-3.0);
  EXPECT_EQ(plant.state().f_cmd, 0.0);
  // rate limit
  PlantConfig r = c;
  r.actuator.rate_limit = 100.0;
  r.actuator.time_constant = 0.0;
  GraspPlant q(r);
  q.set_command(30.0);
  for (int i = 0; i < 100; ++i) {
    const double before = q.state().f_n;
    q.step();
    EXPECT_LE(q.state().f_n - before, 100.0 * q.dt() + 1e-12);
  }
  EXPECT_NEAR(q.state().f_n, 12.0, 1e-9);  // 2 N + 100 N/s * 0.1 s
}

TEST(GraspPlant, SensorNoiseStatisticsBiasAndQuantisation) {
  PlantConfig c = base_config(0.1, 5.0);
  c.sensor.force_noise = 0.005;
  c.sensor.torque_noise = 1e-5;
  c.sensor.bias[1] = {0.1, -0.02, 0.03, 2e-4};
  GraspPlant plant(c);
  EXPECT_EQ(plant.steps_per_sample(), 2);
  const int n = 20000;
  std::vector<double> e0(n), e1(n), et(n), ez(n);
  for (int k = 0; k < n; ++k) {
    plant.advance_sample();
    const FingerSample& a = plant.sensor_sample(0);
    const FingerSample& b = plant.sensor_sample(1);
    EXPECT_EQ(a.index, k + 1);
    e0[k] = a.f_y - a.true_f_y;
    e1[k] = b.f_x - b.true_f_x;
    et[k] = a.tau - a.true_tau;
    ez[k] = b.tau - b.true_tau;
  }
  auto mean = [&](const std::vector<double>& v) {
    double s = 0;
    for (double x : v) s += x;
    return s / v.size();
  };
  auto sd = [&](const std::vector<double>& v) {
    const double m = mean(v);
    double s = 0;
    for (double x : v) s += (x - m) * (x - m);
    return std::sqrt(s / (v.size() - 1));
  };
  // std within 3 % (sampling error of the std for n = 2e4 is 0.5 %), mean within 4 sigma/sqrt(n)
  EXPECT_NEAR(sd(e0), 0.005, 0.03 * 0.005);
  EXPECT_NEAR(sd(et), 1e-5, 0.03 * 1e-5);
  EXPECT_NEAR(mean(e0), 0.0, 4 * 0.005 / std::sqrt(n));
  EXPECT_NEAR(mean(e1), -0.02, 4 * 0.005 / std::sqrt(n));
  EXPECT_NEAR(mean(ez), 2e-4, 4 * 1e-5 / std::sqrt(n));
  double cov = 0;
  for (int k = 0; k < n; ++k) cov += e0[k] * (e1[k] + 0.02);
  EXPECT_LT(std::fabs(cov / n / (0.005 * 0.005)), 0.05);  // fingers independent
  // quantisation
  PlantConfig q = c;
  q.sensor.force_resolution = 0.01;
  q.sensor.torque_resolution = 1e-4;
  GraspPlant pq(q);
  for (int k = 0; k < 50; ++k) {
    pq.advance_sample();
    const FingerSample& s = pq.sensor_sample(0);
    EXPECT_NEAR(s.f_y / 0.01, std::round(s.f_y / 0.01), 1e-9);
    EXPECT_NEAR(s.tau / 1e-4, std::round(s.tau / 1e-4), 1e-9);
  }
}

TEST(GraspPlant, SensorFilterIsFirstOrder) {
  // A step of the actuator force passes through the sensor low-pass.
  PlantConfig c = base_config(0.1, 2.0);
  c.actuator.time_constant = 0.0;
  c.actuator.rate_limit = std::numeric_limits<double>::infinity();
  c.sensor.filter_time_constant = 0.01;
  GraspPlant plant(c);
  plant.set_command(4.0);
  for (int i = 0; i < 10; ++i) plant.step();  // 10 ms = one filter time constant
  EXPECT_NEAR(plant.sensor_sample(0).f_n, 4.0 - 2.0 * std::exp(-1.0), 1e-9);
  EXPECT_EQ(plant.sensor_sample(0).true_f_n, 4.0);
}

TEST(GraspPlant, DeterministicWithASeed) {
  PlantConfig c = base_config(0.1, 0.8);
  c.object.cog_x = 0.02;
  c.sensor.force_noise = 0.005;
  c.sensor.torque_noise = 1e-5;
  c.disturbances.push_back(Disturbance{0.2, 0.1, PulseShape::HalfSine, 0.5, 0.2, 1e-3, 0.0, 0.01});
  c.seed = 42;
  GraspPlant a(c), b(c);
  PlantConfig d = c;
  d.seed = 43;
  GraspPlant other(d);
  bool differ = false;
  std::vector<double> first;
  for (int k = 0; k < 300; ++k) {
    a.advance_sample();
    b.advance_sample();
    other.advance_sample();
    if (k % 50 == 0) a.set_command(0.8 + 0.01 * k), b.set_command(0.8 + 0.01 * k), other.set_command(0.8 + 0.01 * k);
    ASSERT_EQ(a.sensor_sample(0).tau, b.sensor_sample(0).tau);
    ASSERT_EQ(a.sensor_sample(1).f_y, b.sensor_sample(1).f_y);
    ASSERT_EQ(a.state().theta, b.state().theta);
    differ = differ || a.sensor_sample(0).tau != other.sensor_sample(0).tau;
    first.push_back(a.sensor_sample(1).f_x);
  }
  EXPECT_TRUE(differ);
  EXPECT_EQ(a.state().theta, other.state().theta);  // noise does not feed back open loop
  a.reset();
  for (int k = 0; k < 300; ++k) {
    a.advance_sample();
    if (k % 50 == 0) a.set_command(0.8 + 0.01 * k);
    ASSERT_EQ(a.sensor_sample(1).f_x, first[k]);
  }
}

TEST(GraspPlant, NeverNaNUnderExtremeInputs) {
  for (PlantModel model : {PlantModel::Patch, PlantModel::Lumped}) {
    PlantConfig c = base_config(0.05, 5.0);
    c.model = model;
    c.object.cog_x = 0.03;
    c.sensor.force_noise = 0.005;
    c.disturbances.push_back(Disturbance{0.1, 0.05, PulseShape::Rectangular, 1e6, -1e6, 1e3, 0.1, 0.0});
    c.disturbances.push_back(Disturbance{0.3, 0.2, PulseShape::Ramp, 0.0, 0.0, -1e4, 0.0, 0.0});
    c.moves.push_back(GripperMove{0.0, 0.05, 1.0, 1.0});  // violent robot motion
    GraspPlant plant(c);
    for (int i = 0; i < 1500; ++i) {
      if (i == 100) plant.set_command(0.0);
      if (i == 300) plant.set_command(std::numeric_limits<double>::infinity());
      if (i == 400) plant.set_command(std::nan(""));
      if (i == 700) plant.set_command(1e-9);
      plant.step();
      const PlantState& st = plant.state();
      const FingerSample& s = plant.sensor_sample(i & 1);
      for (double v : {st.x, st.y, st.vx, st.vy, st.theta, st.omega, st.contact_fx, st.contact_tau,
                       st.f_n, s.f_x, s.f_y, s.tau, s.true_tau, s.c_tilde, s.slip_vx, s.omega})
        ASSERT_TRUE(std::isfinite(v)) << to_string(model) << " step " << i;
    }
    if (model == PlantModel::Patch) EXPECT_TRUE(plant.state().dropped);
  }
}

TEST(GraspPlant, DisturbanceShapesAndImpulse) {
  PlantConfig c = base_config();
  const double A = 2.0, T = 0.2;
  for (PulseShape sh : {PulseShape::Rectangular, PulseShape::HalfSine, PulseShape::Ramp, PulseShape::Triangle}) {
    c.disturbances = {Disturbance{1.0, T, sh, A, 0.0, 0.0, 0.0, 0.0}};
    GraspPlant plant(c);
    double impulse = 0.0;
    const int n = 100000;
    for (int i = 0; i < n; ++i) {
      double fx, fy, tz;
      plant.disturbance_at(0.9 + 0.4 * (i + 0.5) / n, 0.0, fx, fy, tz);
      impulse += fx * 0.4 / n;
      EXPECT_LE(fx, A + 1e-12);
    }
    const double expect = sh == PulseShape::Rectangular ? A * T : sh == PulseShape::HalfSine ? 2 * A * T / kPi : A * T / 2;
    EXPECT_NEAR(impulse, expect, 1e-4 * A * T) << to_string(sh);
  }
  // force at a point of the object: torque about the CoG = p x F with p rotated by theta
  c.disturbances = {Disturbance{0.0, 1.0, PulseShape::Rectangular, 0.0, 3.0, 0.5, 0.02, 0.0}};
  GraspPlant plant(c);
  double fx, fy, tz;
  plant.disturbance_at(0.5, kPi / 2, fx, fy, tz);  // point now at (0, 0.02): p x F = 0
  EXPECT_NEAR(tz, 0.5, 1e-12);
  plant.disturbance_at(0.5, 0.0, fx, fy, tz);
  EXPECT_NEAR(tz, 0.5 + 0.02 * 3.0, 1e-12);
}

TEST(GraspPlant, PushOnAHeldObjectSlipsAndTheGripRecovers) {
  PlantConfig c = base_config(0.3, 3.0);  // 1.47 N per pad, capacity 2.55 N
  c.disturbances.push_back(Disturbance{0.5, 0.1, PulseShape::HalfSine, 0.0, -4.0, 0.0, 0.0, 0.0});
  GraspPlant plant(c);
  double vmin = 0.0;
  for (int i = 0; i < 1500; ++i) {
    plant.step();
    vmin = std::min(vmin, plant.state().vy);
  }
  const PlantState& st = plant.state();
  EXPECT_LT(vmin, -1e-3);          // slid during the push
  EXPECT_LT(st.slip_y, -1e-5);
  EXPECT_NEAR(st.vy, 0.0, 1e-6);   // and stuck again afterwards
  EXPECT_FALSE(st.dropped);
}

TEST(GraspPlant, EnergyNeverIncreasesWithoutInput) {
  // Pendulum release with friction: kinetic + potential + bristle energy is non-increasing
  // (the contact and the implicit step only dissipate).
  PlantConfig c = base_config(0.1, 1.5);
  c.object.cog_x = 0.04;
  c.object.inertia = 5e-5;
  c.drop.rotation_limit = std::numeric_limits<double>::infinity();
  c.patch.bristle_damping = 0.0;
  GraspPlant plant(c);
  double e = plant.energy();
  const double e0 = e;
  for (int i = 0; i < 2000; ++i) {
    plant.step();
    const double en = plant.energy();
    ASSERT_LE(en, e + 1e-9 * std::fabs(e0) + 1e-12) << "step " << i;
    e = en;
  }
  EXPECT_LT(e, e0 - 0.1 * 0.1 * kG * 0.02);  // it did swing down and lose energy
}

// ---------------------------------------------------------------------------------------------
// Lumped plant (docs/model.md 10.1 (a))

TEST(GraspPlantLumped, TorsionalThresholdMatchesThePatchPlant) {
  // Pure external torque, no gravity: both plants start rotating above 2 tau_max.
  for (PlantModel model : {PlantModel::Patch, PlantModel::Lumped}) {
    for (double ratio : {0.9, 1.15}) {
      PlantConfig c = base_config(0.1, 4.0);
      c.model = model;
      c.gravity = 0.0;
      c.drop.rotation_limit = std::numeric_limits<double>::infinity();
      const double te = ratio * 2.0 * tau_max(c.contact, 4.0);
      c.disturbances.push_back(Disturbance{0.0, 10.0, PulseShape::Rectangular, 0.0, 0.0, te, 0.0, 0.0});
      GraspPlant plant(c);
      for (int i = 0; i < 1000; ++i) plant.step();
      // below: elastic pre-sliding and partial slip of the outer cells only (patch)
      if (ratio < 1.0) EXPECT_LT(plant.state().max_rotation, 1e-2) << to_string(model);
      else EXPECT_GT(plant.state().max_rotation, 0.05) << to_string(model);
    }
  }
}

TEST(GraspPlantLumped, PivotsTowardVerticalAndReadsTheLoad) {
  PlantConfig c = base_config(0.05, 8.0);
  c.model = PlantModel::Lumped;
  c.object.cog_x = 0.04;
  c.object.inertia = 0.05 * 0.04 * 0.04 / 3.0;
  c.drop.rotation_limit = std::numeric_limits<double>::infinity();
  GraspPlant plant(c);
  for (int i = 0; i < 500; ++i) plant.step();
  EXPECT_LT(plant.state().max_rotation, 2e-3);
  const FingerSample& s0 = plant.sensor_sample(0);
  const double W = 0.05 * kG;
  EXPECT_NEAR(s0.true_f_y, -W / 2, 1e-9);
  EXPECT_NEAR(s0.true_tau, -W * 0.04 / 2, 1e-3 * W * 0.04);
  plant.set_command(2.0);
  for (int i = 0; i < 2000; ++i) plant.step();
  const PlantState& st = plant.state();
  EXPECT_LT(st.theta, -50.0 * kPi / 180.0);
  EXPECT_GT(st.theta, -130.0 * kPi / 180.0);
  EXPECT_EQ(st.slip_x, 0.0);  // no translation state
  EXPECT_EQ(st.slip_y, 0.0);
}

// ---------------------------------------------------------------------------------------------
// Exact caches of the plant (cos/sin of the object angle, rho at the actuator force, the actuator
// decay and filter constants, the lumped CoR's rho/g/sigma_1): every cached value must equal,
// bit for bit, the direct computation from the same inputs.

namespace {
PlantConfig cache_config(PlantModel model) {
  PlantConfig c = base_config(0.2, 3.0);
  c.model = model;
  c.object.cog_x = 0.01;
  c.object.cog_y = -0.004;
  c.object.theta0 = 0.3;
  c.sensor.filter_time_constant = 0.003;
  c.sensor.force_noise = 0.004;
  c.sensor.torque_noise = 1e-5;
  c.actuator.time_constant = 0.02;
  c.drop.rotation_limit = std::numeric_limits<double>::infinity();
  c.drop.slip_limit = std::numeric_limits<double>::infinity();
  // pulses applied off the CoG (the force moment needs cos/sin of theta), overlapping
  c.disturbances.push_back(Disturbance{0.05, 0.3, PulseShape::HalfSine, 0.8, -0.5, 0.01, 0.02, 0.01});
  c.disturbances.push_back(Disturbance{0.2, 0.2, PulseShape::Triangle, -0.4, 0.3, -0.02, -0.01, 0.0});
  return c;
}
}  // namespace

TEST(GraspPlantCaches, BitIdenticalToTheDirectComputation) {
  for (PlantModel model : {PlantModel::Lumped, PlantModel::Patch}) {
    const PlantConfig c = cache_config(model);
    GraspPlant plant(c);
    const double h = plant.dt();
    const double decay = std::exp(-h / c.actuator.time_constant);
    const double cmd[] = {3.0, 1.2, 0.5, 2.5, 0.0, 4.0};
    int rotating = 0, pushed = 0;
    for (int n = 0; n < 600; ++n) {
      if (n % 100 == 0) plant.set_command(cmd[n / 100]);
      const double theta = plant.state().theta, f_prev = plant.state().f_n;
      const double held = (n % plant.steps_per_command() == 0) ? plant.state().f_cmd : plant.state().f_held;
      const bool sample = plant.step();
      const PlantState& st = plant.state();
      // disturbance of the step at its end time, with the angle at its start (fresh cos/sin)
      double fx, fy, tau;
      plant.disturbance_at(static_cast<double>(n) * h + 0.0 * h + h, theta, fx, fy, tau);
      ASSERT_EQ(st.ext_fx, fx) << n;
      ASSERT_EQ(st.ext_fy, fy) << n;
      ASSERT_EQ(st.ext_tau, tau) << n;
      if (tau != 0.0) ++pushed;
      // CoG from the end angle (fresh cos/sin)
      const double ct = std::cos(st.theta), sn = std::sin(st.theta);
      ASSERT_EQ(st.x, st.slip_x + ct * c.object.cog_x - sn * c.object.cog_y) << n;
      ASSERT_EQ(st.y, st.slip_y + sn * c.object.cog_x + ct * c.object.cog_y) << n;
      if (st.theta != theta) ++rotating;
      // actuator lag with a fresh exp (the rate limit is 0.2 N per step here)
      const double target = std::min(std::max(held, 0.0), c.actuator.f_max);
      double f = target + (f_prev - target) * decay;
      const double dmax = c.actuator.rate_limit * h;
      f = std::min(std::max(f, f_prev - dmax), f_prev + dmax);
      ASSERT_EQ(st.f_n, std::min(std::max(f, 0.0), c.actuator.f_max)) << n;
      if (sample) {
        const double rho = plant.contact_model().rho(st.f_n);
        ASSERT_EQ(plant.sensor_sample(0).rho, rho) << n;
        ASSERT_EQ(plant.sensor_sample(1).rho, rho) << n;
      }
    }
    EXPECT_GT(rotating, 100) << to_string(model);  // the angle changed: the cache was refreshed
    EXPECT_GT(pushed, 100) << to_string(model);
  }
}

TEST(GraspPlantCaches, ResetRepeatsTheRunBitForBit) {
  // Caches must not leak across reset(): a second run from reset() equals the first exactly, and
  // equals a fresh plant's run.
  for (PlantModel model : {PlantModel::Lumped, PlantModel::Patch}) {
    const PlantConfig c = cache_config(model);
    GraspPlant a(c), b(c);
    std::vector<double> first;
    auto run = [&](GraspPlant& p, std::vector<double>& out) {
      for (int n = 0; n < 400; ++n) {
        if (n % 50 == 0) p.set_command(0.5 + 0.01 * n);
        p.step();
        const PlantState& st = p.state();
        out.insert(out.end(), {st.theta, st.omega, st.f_n, st.contact_tau, st.contact_fx, st.ext_tau,
                               p.sensor_sample(0).tau, p.sensor_sample(1).f_x, p.sensor_sample(0).c_tilde});
      }
    };
    run(a, first);
    a.reset();
    std::vector<double> second, fresh;
    run(a, second);
    run(b, fresh);
    ASSERT_EQ(first.size(), second.size());
    for (size_t i = 0; i < first.size(); ++i) {
      ASSERT_EQ(first[i], second[i]) << to_string(model) << " " << i;
      ASSERT_EQ(first[i], fresh[i]) << to_string(model) << " " << i;
    }
  }
}
