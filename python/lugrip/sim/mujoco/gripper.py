"""A parallel gripper in MuJoCo: two force-controlled fingers ending in compliant pads, a hand
that lifts, translates and rolls, and one object resting on a table (the scenes of every
closed-loop experiment).

World frame: x is the grasp axis (finger 0 at -x, finger 1 at +x), y horizontal in the finger
plane, z up. The scenarios' gripper frame (X horizontal, Y up, Z the grasp axis) maps to
(y, z, x). The object moves in the finger plane (slides along y and z, a hinge about x) and may
centre itself between the pads (a slide along x).

Each pad hangs from its finger on two in-plane slides and a twist hinge with springs and
dampers: the pad deflects before the contact slides (pre-sliding), and the spring of each pad
decides how the load divides between the fingers (the rigid two-point grasp leaves that to the
solver). The pad contact is an elliptic cone with torsional friction (condim 4); its torsional
coefficient is set before every step to mu xi rho(f_n) of the present normal force, so the
torsional capacity grows as f_n^(1 + gamma) like the patch it stands for.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from collections.abc import Mapping
from typing import Any

import mujoco
import numpy as np

from ..._params import ContactParams
from ..._contact import LimitSurface

__all__ = [
    "PadSpec",
    "SceneSpec",
    "WristMove",
    "build_scene",
    "pad_wrenches",
    "spin_coefficient",
]


@dataclasses.dataclass
class PadSpec:
    """A compliant hemispherical fingertip pad on its finger."""

    radius: float = 0.012  #: [m] sphere radius of the pad surface
    mass: float = 0.01  #: [kg] pad mass between its springs and the contact
    tangential_stiffness: float = 4000.0  #: [N/m] in-plane spring finger -> pad (y and z)
    tangential_damping: float = 20.0  #: [N s/m]
    twist_stiffness: float = 2.0  #: [N m/rad] spring about the grasp axis
    twist_damping: float = 0.05  #: [N m s/rad]
    twist_inertia: float = 2.0e-6  #: [kg m^2] about the grasp axis
    solref: tuple[float, float] = (0.002, 1.0)  #: MuJoCo contact time constant [s], damping ratio


@dataclasses.dataclass
class WristMove:
    """Roll of the hand about the grasp axis by `roll_deg` [deg] (minimum jerk) over
    [t_start, t_start + duration]; rolls add up."""

    t_start: float = 0.0
    duration: float = 1.0
    roll_deg: float = 0.0


def _vec(value, n: int, where: str) -> tuple[float, ...]:
    try:
        out = tuple(float(v) for v in value)
    except TypeError:
        raise ValueError(f"{where}: expected {n} numbers, got {value!r}") from None
    if len(out) != n or not all(math.isfinite(v) for v in out):
        raise ValueError(f"{where}: expected {n} finite numbers, got {value!r}")
    return out


@dataclasses.dataclass
class SceneSpec:
    """The MuJoCo side of a scenario (its ``mujoco:`` block); the object's mass, inertia and CoG,
    the contact, actuator, sensors, moves and disturbances come from the scenario's plant block.

    Object shapes: ``box`` with half sizes [across the grasp, horizontal, vertical] [m];
    ``cylinder`` with [radius, half length] and ``axis`` vertical (a can, a cup: grasped on its
    side) or horizontal (a bottle lying in the finger plane).
    """

    shape: str = "box"
    size: tuple[float, ...] = (0.02, 0.05, 0.05)
    axis: str = "vertical"  #: cylinder axis
    #: geometric centre relative to the grasp point, in-plane (horizontal, vertical) [m];
    #: None: at the CoG (uniform object)
    geom_center: tuple[float, float] | None = None
    pad: PadSpec = dataclasses.field(default_factory=PadSpec)
    finger_mass: float = 0.05  #: [kg]
    finger_damping: float = 2.0  #: [N s/m] finger slide
    clearance: float = 0.001  #: [m] gap between each pad and the object at t = 0
    min_half_gap: float = 0.002  #: [m] the fingers' stops: pad surface this close to the axis
    force_range: float = 60.0  #: [N] the finger motors' limit
    #: [m] the object placed away from the grasp site (x, horizontal, vertical): scene faults
    object_offset: tuple[float, float, float] = (0.0, 0.0, 0.0)
    table: bool = True  #: the object rests on a table until lifted (else: it starts in the grasp)
    table_friction: float = 0.5
    wrist: list[WristMove] = dataclasses.field(default_factory=list)
    timestep: float = 0.001  #: [s]
    cone: str = "elliptic"
    noslip_iterations: int = 10
    impratio: float = 10.0
    #: the normal force [N] below which the torsional coefficient stops following rho(f_n)
    spin_force_floor: float = 0.05

    def __post_init__(self):
        if self.shape not in ("box", "cylinder"):
            raise ValueError(f"mujoco.shape {self.shape!r}: expected box or cylinder")
        n = 3 if self.shape == "box" else 2
        self.size = _vec(self.size, n, "mujoco.size")
        if min(self.size) <= 0.0:
            raise ValueError("mujoco.size: every dimension must be > 0")
        if self.axis not in ("vertical", "horizontal"):
            raise ValueError(f"mujoco.axis {self.axis!r}: expected vertical or horizontal")
        if self.geom_center is not None:
            self.geom_center = _vec(self.geom_center, 2, "mujoco.geom_center")
        self.object_offset = _vec(self.object_offset, 3, "mujoco.object_offset")
        if isinstance(self.pad, Mapping):
            self.pad = _build(PadSpec, self.pad, "mujoco.pad")
        self.wrist = [_build(WristMove, w, f"mujoco.wrist[{i}]") for i, w in enumerate(self.wrist)]
        if self.cone not in ("elliptic", "pyramidal"):
            raise ValueError(f"mujoco.cone {self.cone!r}: expected elliptic or pyramidal")
        for name in ("timestep", "finger_mass", "force_range", "min_half_gap"):
            v = float(getattr(self, name))
            if not (math.isfinite(v) and v > 0.0):
                raise ValueError(f"mujoco.{name} = {v!r}: must be finite and > 0")

    @classmethod
    def from_dict(cls, data: Mapping[str, Any] | None) -> SceneSpec:
        return _build(cls, data or {}, "mujoco")

    @property
    def half_width(self) -> float:
        """Half the object's extent along the grasp axis [m]."""
        return self.size[0]

    def to_dict(self) -> dict[str, Any]:
        return dataclasses.asdict(self)


