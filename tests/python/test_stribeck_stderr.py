"""Standard errors of the Stribeck joint fit (identify's stage 7, docs/identification.md).

Kinds of test:
* independent plant: the grid of LuGre cells (lugrip.rigs.grid, Hertzian pressure, Stribeck
  friction, viscous shear), written from contact mechanics, not from lugrip's model: the
  reported standard errors against the spread of the estimates over independent seeds;
* no plant: a quadratic eq. 32 cost written below (per-maneuver parabolas in the fit's
  coordinates), where the sandwich covariance is known in closed form, a flat direction
  and a parameter at its bound.
"""

from __future__ import annotations

import math
import warnings

import lugrip
import numpy as np
import pytest
from lugrip import ContactParams
from lugrip.identification import _driver
from lugrip.identification._common import PARAMETERS
from lugrip.rigs import RubbingDesign
from lugrip.rigs.grid import GridContactRig

FREE = ("mu", "delta", "gamma", "beta_a")
P = ContactParams.table1().replace(static_ratio=1.25, kinetic_ratio=1.0, stribeck_speed=4e-4)


def _coordinates(p: ContactParams) -> np.ndarray:
    return np.array([math.log(getattr(p, n)) for n in FREE]
                    + [math.log(p.static_ratio - 1.0), math.log(p.stribeck_speed)])


class _QuadraticProblem:
    """Stands in for the training problem: maneuver m's weighted loss is
    sum_k a_k (x_k - c_mk)^2 in the joint fit's coordinates x (log of mu, delta, gamma,
    beta_a, ln(static_ratio - 1), ln stribeck_speed), with the C++ evaluation's keys
    (Gauss-Newton matrix and per-maneuver gradients in parameter units)."""

    def __init__(self, a, centres):
        self.a = np.asarray(a, float)
        self.c = np.asarray(centres, float)  # (M, 6)
        self.maneuvers = list(range(len(self.c)))
        self.segment_owner = np.arange(len(self.c))
        self.weight_sum = 1000.0

    def evaluate(self, params, derivatives=True, omega_hat=False):
        x = _coordinates(params)
        per = np.sum(self.a * (x - self.c) ** 2, axis=1)
        ev = {"cost": per.sum() / self.weight_sum, "weight_sum": self.weight_sum,
              "segment_loss": per, "segment_sse": per, "scored": 10 * len(per)}
        if derivatives:
            s = np.array([getattr(params, n) for n in FREE])
            g = 2.0 * self.a[:4] * (x[:4] - self.c[:, :4]) / s  # dL_m / dp
            seg = np.zeros((len(per), 6))
            gn = np.zeros((6, 6))
            for i, n in enumerate(FREE):
                k = PARAMETERS.index(n)
                seg[:, k] = g[:, i]
                gn[k, k] = 2.0 * self.a[i] * len(per) / s[i] ** 2 / self.weight_sum
            ev["segment_gradient"] = seg.ravel()
            ev["gradient"] = seg.sum(axis=0) / self.weight_sum
            ev["gauss_newton"] = gn.ravel()
        return ev

    def maneuver_gradients(self, ev):
        return np.asarray(ev["segment_gradient"]).reshape(-1, 6)


def _stderr(problem, at_bound=()):
    bnds = {n: (1e-6, 1e12) for n in FREE}
    return _driver._joint_stderr(problem, P, FREE, bnds, at_bound, loss="squared",
                                 uncertainty="sandwich", n_bootstrap=0, seed=0,
                                 problem_of=None, refit=None)


def test_quadratic_cost_gives_the_closed_form_sandwich():
    """No plant. For per-maneuver parabolas the sandwich is exact: the variance of x_k is
    sum_m (x_k - c_mk)^2 / M^2 x M / (M - 1), whatever the difference steps; the curve's
    standard errors are the log ones times (static_ratio - 1) and stribeck_speed; a result
    off the minimum along the curve gets the exact Newton step to it in the report line."""
    rng = np.random.default_rng(1)
    x = _coordinates(P)
    c = x + rng.normal(0.0, [0.05, 0.04, 0.03, 0.2, 0.15, 0.3], size=(30, 6))
    c -= c.mean(axis=0) - x  # P is the minimum
    stderr, why, line = _stderr(_QuadraticProblem([5.0, 7.0, 3.0, 1.0, 2.0, 0.5], c))
    assert not why
    M = len(c)
    se_log = np.sqrt(np.sum((c - x) ** 2, axis=0) / M**2 * M / (M - 1))
    for i, n in enumerate(FREE):
        assert stderr[n] == pytest.approx(getattr(P, n) * se_log[i], rel=1e-6)
    assert stderr["static_ratio"] == pytest.approx(0.25 * se_log[4], rel=1e-4)
    assert stderr["stribeck_speed"] == pytest.approx(4e-4 * se_log[5], rel=1e-4)
    assert "standard errors of the joint fit" in line
    # a result off the minimum along the curve: the report gives the Newton step to it
    shifted = _QuadraticProblem([5.0, 7.0, 3.0, 1.0, 2.0, 0.5], c + [0, 0, 0, 0, 0.1, -0.2])
    _, why, line = _stderr(shifted)
    assert not why
    assert "lies +0.1 in ln(static_ratio - 1) and -0.2 in ln stribeck_speed" in line


