"""Parameter identification from sliding logs (paper Section 4, eqs. 32-33, MODEL.md 8).

The cost is the observer's velocity error over many maneuvers,

    C(P) = sum_n w_n loss(omega_hat_n(P) - omega_n) / sum_n w_n,

where ``omega_hat`` comes from the ONLINE observer (:class:`lugrip.Observer`: same CoR estimate,
torque filter, gain rule, integrator and substeps), restarted at every maneuver and at every gap
(never integrated across one). Cost, exact gradient and Gauss-Newton matrix are computed in C++
over all maneuvers in parallel (``lugrip._core.IdentificationProblem``: forward sensitivities of
the discretised observer); the optimiser is an SQP on log-parameters scaled by the start point, with
bounds from physics: by default each step solves the box-constrained quadratic model built from
the exact gradient and the Gauss-Newton matrix (Levenberg-Marquardt damping); scipy's SLSQP and
trust-constr are available.

Identifiability (what the observer output can tell apart):

* delta and gamma enter mostly through the contact radius rho(f_n) = delta f_n^gamma: with a
  single normal force they are not separately identifiable (only rho at that force is);
* mu and delta enter the capacity g = mu f_n rho G(c~) as the product mu delta (tau_max);
  they separate through the CoR estimate and the tangential capacity mu f_n, i.e. only when the
  data contain translation-dominated maneuvers. With rotation-only data (c~ ~ 0) only mu delta
  and beta_A delta^4 are identified;
* beta_A and delta^4 enter sigma_1 = pi beta_A rho^4 (c~^2 + 1/2) as a product, so beta_A is
  separated from delta only through the other places delta appears (g, c, y);
* sigma0 and sigma_z act only in stick and at slip onset (pre-sliding deflection rate
  ydot/sigma0 and its lag sigma0/(sigma_z + sigma_1)): data without load changes in stick do
  not fix them; all-stick data do not fix mu and beta_A (only a lower bound on mu).

:func:`identify` checks the data for the first and last cases before fitting (and fixes the
parameter that cannot be told apart, with a warning), and reports the weakest parameter
combinations (eigenvectors of the scale-free Gauss-Newton matrix) and the correlations after.
"""

from __future__ import annotations

import dataclasses
import functools
import inspect
import math
import os
import time
import warnings
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from .. import _core
from .._contact import LimitSurface, _as_params, estimate_cor
from .._observer import GAIN_MODES, INTEGRATORS, Observer
from .._params import _UNITS, ContactParams, read_observer_settings
from ..io import SlidingLog, read_log

__all__ = [
    "DEFAULT_BOUNDS",
    "PARAMETERS",
    "IdentifiabilityWarning",
    "IdentificationError",
    "IdentificationResult",
    "IdentificationWarning",
    "InitialGuess",
    "ParameterEstimate",
    "identify",
    "initial_guess",
    "load_maneuvers",
]

PARAMETERS: tuple[str, ...] = ("mu", "beta_a", "sigma0", "sigma_z", "delta", "gamma")
"""The identified parameters, in the order of gradients and matrices (MODEL.md 8.1)."""

DEFAULT_BOUNDS: dict[str, tuple[float, float]] = {
    "mu": (0.05, 2.0),  # MODEL.md 8.1
    "beta_a": (1.0e3, 1.0e12),  # N s/m^3; Table 2 ~1e7, Table 1 4.9e9
    "sigma0": (1.0e-3, 1.0e4),  # N m/rad; Table 1 16.66
    "sigma_z": (1.0e-5, 1.0e3),  # N m s/rad; Table 1 2
    "delta": (1.0e-4, 1.0e-2),  # m/N^gamma, MODEL.md 8.1
    "gamma": (0.01, 1.0 / 3.0 - 1.0e-6),  # 0 < gamma < 1/3 (paper, ref. [24])
}
"""Physical bounds (all parameters are optimised in log scale, so every bound is > 0)."""

_DEFAULT_SLIP = 2.0e-3  # [rad/s] |omega| above which a sample counts as sliding (checks, guess)


class IdentificationError(ValueError):
    """Data or arguments that cannot give a meaningful fit (the message says why and what to do)."""


class IdentificationWarning(UserWarning):
    """Something in the data or the fit worth knowing (gaps, a single maneuver, bounds hit)."""


class IdentifiabilityWarning(IdentificationWarning):
    """A parameter (combination) the data cannot determine; fixed or reported."""


# ---------------------------------------------------------------------------------------------
# data: maneuvers and segments
# ---------------------------------------------------------------------------------------------


@dataclasses.dataclass
class _Maneuver:
    key: str  # "<source>#<maneuver id>" (a repeated id gets "/2", "/3", ...)
    f_n: np.ndarray
    f_t: np.ndarray
    tau: np.ndarray
    dt: np.ndarray  # 0 at each segment start
    omega: np.ndarray
    t: np.ndarray
    starts: np.ndarray  # segment starts within the maneuver (first 0), plus its length

    @property
    def n(self) -> int:
        return len(self.f_n)


def _as_logs(logs) -> list[SlidingLog]:
    if isinstance(logs, (SlidingLog, str, os.PathLike, Mapping)):
        logs = [logs]
    out = []
    for item in logs:
        if isinstance(item, SlidingLog):
            out.append(item)
        elif isinstance(item, (str, os.PathLike)):
            out.append(read_log(item, allow_gaps=True))
        elif isinstance(item, Mapping):
            cols = {
                k: item[k]
                for k in ("t", "f_n", "tau", "f_t", "f_x", "f_y", "omega", "maneuver")
                if k in item and item[k] is not None
            }
            if "t" not in cols and "f_n" in cols:
                cols["t"] = np.arange(len(np.asarray(cols["f_n"]))) * 0.002
            missing = [k for k in ("f_n", "tau") if k not in cols]
            if missing:
                raise IdentificationError(f"log mapping is missing {', '.join(missing)}")
            out.append(SlidingLog.from_arrays(**cols, allow_gaps=True, check_units=False))
        else:
            raise TypeError(
                f"expected SlidingLog, a path or a mapping of arrays, got {type(item).__name__}"
            )
    if not out:
        raise IdentificationError("no logs given")
    return out


def load_maneuvers(
    logs, *, max_gap: float | None = None, min_segment: int = 10, require_omega: bool = True
) -> list[_Maneuver]:
    """Split logs into maneuvers (contiguous blocks of one maneuver id) and their gap-free
    segments (:meth:`lugrip.SlidingLog.segments`: split at non-finite samples and at time
    steps above ``max_gap``). Segments shorter than ``min_segment`` samples are dropped.

    Raises:
        IdentificationError: a log without ground-truth ``omega`` (when ``require_omega``) or
            without any usable segment.
    """
    out: list[_Maneuver] = []
    seen: dict[str, int] = {}
    dropped_short = dropped_invalid = 0
    for j, log in enumerate(_as_logs(logs)):
        name = log.source or f"log{j}"
        if require_omega and (log.omega is None or not np.any(np.isfinite(log.omega))):
            raise IdentificationError(
                f"{name}: no ground-truth 'omega' column (sliding velocity [rad/s]): "
                "identification minimises the observer's velocity error and needs it "
                "(eq. 32); record the slider's angular velocity, e.g. from the robot's "
                "encoders"
            )
        dropped_invalid += int(np.count_nonzero(~log.valid))
        segs = log.segments(max_gap)
        omega = log.omega if log.omega is not None else np.full(len(log), np.nan)
        man = log.maneuver
        by_block: dict[int, list[tuple[int, int]]] = {}
        cut = np.flatnonzero(man[1:] != man[:-1]) + 1
        block_of = np.zeros(len(log), dtype=np.int64)
        block_of[cut] = 1
        block_of = np.cumsum(block_of)
        for a, b in segs:
            if b - a < min_segment:
                dropped_short += b - a
                continue
            by_block.setdefault(int(block_of[a]), []).append((a, b))
        for blk in sorted(by_block):
            parts = by_block[blk]
            mid = int(man[parts[0][0]])
            base = f"{name}#{mid}"
            seen[base] = seen.get(base, 0) + 1
            key = base if seen[base] == 1 else f"{base}/{seen[base]}"
            idx = np.concatenate([np.arange(a, b) for a, b in parts])
            dt = np.zeros(idx.size)
            starts = [0]
            pos = 0
            for a, b in parts:
                if b - a > 1:
                    dt[pos + 1 : pos + b - a] = np.diff(log.t[a:b])
                pos += b - a
                starts.append(pos)
            out.append(
                _Maneuver(
                    key=key,
                    f_n=log.f_n[idx],
                    f_t=log.f_t[idx],
                    tau=log.tau[idx],
                    dt=dt,
                    omega=np.asarray(omega[idx], dtype=float),
                    t=log.t[idx],
                    starts=np.asarray(starts, dtype=np.int64),
                )
            )
    if not out:
        raise IdentificationError(
            f"no usable samples: every segment is shorter than {min_segment} samples or invalid"
        )
    if dropped_invalid or dropped_short:
        warnings.warn(
            f"{dropped_invalid} non-finite sample(s) and {dropped_short} sample(s) in segments "
            f"shorter than {min_segment} samples left out; the observer restarts after every "
            "gap and is never integrated across one",
            IdentificationWarning,
            stacklevel=3,
        )
    return out


