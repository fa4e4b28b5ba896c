"""Closed-loop grasp simulation: plant -> two fingertip sensors -> two observers -> grasp-force
controller (or a baseline) -> gripper command, looping in C++ (``lugrip::ClosedLoop``).

Multi-rate as docs/model.md 9.7 / 10.1: the plant steps at 1 kHz, the sensors, observers and the
controller's C_d run at 500 Hz, the force command is issued at 50 Hz and held (zero-order hold)
by the gripper, whose force follows it with a first-order lag. Deterministic with the plant seed.
"""

from __future__ import annotations

import math
import os
from collections.abc import Iterable, Mapping
from typing import Any

import numpy as np

from .. import _core
from .._contact import _params_path
from .._controller import _core_settings
from .._observer import Observer
from .._params import ContactParams
from ._plant import PlantConfig, _Columns

__all__ = [
    "CONTROLLER_KINDS",
    "FAULT_KINDS",
    "MODE_ACTIONS",
    "ClosedLoopRun",
    "closed_loop_config",
    "estimator_params",
    "fault_specs",
    "run_closed_loop",
]

#: Accepted names of the command laws.
CONTROLLER_KINDS = {
    "lugrip": _core.ControllerKind.Lugrip,
    "constant_force": _core.ControllerKind.ConstantForce,
    "friction_cone": _core.ControllerKind.FrictionCone,
}
#: Accepted names of the mode-schedule actions.
MODE_ACTIONS = {
    "pivot": _core.ModeAction.Pivot,
    "pivoting": _core.ModeAction.Pivot,
    "slipping_avoidance": _core.ModeAction.SlippingAvoidance,
    "avoidance": _core.ModeAction.SlippingAvoidance,
    "dynamic_on": _core.ModeAction.DynamicOn,
    "dynamic_off": _core.ModeAction.DynamicOff,
}

#: Accepted names of the injected faults (sensor faults change what the observers receive,
#: actuator faults what the gripper receives; the plant itself is never altered).
FAULT_KINDS = {
    "dropout": _core.FaultKind.Dropout,
    "nan_burst": _core.FaultKind.NanBurst,
    "spike": _core.FaultKind.Spike,
    "bias_drift": _core.FaultKind.BiasDrift,
    "saturation": _core.FaultKind.Saturation,
    "stuck": _core.FaultKind.Stuck,
    "dead": _core.FaultKind.Dead,
    "contact_loss": _core.FaultKind.ContactLoss,
    "actuator_lag": _core.FaultKind.ActuatorLag,
    "actuator_saturation": _core.FaultKind.ActuatorSaturation,
}
_FAULT_FIELDS = {name for name, _k, _d in _core.FaultSpec.fields} - {"kind"}
_FAULT_INTS = {"finger", "burst", "every"}


def fault_specs(items: Iterable[Mapping[str, Any]] | None) -> list[_core.FaultSpec]:
    """C++ FaultSpecs from mappings such as ``{kind: nan_burst, finger: 0, t_start: 3.0,
    burst: 5, every: 50, duration: 1.0}`` (fields of ``lugrip._core.FaultSpec``; times [s],
    burst lengths and periods [samples], forces [N], torques [N m])."""
    out = []
    for k, item in enumerate(items or []):
        if not isinstance(item, Mapping):
            raise ValueError(f"faults[{k}]: expected a mapping with a 'kind', got {item!r}")  # noqa: TRY004 (file content)
        d = dict(item)
        kind = str(d.pop("kind", "")).lower().replace("-", "_")
        if kind not in FAULT_KINDS:
            raise ValueError(
                f"faults[{k}].kind {item.get('kind')!r}: expected one of {', '.join(FAULT_KINDS)}"
            )
        unknown = sorted(set(d) - _FAULT_FIELDS)
        if unknown:
            raise ValueError(f"faults[{k}]: unknown field(s) {', '.join(unknown)}")
        f = _core.FaultSpec()
        f.kind = FAULT_KINDS[kind]
        for name, v in d.items():
            if name in _FAULT_INTS:
                if isinstance(v, bool) or not isinstance(v, int) or abs(v) > 2**31 - 1:
                    raise ValueError(f"faults[{k}].{name} = {v!r}: must be an integer")
                setattr(f, name, int(v))
            else:
                if isinstance(v, bool) or not isinstance(v, (int, float)):
                    raise ValueError(f"faults[{k}].{name} = {v!r}: must be a number")
                setattr(f, name, float(v))
        out.append(f)
    return out


