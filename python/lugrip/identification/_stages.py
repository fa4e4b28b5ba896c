"""The staged estimate: each parameter group from what the data physically carry
(docs/model.md §8).

(a) limit surface and (c) viscous shear, from the gross-sliding samples: per run and speed
    bin the mean wrench (f_n, f_t, |tau|) and the mean |omega| give one point. In normalised
    coordinates (f_t / (mu f_n), |tau| / tau_max(f_n)) a sliding point lies on the limit
    surface shifted by the viscous part, (F(a) + 2 xi a lam, T(a) + lam) with
    lam = K |omega| / (2 xi), K = pi delta^3 beta_A f_n^(3 gamma - 1) / mu (eqs. 9-10). The
    fit minimises each point's distance to that curve (its CoR a is a nuisance, found per
    point) over mu, delta, gamma, the pressure exponent k (through 1/k in [0, 2]: k in
    [0.5, inf]) and kappa = pi delta^3 beta_A / mu >= 0; or, with k = 0, on the elliptic
    limit surface (a point contact on an elliptic friction cone), a shape with no free
    parameter. Standard errors: sandwich, clustered by maneuver.
(b) sigma0, sigma_z from the loading runs: the bristle state is integrated along the
    prescribed motion (eq. 1 with the ground-truth omega) and sigma0 z + sigma_z dz/dt +
    sigma_1 omega is fitted to y = tau - c f_t from the CoR estimate at the stage (a) values.
"""

from __future__ import annotations

import dataclasses
import functools
import math

import numpy as np

from .. import _core
from .._contact import estimate_cor
from .._params import ContactParams
from ._data import _Maneuver
from ._phases import LOADING, SLIDING, runs

__all__ = [
    "LimitSurfaceFit",
    "PreslidingFit",
    "SlidingPoints",
    "fit_limit_surface",
    "fit_presliding",
    "sliding_points",
]

_INV_K = np.linspace(0.0, 2.0, 21)  # table nodes of 1/k (k = inf .. 0.5)
_A = np.concatenate([[0.0], np.geomspace(1e-3, 400.0, 500)])  # |c~| nodes
_FLOOR = 0.01  # model error of a normalised point (1 % of the capacity) [-]


@functools.lru_cache(maxsize=1)
def _tables():
    F = np.empty((_INV_K.size, _A.size))
    T = np.empty_like(F)
    xi = np.empty(_INV_K.size)
    for j, ik in enumerate(_INV_K):
        # 16 quadrature intervals: the curves agree with the default tables to ~1e-8
        ls = _core.LimitSurface(math.inf if ik == 0.0 else 1.0 / ik, 16)
        F[j] = np.abs(np.asarray(ls.ft_star(_A)))
        T[j] = np.asarray(ls.tau_star(_A))
        xi[j] = ls.xi
    return F, T, xi


def _curves(inv_k: float):
    F, T, xi = _tables()
    x = float(np.clip(inv_k, 0.0, 2.0)) / (_INV_K[1] - _INV_K[0])
    j = min(int(x), _INV_K.size - 2)
    w = x - j
    return (
        (1 - w) * F[j] + w * F[j + 1],
        (1 - w) * T[j] + w * T[j + 1],
        (1 - w) * xi[j] + w * xi[j + 1],
    )


@functools.lru_cache(maxsize=1)
def _ellipse_curves():
    ls = _core.LimitSurface(ELLIPSE_K)
    return np.abs(np.asarray(ls.ft_star(_A))), np.asarray(ls.tau_star(_A)), float(ls.xi)


ELLIPSE_K = 0.0  # ContactParams.k of the elliptic limit surface


def k_of(inv_k: float) -> float:
    if math.isnan(inv_k):  # the ellipse (no pressure exponent)
        return ELLIPSE_K
    return math.inf if inv_k <= 1e-9 else 1.0 / inv_k


@dataclasses.dataclass(frozen=True)
class SlidingPoints:
    """Mean gross-sliding wrench per run and speed bin (arrays of equal length).

    Attributes:
        f_n, f_t, tau_abs: mean normal force [N], in-plane force magnitude [N], |mean tau| [N m].
        omega_abs: mean |omega| [rad/s]; samples: samples averaged; maneuver: index into the
            maneuvers (the cluster of the standard errors).
    """

    f_n: np.ndarray
    f_t: np.ndarray
    tau_abs: np.ndarray
    omega_abs: np.ndarray
    samples: np.ndarray
    maneuver: np.ndarray

    def __len__(self) -> int:
        return int(self.f_n.size)