def _build(cls, data, where: str):
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


@functools.lru_cache(maxsize=32)
def _xi(k: float) -> float:
    return LimitSurface(k).xi


def spin_coefficient(params: ContactParams, f_n: float) -> float:
    """MuJoCo's torsional friction coefficient [m] at normal force f_n [N]: mu xi rho(f_n), so
    that its torsional capacity mu_spin f_n equals the patch's tau_max = mu xi rho f_n."""
    return params.mu * _xi(float(params.k)) * params.delta * max(float(f_n), 0.0) ** params.gamma


def _object_geom(spec: SceneSpec, center: tuple[float, float], mu: float) -> str:
    cy, cz = center
    common = f'name="object" pos="0 {cy} {cz}" friction="{mu} 0.005 0.0001" rgba="0.85 0.55 0.2 1"'
    if spec.shape == "box":
        hx, hy, hz = spec.size
        return f'<geom {common} type="box" size="{hx} {hy} {hz}"/>'
    r, half = spec.size
    euler = "0 0 0" if spec.axis == "vertical" else "90 0 0"
    return f'<geom {common} type="cylinder" size="{r} {half}" euler="{euler}"/>'


def _object_bottom(spec: SceneSpec, center_z: float) -> float:
    """Height of the object's lowest point below its grasp point [m] (upright pose)."""
    if spec.shape == "box":
        return center_z - spec.size[2]
    r, half = spec.size
    return center_z - (half if spec.axis == "vertical" else r)


