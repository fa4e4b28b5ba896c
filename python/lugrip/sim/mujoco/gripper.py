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

from ..._contact import LimitSurface
from ..._params import ContactParams
from .pad import Pad, PadSpec, pad_body_xml, pair_xml

__all__ = [
    "PAD_DEFAULTS",
    "SceneSpec",
    "WristMove",
    "build_scene",
    "pad_spec",
    "spin_coefficient",
]

#: The gripper's pads (lugrip.sim.mujoco.pad.PadSpec fields; the scenario's ``mujoco.pad``
#: overrides them): 12 mm hemispheres on 4 N/mm in-plane and 2 N m/rad twist springs. Their
#: damping is MuJoCo's implicit joint damping (``pad_damping``), not the pad's explicit one: a
#: held object on the twist springs is a lightly damped oscillator that the explicit damping
#: could not damp at a 1 ms step without making the pad unstable. The pad's 35 g (sensor
#: flange included) put its twist mode at 1000 rad/s, inside the 1 ms step's stability limit
#: for the explicit spring (with 10 g the held block spins off the pads).
PAD_DEFAULTS = {
    "radius": 0.012,
    "mass": 0.035,
    "k_slide": 4000.0,
    "k_twist": 2.0,
    "d_slide": 0.0,
    "d_twist": 0.0,
    "solref": (0.002, 1.0),
}


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
    #: PadSpec overrides of PAD_DEFAULTS (radius, mass, k_slide, k_twist, solref, ...)
    pad: dict = dataclasses.field(default_factory=dict)
    #: implicit damping of the pad springs: in-plane [N s/m], twist [N m s/rad]
    pad_damping: tuple[float, float] = (20.0, 0.05)
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
        if not isinstance(self.pad, Mapping):
            raise ValueError("mujoco.pad: expected a mapping of pad settings")  # noqa: TRY004 (file content)
        self.pad = dict(self.pad)
        bad = sorted(
            set(self.pad) - {f.name for f in dataclasses.fields(PadSpec)}
            | (set(self.pad) & {"name", "mu", "delta", "gamma", "xi"})
        )
        if bad:
            raise ValueError(
                f"mujoco.pad: unknown or fixed key(s) {', '.join(bad)} (mu and the contact "
                "radius law come from the scenario's contact)"
            )
        self.pad_damping = _vec(self.pad_damping, 2, "mujoco.pad_damping")
        if min(self.pad_damping) < 0.0:
            raise ValueError("mujoco.pad_damping: must be >= 0")
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
        raise ValueError(f"{where}: expected a mapping, got {type(data).__name__}")  # noqa: TRY004
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
    f = max(float(f_n), 0.05)  # the pad's f_n_floor
    return params.mu * _xi(float(params.k)) * params.delta * f**params.gamma


def pad_spec(spec: SceneSpec, params: ContactParams, k: int) -> PadSpec:
    """The PadSpec of pad k (0: at -x, 1: at +x): the gripper's pad with the object's mu and
    the contact radius law of `params`."""
    values = dict(PAD_DEFAULTS)
    values.update(spec.pad)
    if "solref" in values:
        values["solref"] = tuple(float(v) for v in values["solref"])
    return PadSpec(
        name=f"pad{k}",
        mu=float(params.mu),
        delta=float(params.delta),
        gamma=float(params.gamma),
        xi=_xi(float(params.k)),
        rgba=(0.2, 0.4, 0.8, 1.0),
        **values,
    )


#: pad frames (columns x, y, z in world coordinates; z from the face into the finger)
_PAD_FRAMES = (
    np.array([[0.0, 0.0, -1.0], [1.0, 0.0, 0.0], [0.0, -1.0, 0.0]]),  # pad 0, facing +x
    np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]),  # pad 1, facing -x
)


class _ScenePad(Pad):
    """The shared Pad with its contact lookup vectorised over MuJoCo's contact array (the
    per-contact loop was half the closed loop's time)."""

    def contacts(self, data) -> list[int]:
        n = data.ncon
        if n == 0:
            return []
        return np.flatnonzero((data.contact.geom[:n] == self.geom_id).any(axis=1)).tolist()


