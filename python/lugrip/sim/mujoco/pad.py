"""A compliant fingertip pad for MuJoCo models, its torsional-friction law and its sensor.

The pad is a body of its own, attached to the finger body that carries it by three spring
joints: two slides in the pad plane and a twist hinge about the pad normal. Its geom (a sphere
whose front hemisphere touches, or a flat round disc) collides only through explicit contact
pairs with condim 4 (tangential and torsional friction) on an elliptic cone.

MuJoCo's torsional capacity of a point contact is mu_spin f_n with a constant coefficient
mu_spin [m]. :class:`Pad` updates that coefficient before every step from the normal force of
the step before, mu_spin = mu xi rho(f_n) with rho = delta f_n^gamma, so that the pad's
torsional capacity follows tau_max = mu xi delta f_n^(gamma + 1) (docs/model.md §2.1).

Pad frame (the fingertip sensor's frame, as in docs/sliding_log.md): origin on the pad axis at
the pad face, z along the pad axis from the face into the finger (the direction of the normal
force the object exerts on the pad), x and y in the pad plane, right-handed. The pad body's own
frame is this frame; :meth:`Pad.wrench` returns what the object exerts on the pad in it.

    >>> import mujoco
    >>> spec = PadSpec(name="pad")
    >>> finger = ('<body name="finger" pos="0 0 0.0005">'
    ...           '<joint name="press" type="slide" axis="0 0 1" damping="5"/>'
    ...           '<inertial pos="0 0 0" mass="0.05" diaginertia="1e-5 1e-5 1e-5"/>'
    ...           + pad_body_xml(spec) + "</body>")
    >>> slider = '<geom name="slider" type="box" size="0.05 0.05 0.01" pos="0 0 -0.01"/>'
    >>> xml = model_xml(finger + slider, pairs=pair_xml(spec, ["slider"]),
    ...                 actuators='<motor joint="press" gear="1"/>', gravity=(0, 0, 0))
    >>> m = mujoco.MjModel.from_xml_string(xml); d = mujoco.MjData(m); pad = Pad(m, spec)
    >>> for _ in range(300):
    ...     d.ctrl[0] = -2.0                  # press the pad down with 2 N
    ...     _ = pad.update(m, d); mujoco.mj_step(m, d)
    >>> [round(float(x), 6) for x in pad.wrench(m, d)]
    [2.0, 0.0, 0.0, 0.0]
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

import numpy as np

__all__ = [
    "CONTACT_OPTIONS",
    "FingertipSensor",
    "Pad",
    "PadSpec",
    "contact_options_xml",
    "model_xml",
    "pad_body_xml",
    "pair_xml",
]

#: MuJoCo options every fingertip model of the project uses. The elliptic cone couples the
#: tangential and torsional friction (one friction limit, not a pyramid per direction); the
#: noslip post-solver removes the creep of MuJoCo's soft friction constraint, without which
#: a loaded contact below its friction limit slides slowly (validation/mujoco/README.md);
#: impratio > 1 makes the friction rows stiffer than the normal row; 1 ms is the robot's step.
CONTACT_OPTIONS: dict[str, object] = {
    "timestep": 0.001,  #: [s]
    "cone": "elliptic",
    "noslip_iterations": 10,  #: >= 5 required
    "impratio": 10.0,
    "integrator": "implicitfast",  #: the pad springs' damping integrated implicitly
}

#: the contact dimensionality of every pad pair: normal, two tangential, torsional
CONDIM = 4


def contact_options_xml(gravity: Sequence[float] = (0.0, 0.0, -9.81), **overrides) -> str:
    """The MJCF ``<option>`` element with :data:`CONTACT_OPTIONS` (keys may be overridden)."""
    opts = dict(CONTACT_OPTIONS)
    unknown = set(overrides) - set(opts)
    if unknown:
        raise ValueError(f"unknown MuJoCo option(s): {sorted(unknown)}")
    opts.update(overrides)
    if int(opts["noslip_iterations"]) < 5:
        raise ValueError("noslip_iterations must be >= 5 for fingertip contacts")
    if opts["cone"] != "elliptic":
        raise ValueError("fingertip contacts need cone='elliptic'")
    attrs = " ".join(f'{k}="{v}"' for k, v in opts.items())
    g = " ".join(f"{x:g}" for x in gravity)
    return f'<option {attrs} gravity="{g}"/>'


@dataclass(frozen=True)
class PadSpec:
    """Geometry, compliance and friction law of one fingertip pad."""

    name: str = "pad"  #: prefix of the pad's MJCF names (body, joints, geom, pairs)
    shape: str = "sphere"  #: "sphere" (hemispherical pad) or "disc" (flat round pad)
    radius: float = 0.012  #: sphere radius or disc radius [m]
    thickness: float = 0.004  #: disc thickness [m] (sphere: unused)
    mass: float = 0.005  #: pad body mass [kg]
    k_slide: float = 2000.0  #: in-plane stiffness of each slide joint [N/m]
    d_slide: float = 4.0  #: in-plane damping [N s/m]
    k_twist: float = 0.1  #: twist stiffness about the pad normal [N m/rad]
    d_twist: float = 2.5e-4  #: twist damping [N m s/rad]
    mu: float = 0.7  #: Coulomb friction coefficient of the pad pairs [-]
    delta: float = 1.8e-3  #: contact radius law rho = delta f_n^gamma [m / N^gamma]
    gamma: float = 0.254  #: contact radius exponent [-]
    xi: float = 0.6354098135954843  #: torsional shape factor, tau_max = mu xi rho f_n [-] (k = 4)
    f_n_floor: float = 0.05  #: the law is evaluated at max(f_n, f_n_floor) [N]
    #: pair solref: time constant [s] (>= 2 MuJoCo steps), damping ratio; a soft normal lets
    #: the stuck pad creep tangentially
    solref: tuple[float, float] = (0.002, 1.0)
    solimp: tuple[float, ...] = (0.95, 0.99, 0.001, 0.5, 2.0)  #: pair solimp (MuJoCo's meaning)
    rgba: tuple[float, float, float, float] = (0.2, 0.2, 0.2, 1.0)  #: display colour

    def __post_init__(self) -> None:
        if self.shape not in ("sphere", "disc"):
            raise ValueError(f"PadSpec.shape must be 'sphere' or 'disc', not {self.shape!r}")
        positive = ("radius", "thickness", "mass", "k_slide", "k_twist", "mu", "delta", "f_n_floor")
        for name in positive:
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise ValueError(f"PadSpec.{name} must be finite and > 0, got {v!r}")
        for name in ("d_slide", "d_twist"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v >= 0):
                raise ValueError(f"PadSpec.{name} must be finite and >= 0, got {v!r}")
        if not (0.0 <= self.gamma < 1.0):
            raise ValueError(f"PadSpec.gamma must be in [0, 1), got {self.gamma!r}")
        if not (0.0 < self.xi <= 2.0 / 3.0):
            raise ValueError(f"PadSpec.xi must be in (0, 2/3], got {self.xi!r}")
        if not self.name.replace("_", "").isalnum():
            raise ValueError(f"PadSpec.name must be alphanumeric (and '_'), got {self.name!r}")

    # --- the torsional law -------------------------------------------------------------------
    def contact_radius(self, f_n):
        """rho(f_n) = delta max(f_n, f_n_floor)^gamma [m]."""
        return self.delta * np.maximum(f_n, self.f_n_floor) ** self.gamma

    def spin_coefficient(self, f_n):
        """MuJoCo's torsional friction coefficient mu xi rho(f_n) [m]."""
        return self.mu * self.xi * self.contact_radius(f_n)

    def tau_max(self, f_n):
        """The pad's torsional capacity in pure rotation, mu xi delta f_n^(gamma+1) [N m]."""
        return self.spin_coefficient(f_n) * np.maximum(f_n, 0.0)

    # --- names -------------------------------------------------------------------------------
    @property
    def body_name(self) -> str:
        return f"{self.name}"

    @property
    def geom_name(self) -> str:
        return f"{self.name}_geom"

    @property
    def joint_names(self) -> tuple[str, str, str]:
        """(slide along pad x, slide along pad y, twist about pad z)."""
        return (f"{self.name}_x", f"{self.name}_y", f"{self.name}_twist")

    def pair_name(self, other_geom: str) -> str:
        return f"{self.name}__{other_geom}"

    def inertia(self) -> tuple[float, float, float]:
        """Diagonal inertia of the pad body about its geom centre [kg m^2]."""
        m, r = self.mass, self.radius
        if self.shape == "sphere":
            i = 0.4 * m * r * r
            return (i, i, i)
        h = self.thickness
        ixy = m * (3 * r * r + h * h) / 12.0
        return (ixy, ixy, 0.5 * m * r * r)


