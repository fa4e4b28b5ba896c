"""The one-shot start point of earlier versions (:func:`initial_guess`): sliding onsets from a
speed threshold. Kept for the API; :func:`identify` starts from the staged estimate
(:mod:`._stages`), which does not assume that the wrench is at the limit surface when the
motion starts."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence

import numpy as np

from .._contact import LimitSurface, estimate_cor
from .._params import ContactParams
from ._common import _DEFAULT_SLIP, DEFAULT_BOUNDS
from ._data import _Maneuver, load_maneuvers


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