def build_scene(
    spec: SceneSpec,
    *,
    params: ContactParams,
    mass: float,
    inertia: float,
    cog: tuple[float, float],
    grasp_height: float = 0.1,
) -> mujoco.MjModel:
    """The MJCF model of one grasp: the object's grasp point on the grasp axis at
    `grasp_height` [m] (its CoG at `cog` = (horizontal, vertical) [m] from it), the pads
    `clearance` off its faces, the table under it.

    Bodies: ``object`` (joints ox, oy, oz, otheta), ``hand`` (hy, hz, hroll: position servos),
    ``finger0/1`` (f0, f1: force motors m0, m1), ``pad0/1`` (in-plane slides and a twist hinge
    with springs). Contact pairs pad0/pad1 - object: condim 4, elliptic cone.
    """
    p = spec.pad
    hw = spec.half_width
    cy, cz = cog
    center = spec.geom_center if spec.geom_center is not None else (cy, cz)
    ox, oy, oz = spec.object_offset
    z0 = grasp_height
    bottom = z0 + oz + _object_bottom(spec, center[1])
    x_pad = hw + spec.clearance + p.radius  # finger body (pad centre) distance from the axis
    travel = hw + spec.clearance - spec.min_half_gap  # until the pad surface meets the stop
    i_obj = float(inertia)
    spin = spin_coefficient(params, 1.0)
    table = ""
    if spec.table:
        table = (
            f'<geom name="table" type="box" pos="0 0 {bottom - 0.01}" size="0.4 0.4 0.01" '
            f'friction="{spec.table_friction} 0.005 0.0001" rgba="0.6 0.6 0.65 1"/>'
        )
    pads = []
    for k, sign in ((0, -1.0), (1, 1.0)):
        # finger k's slide axis points inward (toward the object): +x for finger 0, -x for 1
        pads.append(
            f"""
      <body name="finger{k}" pos="{sign * x_pad} 0 0" gravcomp="1">
        <joint name="f{k}" type="slide" axis="{-sign} 0 0" damping="{spec.finger_damping}"
               limited="true" range="-0.01 {travel}"/>
        <inertial pos="0 0 0" mass="{spec.finger_mass}" diaginertia="1e-5 1e-5 1e-5"/>
        <geom type="box" pos="{sign * (p.radius + 0.006)} 0 0" size="0.005 0.012 0.02"
              contype="0" conaffinity="0" rgba="0.3 0.3 0.35 1"/>
        <body name="pad{k}" gravcomp="1">
          <joint name="p{k}y" type="slide" axis="0 1 0" stiffness="{p.tangential_stiffness}"
                 damping="{p.tangential_damping}"/>
          <joint name="p{k}z" type="slide" axis="0 0 1" stiffness="{p.tangential_stiffness}"
                 damping="{p.tangential_damping}"/>
          <joint name="p{k}t" type="hinge" axis="1 0 0" stiffness="{p.twist_stiffness}"
                 damping="{p.twist_damping}"/>
          <inertial pos="0 0 0" mass="{p.mass}"
                    diaginertia="{p.twist_inertia} {p.twist_inertia} {p.twist_inertia}"/>
          <geom name="pad{k}" type="sphere" size="{p.radius}" contype="0" conaffinity="0"
                rgba="0.2 0.4 0.8 1"/>
        </body>
      </body>"""
        )
    xml = f"""
<mujoco model="lugrip_gripper">
  <option timestep="{spec.timestep}" cone="{spec.cone}" noslip_iterations="{spec.noslip_iterations}"
          impratio="{spec.impratio}" integrator="implicitfast" gravity="0 0 -9.81"/>
  <visual>
    <global offwidth="640" offheight="480"/>
    <quality shadowsize="0"/>
    <headlight ambient="0.35 0.35 0.35" diffuse="0.5 0.5 0.5"/>
  </visual>
  <asset>
    <texture name="sky" type="skybox" builtin="gradient" rgb1="0.75 0.82 0.9" rgb2="0.35 0.4 0.5"
             width="64" height="64"/>
  </asset>
  <worldbody>
    <light pos="0.3 -0.4 0.6" dir="-0.3 0.4 -0.6" directional="true"/>
    <camera name="side" pos="0.36 0 {z0 + 0.07}" xyaxes="0 1 0 -0.15 0 1" fovy="45"/>
    {table}
    <body name="object" pos="{ox} {oy} {z0 + oz}">
      <joint name="ox" type="slide" axis="1 0 0"/>
      <joint name="oy" type="slide" axis="0 1 0"/>
      <joint name="oz" type="slide" axis="0 0 1"/>
      <joint name="otheta" type="hinge" axis="1 0 0"/>
      <inertial pos="0 {cy} {cz}" mass="{mass}" diaginertia="{i_obj} {i_obj} {i_obj}"/>
      {_object_geom(spec, center, params.mu)}
      <site name="grasp_point" pos="0 0 0" size="0.002" rgba="1 0 0 1"/>
    </body>
    <body name="hand" pos="0 0 {z0}" gravcomp="1">
      <joint name="hy" type="slide" axis="0 1 0" damping="50"/>
      <joint name="hz" type="slide" axis="0 0 1" damping="50"/>
      <joint name="hroll" type="hinge" axis="1 0 0" damping="2"/>
      <inertial pos="0 0 0" mass="2.0" diaginertia="1e-2 1e-2 1e-2"/>
      <geom type="box" pos="0 0 0.06" size="{x_pad + 0.02} 0.015 0.01" contype="0"
            conaffinity="0" rgba="0.3 0.3 0.35 1"/>
      {''.join(pads)}
    </body>
  </worldbody>
  <contact>
    <pair name="pair0" geom1="pad0" geom2="object" condim="4" friction="{params.mu} {params.mu} {spin} 0 0"
          solref="{p.solref[0]} {p.solref[1]}"/>
    <pair name="pair1" geom1="pad1" geom2="object" condim="4" friction="{params.mu} {params.mu} {spin} 0 0"
          solref="{p.solref[0]} {p.solref[1]}"/>
  </contact>
  <actuator>
    <motor name="m0" joint="f0" gear="1" ctrllimited="true" ctrlrange="0 {spec.force_range}"/>
    <motor name="m1" joint="f1" gear="1" ctrllimited="true" ctrlrange="0 {spec.force_range}"/>
    <position name="hy" joint="hy" kp="20000" kv="400"/>
    <position name="hz" joint="hz" kp="20000" kv="400"/>
    <position name="hroll" joint="hroll" kp="300" kv="4"/>
  </actuator>
</mujoco>
"""
    return mujoco.MjModel.from_xml_string(xml)


