#!/usr/bin/env python3
"""Plain numpy/scipy reference implementation of what lugrip's core computes, for timing.

Written as a user would write it with scipy (it does not import lugrip):

* ``ls_quad(a, k)``: the normalized limit-surface curves at one c~ by nested
  ``scipy.integrate.quad`` (docs/model.md 3.3, method A: CoR-centred chords, the inner chord integral
  with the algebraic rim weight (QAWS, ``weight='alg'``), the outer angle integral adaptive).
  Baseline for lugrip's LS evaluation and, over a table grid, for its construction.
* ``LsTable``: F and T by quad on the grid docs/model.md 3.3 recommends (step 0.01 on [0, 3],
  0.05 on [3, 20]) and one ``scipy.interpolate.CubicSpline`` through both curves, with the
  asymptotics of 3.2 beyond 20. Built once; this is the LS the CoR baseline uses, so the CoR
  baseline is a fair, fast one: no quadrature per sample.
* ``estimate_cor(...)``: one sample, docs/model.md 5.2-5.7: sigma (14), ``scipy.optimize.brentq``
  on F^(g+1) - sigma T = 0, the inside test (15), ``brentq`` on the outside equation
  h(a) = f - F - 2 xi a (t - T) on [0, c_max], sign rule, saturation, then c, g, sigma_1, y.
* ``estimate_cor_numpy(...)``: the same, vectorized over samples with numpy (bisection on the
  spline, 60 halvings): the baseline for the vectorized Python path.

Per-call timings use ``time.perf_counter_ns`` around every call (the calls take microseconds,
the clock ~0.1 us), with the cyclic garbage collector disabled while timing, as ``timeit`` does. Run ``python benchmarks/scipy_baseline.py [--quick] [--json]``; the
benchmark driver is run_benchmarks.py.
"""

from __future__ import annotations

import argparse
import gc
import json
import math
import sys
import time

import numpy as np
from scipy import integrate, interpolate, optimize, special

# --- the contact presets (paper Table 1; Table 2 changes mu and beta_A) -------------------------
TABLE1 = {
    "mu": 0.47,
    "beta_a": 4.9e9,
    "sigma0": 16.66,
    "sigma_z": 2.0,
    "delta": 0.0018,
    "gamma": 0.254,
    "k": 4.0,
    "c_max": 1.5,
}
OBJECTS = {"table1": TABLE1, "big_resin_block": dict(TABLE1, mu=0.85, beta_a=1.24e7)}


# --- limit surface by quadrature -------------------------------------------------------------------
class Shape:
    """Normalization constants of the pressure p = (1 - r^k)^(1/k) (docs/model.md 2.2-2.3, 3.2)."""

    def __init__(self, k: float):
        self.k = k
        if math.isinf(k):
            self.P, self.M, self.xi = math.pi, 2 * math.pi / 3, 2 / 3
            self.A_f, self.A_tau = 1 / 8, 3 / 8
        else:
            b = [special.beta(j / k, 1 + 1 / k) for j in (1, 2, 3, 4)]
            self.P, self.M = 2 * math.pi / k * b[1], 2 * math.pi / k * b[2]
            self.xi = b[2] / b[1]
            self.A_f, self.A_tau = b[3] / (4 * b[1]), b[3] / (2 * b[2])


def _h(u, k):
    """(1 - u^(k/2)) / (1 - u): smooth factor of 1 - r^k = (1 - r^2) h(r^2)."""
    if math.isinf(k):
        return 1.0
    om = 1.0 - u
    return k / 2 if om < 1e-12 else -math.expm1(k / 2 * math.log(u)) / om if u > 0 else 1.0