def _fmt(v: Iterable[float]) -> str:
    return " ".join(f"{x:.10g}" for x in v)


def pad_body_xml(spec: PadSpec, pos: Sequence[float] = (0.0, 0.0, 0.0), quat=None) -> str:
    """The MJCF ``<body>`` of the pad, to be placed inside its finger's body.

    ``pos``/``quat`` place the pad frame in the finger's frame; the pad frame's -z points out
    of the face toward the object. The geom's face (its front-most point) is at the pad
    frame's origin, the geom extends toward +z (into the finger).
    """
    q = "" if quat is None else f' quat="{_fmt(quat)}"'
    jx, jy, jt = spec.joint_names
    ixx, iyy, izz = spec.inertia()
    if spec.shape == "sphere":
        centre = (0.0, 0.0, spec.radius)
        geom = f'type="sphere" size="{spec.radius:.10g}"'
    else:
        centre = (0.0, 0.0, 0.5 * spec.thickness)
        geom = f'type="cylinder" size="{spec.radius:.10g} {0.5 * spec.thickness:.10g}"'
    return (
        f'<body name="{spec.body_name}" pos="{_fmt(pos)}"{q}>'
        f'<joint name="{jx}" type="slide" axis="1 0 0" stiffness="{spec.k_slide:.10g}"/>'
        f'<joint name="{jy}" type="slide" axis="0 1 0" stiffness="{spec.k_slide:.10g}"/>'
        f'<joint name="{jt}" type="hinge" axis="0 0 1" stiffness="{spec.k_twist:.10g}"/>'
        f'<inertial pos="{_fmt(centre)}" mass="{spec.mass:.10g}" '
        f'diaginertia="{ixx:.10g} {iyy:.10g} {izz:.10g}"/>'
        f'<geom name="{spec.geom_name}" {geom} pos="{_fmt(centre)}" contype="0" '
        f'conaffinity="0" rgba="{_fmt(spec.rgba)}"/>'
        "</body>"
    )


