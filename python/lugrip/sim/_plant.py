"""Grasp plant: configuration dataclasses (from dicts / YAML), the C++ simulator and batch runs.

Frames and conventions are those of ``include/lugrip/grasp_plant.hpp``: gripper frame X horizontal,
Y up (gravity along -Y), Z along the grasp axis; finger 0 on the -Z face with sensor frame
(X, Y, +Z), finger 1 on the +Z face with sensor frame (-X, Y, -Z); each sensor reads the wrench
the object exerts on its fingertip (docs/model.md 7.2). SI units everywhere.
"""

from __future__ import annotations

import dataclasses
import math
import os
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from .. import _core
from .._nocopy import NoCopy
from .._params import ContactParams

__all__ = [
    "ActuatorConfig",
    "Disturbance",
    "DropConfig",
    "GraspPlant",
    "GripperMove",
    "ObjectConfig",
    "PatchContact",
    "PatchSettings",
    "PlantConfig",
    "PlantLog",
    "SensorConfig",
    "lift",
]

_SHAPES = {
    "rectangular": _core.PulseShape.Rectangular,
    "rect": _core.PulseShape.Rectangular,
    "half_sine": _core.PulseShape.HalfSine,
    "halfsine": _core.PulseShape.HalfSine,
    "ramp": _core.PulseShape.Ramp,
    "triangle": _core.PulseShape.Triangle,
}
_MODELS = {"patch": _core.PlantModel.Patch, "lumped": _core.PlantModel.Lumped}


def _build(cls, data: Mapping[str, Any] | None, where: str):
    """Dataclass from a mapping, naming unknown keys."""
    if data is None:
        return cls()
    if isinstance(data, cls):
        return data
    if not isinstance(data, Mapping):
        raise ValueError(f"{where}: expected a mapping, got {type(data).__name__}")
    names = {f.name for f in dataclasses.fields(cls)}
    unknown = sorted(set(data) - names)
    if unknown:
        raise ValueError(
            f"{where}: unknown key(s) {', '.join(unknown)}; expected {', '.join(sorted(names))}"
        )
    return cls(**dict(data))


def _pair(value, where: str) -> tuple[float, float]:
    try:
        x, y = value
        return float(x), float(y)
    except (TypeError, ValueError):
        raise ValueError(f"{where}: expected a pair [x, y], got {value!r}") from None


def _copy_into(core_obj, values: Mapping[str, Any]) -> None:
    for name, value in values.items():
        setattr(core_obj, name, value)


@dataclasses.dataclass
class ObjectConfig:
    """Rigid planar object. mass [kg]; inertia about the CoG and the grasp axis [kg m^2]; cog:
    CoG in the object frame relative to the grasp point [m]; theta0: initial angle [rad]."""

    mass: float = 0.0
    inertia: float = 0.0
    cog: tuple[float, float] = (0.0, 0.0)
    theta0: float = 0.0

    def __post_init__(self):
        self.cog = _pair(self.cog, "object.cog")

    def to_core(self) -> _core.ObjectConfig:
        o = _core.ObjectConfig()
        _copy_into(
            o,
            {
                "mass": float(self.mass),
                "inertia": float(self.inertia),
                "cog_x": self.cog[0],
                "cog_y": self.cog[1],
                "theta0": float(self.theta0),
            },
        )
        return o


@dataclasses.dataclass
class ActuatorConfig:
    """Gripper force actuator: ZOH at command_rate [Hz], first-order lag time_constant [s],
    saturation between 0 and f_max [N], rate limit [N/s]; f_init: force and command at
    t = 0 [N]."""

    f_init: float = 1.0
    f_max: float = 80.0
    time_constant: float = 0.03
    rate_limit: float = 200.0
    command_rate: float = 50.0

    def to_core(self) -> _core.ActuatorConfig:
        a = _core.ActuatorConfig()
        _copy_into(a, {k: float(v) for k, v in dataclasses.asdict(self).items()})
        return a


