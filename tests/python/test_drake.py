"""Drake as lugrip's second independent engine (lugrip.sim.drake): the compliant-hydroelastic
pad's sensor and contact invariants, identification on the Drake rubbing rig against the
engine's own torsional capacity, and lugrip's closed loop on a short Drake grasp scene.

Every plant here is Drake's physics (hydroelastic pressure field, discrete contact solver), not
lugrip's model. Skipped when pydrake is not installed (pip install "lugrip[drake]").
"""

from __future__ import annotations

import math

import numpy as np
import pytest

pydrake = pytest.importorskip(
    "pydrake", reason="Drake is not installed (pip install 'lugrip[drake]')")

from lugrip import identify  # noqa: E402
from lugrip.rigs import RubbingDesign  # noqa: E402
from lugrip.rigs.registry import make_rig  # noqa: E402
from lugrip.sim import scenarios as sc  # noqa: E402
from lugrip.sim.drake.pad import DrakePad  # noqa: E402
from lugrip.sim.drake.plant import DrakePlant  # noqa: E402
from lugrip.sim.drake.rig import DrakeRubbingRig, measure_capacity  # noqa: E402
from lugrip.sim.plant import Plant, make_plant  # noqa: E402


@pytest.fixture(scope="module")
def held():
    """exp2's block (0.245 kg, CoG 3.5 mm beside the grasp point) grasped with a constant 8 N
    on the Drake gripper, lifted 10 cm over 1-4 s and held: the samples up to 5 s."""
    scn = sc.load_scenario("exp2_small_resin_block")
    cfg = scn.plant_config(None, None)
    plant = DrakePlant()
    clock = plant.reset(scn, config=cfg)
    out = [plant.step(np.full(1, cfg.actuator.f_init))]
    while out[-1].t[-1] < 5.0:
        out.append(plant.step(np.full(clock.command_ratio, 8.0)))
    return scn, cfg, plant, out


def test_registered_plant_and_rig():
    """Drake: make_plant('drake') is a Plant of the registry, make_rig('drake') the Drake rig."""
    plant = make_plant("drake")
    assert isinstance(plant, Plant) and plant.name == "drake"
    assert isinstance(make_rig("drake"), DrakeRubbingRig)


def test_sensor_wrench_holds_the_object_with_the_right_signs(held):
    """Drake: the fingertip sensors' wrench (the object's wrench on each pad, pad frame) turned
    into world forces on the object balances its weight and its gravitational torque while it
    hangs still in the grasp; both normal forces equal the actuator's 8 N and point into the
    fingers."""
    _, cfg, plant, out = held
    last = out[-1]
    w = last.wrench_true[-1]  # (2, 4) at t = 5 s
    assert w[0, 0] == pytest.approx(8.0, rel=0.02) and w[1, 0] == pytest.approx(8.0, rel=0.02)
    from lugrip.sim.drake.plant import _PAD_FRAMES

    g = plant.model
    f_obj = np.zeros(3)
    for k in (0, 1):
        R = g.pads[k][0].EvalPoseInWorld(g.context).rotation().matrix()
        f_pad_P = np.array([w[k, 1], w[k, 2], w[k, 0]])  # (x, y, z) in the pad frame
        f_obj -= R @ f_pad_P  # the pad's force on the object
        # the normal force presses pad k outward: -x for pad 0, +x for pad 1
        assert np.sign((R @ f_pad_P)[0]) == (-1.0 if k == 0 else 1.0)
        assert np.allclose(R, _PAD_FRAMES[k], atol=0.05)
    weight = cfg.object.mass * 9.81
    assert f_obj[2] == pytest.approx(weight, rel=0.02)
    assert abs(f_obj[1]) < 0.02 * weight
    # the torques about the pad axes hold the weight's moment (m g d, d = 3.5 mm; the pads' z
    # axes are opposite, so their readings are opposite)
    moment = weight * cfg.object.cog[0]
    assert w[0, 3] == pytest.approx(-w[1, 3], rel=0.05)
    assert abs(w[0, 3]) + abs(w[1, 3]) == pytest.approx(moment, rel=0.1)


