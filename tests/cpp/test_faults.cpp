// Fault injection of the closed loop (sensor and actuator path) and SlipControl's frozen-sensor
// check: validation messages, the exact pattern of every fault on the logged readings, the
// statuses it raises, the command held while they are raised. The plant is the patch plant
// (distributed cells), not the observer's model; the checks are on the injection itself and
// on the status/command logic, plus a no-drop check for each fault.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "lugrip/closed_loop.hpp"
#include "lugrip/slip_control.hpp"

using namespace lugrip;

namespace {

ClosedLoopConfig hold_config() {
  ClosedLoopConfig c;
  c.plant.contact = object_params("big_resin_block");
  c.plant.contact.sigma_z = 3.3e-3;  // the simulated pad's own pre-sliding damping
  c.plant.model = PlantModel::Patch;
  c.plant.object.mass = 0.5;
  c.plant.object.inertia = 1e-3;
  c.plant.object.cog_y = -0.03;
  c.plant.actuator.f_init = 2.0;
  c.plant.support = true;
  c.plant.moves.push_back(GripperMove{0.2, 0.8, 0.0, 0.05});
  c.plant.seed = 3;
  return c;
}

std::vector<ClosedLoopSample> run(const ClosedLoopConfig& c, double seconds) {
  ClosedLoop loop(c);
  std::vector<ClosedLoopSample> out(static_cast<size_t>(std::lround(seconds / loop.sample_period())));
  for (auto& s : out) loop.step(s);
  return out;
}

FaultSpec fault(FaultKind kind, double t0, double duration, int finger = -1) {
  FaultSpec f;
  f.kind = kind;
  f.t_start = t0;
  f.duration = duration;
  f.finger = finger;
  return f;
}

constexpr int kOnset = 1000;  // sample of t = 2 s at 500 Hz

}  // namespace

TEST(Faults, ValidationNamesTheField) {
  ClosedLoopConfig c = hold_config();
  FaultSpec f = fault(FaultKind::Dropout, 1.0, 1.0);
  f.burst = 0;
  f.every = 0;
  c.faults.push_back(f);
  FaultSpec g = fault(FaultKind::Saturation, -1.0, 0.0, 2);
  g.force = -1.0;
  g.every = 3;
  c.faults.push_back(g);
  c.stuck_samples = -2;
  std::string msg;
  EXPECT_FALSE(validate(c, &msg));
  for (const char* s : {"faults[0].burst", "faults[1].finger", "faults[1].t_start", "faults[1].duration",
                        "faults[1].force", "stuck_samples"})
    EXPECT_NE(msg.find(s), std::string::npos) << s << "\n" << msg;
  EXPECT_EQ(msg.find("faults[1].every"), std::string::npos) << msg;  // 3 >= burst 1 is valid
  c.faults.assign(kMaxFaults + 1, fault(FaultKind::Spike, 0.0, 1.0));
  c.stuck_samples = 0;
  EXPECT_FALSE(validate(c, &msg));
  EXPECT_NE(msg.find("at most"), std::string::npos);
}

TEST(Faults, NanBurstPatternStatusesAndHeldCommand) {
  ClosedLoopConfig c = hold_config();
  FaultSpec f = fault(FaultKind::NanBurst, 2.0, 1.0, 0);
  f.burst = 12;  // > max_invalid = 10: the 10th invalid sample in a row is a SensorFault
  f.every = 100;
  c.faults.push_back(f);
  const auto log = run(c, 3.5);
  for (size_t k = 0; k < log.size(); ++k) {
    const long n = static_cast<long>(k) - kOnset;
    const bool on = n >= 0 && n < 500 && n % 100 < 12;
    EXPECT_EQ(std::isnan(log[k].f_n_meas[0]), on) << k;
    EXPECT_TRUE(std::isfinite(log[k].f_n_meas[1])) << k;  // the other finger is untouched
    EXPECT_EQ(log[k].fault_active, on) << k;
    EXPECT_TRUE(log[k].finite) << k;  // outputs stay finite; NaN readings are the fault
    if (on) {
      const int expected = (n % 100) < 9 ? static_cast<int>(Status::InvalidSample) : static_cast<int>(Status::SensorFault);
      EXPECT_EQ(log[k].observer_status[0], expected) << k;
      EXPECT_NE(log[k].status, 0) << k;
      EXPECT_GE(log[k].command, log[k - 1].command - 1e-12) << k;  // held (or raised), never lowered
    }
  }
  EXPECT_FALSE(log.back().dropped);
}

