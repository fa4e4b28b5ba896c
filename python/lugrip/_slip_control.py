"""SlipControl: fingertip wrenches in, grasp-force command out (C++ ``lugrip::SlipControl``).

One object per gripper replaces the hand wiring of two :class:`lugrip.Observer` and a
:class:`lugrip.GraspController`: each finger's observer runs on its wrench and the controller
gets omega_hat, S, c~, f_t, the speed resolution and the observer status of every finger, so a
contact loss or a bad sample holds the command instead of lowering it.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from . import _core
from ._contact import _as_params, _model, _params_path
from ._controller import (
    REQUEST_PIVOTING,
    REQUEST_SLIPPING_AVOIDANCE,
    ControllerMode,
    _code,
    _core_settings,
)
from ._nocopy import NoCopy
from ._observer import Observer
from ._observer import read_observer_settings
from ._params import ContactParams

__all__ = ["SlipControl", "SlipControlRun"]


class SlipControlRun(dict):
    """Per-sample arrays of :meth:`SlipControl.run`, readable as attributes: the controller's
    output fields (``force``, ``static_force``, ``dynamic_force``, ``slippage``, ``mode``,
    ``status``, ``held``, ``pivot_finished``, ..., ``dynamic_sample_0``/``_1``; the names of
    ``lugrip._core.GraspControllerOutput.fields``) and each finger's observer fields suffixed
    ``_0`` / ``_1`` (``omega_hat_0``, ``S_1``, ``status_0``, ...; the names of
    ``lugrip._core.ObserverOutput.fields``)."""

    def __getattr__(self, name):
        try:
            return self[name]
        except KeyError:
            raise AttributeError(name) from None

    def __len__(self) -> int:
        return len(self["force"])

    def finger(self, i: int) -> dict[str, np.ndarray]:
        """The observer columns of finger i, without the suffix."""
        suffix = f"_{int(i)}"
        names = [name for name, _k, _d in _core.ObserverOutput.fields]
        return {name: self[name + suffix] for name in names if name + suffix in self}


#: Codes of SlipControl.step's ``command`` (lugrip::CommandTiming).
_COMMAND_CODES = {"clock": 0, "now": 1, "hold": 2}


class SlipControl(NoCopy):
    """Slip detection and grasp-force control for a parallel gripper with one or two
    force/torque fingertips (paper eqs. 19-23 and 34-37; docs/model.md §7, §9).

    ``step(wrenches)`` takes each fingertip's wrench as its sensor reads it (the object on the
    fingertip, z along the contact normal): one row (f_n [N], f_x [N], f_y [N], tau [N m]) per
    finger, i.e. a (2, 4) array for two fingers, and returns the command to send with each
    finger's observer output. Every observer status reaches the controller: on contact loss
    (f_n below the contact threshold), a NaN/Inf/out-of-range sample or a sensor fault the
    command due is held, never lowered.

    Args:
        params: ContactParams, a preset name, a dict, or a parameter YAML (a path, or a str
            ending in .yaml/.yml). A file written by ``lugrip identify`` carries the observer the
            parameters were identified with (its ``observer:`` block): that is the observer used,
            with ``observer`` overriding it key by key.
        fingers: 1 or 2 fingertips measured.
        stuck_samples: a finger with a valid estimate whose four channels repeat bit for bit
            this many samples in a row is reported SensorFault (a frozen sensor, or a link
            repeating its last sample) and the command is held; 0: off (a noise-free simulated
            sensor repeats legitimately). None: the C++ default, 25 (50 ms at 500 Hz).
        healthy_finger_fallback: two fingers, one without a valid estimate: the other finger
            alone computes the command (the status still reports the faulty finger) instead of
            the command being held.
        observer: keywords of :class:`lugrip.Observer` (integrator, bandwidth, torque_noise, ...).
            Its ``dt`` defaults to 1 / ``sensor_rate`` when neither the file nor this mapping
            gives one.
        **controller: GraspController settings (``lugrip.controller_settings()`` lists them):
            f_min, f_max [N], max_rate [N/s], s_ref, k_p, k_i, sensor_rate
            [Hz], command_ratio, pivoting settings, ...

    The rates are checked once here: the observer's dt must equal 1 / sensor_rate.

    Raises:
        ValueError: naming every invalid setting or parameter, or a rate mismatch.

    Thread safety: an object belongs to the first thread that uses it; a call from any other
    thread raises RuntimeError (the C++ loops release the GIL, so two threads would interleave
    their samples). Create one SlipControl per thread.

    Example::

        sc = lugrip.SlipControl("fit.yaml", f_min=0.2, f_max=15.0)
        out = sc.step(np.array([[f_n0, fx0, fy0, tau0], [f_n1, fx1, fy1, tau1]]))
        gripper.send(out.force)
    """

    def __init__(
        self,
        params,
        *,
        fingers: int = 2,
        observer: Mapping[str, Any] | None = None,
        stuck_samples: int | None = None,
        healthy_finger_fallback: bool = False,
        **controller: Any,
    ):
        path = _params_path(params)
        self._params: ContactParams = _as_params(params)
        ctrl = _core_settings(controller)
        obs = dict(observer or {})
        block = read_observer_settings(path) if path is not None else None
        if "dt" not in obs and not (block and block.get("dt") is not None):
            obs["dt"] = 1.0 / ctrl.sensor_rate
        s = _core.SlipControlSettings()
        s.observer = Observer(path if path is not None else self._params, **obs)._settings
        s.controller = ctrl
        if isinstance(fingers, bool) or fingers not in (1, 2):
            raise ValueError(f"fingers = {fingers!r}: must be 1 or 2")
        s.fingers = int(fingers)
        if stuck_samples is not None:
            if (isinstance(stuck_samples, bool) or not isinstance(stuck_samples, int)
                    or stuck_samples < 0):
                raise ValueError(
                    f"stuck_samples = {stuck_samples!r}: must be an integer >= 0 (0: off)")
            s.stuck_samples = int(stuck_samples)
        s.healthy_finger_fallback = bool(healthy_finger_fallback)
        try:
            self._sc = _core.SlipControl(_model(self._params), s)
        except ValueError as err:
            raise ValueError(str(err)) from None

    # --- properties ------------------------------------------------------------------------
    @property
    def params(self) -> ContactParams:
        """The contact parameters (mu as last set by :meth:`set_mu`)."""
        return self._params

    @property
    def fingers(self) -> int:
        return self._sc.fingers

    @property
    def command(self) -> float:
        """The last command [N]."""
        return self._sc.command

    @property
    def mode(self) -> ControllerMode:
        return ControllerMode(_code(self._sc.mode))

    @property
    def mu(self) -> float:
        return self._sc.mu

    @property
    def settings(self) -> _core.SlipControlSettings:
        """The effective C++ settings (observer, controller, fingers); a copy."""
        return self._sc.settings

    # --- the cycle -------------------------------------------------------------------------
    def step(self, wrenches, dt: float = 0.0, command: str = "clock"):
        """One cycle at the sensor rate.

        Args:
            wrenches: (fingers, 4) values (f_n, f_x, f_y, tau) per finger, a float64 array for
                the fast path (any array-like is converted). One finger also takes (4,), and
                a (2, 4) array's first row; any other shape (a transposed (4, 2), a flat (8,))
                raises ValueError.
            dt: [s] time since the previous cycle; 0 means the nominal period.
            command: when this cycle computes a command: ``"clock"`` (the first cycle after
                reset and every ``command_ratio``-th after it), ``"now"`` (from the samples up
                to this one; the clock restarts here) or ``"hold"`` (none). A gripper that takes
                one command per batch of samples passes ``"now"`` with the batch's newest
                sample and ``"hold"`` with the others, so the command it sends is not a period
                old.

        Returns:
            ``lugrip._core.SlipControlOutput``: ``force`` (the command [N]), ``status``
            (Status.Ok, or the worst status of the cycle: the command was held), ``controller``
            (GraspControllerOutput: static/dynamic parts, mode, pivot_finished, held, ...) and
            ``fingers`` (each finger's ObserverOutput). Never raises on bad samples.
        """
        code = _COMMAND_CODES.get(command)
        if code is None:
            raise ValueError(f"command {command!r}: expected one of {list(_COMMAND_CODES)}")
        if not isinstance(wrenches, np.ndarray):
            wrenches = np.ascontiguousarray(wrenches, dtype=np.float64)
        shape = wrenches.shape
        n = self._sc.fingers
        if shape != (n, 4) and not (n == 1 and shape in ((4,), (2, 4))):
            # a transposed (4, 2) or a flat (8,) array would otherwise be read row by row
            one = ", or (4,)" if n == 1 else ""
            raise ValueError(f"wrenches of shape {shape}: expected 4 values (f_n, f_x, f_y, "
                             f"tau) per finger, a ({n}, 4) array{one}")
        try:
            return self._sc.step(wrenches, dt, code)
        except TypeError:
            return self._sc.step(np.ascontiguousarray(wrenches, dtype=np.float64), float(dt), code)

    def run(self, wrenches, dt=None, requests=None, commands=None) -> SlipControlRun:
        """Step over N cycles in one C++ loop (state carried over between calls).

        Args:
            wrenches: (N, fingers, 4) array (one finger: (N, 4) too).
            dt: None (nominal period) or (N,) sample periods [s] (0: nominal).
            requests: None, (N,) ints applied before each sample (0 none,
                REQUEST_PIVOTING, REQUEST_SLIPPING_AVOIDANCE) or a dict {sample index:
                "pivoting" | "slipping_avoidance"}.
            commands: None (the controller's clock) or (N,) bools, True where a command is due
                (computed from the samples since the last one, this one included) and False
                where none is (see :meth:`step`).

        Returns:
            :class:`SlipControlRun`.
        """
        w = np.ascontiguousarray(wrenches, dtype=np.float64)
        if w.ndim == 2 and self.fingers == 1 and w.shape[1] == 4:
            w = w.reshape(-1, 1, 4)
        if w.ndim != 3 or w.shape[2] != 4:
            raise ValueError(f"wrenches: expected shape (N, {self.fingers}, 4), got {w.shape}")
        n = w.shape[0]
        d = np.zeros(0) if dt is None else np.ascontiguousarray(np.broadcast_to(dt, (n,)), dtype=np.float64)
        req = np.zeros(n, dtype=np.int32)
        if isinstance(requests, Mapping):
            codes = {"pivoting": REQUEST_PIVOTING, "slipping_avoidance": REQUEST_SLIPPING_AVOIDANCE}
            for index, what in requests.items():
                if what not in codes:
                    raise ValueError(f"unknown request {what!r}; expected one of {list(codes)}")
                req[int(index)] = codes[what]
        elif requests is not None:
            req[:] = np.asarray(requests, dtype=np.int32)
        if commands is None:
            cmd = np.zeros(0, dtype=np.int32)
        else:
            due = np.asarray(commands)
            if due.shape != (n,) or due.dtype != bool:
                raise ValueError(f"commands: expected ({n},) bools, got {due.dtype} {due.shape}")
            cmd = np.where(due, _COMMAND_CODES["now"], _COMMAND_CODES["hold"]).astype(np.int32)
        return SlipControlRun(self._sc.run(w, d, req, cmd))

    # --- run-time calls --------------------------------------------------------------------
    def reset(self, force: float | None = None) -> None:
        """Observers forgotten, controller back to slipping avoidance; ``force`` [N] (default
        f_min) is held until the next step, which starts from it."""
        self._sc.reset(self._sc.controller_settings.f_min if force is None else float(force))

    def request_pivoting(self) -> None:
        """Start pivoting at the next step (from the last command)."""
        self._sc.request_pivoting()

    def request_slipping_avoidance(self) -> None:
        """End pivoting at the next step (``pivot_end`` = REQUESTED)."""
        self._sc.request_slipping_avoidance()

    def set_dynamic_enabled(self, enabled: bool) -> None:
        self._sc.set_dynamic_enabled(bool(enabled))

    def set_mu(self, mu: float) -> None:
        """New friction coefficient for the observers and the controller (the per-object refit;
        the controller's learned belief restarts from it). Real-time safe in C++ (mu scales the
        contact maps; no table is rebuilt). The observers restart at the next sample; the
        controller keeps its mode and command."""
        mu = float(mu)
        params = self._params.replace(mu=mu)  # validates (ValueError naming mu)
        self._sc.set_mu(mu)
        self._params = params

    def update_settings(self, **changes: Any) -> None:
        """Change run-time controller settings (all but sensor_rate, command_ratio, k_cd, p_cd,
        z_cd)."""
        s = self._sc.controller_settings
        values = {name: getattr(s, name) for name, _k, _d in _core.GraspControllerSettings.fields}
        values.update(changes)
        try:
            self._sc.set_controller_settings(_core_settings(values))
        except ValueError as err:
            raise ValueError(str(err)) from None

    def __repr__(self) -> str:
        return (
            f"SlipControl({self._params!r}, fingers={self.fingers}, mode={self.mode.name}, "
            f"command={self.command!r})"
        )
