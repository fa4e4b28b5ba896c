"""Grasp-force controller (slipping avoidance + pivoting) and the static grasp force.

Thin layer over the C++ ``lugrip::GraspController`` and ``lugrip::StaticForceSolver``
(include/lugrip/grasp_controller.hpp, docs/model.md section 9). Loops run in C++.
"""

from __future__ import annotations

import enum
from dataclasses import make_dataclass
from typing import Any

import numpy as np

from . import _core
from ._contact import Status, _as_params, _flat, _model, _shaped
from ._nocopy import NoCopy
from ._params import ContactParams

__all__ = [
    "PAPER_SETTINGS",
    "REQUEST_NONE",
    "REQUEST_PIVOTING",
    "REQUEST_SLIPPING_AVOIDANCE",
    "ControllerMode",
    "ControllerOutput",
    "ControllerRun",
    "GraspController",
    "PivotEnd",
    "controller_settings",
    "static_grasp_force",
    "static_slippage",
]

#: Codes of the ``requests`` array of :meth:`GraspController.run`.
REQUEST_NONE, REQUEST_PIVOTING, REQUEST_SLIPPING_AVOIDANCE = 0, 1, 2

# Names and kinds from the C++ field table (bindings/tables.hpp); the defaults stay in C++.
_SETTINGS_FIELDS = tuple(name for name, _kind, _doc in _core.GraspControllerSettings.fields)
_INT_FIELDS = tuple(name for name, kind, _doc in _core.GraspControllerSettings.fields if kind == "int")
_BOOL_FIELDS = tuple(name for name, kind, _doc in _core.GraspControllerSettings.fields if kind == "bool")


#: The paper's law (eqs. 34-37) as settings, from the C++ preset ``paper_settings()``: constant
#: PI gains (k_p = 4 N, k_i = 10 N/s), no feed-forward, reflex, lag overshoot, reserve, ceiling or learned mu. Pass them
#: to compare with lugrip's defaults: ``GraspController(params, **PAPER_SETTINGS)``. Three
#: implementation choices without a setting apply to it too (docs/controller.md §1): the PI's S
#: is the mean over the command period, C_d's input has a dead band of the observer's speed
#: resolution, and the pivot's end test is lugrip's.
_PAPER, _DEFAULTS = _core.paper_settings(), _core.GraspControllerSettings()
PAPER_SETTINGS: dict[str, Any] = {
    name: getattr(_PAPER, name)
    for name in _SETTINGS_FIELDS
    if getattr(_PAPER, name) != getattr(_DEFAULTS, name)
}


class ControllerMode(enum.IntEnum):
    """Operating mode; values equal the C++ lugrip::ControllerMode."""

    SLIPPING_AVOIDANCE = 0
    PIVOTING = 1


class PivotEnd(enum.IntEnum):
    """Why pivoting ended; values equal the C++ lugrip::PivotEnd."""

    NONE = 0
    COR_THRESHOLD = 1  #: low-passed mean |c~| > 1 on 3 consecutive samples
    TIMEOUT = 2
    REQUESTED = 3
    AT_FLOOR = 4  #: the pivoting filter held at its floor for 1 s


def _code(e) -> int:
    """Integer value of a nanobind enum member."""
    return int(getattr(e, "value", e))


def controller_settings() -> dict[str, Any]:
    """The default settings (the C++ GraspControllerSettings defaults), as a dict."""
    s = _core.GraspControllerSettings()
    return {name: getattr(s, name) for name in _SETTINGS_FIELDS}


def _core_settings(values: dict[str, Any]) -> _core.GraspControllerSettings:
    s = _core.GraspControllerSettings()
    for name, value in values.items():
        if name not in _SETTINGS_FIELDS:
            known = ", ".join(_SETTINGS_FIELDS)
            raise ValueError(f"unknown controller setting {name!r}; known: {known}")
        try:
            if name in _BOOL_FIELDS:
                value = bool(value)
            elif name in _INT_FIELDS:
                if float(value) != int(value):
                    raise ValueError
                value = int(value)
            else:
                value = float(value)
        except (TypeError, ValueError, OverflowError):
            raise ValueError(f"controller setting {name} = {value!r}: must be a number") from None
        setattr(s, name, value)
    message = _core.validate_controller_settings(s)
    if message:
        raise ValueError("invalid controller settings:\n" + message.rstrip())
    return s