@dataclasses.dataclass
class SensorConfig:
    """Fingertip sensors (both fingers): rate [Hz]; white noise std on forces [N] and torque
    [N m] (docs/model.md 10.1: 0.005 N, 0.01 N mm); quantisation steps (0: off); first-order low-pass
    before sampling [s] (0: off); bias per finger of (f_n, f_x, f_y, tau)."""

    rate: float = 500.0
    force_noise: float = 0.005
    torque_noise: float = 1.0e-5
    force_resolution: float = 0.0
    torque_resolution: float = 0.0
    filter_time_constant: float = 0.0
    bias: Sequence[Sequence[float]] = ((0.0, 0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 0.0))

    def __post_init__(self):
        b = np.asarray(self.bias, dtype=float)
        if b.shape != (2, 4):
            raise ValueError(
                "sensor.bias: expected 2 x 4 values (per finger f_n, f_x, f_y, tau), "
                f"got shape {b.shape}"
            )
        self.bias = tuple(tuple(float(v) for v in row) for row in b)

    def to_core(self) -> _core.SensorConfig:
        s = _core.SensorConfig()
        d = dataclasses.asdict(self)
        d.pop("bias")
        _copy_into(s, {k: float(v) for k, v in d.items()})
        for i in range(2):
            for j in range(4):
                s.set_bias(i, j, self.bias[i][j])
        return s


@dataclasses.dataclass
class PatchSettings:
    """Distributed contact: rings of the polar grid (10 -> 314 cells); bristle stiffness per unit
    cell load kappa [1/m] (breakaway deflection mu/kappa); bristle damping time t_d [s];
    Stribeck static_ratio = mu_s/mu (1: off) and stribeck_velocity [m/s]."""

    rings: int = 10
    bristle_stiffness: float = 1.0e6
    bristle_damping: float = 2.0e-4
    static_ratio: float = 1.0
    stribeck_velocity: float = 1.0e-3

    def to_core(self) -> _core.PatchSettings:
        p = _core.PatchSettings()
        _copy_into(
            p,
            {
                "rings": int(self.rings),
                "bristle_stiffness": float(self.bristle_stiffness),
                "bristle_damping": float(self.bristle_damping),
                "static_ratio": float(self.static_ratio),
                "stribeck_velocity": float(self.stribeck_velocity),
            },
        )
        return p


@dataclasses.dataclass
class DropConfig:
    """Drop criteria: translational slip [m], rotation [rad] (``inf`` disables, e.g. for
    pivoting), normal force below which the contact is lost [N]."""

    slip_limit: float = 5.0e-3
    rotation_limit: float = math.radians(20.0)
    contact_force_min: float = 1.0e-3

    def to_core(self) -> _core.DropConfig:
        d = _core.DropConfig()
        _copy_into(d, {k: float(v) for k, v in dataclasses.asdict(self).items()})
        return d


@dataclasses.dataclass
class GripperMove:
    """Minimum-jerk displacement (dx, dy) [m] of the grasp point over
    [t_start, t_start + duration]."""

    t_start: float = 0.0
    duration: float = 1.0
    dx: float = 0.0
    dy: float = 0.0

    def to_core(self) -> _core.GripperMove:
        g = _core.GripperMove()
        _copy_into(g, {k: float(v) for k, v in dataclasses.asdict(self).items()})
        return g


def lift(t_start: float, duration: float, height: float) -> GripperMove:
    """A vertical lift of `height` [m] (minimum jerk)."""
    return GripperMove(t_start=t_start, duration=duration, dx=0.0, dy=height)


@dataclasses.dataclass
class Disturbance:
    """External push: `force` (world axes) [N] at `point` (object frame, relative to the CoG)
    [m] plus a pure `torque` [N m], times the pulse shape ('rectangular', 'half_sine', 'ramp',
    'triangle') over [t_start, t_start + duration]."""

    t_start: float = 0.0
    duration: float = 0.1
    shape: str = "rectangular"
    force: tuple[float, float] = (0.0, 0.0)
    torque: float = 0.0
    point: tuple[float, float] = (0.0, 0.0)

    def __post_init__(self):
        key = str(self.shape).lower().replace("-", "_")
        if key not in _SHAPES:
            raise ValueError(
                f"disturbance shape {self.shape!r}: "
                "expected one of rectangular, half_sine, ramp, triangle"
            )
        self.shape = key
        self.force = _pair(self.force, "disturbance.force")
        self.point = _pair(self.point, "disturbance.point")

    def to_core(self) -> _core.Disturbance:
        d = _core.Disturbance()
        _copy_into(
            d,
            {
                "t_start": float(self.t_start),
                "duration": float(self.duration),
                "shape": _SHAPES[self.shape],
                "force_x": self.force[0],
                "force_y": self.force[1],
                "torque": float(self.torque),
                "point_x": self.point[0],
                "point_y": self.point[1],
            },
        )
        return d


