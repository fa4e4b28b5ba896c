"""Grasp plant (lugrip.sim): the distributed contact against the limit surface and its viscous
extension (docs/model.md 3, 5.1), configuration from dicts, batch runs (hold, slip, fall, pendulum,
lift), actuator, sensor noise, determinism, the lumped plant."""

from __future__ import annotations

import math

import lugrip
import numpy as np
import pytest
from lugrip import ContactParams, LimitSurface
from lugrip.sim import (
    Disturbance,
    GraspPlant,
    PatchContact,
    PatchSettings,
    PlantConfig,
    lift,
)

G = 9.81
RESIN = ContactParams.preset("big_resin_block")


def tau_max(p: ContactParams, f_n: float) -> float:
    return p.mu * p.xi * p.delta * f_n ** (p.gamma + 1.0)


def config(mass=0.1, f_n=5.0, **kw) -> PlantConfig:
    base = {
        "contact": "big_resin_block",
        "object": {"mass": mass, "inertia": mass * 1e-3},
        "actuator": {"f_init": f_n},
        "sensor": {"force_noise": 0.0, "torque_noise": 0.0},
    }
    for key, value in kw.items():
        if isinstance(value, dict) and isinstance(base.get(key), dict):
            base[key] = {**base[key], **value}
        else:
            base[key] = value
    return PlantConfig.from_dict(base)


# ---------------------------------------------------------------------------------------------
# the patch reproduces the limit surface


@pytest.mark.parametrize("c_tilde", [0.0, 0.1, 0.3, 0.6, 1.0, 1.5, 3.0, 8.0])
@pytest.mark.parametrize("direction", [0.0, 0.9])
def test_patch_reproduces_the_limit_surface_k4(c_tilde, direction):
    p = RESIN.replace(beta_a=0.0)
    ls = LimitSurface(4.0)
    pc = PatchContact(p)
    assert pc.cells == 314
    ft, tau = pc.steady_rotation(5.0, c_tilde, 1.5, direction)
    F, T = -ls.ft_star(np.array([c_tilde]))[0], ls.tau_star(np.array([c_tilde]))[0]
    # omega > 0: f_t = F mu f_n (>= 0 in the paper's frame), tau = -T tau_max (eqs. 5-6)
    err = math.hypot(ft - F, tau + T) / math.hypot(F, T)
    assert err < 0.01
    assert abs(ft - F) < 0.005 and abs(tau + T) < 0.005


def test_patch_matches_the_exact_hertz_surface_k2_and_converges():
    # k = 2, |c~| <= 1 has a closed form (docs/model.md 3.2) independent of the library's tables.
    c = np.array([0.15, 0.4, 0.7, 0.95])
    F_exact = 3 * math.pi / 8 * c * (1 - c**2 / 4)
    T_exact = 1 - c**2 + 3 / 8 * c**4
    p = RESIN.replace(beta_a=0.0, k=2.0)
    errs = {}
    for rings in (6, 10, 24):
        pc = PatchContact(p, PatchSettings(rings=rings))
        out = np.array([pc.steady_rotation(3.0, ci, -2.0, 0.4) for ci in c])
        # omega < 0 mirrors: f_t still >= 0, tau > 0
        errs[rings] = np.hypot(out[:, 0] - F_exact, out[:, 1] - T_exact).max()
    assert errs[10] < 0.01
    assert errs[24] < errs[10] < errs[6]
    assert errs[24] < 0.003


