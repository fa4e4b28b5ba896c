// lugrip — planar grasp simulator: a rigid object between the two soft fingertips of a parallel
// gripper, with a distributed-friction contact model (docs/model.md 10.1 (b)) or the lumped slider
// of eqs. 1-2 (docs/model.md 10.1 (a)), a first-order gripper actuator behind a 50 Hz zero-order
// hold, fingertip force/torque sensors at 500 Hz and external pushes. Deterministic (seeded).
//
// Frames (all planar, SI units):
//  * Gripper frame: origin at the grasp point (where the grasp axis, normal to both pads, pierces
//    the finger plane), X horizontal, Y vertical up (gravity along -Y), Z = X x Y along the grasp
//    axis. The gripper translates along a prescribed trajectory and does not rotate.
//  * Object frame: rigid; at t = 0 its origin is at the grasp point and it is rotated by theta0.
//    The CoG sits at `cog` in the object frame. theta is the object's angle about Z.
//  * Fingertip i (i = 0, 1) sits on the -Z (i = 0) or +Z (i = 1) face of the object. Its sensor
//    frame has z_i along the pad normal pointing into the object (z_0 = +Z, z_1 = -Z), y_i = Y and
//    x_i = y_i x z_i (x_0 = +X, x_1 = -X). The sensor reads the wrench the OBJECT exerts on the
//    fingertip (docs/model.md 7.2), so tau_i has the sign of the slip angular velocity omega_i =
//    z_i . omega while sliding, and f_n > 0 is the compression.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "lugrip/contact.hpp"
#include "lugrip/params.hpp"
#include "lugrip/status.hpp"

