"""Synthetic sliding maneuvers like the paper's Section 4 (Fig. 4) and the scoring of the
sliding-velocity observer on them (RMSE of omega_hat, slip-detection delay, false alarms).

The paper identified its parameters on 1342 maneuvers of a cardboard slider pushed by a robot
against a fingertip "with increasing forces and torques, resulting in increasing sliding
velocity", ground truth omega from the robot's encoders. Here the slider is the model itself:

* **plant**: :class:`lugrip.SliderModel` (eqs. 1-2, inertia ``J`` about the CoR, z projected
  onto ``|z| <= g/sigma0``) about a fixed CoR ``c~`` at a constant normal force ``f_n`` per
  maneuver, driven by an external torque ``tau_e`` about the CoR;
* **sensor**: the wrench the object exerts on the fingertip (what a fingertip F/T sensor reads,
  docs/model.md 7.2) for that CoR and the plant's friction torque about it,
  :func:`lugrip.sensor_wrench` (= ``ContactModel::wrench_at``), the in-plane force rotated to a
  random direction of the sensor frame (``f_x``, ``f_y``), plus white noise on ``f_n``,
  ``f_x``, ``f_y`` and ``tau``;
* **ground truth**: the plant's omega (the object's angular velocity relative to the
  fingertip about the contact normal, the observer's sign convention) and the maneuver id.

Maneuver design (one per maneuver, drawn with a seeded generator, stratified so that even a
small set spans every range):

* ``f_n`` uniform in ``f_n_range`` (default 1-10 N, the paper's Section 4 range);
* ``|c~|`` log-uniform in ``c_range`` (default 0.02 to ``2 c_max``): from rotation-dominated to
  translation-dominated, including CoRs beyond the observer's clip ``c_max`` where the
  estimated CoR saturates (docs/model.md 5.6) and the observer's omega refers to the clipped CoR;
* direction of the load (the sign of omega) random;
* torque profile: rest, linear ramp up, hold, ramp down, rest (durations in ``ramp``,
  ``hold``, ``release``, ``rest``; sliding maneuvers hold for at least three time constants
  ``J / sigma_1`` of the slider, at most ``max_hold``, so that weakly viscous sliders reach
  their target speed);
* **sliding maneuvers**: the peak load is ``tau_peak = g + sigma_1 omega_peak``, the steady
  torque that makes the slider slide at ``omega_peak`` (eq. 2 at steady state), with
  ``omega_peak = omega_0 / sqrt(1 + 2 c~^2)`` and ``omega_0`` log-uniform in ``omega_range``
  (default 0.05-0.5 rad/s). ``omega_0`` is the speed of a pure rotation; the factor keeps the
  RMS sliding speed over the patch (``omega rho sqrt(c~^2 + 1/2)``, the speed viscous friction
  sees, eq. 17) independent of the CoR, as for a robot pushing at similar speeds in every
  direction, so translation-dominated maneuvers turn slower. Peak speeds are then tenths of
  rad/s as in the paper's Figure 5. With Table 1's ``beta_A = 4.9e9`` the viscous torque at
  these speeds is 10-60 times the dry capacity ``g``: the loads are far outside the limit
  surface, as the identified parameters imply (docs/model.md 11, item 9). With a Table 2 object the
  same speeds need only a few per cent above ``g``.
* **stick maneuvers** (a fraction ``stick_fraction``): the same profile with a peak load of
  ``load_ratio * g``, ``load_ratio`` uniform in ``stick_load`` (default 0.3-0.85); the plant
  stays in pre-sliding (|omega| of the order of 1e-3 rad/s at most).

Scoring (:func:`score`): RMSE of omega_hat over all samples with ground truth (the paper's
figure) and per regime of ``|c~|``; slip detection per maneuver: the true slip onset is the
first sample with ``|omega| > omega_threshold``, the detection the start of the run of
``S >= s_threshold`` that contains the onset (negative delay: the indicator warned before the
slip) or else the first such sample after it; a maneuver whose truth never exceeds the
threshold is a stick maneuver and any ``S >= s_threshold`` in it is a false alarm.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence

import numpy as np

from .._contact import _as_params
from .._contact import g as _g
from .._contact import sigma_1 as _sigma_1
from .._observer import Observer, ObserverRun, SliderModel, sensor_wrench
from .._params import ContactParams
from ..io import SlidingLog

__all__ = [
    "DEFAULT_NOISE",
    "PAPER_NOISE",
    "REGIMES",
    "Maneuver",
    "ManeuverScore",
    "SlidingScore",
    "SyntheticSliding",
    "evaluate",
    "regime_of",
    "score",
    "simulate_maneuvers",
    "simulate_sliding",
    "slip_detection",
]

DEFAULT_NOISE: tuple[float, float] = (0.005, 1.0e-5)
"""Default white sensor noise (force std [N], torque std [N m]): docs/model.md 10.1 (0.005 N and
0.01 N mm), a fraction of the paper's stated accuracy."""