TEST(Faults, DropoutRepeatsAndStuckFreezesTheLastSample) {
  ClosedLoopConfig c = hold_config();
  FaultSpec d = fault(FaultKind::Dropout, 2.0, 0.2, 1);
  d.burst = 5;
  d.every = 20;
  c.faults.push_back(d);
  c.faults.push_back(fault(FaultKind::Stuck, 2.5, 0.1, 0));
  const auto log = run(c, 3.0);
  int repeated = 0;
  for (int k = kOnset; k < kOnset + 100; ++k) {
    if ((k - kOnset) % 20 < 5) {
      EXPECT_EQ(log[k].f_n_meas[1], log[k - 1].f_n_meas[1]) << k;
      EXPECT_EQ(log[k].tau_meas[1], log[k - 1].tau_meas[1]) << k;
      ++repeated;
    } else {
      EXPECT_NE(log[k].f_n_meas[1], log[k - 1].f_n_meas[1]) << k;  // noisy sensor: never repeats
    }
  }
  EXPECT_EQ(repeated, 25);
  const int k0 = 1250;
  for (int k = k0; k < k0 + 50; ++k) {
    EXPECT_EQ(log[k].f_n_meas[0], log[k0 - 1].f_n_meas[0]) << k;
    EXPECT_EQ(log[k].f_t_meas[0], log[k0 - 1].f_t_meas[0]) << k;
  }
  EXPECT_NE(log[k0 + 50].f_n_meas[0], log[k0 - 1].f_n_meas[0]);
}

TEST(Faults, StuckSensorFlaggedOnlyWithTheCheck) {
  ClosedLoopConfig c = hold_config();
  c.faults.push_back(fault(FaultKind::Stuck, 2.0, 0.5, 0));
  for (int stuck : {0, 25}) {
    c.stuck_samples = stuck;
    const auto log = run(c, 3.0);
    int first = -1;
    for (int k = kOnset; k < kOnset + 250; ++k)
      if (log[k].observer_status[0] == static_cast<int>(Status::SensorFault)) {
        first = k - kOnset;
        break;
      }
    if (stuck == 0) {
      EXPECT_EQ(first, -1);  // without the check a frozen sensor is never flagged
    } else {
      EXPECT_EQ(first, stuck - 1);  // the onset sample is the first exact repeat
      for (int k = kOnset + stuck; k < kOnset + 250; ++k) {
        EXPECT_EQ(log[k].observer_status[0], static_cast<int>(Status::SensorFault)) << k;
        EXPECT_GE(log[k].command, log[k - 1].command - 1e-12) << k;
      }
      // released: the sensor moves again, the check clears
      EXPECT_NE(log[kOnset + 260].observer_status[0], static_cast<int>(Status::SensorFault));
    }
    EXPECT_FALSE(log.back().dropped);
  }
}

TEST(Faults, SpikeBiasAndSaturationChangeTheReadingsExactly) {
  ClosedLoopConfig clean = hold_config();
  const auto ref = run(clean, 2.1);
  ClosedLoopConfig c = hold_config();
  FaultSpec s = fault(FaultKind::Spike, 2.0, 1.0, 0);
  s.torque = 0.01;
  c.faults.push_back(s);
  auto log = run(c, 2.1);
  // the loop is deterministic and the fault starts at the onset: before it both runs agree
  EXPECT_EQ(log[kOnset - 1].tau_meas[0], ref[kOnset - 1].tau_meas[0]);
  EXPECT_NEAR(log[kOnset].tau_meas[0] - ref[kOnset].tau_meas[0], 0.01, 1e-15);
  EXPECT_EQ(log[kOnset].tau_meas[1], ref[kOnset].tau_meas[1]);

  c.faults.assign(1, fault(FaultKind::BiasDrift, 2.0, 1.0, 1));
  c.faults[0].torque_rate = 0.5;
  log = run(c, 2.1);
  EXPECT_EQ(log[kOnset].tau_meas[1], ref[kOnset].tau_meas[1]);  // t_rel = 0 at the onset

  c.faults.assign(1, fault(FaultKind::Saturation, 1.0, 1.0));
  c.faults[0].force = 0.5;
  c.faults[0].torque = 1e-4;
  log = run(c, 2.1);
  for (int k = 500; k < 1000; ++k)
    for (int i = 0; i < 2; ++i) {
      EXPECT_LE(log[k].f_t_meas[i], 0.5 * std::sqrt(2.0) + 1e-12);
      EXPECT_LE(std::fabs(log[k].tau_meas[i]), 1e-4);
    }
}