namespace lugrip {

//! Which contact model the plant uses.
enum class PlantModel : int {
  //! Distributed contact (default): each pad is a polar grid of cells carrying a 2-D elementary
  //! LuGre bristle plus the viscous stress beta_A v; the object has 3 DOF (x, y, theta) and can
  //! slide, fall or pivot. Reproduces the limit surface and its viscous extension by construction.
  Patch = 0,
  //! Lumped slider (eqs. 1-2) about the CoR of the current load, per finger. Only the rotation
  //! theta is a state: the object does NOT translate relative to the fingers (no translational
  //! slip, no falling). Fast, and identical in structure to the observer's model.
  Lumped = 1,
};

//! Time profile of an external disturbance pulse.
enum class PulseShape : int {
  Rectangular = 0,  //!< amplitude over [t_start, t_start + duration)
  HalfSine = 1,     //!< amplitude sin(pi s), s = (t - t_start)/duration in [0, 1]
  Ramp = 2,         //!< amplitude s (linear rise), then released to zero at the end
  Triangle = 3,     //!< amplitude (1 - |2 s - 1|)
};

const char* to_string(PlantModel m) noexcept;
const char* to_string(PulseShape s) noexcept;

//! Rigid planar object.
struct ObjectConfig {
  double mass = 0.0;     //!< [kg], > 0
  double inertia = 0.0;  //!< moment of inertia about the CoG, about the grasp axis [kg m^2], > 0
  double cog_x = 0.0;    //!< CoG in the object frame, relative to the grasp point [m]
  double cog_y = 0.0;    //!< [m]
  double theta0 = 0.0;   //!< initial object angle about Z [rad]
};

//! One minimum-jerk (quintic) displacement of the grasp point, e.g. a lift (dy > 0). Moves add up.
struct GripperMove {
  double t_start = 0.0;   //!< [s]
  double duration = 1.0;  //!< [s], > 0
  double dx = 0.0;        //!< total displacement [m] (gripper frame = world axes)
  double dy = 0.0;        //!< [m]
};

//! External push on the object (e.g. by a person): force applied at a point of the object plus a
//! pure torque about the grasp-axis direction, both scaled by the pulse shape.
struct Disturbance {
  double t_start = 0.0;    //!< [s]
  double duration = 0.1;   //!< [s], > 0
  PulseShape shape = PulseShape::Rectangular;
  double force_x = 0.0;    //!< peak force, world axes [N]
  double force_y = 0.0;    //!< [N]
  double torque = 0.0;     //!< peak pure torque about Z [N m]
  double point_x = 0.0;    //!< application point relative to the CoG, object frame [m]
  double point_y = 0.0;    //!< [m]
};

//! Gripper force actuator: ZOH of the command at command_rate, saturation, first-order lag, rate
//! limit. Both fingers press with the actuator force.
struct ActuatorConfig {
  double f_init = 1.0;          //!< force at t = 0 (also the initial command) [N], in [0, f_max]
  double f_max = 80.0;          //!< saturation [N], > 0 (WSG50: 80 N)
  double time_constant = 0.03;  //!< first-order lag [s], >= 0 (0: no lag)
  double rate_limit = 200.0;    //!< |df/dt| limit [N/s], > 0 (inf: none)
  double command_rate = 50.0;   //!< command ZOH rate [Hz]; rate / command_rate must be an integer
};

//! Fingertip force/torque sensor (one per finger, same settings, independent noise streams).
struct SensorConfig {
  double rate = 500.0;            //!< sampling rate [Hz]; plant rate / rate must be an integer
  double force_noise = 0.005;     //!< white noise std on f_n, f_x, f_y [N] (docs/model.md 10.1)
  double torque_noise = 1.0e-5;   //!< white noise std on tau [N m] (0.01 N mm)
  double force_resolution = 0.0;  //!< quantisation step of the forces [N] (0: off)
  double torque_resolution = 0.0; //!< quantisation step of the torque [N m] (0: off)
  double filter_time_constant = 0.0;  //!< first-order low-pass before sampling [s] (0: off)
  //! Constant bias added per finger to (f_n, f_x, f_y, tau) [N, N, N, N m].
  std::array<std::array<double, 4>, 2> bias{};
};

//! Distributed contact (PlantModel::Patch).
//!
//! | field | meaning | unit | default |
//! |---|---|---|---|
//! | rings | radial rings of the polar grid (cells ~ pi rings^2: 10 -> 314) | - | 10 |
//! | bristle_stiffness | kappa: cell stiffness per unit cell normal load, k_j = kappa n_j | 1/m | 1e6 |
//! | bristle_damping | t_d: cell damping c_j = t_d k_j | s | 2e-4 |
//! | static_ratio | mu_s / mu (Stribeck; 1 = plain Coulomb) | - | 1 |
//! | stribeck_velocity | v_s in mu(v) = mu (1 + (ratio - 1) exp(-(v/v_s)^2)) | m/s | 1e-3 |
struct PatchSettings {
  int rings = 10;
  double bristle_stiffness = 1.0e6;
  double bristle_damping = 2.0e-4;
  double static_ratio = 1.0;
  double stribeck_velocity = 1.0e-3;
};

//! When the object counts as dropped (first crossing is recorded; the simulation goes on).
struct DropConfig {
  double slip_limit = 5.0e-3;          //!< translational slip of the grasped point [m]
  double rotation_limit = 0.349065850398866;  //!< |theta - theta0| [rad] (20 deg; inf disables)
  double contact_force_min = 1.0e-3;   //!< f_n below this while not supported: contact lost [N]
};

//! Everything the plant needs. Physical fields of `contact` and `object` have no silent default.
struct PlantConfig {
  ContactParams contact;         //!< both fingertips (mu, beta_A of the object; Table 1 rest)
  PlantModel model = PlantModel::Patch;
  ObjectConfig object;
  ActuatorConfig actuator;
  SensorConfig sensor;
  PatchSettings patch;
  DropConfig drop;
  double gravity = 9.81;         //!< [m/s^2], >= 0, along -Y
  double rate = 1000.0;          //!< plant step rate [Hz]
  int substeps = 1;              //!< internal integration substeps per plant step (>= 1)
  //! The object starts resting on a support (a table) that holds it still (no slip, no rotation)
  //! until the contact forces lift it; it lands on the support again if it falls back to it.
  bool support = false;
  std::vector<GripperMove> moves;
  std::vector<Disturbance> disturbances;
  uint64_t seed = 1;             //!< sensor noise seed
};

//! Checks every field; one line per bad field in *message. Returns true when valid.
bool validate(const PlantConfig& c, std::string* message);

//! One sensor sample of one finger, with the ground truth at the same instant.
struct FingerSample {
  int64_t index = 0;   //!< sample number (0 at t = 0)
  double t = 0.0;      //!< [s]
  // measured, sensor frame of the finger (noise, bias, quantisation, filter)
  double f_n = 0.0, f_x = 0.0, f_y = 0.0;  //!< [N]
  double tau = 0.0;                         //!< [N m]
  // true wrench object -> fingertip, same frame (no noise, no filter)
  double true_f_n = 0.0, true_f_x = 0.0, true_f_y = 0.0, true_tau = 0.0;
  // object relative to this fingertip, sensor frame
  double slip_x = 0.0, slip_y = 0.0;  //!< displacement of the object point that was at the pad centre [m]
  double slip_angle = 0.0;            //!< rotation since t = 0 about z_i [rad]
  double slip_vx = 0.0, slip_vy = 0.0;  //!< velocity of the object point at the pad centre [m/s]
  double omega = 0.0;                 //!< slip angular velocity about z_i [rad/s]
  //! CoR of the relative motion normalised by rho, signed as the CoR estimator returns it for
  //! the sensor's wrench (sign = -sign(omega)); +-1e3 for (near) pure translation, 0 at rest.
  double c_tilde = 0.0;
  double rho = 0.0;                   //!< contact radius [m]
};

//! Plant state after the last step (gripper frame unless "world").
struct PlantState {
  double t = 0.0;              //!< [s]
  double f_cmd = 0.0;          //!< last command given to set_command [N]
  double f_held = 0.0;         //!< command held by the ZOH [N]
  double f_n = 0.0;            //!< actuator = contact normal force of each finger [N]
  double gripper_x = 0.0, gripper_y = 0.0;    //!< grasp point, world [m]
  double gripper_vx = 0.0, gripper_vy = 0.0;  //!< [m/s]
  double x = 0.0, y = 0.0;     //!< CoG relative to the grasp point [m]
  double vx = 0.0, vy = 0.0;   //!< CoG velocity relative to the gripper [m/s]
  double theta = 0.0;          //!< object angle [rad]
  double omega = 0.0;          //!< [rad/s]
  double slip_x = 0.0, slip_y = 0.0;  //!< displacement of the object point that was at the grasp point [m]
  double slip_angle = 0.0;     //!< theta - theta0 [rad]
  double max_slip = 0.0;       //!< max |slip| so far [m] (lumped: integral of |omega c|)
  double max_rotation = 0.0;   //!< max |theta - theta0| so far [rad]
  double contact_fx = 0.0, contact_fy = 0.0;  //!< friction force on the object, both fingers [N]
  double contact_tau = 0.0;    //!< friction torque on the object about the grasp point, both fingers [N m]
  double ext_fx = 0.0, ext_fy = 0.0, ext_tau = 0.0;  //!< disturbance at this step [N], [N m] (about CoG)
  bool supported = false;      //!< resting on the support
  bool dropped = false;        //!< a drop criterion was met at some time
  double drop_time = -1.0;     //!< first time a criterion was met [s] (-1: never)
  int drop_reason = 0;         //!< bit 0: slip, bit 1: rotation, bit 2: contact lost
  int64_t steps = 0;           //!< plant steps since reset
};

//! Wrench of one pad on the object, about the pad centre, gripper axes.
struct PadWrench {
  double fx = 0.0, fy = 0.0;  //!< [N]
  double tau = 0.0;           //!< about Z [N m]
};

//! One fingertip pad as a discretised pressure patch (docs/model.md 10.1 (b)). Unit-disc polar grid:
//! `rings` uniform rings, each split into ~square cells (staggered), cell at the pressure
//! centroid radius of its ring, cell load share = exact integral of p(r) over the cell (docs/model.md
//! 2.2). At run time the cells are scaled by rho(f_n) = delta f_n^gamma and loaded with f_n.
//! Each cell carries a 2-D bristle z_j [m]:
//!   zdot_j = v_j - |v_j| z_j / z_max(|v_j|),   z_max(v) = mu(v) / kappa,
//!   f_j = -(k_j z_j + c_j zdot_j),  k_j = kappa n_j,  c_j = t_d k_j,
//! (so every cell saturates at mu(v) n_j), plus the viscous stress -beta_A v over the disc, which
//! is linear in position and therefore integrated in closed form: -beta_A pi rho^2 v_centre and
//! -beta_A (pi/2) rho^4 omega (docs/model.md 5.1, eqs. 7-8).
//!
//! Step: the bristles are advanced exactly for velocities frozen over the step (exponential
//! update) and the result is linear in the end-of-step velocity, which lets the plant solve the
//! object's velocity implicitly: prepare() returns the affine wrench A - B v_end, finish()
//! commits the bristles for the chosen end velocity. Allocation-free after construction.
class PatchContact {
 public:
  PatchContact(const ContactParams& params, const PatchSettings& settings);

