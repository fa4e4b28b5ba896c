"""Standard errors and identifiability of the eq. 32 refinement (log-parameter space)."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np


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


def covariance(train, ev, mn, free_t, *, loss: str, uncertainty: str, sse, refit=None,
               n_bootstrap: int = 20, seed: int = 0):
    """Covariance of the free log-parameters at the minimum ``mn`` (:class:`Minimum`), the
    standard errors (NaN for parameters held at a bound) and the notes on weak and
    unidentifiable combinations.

    * "gauss-newton": 2 sigma^2 / W (J^T J)^-1, independent residuals (optimistic when the
      residuals are autocorrelated within a maneuver);
    * "sandwich" (default): H^-1 (sum_m g_m g_m^T) H^-1 with the per-maneuver gradients g_m,
      robust to autocorrelation within maneuvers;
    * "bootstrap": refits on maneuvers resampled with replacement (``refit(problem)`` -> p).

    The regularisation toward the stage values (prior precision) is part of H.
    """
    from ._common import PARAMETERS

    idx = [PARAMETERS.index(n) for n in free_t]
    p_hat, x, lo, hi = mn.params, mn.x, mn.lo, mn.hi
    notes: list[str] = []
    s_free = np.array([getattr(p_hat, n) for n in free_t])
    H = np.asarray(ev["gauss_newton"]).reshape(6, 6)[np.ix_(idx, idx)] * np.outer(s_free, s_free)
    dirs, corr = _weak_directions(H, free_t)
    n_sc = int(ev["scored"])
    wsum = float(ev["weight_sum"])
    dof = max(n_sc - len(free_t), 1)
    # Hessian of the regularisation in units of the cost's Hessian
    # (mn.precision: weight x C^-1 of the normalised objective cost / c0)
    P = 2.0 * mn.c0 * np.asarray(mn.precision, dtype=float)
    cov = np.full((len(free_t), len(free_t)), np.nan)
    inner = np.array([lo[i] + 1e-6 < x[i] < hi[i] - 1e-6 for i in range(len(free_t))])
    ii = np.ix_(inner, inner)
    try:
        if uncertainty == "gauss-newton":
            sigma2 = float(ev["cost"]) * wsum / dof if loss == "squared" else float(sse.sum()) / dof
            cov[ii] = 2.0 * sigma2 / wsum * np.linalg.inv((H + P)[ii])
        elif uncertainty == "sandwich":
            G = train.maneuver_gradients(ev)[:, idx] * s_free
            cov[ii] = sandwich(np.linalg.inv((H + P)[ii] * wsum), G[:, inner])
    except np.linalg.LinAlgError:
        notes.append("Gauss-Newton matrix singular: standard errors not available")
    if uncertainty == "bootstrap":
        if refit is not None and len(train.maneuvers) >= 2:
            samples = [np.log([getattr(refit(ms), n) for n in free_t])
                       for ms in resampled(train.maneuvers, n_bootstrap, seed)]
            cov = np.atleast_2d(np.cov(np.array(samples).T, ddof=1))
        else:
            notes.append("bootstrap needs two or more training maneuvers")
    stderr_log = np.sqrt(np.abs(np.diag(cov)))
    if uncertainty != "bootstrap":
        stderr_log[~inner] = np.nan
    if np.all(np.isfinite(cov[ii])) and inner.any():
        s = np.sqrt(np.maximum(np.diag(cov), 1e-300))
        corr = np.where(np.outer(inner, inner), cov / np.outer(s, s), np.nan)

    for ratio, weights in dirs:
        if ratio < 1e-10:
            notes.append(
                f"not identifiable from these data: {_combination_text(weights)} "
                f"(the scale-free Gauss-Newton matrix is singular along it, eigenvalue "
                f"{ratio:.1e} of the largest)"
            )
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
                notes.append(
                    f"weakly identifiable: {_combination_text(weights)} is determined "
                    f"only to +-{100 * sd:.0f} % (one standard error)"
                )
    for i in range(len(free_t)):
        for j in range(i + 1, len(free_t)):
            if np.isfinite(corr[i, j]) and abs(corr[i, j]) > 0.99:
                c = -cov[i, j] / cov[j, j]
                sd = math.sqrt(max(cov[i, i] + 2 * c * cov[i, j] + c * c * cov[j, j], 0.0))
                notes.append(
                    f"{free_t[i]} and {free_t[j]} are strongly correlated "
                    f"({corr[i, j]:+.3f}): {free_t[i]} * {free_t[j]}^{c:.2g} is "
                    f"determined to +-{100 * sd:.2g} %, {free_t[i]} alone to "
                    f"+-{100 * stderr_log[i]:.2g} %"
                )
    return stderr_log, corr, tuple(weak), notes


def sandwich(Hi: np.ndarray, G: np.ndarray) -> np.ndarray:
    """H^-1 (sum_m g_m g_m^T) H^-1 M / (M - 1): the covariance clustered by maneuver, from the
    inverse Hessian ``Hi`` and the per-maneuver gradients ``G`` (M x k)."""
    M = G.shape[0]
    return Hi @ (G.T @ G) @ Hi * (M / max(M - 1, 1))


def resampled(maneuvers: Sequence, n_bootstrap: int, seed: int):
    """The bootstrap's training sets: ``n_bootstrap`` draws of as many maneuvers with
    replacement (numpy's default_rng(seed + 1))."""
    rng = np.random.default_rng(seed + 1)
    for _ in range(int(n_bootstrap)):
        yield [maneuvers[i] for i in rng.integers(0, len(maneuvers), size=len(maneuvers))]


def _positive_definite(H: np.ndarray) -> bool:
    """Positive diagonal and scale-free eigenvalues above 1e-8 of the largest (empty: True)."""
    if H.size == 0:
        return True
    dg = np.diag(H)
    if not np.all(dg > 0.0):
        return False
    d = np.sqrt(dg)
    lam = np.linalg.eigvalsh(H / np.outer(d, d))
    return bool(lam.min() > 1e-8 * max(lam.max(), 1e-300))


def finite_difference_covariance(problem, at, steps, *, loss: str, uncertainty: str,
                                 samples=None, known=None):
    """Covariance of coordinates ``u`` (a point ``at(u)`` -> ContactParams of the problem,
    u = 0 the estimate) of eq. 32 where the C++ derivatives cover only the first ones (the
    refitted model parameters, in log) and the others (the Stribeck curve's ln(static_ratio -
    1) and ln stribeck_speed) are varied by central differences with ``steps`` (NaN: the
    coordinate is not used, at a bound).

    ``known(ev, params)`` -> (H, G, g): from a C++ evaluation with derivatives, the
    Gauss-Newton block of L (the weighted loss sum, cost x weight sum) over the first
    ``len(H)`` coordinates, their per-maneuver gradients (M x k) and the gradient of L. The
    curve's block of the Hessian comes from second differences of L, its cross terms with the
    first coordinates from central differences of their gradient g, its per-maneuver
    gradients from central differences of each maneuver's part of L. Then

    * "sandwich": H^-1 (sum_m g_m g_m^T) H^-1 M / (M - 1) (clustered by maneuver);
    * "gauss-newton": 2 sigma^2 H^-1, sigma^2 the residual variance (the main fit's formula);
    * "bootstrap": the covariance of ``samples`` (coordinates of refits on resampled
      maneuvers), nothing evaluated.

    Returns (cov, flat, evaluations, step): cov over all coordinates (NaN rows/columns for the
    coordinates not used and those along which H is not positive definite, the others
    conditional on those held), ``flat`` the indices found flat, the number of cost
    evaluations spent, and the Newton step from the point to the minimum of the cost's
    quadratic model along the differenced coordinates, the first ``len(H)`` held (NaN where
    not available: how far the fit stopped from it; the C++ gradient, not exact there, is
    not used)."""
    steps = np.asarray(steps, dtype=float)
    n = steps.size
    cov = np.full((n, n), np.nan)
    if uncertainty == "bootstrap":
        if samples is not None and len(samples) >= 2:
            s = np.asarray(samples, dtype=float)
            ok = np.all(np.isfinite(s), axis=0)
            cov[np.ix_(ok, ok)] = np.atleast_2d(np.cov(s[:, ok].T, ddof=1))
        return cov, (), 0, np.full(n, np.nan)
    owner = problem.segment_owner
    M = len(problem.maneuvers)
    count = [0]

    def ev(u):
        count[0] += 1
        try:
            q = at(np.asarray(u, dtype=float))
            e = problem.evaluate(q, True)
        except ValueError:  # outside the parameters' valid ranges
            return None
        per = np.bincount(owner, weights=np.asarray(e["segment_loss"]), minlength=M)
        return (float(e["cost"]) * float(e["weight_sum"]), per, float(np.sum(e["segment_sse"])),
                int(e["scored"]), known(e, q))

    base = ev(np.zeros(n))
    L0, _, sse0, scored, (Hk, Gk, _) = base
    k = Hk.shape[0]
    H = np.zeros((n, n))
    G = np.zeros((M, n))
    H[:k, :k], G[:, :k] = Hk, Gk
    plus, minus = {}, {}
    bad: list[int] = [j for j in range(n) if not math.isfinite(steps[j])]
    for j in range(k, n):
        if j in bad:
            continue
        e = np.zeros(n)
        e[j] = steps[j]
        plus[j], minus[j] = ev(e), ev(-e)
        if plus[j] is None or minus[j] is None:
            bad.append(j)
            continue
        H[j, j] = (plus[j][0] + minus[j][0] - 2.0 * L0) / steps[j] ** 2
        G[:, j] = (plus[j][1] - minus[j][1]) / (2.0 * steps[j])
        H[:k, j] = H[j, :k] = (plus[j][4][2] - minus[j][4][2]) / (2.0 * steps[j])
    var = [j for j in range(k, n) if j not in bad]
    for a, j in enumerate(var):
        for i in var[a + 1:]:
            e = np.zeros(n)
            e[j], e[i] = steps[j], steps[i]
            pp, mm = ev(e), ev(-e)
            if pp is None or mm is None:
                H[j, i] = H[i, j] = math.nan
                continue
            H[j, i] = H[i, j] = (pp[0] - plus[j][0] - plus[i][0] + 2.0 * L0 - minus[j][0]
                                 - minus[i][0] + mm[0]) / (2.0 * steps[j] * steps[i])
    keep = [j for j in range(n) if j not in bad]
    flat = [j for j in range(k, n) if j in bad and math.isfinite(steps[j])]
    keep = [j for j in keep if np.all(np.isfinite(H[j, keep])) and np.all(np.isfinite(G[:, j]))]
    while keep:  # drop the coordinate that carries the weakest non-positive direction,
        # a differenced one first (the first block is a Gauss-Newton matrix, positive
        # semi-definite by construction)
        Hs = H[np.ix_(keep, keep)]
        if _positive_definite(Hs):
            break
        d = np.sqrt(np.maximum(np.abs(np.diag(Hs)), 1e-300))
        lam, vec = np.linalg.eigh(Hs / np.outer(d, d))
        weight = np.abs(vec[:, int(np.argmin(lam))])
        own = np.array([j >= k for j in keep])  # the differenced coordinates
        if own.any() and _positive_definite(Hs[np.ix_(~own, ~own)]):
            weight = np.where(own, weight, -1.0)
        worst = keep[int(np.argmax(weight))]
        keep.remove(worst)
        flat.append(worst)
    step = np.full(n, np.nan)
    if not keep:
        return cov, tuple(flat), count[0], step
    kk = np.ix_(keep, keep)
    Hi = np.linalg.inv(H[kk])
    var_kept = [j for j in var if j in keep]
    if var_kept:  # along the differenced coordinates, the others held (no C++ gradient in it)
        vv = np.ix_(var_kept, var_kept)
        step[var_kept] = -np.linalg.solve(H[vv], G[:, var_kept].sum(axis=0))
    if uncertainty == "gauss-newton":
        dof = max(scored - len(keep), 1)
        sigma2 = L0 / dof if loss == "squared" else sse0 / dof
        cov[kk] = 2.0 * sigma2 * Hi
    else:
        cov[kk] = sandwich(Hi, G[:, keep])
    return cov, tuple(flat), count[0], step
