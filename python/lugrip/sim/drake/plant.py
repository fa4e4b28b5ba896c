"""The Drake gripper as a :class:`lugrip.sim.plant.Plant` (registered as "drake").

The scene is the scenario's MuJoCo scene (object shape and size, pad clearance, finger stops,
table, wrist rolls: :meth:`lugrip.sim.scenarios.Scenario.scene_spec`) and its plant block (object
mass, inertia and CoG, the contact's mu, actuator, sensors, moves, disturbances), built in Drake:

* world frame as the MuJoCo scene's: x the grasp axis (finger 0 at -x), y horizontal, z up;
* the object on a slide along x (it may centre itself between the pads) and a planar joint in
  the y-z plane (two slides and a hinge about x), a rigid-hydroelastic box or cylinder with the
  contact's mu, resting on a table until lifted;
* the hand's moves and wrist rolls prescribed (its planar joint's position and velocity set
  before every step); two fingers on slides along x with force actuators and stops; each
  fingertip a compliant-hydroelastic sphere on its sprung mount (:mod:`lugrip.sim.drake.pad`),
  so the patch, its pressure field, the torsional capacity and the limit surface are Drake's;
* Drake's discrete solver at 1 ms ("lagged" contact approximation), hydroelastic contact with
  point-contact fallback for the object on the table.

The force actuator is lugrip's (docs/model.md §10.1): the command held at the actuator input
through a first-order lag and a rate limit to the range [0, min(f_max, force_range)], applied at
every step. The fingertip sensors read, at 500 Hz, the wrench the object exerts on each pad from
Drake's contact results, averaged over the sample, plus bias and noise.

``extra`` columns: ``pad_deflection_i`` (pad i's in-plane mount deflection [m]),
``pad_twist_i`` (its twist about world x [rad]), ``roll`` (the hand's roll [rad]),
``patch_polygons_i`` (the polygons Drake integrates over pad i's patch) and
``patch_radius_i`` (the radius of a disc of the patch's area [m]).
"""

from __future__ import annotations

import math
import time
from typing import Any

import numpy as np

from ..mujoco.gripper import _object_bottom
from ..mujoco.loop import disturbance_wrench
from ..plant import PlantClock, PlantSamples
from ..scene_faults import SceneWatch
from .pad import DrakePad, PadWrench, add_pad, rigid_properties

__all__ = ["PAD_FILE", "DrakePlant", "build_gripper", "min_jerk", "pad_parameters"]

#: the identified pad, relative to the shipped objects directory
PAD_FILE = "drake/pad.yaml"


def pad_parameters():
    """The ContactParams of :data:`PAD_FILE` (the Drake pad identified on the rig, mu 0.7)."""
    from ..._data import data_dir
    from ..._params import ContactParams

    objects = data_dir("objects")
    if objects is None or not (objects / PAD_FILE).is_file():
        raise FileNotFoundError(f"the identified Drake pad {PAD_FILE} is not in the objects "
                                "directory of this installation")
    return ContactParams.from_yaml(objects / PAD_FILE)

#: each pad's twist axis (its z) along world x: -1 for pad 0, +1 for pad 1
_TWIST_SIGN = (-1.0, 1.0)
#: pad frames in world (columns x, y, z; z from the face into the finger), as the MuJoCo scene's
_PAD_FRAMES = (
    np.array([[0.0, 0.0, -1.0], [1.0, 0.0, 0.0], [0.0, -1.0, 0.0]]),  # pad 0, facing +x
    np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]),  # pad 1, facing -x
)
#: the in-plane frame of the planar joints (object, hand): its x, y, z along world y, z, x
_PLANE = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
#: the hand's mass [kg]: its motion is prescribed, so that the contact barely changes it
_HAND_MASS = 50.0


def min_jerk(t: float, t0: float, T: float) -> float:
    """The minimum-jerk ramp 0 -> 1 over [t0, t0 + T]."""
    u = min(max((t - t0) / T, 0.0), 1.0) if T > 0 else float(t >= t0)
    return u**3 * (10.0 - 15.0 * u + 6.0 * u * u)


