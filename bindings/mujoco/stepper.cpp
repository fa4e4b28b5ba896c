// lugrip._mjstep: the MuJoCo gripper's physics steps of a run of sensor samples in one call.
//
// Per physics step (what lugrip.sim.mujoco.plant did in Python before): the hand's minimum-jerk
// moves and wrist rolls into the position actuators, the disturbance pulses onto the object
// (rotated with its angle before the step), the gripper's first-order lag and rate limit toward
// the held command, each pad's torsional coefficient mu xi delta max(f_n, floor)^gamma from its
// normal force of the step before and its explicit spring damping, mj_step, and each pad's
// wrench (the object on the pad, pad frame) accumulated over the sensor sample. Per sensor
// sample: the averages, each pad's slip velocity and the state the ground truth is made of.
//
// Built against the headers of the mujoco wheel present at build time and linked to its
// libmujoco (found at run time beside this module in site-packages); Python passes the
// addresses of its MjModel/MjData (their _address), which it keeps alive.
#include <mujoco/mujoco.h>
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/array.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <algorithm>
#include <ctime>
#include <array>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace nb = nanobind;
using namespace nb::literals;

namespace {

//! Everything the loop needs about the scene, filled from Python (lugrip.sim.mujoco.plant).
struct StepperConfig {
  int ratio = 2;  //!< physics steps per sensor sample
  // qpos addresses
  int q_theta = 0, q_roll = 0, q_hz = 0;
  std::array<int, 2> q_finger{}, q_px{}, q_py{}, q_pt{};
  // bodies and geoms
  int body_object = 0;
  std::array<int, 2> body_pad{}, geom_pad{};
  std::vector<int> pairs0, pairs1;        //!< contact pairs of each pad
  std::vector<int> dofs0, dofs1;          //!< the pad's three spring dofs
  std::vector<double> damp0, damp1;       //!< their explicit damping [N s/m, N m s/rad]
  // the pads' torsional law (one set, both pads alike)
  double mu = 0.7, xi = 0.6, delta = 1.8e-3, gamma = 0.25, f_n_floor = 0.05;
  // actuator
  double decay = 0.0;     //!< exp(-h / time constant)
  double step_max = 1e9;  //!< rate limit times h [N]
  double f_cap = 1e9;     //!< min(actuator f_max, motor range) [N]
  // hand moves (gripper X -> world y, Y -> world z) and wrist rolls [s, s, m, m] / [s, s, rad]
  std::vector<double> move_t0, move_T, move_dx, move_dy;
  std::vector<double> wrist_t0, wrist_T, wrist_roll;
  // disturbances: start, duration [s], shape (0 rect, 1 half sine, 2 ramp, 3 triangle),
  // point in the object frame [m], world force [N], torque [N m]
  std::vector<double> dist_t0, dist_T, dist_px, dist_py, dist_fx, dist_fy, dist_tau;
  std::vector<int> dist_shape;
  std::array<double, 2> cog{};  //!< object CoG relative to the grasp point, object frame [m]
};

//! Columns of one sensor sample in the output matrix (the end of the sample unless said).
enum Col : int {
  kW0 = 0,          // pad 0: f_n, f_x, f_y, tau averaged over the sample's steps
  kW1 = 4,          // pad 1: the same
  kFAct = 8,        // actuator force [N]
  kContact0 = 9, kContact1 = 10,  // pad in contact: touched in the sample, mean f_n > 1e-4 N
  kOmega0 = 11, kOmega1 = 12,     // the object's spin relative to the pad about its z (0: no contact)
  kVSlip0 = 13, kVSlip1 = 14,     // its in-plane slip speed at the pad origin (0: no contact)
  kTheta = 15, kRoll = 16, kHz = 17,
  kRelX = 18, kRelY = 19,  // grasp point relative to the pads' midpoint, hand frame [m]
  kRot = 20,               // object angle relative to the hand and the pads' mean twist [rad]
  kCogX = 21, kCogY = 22,  // CoG relative to the pads' midpoint, world (y, z) [m]
  kTwist0 = 23, kTwist1 = 24,  // the pads' twist about world x [rad]
  kDefl0 = 25, kDefl1 = 26,    // the pads' in-plane deflection [m]
  kFinger0 = 27, kFinger1 = 28,  // finger slide positions [m]
  kExtFx = 29, kExtFy = 30, kExtTau = 31,  // the disturbance of the sample's last step
  kNumCols = 32,
};

//! CPU time of the calling thread [ns] (what mj_step costs on its core, whatever the load).
int64_t thread_cpu_ns() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

double min_jerk(double t, double t0, double T) {
  double u = T > 0.0 ? std::min(std::max((t - t0) / T, 0.0), 1.0) : (t >= t0 ? 1.0 : 0.0);
  return u * u * u * (10.0 - 15.0 * u + 6.0 * u * u);
}

double pulse(int shape, double u) {
  switch (shape) {
    case 0: return 1.0;
    case 1: return std::sin(M_PI * u);
    case 2: return u;
    default: return 1.0 - std::abs(2.0 * u - 1.0);
  }
}

class Stepper {
 public:
  Stepper(std::uintptr_t model, std::uintptr_t data, const StepperConfig& cfg, double f_act)
      : m_(reinterpret_cast<const mjModel*>(model)), d_(reinterpret_cast<mjData*>(data)),
        c_(cfg), f_act_(f_act) {
    mjModel* mm = const_cast<mjModel*>(m_);
    model_mut_ = mm;
    if (c_.ratio < 1) throw std::invalid_argument("ratio must be >= 1");
    if (c_.dofs0.size() != 3 || c_.dofs1.size() != 3 || c_.damp0.size() != 3 || c_.damp1.size() != 3)
      throw std::invalid_argument("each pad needs three dofs and three damping values");
    const size_t nd = c_.dist_t0.size();
    for (auto* v : {&c_.dist_T, &c_.dist_px, &c_.dist_py, &c_.dist_fx, &c_.dist_fy, &c_.dist_tau})
      if (v->size() != nd) throw std::invalid_argument("disturbance arrays of unequal length");
    if (c_.dist_shape.size() != nd) throw std::invalid_argument("disturbance shapes: wrong length");
    if (c_.move_T.size() != c_.move_t0.size() || c_.move_dx.size() != c_.move_t0.size() ||
        c_.move_dy.size() != c_.move_t0.size() || c_.wrist_T.size() != c_.wrist_t0.size() ||
        c_.wrist_roll.size() != c_.wrist_t0.size())
      throw std::invalid_argument("move arrays of unequal length");
    jacp_.resize(3 * static_cast<size_t>(m_->nv));
    jacr_.resize(3 * static_cast<size_t>(m_->nv));
  }

