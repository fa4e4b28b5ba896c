"""The MuJoCo fingertip pad (lugrip.sim.mujoco.pad): statics, the torsional law, signs, options.

Every test here runs MuJoCo's own contact solver on a small test bench (a finger pressing the
pad onto a fixed slider box, the finger driven along x and about the pad normal by stiff
servos): an independent plant, not lugrip's contact model. The references are the pad's
stated law (mu, tau_max = mu xi delta f_n^(gamma+1)) and the pressing force.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco")

from lugrip.sim.mujoco import (
    CONTACT_OPTIONS,
    FingertipSensor,
    Pad,
    PadSpec,
    contact_options_xml,
    model_xml,
    pad_body_xml,
    pair_xml,
)


def _bench(spec: PadSpec, **options):
    """Finger above a fixed slider box, its pad facing down (pad z = world z), no gravity."""
    bodies = (
        '<body name="finger" pos="0 0 0.0005">'
        '<joint name="press" type="slide" axis="0 0 1" damping="5"/>'
        '<joint name="fx" type="slide" axis="1 0 0"/>'
        '<joint name="frot" type="hinge" axis="0 0 1"/>'
        '<inertial pos="0 0 0" mass="0.05" diaginertia="1e-5 1e-5 1e-5"/>'
        + pad_body_xml(spec)
        + "</body>"
        '<geom name="slider" type="box" size="0.05 0.05 0.01" pos="0 0 -0.01"/>'
    )
    actuators = (
        '<motor name="press" joint="press" gear="1"/>'
        '<position name="fx" joint="fx" kp="1e5" kv="500"/>'
        '<position name="frot" joint="frot" kp="100" kv="2"/>'
    )
    xml = model_xml(
        bodies, pairs=pair_xml(spec, ["slider"]), actuators=actuators, gravity=(0, 0, 0), **options
    )
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    return m, d, Pad(m, spec)


def _run(m, d, pad, force, x_of_t=None, theta_of_t=None, steps=1000):
    """Press with `force` [N] and drive the finger; returns the wrench and slip velocity
    per step."""
    w = np.zeros((steps, 4))
    v = np.zeros((steps, 3))
    for n in range(steps):
        t = n * m.opt.timestep
        d.ctrl[0] = -force
        if x_of_t is not None:
            d.ctrl[1] = x_of_t(t)
        if theta_of_t is not None:
            d.ctrl[2] = theta_of_t(t)
        pad.update(m, d)
        mujoco.mj_step(m, d)
        w[n] = pad.wrench(m, d)
        v[n] = pad.slip_velocity(m, d)
    return w, v


@pytest.mark.parametrize("force", [0.5, 2.0, 8.0])
def test_statics_pressing_force_is_the_normal_force(force):
    m, d, pad = _bench(PadSpec())
    w, v = _run(m, d, pad, force, steps=400)
    assert w[-1, 0] == pytest.approx(force, rel=1e-6)
    assert np.all(np.abs(w[-1, 1:3]) < 1e-9)
    assert abs(w[-1, 3]) < 1e-12
    assert np.all(np.abs(v[-1]) < 1e-6)


@pytest.mark.parametrize("force", [2.0, 8.0])
def test_torsional_capacity_follows_the_pad_law(force):
    spec = PadSpec()
    m, d, pad = _bench(spec)
    w, v = _run(m, d, pad, force, theta_of_t=lambda t: max(t - 0.2, 0.0) * 1.0, steps=900)
    # gross sliding: the pad turns with the finger at 1 rad/s over the fixed slider
    assert v[-1, 2] == pytest.approx(-1.0, rel=1e-3)
    expected = spec.mu * spec.xi * spec.delta * force ** (spec.gamma + 1.0)
    assert abs(w[-1, 3]) == pytest.approx(expected, rel=1e-3)
    assert float(spec.tau_max(force)) == pytest.approx(expected, rel=1e-12)
    assert np.hypot(w[-1, 1], w[-1, 2]) < 1e-6 * force


def test_torsional_law_is_not_linear_in_the_normal_force():
    """tau_max(8 N) / tau_max(2 N) = 4^(1 + gamma), not MuJoCo's fixed-coefficient 4."""
    spec = PadSpec()
    taus = []
    for f in (2.0, 8.0):
        m, d, pad = _bench(spec)
        w, _ = _run(m, d, pad, f, theta_of_t=lambda t: max(t - 0.2, 0.0), steps=700)
        taus.append(abs(w[-1, 3]))
    assert taus[1] / taus[0] == pytest.approx(4.0 ** (1.0 + spec.gamma), rel=2e-3)