PAPER_NOISE: tuple[float, float] = (0.1, 2.0e-3)
"""The paper's sensor accuracy (0.1 N, 0.002 N m) taken as white-noise std (docs/model.md 10.1
explains why that is pessimistic)."""

REGIMES: tuple[str, ...] = ("rotation", "mixed", "translation", "beyond_clip")
"""Regimes of the true |c~|: rotation-dominated (< 0.5), mixed (0.5-1), translation-dominated
(1 to c_max) and beyond the observer's CoR clip (> c_max)."""


def regime_of(c_abs: float, c_max: float) -> str:
    """Regime name (one of :data:`REGIMES`) of a CoR at normalized distance ``c_abs``."""
    c_abs = abs(float(c_abs))
    if c_abs < 0.5:
        return "rotation"
    if c_abs < 1.0:
        return "mixed"
    if c_abs <= c_max * (1.0 + 1e-12):
        return "translation"
    return "beyond_clip"


# ---------------------------------------------------------------------------------------------
# generator
# ---------------------------------------------------------------------------------------------


@dataclasses.dataclass(frozen=True)
class Maneuver:
    """Design of one synthetic maneuver (SI units).

    Attributes:
        index: maneuver id (the log's ``maneuver`` column).
        kind: "slide" (peak load past the limit surface) or "stick" (peak load inside).
        regime: regime of ``c_tilde`` (:func:`regime_of`).
        f_n: normal force [N].
        c_tilde: |c~| of the true CoR [-] (its side in the sensor frame follows the load
            direction, sign(c~) = -sign(omega)).
        direction: sign of the applied torque, +1 or -1 (the sign of omega while sliding).
        g: dry torque capacity about the CoR [N m] (eq. 18, unclipped CoR).
        sigma_1: viscous coefficient about the CoR [N m s/rad] (eq. 17).
        load_ratio: peak external torque / g [-].
        omega_peak: steady speed at the peak load [rad/s] (0 for stick maneuvers).
        phi: direction of the in-plane force in the sensor frame [rad].
        start, stop: half-open sample range of the maneuver in the log.
        ramp, hold, release: durations of the load ramp up, the hold and the ramp down [s].
    """

    index: int
    kind: str
    regime: str
    f_n: float
    c_tilde: float
    direction: int
    g: float
    sigma_1: float
    load_ratio: float
    omega_peak: float
    phi: float
    start: int
    stop: int
    ramp: float
    hold: float
    release: float

    def to_dict(self) -> dict:
        return dataclasses.asdict(self)


@dataclasses.dataclass(frozen=True, eq=False)
class SyntheticSliding:
    """A synthetic sliding log with its ground truth.

    Attributes:
        log: the sensor log (t, f_n, f_x, f_y, tau, omega, maneuver) as written to files.
        maneuvers: the design of every maneuver, in log order.
        slip: true utilisation sigma0 |z| / g of the plant per sample [-] (S of the truth).
        friction_torque: noiseless friction torque about the true CoR per sample [N m] (y).
        tau_e: external torque about the CoR per sample [N m].
        params: the plant's contact parameters.
        config: the generator's arguments (JSON-able), also in ``log.meta["generator"]``.
    """

    log: SlidingLog
    maneuvers: tuple[Maneuver, ...]
    slip: np.ndarray
    friction_torque: np.ndarray
    tau_e: np.ndarray
    params: ContactParams
    config: dict

    def __len__(self) -> int:
        return len(self.log)

    def regimes(self) -> np.ndarray:
        """Regime name per sample."""
        out = np.empty(len(self.log), dtype=object)
        for m in self.maneuvers:
            out[m.start : m.stop] = m.regime
        return out


def _pair(name: str, value, *, positive: bool = True, ordered: bool = True) -> tuple[float, float]:
    try:
        lo, hi = (float(v) for v in value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} = {value!r}: expected a pair (low, high)") from None
    if not (math.isfinite(lo) and math.isfinite(hi)):
        raise ValueError(f"{name} = {value!r}: must be finite")
    if positive and not lo > 0.0:
        raise ValueError(f"{name} = {value!r}: must be > 0")
    if not positive and lo < 0.0:
        raise ValueError(f"{name} = {value!r}: must be >= 0")
    if ordered and hi < lo:
        raise ValueError(f"{name} = {value!r}: high < low")
    return lo, hi


