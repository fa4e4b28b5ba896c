"""Closed loop on the MuJoCo gripper: MuJoCo at 1 kHz -> fingertip wrench sensors at 500 Hz
(averaged over the sample, bias, noise) -> lugrip.SlipControl (each finger's observer and the
grasp-force controller behind one step) or a baseline -> a force command every 20 ms, held,
through the gripper's first-order lag and rate limit to the finger motors.

:func:`run_mujoco_loop` returns a :class:`~lugrip.sim.ClosedLoopRun` with the columns of the
patch and lumped plants' runs (so one set of metrics serves every plant) plus MuJoCo's own:
the sensor reads the pad's wrench in the pad frame of :mod:`lugrip.sim.mujoco.pad` (torque about
the pad axis, from the face into the finger); ``omega_true_i`` is the true slip rate of the
object relative to pad i about that axis [rad/s], ``v_slip_i`` the true in-plane slip speed at
the pad face [m/s], ``contact_i`` 1 while pad i touches the object, ``pad_deflection_i`` the
pad's in-plane spring deflection [m], ``pad_twist_i`` its twist about world x [rad], ``roll``
the hand's roll [rad].

Scene faults never raise; they set ``ClosedLoopRun.scene`` (see :data:`SCENE_STATUS`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import mujoco

from ..._params import ContactParams
from .._plant import Disturbance, PlantConfig
from ..plant import SCENE_STATUS
from ..runner import PlantRun, run_plant_loop
from .gripper import SceneSpec, spin_coefficient
from .plant import MujocoPlant

__all__ = [
    "SCENE_STATUS",
    "MujocoRun",
    "cone_slip_force",
    "disturbance_wrench",
    "run_mujoco_loop",
]


class MujocoRun(PlantRun):
    """A :class:`ClosedLoopRun` of the MuJoCo plant; ``scene`` holds the scene status:
    {status, detail, time, contact_time, controller_start}."""

    scene: dict[str, Any]


def _pulse(shape: str, u: float) -> float:
    if shape in ("rectangular", "rect"):
        return 1.0
    if shape in ("half_sine", "halfsine"):
        return math.sin(math.pi * u)
    if shape == "ramp":
        return u
    return 1.0 - abs(2.0 * u - 1.0)  # triangle


def disturbance_wrench(
    disturbances: Sequence[Disturbance], t: float, theta: float
) -> tuple[float, float, float]:
    """Sum of the active pulses at t [s] for an object at angle theta [rad]: world force
    (horizontal, vertical) [N] and the torque about the CoG [N m] (the patch plant's rule)."""
    fx = fy = tau = 0.0
    c, s = math.cos(theta), math.sin(theta)
    for d in disturbances:
        u = (t - d.t_start) / d.duration
        if not (0.0 <= u < 1.0):
            continue
        a = _pulse(d.shape, u)
        px = c * d.point[0] - s * d.point[1]
        py = s * d.point[0] + c * d.point[1]
        qx, qy = a * d.force[0], a * d.force[1]
        fx += qx
        fy += qy
        tau += a * d.torque + px * qy - py * qx
    return fx, fy, tau


def cone_slip_force(params: ContactParams, f_t: float, tau: float) -> float:
    """The normal force [N] below which MuJoCo's contact slips under the load (f_t [N], tau
    [N m]): the root of (f_t / (mu f))^2 + (tau / (mu_spin(f) f))^2 = 1 with the torsional
    coefficient mu_spin(f) = mu xi rho(f) the scene sets (bisection on log f)."""
    f_t, tau = abs(float(f_t)), abs(float(tau))
    if f_t == 0.0 and tau == 0.0:
        return 0.0

    def load(f: float) -> float:
        return (f_t / (params.mu * f)) ** 2 + (tau / (spin_coefficient(params, f) * f)) ** 2

    lo, hi = 1e-6, 1.0
    while load(hi) > 1.0:
        hi *= 2.0
    for _ in range(200):
        mid = math.sqrt(lo * hi)
        if load(mid) > 1.0:
            lo = mid
        else:
            hi = mid
        if hi / lo < 1.0 + 1e-9:
            break
    return hi


class _SceneOnly:
    """A scene for :class:`MujocoPlant.reset` made of a SceneSpec alone."""

    def __init__(self, spec: SceneSpec):
        self._spec = spec

    def scene_spec(self) -> SceneSpec:
        return self._spec


def run_mujoco_loop(
    plant: PlantConfig,
    scene: SceneSpec,
    controller_settings: Mapping[str, Any] | None = None,
    observer_settings: Mapping[str, Any] | None = None,
    mode_schedule=None,
    duration: float = 10.0,
    *,
    frame_callback: Callable[[mujoco.MjModel, mujoco.MjData, float], None] | None = None,
    **options: Any,
) -> MujocoRun:
    """Simulate the scenario's grasp on MuJoCo in closed loop for `duration` seconds:
    :func:`lugrip.sim.runner.run_plant_loop` on a :class:`~lugrip.sim.mujoco.plant.MujocoPlant`.

    Args:
        plant: the scenario's plant block (object mass, inertia and CoG; contact; actuator lag,
            rate limit and f_init; sensor rate, noise and bias; moves; disturbances; drop
            limits; seed). The sensor sample is a whole number of ``scene.timestep``.
        scene: the MuJoCo scene (object shape, pads, wrist rolls, solver settings).
        controller_settings, observer_settings, mode_schedule: as
            :func:`lugrip.sim.run_closed_loop`.
        frame_callback: called as f(model, data, t) at every sensor sample (rendering).
        options: :func:`lugrip.sim.runner.run_plant_loop`'s keywords (kind, constant_force,
            cone_margin, cone_release_rate, estimator, faults, stuck_samples,
            healthy_finger_fallback, controller_factory).

    Returns:
        :class:`MujocoRun`, one row per sensor sample.
    """
    run = run_plant_loop(
        MujocoPlant(frame_callback=frame_callback), _SceneOnly(scene), plant,
        controller_settings, observer_settings, mode_schedule, duration, **options,
    )
    out = MujocoRun(run)
    out.scene = run.scene
    return out