def test_signs_of_the_sensor_wrench():
    """The wrench is what the slider exerts on the pad: friction opposes the pad's motion
    over the slider, so the finger moving +x reads f_x < 0 and turning +z reads tau < 0;
    in gross sliding f_t = mu f_n."""
    spec = PadSpec()
    m, d, pad = _bench(spec)
    w, v = _run(m, d, pad, 4.0, x_of_t=lambda t: 0.02 * max(t - 0.1, 0.0), steps=600)
    assert v[-1, 0] < 0.0  # the slider moves -x relative to the pad
    assert w[-1, 1] < 0.0
    assert abs(w[-1, 2]) < 1e-9
    assert -w[-1, 1] / w[-1, 0] == pytest.approx(spec.mu, rel=1e-3)
    m, d, pad = _bench(spec)
    w, v = _run(m, d, pad, 4.0, theta_of_t=lambda t: 0.5 * max(t - 0.1, 0.0), steps=600)
    assert v[-1, 2] < 0.0 and w[-1, 3] < 0.0


def test_presliding_comes_from_the_pad_springs():
    """Before gross sliding the in-plane force is the slide spring's k x (the pad sticks)."""
    spec = PadSpec()
    m, d, pad = _bench(spec)

    def x(t):  # 0.5 mm in 0.2 s: 1 N on the 2000 N/m spring, below mu f_n = 2.8 N
        return 0.0005 * min(t / 0.2, 1.0)

    w, v = _run(m, d, pad, 4.0, x_of_t=x, steps=600)
    qx = d.qpos[pad.joint_qpos[0]]
    assert abs(v[-1, 0]) < 1e-6  # stuck
    assert -w[-1, 1] == pytest.approx(spec.k_slide * (-qx), rel=1e-3)
    # the pad stays where it touched the slider (to the few micrometres MuJoCo's soft friction
    # constraint gives): its spring takes the finger's travel
    x_finger = d.qpos[m.joint("fx").qposadr[0]]
    assert -qx == pytest.approx(x_finger, rel=1e-2)
    assert -w[-1, 1] == pytest.approx(spec.k_slide * x_finger, rel=1e-2)


def test_mujoco_options_of_pad_models():
    spec = PadSpec()
    m, _, pad = _bench(spec)
    assert m.opt.cone == mujoco.mjtCone.mjCONE_ELLIPTIC
    assert m.opt.noslip_iterations >= 5
    assert m.opt.timestep == pytest.approx(1e-3)
    assert m.opt.impratio == pytest.approx(CONTACT_OPTIONS["impratio"])
    assert m.opt.integrator == mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    assert list(m.pair_dim[pad.pair_ids]) == [4]
    assert m.pair_friction[pad.pair_ids[0], 0] == pytest.approx(spec.mu)
    assert m.pair_friction[pad.pair_ids[0], 1] == pytest.approx(spec.mu)
    assert m.geom_contype[pad.geom_id] == 0 and m.geom_conaffinity[pad.geom_id] == 0
    with pytest.raises(ValueError, match="noslip"):
        contact_options_xml(noslip_iterations=2)
    with pytest.raises(ValueError, match="elliptic"):
        contact_options_xml(cone="pyramidal")
    with pytest.raises(ValueError, match="unknown"):
        contact_options_xml(solver="CG2")


def test_pad_rejects_a_model_without_the_required_options():
    spec = PadSpec()
    xml = (
        '<mujoco><option cone="pyramidal"/><worldbody><body name="f">'
        '<joint type="slide" axis="0 0 1"/><inertial pos="0 0 0" mass="0.05" diaginertia="1e-5 1e-5 1e-5"/>'
        + pad_body_xml(spec)
        + "</body>"
        '<geom name="slider" type="box" size="0.05 0.05 0.01" pos="0 0 -0.01"/></worldbody>'
        "<contact>" + pair_xml(spec, ["slider"]) + "</contact></mujoco>"
    )
    m = mujoco.MjModel.from_xml_string(xml)
    with pytest.raises(ValueError, match="elliptic"):
        Pad(m, spec)


@pytest.mark.parametrize(
    "kw", [{"radius": 0.0}, {"mu": -1.0}, {"gamma": 1.5}, {"shape": "cube"}, {"k_slide": math.inf}]
)
def test_pad_spec_rejects_bad_values(kw):
    with pytest.raises(ValueError, match="PadSpec"):
        PadSpec(**kw)


def test_sensor_noise_and_offset():
    s = FingertipSensor(
        force_noise=0.01, torque_noise=2e-5, offset=(0.1, 0, 0, 0), rng=np.random.default_rng(3)
    )
    r = s.read(np.tile([2.0, 0.0, 0.0, 0.0], (20000, 1)))
    assert r[:, 0].mean() == pytest.approx(2.1, abs=3e-4)
    assert r[:, 1].std() == pytest.approx(0.01, rel=0.03)
    assert r[:, 3].std() == pytest.approx(2e-5, rel=0.03)