class _Gripper:
    """The built Drake model of one scene."""

    def __init__(self, spec, *, mu: float, mass: float, inertia: float, cog, pad: DrakePad,
                 timestep: float = 1e-3, approximation: str = "lagged",
                 stiction_tolerance: float = 1e-6, grasp_height: float = 0.1):
        from pydrake.geometry import Box, Cylinder
        from pydrake.math import RigidTransform, RotationMatrix, RollPitchYaw
        from pydrake.multibody.plant import (
            AddMultibodyPlantSceneGraph,
            ContactModel,
            ExternallyAppliedSpatialForce,
        )
        from pydrake.multibody.tree import (
            FixedOffsetFrame,
            PlanarJoint,
            PrismaticJoint,
            SpatialInertia,
            UnitInertia,
        )
        from pydrake.systems.analysis import Simulator
        from pydrake.systems.framework import DiagramBuilder

        from .rig import _approximation

        b = DiagramBuilder()
        plant, sg = AddMultibodyPlantSceneGraph(b, time_step=timestep)
        plant.set_contact_model(ContactModel.kHydroelasticWithFallback)
        plant.set_discrete_contact_approximation(_approximation(approximation))
        plant.set_stiction_tolerance(stiction_tolerance)
        self.plant, self.scene_graph = plant, sg
        gripper = plant.AddModelInstance("gripper")
        objects = plant.AddModelInstance("object")
        pad = pad.replace(mu=float(mu))
        self.pad = pad
        hw = spec.half_width
        cy, cz = (float(v) for v in cog)
        center = spec.geom_center if spec.geom_center is not None else (cy, cz)
        ox, oy, oz = spec.object_offset
        z0 = grasp_height
        x_face = hw + spec.clearance
        self.travel = hw + spec.clearance - spec.min_half_gap
        plane = RotationMatrix(_PLANE)

        # the table (rigid; the object on it is a rigid-rigid contact: point-contact fallback)
        if spec.table:
            bottom = z0 + oz + _object_bottom(spec, center[1])
            tprops = rigid_properties(spec.table_friction, 0.05)
            plant.RegisterCollisionGeometry(
                plant.world_body(), RigidTransform([0.0, 0.0, bottom - 0.01]),
                Box(0.8, 0.8, 0.02), "table", tprops)

        # the object: slide along x, then a planar joint in the y-z plane
        i_obj = float(inertia)
        M = SpatialInertia(mass=float(mass), p_PScm_E=[0.0, cy, cz],
                           G_SP_E=UnitInertia(i_obj / mass, i_obj / mass, i_obj / mass)
                           .ShiftFromCenterOfMass([0.0, -cy, -cz]))
        carrier = plant.AddRigidBody(
            "object_carrier", objects, SpatialInertia.SolidSphereWithMass(1e-3, 1e-3))
        obj = plant.AddRigidBody("object", objects, M)
        self.object = obj
        start = plant.AddFrame(FixedOffsetFrame(
            "object_start", plant.world_frame(), RigidTransform([ox, oy, z0 + oz])))
        self.ox = plant.AddJoint(PrismaticJoint(
            "ox", start, carrier.body_frame(), [1.0, 0.0, 0.0]))
        self.obj_joint = plant.AddJoint(PlanarJoint(
            "object_plane",
            plant.AddFrame(FixedOffsetFrame("object_plane_F", carrier.body_frame(),
                                            RigidTransform(plane, [0.0, 0.0, 0.0]))),
            plant.AddFrame(FixedOffsetFrame("object_plane_M", obj.body_frame(),
                                            RigidTransform(plane, [0.0, 0.0, 0.0])))))
        oprops = rigid_properties(pad.mu, 0.05 if spec.shape == "box" else pad.resolution_hint)
        if spec.shape == "box":
            shape = Box(*(2.0 * v for v in spec.size))
            R_geom = RotationMatrix()
        else:
            r, half = spec.size
            shape = Cylinder(r, 2.0 * half)
            R_geom = (RotationMatrix() if spec.axis == "vertical"
                      else RotationMatrix(RollPitchYaw(math.pi / 2, 0.0, 0.0)))
        self.object_geometry = plant.RegisterCollisionGeometry(
            obj, RigidTransform(R_geom, [0.0, center[0], center[1]]), shape, "object", oprops)
        self.object_shape = (spec.shape, tuple(spec.size), spec.axis, tuple(center))

        # the hand: a planar joint in the y-z plane at the grasp height, prescribed
        hand = plant.AddRigidBody(
            "hand", gripper, SpatialInertia.SolidBoxWithMass(_HAND_MASS, 0.1, 0.03, 0.02))
        self.hand_joint = plant.AddJoint(PlanarJoint(
            "hand",
            plant.AddFrame(FixedOffsetFrame("hand_F", plant.world_frame(),
                                            RigidTransform(plane, [0.0, 0.0, z0]))),
            plant.AddFrame(FixedOffsetFrame("hand_M", hand.body_frame(),
                                            RigidTransform(plane, [0.0, 0.0, 0.0])))))
        self.fingers, self.pads, self.sensors = [], [], []
        pad_geoms = []
        for k, sign in ((0, -1.0), (1, 1.0)):
            finger = plant.AddRigidBody(
                f"finger{k}", gripper,
                SpatialInertia.SolidBoxWithMass(spec.finger_mass, 0.01, 0.024, 0.04))
            j = plant.AddJoint(PrismaticJoint(
                f"f{k}",
                plant.AddFrame(FixedOffsetFrame(f"finger{k}_rest", hand.body_frame(),
                                                RigidTransform([sign * x_face, 0.0, 0.0]))),
                finger.body_frame(), [-sign, 0.0, 0.0],
                pos_lower_limit=-0.01, pos_upper_limit=self.travel,
                damping=spec.finger_damping))
            plant.AddJointActuator(f"m{k}", j)
            body, pj, gid = add_pad(plant, finger.body_frame(),
                                    RigidTransform(RotationMatrix(_PAD_FRAMES[k]), [0.0, 0.0, 0.0]),
                                    f"pad{k}", pad)
            self.fingers.append(j)
            self.pads.append((body, pj))
            pad_geoms.append(gid)
            self.sensors.append(PadWrench(plant, sg, body, gid))
        plant.set_gravity_enabled(gripper, False)  # the gripper carries its own weight
        plant.Finalize()
        self.diagram = b.Build()
        self.simulator = Simulator(self.diagram)
        self.root = self.simulator.get_mutable_context()
        self.context = plant.GetMyMutableContextFromRoot(self.root)
        nu = plant.num_actuators()
        self._act_index = [int(plant.GetJointActuatorByName(f"m{k}").input_start())
                           for k in (0, 1)]
        self._u = np.zeros(nu)
        self.actuation = plant.get_actuation_input_port().FixValue(self.context, self._u)
        self._force = ExternallyAppliedSpatialForce()
        self._force.body_index = obj.index()
        self._force.p_BoBq_B = np.array([0.0, cy, cz])
        self.applied = plant.get_applied_spatial_force_input_port().FixValue(
            self.context, [self._force])
        self.simulator.Initialize()

    def set_inputs(self, f_grip: float, wrench: tuple[float, float, float]) -> None:
        from pydrake.multibody.math import SpatialForce

        self._u[self._act_index[0]] = self._u[self._act_index[1]] = f_grip
        self.actuation.GetMutableData().set_value(self._u)
        fx, fy, tz = wrench
        self._force.F_Bq_W = SpatialForce([tz, 0.0, 0.0], [0.0, fx, fy])
        self.applied.GetMutableData().set_value([self._force])

    def step(self) -> None:
        self.simulator.AdvanceTo(self.root.get_time() + self.plant.time_step())

    def object_between(self) -> bool:
        """The line between the pad origins passes through the object's shape (seen along the
        grasp axis, in the object's frame)."""
        ctx = self.context
        p = [b.EvalPoseInWorld(ctx).translation() for b, _ in self.pads]
        X = self.object.EvalPoseInWorld(ctx)
        mid = X.inverse().multiply(0.5 * (p[0] + p[1]))
        shape, size, axis, (gy, gz) = self.object_shape
        y, z = mid[1] - gy, mid[2] - gz
        if shape == "box":
            return abs(y) <= size[1] and abs(z) <= size[2]
        r, half = size
        return (abs(y) <= r and abs(z) <= half) if axis == "vertical" else (
            abs(y) <= half and abs(z) <= r)


