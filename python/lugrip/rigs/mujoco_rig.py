"""A MuJoCo rubbing rig: a compliant fingertip pad driven over a fixed slider.

The plant is MuJoCo's contact solver, not lugrip's model. A rigid mount (the robot's finger
base) moves in the slider plane with a **prescribed** planar motion about a centre of
rotation fixed in the finger frame (the maneuvers of :mod:`lugrip.rigs.motion`); a force motor
on a normal slide presses the finger with the planned normal force; the pad
(:mod:`lugrip.sim.mujoco.pad`) hangs from the finger on its in-plane and twist springs and
touches the slider through one condim-4 contact on an elliptic cone, with noslip. The wrench
therefore builds up through presliding (the pad's springs deflect while the pad sticks) before
the contact slides, and stays loaded after the motion stops.

Friction is Coulomb only (mu, no Stribeck, no viscous term). MuJoCo's elliptic cone bounds the
contact wrench by (f_t / (mu f_n))^2 + (tau / tau_max(f_n))^2 <= 1, with
tau_max = mu xi delta f_n^(gamma + 1) set by the pad's per-step torsional law: the limit
surface is an ellipse in the normalised (f_t, tau) plane (docs: validation/mujoco/README.md).

    >>> from lugrip.rigs import RubbingDesign
    >>> from lugrip.rigs.mujoco_rig import MujocoRubbingRig
    >>> data = MujocoRubbingRig().simulate(RubbingDesign(), n=2, seed=1)   # doctest: +SKIP
"""

from __future__ import annotations

import dataclasses
import math
import time
import warnings
from dataclasses import asdict, dataclass

import numpy as np

from ..io import SlidingLog
from ..sim.mujoco.pad import CONTACT_OPTIONS, Pad, PadSpec, model_xml, pad_body_xml, pair_xml
from ._data import RigTruth, RubbingData
from .motion import ManeuverPlan, RubbingDesign, plan_maneuvers, stack_times

__all__ = ["MujocoRubbingRig", "RigSettings", "mount_pose", "mount_poses"]

#: :meth:`MujocoRubbingRig.simulate` warns when the true normal force departs from the plan
#: by more than _BOUNCE (relative) on more than _BOUNCE_SHARE of a maneuver's moving samples
#: (a stick-slip transition alone kicks it for a sample or two)
_BOUNCE = 0.1
_BOUNCE_SHARE = 0.02


def _default_pad() -> PadSpec:
    return PadSpec(name="pad", mu=0.7)