def _stratified(rng: np.random.Generator, n: int) -> np.ndarray:
    """n samples in [0, 1), one per equal stratum, in random order (Latin hypercube column)."""
    return rng.permutation((np.arange(n) + rng.random(n)) / max(n, 1))


def simulate_maneuvers(
    params,
    n_maneuvers: int = 240,
    *,
    seed: int = 0,
    f_n_range: Sequence[float] = (1.0, 10.0),
    c_range: Sequence[float] | None = None,
    omega_range: Sequence[float] = (0.05, 0.5),
    stick_fraction: float = 0.15,
    stick_load: Sequence[float] = (0.3, 0.85),
    noise: Sequence[float] = DEFAULT_NOISE,
    dt: float = 0.002,
    J: float = 1.0e-4,
    ramp: Sequence[float] = (0.3, 1.0),
    hold: Sequence[float] = (0.1, 0.5),
    release: Sequence[float] = (0.1, 0.4),
    rest: float = 0.2,
    max_hold: float = 2.0,
    max_substep: float = 1.0e-4,
) -> SyntheticSliding:
    """Simulate ``n_maneuvers`` sliding maneuvers (module docstring) into one log.

    Args:
        params: ContactParams of the plant (and of the sensor model), a preset name or a dict.
        n_maneuvers: number of maneuvers (>= 1).
        seed: seed of ``numpy.random.default_rng``; equal seeds give equal logs.
        f_n_range: normal force range [N], uniform.
        c_range: |c~| range [-], log-uniform; default (0.02, 2 c_max).
        omega_range: range of omega_0 [rad/s], log-uniform (peak speed of a pure rotation;
            ``omega_peak = omega_0 / sqrt(1 + 2 c~^2)``).
        stick_fraction: fraction of stick maneuvers in [0, 1].
        stick_load: range of the peak load / g of stick maneuvers, inside (0, 1).
        noise: white noise std (force [N], torque [N m]) on f_n, f_x, f_y and tau.
        dt: sample period [s] (the paper's sensor rate 500 Hz: 0.002).
        J: inertia of the slider about the CoR axis [kg m^2].
        ramp, hold, release: ranges of the ramp-up, hold and ramp-down durations [s], uniform.
        rest: unloaded time before and after the load profile [s].
        max_hold: sliding maneuvers hold the peak load for at least min(3 J / sigma_1,
            max_hold) [s], so sliders with weak viscous friction reach their target speed.
        max_substep: longest internal step of the plant [s].

    Returns:
        :class:`SyntheticSliding` (``.log`` is the :class:`lugrip.SlidingLog`).

    Raises:
        ValueError: naming the bad argument.
    """
    p = _as_params(params)
    if isinstance(n_maneuvers, bool) or int(n_maneuvers) != n_maneuvers or n_maneuvers < 1:
        raise ValueError(f"n_maneuvers = {n_maneuvers!r}: must be an integer >= 1")
    n_man = int(n_maneuvers)
    f_lo, f_hi = _pair("f_n_range", f_n_range)
    if c_range is None:
        c_range = (0.02, 2.0 * p.c_max)
    c_lo, c_hi = _pair("c_range", c_range)
    w_lo, w_hi = _pair("omega_range", omega_range)
    s_lo, s_hi = _pair("stick_load", stick_load, positive=False)
    if s_hi >= 1.0:
        raise ValueError(f"stick_load = {tuple(stick_load)!r}: must stay below 1 (inside the LS)")
    noise_f, noise_t = _pair("noise", noise, positive=False, ordered=False)
    if noise_t < 0.0:
        raise ValueError(f"noise = {tuple(noise)!r}: must be >= 0")
    if not (0.0 <= stick_fraction <= 1.0):
        raise ValueError(f"stick_fraction = {stick_fraction!r}: must be in [0, 1]")
    for name, v in (("dt", dt), ("J", J), ("max_substep", max_substep), ("max_hold", max_hold)):
        if not (math.isfinite(v) and v > 0.0):
            raise ValueError(f"{name} = {v!r}: must be finite and > 0")
    if not (math.isfinite(rest) and rest >= 0.0):
        raise ValueError(f"rest = {rest!r}: must be finite and >= 0")
    durations = {
        name: _pair(name, v) for name, v in (("ramp", ramp), ("hold", hold), ("release", release))
    }
    if durations["ramp"][0] < dt or durations["release"][0] < dt:
        raise ValueError("ramp and release must last at least one sample period")

    rng = np.random.default_rng(seed)
    # Latin-hypercube columns: every range is covered even by a small set.
    u_f, u_c, u_w, u_s = (_stratified(rng, n_man) for _ in range(4))
    f_n = f_lo + (f_hi - f_lo) * u_f
    c_abs = np.exp(math.log(c_lo) + (math.log(c_hi) - math.log(c_lo)) * u_c)
    omega_0 = np.exp(math.log(w_lo) + (math.log(w_hi) - math.log(w_lo)) * u_w)
    load_stick = s_lo + (s_hi - s_lo) * u_s
    kinds = np.array(["slide"] * n_man, dtype=object)
    n_stick = round(stick_fraction * n_man)
    kinds[rng.permutation(n_man)[:n_stick]] = "stick"
    direction = rng.choice([-1, 1], size=n_man)
    phi = rng.uniform(-math.pi, math.pi, size=n_man)
    t_ramp = rng.uniform(*durations["ramp"], size=n_man)
    t_hold = rng.uniform(*durations["hold"], size=n_man)
    t_release = rng.uniform(*durations["release"], size=n_man)
    g_all = np.asarray(_g(p, f_n, c_abs), dtype=float)
    s1_all = np.asarray(_sigma_1(p, f_n, c_abs), dtype=float)

    sim = SliderModel(p, J, max_substep=max_substep)
    pieces: dict[str, list[np.ndarray]] = {
        k: [] for k in ("f_n", "c", "tau_e", "omega", "y", "slip", "man")
    }
    designs: list[Maneuver] = []
    start = 0
    for i in range(n_man):
        g, s1 = float(g_all[i]), float(s1_all[i])
        if kinds[i] == "slide":
            w_peak = float(omega_0[i] / math.sqrt(1.0 + 2.0 * c_abs[i] ** 2))
            ratio = 1.0 + s1 * w_peak / g
        else:
            w_peak, ratio = 0.0, float(load_stick[i])
        # A slider with weak viscous friction approaches its steady speed with the time
        # constant J / sigma_1 (0.1-0.5 s with Table 2 at low forces): hold the peak load for
        # at least three of them (at most max_hold) so the target speed is reached.
        if kinds[i] == "slide":
            t_hold[i] = max(t_hold[i], min(3.0 * J / s1, max_hold))
        knots = np.cumsum([0.0, rest, t_ramp[i], t_hold[i], t_release[i], rest])
        n = math.ceil(knots[-1] / dt - 1e-9) + 1
        t = np.arange(n) * dt
        tau_e = direction[i] * ratio * g * np.interp(t, knots, [0, 0, 1, 1, 0, 0])
        sim.reset()
        tr = sim.simulate(f_n[i], c_abs[i], tau_e, dt)
        pieces["f_n"].append(np.full(n, f_n[i]))
        pieces["c"].append(np.full(n, c_abs[i]))
        pieces["tau_e"].append(tau_e)
        pieces["omega"].append(tr.omega)
        pieces["y"].append(tr.friction_torque)
        pieces["slip"].append(tr.slip)
        pieces["man"].append(np.full(n, i, dtype=np.int64))
        designs.append(
            Maneuver(
                index=i,
                kind=str(kinds[i]),
                regime=regime_of(c_abs[i], p.c_max),
                f_n=float(f_n[i]),
                c_tilde=float(c_abs[i]),
                direction=int(direction[i]),
                g=g,
                sigma_1=s1,
                load_ratio=float(ratio),
                omega_peak=w_peak,
                phi=float(phi[i]),
                start=start,
                stop=start + n,
                ramp=float(t_ramp[i]),
                hold=float(t_hold[i]),
                release=float(t_release[i]),
            )
        )
        start += n
    cat = {k: np.concatenate(v) for k, v in pieces.items()}
    n_all = cat["f_n"].size
    # Noiseless sensor wrench (object on fingertip), then the in-plane force direction.
    f_t, tau = sensor_wrench(p, cat["f_n"], cat["c"], cat["y"])
    ang = np.repeat(phi, [m.stop - m.start for m in designs])
    f_x, f_y = f_t * np.cos(ang), f_t * np.sin(ang)
    noisy = rng.standard_normal((4, n_all))
    f_n_meas = cat["f_n"] + noise_f * noisy[0]
    f_x = f_x + noise_f * noisy[1]
    f_y = f_y + noise_f * noisy[2]
    tau = tau + noise_t * noisy[3]
    config = {
        "generator": "lugrip.sliding.simulate_maneuvers",
        "params": p.to_dict(),
        "n_maneuvers": n_man,
        "seed": int(seed) if isinstance(seed, (int, np.integer)) else repr(seed),
        "f_n_range": [f_lo, f_hi],
        "c_range": [c_lo, c_hi],
        "omega_range": [w_lo, w_hi],
        "stick_fraction": float(stick_fraction),
        "stick_load": [s_lo, s_hi],
        "noise": [noise_f, noise_t],
        "dt": float(dt),
        "J": float(J),
        "ramp": list(durations["ramp"]),
        "hold": list(durations["hold"]),
        "release": list(durations["release"]),
        "rest": float(rest),
        "max_hold": float(max_hold),
        "max_substep": float(max_substep),
    }
    meta = {"generator": config, "maneuvers": [m.to_dict() for m in designs]}
    log = SlidingLog.from_arrays(
        np.arange(n_all) * dt,
        f_n_meas,
        tau,
        f_x=f_x,
        f_y=f_y,
        omega=cat["omega"],
        maneuver=cat["man"],
        meta=meta,
        check_units=False,
    )
    return SyntheticSliding(
        log=log,
        maneuvers=tuple(designs),
        slip=cat["slip"],
        friction_torque=cat["y"],
        tau_e=cat["tau_e"],
        params=p,
        config=config,
    )