def pair_xml(spec: PadSpec, other_geoms: Sequence[str], f_n0: float = 1.0) -> str:
    """The ``<pair>`` elements between the pad and each named geom (condim 4, the pad's mu,
    torsional coefficient at ``f_n0`` until :meth:`Pad.update` sets it, no rolling friction).
    MuJoCo's compiler may swap geom1 and geom2; :meth:`Pad.wrench` handles either order."""
    spin = float(spec.spin_coefficient(f_n0))
    out = []
    for g in other_geoms:
        out.append(
            f'<pair name="{spec.pair_name(g)}" geom1="{spec.geom_name}" geom2="{g}" '
            f'condim="{CONDIM}" friction="{spec.mu:.10g} {spec.mu:.10g} {spin:.10g} 0 0" '
            f'solref="{_fmt(spec.solref)}" solimp="{_fmt(spec.solimp)}"/>'
        )
    return "".join(out)


def model_xml(
    bodies: str,
    pairs: str = "",
    actuators: str = "",
    name: str = "lugrip_pad",
    extra: str = "",
    **options,
) -> str:
    """A complete MJCF document: :func:`contact_options_xml` (``options`` override it), the
    world bodies, the contact pairs, the actuators and any ``extra`` top-level elements."""
    return (
        f'<mujoco model="{name}">{contact_options_xml(**options)}'
        f"<worldbody>{bodies}</worldbody>"
        f"<contact>{pairs}</contact>"
        f"<actuator>{actuators}</actuator>{extra}</mujoco>"
    )