@pytest.mark.parametrize("beta_a", [1.24e7, 4.9e9])
def test_viscous_excess_matches_eqs_7_8_and_total_eqs_9_10(beta_a):
    ls = LimitSurface(4.0)
    f_n, omega, direction = 4.0, 0.8, 0.3
    wet = PatchContact(RESIN.replace(beta_a=beta_a))
    dry = PatchContact(RESIN.replace(beta_a=0.0))
    p = wet.params
    rho = lugrip.contact_radius(p, f_n)
    K = math.pi * p.delta**3 * beta_a * f_n ** (3 * p.gamma - 1) / p.mu
    for c_tilde in (0.0, 0.5, 1.2, 4.0):
        # excess over the dry patch for the same kinematics = viscous stress over the disc,
        # eqs. 7-8 in vector form: F_v = -beta pi rho^2 V_centre, tau_v = -(pi/2) beta rho^4 omega
        c = c_tilde * rho
        cx, cy = c * math.cos(direction), c * math.sin(direction)
        vx, vy = omega * cy, -omega * cx  # velocity of the pad centre rotating about (cx, cy)
        wet.reset()
        dry.reset()
        fw = np.array(wet.advance(f_n, vx, vy, omega, 0.01, 30))
        fd = np.array(dry.advance(f_n, vx, vy, omega, 0.01, 30))
        excess = fw - fd
        expect = [
            -math.pi * beta_a * rho**2 * vx,
            -math.pi * beta_a * rho**2 * vy,
            -math.pi / 2 * beta_a * rho**4 * omega,
        ]
        assert excess == pytest.approx(expect, rel=1e-9, abs=1e-15)
        # its magnitude along the friction direction is eq. 7: pi beta rho^2 |omega c|
        assert math.hypot(*excess[:2]) == pytest.approx(
            math.pi * beta_a * rho**2 * abs(omega * c), rel=1e-12, abs=1e-15
        )
        # total against eqs. 9-10 with the library's limit surface
        ft_w, tau_w = wet.steady_rotation(f_n, c_tilde, omega, direction)
        ft_pred = -ls.ft_star(np.array([c_tilde]))[0] + K * omega * c_tilde  # eq. 9
        tau_pred = -ls.tau_star(np.array([c_tilde]))[0] - K * omega / (2 * p.xi)  # eq. 10
        assert math.hypot(ft_w - ft_pred, tau_w - tau_pred) / math.hypot(ft_pred, tau_pred) < 0.01


# ---------------------------------------------------------------------------------------------
# configuration


def test_config_from_dict_presets_overrides_and_errors():
    cfg = PlantConfig.from_dict(
        {
            "model": "lumped",
            "contact": {"preset": "aluminium_can", "mu": 0.7},
            "object": {"mass": 0.4, "inertia": 4e-4, "cog": [0.0, -0.03]},
            "lift": {"t_start": 1.0, "duration": 2.0, "height": 0.1},
            "moves": [{"t_start": 4.0, "duration": 1.0, "dx": 0.05}],
            "disturbances": [
                {
                    "t_start": 2.0,
                    "duration": 0.2,
                    "shape": "half_sine",
                    "force": [1.0, 0.0],
                    "point": [0.0, 0.05],
                }
            ],
            "support": True,
            "seed": 7,
        }
    )
    assert (
        cfg.contact.mu == 0.7 and cfg.contact.beta_a == ContactParams.preset("aluminium_can").beta_a
    )
    assert cfg.model == "lumped"
    assert len(cfg.moves) == 2 and cfg.moves[1].dy == 0.1
    core = cfg.to_core()
    assert core.n_moves == 2 and core.n_disturbances == 1 and core.seed == 7
    plant = GraspPlant(cfg)
    assert plant.gripper_at(10.0)[:2] == pytest.approx((0.05, 0.1))
    with pytest.raises(ValueError, match="unknown key"):
        PlantConfig.from_dict(
            {"contact": "table1", "object": {"mass": 1, "inertia": 1}, "colour": "red"}
        )
    with pytest.raises(ValueError, match="object.*unknown"):
        PlantConfig.from_dict(
            {"contact": "table1", "object": {"mass": 1, "inertia": 1, "radius": 2}}
        )
    with pytest.raises(ValueError) as err:
        PlantConfig.from_dict(
            {"contact": "table1", "object": {"mass": -1, "inertia": 0}, "sensor": {"rate": 300.0}}
        )
    for field in ("object.mass", "object.inertia", "sensor.rate"):
        assert field in str(err.value)
    with pytest.raises(ValueError, match="shape"):
        Disturbance(shape="square")


# ---------------------------------------------------------------------------------------------
# open-loop dynamics


def test_stick_holds_and_the_sensors_read_half_the_load_each():
    plant = GraspPlant(config(0.05, 5.0, object={"cog": [0.01, 0.0]}))
    log = plant.run(2.0)
    assert log.t.shape == (1000,) and log.t[-1] == pytest.approx(2.0)
    assert log.max_slip[-1] < 1e-5  # < 0.01 mm
    assert not log.dropped.any()
    W, T = 0.05 * G, 0.05 * G * 0.01
    assert log.true_f_y_0[-1] == pytest.approx(-W / 2, rel=1e-6)
    assert log.true_f_y_1[-1] == pytest.approx(-W / 2, rel=1e-6)
    assert log.true_tau_0[-1] == pytest.approx(-T / 2, rel=1e-6)
    assert log.true_tau_1[-1] == pytest.approx(T / 2, rel=1e-6)