def simulate_sliding(params, n_maneuvers: int = 240, *, seed: int = 0, **kwargs) -> SlidingLog:
    """The log of :func:`simulate_maneuvers` (same arguments): synthetic sliding maneuvers
    like the paper's Section 4, with ground-truth ``omega`` and ``maneuver`` columns; the
    maneuver designs are in ``log.meta["maneuvers"]``."""
    return simulate_maneuvers(params, n_maneuvers, seed=seed, **kwargs).log


# ---------------------------------------------------------------------------------------------
# scoring
# ---------------------------------------------------------------------------------------------


@dataclasses.dataclass(frozen=True)
class ManeuverScore:
    """Scores of one maneuver.

    Attributes:
        maneuver: maneuver id.
        regime: regime of the CoR (true when known, else from the observer's |c~| while
            sliding; "unknown" for stick maneuvers without a design).
        kind: "stick" for a maneuver designed to stay inside the limit surface (without a
            design: whose truth never exceeds the speed threshold), else "slide".
        slides: the truth exceeds the speed threshold somewhere (slip detection is scored on
            these; a designed slide that stays slower is scored on neither count).
        n: samples with ground truth.
        omega_peak: max |omega| of the truth [rad/s].
        rmse: RMSE of omega_hat [rad/s] over the maneuver.
        onset: time of the true slip onset [s] (NaN for stick maneuvers).
        detection: start of the S alarm that flags it [s] (NaN: missed or stick).
        delay: detection - onset [s]; negative when S warned before the slip.
        missed: a sliding maneuver without any S >= threshold at or after the onset.
        false_alarm: a stick maneuver (``kind``) with S >= threshold somewhere.
        alarm_fraction: fraction of its samples with S >= threshold.
        diverged: samples on which the observer's divergence guard re-initialised it.
        truth_delay: the same delay for the TRUE utilisation sigma0 |z| / g of the plant
            instead of S (NaN without it): how late the model itself reaches the threshold.
    """

    maneuver: int
    regime: str
    kind: str
    slides: bool
    n: int
    omega_peak: float
    rmse: float
    onset: float
    detection: float
    delay: float
    missed: bool
    false_alarm: bool
    alarm_fraction: float
    diverged: int
    truth_delay: float = math.nan


