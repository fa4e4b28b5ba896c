"""lugrip's C++ grasp plants (patch, lumped) behind the Plant interface (lugrip.sim.cplant).

Every run here is on lugrip's own plant model (include/lugrip/grasp_plant.hpp); the tests check
that the runner's Python loop over ``step`` and the plant's C++ ``closed_loop`` are the same
closed loop (sample for sample), and that campaigns reach the plants through the registry.
"""

from __future__ import annotations

import numpy as np
import pytest

from lugrip import SlipControl
from lugrip.campaign import CampaignError
from lugrip.campaign.definition import Campaign
from lugrip.sim.cplant import CPlant
from lugrip.sim.plant import Plant, make_plant
from lugrip.sim.runner import run_plant_loop
from lugrip.sim.scenarios import compute_metrics, load_scenario

#: columns the C++ loop and the runner both write, compared bit for bit
_EXACT = ("t", "command", "static_force", "dynamic_force", "mu_belief", "mode",
          "command_issued", "pivot_finished", "pivot_end", "actuator_command", "fault_active",
          "f_n", "slip_x", "slip_y", "rotation", "theta", "cog_x", "cog_y", "gripper_y",
          "ext_fx", "ext_fy", "ext_tau", "supported", "dropped", "finite")
_FINGER = ("f_n_meas", "tau_meas", "tau_true", "omega_hat", "S", "c_tilde",
           "observer_status", "omega_true", "c_tilde_true")


def _both(name: str, model: str, kind: str = "lugrip", **opts):
    """The run of scenario `name` (short) on `model` by the plant's C++ loop and by the
    runner's Python loop over ``step`` (a controller_factory forces it)."""
    s = load_scenario(name).shortened().for_plant(model)
    cfg = s.plant_config(model)
    if s.faults:
        opts.update(faults=s.faults["inject"], stuck_samples=s.faults.get("stuck_samples", 0),
                    healthy_finger_fallback=s.faults.get("healthy_finger_fallback", False))
    args = (s, cfg, s.controller, s.observer, s.schedule if kind == "lugrip" else None,
            s.duration)
    kw = dict(kind=kind, estimator=s.estimator_for(model), **opts)
    fused = run_plant_loop(make_plant(model), *args, **kw)
    stepped = run_plant_loop(make_plant(model), *args, controller_factory=SlipControl, **kw)
    return s, cfg, fused, stepped


@pytest.mark.parametrize(
    ("name", "model", "kind"),
    [
        ("exp2_small_resin_block", "patch", "lugrip"),
        ("exp3_plastic_bottle_pivot", "lumped", "lugrip"),
        ("exp2_small_resin_block", "patch", "constant_force"),
        ("fault_nan_burst", "patch", "lugrip"),
    ],
)
def test_python_loop_over_step_is_the_c_loop(name, model, kind):
    """Plant: lugrip's model. The runner's loop over PatchPlant/LumpedPlant.step gives the C++
    closed loop's run bit for bit (schedule, pivot, baseline, injected faults), the slip to
    1e-15 m (the C++ loop's grasp point against finger 0's pad centre: the same point)."""
    opts = {"constant_force": 6.0} if kind == "constant_force" else {}
    s, cfg, fused, stepped = _both(name, model, kind, **opts)
    assert len(fused["t"]) == len(stepped["t"]) > 1000
    cols = list(_EXACT) + [f"{c}_{k}" for c in _FINGER for k in (0, 1)]
    for c in cols:
        np.testing.assert_array_equal(np.asarray(stepped[c], float), np.asarray(fused[c], float),
                                      err_msg=c)
    np.testing.assert_allclose(stepped["slip"], fused["slip"], rtol=0.0, atol=1e-15)
    # the run moved: a grasp with a lift and a load, not a plant at rest
    assert np.ptp(fused["gripper_y"]) > 0.01 and np.ptp(fused["f_n"]) > 0.1
    ma, mb = compute_metrics(s, fused, cfg=cfg), compute_metrics(s, stepped, cfg=cfg)
    for k in ("hold_slip_mm", "hold_rotation_deg", "mean_force", "dropped"):
        assert ma[k] == pytest.approx(mb[k], rel=1e-12, abs=1e-15), k