class ClosedLoopRun(_Columns):
    """Arrays of a closed-loop run, one row per sensor sample (500 Hz), readable as attributes.

    Columns (the C++ ClosedLoopSample, ``lugrip._core.ClosedLoopSample.fields``; SI units;
    per-finger columns end in ``_0`` / ``_1``):

    * time and command: ``index`` (sample number), ``t`` [s], ``command`` (force sent to the gripper, held between
      commands) [N], ``static_force`` / ``dynamic_force`` (f_ns, f_nd of the last command; for the
      baselines static_force = command, dynamic_force = 0) [N], ``f_n`` (true normal force of each
      finger) [N], ``mode`` (ControllerMode code), ``command_issued``, ``pivot_finished``,
      ``pivot_end`` (PivotEnd code);
    * measured (sensor frame): ``f_n_meas_i``, ``f_t_meas_i`` [N], ``tau_meas_i`` [N m]; true
      friction load ``f_t_true_i`` [N], ``tau_true_i`` [N m];
    * observer: ``omega_hat_i`` [rad/s], ``S_i`` [-], ``c_tilde_i`` [-],
      ``observer_status_i`` (Status code); truth: ``omega_true_i`` [rad/s], ``c_tilde_true_i``;
    * object (truth): ``slip_x``, ``slip_y``, ``slip`` (displacement of the grasped object point;
      lumped plant: slip path length) [m], ``rotation`` (theta - theta0) and ``theta`` [rad],
      ``cog_x``, ``cog_y`` (CoG relative to the grasp point) [m], ``gripper_y`` [m],
      ``ext_fx``, ``ext_fy`` [N], ``ext_tau`` [N m] (disturbance), ``supported``, ``dropped``
      (latched), ``finite`` (every value of the row finite; the measured columns excepted
      while an injected fault acts);
    * cycle: ``status`` (Status code the cycle returned: SlipControl's while the lugrip law
      runs, else the worst observer status), ``fault_active`` (an injected fault acted),
      ``actuator_command`` (what reached the gripper after actuator faults) [N].

    Derived: ``S`` = max(S_0, S_1) (what the controller regulates), ``slip_mm``,
    ``rotation_deg``, ``hang_deg`` (angle of grasp point -> CoG from the downward vertical).
    """

    @property
    def S(self) -> np.ndarray:
        return np.maximum(self["S_0"], self["S_1"])

    @property
    def slip_mm(self) -> np.ndarray:
        return self["slip"] * 1e3

    @property
    def rotation_deg(self) -> np.ndarray:
        return np.degrees(self["rotation"])

    @property
    def hang_deg(self) -> np.ndarray:
        return np.degrees(np.arctan2(self["cog_x"], -self["cog_y"]))

    def index(self, t: float) -> int:
        """Row of the sample at (or just before) time t [s]."""
        return int(np.clip(np.searchsorted(self["t"], t + 1e-9) - 1, 0, len(self["t"]) - 1))

    def window(self, t0: float, t1: float) -> slice:
        """Rows with t0 <= t < t1."""
        t = self["t"]
        return slice(int(np.searchsorted(t, t0 - 1e-9)), int(np.searchsorted(t, t1 - 1e-9)))


def _schedule(mode_schedule) -> list[tuple[float, Any]]:
    """[(time, action)] from a mapping {time: action}, pairs or dicts {time, action}."""
    if mode_schedule is None:
        return []
    items = mode_schedule.items() if isinstance(mode_schedule, Mapping) else mode_schedule
    out = []
    for k, item in enumerate(items):
        if isinstance(item, Mapping):
            unknown = set(item) - {"time", "action"}
            if unknown or "time" not in item or "action" not in item:
                raise ValueError(
                    f"mode_schedule[{k}]: expected {{time, action}}, got {dict(item)!r}"
                )
            t, action = item["time"], item["action"]
        else:
            try:
                t, action = item
            except (TypeError, ValueError):
                raise ValueError(
                    f"mode_schedule[{k}]: expected (time, action), got {item!r}"
                ) from None
        if isinstance(action, str):
            key = action.lower().replace("-", "_").replace(" ", "_")
            if key not in MODE_ACTIONS:
                raise ValueError(
                    f"mode_schedule[{k}]: unknown action {action!r}; "
                    f"expected one of {', '.join(MODE_ACTIONS)}"
                )
            action = MODE_ACTIONS[key]
        t = float(t)
        if not math.isfinite(t):
            raise ValueError(f"mode_schedule[{k}]: time {t!r} must be finite")
        out.append((t, action))
    return out