def test_slips_and_drops_at_a_force_well_below_the_static_requirement():
    log = GraspPlant(config(0.1, 0.05)).run(2.0)  # requirement m g / (2 mu) = 0.58 N
    assert log.dropped[-1]
    assert log.slip_y_0[-1] < -5e-3 and log.slip_y_1[-1] < -5e-3
    assert np.all(np.diff(log.slip_y_0) <= 1e-12)  # keeps sliding down
    assert np.all(np.abs(log.c_tilde_0[-10:]) == 1e3)  # pure translation


def test_free_fall_with_zero_grip_accelerates_at_g():
    log = GraspPlant(config(0.3, 0.0, moves=[lift(0.05, 0.3, 0.05)])).run(0.5)
    v_world = log.vy + log.gripper_vy
    assert v_world == pytest.approx(-G * log.t, abs=1e-9)
    assert (log.y + log.gripper_y) == pytest.approx(-0.5 * G * log.t**2, abs=G * 0.5 * 1e-3)
    assert log.dropped[0]


def test_pendulum_pivots_toward_vertical_when_the_force_is_lowered():
    cfg = config(
        0.05,
        8.0,
        object={"cog": [0.04, 0.0], "inertia": 0.05 * 0.04**2 / 3},
        drop={"rotation_limit": math.inf},
    )
    plant = GraspPlant(cfg)
    hold = plant.run(0.4)
    assert hold.max_rotation[-1] < 2e-3
    log = plant.run(2.0, command=2.0)
    theta = np.degrees(log.theta)
    assert theta[-1] < -50 and theta[-1] > -130
    assert np.all(np.diff(theta[:150]) <= 1e-9)  # swings down monotonically at first
    # hanging: the CoG ends (nearly) below the grasp axis, inside the torsional capacity
    assert 0.05 * G * abs(log.x[-1]) <= 2 * tau_max(cfg.contact, 2.0) * 1.001
    assert abs(log.object_omega[-1]) < 1e-3


def test_support_then_lift():
    cfg = config(0.2, 4.0, support=True, moves=[lift(0.5, 1.0, 0.08)])
    log = GraspPlant(cfg).run(2.0)
    before = log.t < 0.5
    assert log.supported[before].all() and not log.supported[-1]
    assert (log.y + log.gripper_y)[-1] == pytest.approx(0.08, abs=2e-5)
    assert log.max_slip[-1] < 2e-5
    # the pads carry the weight plus the inertia of the lift: minimum-jerk peak acceleration
    # (10 / sqrt(3)) H / T^2 sampled at 500 Hz
    a_peak = 10 / math.sqrt(3) * 0.08 / 1.0**2
    assert log.contact_fy.max() == pytest.approx(0.2 * (G + a_peak), rel=1e-3)
    assert log.contact_fy[-1] == pytest.approx(0.2 * G, rel=1e-6)


def test_actuator_zero_order_hold_and_first_order_lag():
    cfg = config(0.1, 2.0, actuator={"time_constant": 0.03, "rate_limit": math.inf})
    plant = GraspPlant(cfg)
    # command changes at 3 ms intervals; the ZOH only takes the value present at the 20 ms ticks
    log = plant.run(0.2, command=lambda t: 6.0 if t >= 0.011 else 2.0)
    held = log.f_held
    assert np.all(held[log.t <= 0.020 + 1e-9] == 2.0)
    assert np.all(held[log.t > 0.020 + 1e-9] == 6.0)
    t_rel = log.t - 0.020
    mask = t_rel > 0
    expected = 6.0 - 4.0 * np.exp(-t_rel[mask] / 0.03)
    assert log.f_act[mask] == pytest.approx(expected, abs=1e-9)


def test_sensor_noise_statistics_and_seed():
    cfg = config(0.1, 5.0, sensor={"force_noise": 0.005, "torque_noise": 1e-5}, seed=3)
    a = GraspPlant(cfg).run(20.0)
    e_f = a.f_y_0 - a.true_f_y_0
    e_t = a.tau_1 - a.true_tau_1
    assert np.std(e_f) == pytest.approx(0.005, rel=0.03)
    assert np.std(e_t) == pytest.approx(1e-5, rel=0.03)
    assert abs(np.mean(e_f)) < 4 * 0.005 / math.sqrt(e_f.size)
    assert abs(np.corrcoef(e_f, a.f_x_1 - a.true_f_x_1)[0, 1]) < 0.05
    assert abs(np.corrcoef(e_f[1:], e_f[:-1])[0, 1]) < 0.05  # white
    b = GraspPlant(cfg).run(20.0)
    assert np.array_equal(a.tau_0, b.tau_0) and np.array_equal(a.f_n_1, b.f_n_1)
    c = GraspPlant(cfg.replace(seed=4)).run(20.0)
    assert not np.array_equal(a.tau_0, c.tau_0)
    assert np.array_equal(a.theta, c.theta)  # open loop: noise does not act on the plant