class _Problem:
    """A set of maneuvers as one C++ IdentificationProblem (weights: each maneuver counts the
    same with ``weighting='maneuver'``, each sample with ``'sample'``)."""

    def __init__(self, maneuvers: Sequence[_Maneuver], settings, weighting: str):
        self.maneuvers = list(maneuvers)
        cat = lambda name: np.ascontiguousarray(
            np.concatenate([getattr(m, name) for m in self.maneuvers]), dtype=np.float64
        )
        self.omega = cat("omega")
        n_scored = [int(np.count_nonzero(np.isfinite(m.omega))) for m in self.maneuvers]
        total = sum(n_scored)
        weights = []
        for m, k in zip(self.maneuvers, n_scored):
            if weighting == "maneuver":
                w = total / (len(self.maneuvers) * k) if k else 0.0
            else:
                w = 1.0
            weights.append(np.full(m.n, w))
        self.weight = np.concatenate(weights)
        starts, seg_owner, offset = [], [], 0
        for i, m in enumerate(self.maneuvers):
            starts.extend((m.starts[:-1] + offset).tolist())
            seg_owner.extend([i] * (len(m.starts) - 1))
            offset += m.n
        starts.append(offset)
        self.segment_owner = np.asarray(seg_owner, dtype=np.int64)
        self.offsets = np.cumsum([0] + [m.n for m in self.maneuvers])
        self.core = _core.IdentificationProblem(
            cat("f_n"),
            cat("f_t"),
            cat("tau"),
            cat("dt"),
            self.omega,
            self.weight,
            np.asarray(starts, dtype=np.int64),
            settings,
        )
        self.evaluations = 0

    @property
    def samples(self) -> int:
        return int(self.core.samples)

    def evaluate(self, params: ContactParams, derivatives: bool = True, omega_hat: bool = False):
        self.evaluations += 1
        return self.core.evaluate(params.to_core(), derivatives, omega_hat)

    def per_maneuver(self, ev) -> tuple[np.ndarray, np.ndarray]:
        """(sse, count) per maneuver from the per-segment sums."""
        m = len(self.maneuvers)
        sse = np.bincount(self.segment_owner, weights=ev["segment_sse"], minlength=m)
        cnt = np.bincount(self.segment_owner, weights=ev["segment_count"], minlength=m)
        return sse, cnt

    def maneuver_gradients(self, ev) -> np.ndarray:
        g = np.asarray(ev["segment_gradient"]).reshape(-1, len(PARAMETERS))
        out = np.zeros((len(self.maneuvers), len(PARAMETERS)))
        np.add.at(out, self.segment_owner, g)
        return out


# ---------------------------------------------------------------------------------------------
# observer settings
# ---------------------------------------------------------------------------------------------


def _observer_settings(observer, params: ContactParams):
    """Core ObserverSettings from None, a dict of :class:`lugrip.Observer` keywords or an
    Observer (its settings; the parameters are not used)."""
    if observer is None:
        obs = Observer(params)
    elif isinstance(observer, Observer):
        obs = observer
    elif isinstance(observer, Mapping):
        obs = Observer(params, **dict(observer))
    else:
        raise TypeError("observer must be None, a dict of Observer settings or an Observer")
    d = obs.settings
    s = _core.ObserverSettings()
    for name, value in d.items():
        if name == "integrator":
            s.integrator = INTEGRATORS[value]
        elif name == "gain_mode":
            s.gain_mode = GAIN_MODES[value]
        elif hasattr(s.cor, name) and not hasattr(s, name):
            cor = s.cor
            setattr(cor, name, value)
            s.cor = cor
        else:
            setattr(s, name, value)
    return s, d


# ---------------------------------------------------------------------------------------------
# initial guess from the data
# ---------------------------------------------------------------------------------------------


@dataclasses.dataclass(frozen=True)
class InitialGuess:
    """Start point computed from the data (:func:`initial_guess`).

    Attributes:
        params: the guess (k and c_max as given).
        notes: per parameter, how it was obtained (or why a fallback was used).
    """

    params: ContactParams
    notes: dict[str, str]


def _clip(name: str, value: float, bounds: Mapping[str, tuple[float, float]]) -> float:
    lo, hi = bounds[name]
    if not math.isfinite(value):
        return math.sqrt(lo * hi)
    return float(min(max(value, lo * 1.001), hi / 1.001))


def _onsets(maneuvers: Sequence[_Maneuver], thr: float):
    """Per maneuver: index of the first sliding sample (None) and the stick samples before it."""
    res = []
    for m in maneuvers:
        w = np.abs(m.omega)
        slide = np.flatnonzero(np.isfinite(w) & (w > thr))
        res.append(int(slide[0]) if slide.size else None)
    return res


