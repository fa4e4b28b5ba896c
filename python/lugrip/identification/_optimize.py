"""Bounded Gauss-Newton (Levenberg-Marquardt) in log-parameters, and a refit for the bootstrap."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .._params import ContactParams
from ._common import PARAMETERS
from ._data import _Problem


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
        for _ in range(8):
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


@dataclasses.dataclass(frozen=True)
class Prior:
    """A Gaussian regularisation of log-parameters: centre ``values`` and covariance ``cov``
    of (ln p for p in ``names``)."""

    names: tuple
    values: np.ndarray
    cov: np.ndarray

    def spread(self, name: str) -> float:
        """Relative spread (standard deviation of ln p) of one parameter."""
        i = self.names.index(name)
        return float(math.sqrt(max(self.cov[i, i], 0.0)))


@dataclasses.dataclass
class Minimum:
    """Outcome of :func:`minimise`: the parameters, x = ln(p / p0) of the free ones, the
    log-bounds, the optimiser's result, the cost trace, the prior's weight and fit time."""

    params: ContactParams
    x: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    result: object
    trace: list
    iterations: int
    fit_time: float
    prior_weight: float
    c0: float
    precision: np.ndarray  # regularisation weight x C^-1 over the free log-parameters


def minimise(
    train: _Problem,
    p0: ContactParams,
    free_t: tuple,
    bnds: dict,
    *,
    method: str,
    max_iterations: int,
    tolerance: float,
    prior: Prior | None = None,
    prior_weight: float = 0.0,
    progress=None,
) -> Minimum:
    """Minimise cost / cost(p0) + prior_weight * d^T C^-1 d over the free log-parameters,
    d = ln p - ln v for the free parameters the ``prior`` names (C: its covariance,
    marginalised to them); the other free parameters are unregularised."""
    import time
    import warnings

    from scipy.optimize import Bounds, minimize

    idx = [PARAMETERS.index(n) for n in free_t]
    scale = np.array([getattr(p0, n) for n in free_t])
    lo = np.log(np.array([bnds[n][0] for n in free_t]) / scale)
    hi = np.log(np.array([bnds[n][1] for n in free_t]) / scale)
    centre = np.zeros(len(free_t))
    prec = np.zeros((len(free_t), len(free_t)))
    if prior is not None and prior_weight > 0:
        sel = [i for i, n in enumerate(free_t) if n in prior.names]
        if sel:
            j = [prior.names.index(free_t[i]) for i in sel]
            for i, jj in zip(sel, j):
                centre[i] = math.log(prior.values[jj] / getattr(p0, free_t[i]))
            prec[np.ix_(sel, sel)] = prior_weight * np.linalg.pinv(prior.cov[np.ix_(j, j)])

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

    c0 = float(ev_at(np.zeros(len(free_t)))["cost"])
    if not (math.isfinite(c0) and c0 > 0.0):
        from ._common import IdentificationError

        raise IdentificationError(
            f"the cost at the start point is {c0!r}: no scored samples? "
            "(check that omega is finite where the sensor is in contact)"
        )

    def fun(x):
        d = x - centre
        return float(ev_at(x)["cost"]) / c0 + float(d @ prec @ d)

    def jac(x):
        g = np.asarray(ev_at(x)["gradient"])[idx]
        return g * (scale * np.exp(x)) / c0 + 2.0 * prec @ (x - centre)

    def hess(x):
        H = np.asarray(ev_at(x)["gauss_newton"]).reshape(6, 6)[np.ix_(idx, idx)]
        s = scale * np.exp(x)
        return H * np.outer(s, s) / c0 + 2.0 * prec

    trace = [c0]
    it = [0]
    if progress is not None:
        progress(0, c0, p0)

    def callback(xk, *args):
        it[0] += 1
        c = float(ev_at(xk)["cost"])
        trace.append(c)
        if progress is not None:
            progress(it[0], c, params_at(xk))

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
        elif method == "slsqp":
            res = minimize(
                fun,
                x0,
                jac=jac,
                method="SLSQP",
                bounds=list(zip(lo, hi)),
                callback=callback,
                options={"maxiter": int(max_iterations), "ftol": float(tolerance)},
            )
        else:
            res = minimize(
                fun,
                x0,
                jac=jac,
                hess=hess,
                method="trust-constr",
                bounds=Bounds(lo, hi),
                callback=lambda u, state: callback(u),
                options={"maxiter": int(max_iterations), "gtol": 1e-8, "xtol": 1e-10},
            )
    fit_time = time.perf_counter() - t_fit
    x = np.clip(np.asarray(res.x, dtype=float), lo, hi)
    if fun(x) > fun(x0):  # never return worse than the start
        x = x0
    return Minimum(
        params=params_at(x),
        x=x,
        lo=lo,
        hi=hi,
        result=res,
        trace=trace,
        iterations=int(getattr(res, "nit", it[0]) or it[0]),
        fit_time=fit_time,
        prior_weight=prior_weight,
        c0=c0,
        precision=prec,
    )
