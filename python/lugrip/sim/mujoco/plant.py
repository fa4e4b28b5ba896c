"""The MuJoCo gripper as a :class:`lugrip.sim.plant.Plant` (registered as "mujoco").

MuJoCo steps at 1 kHz; the fingertip sensors average the pad wrench over their 2 ms sample and
add bias and noise. Every physics step runs in C++ (:mod:`lugrip._mjstep`): the hand's moves,
the disturbances, the gripper's lag and rate limit toward the held command, each pad's
torsional coefficient from its normal force of the step before, ``mj_step`` and the pad
wrench; :meth:`MujocoPlant.step` makes one call for a run of sensor samples and turns its rows
into :class:`~lugrip.sim.plant.PlantSamples` with numpy.

The sensor reads the pad's wrench in the pad frame of :mod:`lugrip.sim.mujoco.pad` (torque
about the pad axis, from the face into the finger). ``extra`` columns: ``pad_deflection_i``
(the pad's in-plane spring deflection [m]), ``pad_twist_i`` (its twist about world x [rad]),
``roll`` (the hand's roll [rad]).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import mujoco
import numpy as np

from ..plant import PlantClock, PlantSamples
from ..scene_faults import SceneWatch
from .gripper import build_scene

try:
    from ... import _mjstep
except ImportError as _err:  # built against another MuJoCo, or without MuJoCo's headers
    _mjstep = None
    _MJSTEP_ERROR = str(_err)

__all__ = ["MujocoPlant"]

#: pulse shape codes of lugrip._mjstep
_SHAPES = {"rectangular": 0, "rect": 0, "half_sine": 1, "halfsine": 1, "ramp": 2, "triangle": 3}


def _stepper_module():
    if _mjstep is None:
        raise ImportError(
            "lugrip._mjstep (the MuJoCo plant's C++ stepper) could not be loaded: "
            f"{_MJSTEP_ERROR}. It is built against the mujoco package present when lugrip is "
            f"installed (mujoco {mujoco.__version__} is imported now): reinstall lugrip with "
            "this mujoco, e.g. pip install --force-reinstall --no-deps lugrip"
        )
    return _mjstep


class MujocoPlant(SceneWatch):
    """The MuJoCo gripper of a scenario's ``mujoco:`` block (:class:`SceneSpec`).

    Args:
        frame_callback: called as f(model, data, t) after every sensor sample (rendering); the
            samples are then stepped one C++ call each.
    """

    name = "mujoco"

    @staticmethod
    def report_method() -> str:
        """The plant as ``lugrip simulate --plant mujoco``'s report describes it."""
        return (
            "Plant: MuJoCo " + mujoco.__version__ + ", two force-controlled fingers with "
            "compliant 12 mm spherical pads (4 N/mm in-plane and 2 N m/rad twist springs between "
            "finger and pad), elliptic cone, condim 4 with the torsional coefficient μ ξ ρ(f_n) "
            "of the present normal force, noslip 10, 1 ms steps; fingertip wrench (the object's "
            "action on each pad) averaged over 2 ms, 500 Hz, noise 0.005 N / 0.01 N mm; command "
            "at 50 Hz through a 30 ms lag and a 200 N/s rate limit. The observers and controller "
            "use each scenario's estimator block for MuJoCo (the shipped files: the pad and each "
            "object's μ identified on MuJoCo rubbing data, validation/mujoco/README.md). Slip "
            "and rotation: the object's grasp point and angle relative to the pads (pad spring "
            "deflection excluded), from the lift start. *min. static force*: MuJoCo's own slip "
            "force for the steady loads (its cone with μ_spin(f)); for the patch plant lugrip's "
            "limit surface. The wrist roll is MuJoCo only (the patch plant has no wrist "
            "rotation); the seeds vary the sensor noise."
        )

    def __init__(self, *, frame_callback: Callable[[Any, Any, float], None] | None = None):
        self.frame_callback = frame_callback
        self.model = self.data = None

    # --- reset -----------------------------------------------------------------------------
    def reset(self, scene, seed: int | None = None, *, config=None) -> PlantClock:
        mj = _stepper_module()
        cfg = config if config is not None else scene.plant_config(self.name, seed)
        if seed is not None and config is not None:
            cfg = cfg.replace(seed=int(seed))
        spec = scene.scene_spec()
        m, pads = build_scene(
            spec, params=cfg.contact, mass=cfg.object.mass, inertia=cfg.object.inertia,
            cog=cfg.object.cog,
        )
        d = mujoco.MjData(m)
        self.model, self.data, self.spec, self.cfg = m, d, spec, cfg
        h = float(m.opt.timestep)
        fs = float(cfg.sensor.rate)
        ratio = max(1, round(1.0 / (fs * h)))
        self._T = ratio * h
        self._rng = np.random.default_rng(cfg.seed)
        self._bias = np.asarray(cfg.sensor.bias, dtype=float)  # per finger f_n, f_x, f_y, tau
        self._noise = np.array([cfg.sensor.force_noise] * 3 + [cfg.sensor.torque_noise])
        self._travel = float(m.jnt_range[m.joint("f0").id][1])
        self._bodies = tuple(
            mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, n) for n in ("pad0", "pad1")
        )
        self._object_geom = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, "object")

        c = mj.StepperConfig()
        c.ratio = ratio
        qadr = lambda j: int(m.joint(j).qposadr[0])  # noqa: E731
        c.q_theta, c.q_roll, c.q_hz = qadr("otheta"), qadr("hroll"), qadr("hz")
        c.q_finger = [qadr("f0"), qadr("f1")]
        names = [p.spec.joint_names for p in pads]
        c.q_px = [qadr(n[0]) for n in names]
        c.q_py = [qadr(n[1]) for n in names]
        c.q_pt = [qadr(n[2]) for n in names]
        c.body_object = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "object")
        c.body_pad = [p.body_id for p in pads]
        c.geom_pad = [p.geom_id for p in pads]
        c.pairs0, c.pairs1 = ([int(i) for i in p.pair_ids] for p in pads)
        c.dofs0, c.dofs1 = ([int(i) for i in p.joint_dof] for p in pads)
        c.damp0, c.damp1 = ([float(x) for x in p._damping] for p in pads)
        ps = pads[0].spec
        c.mu, c.xi, c.delta, c.gamma, c.f_n_floor = ps.mu, ps.xi, ps.delta, ps.gamma, ps.f_n_floor
        a = cfg.actuator
        c.decay = math.exp(-h / a.time_constant) if a.time_constant > 0 else 0.0
        c.step_max = a.rate_limit * h
        c.f_cap = min(float(a.f_max), spec.force_range)
        mv = cfg.moves
        c.move_t0 = [x.t_start for x in mv]
        c.move_T = [x.duration for x in mv]
        c.move_dx = [x.dx for x in mv]
        c.move_dy = [x.dy for x in mv]
        c.wrist_t0 = [w.t_start for w in spec.wrist]
        c.wrist_T = [w.duration for w in spec.wrist]
        c.wrist_roll = [math.radians(w.roll_deg) for w in spec.wrist]
        ds = cfg.disturbances
        c.dist_t0 = [x.t_start for x in ds]
        c.dist_T = [x.duration for x in ds]
        c.dist_px = [x.point[0] for x in ds]
        c.dist_py = [x.point[1] for x in ds]
        c.dist_fx = [x.force[0] for x in ds]
        c.dist_fy = [x.force[1] for x in ds]
        c.dist_tau = [x.torque for x in ds]
        c.dist_shape = [_SHAPES.get(x.shape, 3) for x in ds]
        c.cog = [float(v) for v in cfg.object.cog]
        self._stepper = mj.Stepper(m._address, d._address, c, float(a.f_init))
        self._pads = pads  # keeps the pair ids' owner alive with the model

        self._i = 0  # next sample index
        self._ref = None  # pose of the grasp point relative to the pads at sample 0
        self._touched = np.zeros(2, dtype=bool)
        self._lost = np.zeros(2, dtype=int)
        self._lift_start = min((x.t_start for x in mv), default=math.inf)
        self._status = {"status": "ok", "detail": "", "time": None, "contact_time": None}
        command_ratio = round(fs / a.command_rate)
        return PlantClock(sample_period=self._T, command_ratio=max(1, int(command_ratio)))

    def scene_status(self) -> dict[str, Any]:
        return dict(self._status)

    # --- step ------------------------------------------------------------------------------
    def step(self, commands) -> PlantSamples:
        cmd = np.ascontiguousarray(commands, dtype=np.float64).reshape(-1)
        n = cmd.shape[0]
        rows = np.empty((n, _mjstep.COLUMNS))
        if self.frame_callback is None:
            self._stepper.run(cmd, rows)
        else:
            for j in range(n):
                self._stepper.run(cmd[j : j + 1], rows[j : j + 1])
                self.frame_callback(self.model, self.data, (self._i + j) * self._T)
        i0 = self._i
        self._i += n
        t = (i0 + np.arange(n)) * self._T
        true = rows[:, 0:8].reshape(n, 2, 4)
        meas = true + self._bias + self._rng.normal(0.0, 1.0, (n, 2, 4)) * self._noise
        contact = rows[:, 9:11] > 0.5
        if self._ref is None:
            self._ref = (rows[0, 18:20].copy(), float(rows[0, 20]))
        self._scene_faults(t, contact, rows[:, 27:29])
        twist = rows[:, 23:25]
        extra = {
            "pad_deflection_0": rows[:, 25], "pad_deflection_1": rows[:, 26],
            "pad_twist_0": twist[:, 0], "pad_twist_1": twist[:, 1], "roll": rows[:, 16],
        }
        return PlantSamples(
            t=t, wrench=meas, wrench_true=true, grip_force=rows[:, 8], contact=contact,
            slip=rows[:, 18:20] - self._ref[0], rotation=rows[:, 20] - self._ref[1],
            theta=rows[:, 15], cog=rows[:, 21:23], omega=rows[:, 11:13], v_slip=rows[:, 13:15],
            external=rows[:, 29:32], gripper_y=rows[:, 17], extra=extra,
        )

    @property
    def mj_step_seconds(self) -> float:
        """CPU time spent inside ``mj_step`` since reset [s] (the stepping thread's clock)."""
        return float(self._stepper.mj_step_seconds)

    def _object_between(self) -> bool:
        """The line between the pad centres passes through the object (now: the scene fault
        is checked at the end of the run of samples it occurred in)."""
        m, d = self.model, self.data
        p0 = d.xpos[self._bodies[0]].copy()
        vec = d.xpos[self._bodies[1]] - p0
        gid = np.array([-1], dtype=np.int32)
        dist = mujoco.mj_ray(m, d, p0, vec, None, 1, self._bodies[0], gid)
        return dist >= 0.0 and int(gid[0]) == self._object_geom