def ls_quad(a: float, k: float = 4.0, shape: Shape | None = None, eps: float = 1.49e-8):
    """(F, T) = (|f~*_tLS|, tau~*_LS) at a = |c~| by nested quad (method A)."""
    sh = shape or Shape(k)
    a = abs(a)
    if a == 0.0:
        return 0.0, 1.0
    inv_k = 0.0 if math.isinf(k) else 1.0 / k

    def chord(phi, m):
        # A_m(phi) = int p(|C + s e_phi|) s^m ds over the chord, rim factor in the QAWS weight
        c, s_ = math.cos(phi), math.sin(phi)
        disc = 1.0 - a * a * s_ * s_
        if disc <= 0.0:
            return 0.0
        root = math.sqrt(disc)
        sp, sm = -a * c + root, -a * c - root
        lo = 0.0 if a < 1.0 else sm
        if sp <= lo:
            return 0.0

        def f(s):
            r2 = a * a + 2 * a * s * c + s * s
            smooth = (s - sm) ** inv_k if a < 1.0 else 1.0  # the (s - s_-) factor off the chord end
            return smooth * _h(min(max(r2, 0.0), 1.0), k) ** inv_k * s**m

        w = (0.0, inv_k) if a < 1.0 else (inv_k, inv_k)
        if inv_k == 0.0:
            return integrate.quad(f, lo, sp, epsabs=eps, epsrel=eps, limit=200)[0]
        return integrate.quad(f, lo, sp, weight="alg", wvar=w, epsabs=eps, epsrel=eps, limit=200)[0]

    if a < 1.0:
        lo, hi = 0.0, math.pi
    else:  # only rays back through the disc: |sin phi| <= 1/a, cos phi < 0
        lo, hi = math.pi - math.asin(1.0 / a), math.pi
    opts = {"epsabs": eps, "epsrel": eps, "limit": 200}
    i1 = integrate.quad(lambda p: math.cos(p) * chord(p, 1), lo, hi, **opts)[0]
    i2 = integrate.quad(lambda p: chord(p, 2), lo, hi, **opts)[0]
    # phi in [0, pi], doubled for the symmetry phi -> -phi; F = -f~* > 0 for c~ > 0
    F = -2.0 * i1 / sh.P
    T = 2.0 * (i2 + a * i1) / sh.M
    return F, T


def table_grid(coarse: bool = False):
    """docs/model.md 3.3 grid: step 0.01 on [0, 3] (node 1.0 included), 0.05 on [3, 20]; 641 nodes.
    coarse (for --quick): steps 0.05 and 0.5, 95 nodes."""
    if coarse:
        return np.concatenate([np.linspace(0.0, 3.0, 61), np.linspace(3.5, 20.0, 34)])
    return np.concatenate([np.linspace(0.0, 3.0, 301), np.linspace(3.05, 20.0, 340)])


class LsTable:
    """F, T tabulated by quad on the docs/model.md 3.3 grid, one CubicSpline, asymptotic tails."""

    def __init__(self, k: float = 4.0, grid=None):
        self.shape = sh = Shape(k)
        self.grid = table_grid() if grid is None else np.asarray(grid)
        vals = np.array([ls_quad(a, k, sh) for a in self.grid])
        self.spline = interpolate.CubicSpline(self.grid, vals, axis=0)
        self.a_end = float(self.grid[-1])

    def __call__(self, a: float):
        if a > self.a_end:
            return 1.0 - self.shape.A_f / (a * a), self.shape.A_tau / a
        F, T = self.spline(a)
        return float(F), float(T)

    def vec(self, a: np.ndarray):
        a = np.asarray(a, dtype=float)
        tab = self.spline(np.minimum(a, self.a_end))
        far = a > self.a_end
        safe = np.where(far, a, 1.0)
        F = np.where(far, 1.0 - self.shape.A_f / safe**2, tab[..., 0])
        T = np.where(far, self.shape.A_tau / safe, tab[..., 1])
        return F, T


