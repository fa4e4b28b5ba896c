"""Stage (d): the friction levels the slip indicator is judged against (docs/model.md §7.5,
§8.3): the break-away level (static friction) against the sliding level (kinetic friction),
both relative to the fitted limit surface, with a significance test for a Stribeck term."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .._observer import Observer
from .._params import ContactParams
from ._data import _Maneuver
from ._phases import SLIDING

__all__ = ["FrictionLevels", "friction_levels", "stribeck_curve"]

STRIBECK_T = 3.0  # |t| of the slope of log(sliding level) on log(speed) above which it counts
STRIBECK_MIN = 1.03  # smallest static / kinetic ratio that counts as a Stribeck term
SLIDING_QUANTILE = 0.05  # the sliding level: this quantile of the gross-sliding load ratio
BREAKAWAY_QUANTILE = 0.9  # the static level: this quantile of the per-run break-away peaks
SHAPE_TOLERANCE = 0.97  # a sliding level above this fraction of the surface is taken as 1
_SMOOTH = 10  # samples of the moving average of the load ratio (20 ms at 500 Hz)
_AFTER = 25  # samples after the first gross-sliding sample still searched for the peak
_MIN_RUNS = 5  # runs with a break-away needed for the test


@dataclasses.dataclass(frozen=True)
class FrictionLevels:
    """Result of stage (d).

    Attributes:
        static_ratio: break-away level over the fitted surface (ContactParams.static_ratio).
        kinetic_ratio: sliding level over the fitted surface (ContactParams.kinetic_ratio).
        stribeck: the break-away level exceeds the sliding level significantly.
        t: t statistic of the slope of the runs' log dry sliding level on their log speed.
        median_ratio: the break-away level (quantile of the peaks) over the sliding level.
        runs: maneuvers with a break-away used for the test.
        line: the report line.
        curve: where the Stribeck term counts, the runs' dry sliding levels against their
            speed fitted with :func:`stribeck_curve`, (level at speed, level at rest,
            Stribeck speed [m/s]);
            None otherwise or where the curve's knee is not in the data.
    """

    static_ratio: float
    kinetic_ratio: float
    stribeck: bool
    t: float
    median_ratio: float
    runs: int
    line: str
    curve: tuple[float, float, float] | None = None


def _smooth(x: np.ndarray, n: int) -> np.ndarray:
    if len(x) < n:
        return x.copy()
    k = np.ones(n) / n
    return np.convolve(x, k, mode="same")


def stribeck_curve(speeds: np.ndarray, levels: np.ndarray, static: float):
    """The runs' dry sliding levels (over the fitted surface) against their sliding speed,
    fitted with l(v) = a + (b - a) exp(-(v / v_s)^2): the level falls from b at rest to a at
    speed, b at least the break-away level ``static``. Robust (soft L1) least squares in a, b
    and log v_s, a run's level also carrying the limit surface's shape error. Returns
    (a, b, v_s), or None when the knee is not in the data (v_s within 5 % of the log speed
    range of its ends, or a range narrower than a factor 4) or b is not above a by
    ``STRIBECK_MIN``."""
    from scipy.optimize import least_squares

    v = np.asarray(speeds, float)
    lv = np.asarray(levels, float)
    lo, hi = math.log(float(v.min())), math.log(float(v.max()))
    if not hi - lo > math.log(4.0):
        return None
    fast = lv[v >= np.quantile(v, 0.75)]
    a0 = float(min(np.median(fast), static / STRIBECK_MIN))
    b0 = max(static, float(np.max(lv)))

    def resid(x):
        return x[0] + (x[1] - x[0]) * np.exp(-np.square(v / math.exp(x[2]))) - lv

    spread = max(float(np.median(np.abs(lv - np.median(lv)))), 1.0e-3)
    fit = least_squares(resid, [a0, b0 * 1.001, 0.5 * (lo + hi)],
                        bounds=([0.5, static, lo], [3.0, 3.0, hi]),
                        loss="soft_l1", f_scale=spread)
    a, b, ls = (float(x) for x in fit.x)
    margin = 0.05 * (hi - lo)
    if not (fit.success and lo + margin < ls < hi - margin and b / a >= STRIBECK_MIN):
        return None
    return a, b, math.exp(ls)


def friction_levels(
    mans: list[_Maneuver], phases: list[np.ndarray], params: ContactParams, observer: dict
) -> FrictionLevels:
    """The load ratio |y| / g (friction torque about the estimated CoR over the capacity of the
    fitted surface, from the online observer's CoR; eqs. 16, 18) on every sample; the sliding
    level is its ``SLIDING_QUANTILE`` over the gross-sliding samples. Its dry part (the
    viscous torque sigma_1 |omega| at the true speed taken off) gives each run's median dry
    sliding level and its break-away, the peak (20 ms average) up to shortly after gross
    sliding begins, on the samples whose CoR is not clipped (sigma_1 is about the clipped CoR). A Stribeck term is
    kept when the runs' median dry sliding level falls with their sliding speed (the RMS speed
    over the patch, |omega| rho sqrt(c~^2 + 1/2) with the estimated CoR; slope of the logs,
    t <= -3) and the ``BREAKAWAY_QUANTILE`` of the peaks exceeds the sliding level by at least
    3 %; that quantile is then static_ratio. Without it both capacities are the sliding level
    (one capacity, as in the paper), and 1 where that level is within 3 % of the surface."""
    p = params.replace(static_ratio=1.0, kinetic_ratio=1.0)
    obs = Observer(p, **observer)
    sliding_q: list[np.ndarray] = []
    peaks, levels, speeds = [], [], []
    for m, ph in zip(mans, phases):
        q = np.full(m.n, np.nan)
        qd = np.full(m.n, np.nan)
        vel = np.full(m.n, np.nan)
        for a, b in zip(m.starts[:-1], m.starts[1:]):
            run = obs.run({"f_n": m.f_n[a:b], "f_t": m.f_t[a:b], "tau": m.tau[a:b], "t": m.t[a:b]})
            g = np.asarray(run.g)
            with np.errstate(invalid="ignore", divide="ignore"):
                q[a:b] = _smooth(np.abs(np.asarray(run.y)) / g, _SMOOTH)
                # the dry part: the viscous torque at the true speed taken off
                visc = np.asarray(run.sigma_1) * np.abs(m.omega[a:b])
                qd[a:b] = _smooth((np.abs(np.asarray(run.y)) - visc) / g, _SMOOTH)
                # RMS sliding speed over the patch, |omega| rho sqrt(c~u^2 + 1/2) [m/s]
                rho = p.delta * np.asarray(m.f_n[a:b]) ** p.gamma
                cu = np.asarray(run.c_tilde_unclipped)
                vel[a:b] = np.abs(m.omega[a:b]) * rho * np.sqrt(cu * cu + 0.5)
                # sigma_1 is about the clipped CoR: the dry part only where the CoR is not clipped
                qd[a:b][np.asarray(run.saturated, bool)] = np.nan
        slide = (np.asarray(ph) == SLIDING) & np.isfinite(q)
        if not slide.any():
            continue
        sliding_q.append(q[slide])
        first = int(np.flatnonzero(slide)[0])
        window = qd[: min(m.n, first + _AFTER)]
        window = window[np.isfinite(window)]
        dry = qd[slide]
        dry = dry[np.isfinite(dry)]
        if dry.size == 0:
            continue
        level = float(np.median(dry))
        speed = float(np.nanmedian(vel[slide]))
        if window.size and level > 0.0 and speed > 0.0 and math.isfinite(speed):
            peaks.append(float(window.max()))
            levels.append(level)
            speeds.append(speed)
    if not sliding_q:
        return FrictionLevels(1.0, 1.0, False, math.nan, math.nan, 0,
                              "(d) friction levels: no gross sliding, ratios 1")
    q_all = np.concatenate(sliding_q)
    kinetic = float(np.quantile(q_all, SLIDING_QUANTILE))
    kinetic = 1.0 if kinetic >= SHAPE_TOLERANCE else min(max(kinetic, 0.5), 1.0)
    peaks_a, levels_a, speeds_a = np.asarray(peaks), np.asarray(levels), np.asarray(speeds)
    n = len(peaks_a)
    t, med = math.nan, math.nan
    stribeck = False
    static = kinetic
    if n >= _MIN_RUNS and np.ptp(np.log(speeds_a)) > 0.0:
        # the sliding level falls with the speed (Stribeck): slope of log level on log speed
        x, y = np.log(speeds_a), np.log(levels_a)
        xc = x - x.mean()
        b = float(np.sum(xc * (y - y.mean())) / np.sum(xc * xc))
        r = y - y.mean() - b * xc
        se = math.sqrt(float(np.sum(r * r)) / max(n - 2, 1) / float(np.sum(xc * xc)))
        t = b / se if se > 0 else -math.inf * np.sign(-b)
        static_q = float(np.quantile(peaks_a, BREAKAWAY_QUANTILE))
        med = static_q / kinetic
        stribeck = t <= -STRIBECK_T and med >= STRIBECK_MIN
        if stribeck:
            static = float(np.clip(static_q, kinetic, 3.0))
    curve = stribeck_curve(speeds_a, levels_a, static) if stribeck else None
    line = (
        f"(d) friction levels from {q_all.size} gross-sliding samples of {n} runs (load |y|/g "
        f"on the fitted surface; dry part without sigma_1 |omega| for the runs): sliding level {kinetic:.3g} ({100 * SLIDING_QUANTILE:g} % "
        "quantile" + (", within 3 % of the surface: 1" if kinetic == 1.0 else "")
        + f"); slope of the runs' sliding level on their speed t = {t:.3g}, break-away "
        f"({100 * BREAKAWAY_QUANTILE:g} % quantile of the peaks) over sliding level {med:.3g}: "
        + (
            f"Stribeck term measured, static_ratio {static:.3g}, kinetic_ratio {kinetic:.3g} "
            f"(mu_s/mu_k {static / kinetic:.3g})"
            if stribeck
            else f"no significant Stribeck term (needs t <= -{STRIBECK_T:g} and a ratio >= "
            f"{STRIBECK_MIN:g}): static_ratio = kinetic_ratio = {kinetic:.3g}"
        )
    )
    if curve is not None:
        line += (f"; the runs' dry levels follow {curve[0]:.3g} + ({curve[1]:.3g} - {curve[0]:.3g}) "
                 f"exp(-(v/{curve[2]:.3g} m/s)^2) with the RMS speed v over the patch")
    return FrictionLevels(static, kinetic, stribeck, t, med, n, line, curve)
