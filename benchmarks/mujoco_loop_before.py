"""The MuJoCo closed loop as it was before the Plant interface and the C++ stepper (lugrip
0.1.0's ``lugrip.sim.mujoco.loop.run_mujoco_loop``, kept verbatim but for its imports) for
benchmarks/bench_mujoco_loop.py, which times it against the present loop in the same run.
Python runs every physics step here: the hand's moves, the disturbance, the actuator, each pad's
torsional law, wrench and slip velocity.

Closed loop on the MuJoCo gripper: MuJoCo at 1 kHz -> fingertip wrench sensors at 500 Hz
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
from collections.abc import Callable, Mapping
from typing import Any

import mujoco
import numpy as np

from lugrip import _core
from lugrip._params import ContactParams
from lugrip._slip_control import SlipControl
from lugrip.sim._closed_loop import ClosedLoopRun, _schedule, estimator_params, fault_specs
from lugrip.sim._plant import PlantConfig
from lugrip.sim.mujoco.gripper import SceneSpec, build_scene
# unchanged since: the disturbance rule and the friction-cone baseline's law
from lugrip.sim.mujoco.loop import cone_slip_force, disturbance_wrench  # noqa: F401
from lugrip.sim.runner import cone_command as _cone_command

__all__ = [
    "SCENE_STATUS",
    "MujocoRun",
    "cone_slip_force",
    "disturbance_wrench",
    "run_mujoco_loop",
]

#: Scene status codes of a MuJoCo run, by name.
SCENE_STATUS = {
    "ok": "both pads touched the object and kept contact from the lift start on",
    "object_not_reached": "a pad never touched the object: it is not between the fingers",
    "closed_on_nothing": "a finger reached its closing stop without touching anything",
    "lost_contact": "a pad lost contact with the object after the grasp was established",
}

#: Consecutive contact-free sensor samples after which a pad's contact counts as lost.
_LOST_SAMPLES = 10


class MujocoRun(ClosedLoopRun):
    """A :class:`ClosedLoopRun` of the MuJoCo plant; ``scene`` holds the scene status:
    {status, detail, time, contact_time, controller_start}."""

    scene: dict[str, Any]


def _min_jerk(t: float, t0: float, T: float) -> float:
    u = min(max((t - t0) / T, 0.0), 1.0) if T > 0 else float(t >= t0)
    return u**3 * (10.0 - 15.0 * u + 6.0 * u * u)


def run_mujoco_loop(
    plant: PlantConfig,
    scene: SceneSpec,
    controller_settings: Mapping[str, Any] | None = None,
    observer_settings: Mapping[str, Any] | None = None,
    mode_schedule=None,
    duration: float = 10.0,
    *,
    kind: str = "lugrip",
    constant_force: float = 1.0,
    cone_margin: float = 0.8,
    cone_release_rate: float = 0.0,
    estimator: ContactParams | Mapping[str, Any] | str | None = None,
    frame_callback: Callable[[mujoco.MjModel, mujoco.MjData, float], None] | None = None,
    faults=None,
    stuck_samples: int | None = None,
    healthy_finger_fallback: bool = False,
    controller_factory: Callable[..., Any] | None = None,
) -> MujocoRun:
    """Simulate the scenario's grasp on MuJoCo in closed loop for `duration` seconds.

    Args:
        plant: the scenario's plant block (object mass, inertia and CoG; contact; actuator lag,
            rate limit and f_init; sensor rate, noise and bias; moves; disturbances; drop
            limits; seed). ``plant.rate`` is replaced by ``scene.timestep``.
        scene: the MuJoCo scene (object shape, pads, wrist rolls, solver settings).
        controller_settings, observer_settings, mode_schedule, kind, constant_force,
        cone_margin, cone_release_rate, estimator: as :func:`lugrip.sim.run_closed_loop`.
            The controller starts when both pads first touch the object (bumpless from the
            force then); before that the gripper closes with ``actuator.f_init``.
        frame_callback: called as f(model, data, t) at every sensor sample (rendering).
        faults, stuck_samples, healthy_finger_fallback: injected sensor/actuator faults, the
            frozen-sensor check (None: SlipControl's default, on) and the one-faulty-finger
            policy, as
            :func:`lugrip.sim.run_closed_loop` (the same C++ FaultInjector: sensor faults change
            the wrenches SlipControl receives, actuator faults the command the gripper gets).
        controller_factory: called with SlipControl's arguments instead of
            :class:`lugrip.SlipControl` (an object with its ``step``, ``reset``, ``settings``,
            ``request_*`` and ``set_dynamic_enabled``): ``lugrip ros sim`` puts the controller
            on the other side of the ROS 2 middleware this way. An object with a
            ``ground_truth(omegas)`` method gets each sample's ``omega_true_0/1`` after its
            step (published for recordings).

    Returns:
        :class:`MujocoRun`, one row per sensor sample.
    """
    contact = plant.contact
    est = estimator_params(contact, estimator) or contact
    m, pads = build_scene(
        scene,
        params=contact,
        mass=plant.object.mass,
        inertia=plant.object.inertia,
        cog=plant.object.cog,
    )
    d = mujoco.MjData(m)
    h = m.opt.timestep
    fs = float(plant.sensor.rate)
    ratio = max(1, round(1.0 / (fs * h)))
    T_s = ratio * h
    ctrl_s = {"sensor_rate": 1.0 / T_s, "command_ratio": round(fs / plant.actuator.command_rate)}
    ctrl_s.update(dict(controller_settings or {}))
    n_cmd = int(ctrl_s["command_ratio"])
    obs_kw = {"torque_noise": float(plant.sensor.torque_noise), "dt": T_s}
    obs_kw.update(dict(observer_settings or {}))
    # the baselines command by their own law; SlipControl's observers still run for the log
    ctrl = (controller_factory or SlipControl)(est, fingers=2, observer=obs_kw, stuck_samples=stuck_samples,
        healthy_finger_fallback=healthy_finger_fallback, **ctrl_s)
    injector = _core.FaultInjector(fault_specs(faults), T_s) if faults else None
    limits = {
        k: getattr(ctrl.settings.controller, k)
        for k in ("f_min", "f_max", "max_rate")
    }
    events = sorted(_schedule(mode_schedule), key=lambda e: e[0]) if kind == "lugrip" else []
    rng = np.random.default_rng(plant.seed)
    bias = np.asarray(plant.sensor.bias, dtype=float)  # per finger f_n, f_x, f_y, tau
    noise = np.array([plant.sensor.force_noise] * 3 + [plant.sensor.torque_noise])

    body = {
        n: mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, n) for n in ("object", "pad0", "pad1")
    }
    obj_geom = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, "object")
    q = {
        j: int(m.joint(j).qposadr[0])
        for j in ("oy", "oz", "otheta", "hy", "hz", "hroll", "f0", "f1")
    }
    for k in (0, 1):
        jx, jy, jt = pads[k].spec.joint_names
        q[f"p{k}x"], q[f"p{k}y"], q[f"p{k}t"] = (int(m.joint(j).qposadr[0]) for j in (jx, jy, jt))
    #: the pad's twist axis (its z) along world x: -1 for pad 0, +1 for pad 1
    twist_sign = (-1.0, 1.0)
    f0_range = m.jnt_range[m.joint("f0").id].copy()
    travel = float(f0_range[1])
    cog = np.asarray(plant.object.cog, dtype=float)

    a_cfg = plant.actuator
    decay = math.exp(-h / a_cfg.time_constant) if a_cfg.time_constant > 0 else 0.0
    f_act = command = gripper_cmd = float(a_cfg.f_init)
    f_cap = min(float(a_cfg.f_max), scene.force_range)
    moves = plant.moves
    wrist = scene.wrist
    n_steps = round(float(duration) / h)
    n_samples = n_steps // ratio

    cols: dict[str, np.ndarray] = {}

    def col(name, dtype=float):
        cols[name] = np.zeros(n_samples, dtype=dtype)
        return cols[name]

    names_f = ["t", "command", "static_force", "dynamic_force", "f_n", "slip_x", "slip_y", "slip", "rotation", "theta", "cog_x", "cog_y", "gripper_y", "ext_fx", "ext_fy", "ext_tau", "roll"]
    for name in names_f:
        col(name)
    for name in (
        "mode",
        "command_issued",
        "pivot_finished",
        "pivot_end",
        "supported",
        "dropped",
        "finite",
        "status",
        "fault_active",
    ):
        col(name, np.int64)
    col("actuator_command")
    col("mu_belief")
    for k in (0, 1):
        for name in (
            "f_n_meas",
            "f_t_meas",
            "tau_meas",
            "f_t_true",
            "tau_true",
            "omega_hat",
            "S",
            "c_tilde",
            "omega_true",
            "v_slip",
            "pad_deflection",
            "pad_twist",
        ):
            col(f"{name}_{k}")
        col(f"observer_status_{k}", np.int64)
        col(f"contact_{k}", np.int64)

    acc = np.zeros((2, 5))
    slip_v = np.zeros((2, 3))
    started = False
    ctrl_start = None
    contact_time = None
    status, detail, status_time = "ok", "", None
    touched = [False, False]
    lost_count = [0, 0]
    dropped = False
    last_fn = np.zeros(2)  # normal force of each pad at the last step [N]
    ev = 0
    cone_sum = np.zeros((2, 2))
    cone_n = 0
    out = None
    drop_cfg = plant.drop
    lift_start = min((mv.t_start for mv in moves), default=math.inf)
    ref = None  # pose of the grasp point relative to the pads at t = 0

    for n in range(n_samples * ratio):
        t = n * h
        # hand: translations (gripper frame X -> world y, Y -> world z) and roll
        d.ctrl[2] = sum(mv.dx * _min_jerk(t, mv.t_start, mv.duration) for mv in moves)
        d.ctrl[3] = sum(mv.dy * _min_jerk(t, mv.t_start, mv.duration) for mv in moves)
        d.ctrl[4] = sum(
            math.radians(w.roll_deg) * _min_jerk(t, w.t_start, w.duration) for w in wrist
        )
        theta = float(d.qpos[q["otheta"]])
        fx, fy, tz = disturbance_wrench(plant.disturbances, t, theta)
        d.xfrc_applied[body["object"]] = (0.0, fx, fy, tz, 0.0, 0.0)
        # gripper force: first-order lag and rate limit toward the held command
        target = gripper_cmd + (f_act - gripper_cmd) * decay
        step_max = a_cfg.rate_limit * h
        f_act = min(max(target, f_act - step_max), f_act + step_max)
        f_act = min(max(f_act, 0.0), f_cap)
        d.ctrl[0] = d.ctrl[1] = f_act
        # torsional coefficient from the last normal force of each pad
        for k in (0, 1):
            pads[k].update(m, d, f_n=last_fn[k])
        mujoco.mj_step(m, d)
        for k in (0, 1):
            w = pads[k].wrench(m, d)
            acc[k, :4] += w
            acc[k, 4] += w[0] > 0.0  # in contact
            last_fn[k] = max(pads[k].f_n_last, 0.0)
        if (n + 1) % ratio:
            continue
        for k in (0, 1):
            v = pads[k].slip_velocity(m, d)
            slip_v[k] = 0.0 if np.isnan(v[0]) else v
        i = (n + 1) // ratio - 1
        ts = i * T_s
        true = acc / ratio  # the sensor's average over its sample period (anti-alias)
        acc[:] = 0.0
        meas = true[:, :4] + bias + rng.normal(0.0, 1.0, (2, 4)) * noise
        fault_on = False
        if injector is not None:
            fault_on, w = injector.sensors(i, meas.ravel().tolist())
            meas = np.asarray(w, dtype=float).reshape(2, 4)
        in_contact = [true[k, 4] > 0 and true[k, 0] > 1e-4 for k in (0, 1)]
        for k in (0, 1):
            touched[k] = touched[k] or in_contact[k]

        # scene faults (never raise: the run goes on, the status says what happened)
        if status == "ok":
            at_stop = [float(d.qpos[q[f"f{k}"]]) >= travel - 2e-4 for k in (0, 1)]
            if not all(touched) and any(at_stop[k] and not touched[k] for k in (0, 1)):
                k = next(k for k in (0, 1) if at_stop[k] and not touched[k])
                between = _object_between(m, d, (body["pad0"], body["pad1"]), obj_geom)
                status = "closed_on_nothing" if between else "object_not_reached"
                detail = f"finger {k} closed to its stop without contact" + (
                    "" if between else "; the object is not between the fingers"
                )
                status_time = ts
            elif not all(touched) and ts >= lift_start:
                status, status_time = "object_not_reached", ts
                detail = f"pad(s) {[k for k in (0, 1) if not touched[k]]} without contact at the lift start"
            elif all(touched):
                for k in (0, 1):
                    lost_count[k] = 0 if in_contact[k] else lost_count[k] + 1
                    if lost_count[k] >= _LOST_SAMPLES and status == "ok":
                        status, status_time = "lost_contact", ts
                        detail = f"pad {k} without contact for {_LOST_SAMPLES * T_s * 1e3:.0f} ms"
        if contact_time is None and all(in_contact):
            contact_time = ts

        # controller
        while ev < len(events) and events[ev][0] <= ts + 1e-9:
            action = events[ev][1]
            name = getattr(action, "name", str(action))
            if name == "Pivot":
                ctrl.request_pivoting()
            elif name == "SlippingAvoidance":
                ctrl.request_slipping_avoidance()
            elif name == "DynamicOn":
                ctrl.set_dynamic_enabled(True)
            elif name == "DynamicOff":
                ctrl.set_dynamic_enabled(False)
            ev += 1
        ft_meas = np.hypot(meas[:, 1], meas[:, 2])
        if not started:
            out = None
        else:
            out = ctrl.step(meas)
        samples = out.fingers if out is not None else None
        tick = i % n_cmd == 0
        if not started and contact_time is not None and tick:
            started, ctrl_start = True, ts
            ctrl.reset(force=command)  # bumpless from the closing force
            if kind == "friction_cone":
                command = limits["f_min"]
            out = ctrl.step(meas)
            samples = out.fingers
        issued = pf = 0
        pend = 0
        if started:
            if kind == "lugrip":
                c = out.controller
                command = out.force
                issued, pf = int(c.command_issued), int(c.pivot_finished)
                pend = int(getattr(c.pivot_end, "value", c.pivot_end))
            elif kind == "constant_force":
                if tick:
                    command, issued = float(constant_force), 1
            elif kind == "friction_cone":
                cone_sum[:, 0] += meas[:, 0]
                cone_sum[:, 1] += ft_meas
                cone_n += 1
                if tick:
                    mean = cone_sum / cone_n
                    command = _cone_command(
                        command,
                        mean[:, 0],
                        mean[:, 1],
                        est.mu,
                        cone_margin,
                        cone_release_rate,
                        n_cmd * T_s,
                        limits,
                    )
                    cone_sum[:] = 0.0
                    cone_n = 0
                    issued = 1
            else:
                raise ValueError(f"kind {kind!r}: expected lugrip, constant_force or friction_cone")

        # ground truth: the object's grasp point relative to the pads, in the hand's frame
        roll = float(d.qpos[q["hroll"]])
        pads_c = 0.5 * (d.xpos[body["pad0"]][1:] + d.xpos[body["pad1"]][1:])
        gp = d.xpos[body["object"]][1:]  # the object frame's origin is the grasp point
        cr, sr = math.cos(roll), math.sin(roll)
        rel = gp - pads_c
        rel_h = np.array([cr * rel[0] + sr * rel[1], -sr * rel[0] + cr * rel[1]])
        twist = [twist_sign[k] * float(d.qpos[q[f"p{k}t"]]) for k in (0, 1)]  # about world x
        theta = float(d.qpos[q["otheta"]])
        rot = theta - roll - 0.5 * (twist[0] + twist[1])
        if ref is None:
            ref = (rel_h.copy(), rot)
        slip_vec = rel_h - ref[0]
        rotation = rot - ref[1]
        c_th, s_th = math.cos(theta), math.sin(theta)
        cog_w = np.array([c_th * cog[0] - s_th * cog[1], s_th * cog[0] + c_th * cog[1]]) + rel
        if not dropped and ts >= lift_start:
            dropped = bool(
                np.hypot(*slip_vec) > drop_cfg.slip_limit
                or abs(rotation) > drop_cfg.rotation_limit
                or status == "lost_contact"
            )

        gripper_cmd = command
        if injector is not None:
            gripper_cmd, acted = injector.actuator(i, command)
            fault_on = fault_on or acted
        cols["t"][i] = ts
        cols["command"][i] = command
        cols["actuator_command"][i] = gripper_cmd
        cols["fault_active"][i] = int(fault_on)
        if out is not None:
            cols["status"][i] = int(getattr(out.status, "value", out.status))
        else:
            cols["status"][i] = 3  # before the first touch: no contact
        lug = kind == "lugrip" and started and out is not None
        cols["static_force"][i] = out.controller.static_force if lug else command
        cols["dynamic_force"][i] = out.controller.dynamic_force if lug else 0.0
        cols["mu_belief"][i] = out.controller.mu_belief if lug else est.mu
        cols["mode"][i] = (
            int(getattr(out.controller.mode, "value", out.controller.mode)) if lug else 0
        )
        cols["command_issued"][i] = issued
        cols["pivot_finished"][i] = pf
        cols["pivot_end"][i] = pend
        cols["f_n"][i] = f_act
        cols["slip_x"][i], cols["slip_y"][i] = slip_vec
        cols["slip"][i] = float(np.hypot(*slip_vec))
        cols["rotation"][i] = rotation
        cols["theta"][i] = theta
        cols["cog_x"][i], cols["cog_y"][i] = cog_w
        cols["gripper_y"][i] = float(d.qpos[q["hz"]])
        cols["ext_fx"][i], cols["ext_fy"][i], cols["ext_tau"][i] = fx, fy, tz
        cols["roll"][i] = roll
        cols["supported"][i] = int(not all(touched) or ts < lift_start)
        cols["dropped"][i] = int(dropped)
        for k in (0, 1):
            o = samples[k] if samples is not None else None
            cols[f"f_n_meas_{k}"][i] = meas[k, 0]
            cols[f"f_t_meas_{k}"][i] = ft_meas[k]
            cols[f"tau_meas_{k}"][i] = meas[k, 3]
            cols[f"f_t_true_{k}"][i] = math.hypot(true[k, 1], true[k, 2])
            cols[f"tau_true_{k}"][i] = true[k, 3]
            if o is not None:
                cols[f"omega_hat_{k}"][i] = o.omega_hat
                cols[f"S_{k}"][i] = o.S
                cols[f"c_tilde_{k}"][i] = o.c_tilde
                cols[f"observer_status_{k}"][i] = int(getattr(o.status, "value", o.status))
            else:  # before the first touch: no contact, nothing observed
                cols[f"observer_status_{k}"][i] = 3
            # the object's motion relative to pad k at the pad face: spin about the pad's z
            # (the sensor's torque axis) and the in-plane slip speed
            cols[f"omega_true_{k}"][i] = slip_v[k, 2] if in_contact[k] else 0.0
            cols[f"v_slip_{k}"][i] = (
                math.hypot(slip_v[k, 0], slip_v[k, 1]) if in_contact[k] else 0.0
            )
            cols[f"pad_deflection_{k}"][i] = math.hypot(d.qpos[q[f"p{k}x"]], d.qpos[q[f"p{k}y"]])
            cols[f"pad_twist_{k}"][i] = twist[k]
            cols[f"contact_{k}"][i] = int(in_contact[k])
        if started and hasattr(ctrl, "ground_truth"):  # a remote controller's recording
            ctrl.ground_truth([cols[f"omega_true_{k}"][i] for k in (0, 1)])
        row_ok = math.isfinite(command) and all(
            math.isfinite(cols[c][i]) for c in ("slip", "theta")
        )
        row_ok = row_ok and (fault_on or bool(np.all(np.isfinite(meas))))
        if samples is not None:
            row_ok = row_ok and all(
                math.isfinite(samples[k].omega_hat) and math.isfinite(samples[k].S) for k in (0, 1)
            )
        cols["finite"][i] = int(row_ok)
        if frame_callback is not None:
            frame_callback(m, d, ts)

    run = MujocoRun(cols)
    run.scene = {
        "status": status,
        "detail": detail,
        "time": status_time,
        "contact_time": contact_time,
        "controller_start": ctrl_start,
    }
    return run


def _object_between(m: mujoco.MjModel, d: mujoco.MjData, pad_bodies, object_geom: int) -> bool:
    """The line between the pad centres passes through the object."""
    p0 = d.xpos[pad_bodies[0]].copy()
    vec = d.xpos[pad_bodies[1]] - p0
    gid = np.array([-1], dtype=np.int32)
    dist = mujoco.mj_ray(m, d, p0, vec, None, 1, pad_bodies[0], gid)
    return dist >= 0.0 and int(gid[0]) == object_geom