# --- CoR estimation, one sample (docs/model.md 5.7) -----------------------------------------------------
def estimate_cor(p: dict, ls: LsTable, f_n: float, f_t: float, tau: float, prev: float = 0.0):
    """Returns (c_tilde, inside, c, g, sigma_1, y) for one sample; same thresholds as lugrip."""
    if not (math.isfinite(f_n) and math.isfinite(f_t) and math.isfinite(tau)) or f_n < 0.03:
        return prev, True, 0.0, 0.0, 0.0, 0.0
    mu, gamma, delta, c_max, xi = p["mu"], p["gamma"], p["delta"], p["c_max"], ls.shape.xi
    rho = delta * f_n**gamma
    ft_t = f_t / (mu * f_n)
    tau_t = tau / (mu * xi * rho * f_n)
    f, t = abs(ft_t), abs(tau_t)
    inside = True
    if f < 1e-4 and t < 1e-4:
        a, sign = abs(prev), (-1.0 if prev < 0 else 1.0)
    elif f < 1e-4:
        a, sign, inside = 0.0, 1.0, t < 1.0
    else:
        if t > 0.0:
            sigma = f ** (gamma + 1) / t

            def phi(x):
                F, T = ls(x)
                return F ** (gamma + 1) - sigma * T

            hi = 20.0 if phi(20.0) > 0 else 2.0 * sigma * ls.shape.A_tau + 20.0
            a_s = optimize.brentq(phi, 0.0, hi, xtol=1e-12, rtol=1e-12)
            F, T = ls(a_s)
            inside = f * f + t * t < F * F + T * T
        else:
            a_s, inside = math.inf, False
        if inside:
            a = a_s
        else:
            xi2 = 2.0 * xi

            def h(x):
                F, T = ls(x)
                return f - F - xi2 * x * (t - T)

            a = c_max if h(c_max) > 0.0 else optimize.brentq(h, 0.0, c_max, xtol=1e-13)
        if t < 1e-4:
            sign = -1.0 if prev < 0 else 1.0
        else:
            sign = -math.copysign(1.0, f_t) * math.copysign(1.0, tau)
    a = min(a, c_max)
    c_tilde = sign * a
    c = c_tilde * rho
    F, T = ls(a)
    g = mu * f_n * rho * (xi * T + a * F)
    sigma_1 = math.pi * p["beta_a"] * rho**4 * (c_tilde * c_tilde + 0.5)
    return c_tilde, inside, c, g, sigma_1, tau - c * f_t


def estimate_cor_numpy(p: dict, ls: LsTable, f_n, f_t, tau):
    """Vectorized version (valid samples only): bisection on the spline, 45 halvings (~1e-12, as brentq's xtol)."""
    mu, gamma, delta, c_max, xi = p["mu"], p["gamma"], p["delta"], p["c_max"], ls.shape.xi
    rho = delta * f_n**gamma
    f = np.abs(f_t / (mu * f_n))
    t = np.abs(tau / (mu * xi * rho * f_n))
    sigma = f ** (gamma + 1) / np.maximum(t, 1e-300)
    lo = np.zeros_like(f)
    hi = np.maximum(20.0, 2.0 * sigma * ls.shape.A_tau + 20.0)
    for _ in range(45):
        mid = 0.5 * (lo + hi)
        F, T = ls.vec(mid)
        pos = F ** (gamma + 1) - sigma * T > 0
        hi = np.where(pos, mid, hi)
        lo = np.where(pos, lo, mid)
    a_s = 0.5 * (lo + hi)
    F, T = ls.vec(a_s)
    inside = f * f + t * t < F * F + T * T
    lo, hi = np.zeros_like(f), np.full_like(f, c_max)
    for _ in range(45):
        mid = 0.5 * (lo + hi)
        F, T = ls.vec(mid)
        pos = f - F - 2 * xi * mid * (t - T) > 0
        lo = np.where(pos, mid, lo)
        hi = np.where(pos, hi, mid)
    a = np.minimum(np.where(inside, a_s, 0.5 * (lo + hi)), c_max)
    c_tilde = -np.sign(f_t) * np.sign(tau) * a
    return c_tilde, inside