def test_pads_press_into_the_object_only_within_their_compliant_layer(held):
    """Drake: each pad's face overlaps the object by about the hydroelastic sphere's depth at
    its normal force, sqrt(f_n / (pi E)), never by more than the pad's radius, and the patch is
    about the continuum contact radius (4 R^2 f_n / (pi E))^(1/4)."""
    scn, _, plant, out = held
    g = plant.model
    spec = scn.scene_spec()
    X_o = g.object.EvalPoseInWorld(g.context)
    pad = plant.pad
    for k in (0, 1):
        p = X_o.inverse().multiply(g.pads[k][0].EvalPoseInWorld(g.context).translation())
        depth = abs(p[0]) - spec.half_width  # < 0: the face inside the object
        f_n = out[-1].wrench_true[-1, k, 0]
        assert -depth == pytest.approx(pad.depth(f_n), rel=0.35)
        assert -depth < pad.radius
        a = out[-1].extra[f"patch_radius_{k}"][-1]
        assert a == pytest.approx(pad.patch_radius(f_n), rel=0.35)


def test_capacity_grows_with_the_patch():
    """Drake: the engine's torsional capacity in a slow pure spin grows as f_n^(1 + gamma)
    with gamma near the hydroelastic sphere's 1/4, within 30 % of mu (8/15) f_n a of the
    continuum paraboloid."""
    pad = DrakePad()
    pts = np.array(measure_capacity(pad, forces=(1.0, 4.0, 16.0)))
    slope = np.polyfit(np.log(pts[:, 0]), np.log(pts[:, 1]), 1)[0]
    assert 1.15 < slope < 1.35
    for f, tau in pts:
        assert tau == pytest.approx(pad.mu * 8.0 / 15.0 * f * pad.patch_radius(f), rel=0.3)


def _tau(p, f: float) -> float:
    from lugrip import LimitSurface

    return p.mu * LimitSurface(p.k).xi * p.delta * f ** (1.0 + p.gamma)


def test_shipped_pad_fit_matches_the_engine():
    """Drake: the shipped pad fit (objects/drake/pad.yaml: lugrip identify on 60 maneuvers of
    the Drake rig, all parameters free) has mu within 3 % of the rig's and tau_max(2 N),
    tau_max(8 N) within 5 % of the capacity measured on the engine now, and no fitted parameter
    at (within 1 % of) a bound."""
    import yaml

    from lugrip._data import data_dir
    from lugrip.sim.drake.plant import PAD_FILE, pad_parameters

    p = pad_parameters()
    truth = DrakeRubbingRig().truth()
    assert p.mu == pytest.approx(truth.mu, rel=0.03)
    for f in (2.0, 8.0):
        assert _tau(p, f) == pytest.approx(truth.tau_max(f), rel=0.05), f
    doc = yaml.safe_load((data_dir("objects") / PAD_FILE).read_text())
    for name, e in doc["contact"].items():
        if isinstance(e, dict) and e.get("free") and "bounds" in e:
            lo, hi = e["bounds"]
            assert lo * 1.01 < e["value"] < hi / 1.01, name


def test_object_fit_on_the_rig_matches_the_engine():
    """Drake: an object of mu 0.5 rubbed by the Drake pad on 16 maneuvers; lugrip's per-object
    step (mu free, the pad's law of objects/drake/pad.yaml held) finds mu within 3 % and
    tau_max(2 N), tau_max(8 N) within 5 % of the capacity measured on the engine with that
    object."""
    from lugrip.sim.drake.plant import pad_parameters
    from lugrip.sim.drake.rig import RIG_PAD

    rig = DrakeRubbingRig(pad=RIG_PAD.replace(mu=0.5))
    data = rig.simulate(RubbingDesign(), n=16, seed=5)
    truth = data.truth
    res = identify([data.log], pad_parameters(), free=("mu",), start="data", refine=False)
    p = res.params
    assert p.mu == pytest.approx(0.5, rel=0.03)
    for f in (2.0, 8.0):
        assert _tau(p, f) == pytest.approx(truth.tau_max(f), rel=0.05), f
    assert not [e.name for e in res.estimates if e.at_bound]


def test_short_drake_grasp_meets_its_criteria():
    """Drake: lugrip's closed loop (observers and controller, the Drake plant's estimator: the
    pad identified on the Drake rig with the object's mu) grasps, lifts and holds the unseen
    light cup (short run, no baselines) within the scenario's closed-loop criteria."""
    r = sc.run_scenario("cup_light", plant_model="drake", short=True, baselines=False)
    assert r.runs["lugrip"].scene["status"] == "ok"
    failed = {k: v for k, v in r.criteria.items() if v["pass"] is False}
    assert not failed, failed
    assert math.isfinite(float(np.max(r.runs["lugrip"]["slip"])))
