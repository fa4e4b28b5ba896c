"""lugrip.SlipControl: one object per gripper, statuses forwarded, same numbers as the simulator.

Kinds of test here:
* independent plant: the patch grasp plant (distributed bristle cells, not the observer's
  equations) driven from Python through SlipControl.step gives the simulator's samples bit for
  bit, and the command held on contact loss keeps the object;
* consistency (same code on both sides): SlipControl against the same Observer and
  GraspController wired by hand, run() against step(), file settings against keywords;
* hold and property tests on a quasi-static grip (a first-order gripper holding a constant
  load: no friction model), hostile inputs (hypothesis), the thread guard.
"""

from __future__ import annotations

import math
import threading

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import lugrip
from lugrip import _core
from lugrip.sim import scenarios as sc
from lugrip.sim._closed_loop import run_closed_loop
from lugrip.sim._plant import PlantConfig

CAN = "aluminium_can"


class QuasiStaticGrip:
    """A gripper with a 50 ms force lag holding a constant load per finger, sampled at 500 Hz."""

    def __init__(self, f_t=0.3, tau=2e-3, force=1.0):
        self.f_t, self.tau, self.force = f_t, tau, force

    def follow(self, command: float) -> None:
        self.force += (command - self.force) * (1.0 - math.exp(-0.002 / 0.05))

    def wrenches(self) -> np.ndarray:
        return np.array([[self.force, self.f_t, 0.0, self.tau]] * 2)


#: the controller's default reference of S
S_REF = lugrip.controller_settings()["s_ref"]


def settle(ctrl, grip: QuasiStaticGrip, n: int):
    out = None
    for _ in range(n):
        out = ctrl.step(grip.wrenches())
        grip.follow(out.force)
    return out


def test_settles_at_the_static_grasp_force():
    ctrl = lugrip.SlipControl(CAN)
    grip = QuasiStaticGrip()
    out = settle(ctrl, grip, 3000)
    expected = lugrip.static_grasp_force(CAN, grip.f_t, grip.tau, S_REF)
    assert out.force == pytest.approx(expected, rel=0.02)
    assert out.status == _core.Status.Ok
    assert out.fingers[0].S == pytest.approx(S_REF, abs=0.02)


def test_contact_loss_holds_the_command_for_0_2_s():
    ctrl = lugrip.SlipControl(CAN)
    grip = QuasiStaticGrip()
    held = settle(ctrl, grip, 3000).force
    assert held > 2 * ctrl.settings.controller.f_min
    lost = np.zeros((2, 4))
    forces = [ctrl.step(lost) for _ in range(100)]
    assert all(o.force >= held for o in forces)
    assert all(o.status == _core.Status.NoContact for o in forces)
    assert forces[-1].controller.held


def test_hand_wiring_without_statuses_drops_the_command():
    """Negative control: the pre-SlipControl wiring with the status left out lowers the
    command to f_min within 0.2 s of contact loss."""
    obs = [lugrip.Observer(CAN), lugrip.Observer(CAN)]
    # the paper's constant gains drain the unloaded command within 0.2 s (the slope gain more slowly)
    ctrl = lugrip.GraspController(CAN, gain_force=0.0)
    grip = QuasiStaticGrip()

    def cycle(w):
        o = [obs[i].step_vector(*w[i]) for i in range(2)]
        return ctrl.step(omega_hat=[x.omega_hat for x in o], S=[x.S for x in o],
                         c_tilde=[x.c_tilde for x in o], f_t=[np.hypot(w[i][1], w[i][2]) for i in range(2)])

    for _ in range(3000):
        grip.follow(cycle(grip.wrenches()).force)
    before = ctrl.command
    for _ in range(100):
        out = cycle(np.zeros((2, 4)))
    assert before > 0.2
    assert out.force < ctrl.settings["f_min"] + 1e-3


def test_invalid_samples_and_sensor_fault_hold_the_command():
    ctrl = lugrip.SlipControl(CAN)
    grip = QuasiStaticGrip()
    held = settle(ctrl, grip, 3000).force
    statuses = set()
    for _ in range(40):
        w = grip.wrenches()
        w[1, 3] = np.nan
        out = ctrl.step(w)
        statuses.add(out.status)
        assert out.force >= held
    assert statuses == {_core.Status.InvalidSample, _core.Status.SensorFault}
    assert out.fingers[1].status == _core.Status.SensorFault
    out = settle(ctrl, grip, 2000)
    assert out.status == _core.Status.Ok
    assert out.force == pytest.approx(held, rel=0.02)


