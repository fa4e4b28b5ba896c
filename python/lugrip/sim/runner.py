"""The closed loop over any :class:`lugrip.sim.plant.Plant`: the plant's fingertip samples ->
injected sensor faults -> lugrip.SlipControl (each finger's observer and the grasp-force
controller) or a baseline (constant force, friction cone) -> a grip-force command per command
period -> injected actuator faults -> the plant.

The runner owns the schedule (the controller starts at the first command tick after both
fingers touch the object, bumpless from the closing force; mode events at their sample), the
faults, the baselines and the log; the plant only simulates. Each command period is one
``plant.step`` call and one ``SlipControl.run`` call (the samples of the period fed in one C++
loop); a controller without ``run`` (``lugrip ros sim``'s remote controller) is stepped sample by
sample.

:func:`run_plant_loop` returns a :class:`~lugrip.sim.ClosedLoopRun` with the columns of the C++
plants' runs (so one set of metrics serves every plant) plus ``v_slip_i``, ``contact_i`` and the
plant's ``extra`` columns, and ``scene`` (the plant's scene status and ``controller_start``).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from .. import _core
from .._params import ContactParams
from .._slip_control import SlipControl
from ._closed_loop import ClosedLoopRun, _schedule, estimator_params, fault_specs
from .plant import Plant, PlantSamples

__all__ = ["PlantRun", "cone_command", "run_plant_loop"]

#: Status code of a sample before the controller starts (no contact observed yet).
_NO_CONTACT = 3


class PlantRun(ClosedLoopRun):
    """A :class:`ClosedLoopRun` of a :class:`Plant`; ``scene`` holds the plant's scene status
    and the controller's start: {status, detail, time, contact_time, controller_start}."""

    scene: dict[str, Any]


def cone_command(command, fn, ft, mu, margin, release, T, s) -> float:
    """The friction-cone baseline's command (as the C++ closed loop's): raised to
    max_i f_t / (mu margin) when the utilisation f_t / (mu f_n) reaches the margin."""
    u = max((ft[i] / (mu * fn[i]) for i in (0, 1) if fn[i] > 0.0), default=0.0)
    required = max(ft) / (mu * margin)
    target = command
    if u >= margin:
        target = max(command, required)
    elif release > 0.0:
        target = max(required, command - release * T)
    f = min(max(target, command - s["max_rate"] * T), command + s["max_rate"] * T)
    return min(max(f, s["f_min"]), s["f_max"])


_REQUESTS = {"Pivot": 1, "SlippingAvoidance": 2}