@dataclasses.dataclass(frozen=True)
class SlidingScore:
    """Summary of an observer run against ground truth.

    Attributes:
        rmse: RMSE of omega_hat over every sample with ground truth [rad/s] (the paper's
            figure: all samples of all maneuvers).
        rms_omega: RMS of the ground truth [rad/s] (an estimate of zero scores this).
        n_samples: samples scored.
        rmse_by_regime: RMSE over the sliding maneuvers of each regime, and over the stick
            maneuvers under "stick".
        maneuvers: per-maneuver scores.
        n_slide, n_detected, n_missed: sliding maneuvers, detected, missed.
        delay_median, delay_p95, delay_max: detection delays of the detected slips [s].
        truth_delay_median: median delay of the plant's own utilisation (NaN without it).
        detection_by_regime: per regime: n_slide, n_detected, delay_median, delay_p95 [s].
        n_stick, n_false_alarm: stick maneuvers and those with a false alarm.
        false_alarm_rate: fraction of stick-maneuver samples with S >= threshold.
        calm_alarm_rate: fraction of samples whose TRUE utilisation is below ``calm`` that
            have S >= threshold (NaN without the truth's slip).
        diverged: samples re-initialised by the observer's divergence guard.
        omega_threshold, s_threshold, calm: the thresholds used.
    """

    rmse: float
    rms_omega: float
    n_samples: int
    rmse_by_regime: dict
    maneuvers: tuple[ManeuverScore, ...]
    n_slide: int
    n_detected: int
    n_missed: int
    delay_median: float
    delay_p95: float
    delay_max: float
    truth_delay_median: float
    detection_by_regime: dict
    n_stick: int
    n_false_alarm: int
    false_alarm_rate: float
    calm_alarm_rate: float
    diverged: int
    omega_threshold: float
    s_threshold: float
    calm: float

    def summary(self) -> dict:
        """The scalar figures as a dict (JSON-able)."""
        out = {
            f.name: getattr(self, f.name) for f in dataclasses.fields(self) if f.name != "maneuvers"
        }
        out["rmse_by_regime"] = dict(self.rmse_by_regime)
        out["detection_by_regime"] = {k: dict(v) for k, v in self.detection_by_regime.items()}
        return out

    def lines(self) -> list[str]:
        """Human-readable summary, one figure per line."""
        out = [
            (
                f"RMSE omega_hat: {self.rmse:.4g} rad/s over {self.n_samples} samples "
                f"(RMS omega {self.rms_omega:.4g} rad/s)"
            )
        ]
        for name, value in self.rmse_by_regime.items():
            out.append(f"  {name:<12s} {value:.4g} rad/s")
        if self.n_slide:
            out.append(
                f"slip detection (|omega| > {self.omega_threshold:g} rad/s -> S >= "
                f"{self.s_threshold:g}): {self.n_detected}/{self.n_slide} detected, delay "
                f"median {1e3 * self.delay_median:.1f} ms, p95 {1e3 * self.delay_p95:.1f} ms, "
                f"max {1e3 * self.delay_max:.1f} ms"
            )
            if math.isfinite(self.truth_delay_median):
                out.append(
                    f"  (the plant's own utilisation reaches {self.s_threshold:g} "
                    f"{1e3 * self.truth_delay_median:.1f} ms after the onset, median)"
                )
        if self.n_stick:
            out.append(
                f"false alarms: {self.n_false_alarm}/{self.n_stick} stick maneuvers, "
                f"{100 * self.false_alarm_rate:.2f} % of their samples"
            )
        if math.isfinite(self.calm_alarm_rate):
            out.append(
                f"S >= {self.s_threshold:g} while the true utilisation < {self.calm:g}: "
                f"{100 * self.calm_alarm_rate:.3f} % of those samples"
            )
        if self.diverged:
            out.append(
                f"observer re-initialised by its divergence guard on {self.diverged} samples"
            )
        return out