def sliding_points(mans: list[_Maneuver], phases: list[np.ndarray], bins: int = 3) -> SlidingPoints:
    """Average the gross-sliding samples of every run, split into up to ``bins`` bins of
    |omega| when the run's speed varies by more than 30 %."""
    cols = {k: [] for k in ("f_n", "f_t", "tau_abs", "omega_abs", "samples", "maneuver")}
    for i, (m, ph) in enumerate(zip(mans, phases)):
        for a, b in runs(m):
            idx = np.arange(a, b)[ph[a:b] == SLIDING]
            if idx.size < 5:
                continue
            w = np.abs(m.omega[idx])
            nb = bins if w.max() > 1.3 * max(w.min(), 1e-12) and idx.size >= 5 * bins else 1
            edges = np.quantile(w, np.linspace(0, 1, nb + 1))
            which = np.clip(np.searchsorted(edges, w, side="right") - 1, 0, nb - 1)
            for k in range(nb):
                sel = idx[which == k]
                if sel.size < 3:
                    continue
                if m.f_x is not None:
                    f_t = math.hypot(float(np.mean(m.f_x[sel])), float(np.mean(m.f_y[sel])))
                else:
                    f_t = float(np.mean(m.f_t[sel]))
                cols["f_n"].append(float(np.mean(m.f_n[sel])))
                cols["f_t"].append(f_t)
                cols["tau_abs"].append(abs(float(np.mean(m.tau[sel]))))
                cols["omega_abs"].append(float(np.mean(np.abs(m.omega[sel]))))
                cols["samples"].append(int(sel.size))
                cols["maneuver"].append(i)
    return SlidingPoints(
        **{
            k: np.asarray(v, dtype=float if k not in ("samples", "maneuver") else np.int64)
            for k, v in cols.items()
        }
    )


_COARSE = np.unique(np.concatenate([[0], np.round(np.geomspace(1, _A.size - 1, 320)).astype(int)]))


def _nearest(ft, tt, lam, F, T, xi):
    """Per point the CoR a on the (shifted) curve nearest to the point, and the residuals:
    a search on a coarse subset of the table, then a parabola through the three nodes around
    the best one, the curve evaluated on the full table at the result."""
    A, Fc, Tc = _A[_COARSE], F[_COARSE], T[_COARSE]
    df = ft[:, None] - Fc[None, :] - 2.0 * xi * A[None, :] * lam[:, None]
    dtt = tt[:, None] - Tc[None, :] - lam[:, None]
    d2 = df * df + dtt * dtt
    j = np.argmin(d2, axis=1)
    jj = np.clip(j, 1, A.size - 2)
    r = np.arange(ft.size)
    x0, x1, x2 = A[jj - 1], A[jj], A[jj + 1]
    y0, y1, y2 = d2[r, jj - 1], d2[r, jj], d2[r, jj + 1]
    den = (x0 - x1) * (x0 - x2) * (x1 - x2)
    A2 = x2 * (y1 - y0) + x1 * (y0 - y2) + x0 * (y2 - y1)
    B2 = x2 * x2 * (y0 - y1) + x1 * x1 * (y2 - y0) + x0 * x0 * (y1 - y2)
    with np.errstate(divide="ignore", invalid="ignore"):
        a = np.where((A2 / den) > 0, -B2 / (2.0 * A2), x1)
    a = np.clip(np.where(np.isfinite(a), a, x1), x0, x2)
    Fa, Ta = np.interp(a, _A, F), np.interp(a, _A, T)
    return a, ft - Fa - 2.0 * xi * a * lam, tt - Ta - lam