#: (name, kind, doc) of every GraspControllerOutput field, from the C++ field table.
OUTPUT_FIELDS = tuple(_core.GraspControllerOutput.fields)
_ENUMS = {"mode": ControllerMode, "pivot_end": PivotEnd, "status": Status}
_KIND_TYPES = {"float": float, "int": int, "bool": bool, "pair": tuple}


def _output_from_core(cls, o):
    values = {}
    for name, kind, _doc in OUTPUT_FIELDS:
        v = getattr(o, name)
        values[name] = _ENUMS[name](_code(v)) if kind == "enum" else v
    return cls(**values)


def _attribute_list(fields) -> str:
    return "\n".join(f"        {name}: {doc}" for name, _kind, doc in fields)


ControllerOutput = make_dataclass(
    "ControllerOutput",
    [(name, _ENUMS[name] if kind == "enum" else _KIND_TYPES[kind]) for name, kind, _d in OUTPUT_FIELDS],
    frozen=True,
    namespace={"_from_core": classmethod(_output_from_core), "__module__": __name__},
)
ControllerOutput.__doc__ = (
    "Output of one :meth:`GraspController.step` (the C++ GraspControllerOutput).\n\n"
    "    Attributes (generated from the C++ struct; mode, pivot_end and status as ControllerMode,\n"
    "    PivotEnd and Status; dynamic_sample a tuple per finger):\n" + _attribute_list(OUTPUT_FIELDS) + "\n    "
)

ControllerRun = make_dataclass(
    "ControllerRun",
    [(name, np.ndarray) for name, _k, _d in OUTPUT_FIELDS],
    frozen=True,
    namespace={"__module__": __name__},
)
ControllerRun.__doc__ = """Per-sample outputs of :meth:`GraspController.run`; arrays of shape (N,), except
    ``dynamic_sample`` (N, 2). ``mode``, ``pivot_end`` and ``status`` hold the integer codes of
    ControllerMode, PivotEnd and Status. Fields as in :class:`ControllerOutput`."""


def _per_finger(value, n: int | None, name: str, dtype) -> np.ndarray:
    """Broadcast a scalar, (N,) or (N, 2) input to (N, 2)."""
    a = np.asarray(value, dtype=dtype)
    if a.ndim == 1:
        a = a[:, None]
    if a.ndim > 2 or (a.ndim == 2 and a.shape[1] not in (1, 2)):
        raise ValueError(f"{name}: expected a scalar, shape (N,) or (N, 2), got {a.shape}")
    return np.ascontiguousarray(np.broadcast_to(a, (n, 2)))