@dataclasses.dataclass
class PlantConfig:
    """Everything the grasp plant needs (see include/lugrip/grasp_plant.hpp for the model).

    ``PlantConfig.from_dict`` accepts the YAML layout used by the scenarios::

        model: patch            # or lumped
        contact: aluminium_can  # preset name, a parameter file (fit.yaml), a ContactParams
                                # mapping, or {preset: name, mu: ...}
        object: {mass: 0.4, inertia: 4.0e-4, cog: [0.0, -0.03], theta0: 0.0}
        actuator: {f_init: 1.0, time_constant: 0.03}
        sensor: {force_noise: 0.005, torque_noise: 1.0e-5}
        patch: {rings: 10}
        drop: {slip_limit: 0.005}
        support: true
        lift: {t_start: 1.0, duration: 2.0, height: 0.1}   # sugar for one vertical move
        moves: [{t_start: 5.0, duration: 1.0, dx: 0.1}]
        disturbances: [{t_start: 14.0, duration: 0.3, shape: half_sine, force: [2.0, 0.0]}]
        seed: 1
    """

    contact: ContactParams
    object: ObjectConfig
    model: str = "patch"
    actuator: ActuatorConfig = dataclasses.field(default_factory=ActuatorConfig)
    sensor: SensorConfig = dataclasses.field(default_factory=SensorConfig)
    patch: PatchSettings = dataclasses.field(default_factory=PatchSettings)
    drop: DropConfig = dataclasses.field(default_factory=DropConfig)
    gravity: float = 9.81
    rate: float = 1000.0
    substeps: int = 1
    support: bool = False
    moves: list[GripperMove] = dataclasses.field(default_factory=list)
    disturbances: list[Disturbance] = dataclasses.field(default_factory=list)
    seed: int = 1

    def __post_init__(self):
        for name, cls in (
            ("object", ObjectConfig),
            ("actuator", ActuatorConfig),
            ("sensor", SensorConfig),
            ("patch", PatchSettings),
            ("drop", DropConfig),
        ):
            setattr(self, name, _build(cls, getattr(self, name), name))
        self.moves = [_build(GripperMove, m, f"moves[{i}]") for i, m in enumerate(self.moves)]
        self.disturbances = [
            _build(Disturbance, q, f"disturbances[{i}]") for i, q in enumerate(self.disturbances)
        ]
        if self.model not in _MODELS:
            raise ValueError(f"model {self.model!r}: expected 'patch' or 'lumped'")
        msg = _core.validate_plant_config(self.to_core())
        if msg:
            raise ValueError("invalid PlantConfig:\n" + msg.rstrip())

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> PlantConfig:
        if not isinstance(data, Mapping):
            raise ValueError("plant config: expected a mapping")
        d = dict(data)
        known = {f.name for f in dataclasses.fields(cls)} | {"lift"}
        unknown = sorted(set(d) - known)
        if unknown:
            raise ValueError(
                f"plant config: unknown key(s) {', '.join(unknown)}; "
                f"expected {', '.join(sorted(known))}"
            )
        if "contact" not in d or "object" not in d:
            raise ValueError("plant config: 'contact' and 'object' are required")
        contact = d.pop("contact")
        if isinstance(contact, (str, os.PathLike)) and \
                Path(contact).suffix.lower() in (".yaml", ".yml"):
            contact = ContactParams.from_yaml(contact)  # e.g. written by lugrip identify
        elif isinstance(contact, str):
            contact = ContactParams.preset(contact)
        elif isinstance(contact, Mapping) and "preset" in contact:
            c = dict(contact)
            contact = ContactParams.preset(c.pop("preset")).replace(**c)
        elif isinstance(contact, Mapping):
            contact = ContactParams.from_dict(contact)
        elif not isinstance(contact, ContactParams):
            raise ValueError("contact: expected a preset name, a parameter file (.yaml), a "
                             "mapping or ContactParams")
        moves = [
            _build(GripperMove, m, f"moves[{i}]") for i, m in enumerate(d.pop("moves", None) or [])
        ]
        if "lift" in d:
            lf = d.pop("lift")
            if lf:
                if not isinstance(lf, Mapping) or set(lf) - {"t_start", "duration", "height"}:
                    raise ValueError("lift: expected {t_start, duration, height}")
                moves.append(
                    lift(
                        float(lf.get("t_start", 0.0)),
                        float(lf.get("duration", 1.0)),
                        float(lf["height"]),
                    )
                )
        dist = [
            _build(Disturbance, q, f"disturbances[{i}]")
            for i, q in enumerate(d.pop("disturbances", None) or [])
        ]
        return cls(
            contact=contact,
            object=_build(ObjectConfig, d.pop("object"), "object"),
            actuator=_build(ActuatorConfig, d.pop("actuator", None), "actuator"),
            sensor=_build(SensorConfig, d.pop("sensor", None), "sensor"),
            patch=_build(PatchSettings, d.pop("patch", None), "patch"),
            drop=_build(DropConfig, d.pop("drop", None), "drop"),
            moves=moves,
            disturbances=dist,
            **d,
        )

    def replace(self, **changes) -> PlantConfig:
        return dataclasses.replace(self, **changes)

    def to_core(self) -> _core.PlantConfig:
        c = _core.PlantConfig()
        c.contact = self.contact.to_core()
        c.model = _MODELS[self.model]
        c.object = self.object.to_core()
        c.actuator = self.actuator.to_core()
        c.sensor = self.sensor.to_core()
        c.patch = self.patch.to_core()
        c.drop = self.drop.to_core()
        c.gravity = float(self.gravity)
        c.rate = float(self.rate)
        c.substeps = int(self.substeps)
        c.support = bool(self.support)
        c.seed = int(self.seed)
        for m in self.moves:
            c.add_move(m.to_core())
        for q in self.disturbances:
            c.add_disturbance(q.to_core())
        return c