# --- samples (same recipe as bench_core.cpp make_sample) -------------------------------------------
def make_samples(p: dict, ls: LsTable, n: int, rng: np.random.Generator):
    """f_n log-uniform [0.2, 16] N; a log-uniform [1e-2, 1e2]; 1/2 inside lambda*(F, T),
    lambda ~ U[0.05, 0.98]; 1/4 LS + viscous excess (F + 2 xi a nu, T + nu), nu log-uniform
    [1e-3, 1]; 1/4 radially outside lambda ~ U[1.02, 2]; random signs."""
    f_n = np.exp(rng.uniform(math.log(0.2), math.log(16.0), n))
    a = np.exp(rng.uniform(math.log(1e-2), math.log(1e2), n))
    F, T = ls.vec(a)
    kind = rng.uniform(size=n)
    lam_in = rng.uniform(0.05, 0.98, n)
    nu = np.exp(rng.uniform(math.log(1e-3), 0.0, n))
    lam_out = rng.uniform(1.02, 2.0, n)
    f = np.where(
        kind < 0.5, lam_in * F, np.where(kind < 0.75, F + 2 * ls.shape.xi * a * nu, lam_out * F)
    )
    t = np.where(kind < 0.5, lam_in * T, np.where(kind < 0.75, T + nu, lam_out * T))
    sf = np.where(rng.uniform(size=n) < 0.5, -1.0, 1.0)
    st = np.where(rng.uniform(size=n) < 0.5, -1.0, 1.0)
    tau_max = p["mu"] * ls.shape.xi * p["delta"] * f_n ** (p["gamma"] + 1)
    return f_n, sf * f * p["mu"] * f_n, st * t * tau_max


# --- timing -----------------------------------------------------------------------------------------
def stats(ns) -> dict:
    v = np.sort(np.asarray(ns, dtype=float))
    return {
        "median_ns": float(np.median(v)),
        "p99_ns": float(np.percentile(v, 99)),
        "worst_ns": float(v[-1]),
        "mean_ns": float(v.mean()),
        "best_ns": float(v[0]),
        "calls": int(v.size),
    }


def time_calls(fn, args_list):
    """Times every call alone; the cyclic garbage collector is off meanwhile (as in timeit)."""
    out, ns = [], []
    clock = time.perf_counter_ns
    gc_was_on = gc.isenabled()
    gc.disable()
    try:
        for args in args_list:
            t0 = clock()
            r = fn(*args)
            ns.append(clock() - t0)
            out.append(r)
    finally:
        if gc_was_on:
            gc.enable()
    return out, ns