class GraspController(NoCopy):
    """Two-mode grasp-force controller f_n = f_ns + f_nd (paper eqs. 34-37, docs/model.md 9).

    * Dynamic part f_nd = |C_d omega_hat|, C_d(s) = k_cd (s + z_cd)/(s + p_cd) discretised by
      Tustin at the sensor rate (one filter per finger); the peak over the last command period
      is handed to the command; clipped to the head-room [0, f_max - f_ns].
    * Static part: PI on e = S - s_ref (e > 0 raises the force), forward Euler at the command
      rate, clipped to [f_min, f_max] with back-calculation anti-windup, bumpless starts.
    * Pivoting: f_nd = 0, tau_p df/dt = -f + k_p (S - s_pivot) (exact discretisation), floor
      max(f_min, 1.1 f_t / mu); ends when a 0.2 s low-pass of the mean |c~_i| exceeds 1 on 3
      samples while the force sits at that floor and S < 0.99 (the paper: the sample's mean
      |c~_i| on 3 samples from the start), after 1 s at the floor, after 10 s or on request, then returns bumplessly to slipping avoidance.
    * step() at the sensor rate (500 Hz); a command every ``command_ratio`` calls (50 Hz), held.
    * Two fingers: S = max_i S_i, f_nd from max_i |C_d omega_hat_i|, pivot end on the mean |c~_i|.
    * Invalid input (NaN/Inf, Status INVALID_SAMPLE / SENSOR_FAULT / NO_CONTACT on a present
      finger): the command is held, never lowered.

    Args:
        params: ContactParams, a preset name or a dict (mu for the pivoting floor; the whole
            contact model for the feed-forward and the slope).
        **settings: any GraspControllerSettings field (see :func:`controller_settings` for the
            names and defaults): the gripper (sensor_rate [Hz], command_ratio, f_min, f_max [N],
            max_rate [N/s], inf = off), the PI (s_ref, k_p [N], k_i [N/s],
            gain_force [N]: gains that follow the plant's slope dS/df_n, 0 = constant), C_d
            (k_cd [N s/rad], p_cd, z_cd [rad/s]; :meth:`set_dynamic_enabled` switches it), the
            floors and ceiling from the measured load (load_floors, reserve_force [N],
            reserve_torque [N m], ceiling_factor), mu_probe: the grip probe that learns mu
            (needs f_n; output mu_belief), pivoting (s_pivot, tau_pivot [s]). See
            :data:`PAPER_SETTINGS` for the paper's law.

    Raises:
        ValueError: unknown or invalid setting (one line per bad field) or invalid params.

    Example::

        ctrl = lugrip.GraspController("aluminium_can", f_min=0.1)
        out = ctrl.step(omega_hat=0.0, S=0.9, c_tilde=1.5, f_t=0.12)   # one finger
        out = ctrl.step(omega_hat=[0.0, 0.01], S=[0.7, 0.9], c_tilde=[1.5, 1.4], f_t=[1, 1])
        run = ctrl.run(omega_hat=w, S=S, c_tilde=c, f_t=ft)              # (N,) or (N, 2) arrays
    """

    def __init__(self, params, **settings: Any):
        self._params = _as_params(params)
        core = _core_settings(settings)
        try:
            self._ctrl = _core.GraspController(_model(self._params), core)
        except ValueError as err:
            raise ValueError(str(err)) from None

    # --- properties ------------------------------------------------------------------------
    @property
    def params(self) -> ContactParams:
        return self._params

    @property
    def settings(self) -> dict[str, Any]:
        s = self._ctrl.settings
        return {name: getattr(s, name) for name in _SETTINGS_FIELDS}

    @property
    def mode(self) -> ControllerMode:
        return ControllerMode(_code(self._ctrl.mode))

    @property
    def command(self) -> float:
        """The last command [N]."""
        return self._ctrl.command

    @property
    def command_period(self) -> float:
        """[s] command_ratio / sensor_rate."""
        return self._ctrl.command_period

    @property
    def dynamic_filter_coefficients(self) -> tuple[float, float, float]:
        """Tustin coefficients (b0, b1, a1) of C_d: y[n] = b0 u[n] + b1 u[n-1] - a1 y[n-1]."""
        f = self._ctrl.dynamic_filter
        return (f.b0, f.b1, f.a1)

    # --- commands --------------------------------------------------------------------------
    def reset(self, current_force: float | None = None) -> None:
        """Slipping avoidance, filters zeroed; the next step() starts bumplessly from
        ``current_force`` [N] (default f_min)."""
        force = self.settings["f_min"] if current_force is None else float(current_force)
        self._ctrl.reset(force)

    def request_pivoting(self) -> None:
        """Start pivoting at the next step() (from the last command, no jump)."""
        self._ctrl.request_pivoting()

    def request_slipping_avoidance(self) -> None:
        """End pivoting at the next step() (PivotEnd.REQUESTED), bumplessly."""
        self._ctrl.request_slipping_avoidance()

    def set_dynamic_enabled(self, enabled: bool) -> None:
        """Switch the dynamic part; re-enabling restarts C_d from rest."""
        self._ctrl.set_dynamic_enabled(bool(enabled))

    def update_settings(self, **changes: Any) -> None:
        """Change run-time settings (all but sensor_rate, command_ratio, k_cd, p_cd, z_cd)."""
        values = self.settings
        values.update(changes)
        try:
            self._ctrl.set_settings(_core_settings(values))
        except ValueError as err:
            raise ValueError(str(err)) from None

    # --- stepping --------------------------------------------------------------------------
    def step(self, omega_hat, S, c_tilde=0.0, f_t=0.0, status=Status.OK,
             present=None, omega_resolution=0.0, tau=0.0, f_n=0.0) -> ControllerOutput:
        """One sensor sample. Scalars describe finger 0 alone (finger 1 absent unless `present`
        says otherwise, then it gets the same values); length-2 sequences describe both fingers.

        Args:
            omega_hat: estimated sliding velocity [rad/s]; S: slippage indicator [-];
            c_tilde: normalized CoR [-]; f_t: tangential force [N]; status: observer Status;
            present: per-finger bools (default: the fingers given).
            omega_resolution: the observer's speed resolution [rad/s] (``omega_resolution`` of
                its output): the dead band of C_d's input.
            tau: measured torsional moment [N m] (signed), with f_t the load of the
                feed-forward and of the slope (``load_floors``, ``gain_force``).
            f_n: measured normal force [N] (the grip probe, ``mu_probe``; 0: unknown, no probe).
        """
        vals = [np.atleast_1d(np.asarray(v, dtype=np.float64))
                for v in (omega_hat, S, c_tilde, f_t, omega_resolution, tau, f_n)]
        st = np.atleast_1d(np.asarray(status, dtype=np.int64))
        n_fingers = max(len(v) for v in vals + [st])
        if n_fingers > 2 or any(len(v) not in (1, n_fingers) for v in vals + [st]):
            raise ValueError("per-finger inputs must be scalars or sequences of length 2")
        vals = [np.broadcast_to(v, (2,)) for v in vals]
        st = np.broadcast_to(st, (2,))
        if present is None:
            pres = (True, n_fingers == 2)
        else:
            p = np.broadcast_to(np.asarray(present, dtype=bool), (2,))
            pres = (bool(p[0]), bool(p[1]))
        w, s, c, f, r, tq, fn = (tuple(float(x) for x in v) for v in vals)
        o = self._ctrl.step(w[0], s[0], c[0], f[0], int(st[0]), pres[0],
                            w[1], s[1], c[1], f[1], int(st[1]), pres[1], r[0], r[1], tq[0], tq[1],
                            fn[0], fn[1])
        return ControllerOutput._from_core(o)

    def run(self, omega_hat, S, c_tilde=0.0, f_t=0.0, status=None, present=None,
            requests=None, omega_resolution=0.0, tau=0.0, f_n=0.0) -> ControllerRun:
        """Step over N sensor samples in one C++ loop (state carried over between calls).

        Args:
            omega_hat, S, c_tilde, f_t: scalars, (N,) arrays (one finger) or (N, 2) arrays;
                shape (1, 2) gives per-finger constants.
            status: Status codes, scalar, (N,) or (N, 2) (default Status.OK).
            present: bools, (2,) per finger or (N, 2) (default: finger 1 present only when some
                input has shape (N, 2)).
            requests: (N,) ints applied before each sample (REQUEST_NONE, REQUEST_PIVOTING,
                REQUEST_SLIPPING_AVOIDANCE), or a dict {sample index: "pivoting" |
                "slipping_avoidance"}.
            omega_resolution: the observers' speed resolution [rad/s], like omega_hat (the
                dead band of C_d's input; default 0: none).
            tau: measured torsional moment [N m], like f_t (feed-forward and slope load).
            f_n: measured normal force [N], like f_t (the grip probe; 0: unknown, no probe).

        Returns:
            ControllerRun with (N,) arrays.
        """
        arrays = [np.asarray(v) for v in (omega_hat, S, c_tilde, f_t, omega_resolution, tau, f_n)]
        extra = [np.asarray(v) for v in (status,) if v is not None]
        shaped = [a for a in arrays + extra if a.ndim >= 1]
        if not shaped:
            raise ValueError("at least one input must be an array of samples")
        lengths = {a.shape[0] for a in shaped}
        if len(lengths) > 1:
            lengths.discard(1)  # (1, 2) or (1,): the same value at every sample
        if len(lengths) != 1:
            raise ValueError("all per-sample inputs must have the same number of samples")
        n = lengths.pop()
        two = any(a.ndim == 2 and a.shape[1] == 2 for a in shaped)
        w, s, c, f, res, tq, fn = (
            _per_finger(a, n, name, np.float64)
            for a, name in zip(
                arrays, ("omega_hat", "S", "c_tilde", "f_t", "omega_resolution", "tau", "f_n")
            )
        )
        st = _per_finger(Status.OK if status is None else status, n, "status", np.int32)
        if present is None:
            pres = np.broadcast_to(np.array([True, two]), (n, 2))
        else:
            pres = np.broadcast_to(np.asarray(present, dtype=bool), (n, 2))
        pres = np.ascontiguousarray(pres)
        req = np.zeros(n, dtype=np.int32)
        if isinstance(requests, dict):
            codes = {"pivoting": REQUEST_PIVOTING, "slipping_avoidance": REQUEST_SLIPPING_AVOIDANCE}
            for index, what in requests.items():
                if what not in codes:
                    raise ValueError(f"unknown request {what!r}; expected one of {list(codes)}")
                req[int(index)] = codes[what]
        elif requests is not None:
            req[:] = np.asarray(requests, dtype=np.int32)
        r = self._ctrl.run(w, s, c, f, st, pres, req, res, tq, fn)
        for name, kind, _doc in OUTPUT_FIELDS:
            if kind == "pair":
                r[name] = np.stack([r.pop(name + "_0"), r.pop(name + "_1")], axis=1)
        return ControllerRun(**r)

    def __repr__(self) -> str:
        return f"GraspController({self._params!r}, mode={self.mode.name}, command={self.command!r})"