def run_plant_loop(
    plant: Plant,
    scene,
    config,
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
    faults=None,
    stuck_samples: int | None = None,
    healthy_finger_fallback: bool = False,
    controller_factory: Callable[..., Any] | None = None,
) -> PlantRun:
    """Simulate the grasp of ``scene`` on ``plant`` in closed loop for ``duration`` seconds.

    Args:
        plant: a :class:`Plant` (:func:`lugrip.sim.plant.make_plant`).
        scene: the scenario (:class:`lugrip.sim.scenarios.Scenario`) the plant builds its scene
            from; config: the run's :class:`lugrip.sim.PlantConfig` (object, contact, actuator,
            sensors, moves, disturbances, drop limits, seed).
        controller_settings, observer_settings, mode_schedule, kind, constant_force,
        cone_margin, cone_release_rate, estimator, faults, stuck_samples,
        healthy_finger_fallback: as :func:`lugrip.sim.run_closed_loop`. The controller starts
            at the first command tick with both fingers in contact (bumpless from the force
            then); before that the gripper closes with ``actuator.f_init``.
        controller_factory: called with SlipControl's arguments instead of
            :class:`lugrip.SlipControl` (an object with its ``step``, ``reset``, ``settings``,
            ``request_*`` and ``set_dynamic_enabled``, and ``run`` for the fast path): ``lugrip
            ros sim`` puts the controller on the other side of the ROS 2 middleware this way.
            An object with a ``ground_truth(omegas)`` method gets each sample's true spin of
            the object on each finger after its step.

    A plant with a ``closed_loop`` method (lugrip's C++ plants) runs the whole loop in that
    one call (same schedule, faults and baselines) unless ``controller_factory`` is given.

    Returns:
        :class:`PlantRun`, one row per sensor sample (a plant's ``closed_loop``: its
        :class:`ClosedLoopRun`, without ``scene``).
    """
    if kind not in ("lugrip", "constant_force", "friction_cone"):
        raise ValueError(f"kind {kind!r}: expected lugrip, constant_force or friction_cone")
    fused = getattr(plant, "closed_loop", None)
    if callable(fused) and controller_factory is None:  # the plant runs the loop in C++
        return fused(config, controller_settings, observer_settings, mode_schedule, duration,
                     kind=kind, constant_force=constant_force, cone_margin=cone_margin,
                     cone_release_rate=cone_release_rate, estimator=estimator, faults=faults,
                     stuck_samples=stuck_samples or 0,
                     healthy_finger_fallback=healthy_finger_fallback)
    contact = config.contact
    est = estimator_params(contact, estimator)
    if est is None:  # the plant's own belief about its contact, when it states one
        own = getattr(plant, "estimator", None)
        est = own(config) if callable(own) else None
    est = est or contact
    clock = plant.reset(scene, config=config)
    T_s = float(clock.sample_period)
    ctrl_s = {"sensor_rate": 1.0 / T_s, "command_ratio": int(clock.command_ratio)}
    ctrl_s.update(dict(controller_settings or {}))
    N = int(ctrl_s["command_ratio"])
    obs_kw = {"torque_noise": float(config.sensor.torque_noise), "dt": T_s}
    obs_kw.update(dict(observer_settings or {}))
    # the baselines command by their own law; SlipControl's observers still run for the log
    ctrl = (controller_factory or SlipControl)(
        est, fingers=2, observer=obs_kw, stuck_samples=stuck_samples,
        healthy_finger_fallback=healthy_finger_fallback, **ctrl_s)
    injector = _core.FaultInjector(fault_specs(faults), T_s) if faults else None
    limits = {k: getattr(ctrl.settings.controller, k)
              for k in ("f_min", "f_max", "max_rate")}
    events = sorted(_schedule(mode_schedule), key=lambda e: e[0]) if kind == "lugrip" else []
    event_samples = [(max(0, math.ceil((t - 1e-9) / T_s - 1e-12)), a) for t, a in events]
    n_samples = int(math.floor(float(duration) / T_s + 1e-9))

    lift_start = min((mv.t_start for mv in config.moves), default=math.inf)
    command = float(config.actuator.f_init)
    carry = command  # the command reaching the gripper during the next sample
    started, ctrl_start, contact_time = False, None, None
    ev = 0
    blocks: list[tuple[PlantSamples, np.ndarray, np.ndarray, np.ndarray, np.ndarray, int]] = []
    i = 0
    while i < n_samples:
        n = 1 if i == 0 else min(N, n_samples - i)
        # the commands reaching the gripper during samples i..i+n-1 (actuator faults per sample)
        cmds = np.empty(n)
        cmds[0] = carry
        fault = np.zeros(n, dtype=bool)
        if injector is None:
            cmds[1:] = command
        else:
            for j in range(1, n):
                cmds[j], fault[j - 1] = injector.actuator(i + j - 1, command)
        out = plant.step(cmds)
        meas = out.wrench
        if injector is not None:
            meas = np.array(meas, dtype=float)
            for j in range(n):
                on, w = injector.sensors(i + j, meas[j].ravel().tolist())
                fault[j] |= on
                meas[j] = np.asarray(w, dtype=float).reshape(2, 4)
        if contact_time is None:
            both = np.flatnonzero(np.asarray(out.contact).all(axis=1))
            if both.size:
                contact_time = float(out.t[both[0]])
        tick_last = (i + n - 1) % N == 0

        # the controller's columns of the block (_LOG), before the start: the closing force
        log = np.empty((n, len(_LOG)))
        log[:] = _before_start(command, est.mu)
        lo = n  # first sample the controller runs on
        if not started:
            # before the start: mode events reach the controller as they fall due
            while ev < len(event_samples) and event_samples[ev][0] <= i + n - 1:
                _apply_event(ctrl, event_samples[ev][1])
                ev += 1
            if contact_time is not None and tick_last:
                started, ctrl_start = True, float(out.t[-1])
                ctrl.reset(force=command)  # bumpless from the closing force
                if kind == "friction_cone":
                    command = limits["f_min"]
                lo = n - 1
        else:
            lo = 0
        if lo < n:
            ev = _run_controller(ctrl, meas[lo:], i + lo, event_samples, ev, out.omega[lo:],
                                 log[lo:])
            if kind == "lugrip":
                command = float(log[-1, 0])
            else:  # the baselines command by their own law
                log[lo:, _BASELINE] = _before_start(command, est.mu)[_BASELINE]
                if tick_last:
                    if kind == "constant_force":
                        command = float(constant_force)
                    else:  # friction_cone: the mean of the period's samples
                        w = meas[lo:]
                        command = cone_command(
                            command, w[:, :, 0].mean(axis=0),
                            np.hypot(w[:, :, 1], w[:, :, 2]).mean(axis=0), est.mu, cone_margin,
                            cone_release_rate, N * T_s, limits)
                    log[-1, _COL["force"]] = log[-1, _COL["static_force"]] = command
                    log[-1, _COL["command_issued"]] = 1.0
        if injector is None:
            carry = command
        else:
            carry, acted = injector.actuator(i + n - 1, command)
            fault[n - 1] |= acted
        blocks.append((out, np.asarray(meas), log, np.append(cmds[1:], carry), fault, lo))
        i += n
    if not blocks:
        raise ValueError(f"duration {duration!r} s is shorter than one sensor sample")
    run = PlantRun(_log(blocks, config, lift_start))
    scene_status = dict(plant.scene_status())
    run.scene = {**scene_status, "contact_time": contact_time, "controller_start": ctrl_start}
    if "dropped" in blocks[0][0].extra:  # the plant's own drop rule (latched)
        return run
    # dropped (latched): from the lift start, the slip or the rotation beyond its limit or the
    # contact lost
    t = run["t"]
    lost_at = scene_status.get("time") if scene_status.get("status") == "lost_contact" else None
    bad = (run["slip"] > config.drop.slip_limit) | (np.abs(run["rotation"]) > config.drop.rotation_limit)
    if lost_at is not None:
        bad |= t >= lost_at - 1e-12
    bad &= t >= lift_start
    run["dropped"] = np.logical_or.accumulate(bad).astype(np.int64)
    return run