def test_flat_speed_and_parameter_at_bound_give_nan():
    """No plant. A cost that does not depend on the Stribeck speed (the speed not determined)
    gives NaN for stribeck_speed with the reason, and only there; a refitted parameter at its
    bound gives NaN for it and leaves the others finite."""
    rng = np.random.default_rng(2)
    x = _coordinates(P)
    c = x + rng.normal(0.0, 0.05, size=(20, 6))
    c -= c.mean(axis=0) - x
    stderr, why, _ = _stderr(_QuadraticProblem([5.0, 7.0, 3.0, 1.0, 2.0, 0.0], c))
    assert set(why) == {"stribeck_speed"} and "not determined" in why["stribeck_speed"]
    assert math.isnan(stderr["stribeck_speed"])
    assert all(math.isfinite(stderr[n]) for n in FREE + ("static_ratio",))
    stderr, why, _ = _stderr(_QuadraticProblem([5.0, 7.0, 3.0, 1.0, 2.0, 0.5], c), ("gamma",))
    assert set(why) == {"gamma"} and "bound" in why["gamma"]
    assert math.isnan(stderr["gamma"])
    assert all(math.isfinite(stderr[n]) for n in ("mu", "delta", "beta_a", "static_ratio",
                                                  "stribeck_speed"))


def test_stribeck_stderr_against_the_spread_over_seeds():
    """Independent plant: grid of LuGre cells (17 x 17, Hertzian pressure, mu_s 0.63 / mu_k
    0.45, Stribeck speed 0.5 mm/s, viscous shear 2e7 N s/m^3), 100 maneuvers per seed (80
    training). Over four independent seeds, where identify() keeps the joint fit with the
    Stribeck curve, the standard deviation of the estimates' logs (mu, delta, beta_a,
    static_ratio - 1, stribeck_speed) lies within a factor 3 of the median reported relative
    standard error (measured on these seeds: spread / standard error 0.52 for mu, 0.60 delta,
    0.84 beta_A, 1.02 static_ratio - 1, 1.07 stribeck_speed), and the params file's entries
    carry the curve's standard errors."""
    rig = GridContactRig.viscous(n_grid=17, mu_s=0.63)
    design = RubbingDesign(edge_speed_range=(1e-4, 1e-2), c_tilde_range=(0.05, 20.0),
                           hold_slip=3e-4)
    logs, rel = [], []
    for seed in (1, 2, 3, 4):
        data = rig.simulate(design, n=100, seed=seed)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            r = lugrip.identify(data.log)
        assert r.friction_estimates, seed  # the joint fit was kept
        entry = r.to_dict()["contact"]["stribeck_speed"]  # the params file's entry carries it
        assert entry["stderr"] == r["stribeck_speed"].stderr and "Stribeck" in entry["note"]
        logs.append([math.log(r[n].value) for n in ("mu", "delta", "beta_a")]
                    + [math.log(r["static_ratio"].value - 1.0),
                       math.log(r["stribeck_speed"].value)])
        rel.append([r[n].stderr / r[n].value for n in ("mu", "delta", "beta_a")]
                   + [r["static_ratio"].stderr / (r["static_ratio"].value - 1.0),
                      r["stribeck_speed"].stderr / r["stribeck_speed"].value])
    spread = np.std(np.array(logs), axis=0, ddof=1)
    reported = np.nanmedian(np.array(rel), axis=0)
    assert np.all(np.isfinite(reported))
    ratio = spread / reported
    assert np.all((ratio > 1 / 3) & (ratio < 3)), ratio
