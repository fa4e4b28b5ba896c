#!/usr/bin/env python3
"""Independent high-accuracy reference values of the normalized limit surface (docs/model.md 3).

Computes f~*_tLS(c~) and tau~*_LS(c~) for several pressure exponents k with SciPy, by a
method that shares nothing with the C++ core (which integrates CoR-centred chords with
Gauss-Jacobi rules built by its own Golub-Welsch solver):

* disc-centred polar coordinates (docs/model.md 3.3, method B): outer r in [0, 1] with a break
  point at r = |c~|, inner theta over the full circle;
* the inner theta integral is done in closed form with complete elliptic integrals. With
  d^2 = r^2 + c^2 - 2 r c cos(theta) and m = 4 r c / (r + c)^2,
      int_0^2pi (r cos(theta) - c) / d dtheta = (2/c) [(r - c) K(m) - (r + c) E(m)],
      int_0^2pi (r^2 - c r cos(theta)) / d dtheta = 2 [(r - c) K(m) + (r + c) E(m)],
  using r cos(theta) = (r^2 + c^2 - d^2) / (2c), int_0^pi dtheta/d = 2 K(m)/(r + c) and
  int_0^pi d dtheta = 2 (r + c) E(m). K is evaluated as ellipkm1(1 - m) with
  1 - m = ((r - c)/(r + c))^2 computed without cancellation, and away from r = c the
  difference K - E as Carlson's (m/3) R_D(0, 1 - m, 1) (no 1/c cancellation at small c);
* the outer r integral is adaptive QUADPACK: QAGS on [0, |c~|] and QAWS (weight
  (1 - r)^(1/k), the exact rim behaviour of the pressure) on the last interval, with the
  smooth factor ((1 - r^k)/(1 - r))^(1/k) left in the integrand.

Self-checks run before anything is written (the script exits non-zero if one fails):
the k = 2 closed form for |c~| <= 1, the docs/model.md 3.4 table (k = 4) and extra check values
(k = 2, 8), the limits of docs/model.md 3.2, and a literal 2-D adaptive quadrature (nested QAGS
in r and theta, no elliptic integrals) at a few points.

Usage (from the repository root; about a minute on one core):
    python tests/reference/generate_ls_reference.py --out tests/reference/ls_reference.csv
"""

from __future__ import annotations

import argparse
import math
import sys
import time
import warnings

import numpy as np
from scipy import integrate, special

K_VALUES = (1.5, 2.0, 3.0, 4.0, 6.0, 8.0, math.inf)
C_VALUES = (
    0.0, 0.01, 0.05, 0.1, 0.2, 0.25, 0.3, 0.4, 0.5, 0.6, 0.7, 0.75, 0.8, 0.9, 0.95, 0.99,
    0.999, 1.0, 1.001, 1.01, 1.05, 1.1, 1.2, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 7.0, 10.0, 15.0,
    20.0, 30.0, 50.0, 100.0, 200.0, 500.0, 1000.0,
)
EPSABS = 1e-13
EPSREL = 1e-12
LIMIT = 400


def beta(x: float, y: float) -> float:
    return math.exp(special.betaln(x, y))


def norms(k: float) -> tuple[float, float]:
    """P_k = int (1-|u|^k)^(1/k) dA, M_k = int (1-|u|^k)^(1/k) |u| dA (docs/model.md 2.2)."""
    if math.isinf(k):
        return math.pi, 2.0 * math.pi / 3.0
    return 2 * math.pi / k * beta(2 / k, 1 + 1 / k), 2 * math.pi / k * beta(3 / k, 1 + 1 / k)


def xi_closed(k: float) -> float:
    if math.isinf(k):
        return 2.0 / 3.0
    return 0.75 * math.gamma(3 / k) ** 2 / (math.gamma(2 / k) * math.gamma(4 / k))