  //! Affine wrench of the pad on the object, about the pad centre, as a function of the
  //! end-of-step velocity (V of the object point at the pad centre, omega):
  //!   F = a_f - b0 V - omega (z x b1),   tau = a_tau - b1 x V - omega b2.
  struct Linear {
    double a_fx = 0.0, a_fy = 0.0, a_tau = 0.0;  //!< [N], [N m]
    double b0 = 0.0;             //!< [N s/m]
    double b1x = 0.0, b1y = 0.0; //!< [N s]
    double b2 = 0.0;             //!< [N m s]
  };

  //! Freezes the step: normal force f_n [N], current velocity (vx, vy, omega) of the object
  //! relative to the pad [m/s, rad/s], step h [s].
  void prepare(double f_n, double vx, double vy, double omega, double h, Linear& lin) noexcept;
  //! Commits the bristles for the end-of-step velocity and returns the actual wrench (equal to the
  //! affine one unless a bristle was projected onto its bound).
  void finish(double vx, double vy, double omega, PadWrench& w) noexcept;
  //! Prescribed kinematics: prepare + finish with the same velocity.
  void advance(double f_n, double vx, double vy, double omega, double h, PadWrench& w) noexcept;

  void reset() noexcept;
  int cells() const noexcept { return static_cast<int>(w_.size()); }
  double rho() const noexcept { return rho_; }
  //! Sum over cells of the normalised load share times (r/rho)^2 (torsional stiffness factor):
  //! stick stiffness kappa f_n (tangential) and kappa f_n rho^2 moment2() (torsional).
  double moment2() const noexcept { return m2_; }
  //! Elastic energy stored in the bristles [J] at the last normal force.
  double bristle_energy() const noexcept;
  const PatchSettings& settings() const noexcept { return s_; }

