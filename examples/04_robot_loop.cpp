// Example 04 (C++): a 500 Hz robot loop with SlipControl, linking lugrip::core only.
//
// Each cycle: read both fingertip wrenches, SlipControl::step(); every tenth cycle send the
// command (the gripper takes one per 20 ms): that cycle asks for it (CommandTiming::Now), so it
// is computed from the ten samples just read, the others pass Hold. The robot
// here is a stand-in (FakeGripper): a gripper whose force follows the command with a 30 ms lag,
// holding a can whose weight and a torsional load grow after 1 s; at 2.0 s finger 1 loses
// contact for 0.2 s (the command is held), at 3.0 s the operator asks for pivoting. Replace
// FakeGripper with your driver; nothing else changes.
//
//   example_04_robot_loop            simulated time (as fast as it runs)
//   example_04_robot_loop --realtime paced at 500 Hz with sleep_until
//
// Build against an installed lugrip (find_package(lugrip), target lugrip::core), or in-tree
// with -DLUGRIP_BUILD_EXAMPLES=ON. Parameters from an identified YAML: link lugrip::yaml and
// use load_parameter_file() / slip_control_settings() (include/lugrip/param_file.hpp).
// The Python twin is examples/04_robot_loop.py.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <thread>

#include "lugrip/lugrip.hpp"

namespace {

// Stand-in for the gripper and its two fingertip sensors.
struct FakeGripper {
  double force = 2.0;    // actual grasp force [N]
  double command = 2.0;  // last command received [N]
  double t = 0.0;        // [s]
  void send(double f) { command = f; }
  void advance(double dt) {
    force += (command - force) * (1.0 - std::exp(-dt / 0.03));
    t += dt;
  }
  // Wrench on each fingertip (sensor frame): half the can's weight along f_x, a torque.
  lugrip::SlipControlInput read() const {
    const double weight = t < 1.0 ? 0.4 : 0.4 + 0.3 * std::min(t - 1.0, 1.0);  // [N] per finger
    const double torque = t < 1.0 ? 1e-3 : 1e-3 + 2e-3 * std::min(t - 1.0, 1.0);  // [N m]
    lugrip::SlipControlInput in;
    for (int i = 0; i < 2; ++i) in.fingers[i] = lugrip::FingerWrench{force, weight, 0.0, torque};
    if (t >= 2.0 && t < 2.2) in.fingers[1] = lugrip::FingerWrench{0.0, 0.0, 0.0, 0.0};  // contact lost
    return in;
  }
};

}  // namespace

int main(int argc, char** argv) {
  using clock = std::chrono::steady_clock;
  const bool realtime = argc > 1 && std::strcmp(argv[1], "--realtime") == 0;

  lugrip::SlipControlSettings settings;     // observer at 500 Hz, controller defaults
  settings.controller.f_min = 0.2;          // [N] never less than this
  settings.controller.f_max = 15.0;         // [N] gripper limit
  settings.controller.max_rate = 100.0;  // [N/s] the gripper's slew rate
  // Construction validates everything (rates included) and builds the contact tables: do it
  // before the loop. step() then never allocates, throws or blocks.
  lugrip::SlipControl control(lugrip::object_params("aluminium_can"), settings);
  const double dt = settings.observer.dt;

  FakeGripper gripper;
  control.reset(gripper.force);  // start from the force the gripper holds now
  lugrip::SlipControlOutput out;  // caller-owned, reused
  double worst_us = 0.0, total_us = 0.0, min_during_loss = 1e9, before_loss = 0.0;
  int not_ok = 0;
  const int cycles = 2000;  // 4 s
  auto next = clock::now();
  std::printf("%6s %9s %6s %6s %-18s %s\n", "t [s]", "force [N]", "S_0", "S_1", "mode", "status");
  for (int k = 0; k < cycles; ++k) {
    if (k == 1500) control.request_pivoting();  // operator: pivot the can
    lugrip::SlipControlInput in = gripper.read();
    // The gripper takes a command after every tenth sample: compute it from the newest one.
    const bool send = k % 10 == 9;
    in.command = send ? lugrip::CommandTiming::Now : lugrip::CommandTiming::Hold;
    const auto t0 = clock::now();
    const lugrip::Status status = control.step(in, out);
    const double us = std::chrono::duration<double, std::micro>(clock::now() - t0).count();
    worst_us = std::max(worst_us, us);
    total_us += us;
    if (send) gripper.send(out.force);
    if (status != lugrip::Status::Ok) ++not_ok;
    if (gripper.t >= 1.99 && gripper.t < 2.0) before_loss = out.force;
    if (gripper.t >= 2.0 && gripper.t < 2.2) min_during_loss = std::min(min_during_loss, out.force);
    if (k % 250 == 0)
      std::printf("%6.2f %9.3f %6.3f %6.3f %-18s %s\n", gripper.t, out.force, out.fingers[0].S, out.fingers[1].S,
                  lugrip::to_string(out.controller.mode), lugrip::to_string(out.status));
    if (out.controller.pivot_finished)
      std::printf("%6.2f pivoting ended: %s\n", gripper.t, lugrip::to_string(out.controller.pivot_end));
    gripper.advance(dt);
    if (realtime) {
      next += std::chrono::microseconds(2000);
      std::this_thread::sleep_until(next);
    }
  }
  std::printf("cycles %d, not ok %d, command before the contact loss %.3f N, lowest during it %.3f N\n", cycles,
              not_ok, before_loss, min_during_loss);
  std::printf("step: mean %.2f us, slowest %.1f us (budget 2000 us; the slowest is the machine's scheduling)\n",
              total_us / cycles, worst_us);
  return min_during_loss >= before_loss ? 0 : 1;
}