def test_same_numbers_as_the_hand_wired_path_with_statuses():
    rng = np.random.default_rng(3)
    n = 3000
    w = np.empty((n, 2, 4))
    w[:, :, 0] = 2.0 + 0.01 * rng.standard_normal((n, 2))
    w[:, :, 1] = 0.4 + 0.3 * np.sin(np.arange(n) / 200.0)[:, None]
    w[:, :, 2] = 0.01 * rng.standard_normal((n, 2))
    w[:, :, 3] = 2e-3 * np.cos(np.arange(n) / 150.0)[:, None]
    w[1000:1030, 0, 0] = 0.0  # finger 0 loses contact
    w[2000, 1, 2] = np.inf
    ctrl = lugrip.SlipControl(CAN, f_min=0.2)
    obs = [lugrip.Observer(CAN), lugrip.Observer(CAN)]
    ref = lugrip.GraspController(CAN, f_min=0.2)
    for k in range(n):
        if k == 1500:
            ctrl.request_pivoting()
            ref.request_pivoting()
        o = [obs[i].step_vector(*w[k, i]) for i in range(2)]
        r = ref.step(omega_hat=[x.omega_hat for x in o], S=[x.S for x in o],
                     c_tilde=[x.c_tilde for x in o], f_t=[x for x in np.hypot(w[k, :, 1], w[k, :, 2])],
                     status=[int(x.status) for x in o], omega_resolution=[x.omega_resolution for x in o],
                     tau=list(w[k, :, 3]), f_n=list(w[k, :, 0]))
        out = ctrl.step(w[k])
        # f_t: the C++ core uses its own planar norm, within an ulp of numpy's hypot
        assert out.force == pytest.approx(r.force, rel=1e-12, abs=1e-12), k
        assert out.fingers[1].omega_hat == pytest.approx(o[1].omega_hat, rel=1e-9, abs=1e-12), k
        assert out.status.value == int(r.status), k


def test_run_equals_step_and_carries_requests():
    rng = np.random.default_rng(8)
    w = np.tile([2.0, 0.3, 0.0, 2e-3], (2000, 2, 1)) + 0.005 * rng.standard_normal((2000, 2, 4))
    w[700:720, 1, 0] = 0.0
    a, b = lugrip.SlipControl(CAN), lugrip.SlipControl(CAN)
    run = a.run(w, requests={900: "pivoting", 1400: "slipping_avoidance"})
    forces, modes, s1 = [], [], []
    for k in range(len(w)):
        if k == 900:
            b.request_pivoting()
        if k == 1400:
            b.request_slipping_avoidance()
        out = b.step(w[k])
        forces.append(out.force)
        modes.append(out.mode.value)
        s1.append(out.fingers[1].S)
    np.testing.assert_array_equal(run.force, forces)
    np.testing.assert_array_equal(run.mode, modes)
    np.testing.assert_array_equal(run.S_1, s1)
    assert len(run) == 2000
    assert run.pivot_finished[1400] and run.pivot_end[1400] == int(lugrip.PivotEnd.REQUESTED)
    assert set(run.finger(0)) == {name for name, _k, _d in _core.ObserverOutput.fields}
    assert "cor_side_flipped_1" in run and "dynamic_sample_1" in run


def test_rates_checked_at_construction():
    with pytest.raises(ValueError, match=r"observer\.dt = 0\.002: must equal 1 / controller\.sensor_rate = 0\.001"):
        lugrip.SlipControl(CAN, observer={"dt": 0.002}, sensor_rate=1000.0)
    # dt not given: follows the sensor rate
    ctrl = lugrip.SlipControl(CAN, sensor_rate=1000.0)
    assert ctrl.settings.observer.dt == pytest.approx(1e-3)
    with pytest.raises(ValueError, match="k_p"):
        lugrip.SlipControl(CAN, k_p=-1.0)
    with pytest.raises(ValueError, match="fingers"):
        lugrip.SlipControl(CAN, fingers=3)