class _Columns(dict):
    """Named arrays of a run: items are also attributes; per-finger columns end in _0 / _1."""

    def __getattr__(self, name):
        try:
            return self[name]
        except KeyError:
            raise AttributeError(name) from None

    def finger(self, i: int) -> dict[str, np.ndarray]:
        """The columns of finger i without the suffix."""
        suffix = f"_{i}"
        return {k[: -len(suffix)]: v for k, v in self.items() if k.endswith(suffix)}


class PlantLog(_Columns):
    """Arrays of a batch run, one row per sensor sample (also readable as attributes).

    Per finger i: ``f_n_i, f_x_i, f_y_i, tau_i`` (measured), ``true_*_i``, ``slip_x_i, slip_y_i,
    slip_angle_i, slip_vx_i, slip_vy_i, omega_i, c_tilde_i, rho_i`` (ground truth in the sensor
    frame). Plant: ``t, f_cmd, f_held, f_act, gripper_x, gripper_y, gripper_vy, x, y, vx, vy, theta,
    object_omega, max_slip, max_rotation, contact_fx, contact_fy, contact_tau, ext_fx, ext_fy,
    ext_tau, energy, supported, dropped``.
    """


class GraspPlant(NoCopy):
    """The C++ grasp simulator (deterministic with the config's seed).

    Args:
        config: a PlantConfig or a mapping for ``PlantConfig.from_dict``.

    The plant steps at ``config.rate`` (1 kHz); sensors sample both fingers at 500 Hz; the gripper
    latches the command at 50 Hz. ``run()`` loops in C++ and returns a PlantLog.
    """

    def __init__(self, config: PlantConfig | Mapping[str, Any]):
        if not isinstance(config, PlantConfig):
            config = PlantConfig.from_dict(config)
        self.config = config
        self._p = _core.GraspPlant(config.to_core())

    # thin pass-throughs ---------------------------------------------------------------
    def reset(self) -> None:
        self._p.reset()

    def set_command(self, f_cmd: float) -> None:
        self._p.set_command(float(f_cmd))

    def set_external(self, fx: float, fy: float, torque: float) -> None:
        self._p.set_external(float(fx), float(fy), float(torque))

    def step(self) -> bool:
        return self._p.step()

    def advance_sample(self) -> int:
        return self._p.advance_sample()

    def sensor_sample(self, finger: int):
        return self._p.sensor_sample(finger)

    @property
    def state(self):
        return self._p.state

    @property
    def time(self) -> float:
        return self._p.time

    @property
    def dt(self) -> float:
        return self._p.dt

    @property
    def sample_period(self) -> float:
        return self._p.dt * self._p.steps_per_sample

    @property
    def cells(self) -> int:
        return self._p.cells

    @property
    def energy(self) -> float:
        return self._p.energy

    def gripper_at(self, t: float):
        return self._p.gripper_at(float(t))

    def disturbance_at(self, t: float, theta: float = 0.0):
        return self._p.disturbance_at(float(t), float(theta))

    # batch ----------------------------------------------------------------------------
    def run(
        self, duration: float, command: float | Sequence[float] | Callable | None = None
    ) -> PlantLog:
        """Runs open loop for `duration` seconds from the current time; one row per sensor sample
        after the current one (t = now + k T_s, k = 1..n).

        Args:
            command: None (keep the current command), a constant [N], an array with one value per
                row (given at the sample before the row; NaN keeps the previous value), or a
                callable f(t) -> force evaluated at the sample times where it is given. The plant's
                ZOH latches the command at its 50 Hz ticks.
        """
        n = round(duration / self.sample_period)
        if n < 0:
            raise ValueError("duration must be >= 0")
        t_given = self.time + self.sample_period * np.arange(n)
        if command is None:
            cmd = np.full(n, np.nan)
        elif callable(command):
            cmd = np.asarray([float(command(t)) for t in t_given], dtype=float)
        elif np.ndim(command) == 0:
            cmd = np.full(n, float(command))
        else:
            cmd = np.ascontiguousarray(command, dtype=float)
            if cmd.shape != (n,):
                raise ValueError(
                    f"command: expected {n} values (one per sample), got shape {cmd.shape}"
                )
        return PlantLog(self._p.run(np.ascontiguousarray(cmd, dtype=np.float64)))