 private:
  ContactParams p_;
  PatchSettings s_;
  std::vector<double> ux_, uy_, w_;  // unit-disc cell positions and load shares (sum 1)
  std::vector<double> zx_, zy_;      // bristle deflections [m]
  std::vector<double> e_, phi_;      // frozen step coefficients
  double m2_ = 0.0;
  double f_n_ = 0.0, rho_ = 0.0, h_ = 0.0, kappa_ = 0.0, zmax_c_ = 0.0;
  double mu_ratio_ = 1.0, inv_vs2_ = 0.0;

  double zmax(double speed) const noexcept;
};

//! Deterministic normal random numbers: xoshiro256++ (seeded by splitmix64) and a 256-layer
//! ziggurat (Marsaglia & Tsang 2000) with an exact tail. The same seed gives the same sequence on
//! every platform (std::normal_distribution does not), up to the last bit of std::exp/std::log
//! in the rare wedge/tail cases. The fast path (98.5 % of the draws) is one next_u64(), an
//! integer compare and one multiplication by a compile-time table entry; the layer index, the
//! sign and the 52-bit abscissa come from disjoint bits of that draw (see grasp_plant_patch.cpp).
class NormalRng {
 public:
  explicit NormalRng(uint64_t seed = 1) noexcept { seed_with(seed); }
  void seed_with(uint64_t seed) noexcept;
  uint64_t next_u64() noexcept {
    const uint64_t result = rotl(s_[0] + s_[3], 23) + s_[0];
    const uint64_t t = s_[1] << 17;
    s_[2] ^= s_[0];
    s_[3] ^= s_[1];
    s_[1] ^= s_[2];
    s_[0] ^= s_[3];
    s_[2] ^= t;
    s_[3] = rotl(s_[3], 45);
    return result;
  }
  //! In [0, 1).
  double uniform() noexcept { return static_cast<double>(next_u64() >> 11) * 0x1.0p-53; }
  //! Standard normal.
  double normal() noexcept {
    const uint64_t u = next_u64();
    const Layer& l = kZigLayers[u & 0xFF];
    const int64_t a = static_cast<int64_t>(u >> 12);  // abscissa in [0, 2^52)
    if (a < l.k) {
      const int64_t neg = -static_cast<int64_t>((u >> 8) & 1);  // 0 or -1: the sign bit
      return static_cast<double>((a ^ neg) - neg) * l.w;         // exact negation, no branch
    }
    return normal_slow(u);
  }