def _percentile(v: np.ndarray, q: float) -> float:
    return float(np.percentile(v, q)) if v.size else math.nan


def slip_detection(t, omega, S, *, omega_threshold: float = 0.01, s_threshold: float = 0.9) -> dict:
    """Slip-detection figures of ONE maneuver (arrays of equal length, in time order).

    The true slip onset is the first sample with ``|omega| > omega_threshold``. The
    detection is the start of the run of ``S >= s_threshold`` that contains the onset sample
    (the indicator already warned: delay <= 0), else the first such sample after the onset;
    without one the slip is missed. Without an onset the maneuver sticks and any
    ``S >= s_threshold`` is a false alarm. NaN omega samples are ignored for the onset.

    Returns:
        dict with slides, onset, detection, delay [s] (NaN when not applicable), missed,
        false_alarm, alarm_fraction.
    """
    t = np.asarray(t, dtype=float)
    omega = np.asarray(omega, dtype=float)
    S = np.asarray(S, dtype=float)
    if not (t.shape == omega.shape == S.shape) or t.ndim != 1:
        raise ValueError(
            f"t, omega and S must be 1-D of equal length, got {t.shape}, {omega.shape}, {S.shape}"
        )
    alarm = S >= s_threshold
    sliding = np.abs(np.nan_to_num(omega, nan=0.0)) > omega_threshold
    out = {
        "slides": bool(sliding.any()),
        "onset": math.nan,
        "detection": math.nan,
        "delay": math.nan,
        "missed": False,
        "false_alarm": False,
        "alarm_fraction": float(alarm.mean()) if alarm.size else 0.0,
    }
    if not out["slides"]:
        out["false_alarm"] = bool(alarm.any())
        return out
    i0 = int(np.argmax(sliding))
    out["onset"] = float(t[i0])
    if alarm[i0]:
        before = np.flatnonzero(~alarm[: i0 + 1])
        j = int(before[-1]) + 1 if before.size else 0
    else:
        after = np.flatnonzero(alarm[i0:])
        if not after.size:
            out["missed"] = True
            return out
        j = i0 + int(after[0])
    out["detection"] = float(t[j])
    out["delay"] = float(t[j] - t[i0])
    return out


