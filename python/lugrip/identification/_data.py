"""Maneuvers from logs (gap-free segments, one observer run each) and the C++ cost over them."""

from __future__ import annotations

import dataclasses
import os
import warnings
from collections.abc import Mapping, Sequence

import numpy as np

from .. import _core
from .._observer import GAIN_MODES, INTEGRATORS, Observer
from .._params import ContactParams
from ..io import SlidingLog, read_log
from ._common import PARAMETERS, IdentificationError, IdentificationWarning


@dataclasses.dataclass
class _Maneuver:
    key: str  # "<source>#<maneuver id>" (a repeated id gets "/2", "/3", ...)
    f_n: np.ndarray
    f_t: np.ndarray
    tau: np.ndarray
    dt: np.ndarray  # 0 at each segment start
    omega: np.ndarray
    t: np.ndarray
    starts: np.ndarray  # segment starts within the maneuver (first 0), plus its length
    f_x: np.ndarray | None = None  # in-plane force components [N] when the log has them
    f_y: np.ndarray | None = None

    @property
    def n(self) -> int:
        return len(self.f_n)


def _as_logs(logs) -> list[SlidingLog]:
    if isinstance(logs, (SlidingLog, str, os.PathLike, Mapping)):
        logs = [logs]
    out = []
    for item in logs:
        if isinstance(item, SlidingLog):
            out.append(item)
        elif isinstance(item, (str, os.PathLike)):
            out.append(read_log(item, allow_gaps=True))
        elif isinstance(item, Mapping):
            cols = {
                k: item[k]
                for k in ("t", "f_n", "tau", "f_t", "f_x", "f_y", "omega", "maneuver")
                if k in item and item[k] is not None
            }
            if "t" not in cols and "f_n" in cols:
                cols["t"] = np.arange(len(np.asarray(cols["f_n"]))) * 0.002
            missing = [k for k in ("f_n", "tau") if k not in cols]
            if missing:
                raise IdentificationError(f"log mapping is missing {', '.join(missing)}")
            out.append(SlidingLog.from_arrays(**cols, allow_gaps=True, check_units=False))
        else:
            raise TypeError(
                f"expected SlidingLog, a path or a mapping of arrays, got {type(item).__name__}"
            )
    if not out:
        raise IdentificationError("no logs given")
    return out


def load_maneuvers(
    logs, *, max_gap: float | None = None, min_segment: int = 10, require_omega: bool = True
) -> list[_Maneuver]:
    """Split logs into maneuvers (contiguous blocks of one maneuver id) and their gap-free
    segments (:meth:`lugrip.SlidingLog.segments`: split at non-finite samples and at time
    steps above ``max_gap``). Segments shorter than ``min_segment`` samples are dropped.

    Raises:
        IdentificationError: a log without ground-truth ``omega`` (when ``require_omega``) or
            without any usable segment.
    """
    out: list[_Maneuver] = []
    seen: dict[str, int] = {}
    dropped_short = dropped_invalid = 0
    for j, log in enumerate(_as_logs(logs)):
        name = log.source or f"log{j}"
        if require_omega and (log.omega is None or not np.any(np.isfinite(log.omega))):
            ros = ("; in a ROS bag or MCAP the ground truth is a topic of its own: name it "
                   "with --omega-topic TOPIC (Python: omega_topic=), a TwistStamped, "
                   "Vector3Stamped, Float64 or a PoseStamped to differentiate"
                   if "wrench_topic" in log.meta and "omega_topic" not in log.meta else "")
            if ros and log.meta.get("omega_candidates"):
                ros += f" (this recording has: {', '.join(log.meta['omega_candidates'])})"
            raise IdentificationError(
                f"{name}: no ground-truth 'omega' column (sliding velocity [rad/s]): "
                "identification minimises the observer's velocity error and needs it "
                "(eq. 32); record the slider's angular velocity, e.g. from the robot's "
                "encoders" + ros
            )
        dropped_invalid += int(np.count_nonzero(~log.valid))
        segs = log.segments(max_gap)
        omega = log.omega if log.omega is not None else np.full(len(log), np.nan)
        man = log.maneuver
        by_block: dict[int, list[tuple[int, int]]] = {}
        cut = np.flatnonzero(man[1:] != man[:-1]) + 1
        block_of = np.zeros(len(log), dtype=np.int64)
        block_of[cut] = 1
        block_of = np.cumsum(block_of)
        for a, b in segs:
            if b - a < min_segment:
                dropped_short += b - a
                continue
            by_block.setdefault(int(block_of[a]), []).append((a, b))
        for blk in sorted(by_block):
            parts = by_block[blk]
            mid = int(man[parts[0][0]])
            base = f"{name}#{mid}"
            seen[base] = seen.get(base, 0) + 1
            key = base if seen[base] == 1 else f"{base}/{seen[base]}"
            idx = np.concatenate([np.arange(a, b) for a, b in parts])
            dt = np.zeros(idx.size)
            starts = [0]
            pos = 0
            for a, b in parts:
                if b - a > 1:
                    dt[pos + 1 : pos + b - a] = np.diff(log.t[a:b])
                pos += b - a
                starts.append(pos)
            out.append(
                _Maneuver(
                    key=key,
                    f_n=log.f_n[idx],
                    f_t=log.f_t[idx],
                    tau=log.tau[idx],
                    dt=dt,
                    omega=np.asarray(omega[idx], dtype=float),
                    t=log.t[idx],
                    starts=np.asarray(starts, dtype=np.int64),
                    f_x=None if log.f_x is None else log.f_x[idx],
                    f_y=None if log.f_y is None else log.f_y[idx],
                )
            )
    if not out:
        raise IdentificationError(
            f"no usable samples: every segment is shorter than {min_segment} samples or invalid"
        )
    if dropped_invalid or dropped_short:
        warnings.warn(
            f"{dropped_invalid} non-finite sample(s) and {dropped_short} sample(s) in segments "
            f"shorter than {min_segment} samples left out; the observer restarts after every "
            "gap and is never integrated across one",
            IdentificationWarning,
            stacklevel=3,
        )
    return out