def test_friction_cone_on_step_matches_the_c_loop():
    """Plant: lugrip's model. The friction-cone baseline by the runner agrees with the C++
    loop's to rounding (the runner's |f_t| is numpy's hypot, the C++ loop's sqrt(x^2 + y^2))."""
    s, cfg, fused, stepped = _both("exp2_small_resin_block", "patch", "friction_cone")
    np.testing.assert_allclose(stepped["command"], fused["command"], rtol=1e-9, atol=1e-9)
    ma, mb = compute_metrics(s, fused, cfg=cfg), compute_metrics(s, stepped, cfg=cfg)
    assert ma["mean_force"] == pytest.approx(mb["mean_force"], rel=1e-9)
    assert ma["dropped"] == mb["dropped"]


def test_cplant_step_contract():
    """Plant: lugrip's model. Sample 0 is the initial state (no advance), the next calls
    advance one sample per command, any length works, and the plant's command lag shows."""
    s = load_scenario("exp2_small_resin_block")
    cfg = s.plant_config("patch")
    p = make_plant("patch")
    assert isinstance(p, Plant) and isinstance(p, CPlant)
    clock = p.reset(s, config=cfg)
    assert clock.sample_period == pytest.approx(1.0 / cfg.sensor.rate)
    assert clock.command_ratio == round(cfg.sensor.rate / cfg.actuator.command_rate)
    first = p.step(np.array([cfg.actuator.f_init]))
    assert first.t.tolist() == [0.0] and first.contact.all()
    assert first.grip_force[0] == pytest.approx(cfg.actuator.f_init)
    f_up = cfg.actuator.f_init + 3.0
    out = p.step(np.full(3 * clock.command_ratio, f_up))
    assert out.t[0] == pytest.approx(clock.sample_period) and len(out) == 3 * clock.command_ratio
    grip = out.grip_force
    # the first-order lag: rises monotonically toward the command, not there at once
    assert np.all(np.diff(grip) >= -1e-12) and cfg.actuator.f_init < grip[-1] < f_up
    assert p.scene_status()["status"] == "ok" and p.scene_status()["contact_time"] == 0.0
    with pytest.raises(RuntimeError, match="before reset"):
        make_plant("lumped").step(np.ones(2))


def _campaign(plant: str, **params) -> Campaign:
    return Campaign.from_dict({
        "name": "t", "scenario": "exp2_small_resin_block", "plant": plant, "seed": 3,
        "duration": 6.0, "steady_window": [3.5, 4.4],
        "overrides": {"plant": {"lift": {"t_start": 1.0, "duration": 2.0, "height": 0.1},
                                "disturbances": []}},
        "controllers": {"constant_force": {"force": 6.0}},
        "parameters": params,
    })


def test_campaign_plant_parameters_come_from_the_registry():
    """Plant: none (campaign definitions). A plant's own campaign parameter (MuJoCo's pad
    springs) lands in the scenario where the registry says; another plant refuses it."""
    pad = {"distribution": "uniform", "low": 2000.0, "high": 8000.0}
    c = _campaign("mujoco", pad_k_slide=pad)
    scn, p = c.run_scenario(0)
    assert scn.block("mujoco")["pad"]["k_slide"] == p["pad_k_slide"]
    assert 2000.0 <= p["pad_k_slide"] <= 8000.0
    assert c.criteria.get("scene_ok") is True  # an engine reports its scene
    for other in ("patch", "drake"):
        with pytest.raises(CampaignError, match="pad_k_slide: a parameter of the mujoco plant"):
            _campaign(other, pad_k_slide=pad)
    assert "scene_ok" not in _campaign("patch").criteria  # lugrip's plant has no scene