def test_defaults_come_from_cpp():
    ctrl = lugrip.SlipControl(CAN)
    s = ctrl.settings
    d = _core.SlipControlSettings()
    for name, _kind, _doc in _core.GraspControllerSettings.fields:
        assert getattr(s.controller, name) == getattr(d.controller, name), name
    for name, kind, _doc in _core.ObserverSettings.fields:
        if kind != "struct":
            assert getattr(s.observer, name) == getattr(d.observer, name), name


def test_parameter_file_brings_its_observer(tmp_path):
    path = tmp_path / "fit.yaml"
    lugrip.ContactParams.preset(CAN).replace(mu=0.6).to_yaml(
        path, observer={"bandwidth": 800.0, "integrator": "rk4", "torque_noise": 2e-5})
    ctrl = lugrip.SlipControl(path, observer={"torque_noise": 3e-5})
    o = ctrl.settings.observer
    assert o.bandwidth == 800.0 and o.integrator == _core.Integrator.Rk4
    assert o.torque_noise == 3e-5  # the keyword overrides the block
    assert ctrl.params.mu == 0.6 and ctrl.mu == 0.6


def test_one_finger_ignores_the_second_row():
    ctrl = lugrip.SlipControl(CAN, fingers=1)
    grip = QuasiStaticGrip()
    for _ in range(3000):
        out = ctrl.step(grip.wrenches()[0])  # shape (4,)
        grip.follow(out.force)
    assert out.force == pytest.approx(lugrip.static_grasp_force(CAN, grip.f_t, grip.tau, S_REF), rel=0.02)
    bad = np.array([grip.wrenches()[0], [np.nan] * 4])
    assert ctrl.step(bad).status == _core.Status.Ok
    with pytest.raises(ValueError, match="expected 4 values"):
        ctrl.step(np.zeros(3))


def test_set_mu_reset_and_settings_at_run_time():
    ctrl = lugrip.SlipControl(CAN)
    grip = QuasiStaticGrip()
    before = settle(ctrl, grip, 3000).force
    ctrl.set_mu(0.375)
    assert ctrl.command == before and ctrl.mu == 0.375 and ctrl.params.mu == 0.375
    after = settle(ctrl, grip, 4000).force
    half = lugrip.ContactParams.preset(CAN).replace(mu=0.375)
    assert after == pytest.approx(lugrip.static_grasp_force(half, grip.f_t, grip.tau, S_REF), rel=0.02)
    with pytest.raises(ValueError, match="mu"):
        ctrl.set_mu(-1.0)
    assert ctrl.mu == 0.375
    ctrl.reset(3.0)
    assert ctrl.command == 3.0
    assert ctrl.step(np.zeros((2, 4))).force == 3.0
    ctrl.update_settings(f_min=0.5, max_rate=50.0)
    assert ctrl.settings.controller.max_rate == 50.0
    with pytest.raises(ValueError):
        ctrl.update_settings(sensor_rate=100.0)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.lists(st.one_of(st.floats(allow_nan=True, allow_infinity=True, width=64),
                                   st.floats(-20, 20)), min_size=8, max_size=8), min_size=1, max_size=30))
def test_hostile_wrenches_keep_the_command_finite_and_in_range(rows):
    ctrl = lugrip.SlipControl(CAN, f_min=0.2, f_max=15.0)
    for row in rows:
        out = ctrl.step(np.array(row).reshape(2, 4))
        assert math.isfinite(out.force) and 0.2 <= out.force <= 15.0
        for f in out.fingers:
            assert math.isfinite(f.omega_hat) and math.isfinite(f.S)


def test_a_second_thread_gets_an_error():
    ctrl = lugrip.SlipControl(CAN)
    ctrl.step(np.zeros((2, 4)))
    obs = lugrip.Observer(CAN)
    obs.step(1.0, 0.1, 1e-3)
    errors = []

    def other():
        for call in (lambda: ctrl.step(np.zeros((2, 4))), lambda: ctrl.run(np.zeros((5, 2, 4))),
                     lambda: obs.step(1.0, 0.1, 1e-3), ctrl.request_pivoting):
            try:
                call()
            except RuntimeError as err:
                errors.append(str(err))

    t = threading.Thread(target=other)
    t.start()
    t.join()
    assert len(errors) == 4
    assert "one object per thread" in errors[0]
    # the owner keeps working; an object made in the other thread belongs to it
    assert math.isfinite(ctrl.step(np.zeros((2, 4))).force)