class PatchContact(NoCopy):
    """One fingertip pad as a discretised pressure patch with per-cell bristles (docs/model.md 10.1
    (b)), driven by prescribed kinematics; for checking the limit surface it produces.

    Args:
        params: ContactParams (mu, beta_A, delta, gamma, k are used).
        settings: PatchSettings (rings, bristle stiffness, ...).
    """

    def __init__(self, params: ContactParams, settings: PatchSettings | None = None):
        self.params = params
        self.settings = settings or PatchSettings()
        self._c = _core.PatchContact(params.to_core(), self.settings.to_core())

    @property
    def cells(self) -> int:
        return self._c.cells

    @property
    def moment2(self) -> float:
        return self._c.moment2

    def reset(self) -> None:
        self._c.reset()

    def advance(self, f_n: float, vx: float, vy: float, omega: float, h: float, steps: int = 1):
        """Prescribed velocity of the object point at the pad centre [m/s] and omega [rad/s] for
        `steps` steps of h [s]; returns the pad's wrench on the object (fx, fy [N], tau [N m])."""
        return self._c.advance(float(f_n), float(vx), float(vy), float(omega), float(h), int(steps))

    def steady_rotation(
        self,
        f_n: float,
        c_tilde: float,
        omega: float,
        direction: float = 0.0,
        duration: float = 0.3,
        h: float = 0.01,
    ) -> tuple[float, float]:
        """Steady rotation at omega about the CoR at c~ rho(f_n) along `direction` [rad]. Returns
        the pad's wrench on the object in the paper's frame (y along the friction force, docs/model.md
        1.2) normalised: (f_t / (mu f_n), tau / tau_max). The bristle update is exact for a constant
        velocity, so a coarse step h loses nothing."""
        p = self.params
        rho = p.delta * f_n**p.gamma
        cx, cy = c_tilde * rho * math.cos(direction), c_tilde * rho * math.sin(direction)
        self.reset()
        fx, fy, tau = self.advance(
            f_n, omega * cy, -omega * cx, omega, h, max(1, round(duration / h))
        )
        return math.hypot(fx, fy) / (p.mu * f_n), tau / (p.mu * p.xi * rho * f_n)