#: the controller's columns of the log (lugrip._core.SLIP_CONTROL_LOG_COLUMNS), by index
_LOG = tuple(_core.SLIP_CONTROL_LOG_COLUMNS)
_COL = {name: k for k, name in enumerate(_LOG)}
#: the columns a baseline's law sets (SlipControl, still stepped, gives the statuses and the
#: observers' columns)
_BASELINE = [_COL[x] for x in ("force", "static_force", "dynamic_force", "mu_belief", "mode",
                                "command_issued", "pivot_finished", "pivot_end")]


def _before_start(command: float, mu: float) -> np.ndarray:
    """The controller's columns of a sample it does not compute: the command held, no
    contact observed."""
    row = np.zeros(len(_LOG))
    row[[_COL["force"], _COL["static_force"]]] = command
    row[_COL["mu_belief"]] = mu
    row[[_COL["status"], _COL["status_0"], _COL["status_1"]]] = _NO_CONTACT
    return row


def _log(blocks, config, lift_start: float) -> dict[str, np.ndarray]:
    """The run's columns from its blocks (PlantSamples, measured wrenches, controller columns,
    actuator commands, fault flags, first controller sample)."""
    cat = np.concatenate
    outs = [b[0] for b in blocks]
    meas = cat([b[1] for b in blocks])
    log = cat([b[2] for b in blocks])
    fault = cat([b[4] for b in blocks])
    stepped = cat([np.arange(len(b[0])) >= b[5] for b in blocks])

    def field(name):
        return cat([getattr(o, name) for o in outs])

    t, slip, theta = field("t"), field("slip"), field("theta")
    wt, cog, ext = field("wrench_true"), field("cog"), field("external")
    contact = field("contact").astype(bool)
    omega, v_slip = field("omega"), field("v_slip")
    c: dict[str, np.ndarray] = {"t": t, "command": log[:, _COL["force"]]}
    for name in ("static_force", "dynamic_force", "mu_belief"):
        c[name] = log[:, _COL[name]]
    for name in ("mode", "command_issued", "pivot_finished", "pivot_end", "status"):
        c[name] = log[:, _COL[name]].astype(np.int64)
    c["actuator_command"] = cat([b[3] for b in blocks])
    c["fault_active"] = fault.astype(np.int64)
    c["f_n"] = field("grip_force")
    c["slip_x"], c["slip_y"] = slip[:, 0], slip[:, 1]
    c["slip"] = np.hypot(slip[:, 0], slip[:, 1])
    c["rotation"], c["theta"] = field("rotation"), theta
    c["cog_x"], c["cog_y"] = cog[:, 0], cog[:, 1]
    c["gripper_y"] = field("gripper_y")
    c["ext_fx"], c["ext_fy"], c["ext_tau"] = ext[:, 0], ext[:, 1], ext[:, 2]
    ft_meas = np.hypot(meas[:, :, 1], meas[:, :, 2])
    for k in (0, 1):
        c[f"f_n_meas_{k}"] = meas[:, k, 0]
        c[f"f_t_meas_{k}"] = ft_meas[:, k]
        c[f"tau_meas_{k}"] = meas[:, k, 3]
        c[f"f_t_true_{k}"] = np.hypot(wt[:, k, 1], wt[:, k, 2])
        c[f"tau_true_{k}"] = wt[:, k, 3]
        for name in ("omega_hat", "S", "c_tilde"):
            c[f"{name}_{k}"] = log[:, _COL[f"{name}_{k}"]]
        c[f"observer_status_{k}"] = log[:, _COL[f"status_{k}"]].astype(np.int64)
        c[f"omega_true_{k}"] = omega[:, k]
        c[f"v_slip_{k}"] = v_slip[:, k]
        c[f"contact_{k}"] = contact[:, k].astype(np.int64)
    for name in outs[0].extra:
        c[name] = cat([o.extra[name] for o in outs])
    if "supported" not in c:  # (a plant that knows it reports it among its extra columns)
        # the object rests on its support until both fingers touched it and the lift started
        touched = np.logical_or.accumulate(contact, axis=0).all(axis=1)
        c["supported"] = (~touched | (t < lift_start)).astype(np.int64)
    ok = np.isfinite(c["command"]) & np.isfinite(c["slip"]) & np.isfinite(theta)
    ok &= fault | np.isfinite(meas).all(axis=(1, 2))
    est = np.isfinite(log[:, [_COL[x] for x in ("omega_hat_0", "omega_hat_1", "S_0", "S_1")]])
    ok &= ~stepped | est.all(axis=1)
    c["finite"] = ok.astype(np.int64)
    c.setdefault("dropped", np.zeros(len(t), dtype=np.int64))
    return c