def build_gripper(spec, **kwargs) -> _Gripper:
    """The Drake model of a MuJoCo scene spec (keywords: mu, mass, inertia, cog, pad,
    timestep, approximation, stiction_tolerance)."""
    return _Gripper(spec, **kwargs)


class DrakePlant(SceneWatch):
    """The Drake gripper of a scenario (its ``mujoco:`` scene block and plant block).

    Args:
        pad: the fingertip pad (:class:`DrakePad`; its mu is replaced by the scenario's).
        timestep: Drake's step [s] (the sensor period must be a multiple of it).
        approximation: Drake's discrete contact approximation.
    """

    name = "drake"

    @staticmethod
    def report_method() -> str:
        """The plant as ``lugrip simulate --plant drake``'s report describes it."""
        from importlib.metadata import PackageNotFoundError, version as dist_version

        try:
            version = dist_version("drake")
        except PackageNotFoundError:  # a Drake not installed from the wheel
            version = "(version unknown)"
        return (
            f"Plant: Drake {version}, the scenario's MuJoCo scene built in Drake: two "
            "force-controlled fingers, each fingertip a compliant-hydroelastic sphere on sprung "
            "in-plane and twist mounts (objects/drake/pad.yaml identified on the Drake rubbing "
            "rig), so the patch's pressure field, torsional capacity and limit surface are the "
            "engine's; discrete solver at 1 ms with regularised friction (the plant's stiction "
            "tolerance, 1e-6 m/s by default); fingertip wrench from Drake's contact results averaged over 2 ms, 500 Hz; "
            "command at 50 Hz through the scenario's actuator lag and rate limit. The observers "
            "and controller use the identified pad with the object's μ unless the scenario names "
            "an estimator for Drake. Slip and rotation: the object's grasp point and angle "
            "relative to the pads (mount deflection excluded), from the lift start. *min. static "
            "force*: the elliptic-cone slip force of the steady loads (as for MuJoCo)."
        )

    def __init__(self, *, pad: DrakePad | None = None, timestep: float = 1e-3,
                 approximation: str = "lagged", stiction_tolerance: float = 1e-6):
        self.pad = pad if pad is not None else DrakePad()
        self.timestep = float(timestep)
        self.approximation = approximation
        self.stiction_tolerance = float(stiction_tolerance)
        self.model: _Gripper | None = None
        self.wall_time = 0.0  #: seconds spent in step() since reset

    # --- reset -----------------------------------------------------------------------------
    def reset(self, scene, seed: int | None = None, *, config=None) -> PlantClock:
        cfg = config if config is not None else scene.plant_config(self.name, seed)
        if seed is not None and config is not None:
            cfg = cfg.replace(seed=int(seed))
        spec = scene.scene_spec()
        self.model = g = _Gripper(
            spec, mu=cfg.contact.mu, mass=cfg.object.mass, inertia=cfg.object.inertia,
            cog=cfg.object.cog, pad=self.pad, timestep=self.timestep,
            approximation=self.approximation, stiction_tolerance=self.stiction_tolerance)
        self.spec, self.cfg = spec, cfg
        h = self.timestep
        fs = float(cfg.sensor.rate)
        self._ratio = ratio = max(1, round(1.0 / (fs * h)))
        self._T = ratio * h
        self._rng = np.random.default_rng(cfg.seed)
        self._bias = np.asarray(cfg.sensor.bias, dtype=float)
        self._noise = np.array([cfg.sensor.force_noise] * 3 + [cfg.sensor.torque_noise])
        self._cog = np.asarray(cfg.object.cog, dtype=float)
        a = cfg.actuator
        self._decay = math.exp(-h / a.time_constant) if a.time_constant > 0 else 0.0
        self._step_max = a.rate_limit * h
        self._f_cap = min(float(a.f_max), spec.force_range)
        self._f_act = float(a.f_init)
        self._n = 0  # physics steps so far
        self._i = 0  # next sample index
        self._ref = None
        self._touched = np.zeros(2, dtype=bool)
        self._lost = np.zeros(2, dtype=int)
        self._lift_start = min((x.t_start for x in cfg.moves), default=math.inf)
        self._travel = g.travel
        self._status = {"status": "ok", "detail": "", "time": None, "contact_time": None}
        self.wall_time = 0.0
        return PlantClock(sample_period=self._T,
                          command_ratio=max(1, int(round(fs / a.command_rate))))

    def scene_status(self) -> dict[str, Any]:
        return dict(self._status)

    def estimator(self, config) -> Any:
        """What lugrip's observers and controller believe about this plant's contact when the
        scenario names nothing for it: the pad's law identified on the Drake rubbing rig
        (``objects/drake/pad.yaml``: delta, gamma, the pressure exponent k, sigma0, sigma_z,
        beta_A; ``lugrip simulate-rubbing --plant drake`` then ``lugrip identify``) with the
        object's friction coefficient ``config.contact.mu`` (the pad law is the pad's; the rig
        identifies its own mu within 1.2 %, BENCHMARKS.md)."""
        return pad_parameters().replace(mu=float(config.contact.mu))

    # --- the hand's prescribed motion ------------------------------------------------------
    def _hand(self, t: float) -> np.ndarray:
        """The hand's planar pose (world y, world z offset, roll) at time t."""
        y = sum(mv.dx * min_jerk(t, mv.t_start, mv.duration) for mv in self.cfg.moves)
        z = sum(mv.dy * min_jerk(t, mv.t_start, mv.duration) for mv in self.cfg.moves)
        r = sum(math.radians(w.roll_deg) * min_jerk(t, w.t_start, w.duration)
                for w in self.spec.wrist)
        return np.array([y, z, r])

    # --- step ------------------------------------------------------------------------------
    def step(self, commands) -> PlantSamples:
        wall = time.perf_counter()
        g = self.model
        cmd = np.asarray(commands, dtype=float).reshape(-1)
        n = cmd.shape[0]
        ctx = g.context
        h, ratio = self.timestep, self._ratio
        true = np.zeros((n, 2, 4))
        frac = np.zeros((n, 2))
        grip = np.zeros(n)
        slip_v = np.zeros((n, 2, 3))
        theta = np.zeros(n)
        roll = np.zeros(n)
        rel = np.zeros((n, 2))
        twist = np.zeros((n, 2))
        defl = np.zeros((n, 2))
        finger_q = np.zeros((n, 2))
        external = np.zeros((n, 3))
        hand_z = np.zeros(n)
        polys = np.zeros((n, 2))
        radius = np.zeros((n, 2))
        hj, oj = g.hand_joint, g.obj_joint
        for j in range(n):
            target_cmd = float(cmd[j])
            for _ in range(ratio):
                t = self._n * h
                # the hand's velocity over the step lands it on its planned pose: its position
                # is never set (a teleport would move the hand under the object it holds)
                q = np.array([*hj.get_translation(ctx), hj.get_rotation(ctx)])
                vel = (self._hand(t + h) - q) / h
                hj.set_translational_velocity(ctx, vel[:2])
                hj.set_angular_velocity(ctx, vel[2])
                th = float(oj.get_rotation(ctx))
                wrench = disturbance_wrench(self.cfg.disturbances, t, th)
                # gripper force: first-order lag and rate limit toward the held command
                f = target_cmd + (self._f_act - target_cmd) * self._decay
                f = min(max(f, self._f_act - self._step_max), self._f_act + self._step_max)
                self._f_act = f = min(max(f, 0.0), self._f_cap)
                g.set_inputs(f, wrench)
                g.step()
                self._n += 1
                results = g.plant.get_contact_results_output_port().Eval(ctx)
                for k in (0, 1):
                    w, faces, area = g.sensors[k].read(ctx, results)
                    true[j, k] += w
                    frac[j, k] += w[0] > 0.0
                    polys[j, k] = faces
                    radius[j, k] = math.sqrt(area / math.pi)
                external[j] = wrench
            true[j] /= ratio
            grip[j] = self._f_act
            # ground truth at the end of the sample
            V_o = g.object.EvalSpatialVelocityInWorld(ctx)
            X_o = g.object.EvalPoseInWorld(ctx)
            p_o = X_o.translation()
            pads_c = np.zeros(3)
            for k, (body, pj) in enumerate(g.pads):
                X_p = body.EvalPoseInWorld(ctx)
                V_p = body.EvalSpatialVelocityInWorld(ctx)
                p = X_p.translation()
                pads_c += 0.5 * p
                w_o = V_o.rotational()
                v_o_at = V_o.translational() + np.cross(w_o, p - p_o)
                R = X_p.rotation().matrix()
                dv = R.T @ (v_o_at - V_p.translational())
                dw = R.T @ (w_o - V_p.rotational())
                slip_v[j, k] = (dv[0], dv[1], dw[2])
                q = pj.get_translation(ctx)
                defl[j, k] = math.hypot(q[0], q[1])
                twist[j, k] = _TWIST_SIGN[k] * float(pj.get_rotation(ctx))
                finger_q[j, k] = g.fingers[k].get_translation(ctx)
            theta[j] = float(oj.get_rotation(ctx))
            roll[j] = float(hj.get_rotation(ctx))
            hand_z[j] = float(hj.get_translation(ctx)[1])
            rel[j] = (p_o - pads_c)[1:]
        i0 = self._i
        self._i += n
        t = (i0 + np.arange(n)) * self._T
        meas = true + self._bias + self._rng.normal(0.0, 1.0, (n, 2, 4)) * self._noise
        contact = (frac > 0.0) & (true[:, :, 0] > 1e-4)
        cr, sr = np.cos(roll), np.sin(roll)
        rel_h = np.stack([cr * rel[:, 0] + sr * rel[:, 1], -sr * rel[:, 0] + cr * rel[:, 1]], 1)
        rot = theta - roll - 0.5 * (twist[:, 0] + twist[:, 1])
        if self._ref is None:
            self._ref = (rel_h[0].copy(), float(rot[0]))
        ct, st = np.cos(theta), np.sin(theta)
        cx, cy = self._cog
        cog = np.stack([ct * cx - st * cy, st * cx + ct * cy], 1) + rel
        self._scene_faults(t, contact, finger_q)
        omega = np.where(contact, slip_v[:, :, 2], 0.0)
        v_slip = np.where(contact, np.hypot(slip_v[:, :, 0], slip_v[:, :, 1]), 0.0)
        extra = {
            "pad_deflection_0": defl[:, 0], "pad_deflection_1": defl[:, 1],
            "pad_twist_0": twist[:, 0], "pad_twist_1": twist[:, 1], "roll": roll,
            "patch_polygons_0": polys[:, 0], "patch_polygons_1": polys[:, 1],
            "patch_radius_0": radius[:, 0], "patch_radius_1": radius[:, 1],
        }
        self.wall_time += time.perf_counter() - wall
        return PlantSamples(
            t=t, wrench=meas, wrench_true=true, grip_force=grip, contact=contact,
            slip=rel_h - self._ref[0], rotation=rot - self._ref[1], theta=theta, cog=cog,
            omega=omega, v_slip=v_slip, external=external, gripper_y=hand_z, extra=extra,
        )

    def _object_between(self) -> bool:
        return self.model.object_between()
