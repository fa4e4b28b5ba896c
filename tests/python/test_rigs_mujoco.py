"""The MuJoCo rubbing rig (lugrip.rigs.mujoco_rig): physics of the engine, not of lugrip.

The plant is MuJoCo's soft-contact solver driving a spring-mounted pad over a fixed slider with
prescribed motion, an independent plant: none of these tests runs lugrip's contact model. The
references are the friction law the rig states (Coulomb mu, the pad's torsional capacity
tau_max = mu xi delta f_n^(gamma+1), MuJoCo's elliptic cone) and the mount's spring constants.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("mujoco")

from lugrip.rigs import ManeuverPlan, RubbingData, RubbingDesign
from lugrip.rigs.mujoco_rig import MujocoRubbingRig, RigSettings, mount_pose


def _plan(rig, c_tilde, f_n, omega=1.0, ramp=0.05, hold=0.6, rest=0.2, angle=0.3):
    """One maneuver about a CoR at c_tilde rho(f_n) along `angle` [rad] of the pad frame:
    ramp to `omega` [rad/s] (pad relative to slider), hold, ramp down, rest; no noise."""
    rho = float(rig.radius(f_n))
    approach = 0.1
    kt = [0.0, approach, approach + ramp, approach + ramp + hold, approach + 2 * ramp + hold]
    kw = [0.0, 0.0, omega, omega, 0.0]
    end = kt[-1]
    t = np.arange(int((end + rest) / 0.002) + 1) * 0.002
    c = c_tilde * rho
    return ManeuverPlan(
        index=0,
        t=t,
        knots_t=np.array(kt),
        knots_omega=np.array(kw),
        cor=c * np.array([math.cos(angle), math.sin(angle)]),
        c_tilde=c_tilde,
        rho_nominal=rho,
        f_n_nominal=f_n,
        approach=approach,
        motion_end=end,
        f_n_start=1.0,
        ripple=0.0,
        ripple_freq=1.0,
        ripple_phase=0.0,
        reversals=0,
        offset=np.zeros(4),
        noise=(0.0, 0.0),
        noise_seed=0,
    )


def _sliding(plan, r):
    ph = plan.commanded_phase()
    return (ph == 1) & r["sliding"]


def _hold(plan, after):
    """Samples of the constant-speed leg from `after` seconds past the motion start."""
    return (plan.t > plan.approach + after) & (plan.t < plan.knots_t[3])


@pytest.fixture(scope="module")
def rig():
    return MujocoRubbingRig()


@pytest.fixture(scope="module")
def built(rig):
    return rig.build()


def test_translation_gross_sliding_reaches_mu_fn(rig, built):
    """A translation-dominated rub (CoR 20 contact radii away): in gross sliding the in-plane
    force is mu f_n (the elliptic cone at c~ = 20 leaves 0.05 % for the torque)."""
    plan = _plan(rig, 20.0, 5.0, omega=0.5)
    r = rig.run_maneuver(plan, built)
    sl = _sliding(plan, r)
    assert sl.sum() > 100
    late = sl & _hold(plan, 0.3)
    assert late.sum() > 100
    ratio = np.hypot(r["f_x"], r["f_y"])[late] / r["f_n"][late]
    assert np.all(np.abs(ratio / rig.pad.mu - 1.0) < 2e-3)
    assert np.all(r["v"][late] > 1e-3)  # the contact slides (c |omega| = 0.027 m/s)


@pytest.mark.parametrize("f_n", [2.0, 8.0])
def test_rotation_gross_sliding_reaches_tau_max(rig, built, f_n):
    """Rotation about the contact point: |tau| -> tau_max(f_n) of the pad law, f_t -> 0."""
    plan = _plan(rig, 0.0, f_n, omega=1.0)
    r = rig.run_maneuver(plan, built)
    late = _sliding(plan, r) & _hold(plan, 0.3)
    assert late.sum() > 50
    tau_max = rig.pad.mu * rig.pad.xi * rig.pad.delta * f_n ** (1.0 + rig.pad.gamma)
    assert np.all(np.abs(np.abs(r["tau"][late]) / tau_max - 1.0) < 2e-3)
    assert np.all(np.hypot(r["f_x"], r["f_y"])[late] < 1e-3 * f_n)
    assert rig.truth().tau_max(f_n) == pytest.approx(tau_max, rel=1e-9)


@pytest.mark.parametrize("c_tilde", [0.3, 1.0, 3.0])
def test_elliptic_cone_couples_force_and_torque(rig, built, c_tilde):
    """Between the two limits the sliding wrench lies on the ellipse
    (f_t / mu f_n)^2 + (tau / tau_max)^2 = 1 with both parts carrying load."""
    f_n = 4.0
    plan = _plan(rig, c_tilde, f_n, omega=1.0, hold=0.8)
    r = rig.run_maneuver(plan, built)
    late = _sliding(plan, r) & _hold(plan, 0.4)
    assert late.sum() > 50
    ft = np.hypot(r["f_x"], r["f_y"])[late] / (rig.pad.mu * r["f_n"][late])
    tq = np.abs(r["tau"][late]) / rig.pad.tau_max(r["f_n"][late])
    assert np.all(np.abs(np.hypot(ft, tq) - 1.0) < 2e-3)
    assert np.all(ft > 0.1) and np.all(tq > 0.1)
    # farther CoR, more force and less torque
    if c_tilde >= 3.0:
        assert np.median(ft) > 0.9


def test_presliding_is_the_mount_compliance(rig, built):
    """Before gross sliding the pad sticks and its springs carry the load: for a rub about a
    far CoR the in-plane force grows as k_slide times the mount's travel at the pad, and the
    wrench takes ~ mu f_n / (k_slide v) to reach the friction limit."""
    f_n, c_tilde, omega = 5.0, 20.0, 0.5
    plan = _plan(rig, c_tilde, f_n, omega=omega, ramp=0.02, hold=0.4)
    r = rig.run_maneuver(plan, built)
    ph = plan.commanded_phase()
    first_slide = int(np.argmax(_sliding(plan, r)))
    stick = (ph == 1) & (np.arange(len(ph)) < first_slide) & (r["utilisation"] < 0.6)
    assert stick.sum() > 10
    assert np.all(r["v"][stick] < 5e-5)  # stuck: the pad does not slip (mount: 27 mm/s)
    # the mount's travel at the pad origin: the chord of its arc about the CoR
    c = float(np.hypot(*plan.cor))
    theta = np.array([_theta(plan, t) for t in plan.t])
    travel = 2.0 * c * np.abs(np.sin(0.5 * theta))
    ft = np.hypot(r["f_x"], r["f_y"])
    k_est = np.polyfit(travel[stick], ft[stick], 1)[0]
    assert k_est == pytest.approx(rig.pad.k_slide, rel=0.03)
    t_pre = plan.t[first_slide] - plan.approach
    v = c * omega
    expected = rig.pad.mu * f_n / (rig.pad.k_slide * v) + 0.5 * 0.02  # half the ramp
    assert t_pre == pytest.approx(expected, rel=0.15)


def _theta(plan, t):
    from lugrip.rigs.mujoco_rig import _theta_at, _theta_segments

    return _theta_at(t, *_theta_segments(plan))


def test_mount_pose_keeps_the_cor_fixed():
    cor = np.array([0.01, -0.02])
    for theta, omega in ((0.3, 1.0), (-1.2, -0.5)):
        pos, vel = mount_pose(cor, theta, omega)
        c, s = math.cos(theta), math.sin(theta)
        world_cor = pos[:2] + np.array([c * cor[0] - s * cor[1], s * cor[0] + c * cor[1]])
        assert np.allclose(world_cor, cor, atol=1e-15)
        # velocity of the mount-frame point cor is zero: v_origin + omega x (R cor) = 0
        rc = world_cor - pos[:2]
        assert np.allclose(vel[:2] + omega * np.array([-rc[1], rc[0]]), 0.0, atol=1e-15)


def test_signs_follow_the_sliding_log_convention(rig, built):
    """The log is what the slider exerts on the fingertip: the in-plane force points along
    the slider's motion relative to the pad, sign(tau) = sign(omega) in rotation, and the
    labelled c~ has the sign -sign(omega) (docs/sliding_log.md)."""
    for omega in (1.0, -1.0):
        plan = _plan(rig, 0.5, 4.0, omega=omega)
        r = rig.run_maneuver(plan, built)
        sl = _sliding(plan, r) & (plan.t > plan.approach + 0.2)
        assert np.all(np.sign(r["omega"][sl]) == -np.sign(omega))  # slider relative to pad
        assert np.all(np.sign(r["tau"][sl]) == np.sign(r["omega"][sl]))
        assert np.all(np.sign(plan.c_tilde_signed(1.0)[sl]) == -np.sign(r["omega"][sl]))
        assert np.all(np.sign(r["c_tilde_slip"][sl]) == -np.sign(r["omega"][sl]))


@pytest.mark.parametrize("c_tilde", [0.0, 1.0, 20.0])
def test_noslip_holds_the_loaded_rest(rig, c_tilde):
    """Why the rig needs the noslip solver: after the motion stops with the pad loaded at its
    limit, MuJoCo's soft friction without noslip lets the contact creep and the load relax;
    with noslip it stays put and loaded."""
    plan = _plan(
        rig, c_tilde, 3.0, omega=1.0 if c_tilde < 10 else 0.2, ramp=0.02, hold=0.2, rest=0.4
    )
    rest = (plan.commanded_phase() == 3) & (plan.t > plan.motion_end + 0.05)  # stopped
    out = {}
    for iters in (10, 0):
        m, d, pad = rig.build()
        m.opt.noslip_iterations = iters
        r = rig.run_maneuver(plan, (m, d, pad))
        out[iters] = (r["load_ratio"][rest], r["omega"][rest], r["v"][rest])
    load, omega, v = out[10]
    assert load[0] > 0.99 and load[-1] > 0.99  # the rest stays loaded at the limit
    assert np.max(np.abs(omega)) < 1e-6 and np.max(v) < 1e-6  # and does not slip
    load0, omega0, v0 = out[0]
    assert load0[-1] < 0.75  # without noslip the load relaxes by creep
    assert np.max(np.abs(omega0)) > 1e-2 or np.max(v0) > 1e-4  # it creeps while relaxing


def test_simulate_is_reproducible_and_labelled(rig):
    design = RubbingDesign(hold_range=(0.1, 0.2), rest_range=(0.1, 0.15), reverse_fraction=0.5)
    a = rig.simulate(design, n=3, seed=7)
    b = rig.simulate(design, n=3, seed=7)
    c = rig.simulate(design, n=3, seed=8)
    assert isinstance(a, RubbingData)
    for x, y in ((a.log.f_n, b.log.f_n), (a.log.tau, b.log.tau), (a.phase, b.phase)):
        assert np.array_equal(x, y)
    assert not np.array_equal(a.log.f_n[:100], c.log.f_n[:100])
    assert set(np.unique(a.phase)) == {0, 1, 2, 3}
    assert np.all(a.load_ratio[a.phase == 2] >= 1.0 - rig.settings.cone_tolerance)
    assert np.all(a.v_true >= 0.0)
    assert np.array_equal(np.unique(a.log.maneuver), [0, 1, 2])
    t = a.truth
    assert (t.mu, t.mu_static, t.viscous, t.beta_a) == (0.7, 0.7, False, None)
    assert t.tau_max(2.0) == pytest.approx(float(rig.pad.tau_max(2.0)), rel=1e-9)
    assert a.meta["plant"] == "mujoco"
    # in gross sliding c~ is the actual slip CoR: its sign is -sign(omega)
    g = a.phase == 2
    assert np.all(np.sign(a.c_tilde_true[g]) == -np.sign(a.log.omega[g]))


def test_rig_rejects_settings_that_allow_creep():
    with pytest.raises(ValueError, match="noslip"):
        MujocoRubbingRig(settings=RigSettings(noslip_iterations=2)).build()


@pytest.mark.parametrize("c_tilde", [0.5, 2.0])
def test_sliding_wrench_is_the_ellipse_maximum_dissipation_point(rig, built, c_tilde):
    """MuJoCo's elliptic cone with noslip picks, for the pad's actual slip (its CoR at
    c~_slip), the point of the ellipse whose normal is the slip twist: f~_t = a / sqrt(1 + a^2),
    tau~ = 1 / sqrt(1 + a^2), a = c~_slip / xi. This is the limit surface MuJoCo implies."""
    plan = _plan(rig, c_tilde, 4.0, omega=1.0, hold=2.5)
    r = rig.run_maneuver(plan, built)
    late = _sliding(plan, r) & _hold(plan, 0.4)
    a = np.abs(r["c_tilde_slip"][late]) / rig.pad.xi
    ft = np.hypot(r["f_x"], r["f_y"])[late] / (rig.pad.mu * r["f_n"][late])
    tq = np.abs(r["tau"][late]) / rig.pad.tau_max(r["f_n"][late])
    assert np.allclose(ft, a / np.sqrt(1 + a * a), atol=5e-3)
    assert np.allclose(tq, 1 / np.sqrt(1 + a * a), atol=5e-3)
    # the slip CoR settles on the prescribed one seen from the displaced contact point
    c_true = r["cor_distance"][late] / rig.radius(r["f_n"][late])
    assert np.abs(np.abs(r["c_tilde_slip"][late][-1]) / c_true[-1] - 1.0) < 0.03