def _solver(params: ContactParams) -> _core.StaticForceSolver:
    # A solver holds estimator state: one per call (copies the cached model's tables, ~0.1 ms).
    return _core.StaticForceSolver(_model(params))


def static_grasp_force(params, f_t, tau, s_ref: float = 0.8, *, full_output: bool = False):
    """Per-finger grasp force at which the static controller settles for a constant load.

    Solves S_static(f_n) = s_ref with S_static = |tau - c f_t| / g(f_n, c) and c~ from the CoR
    estimate at f_n (same estimator and c_max clip as the closed loop, docs/model.md 6). S_static
    decreases with f_n; the root is bracketed by doubling and refined by Illinois on log f_n
    (bounded: <= 120 bracket and 100 refinement evaluations, typically < 15 in all).

    Args:
        params: ContactParams, a preset name or a dict.
        f_t: tangential force per finger [N] (magnitude used); tau: torsional moment per finger
            [N m]. Broadcast against each other.
        s_ref: reference slippage indicator, 0 < s_ref <= 1 (1 gives the slip threshold).
        full_output: also return a dict with c_tilde, slippage, iterations and converged arrays.

    Returns:
        f_n [N] (0 for a zero load, NaN for non-finite input), shaped like the broadcast inputs;
        with full_output, (f_n, info).

    Raises:
        ValueError: a finite load whose force lies outside 1e-12 to 1e12 N (names f_t, tau).

    Example: the empty can (0.12 N per finger, mu = 0.75) needs 0.190 N with c_max = 1.5.
    """
    s_ref = float(s_ref)
    if not 0.0 < s_ref <= 1.0:
        raise ValueError(f"s_ref = {s_ref!r}: must satisfy 0 < s_ref <= 1")
    p = _as_params(params)
    (ft, tq), shape = _flat(f_t, tau)
    r = _solver(p).solve(ft, tq, s_ref)
    lost = np.isfinite(ft) & np.isfinite(tq) & ~np.isfinite(r["force"])
    if np.any(lost):  # a finite load whose force lies outside what the solver evaluates
        i = int(np.flatnonzero(lost)[0])
        raise ValueError(
            f"f_t, tau: the load at index {i} needs a grasp force outside the range the solver "
            "evaluates (1e-12 to 1e12 N)")
    force = _shaped(r["force"], shape)
    if not full_output:
        return force
    info = {k: _shaped(v, shape) for k, v in r.items() if k != "force"}
    return force, info


def static_slippage(params, f_n, f_t, tau):
    """S_static(f_n) = |tau - c f_t| / g(f_n, c) for a constant load (docs/model.md 6, stick), with c~
    from the CoR estimate at f_n. Returns (S, |c~|), broadcast like the inputs; NaN where
    f_n <= 0 or an input is not finite."""
    p = _as_params(params)
    (fn, ft, tq), shape = _flat(f_n, f_t, tau)
    S, c = _solver(p).slippage(fn, ft, tq)
    return _shaped(S, shape), _shaped(c, shape)
