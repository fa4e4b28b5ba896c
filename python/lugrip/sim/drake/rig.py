"""A Drake rubbing rig: the compliant-hydroelastic pad (:mod:`lugrip.sim.drake.pad`) driven
over a fixed rigid slab, for identification (``lugrip simulate-rubbing --plant drake``).

The plant is Drake's hydroelastic contact and discrete solver, not lugrip's model. A heavy mount
(the robot's finger base) moves in the slab plane with a **prescribed** planar motion about a
centre of rotation fixed in the finger frame (the maneuvers of :mod:`lugrip.rigs.motion`; its
position and velocity are set before every step); a force actuator on a normal slide presses
the finger with the planned normal force; the pad hangs from the finger on its in-plane and
twist springs. Drake integrates the pad's pressure field and the friction of every polygon of
the patch, so the torsional capacity and the coupling of tangential force and torsion (the limit
surface) are the engine's.

The true torsional capacity is measured on the engine (:func:`measure_capacity`: a slow pure
spin about the patch centre at a fixed normal force, the mean |tau| once sliding), not taken
from a formula.

    >>> from lugrip.rigs import RubbingDesign
    >>> from lugrip.sim.drake.rig import DrakeRubbingRig
    >>> data = DrakeRubbingRig().simulate(RubbingDesign(), n=2, seed=1)   # doctest: +SKIP
"""

from __future__ import annotations

import dataclasses
import functools
import math
import time
from dataclasses import asdict, dataclass

import numpy as np

from ...rigs._data import RigTruth, RubbingData
from ...rigs.mujoco_rig import _theta_many, _theta_segments, engine_log, mount_poses
from ...rigs.motion import ManeuverPlan, RubbingDesign, plan_maneuvers, stack_times
from .pad import DrakePad, PadWrench, add_pad, rigid_properties

__all__ = ["CAPACITY_FORCES", "RIG_PAD", "DrakeRubbingRig", "RigSettings", "measure_capacity"]

#: the rig's pad: the gripper's, on a 10 times stiffer in-plane mount (40 N/mm, as the MuJoCo
#: rig's), so that translation-dominated rubs reach gross sliding within their legs; the twist
#: mount (the presliding the observer models) is the gripper's
RIG_PAD = DrakePad(k_slide=40000.0, d_slide=40.0)

#: normal forces [N] at which :meth:`DrakeRubbingRig.truth` measures the engine's capacity
CAPACITY_FORCES = (0.5, 1.0, 2.0, 4.0, 8.0, 12.0, 16.0)


@dataclass(frozen=True)
class RigSettings:
    """Mechanics of the rig around the pad and Drake's solver options (SI units)."""

    finger_mass: float = 0.02  #: mass on the normal slide between mount and pad [kg]
    normal_damping: float = 1.0  #: damping of the normal slide [N s/m]
    mount_mass: float = 1e4  #: the prescribed mount (heavy: the contact barely changes it) [kg]
    settle: float = 0.05  #: pressed settling time before each maneuver, not logged [s]
    timestep: float = 1e-3  #: Drake's discrete step [s]
    #: Drake's discrete contact approximation ("lagged", "similar", "sap", "tamsi")
    approximation: str = "lagged"
    #: Drake's friction regularisation: slip speed below which friction is proportional to
    #: the slip [m/s]
    stiction_tolerance: float = 1e-6
    #: gross sliding: slip speed |v| + |omega| a at the patch edge above this [m/s] (far above
    #: the regularisation's creep, so the friction is saturated over the patch)
    slip_speed: float = 1e-4

    def __post_init__(self):
        for f in dataclasses.fields(self):
            if f.name == "approximation":
                continue
            v = float(getattr(self, f.name))
            if not (math.isfinite(v) and v >= 0.0) or (v == 0.0 and f.name != "settle"):
                raise ValueError(f"RigSettings.{f.name} = {v!r}: must be finite and > 0")
        if self.approximation not in ("lagged", "similar", "sap", "tamsi"):
            raise ValueError(f"RigSettings.approximation {self.approximation!r}")


def _approximation(name: str):
    from pydrake.multibody.plant import DiscreteContactApproximation as D

    return {"lagged": D.kLagged, "similar": D.kSimilar, "sap": D.kSap, "tamsi": D.kTamsi}[name]