TEST(Faults, DeadFingerAndContactLossReadNoContact) {
  ClosedLoopConfig c = hold_config();
  c.faults.push_back(fault(FaultKind::Dead, 2.0, 1e300, 1));
  c.faults.push_back(fault(FaultKind::ContactLoss, 2.4, 0.05, 0));
  const auto log = run(c, 3.0);
  for (int k = kOnset; k < 1500; ++k) {
    EXPECT_EQ(log[k].f_n_meas[1], 0.0);
    EXPECT_EQ(log[k].observer_status[1], static_cast<int>(Status::NoContact)) << k;
    EXPECT_GE(log[k].command, log[k - 1].command - 1e-12) << k;
  }
  for (int k = 1200; k < 1225; ++k) EXPECT_EQ(log[k].observer_status[0], static_cast<int>(Status::NoContact)) << k;
  EXPECT_EQ(log[1225].observer_status[0], static_cast<int>(Status::Reinitialized));  // re-contact
  EXPECT_FALSE(log.back().dropped);
}

TEST(Faults, ActuatorLagAndSaturation) {
  ClosedLoopConfig c = hold_config();
  FaultSpec lag = fault(FaultKind::ActuatorLag, 0.0, 1e300);
  lag.time_constant = 0.2;
  c.faults.push_back(lag);
  auto log = run(c, 1.5);
  const double a = std::exp(-0.002 / 0.2);
  for (size_t k = 1; k < log.size(); ++k)
    EXPECT_NEAR(log[k].actuator_command, a * log[k - 1].actuator_command + (1.0 - a) * log[k].command, 1e-12) << k;
  c.faults.assign(1, fault(FaultKind::ActuatorSaturation, 0.5, 1e300));
  c.faults[0].force = 1.5;
  log = run(c, 1.5);
  for (size_t k = 250; k < log.size(); ++k) EXPECT_EQ(log[k].actuator_command, std::min(log[k].command, 1.5)) << k;
  // the gripper's force comes down to the cap (rate limit and lag) and stays at or below it
  for (size_t k = 600; k < log.size(); ++k) EXPECT_LE(log[k].f_n, 1.5 + 1e-6) << k;
}

TEST(Faults, SlipControlStuckSamplesValidated) {
  SlipControlSettings s;
  s.stuck_samples = -1;
  std::string msg;
  EXPECT_FALSE(validate(s, &msg));
  EXPECT_NE(msg.find("stuck_samples"), std::string::npos);
}

TEST(Faults, HealthyFingerFallbackLetsTheOtherFingerCommand) {
  // Finger 1 dead from t = 2 s, then a downward push: without the fallback the command is
  // held, raised only by the reactions computed from finger 0's samples; with it finger 0's
  // estimate drives the whole law while finger 1 stays flagged. Plant: lugrip's own patch model.
  ClosedLoopConfig c = hold_config();
  c.plant.disturbances.push_back(Disturbance{2.5, 0.5, PulseShape::HalfSine, 0.0, -3.0, 0.0, 0.0, 0.0});
  c.faults.push_back(fault(FaultKind::Dead, 2.0, 1e300, 1));
  double peak[2] = {0.0, 0.0};
  for (int fallback = 0; fallback < 2; ++fallback) {
    c.healthy_finger_fallback = fallback == 1;
    const auto log = run(c, 3.5);
    for (int k = kOnset; k < static_cast<int>(log.size()); ++k) {
      EXPECT_EQ(log[k].observer_status[1], static_cast<int>(Status::NoContact)) << k;
      EXPECT_NE(log[k].status, static_cast<int>(Status::Ok)) << k;  // the fault stays reported
      peak[fallback] = std::max(peak[fallback], log[k].command);
    }
    if (fallback == 0)  // held: never lowered, raised only by the live finger's reactions
      for (int k = kOnset; k < static_cast<int>(log.size()); ++k)
        EXPECT_GE(log[k].command, log[k - 1].command - 1e-12) << k;
  }
  // Without the fallback only the raise-only reactions of the live finger's samples answer the
  // push (6.8 N here); with it the PI on that finger's S answers too (7.7 N).
  EXPECT_GT(peak[1], peak[0] + 0.5);
}
