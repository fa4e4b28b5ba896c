"""Example 04 (Python): a 500 Hz robot loop with lugrip.SlipControl.

Each cycle: read both fingertip wrenches as a (2, 4) array (f_n, f_x, f_y, tau per finger),
``SlipControl.step()``; every tenth cycle send ``out.force`` (the gripper takes one command per
20 ms): that cycle passes ``command="now"``, so the command is computed from the ten samples just
read, and the others ``command="hold"``. The robot is a stand-in (FakeGripper, the same as in
the C++ twin): the grasp force follows the command with a 30 ms lag, the can's weight and a
torsional load grow after 1 s, finger 1 loses contact for 0.2 s at 2.0 s (the command is held)
and the operator asks for pivoting at 3.0 s. Replace FakeGripper with your driver.

    python examples/04_robot_loop.py [PARAMS.yaml] [--realtime]

PARAMS.yaml: a parameter file (``lugrip identify`` output brings its observer block); default:
the aluminium-can preset. --realtime paces the loop at 500 Hz (time.sleep), otherwise it runs
in simulated time. The C++ twin is examples/04_robot_loop.cpp (links lugrip::core only).
"""

from __future__ import annotations

import math
import sys
import time

import numpy as np

import lugrip


class FakeGripper:
    """Stand-in for the gripper and its two fingertip sensors."""

    def __init__(self) -> None:
        self.force = 2.0  # actual grasp force [N]
        self.command = 2.0
        self.t = 0.0
        self._w = np.zeros((2, 4))

    def send(self, force: float) -> None:
        self.command = force

    def advance(self, dt: float) -> None:
        self.force += (self.command - self.force) * (1.0 - math.exp(-dt / 0.03))
        self.t += dt

    def read(self) -> np.ndarray:
        ramp = min(max(self.t - 1.0, 0.0), 1.0)
        self._w[:] = (self.force, 0.4 + 0.3 * ramp, 0.0, 1e-3 + 2e-3 * ramp)
        if 2.0 <= self.t < 2.2:
            self._w[1] = 0.0  # finger 1 lost contact
        return self._w


def main(params: str = "aluminium_can", realtime: bool = False) -> float:
    control = lugrip.SlipControl(params, f_min=0.2, f_max=15.0, max_rate=100.0)
    dt = control.settings.observer.dt
    gripper = FakeGripper()
    control.reset(gripper.force)  # start from the force the gripper holds now
    before_loss, lowest_in_loss, times = 0.0, math.inf, []
    next_tick = time.perf_counter()
    print(f"{'t [s]':>6} {'force [N]':>9} {'S_0':>6} {'S_1':>6} {'mode':<18} status")
    for k in range(2000):  # 4 s
        if k == 1500:
            control.request_pivoting()
        w = gripper.read()
        t0 = time.perf_counter()
        send = k % 10 == 9  # the gripper takes a command after every tenth sample
        out = control.step(w, command="now" if send else "hold")
        times.append(time.perf_counter() - t0)
        if send:
            gripper.send(out.force)
        if 1.99 <= gripper.t < 2.0:
            before_loss = out.force
        if 2.0 <= gripper.t < 2.2:
            lowest_in_loss = min(lowest_in_loss, out.force)
        if k % 250 == 0:
            f0, f1 = out.fingers
            print(f"{gripper.t:6.2f} {out.force:9.3f} {f0.S:6.3f} {f1.S:6.3f} "
                  f"{out.mode.name:<18} {out.status.name}")
        if out.pivot_finished:
            print(f"{gripper.t:6.2f} pivoting ended: {out.controller.pivot_end.name}")
        gripper.advance(dt)
        if realtime:
            next_tick += dt
            time.sleep(max(0.0, next_tick - time.perf_counter()))
    print(f"command before the contact loss {before_loss:.3f} N, lowest during it {lowest_in_loss:.3f} N")
    print(f"step: median {np.median(times) * 1e6:.1f} us, slowest {max(times) * 1e6:.1f} us "
          f"(budget {dt * 1e6:.0f} us; the slowest is the machine's scheduling, not the core)")
    return lowest_in_loss - before_loss


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if a != "--realtime"]
    margin = main(args[0] if args else "aluminium_can", realtime="--realtime" in sys.argv)
    sys.exit(0 if margin >= 0.0 else 1)