  //! Ziggurat tables (read-only; public for the table test). Layer i: an abscissa a in [0, 2^52)
  //! is accepted at once when a < k, and the sample is then +-a * w (w = layer width * 2^-52).
  struct Layer {
    int64_t k;
    double w;
  };
  static const Layer kZigLayers[256];
  static const double kZigF[256];  //!< exp(-x_i^2 / 2) at the layer edges x_0 = r > ... > x_255 = 0

 private:
  static uint64_t rotl(uint64_t x, int k) noexcept { return (x << k) | (x >> (64 - k)); }
  double normal_slow(uint64_t u) noexcept;  //!< wedge and tail cases, then fresh draws

  uint64_t s_[4] = {0, 0, 0, 0};
};

//! Input of one sensor-rate step() of the plant.
struct PlantInput {
  double command = std::numeric_limits<double>::quiet_NaN();  //!< grasp-force command [N]; NaN: keep the last
};

//! Output of one sensor-rate step(): the state and both fingertip samples at the new sample.
struct PlantOutput {
  PlantState state;                      //!< plant state at the new sample
  std::array<FingerSample, 2> fingers{};  //!< sensor sample of each finger
};

//! The grasp simulator. Lifecycle: construct (validates, allocates) -> set_command / step
//! (noexcept, no allocation) -> reset. One step advances 1/rate seconds; a sensor sample of both
//! fingers is taken at t = 0 and every rate/sensor.rate steps.
//!
//! Closed loop at the sensor rate (the intended use):
//! \code
//!   GraspPlant plant(cfg);
//!   for (int64_t n = 0; n < N; ++n) {
//!     const FingerSample& s0 = plant.sensor_sample(0), &s1 = plant.sensor_sample(1);
//!     ... observers, controller ...
//!     if (n % 10 == 0) plant.set_command(f);  // 50 Hz (the plant's ZOH latches at its ticks anyway)
//!     plant.advance_sample();                 // to the next 500 Hz sample
//!   }
//! \endcode
class GraspPlant {
 public:
  //! Throws std::invalid_argument (every bad field listed) for an invalid config.
  explicit GraspPlant(const PlantConfig& config);

  //! Back to t = 0 (same seed: the run repeats exactly).
  void reset() noexcept;
  //! Grasp-force command [N]; latched by the ZOH at the next command tick (ticks at t = j /
  //! command_rate, the first at t = 0). Clipped to [0, f_max]; NaN is ignored.
  void set_command(double f_cmd) noexcept;
  //! Applies an additional force/torque on the object (world axes, at the CoG) from now on, on top
  //! of the configured pulses, e.g. for interactive use [N], [N m].
  void set_external(double fx, double fy, double torque) noexcept;
  //! One plant step of 1/rate s. Returns true when a new sensor sample was taken at its end.
  bool step() noexcept;
  //! Steps until the next sensor sample; returns its index.
  int64_t advance_sample() noexcept;
  //! The component shape of the library: set_command(in.command), advance_sample(), then the
  //! new state and samples into `out`. Returns Ok, or InvalidSample for a command that is not a
  //! number (ignored: the last command is kept).
  Status step(const PlantInput& in, PlantOutput& out) noexcept;