def initial_guess(
    logs,
    *,
    k: float = 4.0,
    c_max: float = 1.5,
    slip_threshold: float = _DEFAULT_SLIP,
    bounds: Mapping[str, tuple[float, float]] | None = None,
    max_gap: float | None = None,
) -> InitialGuess:
    """Start point for :func:`identify` computed from the data, not asked from the user.

    * mu: 90th percentile of f_t / f_n at the sliding onsets (first |omega| > slip_threshold
      per maneuver): translation-dominated onsets sit at f_t = mu f_n;
    * delta, gamma: torsional against tangential capacity at the onsets: on the limit surface
      f_t = mu f_n F(a) and |tau| = mu xi rho f_n T(a), so F(a) from the force ratio gives a,
      then rho = |tau| / (mu xi f_n T(a)); ln rho = ln delta + gamma ln f_n by least squares
      (gamma = 0.25 when the normal force hardly varies);
    * mu and beta_A refined from the sliding samples: |y| = mu [f_n rho G(a)] +
      beta_A [pi rho^4 (a^2 + 1/2) |omega|] (non-negative least squares; y, a from the CoR
      estimate at the current guess), twice;
    * sigma0, sigma_z: stick stiffness and damping, y - y_0 = sigma0 theta + (sigma_z +
      sigma_1) omega on the samples before each onset (theta the integrated ground-truth
      rotation).

    Each step falls back to the paper's Table 1 value (noted) when the data do not support it.
    """
    bounds = dict(DEFAULT_BOUNDS if bounds is None else bounds)
    mans = (
        logs
        if (isinstance(logs, list) and logs and isinstance(logs[0], _Maneuver))
        else load_maneuvers(logs, max_gap=max_gap)
    )
    table1 = ContactParams.table1()
    ls = LimitSurface(k)
    xi = ls.xi
    notes: dict[str, str] = {}
    onset = _onsets(mans, slip_threshold)
    on = [(m, i) for m, i in zip(mans, onset) if i is not None and i > 0]

    # --- mu from the force ratio at the onsets
    ratio = np.array([m.f_t[i] / m.f_n[i] for m, i in on if m.f_n[i] > 0])
    if ratio.size:
        mu = float(np.percentile(ratio, 90))
        notes["mu"] = f"90th percentile of f_t/f_n at {ratio.size} sliding onsets"
    else:
        mu = table1.mu
        notes["mu"] = "no sliding onset in the data: Table 1 value"
    mu = _clip("mu", mu, bounds)

    # tables of F, T over a for the inversions
    a_grid = np.concatenate([[0.0], np.geomspace(1e-3, 50.0, 600)])
    F_grid = np.abs(ls.ft_star(a_grid))
    T_grid = ls.tau_star(a_grid)

    def radius_fit(mu_: float):
        f_n = np.array([m.f_n[i] for m, i in on])
        f = np.array([m.f_t[i] / (mu_ * m.f_n[i]) for m, i in on])
        t = np.array([abs(m.tau[i]) for m, i in on])
        ok = (f > 0.02) & (f < 0.95) & (f_n > 0)
        if np.count_nonzero(ok) < 1:
            return None
        a = np.interp(f[ok], F_grid, a_grid)
        T = np.interp(a, a_grid, T_grid)
        rho = t[ok] / (mu_ * xi * f_n[ok] * np.maximum(T, 1e-3))
        fn = f_n[ok]
        good = rho > 0
        rho, fn = rho[good], fn[good]
        if rho.size == 0:
            return None
        if rho.size >= 3 and fn.max() / fn.min() >= 1.5:
            A = np.column_stack([np.ones(rho.size), np.log(fn)])
            (ld, gam), *_ = np.linalg.lstsq(A, np.log(rho), rcond=None)
            if 0.02 < gam < 1.0 / 3.0:
                return float(np.exp(ld)), float(gam), rho.size, "fit"
        gam = 0.25
        return float(np.median(rho / fn**gam)), gam, rho.size, "fixed"

    def refine_mu_beta(p: ContactParams):
        rows_g, rows_v, rhs = [], [], []
        for m in mans:
            w = np.abs(m.omega)
            sel = np.isfinite(w) & (w > slip_threshold)
            if not np.any(sel):
                continue
            est = estimate_cor(p, m.f_n[sel], m.f_t[sel], m.tau[sel])
            a = np.abs(est.c_tilde)
            rho = p.delta * m.f_n[sel] ** p.gamma
            G = np.asarray(ls.G(a))
            rows_g.append(m.f_n[sel] * rho * G)
            rows_v.append(math.pi * rho**4 * (a**2 + 0.5) * w[sel])
            rhs.append(np.abs(est.y))
        if not rhs:
            return None
        from scipy.optimize import nnls

        A = np.column_stack([np.concatenate(rows_g), np.concatenate(rows_v)])
        b = np.concatenate(rhs)
        scale = np.maximum(np.abs(A).max(axis=0), 1e-300)
        x, _ = nnls(A / scale, b)
        return float(x[0] / scale[0]), float(x[1] / scale[1]), b.size

    delta, gamma = table1.delta, table1.gamma
    beta = table1.beta_a
    for it in range(2):
        fit = radius_fit(mu)
        if fit is not None:
            delta, gamma, n_on, how = fit
            notes["delta"] = (
                f"contact radius from torsional vs tangential capacity at {n_on} onsets"
            )
            notes["gamma"] = (
                "least squares of ln rho on ln f_n"
                if how == "fit"
                else "normal force hardly varies: 0.25 (delta from rho at that force)"
            )
        else:
            notes["delta"] = notes["gamma"] = "no rotation-dominated onset: Table 1 value"
        delta, gamma = _clip("delta", delta, bounds), _clip("gamma", gamma, bounds)
        p = table1.replace(mu=mu, delta=delta, gamma=gamma, beta_a=beta, k=k, c_max=c_max)
        mb = refine_mu_beta(p)
        if mb is None:
            notes["beta_a"] = "no sliding samples: Table 1 value"
            break
        mu_new, beta_new, n_sl = mb
        if mu_new > 0:
            mu = _clip("mu", mu_new, bounds)
            notes["mu"] = f"dry part of |y| on {n_sl} sliding samples (onsets: initial value)"
        if beta_new > 0:
            beta = _clip("beta_a", beta_new, bounds)
            notes["beta_a"] = f"viscous excess of |y| against speed on {n_sl} sliding samples"
        else:
            notes["beta_a"] = "no viscous excess measurable: Table 1 value"

    # --- sigma0, sigma_z from the stick phases
    p = table1.replace(mu=mu, delta=delta, gamma=gamma, beta_a=beta, k=k, c_max=c_max)
    X, Y, S1 = [], [], []
    for m, i in zip(mans, onset):
        stop = m.starts[1] if i is None else min(i, m.starts[1])
        if stop < 10:
            continue
        sl = slice(0, stop)
        if not np.all(np.isfinite(m.omega[sl])):
            continue
        est = estimate_cor(p, m.f_n[sl], m.f_t[sl], m.tau[sl])
        theta = np.concatenate(
            [[0.0], np.cumsum(0.5 * (m.omega[sl][1:] + m.omega[sl][:-1]) * m.dt[sl][1:])]
        )
        y = np.asarray(est.y)
        keep = np.abs(y) < 0.7 * np.asarray(est.g)
        if np.count_nonzero(keep) < 5:
            continue
        X.append(np.column_stack([theta[keep], m.omega[sl][keep]]))
        Y.append(y[keep] - y[0])
        S1.append(np.asarray(est.sigma_1)[keep])
    sigma0, sigma_z = table1.sigma0, table1.sigma_z
    if X:
        A, b = np.vstack(X), np.concatenate(Y)
        scale = np.maximum(np.abs(A).max(axis=0), 1e-300)
        coef, *_ = np.linalg.lstsq(A / scale, b, rcond=None)
        coef = coef / scale
        if coef[0] > 0:
            sigma0 = float(coef[0])
            notes["sigma0"] = (
                f"stick stiffness: slope of y against the rotation on {b.size} samples"
            )
            damp = coef[1] - float(np.median(np.concatenate(S1)))
            if damp > 0:
                sigma_z = float(damp)
                notes["sigma_z"] = "stick damping: y against omega, minus the viscous sigma_1"
            else:
                sigma_z = 0.1 * sigma0
                notes["sigma_z"] = "stick damping not measurable: 0.1 s x sigma0"
        else:
            notes["sigma0"] = notes["sigma_z"] = "no stick stiffness measurable: Table 1 value"
    else:
        notes["sigma0"] = notes["sigma_z"] = "no stick phase before the onsets: Table 1 value"
    sigma0, sigma_z = _clip("sigma0", sigma0, bounds), _clip("sigma_z", sigma_z, bounds)
    return InitialGuess(
        ContactParams(
            mu=mu,
            beta_a=beta,
            sigma0=sigma0,
            sigma_z=sigma_z,
            delta=delta,
            gamma=gamma,
            k=k,
            c_max=c_max,
        ),
        notes,
    )


# ---------------------------------------------------------------------------------------------
# result
# ---------------------------------------------------------------------------------------------


@dataclasses.dataclass(frozen=True)
class ParameterEstimate:
    """One parameter of an identification.

    Attributes:
        name, unit: as in :class:`lugrip.ContactParams`.
        value: estimate (the fixed value when not free).
        initial: start value.
        lower, upper: bounds used (free parameters).
        free: optimised (False: held at ``initial``).
        at_bound: "lower", "upper" or None.
        stderr: standard error (NaN when not free or not available).
        note: how the start value was obtained, or why the parameter was fixed.
    """

    name: str
    unit: str
    value: float
    initial: float
    lower: float
    upper: float
    free: bool
    at_bound: str | None
    stderr: float
    note: str = ""

    @property
    def relative_stderr(self) -> float:
        return self.stderr / abs(self.value) if self.value else math.nan


