"""Reaction to a pulse faster than one command period, on an independent plant (MuJoCo's contact
solver, the gripper's 30 ms lag and 200 N/s rate limit in the loop): the 30 g cup of
scenarios/unseen/cup_light.yaml lifted at 1-3 s, then its 0.3 N downward pulse (twice the cup's
weight, 20 ms edges) at 3.5 s instead of 6.5 s. Not a consistency test: neither the plant nor the
gripper is lugrip's model."""

import dataclasses

import numpy as np
import pytest

import lugrip

def _cup_down_pulse(over):
    pytest.importorskip("mujoco")
    from lugrip.sim import scenarios as sc
    from lugrip.sim.mujoco.loop import run_mujoco_loop

    scn = sc.load_scenario(sc.scenario_dir() / "unseen" / "cup_light.yaml")
    cfg = scn.plant_config("mujoco")
    pulse = [dataclasses.replace(d, t_start=d.t_start - 3.0) for d in cfg.disturbances
             if 6.5 <= d.t_start < 6.75]
    assert pulse and min(d.force[1] for d in pulse) == pytest.approx(-0.3)
    cfg = dataclasses.replace(cfg, disturbances=pulse, moves=[m for m in cfg.moves if m.t_start < 3.0])
    # without the scene's standing reserve: these tests are about the reaction alone
    ctrl = {**scn.controller, "reserve_force": 0.0, "reserve_torque": 0.0, **over}
    run = run_mujoco_loop(cfg, scn.scene_spec(), ctrl, scn.observer, None,
                          4.0, estimator=scn.estimator_for("mujoco"))
    lift = run["t"] >= 1.0
    slip = np.hypot(run["slip_x"] - run["slip_x"][lift][0], run["slip_y"] - run["slip_y"][lift][0])
    return run, float(np.max(slip[lift]))


def test_cup_holds_a_pulse_twice_its_weight():
    """Defaults: the command rises at the command after the edge (the trend feed-forward); the
    cup stays in the grasp (it slides ~1 mm on the standing reserve of S_ref = 0.8 before the
    force arrives); 0.3 s after the pulse the PI (k_i s_ref / gain_force = 2/s) has drained the
    command below 60 % of its peak."""
    run, slip = _cup_down_pulse({})
    assert run.scene["status"] == "ok"
    assert slip < 1.5e-3
    t, cmd = run["t"], run["command"]
    before = float(np.mean(cmd[(t > 3.2) & (t < 3.5)]))
    peak = float(np.max(cmd[(t > 3.5) & (t < 3.56)]))
    assert peak > 1.5 * before  # within the edge + 2 commands
    assert float(np.mean(cmd[(t > 4.0 - 0.1)])) < 0.6 * peak