def estimator_params(
    plant_contact: ContactParams,
    estimator: ContactParams | Mapping[str, Any] | str | os.PathLike | None,
) -> ContactParams | None:
    """The contact parameters the estimator side (observers, controller) uses.

    ``None``: the plant's own (returns None). A :class:`ContactParams` is used as is; a
    parameter YAML file (a path, or a str ending in .yaml/.yml, e.g. written by
    ``lugrip identify``) is read; a preset name (``"big_resin_block"``) loads that object; a
    mapping with ``preset`` loads it and applies the other keys; any other mapping overrides
    fields of the plant's parameters, e.g. ``{"sigma_z": 0.0033}`` (a fingertip whose
    pre-sliding damping differs from Table 1).
    """
    if estimator is None:
        return None
    if isinstance(estimator, ContactParams):
        return estimator
    if _params_path(estimator) is not None:
        return ContactParams.from_yaml(_params_path(estimator))
    if isinstance(estimator, str):
        return ContactParams.preset(estimator)
    if isinstance(estimator, Mapping):
        d = dict(estimator)
        if "preset" in d:
            return ContactParams.preset(str(d.pop("preset"))).replace(**d)
        return plant_contact.replace(**d)
    raise ValueError(
        "estimator: expected None, ContactParams, a YAML file, a preset name or a mapping"
    )


def closed_loop_config(
    config: PlantConfig | Mapping[str, Any],
    controller_settings: Mapping[str, Any] | None = None,
    observer_settings: Mapping[str, Any] | None = None,
    mode_schedule: Iterable | Mapping | None = None,
    *,
    kind: str = "lugrip",
    controller_start: float = 0.0,
    constant_force: float = 1.0,
    cone_margin: float = 0.8,
    cone_release_rate: float = 0.0,
    estimator: ContactParams | Mapping[str, Any] | str | None = None,
    faults: Iterable[Mapping[str, Any]] | None = None,
    stuck_samples: int = 0,
    healthy_finger_fallback: bool = False,
) -> _core.ClosedLoopConfig:
    """The validated C++ ClosedLoopConfig (see :func:`run_closed_loop` for the arguments)."""
    plant = config if isinstance(config, PlantConfig) else PlantConfig.from_dict(config)
    fs = float(plant.sensor.rate)
    ctrl = {"sensor_rate": fs, "command_ratio": round(fs / float(plant.actuator.command_rate))}
    ctrl.update(dict(controller_settings or {}))
    obs = {"torque_noise": float(plant.sensor.torque_noise)}
    obs.update(dict(observer_settings or {}))
    obs.setdefault("dt", 1.0 / fs)
    if str(kind) not in CONTROLLER_KINDS:
        raise ValueError(f"kind {kind!r}: expected one of {', '.join(CONTROLLER_KINDS)}")
    c = _core.ClosedLoopConfig()
    c.plant = plant.to_core()
    est = estimator_params(plant.contact, estimator)
    # A parameter YAML from identification carries the observer it was identified with (its
    # observer: block); Observer(path) starts from it, the settings above override it.
    path = None if estimator is None else _params_path(estimator)
    c.observer = Observer(path if path is not None else (est or plant.contact), **obs)._settings
    if est is not None:
        c.estimator = est.to_core()
    c.controller = _core_settings(ctrl)
    c.kind = CONTROLLER_KINDS[str(kind)]
    c.controller_start = float(controller_start)
    c.constant_force = float(constant_force)
    c.cone_margin = float(cone_margin)
    c.cone_release_rate = float(cone_release_rate)
    for t, action in _schedule(mode_schedule):
        c.add_event(t, action)
    for f in fault_specs(faults):
        c.add_fault(f)
    if isinstance(stuck_samples, bool) or not isinstance(stuck_samples, int) or stuck_samples < 0:
        raise ValueError(f"stuck_samples = {stuck_samples!r}: must be an integer >= 0 (0: off)")
    c.stuck_samples = int(stuck_samples)
    c.healthy_finger_fallback = bool(healthy_finger_fallback)
    msg = _core.validate_closed_loop_config(c)
    if msg:
        raise ValueError("invalid closed-loop configuration:\n" + msg.rstrip())
    return c


