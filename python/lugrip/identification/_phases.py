"""What each sample of a log is doing, found from the wrench and the motion together, and the
sensor noise measured where the finger stands still (docs/model.md §8).

A sample is *still* where the ground-truth |omega| is below a small fraction of the
maneuver's peak; every contiguous block of motion in one direction is a *run*. Within a run
the friction first builds up (presliding, the bristles load) and then stops growing while the
motion goes on (gross sliding). The build-up is measured against the slip angle
s = integral |omega| dt since the run start: a load signal (the in-plane force along its
direction in the run, or the torque, whichever stands further above the noise, per unit
normal force) rises from zero (or from the opposite load after a reversal: from its zero
crossing) to 90 % of its plateau over a slip angle s_b, and the samples beyond twice that
count as gross sliding when the load no longer grows there and the run slips on over at least
another s_b (a creep that dies out under a held load is not sliding). No speed threshold decides where sliding starts:
a robot that prescribes the motion moves from the first sample on, while the friction only
reaches the limit surface after the presliding distance.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from ._data import _Maneuver

__all__ = ["LOADING", "SLIDING", "STILL", "Noise", "estimate_noise", "find_phases", "runs"]

STILL, LOADING, SLIDING = 0, 1, 2

_MOTION_FRACTION = 0.05  # |omega| above this fraction of the maneuver's peak: moving [-]
_MOTION_FLOOR = 1.0e-4  # ... and above this [rad/s]
_SMOOTH = 7  # samples of the centred moving average of the load signal
_REACHED = 0.9  # fraction of the plateau that ends the build-up [-]
_SETTLE = 2.0  # gross sliding from this multiple of the build-up slip angle [-]
_GROWTH = 0.1  # largest rise of the load over the sliding part, as a fraction of it [-]
_UNLOADED = 3.0  # a run whose load exceeds its plateau this many times is an unloading [-]
_MIN_RUN = 10  # samples of a run (shorter ones are loading at most)
_MIN_STILL = 20  # samples of a still block used for the noise


def _moving_average(x: np.ndarray, w: int) -> np.ndarray:
    if x.size < w or w <= 1:
        return x.copy()
    k = np.ones(w) / w
    pad = w // 2
    xp = np.concatenate([np.full(pad, x[0]), x, np.full(pad, x[-1])])
    return np.convolve(xp, k, mode="valid")


def runs(m: _Maneuver) -> list[tuple[int, int]]:
    """[a, b) blocks of motion in one direction inside one gap-free segment."""
    w = np.nan_to_num(m.omega, nan=0.0)
    peak = float(np.max(np.abs(w))) if w.size else 0.0
    eps = max(_MOTION_FRACTION * peak, _MOTION_FLOOR)
    sgn = np.where(np.abs(w) > eps, np.sign(w), 0.0)
    out = []
    for a0, b0 in zip(m.starts[:-1], m.starts[1:]):
        s = sgn[a0:b0]
        edge = np.flatnonzero(np.diff(s) != 0) + 1
        bounds = np.concatenate([[0], edge, [s.size]])
        for a, b in zip(bounds[:-1], bounds[1:]):
            if s[a] != 0:
                out.append((int(a0 + a), int(a0 + b)))
    return out


@dataclasses.dataclass(frozen=True)
class Noise:
    """Sensor noise measured on still samples (first differences, robust scale).

    Attributes:
        torque, force: standard deviations of tau [N m] and of the in-plane force [N];
            NaN when the log has no still stretch long enough.
        samples: still samples used.
    """

    torque: float
    force: float
    samples: int


def estimate_noise(mans: list[_Maneuver], phases: list[np.ndarray]) -> Noise:
    """White-noise level of tau and f_t from the still stretches (>= 20 samples) of the logs:
    1.4826 MAD of the first differences / sqrt(2), insensitive to slow drifts and offsets."""
    d_tau, d_f = [], []
    n = 0
    for m, ph in zip(mans, phases):
        still = ph == STILL
        edge = np.flatnonzero(np.diff(still.astype(np.int8)) != 0) + 1
        bounds = np.concatenate([[0], edge, [still.size]])
        seg_start = {int(v) for v in m.starts[1:-1]}
        for a, b in zip(bounds[:-1], bounds[1:]):
            if not still[a] or b - a < _MIN_STILL:
                continue
            cut = [a] + sorted(v for v in seg_start if a < v < b) + [b]
            for c0, c1 in zip(cut[:-1], cut[1:]):
                if c1 - c0 < 3:
                    continue
                d_tau.append(np.diff(m.tau[c0:c1]))
                if m.f_x is not None:
                    d_f.append(np.diff(m.f_x[c0:c1]))
                    d_f.append(np.diff(m.f_y[c0:c1]))
                else:
                    d_f.append(np.diff(m.f_t[c0:c1]))
                n += c1 - c0

    def scale(parts):
        if not parts:
            return math.nan
        d = np.concatenate(parts)
        d = d[np.isfinite(d)]
        if d.size < 10:
            return math.nan
        return float(1.4826 * np.median(np.abs(d - np.median(d))) / math.sqrt(2.0))

    return Noise(torque=scale(d_tau), force=scale(d_f), samples=n)


def _load_signal(m: _Maneuver, a: int, b: int, s: np.ndarray, noise: Noise) -> np.ndarray:
    """The load of run [a, b) per unit normal force, normalised by its plateau (1 there)."""
    fn = np.maximum(m.f_n[a:b], 1e-9)
    late = s >= 0.5 * s[-1]
    if m.f_x is not None:
        ux, uy = float(np.mean(m.f_x[a:b][late])), float(np.mean(m.f_y[a:b][late]))
        nrm = math.hypot(ux, uy)
        q_f = (m.f_x[a:b] * ux + m.f_y[a:b] * uy) / nrm / fn if nrm > 0 else m.f_t[a:b] / fn
    else:
        q_f = m.f_t[a:b] / fn
    q_t = m.tau[a:b] / fn
    q_f, q_t = _moving_average(q_f, _SMOOTH), _moving_average(q_t, _SMOOTH)
    p_f, p_t = float(np.median(q_f[late])), float(np.median(q_t[late]))
    f_med = float(np.median(fn))
    sf = (noise.force if math.isfinite(noise.force) else 0.01) / f_med
    st = (noise.torque if math.isfinite(noise.torque) else 1e-5) / f_med
    snr_f = abs(p_f) / max(sf, 1e-12)
    snr_t = abs(p_t) / max(st, 1e-15)
    if snr_f >= snr_t:
        return q_f / p_f if p_f != 0 else np.zeros_like(q_f)
    return q_t / p_t if p_t != 0 else np.zeros_like(q_t)


def find_phases(m: _Maneuver, noise: Noise, min_slip=None) -> np.ndarray:
    """Per sample of a maneuver: STILL (0), LOADING (1: moving, friction still building up)
    or SLIDING (2: moving, the friction has stopped growing).

    ``min_slip(m, a, b)``, when given, is the slip angle [rad] a run [a, b) needs beyond the
    start of its build-up before it can slide (e.g. 4.6 g / sigma0 once sigma0 is known: the
    bristles within 1 % of their bound even where a viscous part dominates the load)."""
    ph = np.zeros(m.n, dtype=np.int8)
    for a, b in runs(m):
        ph[a:b] = LOADING
        if b - a < _MIN_RUN:
            continue
        w = np.abs(np.nan_to_num(m.omega[a:b]))
        dt = np.concatenate([[0.0], m.dt[a + 1 : b]])
        s = np.cumsum(w * dt)
        if not s[-1] > 0:
            continue
        load = _load_signal(m, a, b, s, noise)
        # the build-up starts at the lowest load of the first half (zero, or the opposite
        # load after a reversal); its length is measured from the zero crossing to 90 %
        if not np.all(np.isfinite(load)) or float(np.max(np.abs(load))) > _UNLOADED:
            continue  # the plateau is small against earlier loads: an unloading, not sliding
        first = np.flatnonzero(s <= 0.5 * s[-1])
        j_min = int(first[np.argmin(load[first])]) if first.size else 0
        up = np.flatnonzero(load[j_min:] >= 0.0)
        reached = np.flatnonzero(load[j_min:] >= _REACHED)
        if reached.size == 0 or up.size == 0:
            continue
        s0, s90 = s[j_min + up[0]], s[j_min + reached[0]]
        s_slide = s90 + (_SETTLE - 1.0) * (s90 - s0)
        if min_slip is not None:
            req = min_slip(m, a, b)
            if req is not None and math.isfinite(req):
                s_slide = max(s_slide, s[j_min] + req)
        slide = s >= max(s_slide, s[min(_SMOOTH, b - a - 1)])
        if not slide.any() or s_slide > 0.75 * s[-1] or s[-1] - s_slide < s90 - s0:
            continue  # no plateau, or it slipped less than the build-up: creep, not sliding
        part = load[slide]
        q = max(part.size // 4, 1)
        if float(np.median(part[-q:])) - float(np.median(part[:q])) > _GROWTH:
            continue  # still growing: a long presliding, not sliding
        ph[a:b][slide] = SLIDING
    return ph