@dataclasses.dataclass(frozen=True)
class IdentificationResult:
    """Result of :func:`identify`.

    Attributes:
        status: "converged", "max_iterations" or "failed"; success: status == "converged".
        message: the optimiser's message.
        params: identified :class:`lugrip.ContactParams`; params0: the start point.
        estimates: per parameter (:class:`ParameterEstimate`), in :data:`PARAMETERS` order.
        free: the optimised parameters.
        cost_trace: cost (eq. 32 with weights and loss) at the start and after every iteration.
        rmse_train, rmse_validation: RMSE of omega_hat [rad/s] over the scored samples of the
            training / validation maneuvers (per sample, the paper's metric; NaN without
            validation maneuvers).
        rms_omega_train, rms_omega_validation: RMS of the ground truth there [rad/s] (scale).
        maneuver_rmse: RMSE per maneuver key [rad/s]; validation_keys: the validation ones.
        correlation: correlation matrix of the free log-parameters (Gauss-Newton).
        identifiability: notes on parameters (combinations) the data cannot fix.
        weak_directions: principal axes of the covariance of the log-parameters, least
            determined first: (standard error along the axis, {parameter: exponent}), the
            axis normalised so that its largest exponent is 1 (relative spread of the product
            of powers).
        uncertainty: method of the standard errors.
        wall_time: seconds for the whole call; fit_time: optimiser only.
        iterations, evaluations: optimiser iterations and cost evaluations.
        samples_train, samples_validation: scored samples.
        truncated: samples where the gradient guard restarted the sensitivities (the
            observer's discrete map was locally chaotic) at the final point.
        samples_saturated: sliding samples (training and validation) left unscored because
            the observer's CoR was clipped at c_max there (``score_saturated=False``).
        settings: loss, weighting, method, observer settings, ...
        validation_trace: arrays for the Figure-5 plot of the validation maneuvers (t, omega,
            omega_hat, maneuver index) or None.
    """

    status: str
    message: str
    params: ContactParams
    params0: ContactParams
    estimates: tuple[ParameterEstimate, ...]
    free: tuple[str, ...]
    cost_trace: tuple[float, ...]
    rmse_train: float
    rmse_validation: float
    rms_omega_train: float
    rms_omega_validation: float
    maneuver_rmse: dict[str, float]
    validation_keys: tuple[str, ...]
    correlation: np.ndarray
    identifiability: tuple[str, ...]
    weak_directions: tuple[tuple[float, dict[str, float]], ...]
    uncertainty: str
    wall_time: float
    fit_time: float
    iterations: int
    evaluations: int
    samples_train: int
    samples_validation: int
    truncated: int
    settings: dict
    validation_trace: dict | None = None
    samples_saturated: int = 0

    @property
    def success(self) -> bool:
        return self.status == "converged"

    @property
    def observer(self) -> dict:
        """Settings of the observer inside the cost (keywords of :class:`lugrip.Observer`):
        run online with exactly these, ``lugrip.Observer(result.params, **result.observer)``;
        :meth:`save_yaml` writes them as the ``observer:`` block."""
        return dict(self.settings.get("observer", {}))

    def make_observer(self) -> Observer:
        """The online observer the parameters were identified for."""
        return Observer(self.params, **self.observer)

    def __getitem__(self, name: str) -> ParameterEstimate:
        for e in self.estimates:
            if e.name == name:
                return e
        raise KeyError(name)

    def table(self) -> str:
        """Plain-text parameter table: value, unit, bounds, standard error, start."""
        head = (
            f"{'parameter':10s} {'value':>12s} {'std.err':>10s} {'rel':>7s}  "
            f"{'bounds':>23s} {'start':>12s}  unit"
        )
        lines = [head, "-" * len(head)]
        for e in self.estimates:
            if e.free:
                se = f"{e.stderr:10.3g}" if math.isfinite(e.stderr) else f"{'n/a':>10s}"
                rel = f"{100 * e.relative_stderr:6.2f}%" if math.isfinite(e.stderr) else f"{'':>7s}"
                bnd = f"[{e.lower:.3g}, {e.upper:.3g}]"
                if e.at_bound:
                    bnd = f"{e.at_bound.upper()} {bnd}"
            else:
                se, rel, bnd = f"{'fixed':>10s}", f"{'':>7s}", ""
            lines.append(
                f"{e.name:10s} {e.value:12.6g} {se} {rel}  {bnd:>23s} {e.initial:12.6g}  {e.unit}"
            )
        return "\n".join(lines)

    def summary(self) -> str:
        """Status, RMSE, timing, the table and the identifiability notes."""
        out = [
            (
                f"status: {self.status} ({self.message}); {self.iterations} iterations, "
                f"{self.evaluations} evaluations, fit {self.fit_time:.2f} s, total "
                f"{self.wall_time:.2f} s"
            ),
            (
                f"RMSE omega_hat: train {self.rmse_train:.4g} rad/s (RMS omega "
                f"{self.rms_omega_train:.3g}, {self.samples_train} samples), validation "
                f"{self.rmse_validation:.4g} rad/s (RMS omega {self.rms_omega_validation:.3g}, "
                f"{self.samples_validation} samples, {len(self.validation_keys)} maneuvers)"
            ),
            self.table(),
        ]
        if self.identifiability:
            out.append("identifiability:")
            out.extend(f"  - {s}" for s in self.identifiability)
        return "\n".join(out)

    def to_dict(self) -> dict:
        """JSON/YAML-able summary (no arrays except the correlation as nested lists)."""
        return {
            "contact": {
                e.name: {
                    k: v
                    for k, v in {
                        "value": e.value,
                        "unit": e.unit,
                        "free": e.free,
                        "stderr": e.stderr if math.isfinite(e.stderr) else None,
                        "initial": e.initial,
                        "bounds": [e.lower, e.upper] if e.free else None,
                        "at_bound": e.at_bound,
                        "note": e.note or None,
                    }.items()
                    if v is not None
                }
                for e in self.estimates
            }
            | {
                "k": {
                    "value": self.params.k if math.isfinite(self.params.k) else ".inf",
                    "unit": "-",
                },
                "c_max": {"value": self.params.c_max, "unit": "-"},
            },
            # the observer inside the cost: the parameters are identified FOR it (MODEL.md
            # 8.1), so online use must run the same one (lugrip observe --params reads this)
            "observer": dict(self.observer),
            "identification": {
                "status": self.status,
                "message": self.message,
                "free": list(self.free),
                "rmse_train": self.rmse_train,
                "rmse_validation": None
                if math.isnan(self.rmse_validation)
                else self.rmse_validation,
                "rms_omega_train": self.rms_omega_train,
                "rms_omega_validation": None
                if math.isnan(self.rms_omega_validation)
                else self.rms_omega_validation,
                "samples_train": self.samples_train,
                "samples_validation": self.samples_validation,
                "validation_maneuvers": list(self.validation_keys),
                "iterations": self.iterations,
                "evaluations": self.evaluations,
                "wall_time": self.wall_time,
                "fit_time": self.fit_time,
                "cost_trace": list(self.cost_trace),
                "uncertainty": self.uncertainty,
                "correlation": {
                    "parameters": list(self.free),
                    "matrix": np.round(self.correlation, 6).tolist(),
                },
                "identifiability": list(self.identifiability),
                "truncated_gradient_samples": self.truncated,
                "saturated_samples_unscored": self.samples_saturated,
                "settings": self.settings,
            },
        }

    def save_yaml(self, path: str | Path) -> Path:
        """Write the identified parameters with units, standard errors, bounds, the
        ``observer:`` block (the settings of the observer inside the cost) and the fit
        summary. :meth:`lugrip.ContactParams.from_yaml` reads the parameters back (the
        ``contact`` block), :func:`lugrip.read_observer_settings` the observer block;
        ``lugrip observe --params`` and ``lugrip identify --params0`` use both."""
        import yaml

        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        text = (
            "# lugrip identification (paper Section 4, MODEL.md 8): contact parameters\n"
            "# value [unit], standard error, bounds; the observer they were identified with\n"
            "# (use it online: lugrip observe --params reads the observer block); fit summary\n"
            + yaml.safe_dump(_plain(self.to_dict()), sort_keys=False)
        )
        tmp = path.with_name(path.name + ".tmp")
        tmp.write_text(text)
        os.replace(tmp, path)
        return path