def test_disturbance_push_slides_then_sticks():
    push = Disturbance(t_start=0.5, duration=0.1, shape="half_sine", force=(0.0, -4.0))
    log = GraspPlant(config(0.3, 3.0, disturbances=[push])).run(1.5)
    assert log.ext_fy.min() == pytest.approx(-4.0, abs=0.01)
    assert log.vy.min() < -1e-3
    assert abs(log.vy[-1]) < 1e-6
    assert not log.dropped[-1]


def test_no_nan_under_extreme_inputs():
    dist = [
        Disturbance(t_start=0.1, duration=0.05, force=(1e6, -1e6), torque=1e3, point=(0.1, 0.0))
    ]
    for model in ("patch", "lumped"):
        cfg = config(
            0.05,
            5.0,
            model=model,
            disturbances=dist,
            object={"cog": [0.03, 0.0]},
            moves=[{"t_start": 0.0, "duration": 0.05, "dx": 1.0, "dy": 1.0}],
        )
        cmd = np.full(750, np.nan)
        cmd[50], cmd[150], cmd[300] = 0.0, np.inf, 1e-9
        log = GraspPlant(cfg).run(1.5, command=cmd)
        for key, value in log.items():
            assert np.all(np.isfinite(value)), (model, key)


# ---------------------------------------------------------------------------------------------
# lumped plant (docs/model.md 10.1 (a))


@pytest.mark.parametrize("model", ["patch", "lumped"])
def test_torsional_slip_threshold_is_twice_tau_max_for_both_plants(model):
    f_n = 4.0
    tm = tau_max(RESIN, f_n)
    out = {}
    for ratio in (0.9, 1.15):
        torque = Disturbance(t_start=0.0, duration=10.0, torque=ratio * 2 * tm)
        cfg = config(
            0.1,
            f_n,
            model=model,
            gravity=0.0,
            disturbances=[torque],
            drop={"rotation_limit": math.inf},
        )
        out[ratio] = GraspPlant(cfg).run(1.0).max_rotation[-1]
    assert out[0.9] < 1e-2 and out[1.15] > 0.05


def test_lumped_plant_has_no_translation_and_is_fast():
    cfg = config(
        0.05,
        0.5,
        model="lumped",
        object={"cog": [0.03, 0.0], "inertia": 2e-5},
        drop={"rotation_limit": math.inf},
    )
    log = GraspPlant(cfg).run(3.0)
    assert np.all(log.slip_x_0 == 0.0) and np.all(log.slip_y_0 == 0.0)
    assert math.degrees(log.theta[-1]) < -45  # pivots down
    assert np.all(log.slip_angle_0 == -log.slip_angle_1)


@pytest.mark.parametrize("force, torque_ratio", [(1.0, 1.1), (3.0, 0.75), (5.0, 0.5), (2.0, -1.0)])
def test_true_cor_agrees_with_the_cor_estimator_on_the_true_wrench(force, torque_ratio):
    # Steady combined sliding (no gravity, constant push and torque): the CoR of the relative motion
    # (ground truth of the plant) and the CoR the estimator (docs/model.md 5.4, viscous LS) recovers from
    # the true sensor wrench must agree, with the estimator's sign convention, on both fingers.
    f_n = 4.0
    cfg = config(
        0.1,
        f_n,
        gravity=0.0,
        drop={"rotation_limit": math.inf, "slip_limit": math.inf},
        disturbances=[
            {
                "t_start": 0.0,
                "duration": 100.0,
                "force": [force, 0.0],
                "torque": torque_ratio * 4 * tau_max(RESIN, f_n),
            }
        ],
    )
    log = GraspPlant(cfg).run(0.6)
    for i in (0, 1):
        f = log.finger(i)
        ft = math.hypot(f["true_f_x"][-1], f["true_f_y"][-1])
        est = lugrip.estimate_cor(RESIN, f_n, ft, f["true_tau"][-1])
        assert not est.inside  # sliding
        assert est.c_tilde == pytest.approx(f["c_tilde"][-1], rel=0.01, abs=2e-3)
        assert np.sign(f["true_tau"][-1]) == np.sign(f["omega"][-1])  # docs/model.md 7.2
    assert log.omega_0[-1] == -log.omega_1[-1]