  //! Simulate commands.size() sensor samples; fills out (n, kNumCols).
  void run(nb::ndarray<const double, nb::ndim<1>, nb::c_contig> commands,
           nb::ndarray<double, nb::ndim<2>, nb::c_contig> out) {
    const size_t n = commands.shape(0);
    if (out.shape(0) != n || out.shape(1) != kNumCols)
      throw std::invalid_argument("out: expected shape (len(commands), " + std::to_string(kNumCols) + ")");
    const double* cmd = commands.data();
    double* o = out.data();
    nb::gil_scoped_release release;
    for (size_t i = 0; i < n; ++i) sample(cmd[i], o + i * kNumCols);
  }

  double f_act() const { return f_act_; }
  int64_t steps() const { return n_; }
  double mj_step_seconds() const { return 1e-9 * static_cast<double>(mj_step_ns_); }

 private:
  void sample(double command, double* row) {
    const double h = m_->opt.timestep;
    double acc[2][4] = {{0, 0, 0, 0}, {0, 0, 0, 0}};
    int touched[2] = {0, 0};
    double fx = 0.0, fy = 0.0, tz = 0.0;
    for (int s = 0; s < c_.ratio; ++s) {
      const double t = static_cast<double>(n_) * h;
      double y = 0.0, z = 0.0, roll = 0.0;
      for (size_t k = 0; k < c_.move_t0.size(); ++k) {
        const double a = min_jerk(t, c_.move_t0[k], c_.move_T[k]);
        y += c_.move_dx[k] * a;
        z += c_.move_dy[k] * a;
      }
      for (size_t k = 0; k < c_.wrist_t0.size(); ++k)
        roll += c_.wrist_roll[k] * min_jerk(t, c_.wrist_t0[k], c_.wrist_T[k]);
      d_->ctrl[2] = y;
      d_->ctrl[3] = z;
      d_->ctrl[4] = roll;
      disturbance(t, d_->qpos[c_.q_theta], fx, fy, tz);
      mjtNum* xf = d_->xfrc_applied + 6 * c_.body_object;
      xf[0] = 0.0; xf[1] = fx; xf[2] = fy; xf[3] = tz; xf[4] = 0.0; xf[5] = 0.0;
      const double target = command + (f_act_ - command) * c_.decay;
      f_act_ = std::min(std::max(target, f_act_ - c_.step_max), f_act_ + c_.step_max);
      f_act_ = std::min(std::max(f_act_, 0.0), c_.f_cap);
      d_->ctrl[0] = d_->ctrl[1] = f_act_;
      for (int k = 0; k < 2; ++k) update_pad(k);
      const int64_t t0 = thread_cpu_ns();
      mj_step(m_, d_);
      mj_step_ns_ += thread_cpu_ns() - t0;
      ++n_;
      for (int k = 0; k < 2; ++k) {
        double w[4];
        wrench(k, w);
        for (int j = 0; j < 4; ++j) acc[k][j] += w[j];
        touched[k] += w[0] > 0.0 ? 1 : 0;
        last_fn_[k] = std::max(w[0], 0.0);
      }
    }
    const mjtNum* q = d_->qpos;
    for (int k = 0; k < 2; ++k) {
      double* w = row + (k == 0 ? kW0 : kW1);
      for (int j = 0; j < 4; ++j) w[j] = acc[k][j] / c_.ratio;
      const bool in_contact = touched[k] > 0 && w[0] > 1e-4;
      row[kContact0 + k] = in_contact ? 1.0 : 0.0;
      double v[3];
      slip_velocity(k, v);
      row[kOmega0 + k] = in_contact ? v[2] : 0.0;
      row[kVSlip0 + k] = in_contact ? std::hypot(v[0], v[1]) : 0.0;
      row[kTwist0 + k] = (k == 0 ? -1.0 : 1.0) * q[c_.q_pt[k]];
      row[kDefl0 + k] = std::hypot(q[c_.q_px[k]], q[c_.q_py[k]]);
      row[kFinger0 + k] = q[c_.q_finger[k]];
    }
    row[kFAct] = f_act_;
    const double theta = q[c_.q_theta], roll = q[c_.q_roll];
    row[kTheta] = theta;
    row[kRoll] = roll;
    row[kHz] = q[c_.q_hz];
    const mjtNum* p0 = d_->xpos + 3 * c_.body_pad[0];
    const mjtNum* p1 = d_->xpos + 3 * c_.body_pad[1];
    const mjtNum* g = d_->xpos + 3 * c_.body_object;  // the object frame's origin: the grasp point
    const double ry = g[1] - 0.5 * (p0[1] + p1[1]), rz = g[2] - 0.5 * (p0[2] + p1[2]);
    const double cr = std::cos(roll), sr = std::sin(roll);
    row[kRelX] = cr * ry + sr * rz;
    row[kRelY] = -sr * ry + cr * rz;
    row[kRot] = theta - roll - 0.5 * (row[kTwist0] + row[kTwist1]);
    const double ct = std::cos(theta), st = std::sin(theta);
    row[kCogX] = ct * c_.cog[0] - st * c_.cog[1] + ry;
    row[kCogY] = st * c_.cog[0] + ct * c_.cog[1] + rz;
    row[kExtFx] = fx;
    row[kExtFy] = fy;
    row[kExtTau] = tz;
  }