@dataclass(frozen=True)
class RigSettings:
    """Mechanics of the rig around the pad (SI units)."""

    finger_mass: float = 0.02  #: mass on the normal slide between mount and pad [kg]
    normal_damping: float = 1.0  #: damping of the normal slide [N s/m]
    #: mount mass [kg]: its motion is prescribed (position and velocity set before every step);
    #: heavy, so that the springs' reaction within a step does not change its velocity
    mount_mass: float = 1e4
    settle: float = 0.05  #: pressed settling time before each maneuver, not logged [s]
    cone_tolerance: float = 1e-3  #: gross sliding: cone utilisation >= 1 - this [-]
    slip_speed: float = 1e-4  #: gross sliding: slip speed |v| + |omega| rho above this [m/s]
    noslip_iterations: int = int(CONTACT_OPTIONS["noslip_iterations"])  #: MuJoCo noslip
    #: MuJoCo impratio: 1, not the fingertip models' 10: with noslip holding the stuck pad,
    #: a stiffer friction row only couples the sliding pad's friction into its normal force
    #: (stick-slip and normal kicks at low f_n; validation/mujoco/README.md)
    impratio: float = 1.0
    timestep: float = float(CONTACT_OPTIONS["timestep"])  #: MuJoCo step [s]
    #: MuJoCo's implicit joint damping of the pad springs, (in-plane [N s/m], twist
    #: [N m s/rad]), in place of the pad's explicit d_slide / d_twist; None: the pad's own
    pad_damping: tuple[float, float] | None = None

    def __post_init__(self) -> None:
        if self.pad_damping is not None:
            pd = tuple(float(v) for v in self.pad_damping)
            if len(pd) != 2 or not all(math.isfinite(v) and v >= 0 for v in pd):
                raise ValueError(
                    f"RigSettings.pad_damping must be two finite numbers >= 0, got "
                    f"{self.pad_damping!r}"
                )
            object.__setattr__(self, "pad_damping", pd)
        for name in ("finger_mass", "mount_mass", "slip_speed", "timestep", "impratio"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise ValueError(f"RigSettings.{name} must be finite and > 0, got {v!r}")
        for name in ("normal_damping", "settle"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v >= 0):
                raise ValueError(f"RigSettings.{name} must be finite and >= 0, got {v!r}")
        if not (0.0 < self.cone_tolerance < 0.5):
            raise ValueError(
                f"RigSettings.cone_tolerance must be in (0, 0.5), got {self.cone_tolerance!r}"
            )
        if self.timestep > 0.002:
            raise ValueError(f"RigSettings.timestep must be <= 2 ms, got {self.timestep!r}")


def _theta_segments(plan: ManeuverPlan):
    """Cumulative pad angle at the knots of the plan's angular-velocity profile [rad]."""
    kt, kw = np.asarray(plan.knots_t), np.asarray(plan.knots_omega)
    span = np.diff(kt)
    # integral of kw_j + (kw_j+1 - kw_j) (1 - cos(pi x)) / 2 over one segment: the mean value
    seg = span * 0.5 * (kw[:-1] + kw[1:])
    return kt, kw, np.concatenate([[0.0], np.cumsum(seg)])


def _theta_at(t: float, kt, kw, cum) -> float:
    """The pad's angle relative to the slider at time t: the integral of omega_pad [rad]."""
    if t <= kt[0]:
        return kw[0] * (t - kt[0])
    if t >= kt[-1]:
        return cum[-1] + kw[-1] * (t - kt[-1])
    j = int(np.searchsorted(kt, t, side="right") - 1)
    span = kt[j + 1] - kt[j]
    x = (t - kt[j]) / span
    dw = kw[j + 1] - kw[j]
    return cum[j] + span * (kw[j] * x + dw * (0.5 * x - math.sin(math.pi * x) / (2 * math.pi)))


def _theta_many(t: np.ndarray, kt, kw, cum) -> np.ndarray:
    """:func:`_theta_at` at many times (the same closed form, vectorised) [rad]."""
    t = np.asarray(t, dtype=float)
    j = np.clip(np.searchsorted(kt, t, side="right") - 1, 0, len(kt) - 2)
    span = kt[j + 1] - kt[j]
    x = np.clip((t - kt[j]) / span, 0.0, 1.0)
    dw = kw[j + 1] - kw[j]
    inner = cum[j] + span * (kw[j] * x + dw * (0.5 * x - np.sin(np.pi * x) / (2 * np.pi)))
    before = kw[0] * (t - kt[0])
    after = cum[-1] + kw[-1] * (t - kt[-1])
    return np.where(t <= kt[0], before, np.where(t >= kt[-1], after, inner))


def mount_poses(cor: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """(n, 3) planar poses (x, y, theta) of :func:`mount_pose` for many angles."""
    c, s = np.cos(theta), np.sin(theta)
    cx, cy = float(cor[0]), float(cor[1])
    return np.stack([cx - (c * cx - s * cy), cy - (s * cx + c * cy), theta], axis=1)


def mount_pose(cor: np.ndarray, theta: float, omega: float) -> tuple[np.ndarray, np.ndarray]:
    """Planar pose (x, y, theta) and its rate of a mount turning by ``theta`` at ``omega``
    about the point ``cor`` of its own frame, starting at the origin with theta = 0: the
    mount-frame point ``cor`` stays where it was at the start."""
    c, s = math.cos(theta), math.sin(theta)
    cx, cy = float(cor[0]), float(cor[1])
    rc = np.array([c * cx - s * cy, s * cx + c * cy])  # R(theta) cor
    pos = np.array([cx - rc[0], cy - rc[1], theta])
    # d/dt (cor - R cor) = -omega J R cor, J = rotation by +90 deg
    vel = np.array([omega * rc[1], -omega * rc[0], omega])
    return pos, vel


class MujocoRubbingRig:
    """A fingertip pad on a compliant mount rubbing a fixed slider in MuJoCo.

    Attributes:
        pad: the pad (its mu is the plant's Coulomb coefficient, its delta/gamma/xi the
            torsional law).
        settings: the rig's mechanics and MuJoCo options.
    """

    name = "mujoco"

    def __init__(
        self, mu: float = 0.7, pad: PadSpec | None = None, settings: RigSettings | None = None
    ):
        """``pad``: the pad (default: PadSpec with mu 0.7); a ``mu`` other than 0.7 replaces
        the pad's. ``settings``: the rig's mechanics (default RigSettings())."""
        base = pad if pad is not None else _default_pad()
        if pad is None or mu != 0.7:
            base = dataclasses.replace(base, mu=float(mu))
        self.pad = base
        self.settings = settings if settings is not None else RigSettings()
        self._model = None

    # --- the plant's truth ---------------------------------------------------------------------
    def radius(self, f_n):
        """The pad law's contact radius rho = delta f_n^gamma [m]."""
        return self.pad.contact_radius(f_n)

    def truth(self) -> RigTruth:
        """mu, the torsional law and what the plant does not model."""
        p = self.pad
        forces = (0.25, 0.5, 1.0, 2.0, 4.0, 8.0, 12.0, 16.0, 24.0)
        return RigTruth.coulomb(
            "mujoco",
            p.mu,
            delta=p.delta,
            gamma=p.gamma,
            pressure=(
                "none: one point contact (MuJoCo soft contact, condim 4, elliptic cone); "
                "the torsional capacity follows mu xi delta f_n^(gamma+1), "
                f"xi = {p.xi:.6g}"
            ),
            tau_max_points=tuple((f, float(p.tau_max(f))) for f in forces),
            notes=(
                "Coulomb friction only. Limit surface: the ellipse (f_t/(mu f_n))^2 + "
                "(tau/tau_max)^2 = 1. Presliding from the pad's springs: in-plane "
                f"{p.k_slide:g} N/m, twist {p.k_twist:g} N m/rad."
            ),
        )

    # --- the model -----------------------------------------------------------------------------
    def model_xml(self) -> str:
        """The MJCF: a slider plane (top at z = 0), the mount on planar joints (x, y, yaw),
        the finger on a normal slide with a force motor, the pad facing down."""
        s, p = self.settings, self.pad
        im = s.mount_mass * 0.01
        fi = s.finger_mass * 1e-4
        bodies = (
            '<geom name="slider" type="plane" size="0.3 0.3 0.01" rgba="0.7 0.7 0.6 1"/>'
            '<body name="mount" pos="0 0 0">'
            '<joint name="mount_x" type="slide" axis="1 0 0"/>'
            '<joint name="mount_y" type="slide" axis="0 1 0"/>'
            '<joint name="mount_theta" type="hinge" axis="0 0 1"/>'
            f'<inertial pos="0 0 0.05" mass="{s.mount_mass:g}" diaginertia="{im:g} {im:g} {im:g}"/>'
            '<body name="finger" pos="0 0 0">'
            f'<joint name="press" type="slide" axis="0 0 1" damping="{s.normal_damping:g}"/>'
            f'<inertial pos="0 0 0.02" mass="{s.finger_mass:g}" '
            f'diaginertia="{fi:g} {fi:g} {fi:g}"/>' + pad_body_xml(p) + "</body></body>"
        )
        return model_xml(
            bodies,
            pairs=pair_xml(p, ["slider"]),
            actuators='<motor name="press" joint="press" gear="1"/>',
            name="lugrip_rubbing_rig",
            gravity=(0.0, 0.0, 0.0),
            timestep=s.timestep,
            noslip_iterations=s.noslip_iterations,
            impratio=s.impratio,
        )

    def build(self):
        """(MjModel, MjData, Pad) of the rig."""
        import mujoco

        m = mujoco.MjModel.from_xml_string(self.model_xml())
        d = mujoco.MjData(m)
        pad = Pad(m, self.pad)
        pd = self.settings.pad_damping
        if pd is not None:  # the springs' damping implicit, as the gripper scenes have it
            m.dof_damping[pad.joint_dof] = (pd[0], pd[0], pd[1])
            pad._damping = np.zeros(3)
        return m, d, pad

    @classmethod
    def for_scene(cls, spec, params) -> MujocoRubbingRig:
        """The rig with the pad of a MuJoCo gripper scene: ``spec`` a
        :class:`lugrip.sim.mujoco.SceneSpec` (its pad overrides, implicit pad damping, finger
        mass and contact options), ``params`` the scene's ContactParams (mu, the radius law
        delta, gamma and the torsional factor xi of k), as
        :func:`lugrip.sim.mujoco.gripper.pad_spec` builds the scene's pads."""
        from ..sim.mujoco.gripper import pad_spec

        pad = dataclasses.replace(pad_spec(spec, params, 0), name="pad")
        settings = RigSettings(
            finger_mass=float(spec.finger_mass),
            normal_damping=float(spec.finger_damping),
            noslip_iterations=int(spec.noslip_iterations),
            impratio=float(spec.impratio),
            timestep=float(spec.timestep),
            pad_damping=tuple(spec.pad_damping),
        )
        return cls(pad=pad, settings=settings)

    # --- one maneuver --------------------------------------------------------------------------
    def run_maneuver(self, plan: ManeuverPlan, model=None) -> dict[str, np.ndarray]:
        """Simulate one maneuver; per-sample arrays (averages over each sample period of the
        1 ms steps): true wrench ``f_n, f_x, f_y, tau`` on the pad [N, N m], ``omega`` of the
        slider relative to the pad [rad/s], ``v`` slip speed of the contact [m/s],
        ``sliding`` (bool: every step of the sample at the cone limit and slipping),
        ``cor_distance`` from the contact point (the pad origin, displaced from the mount
        frame's origin by the pad springs) to the prescribed CoR [m],
        ``utilisation`` of the cone (its maximum over the sample) [-], ``load_ratio`` (the same:
        the plant's friction utilisation) [-], ``c_tilde_slip`` (the CoR of the actual slip
        over rho, signed as ``c_tilde_true``) [-]."""
        import mujoco

        if model is None:
            m, d, pad = self.build()
        else:
            m, d, pad = model
            mujoco.mj_resetData(m, d)
        s = self.settings
        h = m.opt.timestep
        dt = float(plan.t[1] - plan.t[0]) if len(plan.t) > 1 else 0.002
        ratio = max(1, round(dt / h))
        kt, kw, cum = _theta_segments(plan)
        jq = [m.joint(j).qposadr[0] for j in ("mount_x", "mount_y", "mount_theta")]
        jv = [m.joint(j).dofadr[0] for j in ("mount_x", "mount_y", "mount_theta")]
        cor = np.asarray(plan.cor, dtype=float)
        mu = self.pad.mu
        n_samples = len(plan.t)
        n_settle = round(s.settle / h)
        n_steps = n_settle + (n_samples - 1) * ratio + ratio
        t0 = -(n_settle + ratio) * h  # the first logged sample averages the steps ending at 0
        keys = ("f_n", "f_x", "f_y", "tau", "omega", "v", "cor_distance")
        out = {k: np.zeros(n_samples) for k in keys}
        qx, qy = int(pad.joint_qpos[0]), int(pad.joint_qpos[1])
        util = np.zeros(n_samples)
        sliding = np.zeros(n_samples, dtype=bool)
        acc = np.zeros(7)
        slide_all = True
        util_max = 0.0
        # per step n (start time t0 + n h): the normal force command and the mount's pose; its
        # velocity over a step is the secant to the next pose, so that the Euler position
        # update lands on the planned pose (no drift)
        t_steps = np.maximum(t0 + np.arange(n_steps + 1) * h, 0.0)
        f_cmd = np.asarray(plan.f_n_at(t_steps[:-1]), dtype=float)
        poses = mount_poses(cor, _theta_many(t_steps, kt, kw, cum))
        vels = np.diff(poses, axis=0) / h
        jq = np.asarray(jq)
        jv = np.asarray(jv)
        law = self.pad
        r_coef, r_floor, r_exp = law.delta, law.f_n_floor, law.gamma
        tol = 1.0 - s.cone_tolerance
        f_n_now = float(f_cmd[0])
        for n in range(n_steps):
            d.qpos[jq] = poses[n]
            d.qvel[jv] = vels[n]
            d.ctrl[0] = -f_cmd[n]
            spin = pad.update(m, d, f_n=f_n_now)
            mujoco.mj_step(m, d)
            w = pad.wrench(m, d)
            f_n_now = w[0]
            i_rel = n - n_settle - ratio  # steps of sample k: i_rel in ((k-1) ratio, k ratio]
            if i_rel < -ratio:
                continue
            rel = pad.slip_velocity(m, d)
            fn = w[0]
            if fn > 0.0:
                u = math.hypot(math.hypot(w[1], w[2]) / (mu * fn), w[3] / (spin * fn))
                rho = r_coef * max(fn, r_floor) ** r_exp
                v_t = math.hypot(rel[0], rel[1])
                slipping = u >= tol and v_t + abs(rel[2]) * rho > s.slip_speed
                acc[4] += rel[2]
                acc[5] += v_t
            else:
                u, slipping = 0.0, False
            acc[:4] += w
            # the CoR seen from the contact point: the pad's springs shift the pad (and its
            # contact) from the mount-frame origin by their deflection
            acc[6] += math.hypot(cor[0] - d.qpos[qx], cor[1] - d.qpos[qy])
            slide_all = slide_all and slipping
            util_max = max(util_max, u)
            if (i_rel + ratio) % ratio == ratio - 1:
                k = (i_rel + ratio) // ratio
                a = acc / ratio
                for j, key in enumerate(keys):
                    out[key][k] = a[j]
                sliding[k] = slide_all
                util[k] = util_max
                acc[:] = 0.0
                slide_all = True
                util_max = 0.0
        # the load ratio is the cone utilisation (f~_t^2 + tau~^2)^(1/2): it bounds the friction
        # moment about the prescribed CoR over its full-sliding maximum on the elliptic cone from
        # above, and equals it where the wrench is the cone's maximum-dissipation point for that CoR
        out.update(sliding=sliding, utilisation=util, load_ratio=util.copy())
        # the CoR of the slider's actual motion relative to the pad over rho, signed like
        # c_tilde_true (sign(c~) = -sign(omega)); NaN where the contact does not turn
        w_rel = out["omega"]
        with np.errstate(divide="ignore", invalid="ignore"):
            c_slip = -np.sign(w_rel) * out["v"] / np.abs(w_rel) / self.radius(out["f_n"])
        out["c_tilde_slip"] = np.where(np.abs(w_rel) > 1e-6, c_slip, np.nan)
        return out

    # --- a campaign ----------------------------------------------------------------------------
    def plans(self, design: RubbingDesign, n: int, seed: int = 0) -> list[ManeuverPlan]:
        """The maneuvers of :func:`plan_maneuvers` with this pad's radius law."""
        return plan_maneuvers(design, n, seed, radius=lambda f: float(self.radius(f)))

    def simulate(
        self, design: RubbingDesign | None = None, n: int = 160, seed: int = 0
    ) -> RubbingData:
        """Run ``n`` maneuvers of ``design`` (default :class:`RubbingDesign`) drawn from
        ``seed``; the sensor log (the plan's noise and offsets on the true wrench) with its
        labels. Gross sliding (phase 2) is where MuJoCo's contact is at its cone limit and
        slipping for the whole sample while the motion runs. ``load_ratio`` is the cone
        utilisation; ``c_tilde_true`` in gross sliding the CoR of the pad's actual slip over
        rho(f_n) (from MuJoCo's state), elsewhere the distance from the contact point to the
        prescribed CoR over rho(f_n), signed -sign(omega) (the two agree once the pad's slip
        has settled, about 0.2 s into a leg);
        ``v_true`` the contact's slip speed and the
        log's ``omega`` the slider's angular velocity relative to the pad, both from MuJoCo's
        state (averages over each sample period)."""
        import mujoco

        design = design if design is not None else RubbingDesign()
        wall = time.perf_counter()
        plans = self.plans(design, n, seed)
        dt = 1.0 / design.sample_rate
        starts = stack_times(plans, dt)
        built = self.build()
        runs = [self.run_maneuver(plan, built) for plan in plans]
        f_n_dev = []
        for plan, r in zip(plans, runs):
            moving = plan.commanded_phase() >= 1
            dev = np.abs(r["f_n"][moving] / plan.f_n[moving] - 1.0)
            f_n_dev.append((float(np.max(dev)), float(np.mean(dev > _BOUNCE))))
        bounced = [i for i, (_, share) in enumerate(f_n_dev) if share > _BOUNCE_SHARE]
        if bounced:
            warnings.warn(
                f"MujocoRubbingRig: in maneuvers {bounced[:10]} the true normal force left the "
                f"plan by more than {100 * _BOUNCE:.0f} % on more than "
                f"{100 * _BOUNCE_SHARE:.0f} % of the moving samples (MuJoCo's soft elliptic "
                "cone makes a fast-sliding pad bounce; keep contact speeds below about 5 mm/s)",
                stacklevel=2,
            )
        log, labels = engine_log(plans, starts, runs, self.radius, plant="mujoco", seed=seed)
        meta = {
            "plant": "mujoco",
            "mujoco": mujoco.__version__,
            "seed": int(seed),
            "n_maneuvers": int(n),
            "design": design.to_dict(),
            "pad": asdict(self.pad),
            "settings": asdict(self.settings),
            "seconds": time.perf_counter() - wall,
            "normal_force_deviation_max": max(dev for dev, _ in f_n_dev),
            "normal_force_deviation_share": max(share for _, share in f_n_dev),
            "normal_force_bounce_maneuvers": bounced,
        }
        return RubbingData(log=log, **labels, truth=self.truth(), meta=meta)


def engine_log(plans, starts, runs, radius, *, plant: str, seed: int):
    """The sensor log and labels of an engine rig's maneuvers (``runs``: the dicts of its
    ``run_maneuver``, one per plan, starting at ``starts`` [s]): each plan's sensor (offsets,
    noise) on the run's true wrench, the engine's own omega; phase 2 where the engine slides
    while the motion runs; ``c_tilde_true`` in gross sliding the CoR of the actual slip over
    ``radius(f_n)``, elsewhere (no slip) that of the prescribed motion seen from the contact
    point. Returns (SlidingLog, {phase, load_ratio, c_tilde_true, v_true})."""
    cols: dict[str, list[np.ndarray]] = {
        k: [] for k in ("t", "f_n", "f_x", "f_y", "tau", "omega", "maneuver")
    }
    phase, load, c_tilde, v_true = [], [], [], []
    for plan, t_start, r in zip(plans, starts, runs):
        f_n, f_x, f_y, tau = plan.sensor(r["f_n"], r["f_x"], r["f_y"], r["tau"])
        cols["t"].append(t_start + plan.t)
        cols["f_n"].append(f_n)
        cols["f_x"].append(f_x)
        cols["f_y"].append(f_y)
        cols["tau"].append(tau)
        cols["omega"].append(r["omega"])
        cols["maneuver"].append(np.full(len(plan.t), plan.index, dtype=np.int64))
        ph = plan.commanded_phase()
        ph[(ph == 1) & r["sliding"]] = 2
        phase.append(ph)
        load.append(r["load_ratio"])
        sign = np.sign(plan.c_tilde_signed(1.0))
        c_geom = sign * r["cor_distance"] / radius(np.maximum(r["f_n"], 1e-9))
        slip_ok = (ph == 2) & np.isfinite(r["c_tilde_slip"])
        c_tilde.append(np.where(slip_ok, r["c_tilde_slip"], c_geom))
        v_true.append(r["v"])
    cat = {k: np.concatenate(v) for k, v in cols.items()}
    log = SlidingLog.from_arrays(
        cat["t"], cat["f_n"], cat["tau"], f_x=cat["f_x"], f_y=cat["f_y"], omega=cat["omega"],
        maneuver=cat["maneuver"], meta={"plant": plant, "seed": int(seed)},
    )
    labels = {
        "phase": np.concatenate(phase), "load_ratio": np.concatenate(load),
        "c_tilde_true": np.concatenate(c_tilde), "v_true": np.concatenate(v_true),
    }
    return log, labels


def _sweep_plan(rig: MujocoRubbingRig, c_tilde: float, f_n: float) -> ManeuverPlan:
    """A rub about a CoR at c_tilde rho at 3 mm/s contact speed (1 rad/s at most), 0.4 s of
    sliding, then 0.4 s of loaded rest; no sensor noise."""
    rho = float(rig.radius(f_n))
    omega = min(1.0, 3e-3 / (c_tilde * rho)) if c_tilde > 0 else 1.0
    kt = np.array([0.0, 0.1, 0.15, 0.55, 0.6])
    kw = np.array([0.0, 0.0, omega, omega, 0.0])
    t = np.arange(int(1.0 / 0.002) + 1) * 0.002
    c = c_tilde * rho
    return ManeuverPlan(
        index=0, t=t, knots_t=kt, knots_omega=kw, cor=np.array([c, 0.0]), c_tilde=c_tilde,
        rho_nominal=rho, f_n_nominal=f_n, approach=0.1, motion_end=0.6, f_n_start=1.0,
        ripple=0.0, ripple_freq=1.0, ripple_phase=0.0, reversals=0, offset=np.zeros(4),
        noise=(0.0, 0.0), noise_seed=0,
    )  # fmt: skip


#: (label, changes to the rig's model after it is built) compared by :func:`settings_sweep`
SWEEP_SETTINGS = (
    ("rig defaults: elliptic, noslip 10, impratio 1, solref 2 ms, explicit pad damping", {}),
    ("noslip 5", {"noslip_iterations": 5}),
    ("noslip 0", {"noslip_iterations": 0}),
    ("noslip 0, impratio 10", {"noslip_iterations": 0, "impratio": 10.0}),
    ("pad damping as MuJoCo joint damping (implicit)", {"implicit_damping": True}),
    ("contact solref 4 ms", {"solref": 0.004}),
    ("impratio 10", {"impratio": 10.0}),
)


def settings_sweep(c_tilde: float = 1.0, f_n: float = 4.0) -> list[dict]:
    """Stick, creep and sliding of the rig under each MuJoCo setting of
    :data:`SWEEP_SETTINGS`, on one rub (:func:`_sweep_plan`). Per row: slip of the stuck pad
    while its load builds [um], creep at the loaded rest [um/s], the load left at the end of
    the rest, and the largest departure of the sliding wrench from the elliptic cone."""
    rows = []
    for label, change in SWEEP_SETTINGS:
        pad = MujocoRubbingRig().pad
        if "solref" in change:
            pad = dataclasses.replace(pad, solref=(change["solref"], 1.0))
        rig = MujocoRubbingRig(pad=pad)
        m, d, p = rig.build()
        if "noslip_iterations" in change:
            m.opt.noslip_iterations = change["noslip_iterations"]
        if "impratio" in change:
            m.opt.impratio = change["impratio"]
        if change.get("implicit_damping"):
            m.dof_damping[p.joint_dof] = p._damping
            p._damping = np.zeros(3)
        plan = _sweep_plan(rig, c_tilde, f_n)
        r = rig.run_maneuver(plan, (m, d, p))
        ph = plan.commanded_phase()
        dt = float(plan.t[1] - plan.t[0])
        rho = rig.radius(r["f_n"])
        speed = r["v"] + np.abs(r["omega"]) * rho
        first = int(np.argmax((ph == 1) & r["sliding"])) if np.any(r["sliding"]) else len(ph)
        build = (ph == 1) & (np.arange(len(ph)) < first) & (r["utilisation"] < 0.9)
        rest = (ph == 3) & (plan.t > plan.motion_end + 0.05)
        slide = (ph == 1) & r["sliding"]
        rows.append(
            {
                "setting": label,
                "onset_slip_um": 1e6 * float(np.sum(speed[build]) * dt),
                "rest_creep_um_s": 1e6 * float(np.mean(speed[rest])),
                "rest_load_end": float(r["load_ratio"][-1]),
                "rest_load_start": float(r["load_ratio"][rest][0]),
                "sliding_off_cone": float(np.max(np.abs(r["utilisation"][slide] - 1.0)))
                if slide.any()
                else float("nan"),
            }
        )
    return rows


def main(argv=None) -> int:
    """``python -m lugrip.rigs.mujoco_rig [--c-tilde C] [--f-n F]``: the settings table."""
    import argparse

    ap = argparse.ArgumentParser(description=main.__doc__)
    ap.add_argument("--c-tilde", type=float, default=1.0)
    ap.add_argument("--f-n", type=float, default=4.0)
    args = ap.parse_args(argv)
    print(
        "| MuJoCo setting | slip while the load builds [um] | creep at loaded rest [um/s] "
        "| load at rest start -> end | sliding wrench off the cone |"
    )
    print("|---|---|---|---|---|")
    for row in settings_sweep(args.c_tilde, args.f_n):
        print(
            f"| {row['setting']} | {row['onset_slip_um']:.2f} | {row['rest_creep_um_s']:.3g} "
            f"| {row['rest_load_start']:.3f} -> {row['rest_load_end']:.3f} "
            f"| {row['sliding_off_cone']:.1e} |"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