class _RigModel:
    """The built rig: Drake diagram, simulator, plant context, joints and the pad sensor."""

    def __init__(self, pad: DrakePad, s: RigSettings):
        from pydrake.geometry import Box
        from pydrake.math import RigidTransform
        from pydrake.multibody.plant import AddMultibodyPlantSceneGraph, ContactModel
        from pydrake.multibody.tree import PlanarJoint, PrismaticJoint, SpatialInertia
        from pydrake.systems.analysis import Simulator
        from pydrake.systems.framework import DiagramBuilder

        b = DiagramBuilder()
        plant, sg = AddMultibodyPlantSceneGraph(b, time_step=s.timestep)
        plant.set_contact_model(ContactModel.kHydroelastic)
        plant.set_discrete_contact_approximation(_approximation(s.approximation))
        plant.set_stiction_tolerance(s.stiction_tolerance)
        plant.mutable_gravity_field().set_gravity_vector([0.0, 0.0, 0.0])
        plant.RegisterCollisionGeometry(
            plant.world_body(), RigidTransform([0.0, 0.0, -0.01]), Box(0.4, 0.4, 0.02), "slab",
            rigid_properties(pad.mu, 0.05))
        mount = plant.AddRigidBody(
            "mount", SpatialInertia.SolidBoxWithMass(s.mount_mass, 0.1, 0.1, 0.1))
        finger = plant.AddRigidBody(
            "finger", SpatialInertia.SolidBoxWithMass(s.finger_mass, 0.01, 0.01, 0.01))
        self.mount_joint = plant.AddJoint(
            PlanarJoint("mount", plant.world_frame(), mount.body_frame()))
        self.press = plant.AddJoint(PrismaticJoint(
            "press", mount.body_frame(), finger.body_frame(), [0.0, 0.0, 1.0],
            damping=s.normal_damping))
        plant.AddJointActuator("press", self.press)
        # the pad faces down: its frame's z (from the face into the finger) is world +z
        self.pad_body, self.pad_joint, gid = add_pad(
            plant, finger.body_frame(), RigidTransform(), "pad", pad)
        plant.Finalize()
        self.diagram = b.Build()
        self.plant = plant
        self.simulator = Simulator(self.diagram)
        self.root = self.simulator.get_mutable_context()
        self.context = plant.GetMyMutableContextFromRoot(self.root)
        self.actuation = plant.get_actuation_input_port().FixValue(self.context, [0.0])
        self.sensor = PadWrench(plant, sg, self.pad_body, gid)
        self.initial = self.root.Clone()

    def reset(self, gap: float = 0.0) -> None:
        self.root.SetTimeStateAndParametersFrom(self.initial)
        self.press.set_translation(self.context, gap)
        self.simulator.Initialize()

    def set_force(self, f: float) -> None:
        self.actuation.GetMutableData().set_value(np.array([-float(f)]))

    def step(self) -> None:
        self.simulator.AdvanceTo(self.root.get_time() + self.plant.time_step())

    def slip(self) -> tuple[float, float, float]:
        """The slab's motion relative to the pad at the pad origin: (v_x, v_y) in the pad frame
        [m/s] and the spin about the pad z [rad/s]."""
        V = self.pad_body.EvalSpatialVelocityInWorld(self.context)
        R = self.pad_body.EvalPoseInWorld(self.context).rotation().matrix()
        v = R.T @ (-V.translational())
        w = R.T @ (-V.rotational())
        return float(v[0]), float(v[1]), float(w[2])


def measure_capacity(pad: DrakePad, forces=CAPACITY_FORCES, settings: RigSettings | None = None,
                     omega: float = 0.3, duration: float = 0.4) -> tuple[tuple[float, float], ...]:
    """The engine's torsional capacity: the pad pressed with each normal force [N] and spun
    about its own axis at ``omega`` [rad/s] (pure spin about the patch centre: slip speeds
    0.3 rad/s x 2-4 mm, far above the stiction tolerance over the patch but its centre);
    the mean |tau| over the last half of ``duration`` [s]. Returns ((f_n, tau_max), ...)."""
    return _capacity(pad, tuple(float(f) for f in forces), settings or RigSettings(),
                     float(omega), float(duration))


@functools.lru_cache(maxsize=8)
def _capacity(pad, forces, s, omega, duration):
    rig = _RigModel(pad, s)
    jm = rig.mount_joint
    h = s.timestep
    out = []
    for f in forces:
        rig.reset()
        rig.set_force(f)
        for _ in range(round(0.1 / h)):
            rig.step()
        taus = []
        n = round(duration / h)
        ctx = rig.context
        for k in range(n):
            # velocities landing the mount on the spin's pose (a pure spin about the pad axis)
            jm.set_angular_velocity(ctx, (omega * (k + 1) * h - jm.get_rotation(ctx)) / h)
            jm.set_translational_velocity(ctx, -np.asarray(jm.get_translation(ctx)) / h)
            rig.step()
            if k >= n // 2:
                taus.append(abs(rig.sensor.read(rig.context)[0][3]))
        out.append((f, float(np.mean(taus))))
    return tuple(out)


