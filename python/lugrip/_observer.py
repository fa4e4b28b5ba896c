"""Planar-slider plant (paper eqs. 1-2), sliding-velocity observer (eqs. 19-23) with the
slippage indicator S (eq. 37), and the observability check of Proposition 1 (eqs. 27-31).

The loops run in C++ (``lugrip._core``); this module converts arguments, validates settings and
returns numpy arrays in dataclasses.

Sign convention (docs/model.md 7.2): the observer is fed the wrench the OBJECT exerts on the
FINGERTIP, i.e. what a fingertip force/torque sensor reads. Then ``omega_hat`` is the object's
angular velocity relative to the fingertip about the sensor's z axis (the contact normal).
Feeding the opposite wrench returns ``-omega_hat`` with the same S.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from . import _core
from ._contact import Status, _as_params, _flat, _model, _params_path, _shaped
from ._nocopy import NoCopy
from ._observer_fields import _COR_FIELDS, _OBS_FIELDS, _OBS_KINDS, GAIN_MODES, INTEGRATORS
from ._params import ContactParams, _plain_observer_block
from ._yaml import load_yaml
from ._yaml import to_number

__all__ = [
    "GAIN_MODES",
    "INTEGRATORS",
    "Observability",
    "Observer",
    "ObserverRun",
    "ObserverSample",
    "SliderModel",
    "SliderState",
    "SliderTrajectory",
    "observability",
    "read_observer_settings",
    "sensor_wrench",
]



def _enum(table: dict, name: str, value):
    if isinstance(value, str):
        key = value.lower().replace("-", "_")
        if key not in table:
            raise ValueError(f"{name} = {value!r}: expected one of {', '.join(table)}")
        return table[key]
    if value in table.values():
        return value
    raise ValueError(f"{name} = {value!r}: expected one of {', '.join(table)}")


def _enum_name(table: dict, value) -> str:
    return next(k for k, v in table.items() if v == value)


# --------------------------------------------------------------------------------------------
# observer
# --------------------------------------------------------------------------------------------


_SAMPLE_DOC = """Observer output for one sample (the C++ ObserverOutput, SI units).

    ``omega_hat`` is the slip about the clipped CoR, the quantity the grasp controller's C_d
    filters; on translation-dominated slides (|c~| clipped) it exceeds the object's angular
    velocity, which ``omega_object`` estimates: with a viscous stress uniform over the patch,
    omega_object = omega_hat (a^2 + 1/2) / (a a_u + 1/2) and v_slip = |omega_object| a_u rho,
    a = |c_tilde|, a_u = |c_tilde_unclipped| (both equal omega_hat and |omega_hat c| below the
    clip).
    """

_KIND_TYPES = {"float": float, "int": int, "bool": bool}

#: (name, kind, doc) of every ObserverOutput field, from the C++ field table (bindings/tables.hpp).
OUTPUT_FIELDS = tuple(_core.ObserverOutput.fields)


def _field_list(fields) -> str:
    return "\n".join(f"        {name}: {doc}" for name, _kind, doc in fields)


def _sample_from_core(cls, o):
    values = {name: getattr(o, name) for name, _k, _d in OUTPUT_FIELDS if name != "status"}
    return cls(status=Status(o.status.value), **values)


ObserverSample = dataclasses.make_dataclass(
    "ObserverSample",
    [(name, Status if name == "status" else _KIND_TYPES[kind]) for name, kind, _d in OUTPUT_FIELDS],
    frozen=True,
    namespace={"_from_core": classmethod(_sample_from_core), "__module__": __name__},
)
ObserverSample.__doc__ = (
    _SAMPLE_DOC.rstrip()
    + "\n\n    Attributes (generated from the C++ ObserverOutput):\n"
    + _field_list(OUTPUT_FIELDS)
    + "\n    "
)


class _RunMethods:
    def __len__(self) -> int:
        return len(self.omega_hat)

    def to_dict(self) -> dict[str, np.ndarray]:
        return {
            f.name: getattr(self, f.name)
            for f in dataclasses.fields(self)
            if getattr(self, f.name) is not None
        }

    @property
    def valid(self) -> np.ndarray:
        """Samples that carry an estimate (Ok, Saturated, Degenerate, Reinitialized)."""
        return np.isin(
            self.status, [Status.OK, Status.SATURATED, Status.DEGENERATE, Status.REINITIALIZED]
        )

    def rmse(self, omega, mask=None) -> float:
        """Root-mean-square error of omega_hat against ground truth `omega` [rad/s] over the
        valid samples (and `mask` when given); NaN entries of `omega` are ignored."""
        omega = np.asarray(omega, dtype=np.float64)
        if omega.shape != self.omega_hat.shape:
            raise ValueError(f"omega has shape {omega.shape}, expected {self.omega_hat.shape}")
        sel = self.valid & np.isfinite(omega)
        if mask is not None:
            sel &= np.asarray(mask, dtype=bool)
        if not np.any(sel):
            return float("nan")
        return float(np.sqrt(np.mean((self.omega_hat[sel] - omega[sel]) ** 2)))


ObserverRun = dataclasses.make_dataclass(
    "ObserverRun",
    [(name, np.ndarray) for name, _k, _d in OUTPUT_FIELDS]
    + [("t", "np.ndarray | None", dataclasses.field(default=None))],
    bases=(_RunMethods,),
    frozen=True,
    namespace={"__module__": __name__},
)
ObserverRun.__doc__ = """Observer outputs over a log, one entry per sample (arrays of shape (n,)).

    Same fields as :class:`ObserverSample` (``status`` is an int array of Status values), plus
    ``t`` [s] when the log had times.
    """


def _column(log, name: str):
    """Column `name` of a mapping, DataFrame-like, pyarrow table, structured array or object;
    None when absent."""
    if isinstance(log, Mapping):
        value = log.get(name)
    elif hasattr(log, "column_names") and hasattr(log, "column"):  # pyarrow.Table
        value = log.column(name).to_numpy() if name in log.column_names else None
    elif hasattr(log, "columns") and hasattr(log, "__getitem__"):  # pandas / polars DataFrame
        value = log[name] if name in list(log.columns) else None
    elif isinstance(log, np.ndarray) and log.dtype.names is not None:
        value = log[name] if name in log.dtype.names else None
    else:
        value = getattr(log, name, None)
    if value is None:
        return None
    return np.ascontiguousarray(np.asarray(value, dtype=np.float64)).reshape(-1)


class Observer(NoCopy):
    """Sliding-velocity observer of one fingertip (paper eqs. 21-23, docs/model.md 7).

    Per sample: CoR estimate from f_n, f_t and the low-pass filtered torque (raw torque for
    y), g and sigma_1, y = tau - c f_t, one update of (z_hat, omega_hat) with the chosen
    integrator, projection |z_hat| <= g/sigma0, S = sigma0 |z_hat| / g.

    The slip indicator S is always observable; the slip SPEED only through viscous friction
    (omega_hat converges to (|y| - g)/sigma_1 at rate l sigma_1): see ``omega_resolution`` and
    ``speed_observable`` in the outputs.

    Args:
        params: ContactParams, a preset name, a dict, or a parameter YAML file (a path, or a
            str ending in .yaml/.yml). When the file has an ``observer:`` block (written by
            ``lugrip identify`` / :meth:`lugrip.IdentificationResult.save_yaml`: the observer
            the parameters were identified with, see :func:`lugrip.read_observer_settings`),
            those settings are the starting point and the keywords below override them one by
            one; files without the block (``objects/*.yaml``) start from the defaults.
        dt: nominal sample period [s] (used when a step gives no dt; default 0.002).
        integrator: "rosenbrock" (default: L-stable, 2nd order), "implicit" (exponential-
            implicit Euler), "rk4" (the paper's one step per sample), "rk4_adaptive".
        gain_mode: "fixed" (l = gain) or "bandwidth" (l = bandwidth / sigma_1 clipped to
            [gain_min, gain_max]). Default: "fixed" when only `gain` is given, else "bandwidth"
            (with a file's observer block: that rule applied to the keywords given here, and the
            block's gain_mode when neither `gain` nor `bandwidth` is given).
        gain: fixed observer gain l [1/(kg m^2)] (default 200).
        bandwidth: B = l sigma_1 [1/s] (default 3000; the rate at which omega_hat converges
            in sliding: higher tracks slip ramps with less lag, lower filters torque noise).
        **settings: the other fields of the C++ ObserverSettings (gain_min, gain_max,
            g_floor, torque_cutoff [Hz], filter_force, cor_sign_sigmas, max_invalid,
            max_dt_gap [s], torque_noise [N m], resolution_max [rad/s], omega_limit [rad/s],
            substeps, max_substeps) and of CorSettings (f_n_min [N], force_limit [N],
            torque_limit [N m], zero_force, zero_torque). None means "not given": the file's
            observer block, else the C++ default. The accepted ranges (the table of
            include/lugrip/observer.hpp) keep every output finite and bound the work per
            sample, e.g. dt in [1e-9, 10] s, max_substeps <= 5000, omega_limit <= 1e6 rad/s,
            f_n_min >= 1e-6 N, force_limit and torque_limit <= 1e9.

    Raises:
        ValueError: naming every invalid setting (for a file's observer block: the file, the
            block and the setting).
    """

    def __init__(
        self,
        params,
        *,
        dt: float | None = None,
        integrator: str | None = None,
        gain_mode: str | None = None,
        gain: float | None = None,
        bandwidth: float | None = None,
        **settings,
    ):
        given = {"dt": dt, "integrator": integrator, "gain_mode": gain_mode, "gain": gain}
        given.update(bandwidth=bandwidth, **settings)
        given = {k: v for k, v in given.items() if v is not None}
        path = _params_path(params)
        self.params = _as_params(params)
        block = read_observer_settings(path) if path is not None else None
        if block:
            if "gain_mode" not in given and ("gain" in given or "bandwidth" in given):
                # the keywords' own rule: a gain alone means a fixed gain
                given["gain_mode"] = "bandwidth" if "bandwidth" in given else "fixed"
            given = {k: v for k, v in {**block, **given}.items() if v is not None}
        s = _core.ObserverSettings()
        if "integrator" in given:
            s.integrator = _enum(INTEGRATORS, "integrator", given.pop("integrator"))
        gain, bandwidth = given.pop("gain", None), given.pop("bandwidth", None)
        gain_mode = given.pop("gain_mode", None)
        if gain_mode is None:
            gain_mode = "fixed" if gain is not None and bandwidth is None else "bandwidth"
        s.gain_mode = _enum(GAIN_MODES, "gain_mode", gain_mode)
        if gain is not None:
            s.gain = to_number(gain, "gain")
        if bandwidth is not None:
            s.bandwidth = to_number(bandwidth, "bandwidth")
        cor = s.cor
        for name, value in given.items():
            if name in _COR_FIELDS:
                setattr(cor, name, to_number(value, name))
            elif name in _OBS_FIELDS:
                kind = _OBS_KINDS[name]
                if kind == "int":
                    number = to_number(value, name)
                    if isinstance(value, bool) or not math.isfinite(number) or number != int(number):
                        raise ValueError(f"{name}: must be an integer")
                    if abs(number) >= 2**31:
                        raise ValueError(f"{name}: out of range for an integer setting")
                    value = int(number)
                elif kind == "bool":
                    if not isinstance(value, (bool, np.bool_)):
                        raise ValueError(f"{name}: must be true or false")
                    value = bool(value)
                else:
                    value = to_number(value, name)
                setattr(s, name, value)
            else:
                raise TypeError(f"Observer() got an unexpected keyword argument {name!r}")
        s.cor = cor
        message = _core.validate_observer_settings(s)
        if message:
            raise ValueError("invalid observer settings:\n" + message.rstrip())
        self._settings = s
        self._obs = _core.Observer(_model(self.params), s)

    @property
    def settings(self) -> dict:
        """The effective settings (C++ ObserverSettings) as a dict."""
        s = self._settings
        out = {name: getattr(s, name) for name in _OBS_FIELDS}
        out["integrator"] = _enum_name(INTEGRATORS, s.integrator)
        out["gain_mode"] = _enum_name(GAIN_MODES, s.gain_mode)
        out.update({name: getattr(s.cor, name) for name in _COR_FIELDS})
        return out

    @property
    def omega_hat(self) -> float:
        """The last reported omega_hat [rad/s] (0 where the speed is not in the data)."""
        return self._obs.omega_hat

    @property
    def omega_state(self) -> float:
        """The observer's slip-velocity state [rad/s] (omega_hat before the resolution gate)."""
        return self._obs.omega_state

    @property
    def z_hat(self) -> float:
        return self._obs.z_hat

    def reset(self) -> None:
        """Forget the state; the next valid sample re-initialises (omega_hat = 0)."""
        self._obs.reset()

    def step(self, f_n: float, f_t: float, tau: float, dt: float | None = None) -> ObserverSample:
        """One sensor sample: f_n [N], f_t [N] (in-plane magnitude or signed), tau [N m], dt [s]
        since the previous sample (None: the nominal dt). Never raises on bad samples."""
        out = self._obs.step(float(f_n), float(f_t), float(tau), 0.0 if dt is None else float(dt))
        return ObserverSample._from_core(out)

    def step_vector(
        self, f_n: float, f_x: float, f_y: float, tau: float, dt: float | None = None
    ) -> ObserverSample:
        """As :meth:`step` with the in-plane force vector (f_t = hypot(f_x, f_y))."""
        return self.step(f_n, float(np.hypot(f_x, f_y)), tau, dt)

    def run(self, log, *, reset: bool = True, reset_on_maneuver: bool = True,
            t_before: float | None = None) -> ObserverRun:
        """Replay a log in C++ and return the per-sample outputs.

        Args:
            log: mapping, dataclass/object (e.g. :class:`lugrip.SlidingLog`), DataFrame, pyarrow
                table or structured array with arrays ``f_n`` [N], ``tau`` [N m], and ``f_t``
                [N] or both ``f_x`` and ``f_y`` [N]; ``t`` [s] (strictly increasing) gives the
                sample periods, otherwise the nominal dt is used. An optional ``maneuver``
                column restarts the observer where it changes (``reset_on_maneuver``).
            reset: start from a fresh state (default) instead of continuing.
            t_before: with ``reset=False`` and ``t``, the time of the sample the observer
                stepped last [s]: the first sample's period is ``t[0] - t_before`` (a log
                replayed in pieces gives the outputs of one run over the whole log), instead
                of the nominal dt.

        Raises:
            ValueError: missing columns, different lengths, non-increasing or non-finite t.
        """
        f_n, tau = _column(log, "f_n"), _column(log, "tau")
        f_t = _column(log, "f_t")
        if f_t is None:
            f_x, f_y = _column(log, "f_x"), _column(log, "f_y")
            if f_x is None or f_y is None:
                raise ValueError("log needs 'f_t' or both 'f_x' and 'f_y'")
            if f_x.shape != f_y.shape:
                raise ValueError(f"f_x has {f_x.size} samples, f_y has {f_y.size}")
            f_t = np.hypot(f_x, f_y)
        missing = [name for name, v in (("f_n", f_n), ("tau", tau)) if v is None]
        if missing:
            raise ValueError(f"log is missing column(s): {', '.join(missing)}")
        n = f_n.size
        for name, v in (("f_t", f_t), ("tau", tau)):
            if v.size != n:
                raise ValueError(f"{name} has {v.size} samples, f_n has {n}")
        t = _column(log, "t")
        dt = np.zeros(n)
        if t is not None:
            if t.size != n:
                raise ValueError(f"t has {t.size} samples, f_n has {n}")
            bad = np.flatnonzero(~np.isfinite(t))
            if bad.size:
                raise ValueError(f"t is not finite at row {bad[0]}")
            d = np.diff(t)
            bad = np.flatnonzero(~(d > 0.0))
            if bad.size:
                raise ValueError(
                    f"t must be strictly increasing: t[{bad[0] + 1}] = {t[bad[0] + 1]!r}"
                    f" <= t[{bad[0]}] = {t[bad[0]]!r}"
                )
            dt[1:] = d
            if t_before is not None and not reset and n:
                d0 = t[0] - float(t_before)
                if not d0 > 0.0:
                    raise ValueError(f"t[0] = {t[0]!r} must be after t_before = {t_before!r}")
                dt[0] = d0
        if reset:
            self._obs.reset()
        man = _column(log, "maneuver") if reset_on_maneuver else None
        if man is not None and man.size == n and n > 0:
            cuts = np.flatnonzero(man[1:] != man[:-1]) + 1
        else:
            cuts = np.zeros(0, dtype=np.int64)
        if cuts.size == 0:
            raw = self._obs.run(f_n, f_t, tau, dt)
        else:
            parts = []
            for a, b in zip(np.r_[0, cuts], np.r_[cuts, n]):
                seg_dt = dt[a:b].copy()
                if a > 0:
                    self._obs.reset()
                    seg_dt[0] = 0.0
                parts.append(self._obs.run(f_n[a:b], f_t[a:b], tau[a:b], seg_dt))
            raw = {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}
        return ObserverRun(t=t, **raw)

    def __repr__(self) -> str:
        s = self.settings
        return (
            f"Observer({self.params!r}, integrator={s['integrator']!r}, "
            f"gain_mode={s['gain_mode']!r}, gain={s['gain']!r}, bandwidth={s['bandwidth']!r})"
        )


# --------------------------------------------------------------------------------------------
# plant
# --------------------------------------------------------------------------------------------


@dataclasses.dataclass(frozen=True)
class SliderState:
    """Plant state after one step: z [rad], omega [rad/s], zdot [rad/s], g [N m], sigma_1
    [N m s/rad], dry_torque = sigma0 z + sigma_z zdot [N m], friction_torque = dry_torque +
    sigma_1 omega [N m] (what a fingertip sensor reads about the CoR), slip = sigma0 |z| / g,
    substeps, projected, status."""

    z: float
    omega: float
    zdot: float
    g: float
    sigma_1: float
    dry_torque: float
    friction_torque: float
    slip: float
    substeps: int
    projected: bool
    status: Status


@dataclasses.dataclass(frozen=True)
class SliderTrajectory:
    """Plant outputs over a simulation, arrays of shape (n,); fields as :class:`SliderState`
    (``status`` as ints)."""

    z: np.ndarray
    omega: np.ndarray
    zdot: np.ndarray
    g: np.ndarray
    sigma_1: np.ndarray
    dry_torque: np.ndarray
    friction_torque: np.ndarray
    slip: np.ndarray
    substeps: np.ndarray
    projected: np.ndarray
    status: np.ndarray


class SliderModel(NoCopy):
    """The planar slider of eqs. 1-2 about a given (virtual) CoR, for simulators and tests.

    State z [rad], omega [rad/s]; inertia J [kg m^2] about the CoR axis; per step the normal
    force f_n [N], the CoR c_tilde [-] and the external torque tau_e [N m] about the CoR are held.
    z is projected onto |z| <= g/sigma0 after every substep (docs/model.md 7.1).

    Args:
        params: ContactParams, a preset name or a dict.
        J: inertia [kg m^2], > 0.
        integrator: "rosenbrock" (default), "implicit", "rk4_adaptive" or "rk4".
        max_substep: longest internal step [s] (default 2e-5); max_substeps: cap per step;
        g_floor: lower bound on g [N m].
    """

    def __init__(
        self,
        params,
        J: float,
        *,
        integrator: str = "rosenbrock",
        max_substep: float | None = None,
        max_substeps: int | None = None,
        g_floor: float | None = None,
    ):
        self.params = _as_params(params)
        s = _core.SliderSettings()
        s.integrator = _enum(INTEGRATORS, "integrator", integrator)
        if max_substep is not None:
            s.max_substep = float(max_substep)
        if max_substeps is not None:
            s.max_substeps = int(max_substeps)
        if g_floor is not None:
            s.g_floor = float(g_floor)
        message = _core.validate_slider_settings(s)
        if message:
            raise ValueError("invalid slider settings:\n" + message.rstrip())
        self._sim = _core.SliderModel(_model(self.params), float(J), s)

    @property
    def z(self) -> float:
        return self._sim.z

    @property
    def omega(self) -> float:
        return self._sim.omega

    @property
    def J(self) -> float:
        return self._sim.J

    def reset(self, z: float = 0.0, omega: float = 0.0) -> None:
        self._sim.reset(float(z), float(omega))

    def step(self, f_n: float, c_tilde: float, tau_e: float, dt: float) -> SliderState:
        """Advance by dt [s]; invalid input gives Status.INVALID_SAMPLE and leaves the state."""
        o = self._sim.step(float(f_n), float(c_tilde), float(tau_e), float(dt))
        values = {
            f.name: getattr(o, f.name)
            for f in dataclasses.fields(SliderState)
            if f.name != "status"
        }
        return SliderState(status=Status(o.status.value), **values)

    def simulate(self, f_n, c_tilde, tau_e, dt) -> SliderTrajectory:
        """Step through the samples (inputs broadcast to one 1-D length; dt scalar or array).
        Continues from the current state; call :meth:`reset` first for a fresh start."""
        (fn, ct, te, d), shape = _flat(f_n, c_tilde, tau_e, dt)
        if len(shape) > 1:
            raise ValueError(f"inputs must be scalars or 1-D arrays, got shape {shape}")
        return SliderTrajectory(**self._sim.simulate(fn, ct, te, d))


def sensor_wrench(params, f_n, c_tilde, y):
    """The sensor's reading (f_t >= 0 [N], tau [N m]) for a contact with CoR |c_tilde| whose
    friction torque about the CoR is y [N m] (e.g. SliderTrajectory.friction_torque): inverse of
    the CoR estimate (ContactModel::wrench_at); the CoR side follows sign(c~) = -sign(y)."""
    p = _as_params(params)
    (fn, ct, yy), shape = _flat(f_n, c_tilde, y)
    ft, tau = _model(p).wrench_at(fn, ct, yy)
    return _shaped(ft, shape), _shaped(tau, shape)


# --------------------------------------------------------------------------------------------
# observability (Proposition 1)
# --------------------------------------------------------------------------------------------


@dataclasses.dataclass(frozen=True)
class Observability:
    """Observability matrix Theta(x) of eq. 28 along a trajectory (arrays of shape (n,)).

    Attributes:
        theta: (n, 2, 2) matrices [dh; d(L_f h)] with J = 1/l.
        det: det Theta = sigma0^2 * gain_factor * motion_factor.
        gain_factor: 1 - l sigma_1 sigma_z / sigma0 (eq. 29's common factor; zero when
            l sigma_1 sigma_z = sigma0, a degeneracy the paper's proof does not discuss).
        motion_factor: 1 - sigma0 z sign(omega)/g + sigma_1 |omega|/g; >= 0 for
            |z| <= g/sigma0, and -> 0 in steady sliding (z at the bound) when
            sigma_1 |omega| << g, i.e. slow slip or weak viscous friction (eqs. 30-31).
        cond: 2-norm condition number of Theta with unit-norm rows (scale-free).
        rank: numerical rank (singular values of the row-normalised Theta against `rtol`).
        outside_domain: |omega| <= omega_eps: outside M and M' of Proposition 1 (the regularised
            sign makes the rank test meaningless there).
        degraded: rank < 2, cond > cond_max, or outside_domain.
    """

    theta: np.ndarray
    det: np.ndarray
    gain_factor: np.ndarray
    motion_factor: np.ndarray
    cond: np.ndarray
    rank: np.ndarray
    outside_domain: np.ndarray
    degraded: np.ndarray

    def __len__(self) -> int:
        return len(self.det)


def observability(
    params,
    z,
    omega=None,
    g=None,
    sigma_1=None,
    *,
    gain=200.0,
    rtol: float = 1e-6,
    cond_max: float = 1e4,
    omega_eps: float = 1e-9,
) -> Observability:
    """Evaluate Theta(x) of eq. 28 (Proposition 1) along a trajectory, with J = 1/l.

    Theta = [[sigma0, sigma_1],
             [-sigma0 sigma_1 l - (sigma0/g) k |omega|,
              sigma0 - l sigma_1 (sigma_1 + sigma_z) - (sigma0/g) k z sign(omega)]],
    k = sigma0 - l sigma_1 sigma_z

    (rows: the gradient of h = sigma0 z + sigma_1 omega and of its Lie derivative along
    eqs. 1-2 with 1/J = l, g and sigma_1 frozen).

    Args:
        params: ContactParams (sigma0, sigma_z are used), a preset name or a dict.
        z [rad], omega [rad/s], g [N m], sigma_1 [N m s/rad]: arrays (broadcast). Alternatively
            pass an :class:`ObserverRun` as `z` (z_hat, omega_state, g, sigma_1 and the gain used
            are taken from it).
        gain: observer gain l (scalar or array) [1/(kg m^2)].
        rtol: rank tolerance on the ratio of singular values of the row-normalised Theta.
        cond_max: condition numbers above this count as degraded.
        omega_eps: |omega| at or below this is outside the domain of Proposition 1 [rad/s].
    """
    p = _as_params(params)
    if isinstance(z, ObserverRun):
        run = z
        z, omega, g, sigma_1, gain = run.z_hat, run.omega_state, run.g, run.sigma_1, run.gain
    if omega is None or g is None or sigma_1 is None:
        raise ValueError("give z, omega, g and sigma_1 (or an ObserverRun)")
    (z, w, g, s1, l), shape = _flat(z, omega, g, sigma_1, gain)
    if np.any(~(g > 0.0)):
        raise ValueError("g must be > 0")
    s0, sz = p.sigma0, p.sigma_z
    sgn = np.sign(w)
    k = s0 - l * s1 * sz
    theta = np.empty(z.shape + (2, 2))
    theta[:, 0, 0] = s0
    theta[:, 0, 1] = s1
    theta[:, 1, 0] = -s0 * s1 * l - s0 / g * k * np.abs(w)
    theta[:, 1, 1] = s0 - l * s1 * (s1 + sz) - s0 / g * k * z * sgn
    det = theta[:, 0, 0] * theta[:, 1, 1] - theta[:, 0, 1] * theta[:, 1, 0]
    gain_factor = 1.0 - l * s1 * sz / s0
    motion_factor = 1.0 - s0 * z * sgn / g + s1 * np.abs(w) / g
    norms = np.linalg.norm(theta, axis=2, keepdims=True)
    normalised = theta / np.where(norms > 0.0, norms, 1.0)
    sv = np.linalg.svd(normalised, compute_uv=False)
    with np.errstate(divide="ignore"):
        cond = np.where(sv[:, 1] > 0.0, sv[:, 0] / np.where(sv[:, 1] > 0.0, sv[:, 1], 1.0), np.inf)
    rank = np.sum(sv > rtol * sv[:, :1], axis=1)
    outside = np.abs(w) <= omega_eps
    degraded = (rank < 2) | (cond > cond_max) | outside
    return Observability(
        theta=theta.reshape(shape + (2, 2)),
        det=_shaped(det, shape),
        gain_factor=_shaped(gain_factor, shape),
        motion_factor=_shaped(motion_factor, shape),
        cond=_shaped(cond, shape),
        rank=_shaped(rank, shape),
        outside_domain=_shaped(outside, shape),
        degraded=_shaped(degraded, shape),
    )


def _check_observer_block(block, where: str) -> dict:
    """Validates an observer block (keywords of :class:`Observer`) by building the observer;
    returns it with plain Python values. Errors name ``where`` and the key, never the value."""
    plain = _plain_observer_block(block, where)
    try:
        Observer(ContactParams.table1(), **plain)
    except (TypeError, ValueError, OverflowError) as err:
        lines = [ln.strip() for ln in str(err).splitlines() if ln.strip()]
        if lines and lines[0].startswith("invalid observer settings"):
            lines = lines[1:]
        raise ValueError("; ".join(f"{where}.{ln}" for ln in lines) or where) from None
    return plain


def read_observer_settings(path: str | Path) -> dict[str, Any] | None:
    """The ``observer:`` block of a parameter YAML (written by ``lugrip identify`` /
    :meth:`lugrip.identification.IdentificationResult.save_yaml`): the settings of the observer the
    parameters were identified with, as keywords of :class:`lugrip.Observer`, so that the
    observer used online is the one inside the identification cost (docs/model.md 8.1). None when
    the file has no such block (e.g. ``objects/*.yaml``, ``lugrip params`` output).
    ``lugrip.Observer(path)`` starts from this block (its keywords override it), as do
    ``lugrip observe --params``, ``lugrip identify --params0`` and ``lugrip.identify`` with a
    YAML ``params0``.

    Raises:
        ValueError: the file cannot be read within the limits of :func:`lugrip._yaml.load_yaml`,
            or the block is not a mapping or holds an unknown or invalid setting (message
            ``<file>: observer.<key>: ...``).
    """
    path = Path(path)
    data = load_yaml(path)
    if not isinstance(data, dict) or data.get("observer") is None:
        return None
    return _check_observer_block(data["observer"], f"{path}: observer")