def pad_wrenches(m: mujoco.MjModel, d: mujoco.MjData, pad_geoms, object_geom: int) -> np.ndarray:
    """Per pad: (f_n, f_y, f_z, tau, n_contacts) of the wrench the object exerts on the pad:
    f_n along the pad's inward normal (+x for pad 0, -x for pad 1), the in-plane force in world
    y, z, and tau the torsional moment about the inward normal [N, N, N, N m, -]."""
    out = np.zeros((2, 5))
    f6 = np.zeros(6)
    for i in range(d.ncon):
        c = d.contact[i]
        g1, g2 = c.geom1, c.geom2
        for k in (0, 1):
            pad = pad_geoms[k]
            if not ((g1 == pad and g2 == object_geom) or (g2 == pad and g1 == object_geom)):
                continue
            mujoco.mj_contactForce(m, d, i, f6)
            frame = np.asarray(c.frame).reshape(3, 3)  # rows: normal (geom1 -> geom2), tangents
            f_on_2 = frame.T @ f6[:3]  # force geom1 exerts on geom2, world coordinates
            t_on_2 = f6[3] * frame[0]
            f_pad, t_pad = (f_on_2, t_on_2) if g2 == pad else (-f_on_2, -t_on_2)
            inward = 1.0 if k == 0 else -1.0
            out[k, 0] += -f_pad[0] * inward
            out[k, 1] += f_pad[1]
            out[k, 2] += f_pad[2]
            out[k, 3] += t_pad[0] * inward
            out[k, 4] += 1.0
    return out
