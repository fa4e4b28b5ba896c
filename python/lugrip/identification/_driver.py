"""The driver of the identification: stages from the data, then the eq. 32 refinement."""

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
from .._contact import _as_params, estimate_cor
from .._observer import Observer
from .._params import _UNITS, ContactParams, read_observer_settings
from ._common import (
    _DEFAULT_SLIP,
    PARAMETERS,
    IdentifiabilityWarning,
    IdentificationError,
    IdentificationWarning,
)
from ._data import _Maneuver, _observer_settings, _Problem, load_maneuvers
from ._guess import _clip, initial_guess
from ._optimize import _gauss_newton, _refit
from ._result import IdentificationResult, ParameterEstimate
from ._setup import _bounds, _parse_free, _split
from ._uncertainty import _combination_text, _weak_directions

__all__ = ["identify"]


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