@dataclass
class FingertipSensor:
    """A fingertip force/torque sensor: white noise and a constant offset on each channel.

    Channels are (f_n, f_x, f_y, tau) in the pad frame [N, N, N, N m].
    """

    force_noise: float = 0.01  #: standard deviation of f_n, f_x, f_y [N]
    torque_noise: float = 2e-5  #: standard deviation of tau [N m]
    offset: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)  #: bias per channel
    rng: np.random.Generator = field(default_factory=lambda: np.random.default_rng(0))

    def read(self, wrench: np.ndarray) -> np.ndarray:
        """``wrench`` (..., 4) plus offset and noise; a new array."""
        w = np.asarray(wrench, dtype=float)
        sd = np.array([self.force_noise] * 3 + [self.torque_noise])
        return w + np.asarray(self.offset, dtype=float) + self.rng.normal(0.0, 1.0, w.shape) * sd


class Pad:
    """One pad in a compiled MuJoCo model: its torsional law and its sensor wrench.

    ``Pad(model, spec)`` finds the pad's body, geom and pairs by their names. Each step::

        pad.update(model, data)     # torsional coefficient, the springs' damping
        mujoco.mj_step(model, data)
        w = pad.wrench(model, data) # (f_n, f_x, f_y, tau) on the pad, pad frame
    """

    def __init__(self, model, spec: PadSpec):
        import mujoco

        self.spec = spec
        self._mj = mujoco
        self.body_id = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, spec.body_name)
        self.geom_id = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, spec.geom_name)
        if self.body_id < 0 or self.geom_id < 0:
            raise ValueError(f"pad {spec.name!r} is not in the model (build it with pad_body_xml)")
        self.pair_ids = np.array(
            [
                i
                for i in range(model.npair)
                if self.geom_id in (model.pair_geom1[i], model.pair_geom2[i])
            ],
            dtype=int,
        )
        if self.pair_ids.size == 0:
            raise ValueError(f"pad {spec.name!r} has no contact pair (add pair_xml to <contact>)")
        if model.opt.cone != mujoco.mjtCone.mjCONE_ELLIPTIC:
            raise ValueError("pad contacts need an elliptic friction cone")
        if model.opt.noslip_iterations < 5:
            raise ValueError("pad contacts need noslip_iterations >= 5")
        self.joint_qpos = np.array([model.joint(j).qposadr[0] for j in spec.joint_names], dtype=int)
        self.joint_dof = np.array([model.joint(j).dofadr[0] for j in spec.joint_names], dtype=int)
        self._damping = np.array([spec.d_slide, spec.d_slide, spec.d_twist])
        # explicit damping is stable while d h / m < 2 for each dof (checked with margin)
        h = float(model.opt.timestep)
        m_dof = model.dof_M0[self.joint_dof] if hasattr(model, "dof_M0") else None
        mass = np.array([spec.mass, spec.mass, spec.inertia()[2]])
        if m_dof is not None and np.all(m_dof > 0):
            mass = np.minimum(mass, m_dof)
        if np.any(self._damping * h / mass > 1.5):
            raise ValueError(
                f"pad {spec.name!r}: damping too large for explicit integration at "
                f"{h:g} s (d h / m = {np.max(self._damping * h / mass):.2f} > 1.5)"
            )
        self._f6 = np.zeros(6)
        self.f_n_last = 0.0  #: normal force of the last wrench() call [N]
        self._spin_set = float("nan")
        self._jac: tuple[np.ndarray, np.ndarray] | None = None

    def update(self, model, data=None, f_n: float | None = None) -> float:
        """Before each ``mj_step``: set the pairs' torsional coefficient from ``f_n`` (default:
        the pad's normal force in ``data``'s present contacts) and apply the pad springs'
        damping as explicit joint forces (``data.qfrc_applied`` of the pad's three dofs).
        Returns the coefficient [m].

        The damping is explicit because MuJoCo integrates joint damping implicitly after the
        constraint solve, which gives a stuck pad a small slip velocity (a creep of tens of
        micrometres per second under load, even with noslip)."""
        if f_n is None:
            f_n = self._normal_force(model, data) if data is not None else self.f_n_last
        spin = float(self.spec.spin_coefficient(f_n))
        if spin != self._spin_set:
            model.pair_friction[self.pair_ids, 2] = spin
            self._spin_set = spin
        if data is not None:
            data.qfrc_applied[self.joint_dof] = -self._damping * data.qvel[self.joint_dof]
        return spin

    def frame(self, data) -> tuple[np.ndarray, np.ndarray]:
        """(origin, R) of the pad frame in world coordinates; columns of R are x, y, z."""
        return data.xpos[self.body_id].copy(), data.xmat[self.body_id].reshape(3, 3).copy()

    def contacts(self, data) -> list[int]:
        """Indices of the present contacts that involve the pad's geom."""
        g = self.geom_id
        return [
            i for i in range(data.ncon) if data.contact[i].geom1 == g or data.contact[i].geom2 == g
        ]

    def _normal_force(self, model, data) -> float:
        total = 0.0
        for i in self.contacts(data):
            self._mj.mj_contactForce(model, data, i, self._f6)
            total += self._f6[0]
        return total

    def wrench(self, model, data) -> np.ndarray:
        """(f_n, f_x, f_y, tau): the wrench the object exerts on the pad, in the pad frame
        [N, N, N, N m], its moment taken about the centre of pressure of the pad's contacts
        (with one contact: the contact point). Zero without contact."""
        _, R = self.frame(data)
        force = np.zeros(3)
        moment = np.zeros(3)
        points = []
        for i in self.contacts(data):
            c = data.contact[i]
            self._mj.mj_contactForce(model, data, i, self._f6)
            basis = np.asarray(c.frame).reshape(3, 3)  # rows: normal (geom1 -> geom2), tangents
            f_on_geom2 = basis.T @ self._f6[:3]
            spin_on_geom2 = self._f6[3] * basis[0]
            sign = -1.0 if c.geom1 == self.geom_id else 1.0  # reaction when the pad is geom1
            f = sign * f_on_geom2
            force += f
            moment += sign * spin_on_geom2
            points.append((np.asarray(c.pos, dtype=float).copy(), f))
        out = np.zeros(4)
        if not points:
            self.f_n_last = 0.0
            return out
        if len(points) > 1:
            # moment of the contact forces about their centre of pressure
            weights = np.array([max(float(f @ R[:, 2]), 0.0) for _, f in points])
            ps = np.array([p for p, _ in points])
            cop = (weights @ ps) / weights.sum() if weights.sum() > 0 else ps.mean(axis=0)
            for p, f in points:
                moment += np.cross(p - cop, f)
        local_f = R.T @ force
        out[0] = local_f[2]
        out[1] = local_f[0]
        out[2] = local_f[1]
        out[3] = float(moment @ R[:, 2])
        self.f_n_last = float(out[0])
        return out

    def slip_velocity(self, model, data) -> np.ndarray:
        """(v_x, v_y, omega) of the object relative to the pad at the pad frame's origin, in
        the pad frame [m/s, m/s, rad/s]; NaN without contact. The object is the other geom of
        the first present contact.

        Called after ``mj_step``: the present ``qvel`` (the velocity the step's contact forces
        produced) through the body Jacobians of the step's own forward pass, i.e. the slip
        velocity that the step's constraint solve acted on (``mj_objectVelocity`` would give
        the velocity before the step).
        """
        idx = self.contacts(data)
        if not idx:
            return np.full(3, np.nan)
        c = data.contact[idx[0]]
        other = c.geom2 if c.geom1 == self.geom_id else c.geom1
        other_body = int(model.geom_bodyid[other])
        o, R = self.frame(data)
        mj = self._mj
        if self._jac is None or self._jac[0].shape[1] != model.nv:
            self._jac = (np.zeros((3, model.nv)), np.zeros((3, model.nv)))
        jp, jr = self._jac
        mj.mj_jac(model, data, jp, jr, o, self.body_id)
        v_pad, w_pad = jp @ data.qvel, jr @ data.qvel
        if other_body == 0:
            v_obj = w_obj = np.zeros(3)
        else:
            mj.mj_jac(model, data, jp, jr, o, other_body)  # the object's point at the pad origin
            v_obj, w_obj = jp @ data.qvel, jr @ data.qvel
        rel_v = R.T @ (v_obj - v_pad)
        rel_w = R.T @ (w_obj - w_pad)
        return np.array([rel_v[0], rel_v[1], rel_w[2]])