def run(quick: bool = False, seed: int = 20240521, log=lambda *a: None) -> dict:
    rng = np.random.default_rng(seed)
    res = {"tool": "scipy_baseline", "quick": quick, "seed": seed, "results": []}
    k = 4.0
    sh = Shape(k)

    # (a) LS at one c~ by nested quad
    n_q = 8 if quick else 30
    for name, pts in (
        (
            "quad, c~ log-uniform [1e-3,1e3]",
            np.exp(rng.uniform(math.log(1e-3), math.log(1e3), n_q)),
        ),
        ("quad, c~ uniform [0,3]", rng.uniform(0.0, 3.0, n_q)),
    ):
        log(f"  ls {name}")
        vals, ns = time_calls(lambda a: ls_quad(a, k, sh), [(a,) for a in pts])
        res["results"].append(
            {
                "group": "ls_eval",
                "name": name,
                "method": "nested scipy.integrate.quad",
                "stats": stats(ns),
                "c_tilde": [float(a) for a in pts],
                "F": [v[0] for v in vals],
                "T": [v[1] for v in vals],
            }
        )

    # (c) construction: quad on the table grid + CubicSpline (--quick: coarse grid, extrapolated)
    log("  ls table (construction)")
    grid, n_full = table_grid(coarse=quick), len(table_grid())
    t0 = time.perf_counter()
    table = LsTable(k, grid=grid)
    ms = (time.perf_counter() - t0) * 1e3 * n_full / len(grid)
    how = (
        f"quad at {n_full} grid points + CubicSpline, one build"
        if not quick
        else f"extrapolated to {n_full} points from a {len(grid)}-point build"
    )
    res["results"].append(
        {
            "group": "construct",
            "name": "LsTable(k=4)",
            "unit": "ms",
            "method": how,
            "stats": {"median_ms": ms, "p99_ms": ms, "worst_ms": ms, "mean_ms": ms, "calls": 1},
        }
    )

    # (a') LS from the table: one scalar CubicSpline call (F and T together)
    pts = list(np.exp(rng.uniform(math.log(1e-3), math.log(1e3), 2000 if quick else 20000)))
    _, ns = time_calls(table, [(a,) for a in pts])
    res["results"].append(
        {
            "group": "ls_eval",
            "name": "CubicSpline table, log-uniform",
            "method": "scalar CubicSpline call, F and T together",
            "stats": stats(ns),
        }
    )
    pts = list(rng.uniform(0.0, 3.0, 2000 if quick else 20000))
    _, ns = time_calls(table, [(a,) for a in pts])
    res["results"].append(
        {
            "group": "ls_eval",
            "name": "CubicSpline table, uniform [0,3]",
            "method": "scalar CubicSpline call, F and T together",
            "stats": stats(ns),
        }
    )

    # (b) CoR per sample with brentq, and vectorized numpy
    n_cor = 600 if quick else 5000
    res["samples"] = {}
    for obj, p in OBJECTS.items():
        log(f"  cor {obj}")
        f_n, f_t, tau = make_samples(p, table, n_cor, rng)
        args = [(p, table, float(a), float(b), float(c)) for a, b, c in zip(f_n, f_t, tau)]
        out, ns = time_calls(estimate_cor, args)
        ns = np.asarray(ns)
        inside = np.array([o[1] for o in out])
        for label, mask in (
            ("inside LS", inside),
            ("outside LS", ~inside),
            ("all", np.ones_like(inside)),
        ):
            res["results"].append(
                {
                    "group": "cor_step",
                    "name": f"{obj}: {label}",
                    "method": "brentq on the CubicSpline table",
                    "inside_fraction": float(inside[mask].mean()),
                    "stats": stats(ns[mask]),
                }
            )
        res["samples"][obj] = {
            "f_n": f_n.tolist(),
            "f_t": f_t.tolist(),
            "tau": tau.tolist(),
            "c_tilde": [o[0] for o in out],
            "inside": inside.tolist(),
        }
        # vectorized
        n_vec = 20000 if quick else 100000
        fv, ftv, tv = make_samples(p, table, n_vec, rng)
        reps = []
        for _ in range(2 if quick else 5):
            t0 = time.perf_counter_ns()
            estimate_cor_numpy(p, table, fv, ftv, tv)
            reps.append((time.perf_counter_ns() - t0) / n_vec)
        res["results"].append(
            {
                "group": "cor_vectorized",
                "name": f"{obj}: numpy bisection, {n_vec} samples",
                "method": "vectorized numpy bisection on the CubicSpline table (per sample)",
                "stats": stats(reps),
            }
        )
    res["_table"] = table  # reused by run_benchmarks.py (not JSON)
    return res


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--seed", type=int, default=20240521)
    args = ap.parse_args(argv)
    res = run(args.quick, args.seed, log=lambda *a: print(*a, file=sys.stderr))
    res.pop("samples", None)
    res.pop("_table", None)
    for r in res["results"]:
        for key in ("c_tilde", "F", "T"):
            r.pop(key, None)
    if args.json:
        json.dump(res, sys.stdout, indent=1)
        print()
    else:
        for r in res["results"]:
            s = r["stats"]
            unit = "ms" if "median_ms" in s else "ns"
            print(
                f"{r['group']:15s} {r['name']:45s} median {s['median_' + unit]:12.1f} {unit}  "
                f"p99 {s['p99_' + unit]:12.1f}  worst {s['worst_' + unit]:12.1f}"
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