def _scenario_slip_control(path):
    scn = sc.load_scenario(path)
    cfg = scn.plant_config()
    est = lugrip.sim._closed_loop.estimator_params(cfg.contact, scn.estimator_for(cfg.model))
    fs = cfg.sensor.rate
    ctrl = dict(sensor_rate=fs, command_ratio=round(fs / cfg.actuator.command_rate), **scn.controller)
    observer = {"torque_noise": cfg.sensor.torque_noise, **scn.observer}
    return scn, cfg, lugrip.SlipControl(est or cfg.contact, observer=observer, **ctrl)


@pytest.mark.parametrize("name", ["exp4_aluminium_can_full", "exp2_small_resin_block"])
def test_patch_plant_driven_through_slip_control_equals_the_simulator(name):
    scn, cfg, ctrl = _scenario_slip_control(sc.find_scenario(name))
    duration = 4.0
    ref = run_closed_loop(cfg, scn.controller, scn.observer, None, duration,
                          estimator=scn.estimator_for(cfg.model))
    plant = _core.GraspPlant(cfg.to_core() if isinstance(cfg, PlantConfig) else cfg)
    ctrl.reset(plant.state.f_cmd)
    n = len(ref["t"])
    command = np.empty(n)
    w = np.empty((2, 4))
    for k in range(n):
        for i in range(2):
            s = plant.sensor_sample(i)
            w[i] = (s.f_n, s.f_x, s.f_y, s.tau)
        out = ctrl.step(w)
        command[k] = out.force
        plant.set_command(out.force)
        plant.advance_sample()
    np.testing.assert_array_equal(command, ref["command"])
    assert not ref["dropped"][-1]


def test_robot_loop_example_holds_through_the_contact_loss():
    import runpy
    from pathlib import Path

    path = Path(__file__).resolve().parents[2] / "examples" / "04_robot_loop.py"
    module = runpy.run_path(str(path), run_name="example_04")
    assert module["main"]() >= 0.0


def test_the_caller_says_when_a_command_is_due():
    """A 50 Hz gripper fed 10-sample batches: 'now' with each batch's newest sample, 'hold'
    with the others. Commands come exactly there, step() and run() agree, and the clock (the
    first sample of each period) computes its commands from a period that lags by nine samples
    (S is the period's mean: a rising load reads higher when the newest samples are in it)."""
    rng = np.random.default_rng(4)
    n = 400
    w = np.empty((n, 2, 4))
    w[:, :, 0] = 3.0 + 0.005 * rng.standard_normal((n, 2))
    w[:, :, 1] = np.linspace(0.1, 1.2, n)[:, None]            # a load rising through the run
    w[:, :, 2] = 0.005 * rng.standard_normal((n, 2))
    w[:, :, 3] = 1e-4 * rng.standard_normal((n, 2))
    due = np.arange(n) % 10 == 9
    a = lugrip.SlipControl(CAN)
    stepped = [a.step(w[k], command="now" if due[k] else "hold") for k in range(n)]
    issued = np.array([o.controller.command_issued for o in stepped])
    np.testing.assert_array_equal(issued, due)
    b = lugrip.SlipControl(CAN)
    run = b.run(w, commands=due)
    np.testing.assert_array_equal(run["command_issued"].astype(bool), due)
    np.testing.assert_array_equal(run["force"], [o.force for o in stepped])
    c = lugrip.SlipControl(CAN)
    clock = c.run(w)
    np.testing.assert_array_equal(clock["command_issued"].astype(bool), np.arange(n) % 10 == 0)
    # what the gripper gets after batch k (samples 10k..10k+9): the command from samples up to
    # 10k+9 (now) against the clock's latest, computed at sample 10k (samples 10k-9..10k)
    s_now = run["slippage"][due][5:]
    s_clock = clock["slippage"][np.arange(n) % 10 == 0][5:]
    assert np.all(s_now > s_clock)
    with pytest.raises(ValueError, match="command"):
        a.step(w[0], command="later")
    with pytest.raises(ValueError, match="commands"):
        b.run(w, commands=np.ones(n, dtype=int))
