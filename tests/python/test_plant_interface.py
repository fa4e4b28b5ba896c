"""The Plant interface (lugrip.sim.plant), its registry and the closed loop over it
(lugrip.sim.runner.run_plant_loop)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from lugrip.sim.plant import (
    Plant,
    PlantClock,
    PlantSamples,
    builds_scene,
    make_plant,
    plant_kind,
    plant_names,
    plant_renders,
    register_plant,
    registered,
)
from lugrip.sim.runner import run_plant_loop
from lugrip.sim.scenarios import load_scenario


class SpringPlant:
    """A plant written here, not lugrip's model: a rigid object squeezed between two springy
    fingertips with no friction limit (it never slips). The gripper force follows the command
    with one sample of delay; each sensor reads that force as its normal force and half the
    object's weight as its tangential force; contact starts at sample ``touch``."""

    name = "spring"

    def __init__(self, touch: int = 7, weight: float = 1.0):
        self.touch, self.weight = touch, weight
        self.commands: list[float] = []

    def reset(self, scene, seed=None, *, config=None) -> PlantClock:
        self.i, self.force, self.commands = 0, float(config.actuator.f_init), []
        self.T = 1.0 / float(config.sensor.rate)
        return PlantClock(sample_period=self.T, command_ratio=10)

    def step(self, commands) -> PlantSamples:
        n = len(commands)
        idx = self.i + np.arange(n)
        force = np.empty(n)
        for j, c in enumerate(commands):  # the force reaches the command during the sample
            self.commands.append(float(c))
            self.force = float(c)
            force[j] = self.force
        self.i += n
        contact = np.repeat((idx >= self.touch)[:, None], 2, axis=1)
        w = np.zeros((n, 2, 4))
        w[:, :, 0] = np.where(contact, force[:, None], 0.0)
        w[:, :, 2] = np.where(contact, 0.5 * self.weight, 0.0)
        z = np.zeros((n, 2))
        return PlantSamples(
            t=idx * self.T, wrench=w, wrench_true=w.copy(), grip_force=force, contact=contact,
            slip=z, rotation=np.zeros(n), theta=np.zeros(n), cog=z.copy(), omega=z.copy(),
            v_slip=z.copy(), external=np.zeros((n, 3)), gripper_y=np.zeros(n),
            extra={"probe": idx.astype(float)},
        ).check()

    def scene_status(self):
        return {"status": "ok", "detail": "", "time": None, "contact_time": None}


def test_registry_names_and_rejects():
    """Plant: none. The registry holds lugrip's C++ plants, MuJoCo and Drake; a new kind is
    one call."""
    assert {"patch", "lumped", "mujoco", "drake"} <= set(plant_names())
    assert registered("mujoco") and registered("patch")
    assert plant_renders("mujoco") and not plant_renders("patch")
    assert builds_scene("mujoco") and builds_scene("drake") and not builds_scene("lumped")
    assert plant_kind("lumped").config_model == "lumped"
    assert plant_kind("drake").config_model == "patch"
    register_plant("spring_test", SpringPlant, "a test plant")
    try:
        p = make_plant("spring_test", touch=3)
        assert isinstance(p, Plant) and p.touch == 3
        assert "spring_test" in plant_names()
        assert not plant_renders("spring_test")
    finally:
        from lugrip.sim import plant as mod

        mod._REGISTRY.pop("spring_test")
    with pytest.raises(ValueError, match="unknown plant"):
        make_plant("no_such_plant")
    with pytest.raises(ValueError, match="built-in plants"):
        register_plant("patch", SpringPlant)
    with pytest.raises(ValueError):
        register_plant("bad name!", SpringPlant)
    with pytest.raises(TypeError):
        register_plant("x", 42)


def test_plant_samples_check_names_a_wrong_shape():
    n = 3
    z = np.zeros((n, 2))
    good = dict(t=np.zeros(n), wrench=np.zeros((n, 2, 4)), wrench_true=np.zeros((n, 2, 4)),
                grip_force=np.zeros(n), contact=np.zeros((n, 2), bool), slip=z, rotation=np.zeros(n),
                theta=np.zeros(n), cog=z, omega=z, v_slip=z, external=np.zeros((n, 3)),
                gripper_y=np.zeros(n))
    assert len(PlantSamples(**good).check()) == n
    with pytest.raises(ValueError, match="omega"):
        PlantSamples(**(good | {"omega": np.zeros((n, 3))})).check()


def test_runner_schedule_on_an_independent_plant():
    """Plant: SpringPlant above (independent of lugrip's model; rigid, never slips). The runner
    closes with f_init until both fingers touch, starts the controller at the next command
    tick, sends the command it logs (held over each command period) and logs the plant's
    samples, truth and extra columns unchanged."""
    scn = load_scenario("exp2_small_resin_block")
    cfg = scn.plant_config("patch")
    plant = SpringPlant(touch=7)
    run = run_plant_loop(plant, scn, cfg, scn.controller, scn.observer, None, 1.0)
    n = len(run.t)
    T = 1.0 / cfg.sensor.rate
    assert n == int(math.floor(1.0 / T + 1e-9))
    assert np.allclose(np.diff(run.t), T)
    # the first tick (multiple of 10) with contact: sample 10
    assert run.scene["contact_time"] == pytest.approx(7 * T)
    assert run.scene["controller_start"] == pytest.approx(10 * T)
    assert np.all(run.status[:10] == 3) and np.all(run.command[:10] == cfg.actuator.f_init)
    # the gripper got, during sample j, the command logged after sample j - 1
    sent = np.asarray(plant.commands)
    assert sent[0] == cfg.actuator.f_init
    assert np.array_equal(sent[1:], run.actuator_command[:-1])
    # commands change only at the ticks (every 10th sample from the start)
    changes = np.flatnonzero(np.diff(run.command) != 0.0) + 1
    assert np.all(changes % 10 == 0)
    # the plant's columns reach the log unchanged
    assert np.array_equal(run.probe, np.arange(n, dtype=float))
    assert np.array_equal(run.f_n_meas_0, np.where(np.arange(n) >= 7, run.f_n, 0.0))
    assert np.all(run.contact_0[7:] == 1) and np.all(run.contact_0[:7] == 0)
    assert not run.dropped.any() and run.finite.all()


def test_mujoco_plant_samples_hold_a_static_grasp():
    """Plant: MuJoCo (independent engine). A constant 6 N command on the exp2 block resting on
    its table: after the closing transient both pads touch, each measures (noise-free) the
    gripper's force as its normal force, the object does not slip, and the samples are
    periodic in time with the documented shapes."""
    scn = load_scenario("exp2_small_resin_block").for_plant("mujoco")
    cfg = scn.plant_config("mujoco", 3)
    p = make_plant("mujoco")
    clock = p.reset(scn, config=cfg)
    assert clock.sample_period == pytest.approx(1.0 / cfg.sensor.rate)
    outs = [p.step(np.full(1, 6.0))] + [p.step(np.full(clock.command_ratio, 6.0))
                                         for _ in range(40)]
    for o in outs:
        o.check()
    t = np.concatenate([o.t for o in outs])
    assert np.allclose(np.diff(t), clock.sample_period)
    last = outs[-1]
    assert last.contact.all()
    fn = last.wrench_true[:, :, 0]
    assert np.allclose(fn, last.grip_force[:, None], rtol=0.03), (fn.mean(0), last.grip_force.mean())
    assert np.all(np.abs(last.slip) < 1e-4) and np.all(np.abs(last.rotation) < 1e-3)
    assert p.scene_status()["status"] == "ok"
    assert p.scene_status()["contact_time"] is not None