  void disturbance(double t, double theta, double& fx, double& fy, double& tau) const {
    fx = fy = tau = 0.0;
    const double c = std::cos(theta), s = std::sin(theta);
    for (size_t k = 0; k < c_.dist_t0.size(); ++k) {
      const double u = (t - c_.dist_t0[k]) / c_.dist_T[k];
      if (!(u >= 0.0 && u < 1.0)) continue;
      const double a = pulse(c_.dist_shape[k], u);
      const double px = c * c_.dist_px[k] - s * c_.dist_py[k];
      const double py = s * c_.dist_px[k] + c * c_.dist_py[k];
      const double qx = a * c_.dist_fx[k], qy = a * c_.dist_fy[k];
      fx += qx;
      fy += qy;
      tau += a * c_.dist_tau[k] + px * qy - py * qx;
    }
  }

  void update_pad(int k) {
    const double spin =
        c_.mu * c_.xi * c_.delta * std::pow(std::max(last_fn_[k], c_.f_n_floor), c_.gamma);
    if (spin != spin_set_[k]) {
      for (int p : (k == 0 ? c_.pairs0 : c_.pairs1)) model_mut_->pair_friction[5 * p + 2] = spin;
      spin_set_[k] = spin;
    }
    const auto& dofs = k == 0 ? c_.dofs0 : c_.dofs1;
    const auto& damp = k == 0 ? c_.damp0 : c_.damp1;
    for (int j = 0; j < 3; ++j) d_->qfrc_applied[dofs[j]] = -damp[j] * d_->qvel[dofs[j]];
  }