def score(
    log,
    run: ObserverRun,
    *,
    maneuvers: Sequence[Maneuver] | None = None,
    truth_slip=None,
    omega_threshold: float = 0.01,
    s_threshold: float = 0.9,
    calm: float = 0.8,
) -> SlidingScore:
    """Score an observer run against the log's ground truth ``omega``.

    Args:
        log: :class:`lugrip.SlidingLog` (or a :class:`SyntheticSliding`) with ``omega``.
        run: ``Observer.run(log)`` output, one entry per log sample.
        maneuvers: designs giving each maneuver's regime (default: a SyntheticSliding's, or
            ``log.meta["maneuvers"]`` when present, else estimated from the observer's median
            |c~| over the samples where the truth slides).
        truth_slip: true utilisation per sample (default: a SyntheticSliding's) for the
            ``calm_alarm_rate``.
        omega_threshold: |omega| above which the truth slides [rad/s].
        s_threshold: S at or above which the observer signals slip.
        calm: true utilisation below which an alarm counts against ``calm_alarm_rate``.

    Raises:
        ValueError: no ground truth or mismatched lengths.
    """
    if isinstance(log, SyntheticSliding):
        maneuvers = log.maneuvers if maneuvers is None else maneuvers
        truth_slip = log.slip if truth_slip is None else truth_slip
        log = log.log
    omega = getattr(log, "omega", None)
    if omega is None:
        raise ValueError("the log has no ground-truth 'omega' column to score against")
    omega = np.asarray(omega, dtype=float)
    n = omega.size
    if len(run) != n:
        raise ValueError(f"the run has {len(run)} samples, the log {n}")
    t = np.asarray(log.t, dtype=float)
    man = np.asarray(log.maneuver) if getattr(log, "maneuver", None) is not None else np.zeros(n)
    if maneuvers is None and isinstance(getattr(log, "meta", None), Mapping):
        raw = log.meta.get("maneuvers")
        if isinstance(raw, list) and raw and isinstance(raw[0], Mapping):
            try:
                maneuvers = [Maneuver(**m) for m in raw]
            except TypeError:
                maneuvers = None
    design = {m.index: m for m in maneuvers} if maneuvers is not None else {}
    valid = run.valid & np.isfinite(omega)
    err2 = np.where(valid, (run.omega_hat - np.nan_to_num(omega)) ** 2, 0.0)
    n_scored = int(valid.sum())
    rmse = math.sqrt(err2.sum() / n_scored) if n_scored else math.nan
    rms = math.sqrt(float(np.mean(omega[valid] ** 2))) if n_scored else math.nan

    ts = None
    if truth_slip is not None:
        ts = np.asarray(truth_slip, dtype=float)
        if ts.shape != (n,):
            raise ValueError(f"truth_slip has shape {ts.shape}, expected ({n},)")
    cuts = np.flatnonzero(man[1:] != man[:-1]) + 1
    bounds = np.concatenate(([0], cuts, [n])).astype(int)
    scores: list[ManeuverScore] = []
    regime_err: dict[str, list[float]] = {}
    regime_n: dict[str, int] = {}
    for a, b in zip(bounds[:-1], bounds[1:]):
        mid = int(man[a])
        det = slip_detection(
            t[a:b], omega[a:b], run.S[a:b], omega_threshold=omega_threshold, s_threshold=s_threshold
        )
        sel = valid[a:b]
        k = int(sel.sum())
        m_rmse = math.sqrt(err2[a:b].sum() / k) if k else math.nan
        if mid in design:
            regime = design[mid].regime
        elif det["slides"]:
            moving = np.abs(np.nan_to_num(omega[a:b])) > omega_threshold
            regime = regime_of(float(np.median(np.abs(run.c_tilde[a:b][moving]))), math.inf)
        else:
            regime = "unknown"
        if mid in design:
            kind = design[mid].kind
        else:
            kind = "slide" if det["slides"] else "stick"
        false_alarm = kind == "stick" and bool(np.any(run.S[a:b] >= s_threshold))
        key = regime if kind == "slide" else "stick"
        regime_err.setdefault(key, []).append(float(err2[a:b].sum()))
        regime_n[key] = regime_n.get(key, 0) + k
        truth_delay = math.nan
        if ts is not None and det["slides"]:
            truth_delay = slip_detection(
                t[a:b],
                omega[a:b],
                ts[a:b],
                omega_threshold=omega_threshold,
                s_threshold=s_threshold,
            )["delay"]
        w = np.abs(omega[a:b][np.isfinite(omega[a:b])])
        scores.append(
            ManeuverScore(
                maneuver=mid,
                regime=regime,
                kind=kind,
                slides=det["slides"],
                n=k,
                omega_peak=float(w.max()) if w.size else math.nan,
                rmse=m_rmse,
                onset=det["onset"],
                detection=det["detection"],
                delay=det["delay"],
                missed=det["missed"],
                false_alarm=false_alarm,
                alarm_fraction=det["alarm_fraction"],
                diverged=int(run.diverged[a:b].sum()),
                truth_delay=truth_delay,
            )
        )
    order = [r for r in REGIMES if r in regime_err] + sorted(
        r for r in regime_err if r not in REGIMES
    )
    by_regime = {
        r: (math.sqrt(sum(regime_err[r]) / regime_n[r]) if regime_n[r] else math.nan) for r in order
    }
    slides = [s for s in scores if s.slides]
    sticks = [s for s in scores if s.kind == "stick"]
    delays = np.array([s.delay for s in slides if not s.missed])
    stick_mask = np.zeros(n, dtype=bool)
    for s, a, b in zip(scores, bounds[:-1], bounds[1:]):
        if s.kind == "stick":
            stick_mask[a:b] = True
    alarm = run.S >= s_threshold
    far = float(alarm[stick_mask].mean()) if stick_mask.any() else math.nan
    by_regime_det = {}
    for r in order:
        group = [s for s in slides if s.regime == r]
        if not group:
            continue
        d = np.array([s.delay for s in group if not s.missed])
        by_regime_det[r] = {
            "n_slide": len(group),
            "n_detected": int(d.size),
            "delay_median": _percentile(d, 50),
            "delay_p95": _percentile(d, 95),
        }
    truth_delays = np.array([s.truth_delay for s in slides if math.isfinite(s.truth_delay)])
    calm_rate = math.nan
    if ts is not None:
        sel = (ts < calm) & run.valid
        calm_rate = float(alarm[sel].mean()) if sel.any() else math.nan
    return SlidingScore(
        rmse=rmse,
        rms_omega=rms,
        n_samples=n_scored,
        rmse_by_regime=by_regime,
        maneuvers=tuple(scores),
        n_slide=len(slides),
        n_detected=int(delays.size),
        n_missed=sum(s.missed for s in slides),
        delay_median=_percentile(delays, 50),
        delay_p95=_percentile(delays, 95),
        delay_max=float(delays.max()) if delays.size else math.nan,
        truth_delay_median=_percentile(truth_delays, 50),
        detection_by_regime=by_regime_det,
        n_stick=len(sticks),
        n_false_alarm=sum(s.false_alarm for s in sticks),
        false_alarm_rate=far,
        calm_alarm_rate=calm_rate,
        diverged=int(run.diverged.sum()),
        omega_threshold=float(omega_threshold),
        s_threshold=float(s_threshold),
        calm=float(calm),
    )