@dataclasses.dataclass(frozen=True)
class LimitSurfaceFit:
    """Stage (a)+(c) result.

    Attributes:
        mu, delta, gamma, k: limit-surface parameters (k = 0: the elliptic limit surface,
            ``elliptic``); kappa: pi delta^3 beta_A / mu [s/rad
            N^(1-3 gamma)]; beta_a: kappa mu / (pi delta^3) [N s/m^3].
        stderr: sandwich standard errors {mu, delta, gamma, inv_k, kappa, beta_a}.
        free: fitted among ("mu", "delta", "gamma", "inv_k", "kappa").
        at_bound: names of fitted parameters that ended at a bound (kappa = 0 is not one:
            it is "no viscous excess").
        points: the sliding points; c_abs: their fitted |c~|; residual_rms: RMS of the
            normalised distances; rms_zero_viscous: the same refitted with kappa = 0.
        viscous_t: kappa / stderr (NaN without a speed term).
        shape_rms: RMS distance of every limit-surface shape tried by the selection
            ({"pressure": ..., "ellipse": ...}; empty when the shape was given).
    """

    mu: float
    delta: float
    gamma: float
    k: float
    kappa: float
    beta_a: float
    stderr: dict
    free: tuple
    at_bound: tuple
    points: SlidingPoints
    c_abs: np.ndarray
    residual_rms: float
    viscous_t: float
    xi: float
    cov: (
        np.ndarray
    )  # sandwich covariance of the fitted variables (ln mu, ln delta, gamma, 1/k, kappa)
    shape_rms: dict = dataclasses.field(default_factory=dict)

    @property
    def elliptic(self) -> bool:
        return self.k == ELLIPSE_K

    def tau_max(self, f_n) -> np.ndarray:
        return self.mu * self.xi * self.delta * np.asarray(f_n, float) ** (1.0 + self.gamma)


_LO = {"mu": math.log(0.05), "delta": math.log(1e-4), "gamma": 0.0, "inv_k": 0.0, "kappa": 0.0}
_HI = {
    "mu": math.log(2.0),
    "delta": math.log(1e-2),
    "gamma": 1.0 / 3.0,
    "inv_k": 2.0,
    "kappa": np.inf,
}


def fit_limit_surface(
    pts: SlidingPoints,
    *,
    gamma: float | None = None,
    k: float | None = None,
    viscous: bool = True,
    delta: float | None = None,
) -> LimitSurfaceFit:
    """Fit stage (a) (and (c) with ``viscous``) to the sliding points. ``gamma`` / ``k`` /
    ``delta`` given: held at that value (k = 0: the elliptic limit surface)."""
    from scipy.optimize import least_squares  # on first fit: `import lugrip` stays light

    if len(pts) < 3:
        raise ValueError("fewer than 3 gross-sliding points")
    elliptic = k is not None and k == ELLIPSE_K
    curves = (lambda _ik: _ellipse_curves()) if elliptic else _curves
    names = (
        ["mu"]
        + (["delta"] if delta is None else [])
        + (["gamma"] if gamma is None else [])
        + (["inv_k"] if k is None else [])
        + (["kappa"] if viscous else [])
    )
    fixed = {
        "delta": delta,
        "gamma": gamma,
        "inv_k": None if k is None else (math.nan if elliptic else (0.0 if math.isinf(k) else 1.0 / k)),
        "kappa": 0.0,
    }
    fn, ft_raw, tau, w = pts.f_n, pts.f_t, pts.tau_abs, pts.omega_abs

    def unpack(x):
        d = dict(zip(names, x))
        mu = math.exp(d["mu"])
        delta = math.exp(d["delta"]) if "delta" in d else fixed["delta"]
        g_ = d.get("gamma", fixed["gamma"])
        ik = d.get("inv_k", fixed["inv_k"])
        kap = d.get("kappa", fixed["kappa"])
        return mu, delta, g_, ik, kap

    def resid(x):
        mu, delta, g_, ik, kap = unpack(x)
        F, T, xi = curves(ik)
        ft = ft_raw / (mu * fn)
        tt = tau / (mu * xi * delta * fn ** (1.0 + g_))
        lam = kap * fn ** (3.0 * g_ - 1.0) * w / (2.0 * xi)
        _, r1, r2 = _nearest(ft, tt, lam, F, T, xi)
        return np.concatenate([r1, r2]) / _FLOOR

    g0 = 0.2 if gamma is None else gamma
    mu0 = float(np.percentile(ft_raw / fn, 90))
    xi0 = curves(0.25)[2]
    d0 = float(np.percentile(tau / (mu0 * xi0 * fn ** (1.0 + g0)), 90))
    d0 = min(max(d0, 2e-4), 5e-3)
    best = None
    for ik0 in (0.25, 1.0) if k is None else (None,):
        x0 = []
        for n in names:
            x0.append(
                {
                    "mu": math.log(min(max(mu0, 0.06), 1.9)),
                    "delta": math.log(d0),
                    "gamma": g0,
                    "inv_k": ik0,
                    "kappa": 0.0,
                }[n]
            )
        lo = [_LO[n] for n in names]
        hi = [_HI[n] for n in names]
        x0 = np.clip(x0, np.array(lo) + 1e-9, np.array(hi) - 1e-9)
        r = least_squares(resid, x0, bounds=(lo, hi), x_scale="jac", diff_step=1e-4, max_nfev=200)
        if best is None or r.cost < best.cost:
            best = r
    x = best.x
    mu, delta, g_, ik, kap = unpack(x)
    F, T, xi = curves(ik)
    # sandwich covariance clustered by maneuver
    J = best.jac
    res = best.fun
    n = len(pts)
    cl = np.concatenate([pts.maneuver, pts.maneuver])
    try:
        bread = np.linalg.pinv(J.T @ J)
        groups = np.unique(cl)
        meat = np.zeros((len(names), len(names)))
        for gidx in groups:
            s = cl == gidx
            u = J[s].T @ res[s]
            meat += np.outer(u, u)
        G = groups.size
        cov = bread @ meat @ bread * (G / max(G - 1, 1))
    except np.linalg.LinAlgError:
        cov = np.full((len(names), len(names)), np.nan)
    sd = dict(zip(names, np.sqrt(np.abs(np.diag(cov)))))
    stderr = {
        "mu": mu * sd.get("mu", math.nan),
        "delta": delta * sd.get("delta", math.nan),
        "gamma": sd.get("gamma", math.nan),
        "inv_k": sd.get("inv_k", math.nan),
        "kappa": sd.get("kappa", math.nan),
    }
    beta = kap * mu / (math.pi * delta**3)
    stderr["beta_a"] = stderr["kappa"] * mu / (math.pi * delta**3)
    at = []
    for i, nme in enumerate(names):
        if nme in ("kappa",):
            continue
        if nme == "inv_k" and x[i] <= 1e-6:
            continue  # k = inf: the uniform-pressure member, not a bound of the model
        if x[i] <= _LO[nme] + 1e-6 or x[i] >= _HI[nme] - 1e-6:
            at.append(nme if nme != "inv_k" else "k")
    ft = ft_raw / (mu * fn)
    tt = tau / (mu * xi * delta * fn ** (1.0 + g_))
    lam = kap * fn ** (3.0 * g_ - 1.0) * w / (2.0 * xi)
    a, r1, r2 = _nearest(ft, tt, lam, F, T, xi)
    return LimitSurfaceFit(
        mu=mu,
        delta=delta,
        gamma=float(g_),
        k=k_of(ik),
        kappa=float(kap),
        beta_a=float(beta),
        stderr=stderr,
        free=tuple(names),
        at_bound=tuple(at),
        points=pts,
        c_abs=a,
        residual_rms=float(np.sqrt(np.mean(np.concatenate([r1, r2]) ** 2))),
        viscous_t=(kap / stderr["kappa"]) if viscous and stderr["kappa"] > 0 else math.nan,
        xi=float(xi),
        cov=cov,
    )