def run_closed_loop(
    config: PlantConfig | Mapping[str, Any],
    controller_settings: Mapping[str, Any] | None = None,
    observer_settings: Mapping[str, Any] | None = None,
    mode_schedule: Iterable | Mapping | None = None,
    duration: float = 10.0,
    *,
    kind: str = "lugrip",
    controller_start: float = 0.0,
    constant_force: float = 1.0,
    cone_margin: float = 0.8,
    cone_release_rate: float = 0.0,
    estimator: ContactParams | Mapping[str, Any] | str | None = None,
    faults: Iterable[Mapping[str, Any]] | None = None,
    stuck_samples: int = 0,
    healthy_finger_fallback: bool = False,
) -> ClosedLoopRun:
    """Simulate the grasp in closed loop for `duration` seconds (one C++ call).

    Args:
        config: the plant (object, contact, actuator, sensors, lift, disturbances, seed): a
            :class:`PlantConfig` or a mapping for ``PlantConfig.from_dict``.
        controller_settings: GraspController settings (``lugrip.controller_settings()`` lists
            them); ``sensor_rate`` and ``command_ratio`` default to the plant's rates. The force
            range and rate limits also bound the baselines.
        observer_settings: keyword arguments of :class:`lugrip.Observer` for both fingers;
            ``dt`` defaults to 1 / sensor rate and ``torque_noise`` to the sensor's.
        mode_schedule: controller actions, e.g. ``[(11.5, "pivot")]`` or
            ``[{"time": 11.5, "action": "pivot"}]``; actions: pivot, slipping_avoidance,
            dynamic_on, dynamic_off. Ignored by the baselines.
        duration: simulated time [s]; rows at t = 0, T, ..., (N - 1) T with T = 1 / sensor rate.
        kind: "lugrip" (the paper's controller), "constant_force" or "friction_cone" (baselines).
        controller_start: before this time [s] the command stays at the actuator's ``f_init``.
        constant_force: command of the constant-force baseline [N].
        cone_margin: friction-cone baseline: the command is raised to max_i |f_t,i| / (mu margin)
            when the measured utilisation |f_t| / (mu f_n) reaches the margin; blind to torsion.
        cone_release_rate: friction-cone baseline: decrease rate while below the margin [N/s]
            (0: the command only rises).
        estimator: contact parameters of the observers and the controller (what the robot
            believes about the contact), see :func:`estimator_params`; None: the plant's own.
            A YAML written by ``lugrip identify`` also brings its ``observer:`` block (the
            observer it was identified with) as the base of `observer_settings`.
        faults: injected sensor/actuator faults (:func:`fault_specs` mappings); the plant is
            never altered, only what the observers read and what the gripper receives.
        stuck_samples: the lugrip law reports SensorFault (and holds the command) when a
            finger's wrench repeats bit for bit this many samples in a row; 0: off.
        healthy_finger_fallback: the lugrip law: with one finger faulty the other computes
            the command (instead of holding it).

    Returns:
        :class:`ClosedLoopRun` (dict of numpy arrays).

    Raises:
        ValueError: invalid plant, settings or schedule (every problem listed).
    """
    c = closed_loop_config(
        config,
        controller_settings,
        observer_settings,
        mode_schedule,
        kind=kind,
        controller_start=controller_start,
        constant_force=constant_force,
        cone_margin=cone_margin,
        cone_release_rate=cone_release_rate,
        estimator=estimator,
        faults=faults,
        stuck_samples=stuck_samples,
        healthy_finger_fallback=healthy_finger_fallback,
    )
    duration = float(duration)
    if not (math.isfinite(duration) and duration >= 0.0):
        raise ValueError(f"duration {duration!r}: must be finite and >= 0")
    loop = _core.ClosedLoop(c)
    n = round(duration / loop.sample_period)
    return ClosedLoopRun(loop.run(n))