  bool involves(int i, int k) const {
    const int g = c_.geom_pad[k];
    return d_->contact[i].geom[0] == g || d_->contact[i].geom[1] == g;
  }

  // (f_n, f_x, f_y, tau) the object exerts on pad k in the pad frame; moment about the centre
  // of pressure of the pad's contacts (one contact: its point). Zero without contact.
  void wrench(int k, double w[4]) {
    w[0] = w[1] = w[2] = w[3] = 0.0;
    const mjtNum* R = d_->xmat + 9 * c_.body_pad[k];  // row-major; columns are the pad axes
    int count = 0;
    double force[3] = {0, 0, 0}, moment[3] = {0, 0, 0};
    cf_.clear();
    for (int i = 0; i < d_->ncon; ++i) {
      if (!involves(i, k)) continue;
      ++count;
      mjtNum f6[6];
      mj_contactForce(m_, d_, i, f6);
      const mjContact& con = d_->contact[i];
      const double sign = con.geom[0] == c_.geom_pad[k] ? -1.0 : 1.0;
      std::array<double, 6> fp{};  // force (world) then point
      for (int a = 0; a < 3; ++a) {
        fp[a] = sign * (f6[0] * con.frame[a] + f6[1] * con.frame[3 + a] + f6[2] * con.frame[6 + a]);
        moment[a] += sign * f6[3] * con.frame[a];
        force[a] += fp[a];
        fp[3 + a] = con.pos[a];
      }
      cf_.push_back(fp);
    }
    if (count == 0) return;
    if (count > 1) {
      double wsum = 0.0, cop[3] = {0, 0, 0};
      std::vector<double> weights(cf_.size());
      for (size_t j = 0; j < cf_.size(); ++j) {
        const double wn = cf_[j][0] * R[2] + cf_[j][1] * R[5] + cf_[j][2] * R[8];
        weights[j] = std::max(wn, 0.0);
        wsum += weights[j];
      }
      for (size_t j = 0; j < cf_.size(); ++j)
        for (int a = 0; a < 3; ++a)
          cop[a] += (wsum > 0 ? weights[j] / wsum : 1.0 / static_cast<double>(cf_.size())) * cf_[j][3 + a];
      for (const auto& fp : cf_) {
        const double r[3] = {fp[3] - cop[0], fp[4] - cop[1], fp[5] - cop[2]};
        moment[0] += r[1] * fp[2] - r[2] * fp[1];
        moment[1] += r[2] * fp[0] - r[0] * fp[2];
        moment[2] += r[0] * fp[1] - r[1] * fp[0];
      }
    }
    // pad-frame components: force @ R (R's columns are the pad axes)
    double local[3];
    for (int b = 0; b < 3; ++b) local[b] = force[0] * R[b] + force[1] * R[3 + b] + force[2] * R[6 + b];
    w[0] = local[2] + 0.0;
    w[1] = local[0] + 0.0;
    w[2] = local[1] + 0.0;
    w[3] = moment[0] * R[2] + moment[1] * R[5] + moment[2] * R[8] + 0.0;
  }

  // (v_x, v_y, omega) of the object relative to pad k at the pad frame's origin, pad frame;
  // zeros without contact. The present qvel through the Jacobians of the step's forward pass.
  void slip_velocity(int k, double* v) {
    v[0] = v[1] = v[2] = 0.0;
    int first = -1;
    for (int i = 0; i < d_->ncon && first < 0; ++i)
      if (involves(i, k)) first = i;
    if (first < 0) return;
    const mjContact& con = d_->contact[first];
    const int other = con.geom[0] == c_.geom_pad[k] ? con.geom[1] : con.geom[0];
    const int other_body = m_->geom_bodyid[other];
    const int pad = c_.body_pad[k];
    const mjtNum* o = d_->xpos + 3 * pad;
    const mjtNum* R = d_->xmat + 9 * pad;
    const int nv = m_->nv;
    double rel_v[3] = {0, 0, 0}, w[3] = {0, 0, 0};
    auto accumulate = [&](int body, double sign) {
      mj_jac(m_, d_, jacp_.data(), jacr_.data(), o, body);
      for (int a = 0; a < 3; ++a) {
        double sp = 0.0, sr = 0.0;
        for (int j = 0; j < nv; ++j) {
          sp += jacp_[a * nv + j] * d_->qvel[j];
          sr += jacr_[a * nv + j] * d_->qvel[j];
        }
        rel_v[a] += sign * sp;
        w[a] += sign * sr;
      }
    };
    accumulate(pad, -1.0);
    if (other_body != 0) accumulate(other_body, 1.0);
    for (int b = 0; b < 2; ++b) v[b] = rel_v[0] * R[b] + rel_v[1] * R[3 + b] + rel_v[2] * R[6 + b];
    v[2] = R[2] * w[0] + R[5] * w[1] + R[8] * w[2];
  }