  //! Latest sample of finger 0 or 1 (taken at t = index / sensor.rate).
  const FingerSample& sensor_sample(int finger) const noexcept { return sample_[finger & 1]; }
  const PlantState& state() const noexcept { return st_; }
  const PlantConfig& config() const noexcept { return cfg_; }
  const ContactModel& contact_model() const noexcept { return model_; }
  double time() const noexcept { return st_.t; }
  double dt() const noexcept { return h_; }
  int steps_per_sample() const noexcept { return steps_per_sample_; }
  int steps_per_command() const noexcept { return steps_per_command_; }
  int cells() const noexcept { return patch_.cells(); }
  //! Mechanical energy in the world frame: kinetic + gravitational + bristle elastic [J].
  double energy() const noexcept;

  //! Gripper trajectory (sum of the configured moves) at time t [m], [m/s].
  void gripper_at(double t, double& x, double& y, double& vx, double& vy) const noexcept;
  //! Disturbance at time t: world force at the CoG and torque about the CoG [N], [N m].
  void disturbance_at(double t, double theta, double& fx, double& fy, double& tau) const noexcept;

 private:
  PlantConfig cfg_;
  ContactModel model_;
  PatchContact patch_;
  CorEstimator cor_;
  double h_ = 0.0;
  int steps_per_sample_ = 1, steps_per_command_ = 1;
  // dynamic state
  PlantState st_;
  double f_act_ = 0.0, f_held_ = 0.0, f_cmd_ = 0.0;
  // CoG position r and velocity v relative to the grasp point, angle, angular velocity; slip u of
  // the object point that was at the grasp point; twist of the last step (V at the pad centre)
  double rx_ = 0.0, ry_ = 0.0, vx_ = 0.0, vy_ = 0.0, th_ = 0.0, om_ = 0.0;
  double ux_ = 0.0, uy_ = 0.0, Vx_ = 0.0, Vy_ = 0.0;
  double support_y_ = 0.0;  // world CoG height of the support
  bool supported_ = false;
  double ext_fx_ = 0.0, ext_fy_ = 0.0, ext_tau_ = 0.0;  // set_external
  PadWrench pad_;         // one pad on the object about the grasp point
  double lumped_z_ = 0.0, lumped_c_ = 0.0, lumped_slip_ = 0.0;
  std::array<std::array<double, 4>, 2> filt_{};  // sensor low-pass state per finger
  std::array<NormalRng, 2> rng_;
  std::array<FingerSample, 2> sample_;

  // Exact caches of run-time constants and of values recomputed with bit-identical inputs
  // (same inputs -> same bits as the direct computation; they only skip repeated work).
  double act_decay_ = 0.0;   // exp(-h / actuator.time_constant) (0 when there is no lag)
  double filt_alpha_ = 1.0;  // -expm1(-h / sensor.filter_time_constant) (1 when off)
  double trig_th_ = 0.0, trig_c_ = 1.0, trig_s_ = 0.0;  // cos, sin of the angle trig_th_
  bool trig_ok_ = false;
  double rho_fn_ = 0.0, rho_ = 0.0;  // rho(rho_fn_) of the contact model
  bool rho_ok_ = false;
  int cmd_phase_ = 0, sample_phase_ = 0;  // steps since the last command tick / sensor sample
  int64_t sample_index_ = 0;               // index of the next sensor sample
  CorOutput cor_out_;                      // scratch of the lumped plant's CoR estimate
  void trig(double th, double& c, double& s) noexcept;  // cos, sin (cached on the exact angle)
  double rho_at(double f_n) noexcept;                   // model_.rho (cached on the exact f_n)
  void disturbance_cs(double t, double c, double s, double& fx, double& fy, double& tau) const noexcept;

  void substep_patch(double h, double t0) noexcept;
  void substep_lumped(double h, double t0) noexcept;
  void take_sample() noexcept;
  void true_wrench(int finger, double out[4]) const noexcept;
  void update_drop() noexcept;
  void report_state() noexcept;  // fill st_ from the integration state at st_.t
};

}  // namespace lugrip