def evaluate(
    data,
    params=None,
    *,
    observer: Observer | None = None,
    omega_threshold: float = 0.01,
    s_threshold: float = 0.9,
    calm: float = 0.8,
    **observer_settings,
) -> tuple[ObserverRun, SlidingScore]:
    """Run an observer over ``data`` (SyntheticSliding or SlidingLog with ``omega``) and score
    it (:func:`score`).

    Args:
        params: the observer's parameters (default: the SyntheticSliding's true ones):
            ContactParams, a preset name, a dict or a parameter YAML file; a file's
            ``observer:`` block (written by ``lugrip identify``) is the base of the settings.
        observer: a ready :class:`lugrip.Observer` (then ``params`` and settings are unused).
        observer_settings: keywords of :class:`lugrip.Observer` (integrator, gain, bandwidth,
            ...), overriding the file's observer block; none: the block, else the defaults.
            The nominal dt is always the log's sample period.

    Returns:
        (run, score).
    """
    log = data.log if isinstance(data, SyntheticSliding) else data
    if observer is None:
        if params is None:
            if not isinstance(data, SyntheticSliding):
                raise ValueError("evaluate: give params (or an observer) for a plain log")
            params = data.params
        observer = Observer(
            params, dt=float(log.sample_period) if len(log) > 1 else 0.002, **observer_settings
        )
    elif observer_settings:
        raise ValueError("evaluate: give either an observer or observer settings, not both")
    run = observer.run(log)
    return run, score(
        data, run, omega_threshold=omega_threshold, s_threshold=s_threshold, calm=calm
    )