  const mjModel* m_;
  mjModel* model_mut_;
  mjData* d_;
  StepperConfig c_;
  double f_act_;
  std::array<double, 2> last_fn_{0.0, 0.0};
  std::array<double, 2> spin_set_{NAN, NAN};
  int64_t n_ = 0;
  int64_t mj_step_ns_ = 0;  //!< CPU time inside mj_step [ns] (for the benchmark)
  std::vector<mjtNum> jacp_, jacr_;
  std::vector<std::array<double, 6>> cf_;
};

}  // namespace

NB_MODULE(_mjstep, m) {
  m.doc() = "lugrip's MuJoCo gripper stepped in C++: a run of sensor samples per call";
  m.attr("MUJOCO_VERSION") = mjVERSION_HEADER;
  m.attr("COLUMNS") = static_cast<int>(kNumCols);
  m.def("mujoco_version", [] { return mj_version(); }, "The linked libmujoco's mj_version().");

  nb::class_<StepperConfig>(m, "StepperConfig")
      .def(nb::init<>())
#define LUGRIP_RW(name) .def_rw(#name, &StepperConfig::name)
      LUGRIP_RW(ratio) LUGRIP_RW(q_theta) LUGRIP_RW(q_roll) LUGRIP_RW(q_hz) LUGRIP_RW(q_finger)
      LUGRIP_RW(q_px) LUGRIP_RW(q_py) LUGRIP_RW(q_pt) LUGRIP_RW(body_object) LUGRIP_RW(body_pad)
      LUGRIP_RW(geom_pad) LUGRIP_RW(pairs0) LUGRIP_RW(pairs1) LUGRIP_RW(dofs0) LUGRIP_RW(dofs1)
      LUGRIP_RW(damp0) LUGRIP_RW(damp1) LUGRIP_RW(mu) LUGRIP_RW(xi) LUGRIP_RW(delta)
      LUGRIP_RW(gamma) LUGRIP_RW(f_n_floor) LUGRIP_RW(decay) LUGRIP_RW(step_max) LUGRIP_RW(f_cap)
      LUGRIP_RW(move_t0) LUGRIP_RW(move_T) LUGRIP_RW(move_dx) LUGRIP_RW(move_dy)
      LUGRIP_RW(wrist_t0) LUGRIP_RW(wrist_T) LUGRIP_RW(wrist_roll) LUGRIP_RW(dist_t0)
      LUGRIP_RW(dist_T) LUGRIP_RW(dist_px) LUGRIP_RW(dist_py) LUGRIP_RW(dist_fx)
      LUGRIP_RW(dist_fy) LUGRIP_RW(dist_tau) LUGRIP_RW(dist_shape) LUGRIP_RW(cog);
#undef LUGRIP_RW

  nb::class_<Stepper>(m, "Stepper")
      .def(nb::init<std::uintptr_t, std::uintptr_t, const StepperConfig&, double>(), "model"_a,
           "data"_a, "config"_a, "f_act"_a,
           "The stepper of the MjModel/MjData at these addresses (the caller keeps them alive).")
      .def("run", &Stepper::run, "commands"_a, "out"_a,
           "Simulate len(commands) sensor samples, commands[i] [N] held at the actuator input "
           "during sample i; fills out (n, COLUMNS).")
      .def_prop_ro("f_act", &Stepper::f_act)
      .def_prop_ro("steps", &Stepper::steps, "Physics steps taken.")
      .def_prop_ro("mj_step_seconds", &Stepper::mj_step_seconds,
                   "CPU time of this thread spent inside mj_step [s] (CLOCK_THREAD_CPUTIME_ID "
                   "around each call).");
}
