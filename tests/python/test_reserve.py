"""Standing reserve for the task's pulses (GraspController ``reserve_force`` /
``reserve_torque``, stated as numbers by the scenes, and the rule
``lugrip.sim.scenarios.disturbance_reserve`` that computes them from an expected pulse list).

The rule is checked against the same numbers written out by hand for the 0.45 kg box. The
closed loop runs on an independent plant: MuJoCo's contact solver with the gripper's 30 ms lag
and 200 N/s rate limit (scenarios/unseen/box_heavy.yaml), not lugrip's model.
"""

import math

import numpy as np
import pytest

from lugrip.sim import scenarios as sc


def test_reserve_rule_for_the_box_by_hand():
    """Box: 0.45 kg, I = 6.15e-4 kg m^2, CoG 10 mm below the grasp point; pulses 3 N down, 2 N
    sideways (at the CoG: 20 N mm about the grasp point), 5 N up, +-20 N mm. The largest rise of
    |load| is the 3 N push (the up push lowers it, the sideways one adds
    sqrt(4.41^2 + 2^2) - 4.41 = 0.43 N); of |torque| 20 N mm (the weight has no arm). Without a
    rate limit the reaction time is 20 ms + 30 ms; allowances 2 m x / t^2 = 0.36 N and
    2 (I + m d^2) theta / t^2 = 9.2 N mm."""
    scn = sc.load_scenario(sc.scenario_dir() / "unseen" / "box_heavy.yaml")
    crit = scn.criteria_by_plant["mujoco"]
    r = sc.disturbance_reserve(scn.plant, crit, 0.02)
    t = 0.02 + 0.03
    allow_f = 2 * 0.45 * 1e-3 / t**2
    allow_t = 2 * (6.15e-4 + 0.45 * 0.01**2) * math.radians(1.0) / t**2
    assert r["reaction_time"] == pytest.approx(t)
    assert r["largest_force_rise"] == pytest.approx(3.0)
    assert r["largest_torque_rise"] == pytest.approx(0.020)
    assert r["allowance_force"] == pytest.approx(allow_f)
    assert r["allowance_torque"] == pytest.approx(allow_t)
    assert r["reserve_force"] == pytest.approx((3.0 - allow_f) / 2)  # 1.32 N
    assert r["reserve_torque"] == pytest.approx((0.020 - allow_t) / 2)  # 5.4 N mm


def test_reserve_rule_with_the_rate_limit_is_its_own_fixed_point():
    """With the scene's identified contact and 200 N/s the reaction time adds the ramp from the
    reserve's force to the force the whole pulse needs; the solved t_r reproduces itself
    (consistency with lugrip's static grasp force), and the reserve only grows. The box scene
    states this envelope as numbers (rounded to 3 digits); its loader derives nothing."""
    import lugrip
    from lugrip.sim._closed_loop import estimator_params

    scn = sc.load_scenario(sc.scenario_dir() / "unseen" / "box_heavy.yaml")
    contact = estimator_params(scn.plant_config().contact, scn.estimator_for("mujoco"))
    r = sc.disturbance_reserve(scn.plant, scn.criteria_by_plant["mujoco"], 0.02,
                               contact=contact, rate_up=200.0)
    assert scn.controller["reserve_force"] == pytest.approx(r["reserve_force"], rel=5e-3)
    assert scn.controller["reserve_torque"] == pytest.approx(r["reserve_torque"], rel=5e-3)
    load_f, load_t = 0.5 * 0.45 * 9.81, 0.0
    full = max(lugrip.static_grasp_force(contact, load_f + 1.5, load_t, 1.0)
               - lugrip.static_grasp_force(contact, load_f + r["reserve_force"], load_t, 1.0),
               lugrip.static_grasp_force(contact, load_f, load_t + 0.010, 1.0)
               - lugrip.static_grasp_force(contact, load_f, load_t + r["reserve_torque"], 1.0))
    assert r["reaction_time"] == pytest.approx(0.05 + full / 200.0, rel=1e-6)
    assert r["ramp_time"] > 0.0
    bare = sc.disturbance_reserve(scn.plant, scn.criteria_by_plant["mujoco"], 0.02)
    assert r["reserve_force"] > bare["reserve_force"] and r["reserve_torque"] > bare["reserve_torque"]


def test_a_scene_may_not_derive_its_reserve_from_its_own_pulses(tmp_path):
    src = (sc.scenario_dir() / "unseen" / "box_heavy.yaml").read_text()
    bad = tmp_path / "bad.yaml"
    bad.write_text(src.replace("reserve_force: 1.38, reserve_torque: 0.00682",
                               "reserve: disturbances"))
    assert bad.read_text() != src
    with pytest.raises(ValueError, match="state the task's envelope as numbers"):
        sc.load_scenario(bad)


def test_rule_gives_no_reserve_for_pulses_within_the_allowance():
    """A 0.1 N push on the box moves it less than the budget before the reaction: no reserve."""
    plant = {"object": {"mass": 0.45, "inertia": 6.15e-4, "cog": [0.0, -0.01]},
             "actuator": {"time_constant": 0.03},
             "disturbances": [{"force": [0.0, -0.1]}, {"torque": 0.002}]}
    r = sc.disturbance_reserve(plant, {"max_hold_slip_mm": 1.0, "max_hold_rotation_deg": 1.0})
    assert r["reserve_force"] == 0.0 and r["reserve_torque"] == 0.0


def _box_hold(over):
    pytest.importorskip("mujoco")
    scn = sc.load_scenario(sc.scenario_dir() / "unseen" / "box_heavy.yaml")
    scn.controller.update(over)
    cfg = scn.plant_config()
    run = sc.simulate(scn, cfg, "mujoco", scn.schedule)
    return sc.compute_metrics(scn, run, cfg=cfg)


def test_box_holds_its_pushes_on_mujoco_with_the_reserve_and_slides_without():
    """The 3 N push (68 % of the box's weight, 20 ms edges) arrives before any command can: with
    the standing reserve the box moves < 1 mm / < 1 deg over all five pulses and the wrist move;
    without it (the paper's margin S_ref = 0.8 alone) the push slides it by more than 1 mm."""
    held = _box_hold({})
    assert held["hold_slip_mm"] < 1.0 and held["hold_rotation_deg"] < 1.0
    assert not held["dropped"]
    bare = _box_hold({"reserve_force": 0.0, "reserve_torque": 0.0})
    assert bare["hold_slip_mm"] > 1.0
    assert np.isfinite(held["mean_force"]) and held["mean_force"] > bare["steady_force"]