def _theta_profile(plan: ManeuverPlan):
    return _theta_segments(plan), _theta_many, mount_poses


class DrakeRubbingRig:
    """The compliant-hydroelastic pad on its sprung mount rubbing a fixed slab in Drake.

    Attributes:
        pad: the pad (its mu is the contact's Coulomb coefficient).
        settings: the rig's mechanics and Drake's options.
    """

    name = "drake"

    def __init__(self, pad: DrakePad | None = None, settings: RigSettings | None = None):
        self.pad = pad if pad is not None else RIG_PAD
        self.settings = settings if settings is not None else RigSettings()
        self._model: _RigModel | None = None

    def model(self) -> _RigModel:
        if self._model is None:
            self._model = _RigModel(self.pad, self.settings)
        return self._model

    # --- the plant's truth ---------------------------------------------------------------------
    def capacity(self) -> tuple[tuple[float, float], ...]:
        """The engine's (f_n, tau_max) points (:func:`measure_capacity`, cached)."""
        return measure_capacity(self.pad, settings=self.settings)

    def radius(self, f_n):
        """The contact radius law the truth states: the power law through the engine's
        capacity points, rho = tau_max / (mu xi f_n) with the paraboloid's xi = 8/15."""
        delta, gamma = self._radius_law()
        out = delta * np.maximum(np.asarray(f_n, dtype=float), 1e-9) ** gamma
        return float(out) if np.ndim(out) == 0 else out

    def _radius_law(self) -> tuple[float, float]:
        pts = np.array(self.capacity())
        slope, icpt = np.polyfit(np.log(pts[:, 0]), np.log(pts[:, 1]), 1)
        gamma = slope - 1.0
        delta = math.exp(icpt) / (self.pad.mu * 8.0 / 15.0)
        return delta, gamma

    def truth(self) -> RigTruth:
        """mu, the engine's measured torsional capacity and what the plant does not model."""
        p = self.pad
        delta, gamma = self._radius_law()
        return RigTruth.coulomb(
            "drake",
            p.mu,
            delta=delta,
            gamma=gamma,
            pressure=(
                "Drake hydroelastic: the pad sphere's pressure field (modulus "
                f"{p.modulus:.3g} Pa, radius {1e3 * p.radius:g} mm, mesh hint "
                f"{1e3 * p.resolution_hint:g} mm) integrated over the patch polygons; about a "
                "paraboloid"),
            tau_max_points=self.capacity(),
            notes=(
                "Coulomb friction, regularised below the stiction tolerance "
                f"{self.settings.stiction_tolerance:g} m/s (Drake's discrete "
                f"'{self.settings.approximation}' solver). The torsional capacity points are "
                "measured on the engine (slow pure spin); delta and gamma are the power law "
                "through them with xi = 8/15 (paraboloid pressure). Presliding from the pad's "
                f"mount springs: in-plane {p.k_slide:g} N/m, twist {p.k_twist:g} N m/rad."),
        )

    # --- one maneuver --------------------------------------------------------------------------
    def run_maneuver(self, plan: ManeuverPlan) -> dict[str, np.ndarray]:
        """Simulate one maneuver; per-sample arrays (averages over each sample period of the
        steps): true wrench ``f_n, f_x, f_y, tau`` on the pad [N, N m], ``omega`` of the slab
        relative to the pad [rad/s], ``v`` its slip speed at the pad origin [m/s], ``sliding``
        (every step of the sample slipping beyond the regularisation over the patch),
        ``cor_distance`` from the pad origin to the prescribed CoR [m], ``load_ratio`` (the
        wrench's utilisation of the engine's capacity on the ellipse
        ((f_t / (mu f_n))^2 + (tau / tau_max(f_n))^2)^(1/2), tau_max measured on the engine)."""
        rig = self.model()
        s = self.settings
        h = s.timestep
        dt = float(plan.t[1] - plan.t[0]) if len(plan.t) > 1 else 0.002
        ratio = max(1, round(dt / h))
        (kt, kw, cum), theta_many, mount_poses = _theta_profile(plan)
        cor = np.asarray(plan.cor, dtype=float)
        n_samples = len(plan.t)
        n_settle = round(s.settle / h)
        n_steps = n_settle + (n_samples - 1) * ratio + ratio
        t0 = -(n_settle + ratio) * h
        t_steps = np.maximum(t0 + np.arange(n_steps + 1) * h, 0.0)
        f_cmd = np.asarray(plan.f_n_at(t_steps[:-1]), dtype=float)
        poses = mount_poses(cor, theta_many(t_steps, kt, kw, cum))
        keys = ("f_n", "f_x", "f_y", "tau", "omega", "v", "cor_distance")
        out = {k: np.zeros(n_samples) for k in keys}
        sliding = np.zeros(n_samples, dtype=bool)
        acc = np.zeros(7)
        slide_all = True
        rig.reset()
        jm, ctx = rig.mount_joint, rig.context
        mu = self.pad.mu
        v_slide = s.slip_speed
        for n in range(n_steps):
            # the mount's velocity over the step lands it on the next planned pose (its position
            # is never set: a teleport would move it under the contact)
            q = np.array([*jm.get_translation(ctx), jm.get_rotation(ctx)])
            v = (poses[n + 1] - q) / h
            jm.set_translational_velocity(ctx, v[:2])
            jm.set_angular_velocity(ctx, v[2])
            rig.set_force(f_cmd[n])
            rig.step()
            i_rel = n - n_settle - ratio
            if i_rel < -ratio:
                continue
            w, _, area = rig.sensor.read(ctx)
            vx, vy, om = rig.slip()
            v_t = math.hypot(vx, vy)
            a = math.sqrt(area / math.pi)
            # the slowest-slipping point of the patch: its centre in translation, a point at
            # the CoR when the CoR lies in the patch (measure zero): the patch slides as a
            # whole when the slip at its edge is well beyond the regularisation
            slipping = w[0] > 0.0 and v_t + abs(om) * a > v_slide
            acc[:4] += w
            acc[4] += om
            acc[5] += v_t
            d_xy = rig.pad_joint.get_translation(ctx)
            acc[6] += math.hypot(cor[0] - d_xy[0], cor[1] - d_xy[1])
            slide_all = slide_all and slipping
            if (i_rel + ratio) % ratio == ratio - 1:
                k = (i_rel + ratio) // ratio
                avg = acc / ratio
                for j, key in enumerate(keys):
                    out[key][k] = avg[j]
                sliding[k] = slide_all
                acc[:] = 0.0
                slide_all = True
        truth = self.truth()
        fn = np.maximum(out["f_n"], 1e-6)
        ft = np.hypot(out["f_x"], out["f_y"])
        out["load_ratio"] = np.hypot(ft / (mu * fn), out["tau"] / truth.tau_max(fn))
        out["sliding"] = sliding
        w_rel = out["omega"]
        with np.errstate(divide="ignore", invalid="ignore"):
            c_slip = -np.sign(w_rel) * out["v"] / np.abs(w_rel) / self.radius(fn)
        out["c_tilde_slip"] = np.where(np.abs(w_rel) > 1e-6, c_slip, np.nan)
        return out

    # --- a campaign ----------------------------------------------------------------------------
    def plans(self, design: RubbingDesign, n: int, seed: int = 0) -> list[ManeuverPlan]:
        """The maneuvers of :func:`plan_maneuvers` with this pad's radius law."""
        return plan_maneuvers(design, n, seed, radius=lambda f: float(self.radius(f)))

    def simulate(self, design: RubbingDesign | None = None, n: int = 160,
                 seed: int = 0) -> RubbingData:
        """Run ``n`` maneuvers of ``design`` (default :class:`RubbingDesign`) drawn from
        ``seed``: the sensor log (the plan's noise and offsets on the true wrench) with its
        labels. Gross sliding (phase 2) is where the patch slips beyond the regularisation for
        the whole sample while the motion runs; ``c_tilde_true`` there the CoR of the actual
        slip over rho(f_n), elsewhere the distance from the pad origin to the prescribed CoR
        over rho(f_n), signed -sign(omega)."""
        import pydrake

        design = design if design is not None else RubbingDesign()
        wall = time.perf_counter()
        plans = self.plans(design, n, seed)
        starts = stack_times(plans, 1.0 / design.sample_rate)
        runs = [self.run_maneuver(plan) for plan in plans]
        log, labels = engine_log(plans, starts, runs, self.radius, plant="drake", seed=seed)
        meta = {
            "plant": "drake",
            "drake": getattr(pydrake, "__version__", "unknown"),
            "seed": int(seed),
            "n_maneuvers": int(n),
            "design": design.to_dict(),
            "pad": asdict(self.pad),
            "settings": asdict(self.settings),
            "seconds": time.perf_counter() - wall,
        }
        return RubbingData(log=log, **labels, truth=self.truth(), meta=meta)