def smooth_pressure(r: float, k: float) -> float:
    """((1 - r^k)/(1 - r))^(1/k): the pressure with its rim factor (1 - r)^(1/k) removed."""
    if math.isinf(k):
        return 1.0
    if r >= 1.0:
        return k ** (1.0 / k)
    om = 1.0 - r
    if om < 1e-6:  # (1 - r^k)/(1 - r) = k - k(k-1)/2 (1-r) + ... ; series avoids cancellation
        q = k - 0.5 * k * (k - 1.0) * om + k * (k - 1.0) * (k - 2.0) / 6.0 * om * om
    else:
        q = -math.expm1(k * math.log(r)) / om
    return q ** (1.0 / k)


def pressure(r: float, k: float) -> float:
    if math.isinf(k):
        return 1.0 if r <= 1.0 else 0.0
    return max(0.0, 1.0 - r**k) ** (1.0 / k)


def theta_integrals(r: float, c: float) -> tuple[float, float]:
    """Closed-form inner integrals over theta in [0, 2 pi] (see the module docstring)."""
    s = r + c
    if s == 0.0:
        return 0.0, 0.0
    q = (r - c) / s
    m1 = q * q  # 1 - m, without cancellation
    if m1 < 1e-2:  # near the CoR: (r - c) K(m) -> 0 as r -> c (log singularity of K)
        lk = (r - c) * special.ellipkm1(m1) if m1 > 0.0 else 0.0
        ee = special.ellipe(1.0 - m1)
        return 2.0 / c * (lk - s * ee), 2.0 * (lk + s * ee)
    # Elsewhere write E = K - D with D = K - E = (m/3) R_D(0, 1 - m, 1) (Carlson), which
    # removes the 1/c cancellation of the first form for small c:
    #   I_f = -4 K + 8 r R_D / (3 (r + c)),  I_t = 4 r K - 8 r c R_D / (3 (r + c)).
    kk = special.ellipkm1(m1)
    rd = special.elliprd(0.0, m1, 1.0)
    w = 8.0 * r * rd / (3.0 * s)
    return -4.0 * kk + w, 4.0 * r * kk - c * w


def _quad(fn, a, b, k, rim):
    with warnings.catch_warnings():
        warnings.simplefilter("error", integrate.IntegrationWarning)
        if rim and not math.isinf(k):
            val, err = integrate.quad(fn, a, b, weight="alg", wvar=(0.0, 1.0 / k),
                                      epsabs=EPSABS, epsrel=EPSREL, limit=LIMIT)
        else:
            val, err = integrate.quad(fn, a, b, epsabs=EPSABS, epsrel=EPSREL, limit=LIMIT)
    return val, err


def ls_point(c: float, k: float) -> tuple[float, float, float]:
    """(f~*_tLS(c), tau~*_LS(c), error estimate) for c >= 0 by the elliptic/QUADPACK route."""
    if c == 0.0:
        return 0.0, 1.0, 0.0
    p_k, m_k = norms(k)
    inf = math.isinf(k)

    def rim_factor(r):  # 1 on the uniform disc; (1-r)^(1/k) is in the QAWS weight otherwise
        return 1.0 if inf else smooth_pressure(r, k)

    def f_int(r, with_rim):
        i_f, _ = theta_integrals(r, c)
        return (rim_factor(r) if with_rim else pressure(r, k)) * r * i_f

    def t_int(r, with_rim):
        _, i_t = theta_integrals(r, c)
        return (rim_factor(r) if with_rim else pressure(r, k)) * r * i_t

    pieces = []
    if c < 1.0:
        pieces.append((0.0, c, False))
        lo = c
    else:
        lo = 0.0
    # A second break between the CoR (or the rim's near-singular point for c just above 1)
    # and the rim keeps QAWS working on a single endpoint behaviour.
    mid = lo + 0.5 * (1.0 - lo)
    if c < 1.0:
        pieces += [(lo, mid, False), (mid, 1.0, True)]
    else:
        pieces += [(0.0, 1.0, True)]
    fv = tv = err = 0.0
    for a, b, rim in pieces:
        if b <= a:
            continue
        v, e = _quad(lambda r: f_int(r, rim), a, b, k, rim)
        fv += v
        err += e / p_k
        v, e = _quad(lambda r: t_int(r, rim), a, b, k, rim)
        tv += v
        err += e / m_k
    return fv / p_k, tv / m_k, err