def _plain(obj):
    """Python scalars/lists for yaml.safe_dump."""
    if isinstance(obj, dict):
        return {str(k): _plain(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_plain(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _plain(obj.tolist())
    if isinstance(obj, (np.floating, float)):
        v = float(obj)
        return v if math.isfinite(v) else (".nan" if math.isnan(v) else ".inf")
    if isinstance(obj, (np.integer,)):
        return int(obj)
    if isinstance(obj, np.bool_):
        return bool(obj)
    return obj


# ---------------------------------------------------------------------------------------------
# identify
# ---------------------------------------------------------------------------------------------


def _parse_free(free) -> tuple[str, ...]:
    if isinstance(free, str):
        free = [f for f in free.replace(" ", "").split(",") if f]
    names = []
    for f in free:
        key = str(f).lower().replace("-", "_")
        key = {"beta": "beta_a", "betaa": "beta_a", "sigmaz": "sigma_z", "sigma_0": "sigma0"}.get(
            key, key
        )
        if key not in PARAMETERS:
            raise ValueError(f"free parameter {f!r}: expected some of {', '.join(PARAMETERS)}")
        if key not in names:
            names.append(key)
    if not names:
        raise ValueError("free: give at least one parameter to identify")
    return tuple(n for n in PARAMETERS if n in names)


def _bounds(bounds) -> dict[str, tuple[float, float]]:
    out = dict(DEFAULT_BOUNDS)
    for name, pair in (bounds or {}).items():
        if name not in PARAMETERS:
            raise ValueError(f"bounds: unknown parameter {name!r}")
        lo, hi = (float(v) for v in pair)
        if not (0.0 < lo < hi < math.inf):
            raise ValueError(
                f"bounds[{name!r}] = ({lo!r}, {hi!r}): need 0 < lower < upper < inf "
                "(parameters are optimised in log scale)"
            )
        if name == "gamma" and hi >= 1.0 / 3.0:
            raise ValueError(f"bounds['gamma'] upper = {hi!r}: gamma < 1/3 (contact mechanics)")
        out[name] = (lo, hi)
    return out


def _split(keys: Sequence[str], validation, seed) -> list[int]:
    m = len(keys)
    if validation is None or (
        isinstance(validation, (int, float))
        and not isinstance(validation, bool)
        and float(validation) == 0.0
    ):
        return []
    if isinstance(validation, (int, float)) and not isinstance(validation, bool):
        frac = float(validation)
        if not (0.0 < frac < 1.0):
            raise ValueError(f"validation = {validation!r}: a fraction in [0, 1) or maneuver keys")
        if m < 2:
            return []
        n_val = min(max(1, round(frac * m)), m - 1)
        rng = np.random.default_rng(seed)
        return sorted(rng.choice(m, size=n_val, replace=False).tolist())
    chosen = []
    for v in validation:
        if isinstance(v, (int, np.integer)):
            if not 0 <= int(v) < m:
                raise ValueError(f"validation maneuver index {v} out of range (0..{m - 1})")
            chosen.append(int(v))
        else:
            if str(v) not in keys:
                raise ValueError(
                    f"validation maneuver {v!r} not in the data (keys look like {keys[0]!r})"
                )
            chosen.append(keys.index(str(v)))
    if len(set(chosen)) >= m:
        raise ValueError("validation: leave at least one maneuver for training")
    return sorted(set(chosen))


def _weak_directions(H: np.ndarray, names: Sequence[str]):
    """Eigen-decomposition of the scale-free (unit-diagonal) Gauss-Newton matrix: pairs
    (eigenvalue / largest, {name: weight}), weakest first; and the correlation matrix."""
    d = np.sqrt(np.maximum(np.diag(H), 1e-300))
    Hn = H / np.outer(d, d)
    lam, vec = np.linalg.eigh(Hn)
    lam_max = max(lam.max(), 1e-300)
    dirs = []
    for i in np.argsort(lam):
        v = vec[:, i] / d  # back to log-parameter units
        v = v / np.max(np.abs(v))
        dirs.append(
            (
                float(max(lam[i], 0.0) / lam_max),
                {n: float(round(c, 3)) for n, c in zip(names, v) if abs(c) >= 0.05},
            )
        )
    try:
        cov = np.linalg.inv(Hn)
        s = np.sqrt(np.abs(np.diag(cov)))
        corr = cov / np.outer(s, s)
    except np.linalg.LinAlgError:
        corr = np.full_like(H, np.nan)
    return dirs, corr


def _combination_text(weights: Mapping[str, float]) -> str:
    parts = []
    for n, c in weights.items():
        ex = f"{c:+.2g}"
        parts.append(f"{n}^{ex}")
    return " * ".join(parts)


def _identify_pass(
    logs,
    params0=None,
    free: Sequence[str] | str = PARAMETERS,
    bounds: Mapping[str, tuple[float, float]] | None = None,
    *,
    observer: Mapping[str, Any] | Observer | None = None,
    validation: float | Sequence = 0.2,
    seed: int = 0,
    loss: str = "squared",
    huber_scale: float = 0.05,
    weighting: str = "maneuver",
    method: str = "gauss-newton",
    max_iterations: int = 200,
    tolerance: float | None = None,
    uncertainty: str = "gauss-newton",
    n_bootstrap: int = 20,
    start: str | None = None,
    slip_threshold: float = _DEFAULT_SLIP,
    max_gap: float | None = None,
    fix_unidentifiable: bool = True,
    score_saturated: bool = False,
    threads: int = 0,
    k: float | None = None,
    c_max: float | None = None,
    progress: Callable[[int, float, ContactParams], None] | None = None,
    clip_params: ContactParams | None = None,
) -> IdentificationResult:
    """Identify contact parameters from sliding logs with ground-truth velocity (paper
    Section 4): minimise the online observer's velocity error (eqs. 32-33) with SQP.

    Args:
        logs: :class:`lugrip.SlidingLog`, a path (:func:`lugrip.read_log`), a mapping of arrays
            or a sequence of these; needs ``omega``. Each maneuver (``maneuver`` column) and
            each gap-free stretch of it is a separate observer run.
        params0: start point and the values of the parameters that are not free
            (ContactParams, preset name, dict or YAML path). None: the start is computed from
            the data (:func:`initial_guess`); then every parameter must be free.
        free: parameters to identify (names or "mu,beta_a"); the others stay at params0.
            The per-object step of the paper is ``free=("mu", "beta_a")``.
        bounds: {name: (lower, upper)} overriding :data:`DEFAULT_BOUNDS`.
        observer: settings of the online observer (keywords of :class:`lugrip.Observer`, or
            an Observer). None: the ``observer:`` block of a params0 YAML file when it has
            one (an earlier identification, e.g. the fingertip's for an object refit), else
            the observer's defaults. The result records them (``result.observer``, the
            ``observer:`` block of :meth:`IdentificationResult.save_yaml`): the parameters
            are identified for that observer and must be used with it online.
        validation: fraction of maneuvers held out (random, ``seed``) or their keys/indices;
            0 or None: no validation set.
        loss: "squared" (eq. 32) or "huber" (residuals above ``huber_scale`` [rad/s] count
            linearly: robust against outliers in the ground truth).
        weighting: "maneuver" (each maneuver weighs the same, so short maneuvers count) or
            "sample" (eq. 32).
        method: "gauss-newton" (default: SQP whose Hessian is the Gauss-Newton matrix from
            C++, each step a box-constrained quadratic subproblem with Levenberg-Marquardt
            damping), "slsqp" (scipy's SQP, quasi-Newton Hessian) or "trust-constr" (scipy,
            with the Gauss-Newton Hessian). The first needs 3-5x fewer cost evaluations on
            the benchmark data (BENCHMARKS.md).
        max_iterations, tolerance: optimiser limits (tolerance on the relative cost change;
            default 1e-8 for gauss-newton, 1e-10 (ftol) for slsqp).
        uncertainty: "gauss-newton" (J^T J at the optimum, independent residuals: optimistic
            for autocorrelated errors), "sandwich" (maneuver-clustered, robust to
            autocorrelation within maneuvers) or "bootstrap" (``n_bootstrap`` refits on
            maneuvers resampled with replacement).
        start: "data" (computed) or "params0"; default: params0 when given, else data.
        slip_threshold: |omega| [rad/s] above which a sample counts as sliding (checks, the
            initial guess and the clipped-CoR exclusion).
        max_gap: split segments at time steps above this [s] (default: 5 sample periods).
        fix_unidentifiable: fix gamma when the normal force does not vary and delta when the
            data hold only rotations (with an :class:`IdentifiabilityWarning`); False: keep
            them free and only warn.
        score_saturated: also score sliding samples where the observer's CoR is clipped at
            c_max. Default False: where the load puts the CoR beyond the clip (translation-
            dominated sliding) the observer estimates the slip rate about the clipped CoR, not
            the object's rotation, so no ground-truth omega compares with it; such samples
            (|omega| > slip_threshold) still run through the observer but are left out of the
            cost (``samples_saturated``); stick samples are scored (omega_hat ~ 0 there).
            Scoring them bends mu, delta, beta_A and sigma0 (measured: mu x1.5 on logs with
            10 % of such maneuvers).
        threads: C++ worker threads (0: all cores).
        k, c_max: pressure exponent and CoR clip when params0 is None (default 4 and 1.5).
        progress: called after every iteration as progress(iteration, cost, params).

    Returns:
        :class:`IdentificationResult`.

    Raises:
        IdentificationError: no ground truth, all-stick data with mu or beta_a free, no
            parameters left to fit, or a fit that produced no finite cost.
        ValueError: bad arguments.
    """
    t_start = time.perf_counter()
    free = _parse_free(free)
    bnds = _bounds(bounds)
    if loss not in ("squared", "huber"):
        raise ValueError(f"loss = {loss!r}: 'squared' or 'huber'")
    if weighting not in ("maneuver", "sample"):
        raise ValueError(f"weighting = {weighting!r}: 'maneuver' or 'sample'")
    if method not in ("slsqp", "trust-constr", "gauss-newton"):
        raise ValueError(f"method = {method!r}: 'gauss-newton', 'slsqp' or 'trust-constr'")
    if tolerance is None:
        tolerance = 1e-8 if method == "gauss-newton" else 1e-10
    if uncertainty not in ("gauss-newton", "sandwich", "bootstrap"):
        raise ValueError(
            f"uncertainty = {uncertainty!r}: 'gauss-newton', 'sandwich' or 'bootstrap'"
        )
    if (
        params0 is not None
        and isinstance(params0, (str, os.PathLike))
        and Path(params0).suffix in (".yaml", ".yml")
    ):
        if observer is None:
            observer = read_observer_settings(params0)
            if observer is not None:
                observer.pop("dt", None)  # the nominal sample period is this data's
        params0 = ContactParams.from_yaml(params0)
    p_given = None if params0 is None else _as_params(params0)
    if p_given is None and len(free) < len(PARAMETERS):
        fixed = [n for n in PARAMETERS if n not in free]
        raise IdentificationError(
            f"params0 is needed for the fixed parameter(s) {', '.join(fixed)} (e.g. the "
            "fingertip's identified parameters for an object refit)"
        )
    if start is None:
        start = "params0" if p_given is not None else "data"
    if start not in ("data", "params0"):
        raise ValueError(f"start = {start!r}: 'data' or 'params0'")
    if start == "params0" and p_given is None:
        raise ValueError("start = 'params0' needs params0")
    kk = p_given.k if p_given is not None else (4.0 if k is None else float(k))
    cm = p_given.c_max if p_given is not None else (1.5 if c_max is None else float(c_max))

    # --- data
    mans = load_maneuvers(logs, max_gap=max_gap)
    keys = [m.key for m in mans]
    notes: list[str] = []
    if len(mans) == 1:
        warnings.warn(
            "a single maneuver: no validation split is possible and one maneuver "
            "rarely fixes all six parameters (one force, one CoR); record several "
            "maneuvers at different forces and CoRs",
            IdentificationWarning,
            stacklevel=2,
        )
        notes.append("single maneuver: no validation set")
    omega_all = np.concatenate([m.omega for m in mans])
    finite = np.isfinite(omega_all)
    sliding = finite & (np.abs(omega_all) > slip_threshold)
    n_slide = int(np.count_nonzero(sliding))
    if n_slide < max(10, int(0.002 * np.count_nonzero(finite))):
        msg = (
            f"no sliding in the data: |omega| <= {slip_threshold:g} rad/s on all but {n_slide} "
            f"of {int(np.count_nonzero(finite))} samples (all-stick). mu and beta_A are not "
            "identifiable from stick data (the friction never reaches its capacity: only a "
            "lower bound on mu). Record maneuvers that slide, or fit only sigma0/sigma_z "
            "with free=('sigma0', 'sigma_z') and params0."
        )
        if "mu" in free or "beta_a" in free:
            raise IdentificationError(msg)
        warnings.warn(msg, IdentifiabilityWarning, stacklevel=2)

    # --- start point
    guess_notes: dict[str, str] = {}
    if start == "data":
        g = initial_guess(mans, k=kk, c_max=cm, slip_threshold=slip_threshold, bounds=bnds)
        guess_notes = dict(g.notes)
        base = g.params if p_given is None else p_given
        p0 = base.replace(**{n: getattr(g.params, n) for n in free})
    else:
        p0 = p_given
        guess_notes = {n: "params0" for n in PARAMETERS}
    for n in free:  # inside the bounds
        v = getattr(p0, n)
        lo, hi = bnds[n]
        if not (lo < v < hi):
            p0 = p0.replace(**{n: _clip(n, v, bnds)})
            notes.append(
                f"{n}: start {v:.4g} outside the bounds [{lo:.3g}, {hi:.3g}], moved inside"
            )

    # --- structural identifiability checks (before fitting)
    fixed_notes: dict[str, str] = {}
    free_list = list(free)
    f_man = np.array([np.median(m.f_n) for m in mans])
    if (
        "delta" in free_list
        and "gamma" in free_list
        and f_man.max() / max(f_man.min(), 1e-12) < 1.5
    ):
        msg = (
            f"normal force hardly varies (median per maneuver {f_man.min():.3g}-"
            f"{f_man.max():.3g} N): delta and gamma enter through rho = delta f_n^gamma only "
            "and are not separately identifiable"
        )
        if fix_unidentifiable:
            free_list.remove("gamma")
            fixed_notes["gamma"] = f"fixed at {p0.gamma:.4g}: normal force hardly varies"
            msg += f"; gamma fixed at {p0.gamma:.4g}"
        warnings.warn(msg, IdentifiabilityWarning, stacklevel=2)
        notes.append(msg)
    if "delta" in free_list and ("mu" in free_list or "beta_a" in free_list):
        c_abs = []
        for m in mans:
            sel = np.isfinite(m.omega) & (np.abs(m.omega) > slip_threshold)
            if np.any(sel):
                c_abs.append(np.abs(estimate_cor(p0, m.f_n[sel], m.f_t[sel], m.tau[sel]).c_tilde))
        if c_abs and np.percentile(np.concatenate(c_abs), 95) < 0.15:
            msg = (
                "the data hold only rotations (estimated |c~| < 0.15 on 95 % of the sliding "
                "samples): mu and delta enter only as mu delta (tau_max) and beta_A only as "
                "beta_A delta^4, so delta is not separately identifiable"
            )
            if fix_unidentifiable:
                free_list.remove("delta")
                fixed_notes["delta"] = f"fixed at {p0.delta:.4g}: rotation-only data"
                msg += f"; delta fixed at {p0.delta:.4g}"
            warnings.warn(msg, IdentifiabilityWarning, stacklevel=2)
            notes.append(msg)
    if not free_list:
        raise IdentificationError("no parameter left to identify")
    free_t = tuple(free_list)
    idx = [PARAMETERS.index(n) for n in free_t]

    # --- problems
    if observer is None:
        observer = {}
    if isinstance(observer, Mapping) and observer.get("dt") is None:
        # the nominal sample period (sign hysteresis band of the CoR torque) is the data's,
        # as in `lugrip observe`, which takes it from the log
        steps = np.concatenate([m.dt[m.dt > 0] for m in mans] or [np.zeros(0)])
        if steps.size:
            observer = {**observer, "dt": float(np.median(steps))}
    osettings, odict = _observer_settings(observer, p0)
    settings = _core.IdentificationSettings()
    settings.observer = osettings
    settings.loss = _core.IdLoss.Huber if loss == "huber" else _core.IdLoss.Squared
    settings.huber_scale = float(huber_scale)
    settings.threads = int(threads)
    msg = _core.validate_identification_settings(settings)
    if msg:
        raise ValueError("invalid identification settings:\n" + msg.rstrip())
    # Sliding samples whose CoR the online observer clips at c_max are not scored (their
    # ground truth is left out, the observer still runs through them): computed at fixed
    # parameters (`clip_params`, else the start) so that the cost stays smooth during the fit;
    # identify() repeats the fit with the set found at the previous result until it settles.
    n_clipped = 0
    if not score_saturated:
        online = Observer(p0 if clip_params is None else clip_params, **odict)
        for m in mans:
            mask = _clipped_sliding(m, online, slip_threshold)
            if np.any(mask):
                m.omega = np.where(mask, np.nan, m.omega)
                n_clipped += int(mask.sum())
    val_idx = _split(keys, validation, seed)
    train_m = [m for i, m in enumerate(mans) if i not in set(val_idx)]
    val_m = [mans[i] for i in val_idx]
    train = _Problem(train_m, settings, weighting)
    val = _Problem(val_m, settings, weighting) if val_m else None

    # A computed start can be poor when the data break its assumptions (e.g. a robot that
    # imposes the motion: the friction at the first sliding sample is far below mu f_n); keep
    # it only if its cost beats the paper's Table 1 fingertip as a prior guess.
    if start == "data":
        prior = ContactParams.table1().replace(k=kk, c_max=cm)
        cand = p0.replace(**{n: getattr(prior, n) for n in free_t})
        c_guess = float(train.evaluate(p0, False)["cost"])
        c_prior = float(train.evaluate(cand, False)["cost"])
        if math.isfinite(c_prior) and not (c_guess <= c_prior):
            notes.append(
                f"the start computed from the data (cost {c_guess:.3g}) was worse than "
                f"the Table 1 values (cost {c_prior:.3g}): started from Table 1"
            )
            guess_notes = {
                n: "Table 1 (better cost than the data-computed guess)" for n in PARAMETERS
            }
            p0 = cand

    # --- optimisation in x = ln(p / p0) over the free parameters
    scale = np.array([getattr(p0, n) for n in free_t])
    lo = np.log(np.array([bnds[n][0] for n in free_t]) / scale)
    hi = np.log(np.array([bnds[n][1] for n in free_t]) / scale)

    def params_at(x) -> ContactParams:
        vals = scale * np.exp(np.clip(x, lo, hi))
        return p0.replace(**{n: float(v) for n, v in zip(free_t, vals)})

    cache: dict[bytes, dict] = {}

    def ev_at(x):
        key = np.asarray(x, dtype=float).tobytes()
        if key not in cache:
            if len(cache) > 4:
                cache.clear()
            cache[key] = train.evaluate(params_at(x), True)
        return cache[key]

    ev0 = ev_at(np.zeros(len(free_t)))
    c0 = float(ev0["cost"])
    if not (math.isfinite(c0) and c0 > 0.0):
        raise IdentificationError(
            f"the cost at the start point is {c0!r}: no scored samples? "
            "(check that omega is finite where the sensor is in contact)"
        )

    def fun(x):
        return float(ev_at(x)["cost"]) / c0

    def jac(x):
        g = np.asarray(ev_at(x)["gradient"])[idx]
        return g * (scale * np.exp(x)) / c0

    def hess(x):
        H = np.asarray(ev_at(x)["gauss_newton"]).reshape(6, 6)[np.ix_(idx, idx)]
        s = scale * np.exp(x)
        return H * np.outer(s, s) / c0

    trace = [c0]
    iteration = [0]
    if progress is not None:
        progress(0, c0, p0)

    # The variables are already scaled (log of the start point); a further diagonal
    # preconditioning with the Gauss-Newton diagonal made SLSQP slower on the benchmark data.
    D = np.ones(len(free_t))

    def callback(xk, *args):
        iteration[0] += 1
        c = float(ev_at(xk)["cost"])
        trace.append(c)
        if progress is not None:
            progress(iteration[0], c, params_at(xk))

    from scipy.optimize import Bounds, minimize

    t_fit = time.perf_counter()
    x0 = np.zeros(len(free_t))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        if method == "gauss-newton":
            res = _gauss_newton(
                lambda x: (fun(x), jac(x), hess(x)),
                x0,
                lo,
                hi,
                max_iterations=max_iterations,
                tolerance=tolerance,
                callback=callback,
            )
        else:
            fu = lambda u: fun(u / D)
            ju = lambda u: jac(u / D) / D
            if method == "slsqp":
                res = minimize(
                    fu,
                    x0,
                    jac=ju,
                    method="SLSQP",
                    bounds=list(zip(D * lo, D * hi)),
                    callback=lambda u: callback(u / D),
                    options={"maxiter": int(max_iterations), "ftol": float(tolerance)},
                )
            else:
                res = minimize(
                    fu,
                    x0,
                    jac=ju,
                    hess=lambda u: hess(u / D) / np.outer(D, D),
                    method="trust-constr",
                    bounds=Bounds(D * lo, D * hi),
                    callback=lambda u, state: callback(u / D),
                    options={"maxiter": int(max_iterations), "gtol": 1e-8, "xtol": 1e-10},
                )
            res.x = np.asarray(res.x) / D
    fit_time = time.perf_counter() - t_fit
    x = np.clip(np.asarray(res.x, dtype=float), lo, hi)
    if fun(x) > fun(x0):  # never return worse than the start
        x = x0
    p_hat = params_at(x)
    if res.success:
        status = "converged"
    elif "iteration" in str(res.message).lower():
        status = "max_iterations"
    else:
        status = "failed"

    # --- final evaluations
    ev = train.evaluate(p_hat, True, True)
    if not math.isfinite(ev["cost"]):
        raise IdentificationError("the cost at the identified point is not finite")
    sse, cnt = train.per_maneuver(ev)
    m_rmse = {
        m.key: float(math.sqrt(s / c)) if c else math.nan for m, s, c in zip(train_m, sse, cnt)
    }
    rmse_train = float(math.sqrt(sse.sum() / max(cnt.sum(), 1)))
    rms_train = float(np.sqrt(np.nanmean(train.omega[np.isfinite(train.omega)] ** 2)))
    rmse_val = rms_val = math.nan
    trace_val = None
    n_val = 0
    if val is not None:
        evv = val.evaluate(p_hat, False, True)
        s_v, c_v = val.per_maneuver(evv)
        m_rmse.update(
            {m.key: float(math.sqrt(s / c)) if c else math.nan for m, s, c in zip(val_m, s_v, c_v)}
        )
        n_val = int(c_v.sum())
        rmse_val = float(math.sqrt(s_v.sum() / max(n_val, 1)))
        fin = np.isfinite(val.omega)
        rms_val = float(np.sqrt(np.mean(val.omega[fin] ** 2))) if fin.any() else math.nan
        trace_val = {
            "t": np.concatenate([m.t for m in val_m]),
            "omega": val.omega,
            "omega_hat": np.asarray(evv["omega_hat"]),
            "maneuver": np.repeat(np.arange(len(val_m)), [m.n for m in val_m]),
            "keys": [m.key for m in val_m],
        }

    # --- uncertainty and identifiability (log-parameter space)
    s_free = np.array([getattr(p_hat, n) for n in free_t])
    H = np.asarray(ev["gauss_newton"]).reshape(6, 6)[np.ix_(idx, idx)] * np.outer(s_free, s_free)
    dirs, corr = _weak_directions(H, free_t)
    n_sc = int(ev["scored"])
    wsum = float(ev["weight_sum"])
    dof = max(n_sc - len(free_t), 1)
    cov = np.full((len(free_t), len(free_t)), np.nan)
    # parameters at a bound are held there: the covariance is that of the interior ones
    inner = np.array([lo[i] + 1e-6 < x[i] < hi[i] - 1e-6 for i in range(len(free_t))])
    ii = np.ix_(inner, inner)
    try:
        if uncertainty == "gauss-newton":
            sigma2 = float(ev["cost"]) * wsum / dof if loss == "squared" else float(sse.sum()) / dof
            cov[ii] = 2.0 * sigma2 / wsum * np.linalg.inv(H[ii])
        elif uncertainty == "sandwich":
            G = train.maneuver_gradients(ev)[:, idx] * s_free  # d(sum w loss)/d ln p per maneuver
            Hi = np.linalg.inv(H[ii] * wsum)  # Hessian of sum w loss
            cov[ii] = Hi @ (G[:, inner].T @ G[:, inner]) @ Hi
    except np.linalg.LinAlgError:
        notes.append("Gauss-Newton matrix singular: standard errors not available")
    if uncertainty == "bootstrap":
        if len(train_m) >= 2:
            rng = np.random.default_rng(seed + 1)
            samples = []
            for _ in range(int(n_bootstrap)):
                pick = rng.integers(0, len(train_m), size=len(train_m))
                prob_b = _Problem([train_m[i] for i in pick], settings, weighting)
                pb = _refit(prob_b, p_hat, free_t, bnds, max_iterations, tolerance)
                samples.append(np.log([getattr(pb, n) for n in free_t]))
            cov = np.atleast_2d(np.cov(np.array(samples).T, ddof=1))
        else:
            notes.append("bootstrap needs two or more training maneuvers")
    stderr_log = np.sqrt(np.abs(np.diag(cov)))
    if uncertainty != "bootstrap":
        stderr_log[~inner] = np.nan
    if np.all(np.isfinite(cov[ii])) and inner.any():
        s = np.sqrt(np.maximum(np.diag(cov), 1e-300))
        corr = np.where(np.outer(inner, inner), cov / np.outer(s, s), np.nan)

    ident = list(notes)
    for ratio, weights in dirs:
        if ratio < 1e-10:
            ident.append(
                f"not identifiable from these data: {_combination_text(weights)} "
                f"(the scale-free Gauss-Newton matrix is singular along it, eigenvalue "
                f"{ratio:.1e} of the largest)"
            )
    # least determined combinations: principal axes of the covariance of the log-parameters
    # (statistical spread only; model mismatch, e.g. the observer's lag, biases beyond it)
    weak: list[tuple[float, dict[str, float]]] = []
    names_in = [n for n, k in zip(free_t, inner) if k]
    if names_in and np.all(np.isfinite(cov[ii])):
        var, vec = np.linalg.eigh(cov[ii])
        for ax in np.argsort(var)[::-1]:
            v = vec[:, ax] / np.max(np.abs(vec[:, ax]))
            sd = math.sqrt(max(var[ax], 0.0)) * float(np.linalg.norm(v))
            weak.append(
                (sd, {n: float(round(c, 3)) for n, c in zip(names_in, v) if abs(c) >= 0.05})
            )
        for sd, weights in weak:
            if sd > 0.05 and len(weights) > 1:
                ident.append(
                    f"weakly identifiable: {_combination_text(weights)} is determined "
                    f"only to +-{100 * sd:.0f} % (one standard error)"
                )
    for i in range(len(free_t)):
        for j in range(i + 1, len(free_t)):
            if np.isfinite(corr[i, j]) and abs(corr[i, j]) > 0.99:
                # the best-determined combination ln p_i + c ln p_j, c = -cov_ij / cov_jj
                c = -cov[i, j] / cov[j, j]
                sd = math.sqrt(max(cov[i, i] + 2 * c * cov[i, j] + c * c * cov[j, j], 0.0))
                ident.append(
                    f"{free_t[i]} and {free_t[j]} are strongly correlated "
                    f"({corr[i, j]:+.3f}): {free_t[i]} * {free_t[j]}^{c:.2g} is "
                    f"determined to +-{100 * sd:.2g} %, {free_t[i]} alone to "
                    f"+-{100 * stderr_log[i]:.2g} %"
                )
    if n_clipped:
        n_all = sum(m.n for m in mans)
        ident.append(
            f"{n_clipped} samples ({100 * n_clipped / max(n_all, 1):.1f} %) not scored: "
            "sliding with the CoR clipped at c_max (translation beyond the clip), where "
            "omega_hat is the slip about the clipped CoR, not the object's rotation"
        )
    if int(ev["truncated"]):
        ident.append(
            f"gradient truncated on {int(ev['truncated'])} samples where the observer "
            "chatters (its discrete map is locally chaotic there)"
        )

    estimates = []
    for n in PARAMETERS:
        v = getattr(p_hat, n)
        if n in free_t:
            i = free_t.index(n)
            lo_n, hi_n = bnds[n]
            at = "lower" if x[i] <= lo[i] + 1e-6 else "upper" if x[i] >= hi[i] - 1e-6 else None
            if at:
                ident.append(
                    f"{n} at its {at} bound ({v:.4g}): the data push it outside the "
                    "physical range, or the bound is too tight"
                )
            estimates.append(
                ParameterEstimate(
                    n,
                    _UNITS[n],
                    v,
                    getattr(p0, n),
                    lo_n,
                    hi_n,
                    True,
                    at,
                    float(v * stderr_log[i]),
                    guess_notes.get(n, ""),
                )
            )
        else:
            estimates.append(
                ParameterEstimate(
                    n,
                    _UNITS[n],
                    v,
                    getattr(p0, n),
                    math.nan,
                    math.nan,
                    False,
                    None,
                    math.nan,
                    fixed_notes.get(n, "fixed (params0)"),
                )
            )
    if any(e.at_bound for e in estimates):
        warnings.warn(
            "parameter(s) at a bound: "
            + ", ".join(f"{e.name} ({e.at_bound})" for e in estimates if e.at_bound),
            IdentificationWarning,
            stacklevel=2,
        )
    if status != "converged":
        warnings.warn(
            f"the optimiser stopped without convergence: {res.message}",
            IdentificationWarning,
            stacklevel=2,
        )
    return IdentificationResult(
        status=status,
        message=str(res.message),
        params=p_hat,
        params0=p0,
        estimates=tuple(estimates),
        free=free_t,
        cost_trace=tuple(trace),
        rmse_train=rmse_train,
        rmse_validation=rmse_val,
        rms_omega_train=rms_train,
        rms_omega_validation=rms_val,
        maneuver_rmse=m_rmse,
        validation_keys=tuple(m.key for m in val_m),
        correlation=corr,
        identifiability=tuple(ident),
        weak_directions=tuple(weak),
        uncertainty=uncertainty,
        wall_time=time.perf_counter() - t_start,
        fit_time=fit_time,
        iterations=int(getattr(res, "nit", iteration[0]) or iteration[0]),
        evaluations=train.evaluations,
        samples_train=int(cnt.sum()),
        samples_validation=n_val,
        truncated=int(ev["truncated"]),
        samples_saturated=n_clipped,
        settings={
            "loss": loss,
            "huber_scale": float(huber_scale),
            "weighting": weighting,
            "method": method,
            "start": start,
            "validation": len(val_m),
            "seed": int(seed),
            "slip_threshold": float(slip_threshold),
            "score_saturated": bool(score_saturated),
            "observer": dict(odict),
            "bounds": {n: list(bnds[n]) for n in free_t},
            "threads": int(threads),
            "maneuvers": len(mans),
        },
        validation_trace=trace_val,
    )


def _clipped_sliding(m: _Maneuver, observer: Observer, slip_threshold: float) -> np.ndarray:
    """Samples of a maneuver where the online observer (restarted per segment, as in the cost)
    clips the CoR at c_max while the ground truth slides (|omega| > slip_threshold)."""
    mask = np.zeros(m.n, dtype=bool)
    for a, b in zip(m.starts[:-1], m.starts[1:]):
        run = observer.run({"f_n": m.f_n[a:b], "f_t": m.f_t[a:b], "tau": m.tau[a:b], "t": m.t[a:b]})
        mask[a:b] = np.asarray(run.saturated, dtype=bool)
    with np.errstate(invalid="ignore"):
        return mask & (np.abs(m.omega) > slip_threshold)


@functools.wraps(_identify_pass)
def identify(logs, params0=None, **kwargs) -> IdentificationResult:
    # Without score_saturated the clipped-CoR samples are found at fixed parameters: the start
    # for the first fit, then each fit's result; the fit is repeated (from the same start) while
    # the set located at its result differs from the one it used (at most 4 fits).
    if "clip_params" in kwargs:
        raise TypeError("identify() got an unexpected keyword argument 'clip_params'")
    t0 = time.perf_counter()
    r = _identify_pass(logs, params0, **kwargs)
    if kwargs.get("score_saturated", False):
        return r
    probe_kw = {**kwargs, "max_iterations": 0, "progress": None, "uncertainty": "gauss-newton"}
    fits, fit_time = 1, r.fit_time
    for _ in range(3):
        # the set at the result, without fitting (no iteration)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            probe = _identify_pass(logs, r.params, clip_params=r.params, **probe_kw)
        if probe.samples_saturated == r.samples_saturated:
            break
        r = _identify_pass(logs, params0, clip_params=r.params, **kwargs)
        fits += 1
        fit_time += r.fit_time
    notes = r.identifiability
    if fits > 1:
        note = (
            f"{fits} fits: the clipped-CoR samples were located again at each fit's result "
            "until the set settled"
        )
        notes = (*notes, note)
    return dataclasses.replace(
        r, identifiability=notes, wall_time=time.perf_counter() - t0, fit_time=fit_time
    )


_sig = inspect.signature(_identify_pass)
identify.__signature__ = _sig.replace(
    parameters=[q for q in _sig.parameters.values() if q.name != "clip_params"]
)
del _sig


@dataclasses.dataclass
class _GNResult:
    x: np.ndarray
    success: bool
    message: str
    nit: int


def _gauss_newton(
    ev_fun, x0, lo, hi, *, max_iterations: int, tolerance: float, xtol: float = 1e-4, callback=None
) -> _GNResult:
    """Bounded Levenberg-Marquardt: a sequential quadratic programme whose Hessian is the
    Gauss-Newton matrix of the residuals (exact gradient, box constraints by an active set).

    ev_fun(x) -> (cost, gradient, gauss_newton) in the scaled log-parameters. Stops after three
    accepted steps in a row that lower the cost by less than `tolerance` (relative) or move
    every log-parameter by less than `xtol` (creeping along a flat valley).
    """
    x = np.clip(np.asarray(x0, dtype=float), lo, hi)
    f, g, H = ev_fun(x)
    lam = 1e-3
    small = 0
    n = x.size
    for it in range(1, int(max_iterations) + 1):
        eps = 1e-10
        active = ((x <= lo + eps) & (g > 0)) | ((x >= hi - eps) & (g < 0))
        F = ~active
        if not np.any(F):
            return _GNResult(x, True, "every free parameter at a bound", it - 1)
        pg = np.where(F, g, 0.0)
        if np.max(np.abs(pg)) < 1e-12 * max(1.0, abs(f)):
            return _GNResult(x, True, "projected gradient zero", it - 1)
        HF = H[np.ix_(F, F)]
        D = np.maximum(np.diag(HF), 1e-12 * max(np.max(np.diag(HF)), 1e-300))
        accepted = False
        for _ in range(30):
            try:
                step_f = np.linalg.solve(HF + lam * np.diag(D), -g[F])
            except np.linalg.LinAlgError:
                lam *= 10.0
                continue
            step = np.zeros(n)
            step[F] = step_f
            # keep a step of at most a factor e^2 per iteration (log scale)
            big = np.max(np.abs(step))
            if big > 2.0:
                step *= 2.0 / big
            x_new = np.clip(x + step, lo, hi)
            d = x_new - x
            pred = -(g @ d + 0.5 * d @ H @ d)
            f_new, g_new, H_new = ev_fun(x_new)
            if math.isfinite(f_new) and pred > 0 and (f - f_new) >= 1e-4 * pred:
                ratio = (f - f_new) / pred
                lam = lam / 3.0 if ratio > 0.5 else (lam if ratio > 0.1 else lam * 2.0)
                lam = max(lam, 1e-9)
                rel = (f - f_new) / max(abs(f), 1e-300)
                x, f, g, H = x_new, f_new, g_new, H_new
                accepted = True
                if callback is not None:
                    callback(x)
                small = small + 1 if (rel < tolerance or np.max(np.abs(d)) < xtol) else 0
                break
            lam *= 4.0
            if lam > 1e12:
                break
        if not accepted:
            return _GNResult(
                x, True, "no further decrease (converged to the resolution of the cost)", it
            )
        if small >= 3:
            return _GNResult(
                x,
                True,
                f"relative cost change below {tolerance:g} or steps below {xtol:g} (log scale)",
                it,
            )
    return _GNResult(x, False, "maximum number of iterations reached", int(max_iterations))


def _refit(prob: _Problem, p_start: ContactParams, free_t, bnds, max_iterations, tolerance):
    """Gauss-Newton refit from p_start on another problem (bootstrap)."""
    idx = [PARAMETERS.index(n) for n in free_t]
    scale = np.array([getattr(p_start, n) for n in free_t])
    lo = np.log(np.array([bnds[n][0] for n in free_t]) / scale)
    hi = np.log(np.array([bnds[n][1] for n in free_t]) / scale)

    def at(x):
        vals = scale * np.exp(np.clip(x, lo, hi))
        return p_start.replace(**{n: float(v) for n, v in zip(free_t, vals)})

    c0 = float(prob.evaluate(p_start, False)["cost"])

    def ev(x):
        e = prob.evaluate(at(x), True)
        s = scale * np.exp(x)
        g = np.asarray(e["gradient"])[idx] * s / c0
        H = np.asarray(e["gauss_newton"]).reshape(6, 6)[np.ix_(idx, idx)] * np.outer(s, s) / c0
        return float(e["cost"]) / c0, g, H

    res = _gauss_newton(
        ev,
        np.zeros(len(free_t)),
        lo,
        hi,
        max_iterations=max_iterations,
        tolerance=max(tolerance, 1e-8),
    )
    return at(np.asarray(res.x))