def _apply_event(ctrl, action) -> None:
    name = getattr(action, "name", str(action))
    if name == "Pivot":
        ctrl.request_pivoting()
    elif name == "SlippingAvoidance":
        ctrl.request_slipping_avoidance()
    elif name == "DynamicOn":
        ctrl.set_dynamic_enabled(True)
    elif name == "DynamicOff":
        ctrl.set_dynamic_enabled(False)


def _run_controller(ctrl, meas, i0, event_samples, ev, omega, log) -> int:
    """Feed the controller samples i0.. (meas (n, 2, 4)), each mode event before its sample;
    writes the controller's columns into log (n, len(_LOG)); returns the index of the next
    event. SlipControl takes the samples in one C++ call per run of samples between events
    that are not pivoting requests; another controller is stepped sample by sample."""
    n = meas.shape[0]
    if isinstance(ctrl, SlipControl):
        meas = np.ascontiguousarray(meas, dtype=np.float64)
        start = 0
        while start < n:
            req = np.zeros(n, dtype=np.int32)
            stop = n
            while ev < len(event_samples) and event_samples[ev][0] <= i0 + n - 1:
                j = max(event_samples[ev][0] - i0, start)
                name = getattr(event_samples[ev][1], "name", str(event_samples[ev][1]))
                if name in _REQUESTS:
                    req[j] = _REQUESTS[name]
                elif j == start:
                    _apply_event(ctrl, event_samples[ev][1])
                else:
                    stop = j  # set_dynamic_enabled between two C++ calls
                    break
                ev += 1
            ctrl._sc.run_log(meas[start:stop], req[start:stop], log[start:stop])
            start = stop
        return ev
    for j in range(n):
        while ev < len(event_samples) and event_samples[ev][0] <= i0 + j:
            _apply_event(ctrl, event_samples[ev][1])
            ev += 1
        o = ctrl.step(meas[j])
        c = o.controller
        row = log[j]
        row[_COL["force"]] = o.force
        row[_COL["status"]] = int(getattr(o.status, "value", o.status))
        for name in ("static_force", "dynamic_force", "mu_belief"):
            row[_COL[name]] = getattr(c, name)
        for name in ("mode", "command_issued", "pivot_finished", "pivot_end"):
            v = getattr(c, name)
            row[_COL[name]] = int(getattr(v, "value", v))
        for k, f in enumerate(o.fingers):
            row[_COL[f"omega_hat_{k}"]] = f.omega_hat
            row[_COL[f"S_{k}"]] = f.S
            row[_COL[f"c_tilde_{k}"]] = f.c_tilde
            row[_COL[f"status_{k}"]] = int(getattr(f.status, "value", f.status))
        if hasattr(ctrl, "ground_truth"):  # a remote controller's recording
            ctrl.ground_truth([float(omega[j, 0]), float(omega[j, 1])])
    return ev