def ls_point_2d(c: float, k: float) -> tuple[float, float]:
    """Literal docs/model.md 3.3 method B: nested adaptive quadrature of the boxed 2-D integrals
    (outer r with a break at |c|, inner theta in [0, pi] doubled). Slow; cross-check only."""
    p_k, m_k = norms(k)

    def inner(r, which):
        def g(th):
            d = math.sqrt(max(r * r + c * c - 2 * r * c * math.cos(th), 0.0))
            if d == 0.0:
                return 0.0
            if which == 0:
                return (r * math.cos(th) - c) / d
            return (r * r - c * r * math.cos(th)) / d
        v, _ = integrate.quad(g, 0.0, math.pi, epsabs=1e-13, epsrel=1e-12, limit=400)
        return 2.0 * v * pressure(r, k) * r

    pts = [c] if 0.0 < c < 1.0 else None
    out = []
    for which, norm in ((0, p_k), (1, m_k)):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", integrate.IntegrationWarning)
            v, _ = integrate.quad(inner, 0.0, 1.0, args=(which,), points=pts, epsabs=1e-12,
                                  epsrel=1e-12, limit=400)
        out.append(v / norm)
    return out[0], out[1]


def self_check(verbose: bool = True) -> list[str]:
    """Checks the generator against every independent value we have; returns failures."""
    fails = []

    def check(name, got, want, tol):
        ok = abs(got - want) <= tol
        if verbose:
            print(f"  {'ok ' if ok else 'BAD'} {name}: got {got:.12f} want {want:.12f} "
                  f"(|diff| {abs(got - want):.2e}, tol {tol:.0e})")
        if not ok:
            fails.append(name)

    print("k = 2 closed form (|c~| <= 1):")
    for c in (0.05, 0.3, 0.5, 0.77, 0.95, 0.999, 1.0):
        f, t, _ = ls_point(c, 2.0)
        check(f"k=2 f*({c})", f, -3 * math.pi / 8 * c * (1 - c * c / 4), 1e-12)
        check(f"k=2 tau*({c})", t, 1 - c * c + 0.375 * c**4, 1e-12)
    print("docs/model.md 3.4 table (k = 4) and extra check values:")
    table = {
        4.0: [(0.1, -0.1059068333, 0.9916725251), (0.25, -0.2626505930, 0.9485788612),
              (0.5, -0.5094317274, 0.8037455127), (0.75, -0.7203649578, 0.5978502942),
              (1.0, -0.8640993375, 0.4029076144), (1.5, -0.9460703579, 0.2496260446),
              (2.0, -0.9704899177, 0.1838373829), (5.0, -0.9954017542, 0.0722525720),
              (10.0, -0.9988545171, 0.0360408313)],
        2.0: [(0.5, -0.5522330836, 0.7734375000), (2.0, -0.9742785793, 0.1730066569)],
        8.0: [(0.5, -0.4921547025, 0.8157217702), (1.0, -0.8545461297, 0.4162588118),
              (2.0, -0.9687041210, 0.1888186923)],
    }
    for k, rows in table.items():
        for c, f_ref, t_ref in rows:
            f, t, _ = ls_point(c, k)
            check(f"k={k:g} f*({c})", f, f_ref, 6e-11)
            check(f"k={k:g} tau*({c})", t, t_ref, 6e-11)
    print("Limits (docs/model.md 3.2): small-c~ slope, large-c~ tails, xi closed form:")
    for k in (2.0, 4.0, 8.0, math.inf):
        p_k, m_k = norms(k)
        if not math.isinf(k):
            s_k = beta(1 / k, 1 + 1 / k) / (2 * beta(2 / k, 1 + 1 / k))
            a_f = beta(4 / k, 1 + 1 / k) / (4 * beta(2 / k, 1 + 1 / k))
            a_t = beta(4 / k, 1 + 1 / k) / (2 * beta(3 / k, 1 + 1 / k))
        else:
            s_k, a_f, a_t = 1.0, 0.125, 0.375
        c = 1e-4
        f, t, _ = ls_point(c, k)
        check(f"k={k:g} -f*(1e-4)/1e-4 vs s_k", -f / c, s_k, 1e-6)
        c = 1e3
        f, t, _ = ls_point(c, k)
        check(f"k={k:g} (1+f*(1e3)) c^2 vs A_f", (1 + f) * c * c, a_f, 1e-4)
        check(f"k={k:g} tau*(1e3) c vs A_tau", t * c, a_t, 1e-4)
        # xi = M_k / P_k from direct 1-D quadrature of the pressure moments
        if not math.isinf(k):
            pk = 2 * math.pi * integrate.quad(lambda r: pressure(r, k) * r, 0, 1,
                                              epsabs=1e-14, epsrel=1e-14, limit=200)[0]
            mk = 2 * math.pi * integrate.quad(lambda r: pressure(r, k) * r * r, 0, 1,
                                              epsabs=1e-14, epsrel=1e-14, limit=200)[0]
            check(f"k={k:g} P_k quad vs Beta", pk, p_k, 1e-10)
            check(f"k={k:g} xi quad vs Gamma closed form", mk / pk, xi_closed(k), 1e-10)
    print("Literal 2-D method B (nested QAGS) vs the elliptic route:")
    for k, c in ((4.0, 0.3), (4.0, 1.0), (4.0, 1.5), (2.0, 0.8), (8.0, 3.0), (math.inf, 0.6),
                 (1.5, 0.999), (6.0, 1.001)):
        f2, t2 = ls_point_2d(c, k)
        f, t, _ = ls_point(c, k)
        check(f"k={k:g} 2-D f*({c})", f, f2, 1e-10)
        check(f"k={k:g} 2-D tau*({c})", t, t2, 1e-10)
    return fails


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default="tests/reference/ls_reference.csv")
    ap.add_argument("--skip-check", action="store_true", help="do not run the self-checks")
    args = ap.parse_args(argv)

    t0 = time.time()
    if not args.skip_check:
        fails = self_check()
        if fails:
            print(f"SELF-CHECK FAILED: {', '.join(fails)}", file=sys.stderr)
            return 1
        print(f"self-checks passed ({time.time() - t0:.1f} s)")

    rows = []
    worst = 0.0
    for k in K_VALUES:
        xi = xi_closed(k)
        for c in C_VALUES:
            f, t, err = ls_point(c, k)
            worst = max(worst, err)
            rows.append((k, c, f, t, xi * t + c * abs(f), err))
    with open(args.out, "w") as fh:
        fh.write("# Normalized limit surface, independent reference (tests/reference/"
                 "generate_ls_reference.py).\n")
        fh.write("# Signed f~*_tLS (opposite sign to c~) and tau~*_LS at c~ >= 0; "
                 "G = xi tau~* + c~ |f~*|; quad_err = QUADPACK error estimate.\n")
        fh.write("k,c_tilde,ft_star,tau_star,G,quad_err\n")
        for k, c, f, t, g, err in rows:
            ks = "inf" if math.isinf(k) else repr(k)
            fh.write(f"{ks},{c!r},{f:.17g},{t:.17g},{g:.17g},{err:.3g}\n")
    print(f"wrote {len(rows)} rows to {args.out}; worst QUADPACK error estimate {worst:.2e}; "
          f"total {time.time() - t0:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