def _quat(R: np.ndarray) -> np.ndarray:
    q = np.zeros(4)
    mujoco.mju_mat2Quat(q, np.ascontiguousarray(R).reshape(-1))
    return q


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
) -> tuple[mujoco.MjModel, list[Pad]]:
    """The MJCF model of one grasp: the object's grasp point on the grasp axis at
    `grasp_height` [m] (its CoG at `cog` = (horizontal, vertical) [m] from it), the pads
    `clearance` off its faces, the table (a plane) under it.

    Bodies: ``object`` (joints ox, oy, oz, otheta), ``hand`` (hy, hz, hroll: position servos),
    ``finger0/1`` (f0, f1: force motors m0, m1), ``pad0/1`` (pad0_x, pad0_y, pad0_twist: in-plane
    slides and a twist hinge about the pad normal
    with springs, lugrip.sim.mujoco.pad). Contact pairs pad0/pad1 - object: condim 4,
    elliptic cone. Returns (model, [Pad 0, Pad 1]).
    """
    pads_spec = [pad_spec(spec, params, k) for k in (0, 1)]
    r = pads_spec[0].radius
    hw = spec.half_width
    cy, cz = cog
    center = spec.geom_center if spec.geom_center is not None else (cy, cz)
    ox, oy, oz = spec.object_offset
    z0 = grasp_height
    bottom = z0 + oz + _object_bottom(spec, center[1])
    x_face = hw + spec.clearance  # the pad faces' distance from the grasp axis at t = 0
    travel = hw + spec.clearance - spec.min_half_gap  # until the pad face meets the stop
    i_obj = float(inertia)
    table = ""
    if spec.table:
        # A plane, not a box: every contact of the scene (table-object, pad sphere-object) then
        # goes through one of MuJoCo's closed-form colliders (plane-box, plane-cylinder,
        # sphere-box, sphere-cylinder), which compute the same contacts from 3.2 to 4.x. On a
        # box table a cylinder goes through convex collision detection, whose defaults changed
        # (native CCD from 3.3; multiccd from 3.8: one contact under a lying cylinder before),
        # and the box-box collider changed its depth in 3.4 and was rewritten in 3.12
        # (docs/simulation.md).
        table = (
            f'<geom name="table" type="plane" pos="0 0 {bottom}" size="0.4 0.4 0.01" '
            f'friction="{spec.table_friction} 0.005 0.0001" rgba="0.6 0.6 0.65 1"/>'
        )
    pads = []
    for k, sign in ((0, -1.0), (1, 1.0)):
        # finger k's slide axis points inward (toward the object): +x for finger 0, -x for 1
        q = " ".join(f"{v:.12g}" for v in _quat(_PAD_FRAMES[k]))
        pads.append(
            f"""
      <body name="finger{k}" pos="{sign * x_face} 0 0" gravcomp="1">
        <joint name="f{k}" type="slide" axis="{-sign} 0 0" damping="{spec.finger_damping}"
               limited="true" range="-0.01 {travel}"/>
        <inertial pos="0 0 0" mass="{spec.finger_mass}" diaginertia="1e-5 1e-5 1e-5"/>
        <geom type="box" pos="{sign * (2 * r + 0.005)} 0 0" size="0.005 0.012 0.02"
              contype="0" conaffinity="0" rgba="0.3 0.3 0.35 1"/>
        {pad_body_xml(pads_spec[k], quat=[float(v) for v in q.split()])}
      </body>"""
        )
    pairs = "".join(pair_xml(ps, ["object"]) for ps in pads_spec)
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
      <geom type="box" pos="0 0 0.06" size="{x_face + 2 * r + 0.02} 0.015 0.01" contype="0"
            conaffinity="0" rgba="0.3 0.3 0.35 1"/>
      {"".join(pads)}
    </body>
  </worldbody>
  <contact>{pairs}</contact>
  <actuator>
    <motor name="m0" joint="f0" gear="1" ctrllimited="true" ctrlrange="0 {spec.force_range}"/>
    <motor name="m1" joint="f1" gear="1" ctrllimited="true" ctrlrange="0 {spec.force_range}"/>
    <position name="hy" joint="hy" kp="20000" kv="400"/>
    <position name="hz" joint="hz" kp="20000" kv="400"/>
    <position name="hroll" joint="hroll" kp="300" kv="4"/>
  </actuator>
</mujoco>
"""
    m = mujoco.MjModel.from_xml_string(xml)
    # the pad springs' damping, implicit (see PAD_DEFAULTS)
    for k in (0, 1):
        for j, value in zip(
            pads_spec[k].joint_names, (spec.pad_damping[0],) * 2 + (spec.pad_damping[1],)
        ):
            m.dof_damping[m.joint(j).dofadr[0]] = value
    return m, [_ScenePad(m, ps) for ps in pads_spec]