@dataclasses.dataclass(frozen=True)
class PreslidingFit:
    """Stage (b) result: sigma0 [N m/rad], sigma_z [N m s/rad], their sandwich standard
    errors, the runs and samples used and the RMS of the normalised residual (y - y_model)/g."""

    sigma0: float
    sigma_z: float
    stderr: dict
    runs: int
    samples: int
    residual_rms: float


def fit_presliding(
    mans: list[_Maneuver],
    phases: list[np.ndarray],
    params: ContactParams,
    *,
    tail: int = 20,
    max_len: int = 400,
    max_runs: int = 60,
) -> PreslidingFit | None:
    """Fit sigma0 and sigma_z on the runs' loading samples (plus ``tail`` sliding samples; at
    most ``max_runs`` runs, evenly spread); None when no run has a loading phase of >= 3
    samples."""
    from scipy.optimize import least_squares  # on first fit: `import lugrip` stays light

    wins = []
    for i, (m, ph) in enumerate(zip(mans, phases)):
        for a, b in runs(m):
            load = np.flatnonzero(ph[a:b] == LOADING)
            if load.size < 3:
                continue
            slide = np.flatnonzero(ph[a:b] == SLIDING)
            end = a + (int(slide[0]) + tail if slide.size else b - a)
            end = min(end, b, a + max_len)
            # include the still sample before the run: the load it starts from
            a0 = max(a - 1, int(m.starts[np.searchsorted(m.starts, a, side="right") - 1]))
            sl = slice(a0, end)
            est = estimate_cor(params, m.f_n[sl], m.f_t[sl], m.tau[sl])
            if np.any(np.asarray(est.saturated, bool)[1:]):
                continue  # CoR clipped at c_max: y is not the torque about the true CoR
            wins.append(
                (
                    i,
                    np.nan_to_num(m.omega[sl]),
                    np.concatenate([[0.0], m.dt[a0 + 1 : end]]),
                    np.asarray(est.y, float),
                    np.asarray(est.g, float),
                    np.asarray(est.sigma_1, float),
                )
            )
    if not wins:
        return None
    if len(wins) > max_runs:  # evenly spread subset: two parameters need no more
        wins = [wins[i] for i in np.linspace(0, len(wins) - 1, max_runs).round().astype(int)]
    L = max(len(wv[1]) for wv in wins)
    R = len(wins)
    W = np.zeros((R, L))
    DT = np.zeros((R, L))
    Y = np.zeros((R, L))
    Gm = np.ones((R, L))
    S1 = np.zeros((R, L))
    mask = np.zeros((R, L), bool)
    for r, (_, w, dt, y, g_, s1) in enumerate(wins):
        n = len(w)
        W[r, :n], DT[r, :n], Y[r, :n], Gm[r, :n], S1[r, :n] = w, dt, y, g_, s1
        mask[r, 1:n] = True
    cluster = np.array([wv[0] for wv in wins])

    def model(s0, sz):
        z = np.clip(Y[:, 0] / s0, -Gm[:, 0] / s0, Gm[:, 0] / s0)
        out = np.zeros((R, L))
        zd_all = np.zeros((R, L))
        out[:, 0] = Y[:, 0]
        for n in range(1, L):
            wm = 0.5 * (W[:, n - 1] + W[:, n])
            zinf = np.sign(wm) * Gm[:, n] / s0
            e = np.exp(-s0 * np.abs(wm) * DT[:, n] / Gm[:, n])
            z = np.where(wm != 0, zinf + (z - zinf) * e, z)
            zd = W[:, n] - s0 * np.abs(W[:, n]) * z / Gm[:, n]
            zd_all[:, n] = zd
            out[:, n] = s0 * z + sz * zd + S1[:, n] * W[:, n]
        return out, zd_all

    def resid(x):
        out, _ = model(math.exp(x[0]), x[1])
        return ((Y - out) / Gm)[mask]

    # start: the stiffness that builds the capacity g over the slip angle of the loading
    # part (LuGre reaches 90 % of g after 2.3 g / sigma0)
    theta = np.cumsum(np.abs(W) * DT, axis=1)
    n_load = np.array([len(wv[1]) - 1 for wv in wins])
    th = theta[np.arange(R), n_load]
    ok = th > 0
    s0_0 = float(np.median(2.3 * Gm[np.arange(R), n_load][ok] / th[ok])) if ok.any() else 1.0
    best = None
    for f0 in (1.0,):
        for sz0 in (0.01 * s0_0 * f0,):
            r = least_squares(
                resid,
                [math.log(s0_0 * f0), sz0],
                bounds=([math.log(1e-3), 0.0], [math.log(1e4), np.inf]),
                x_scale="jac",
                diff_step=1e-4,
                max_nfev=40,
            )
            if best is None or r.cost < best.cost:
                best = r
    J, res = np.array(best.jac), best.fun
    # sigma_z enters linearly: its column exactly (a relative finite-difference step is
    # zero at sigma_z = 0, the bound where a contact without micro-damping ends)
    _, zd = model(math.exp(best.x[0]), best.x[1])
    J[:, 1] = -(zd / Gm)[mask]
    cl = np.broadcast_to(cluster[:, None], (R, L))[mask]
    bread = np.linalg.pinv(J.T @ J)
    meat = np.zeros((2, 2))
    groups = np.unique(cl)
    for gidx in groups:
        s = cl == gidx
        u = J[s].T @ res[s]
        meat += np.outer(u, u)
    cov = bread @ meat @ bread * (groups.size / max(groups.size - 1, 1))
    sd = np.sqrt(np.abs(np.diag(cov)))
    s0 = math.exp(best.x[0])
    return PreslidingFit(
        sigma0=s0,
        sigma_z=float(best.x[1]),
        stderr={"sigma0": s0 * float(sd[0]), "sigma_z": float(sd[1])},
        runs=R,
        samples=int(mask.sum()),
        residual_rms=float(np.sqrt(np.mean(res**2))),
    )