class _Problem:
    """A set of maneuvers as one C++ IdentificationProblem (weights: each maneuver counts the
    same with ``weighting='maneuver'``, each sample with ``'sample'``)."""

    def __init__(self, maneuvers: Sequence[_Maneuver], settings, weighting: str):
        self.maneuvers = list(maneuvers)
        cat = lambda name: np.ascontiguousarray(
            np.concatenate([getattr(m, name) for m in self.maneuvers]), dtype=np.float64
        )
        self.omega = cat("omega")
        n_scored = [int(np.count_nonzero(np.isfinite(m.omega))) for m in self.maneuvers]
        total = sum(n_scored)
        weights = []
        for m, k in zip(self.maneuvers, n_scored):
            if weighting == "maneuver":
                w = total / (len(self.maneuvers) * k) if k else 0.0
            else:
                w = 1.0
            weights.append(np.full(m.n, w))
        self.weight = np.concatenate(weights)
        starts, seg_owner, offset = [], [], 0
        for i, m in enumerate(self.maneuvers):
            starts.extend((m.starts[:-1] + offset).tolist())
            seg_owner.extend([i] * (len(m.starts) - 1))
            offset += m.n
        starts.append(offset)
        self.segment_owner = np.asarray(seg_owner, dtype=np.int64)
        self.offsets = np.cumsum([0] + [m.n for m in self.maneuvers])
        self.core = _core.IdentificationProblem(
            cat("f_n"),
            cat("f_t"),
            cat("tau"),
            cat("dt"),
            self.omega,
            self.weight,
            np.asarray(starts, dtype=np.int64),
            settings,
        )
        self.evaluations = 0

    @property
    def samples(self) -> int:
        return int(self.core.samples)

    def evaluate(self, params: ContactParams, derivatives: bool = True, omega_hat: bool = False):
        self.evaluations += 1
        return self.core.evaluate(params.to_core(), derivatives, omega_hat)

    def per_maneuver(self, ev) -> tuple[np.ndarray, np.ndarray]:
        """(sse, count) per maneuver from the per-segment sums."""
        m = len(self.maneuvers)
        sse = np.bincount(self.segment_owner, weights=ev["segment_sse"], minlength=m)
        cnt = np.bincount(self.segment_owner, weights=ev["segment_count"], minlength=m)
        return sse, cnt

    def maneuver_gradients(self, ev) -> np.ndarray:
        g = np.asarray(ev["segment_gradient"]).reshape(-1, len(PARAMETERS))
        out = np.zeros((len(self.maneuvers), len(PARAMETERS)))
        np.add.at(out, self.segment_owner, g)
        return out


def _observer_settings(observer, params: ContactParams):
    """Core ObserverSettings from None, a dict of :class:`lugrip.Observer` keywords or an
    Observer (its settings; the parameters are not used)."""
    if observer is None:
        obs = Observer(params)
    elif isinstance(observer, Observer):
        obs = observer
    elif isinstance(observer, Mapping):
        obs = Observer(params, **dict(observer))
    else:
        raise TypeError("observer must be None, a dict of Observer settings or an Observer")
    d = obs.settings
    s = _core.ObserverSettings()
    for name, value in d.items():
        if name == "integrator":
            s.integrator = INTEGRATORS[value]
        elif name == "gain_mode":
            s.gain_mode = GAIN_MODES[value]
        elif hasattr(s.cor, name) and not hasattr(s, name):
            cor = s.cor
            setattr(cor, name, value)
            s.cor = cor
        else:
            setattr(s, name, value)
    return s, d
