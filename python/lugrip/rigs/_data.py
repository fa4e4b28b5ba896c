"""Common types of the rubbing rigs: what a plant knows about itself (:class:`RigTruth`) and
what a rubbing run produces (:class:`RubbingData`: the sensor log plus per-sample labels).

Sign conventions are those of docs/sliding_log.md: the log holds the wrench the slider
exerts on the fingertip (what the fingertip's force/torque sensor reads), ``omega`` is the
angular velocity of the slider relative to the fingertip about the sensor's z axis.
"""

from __future__ import annotations

import dataclasses
import json
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..io import SlidingLog, read_log, write_log

__all__ = ["PHASES", "RigTruth", "RubbingData"]

#: Phase labels of :attr:`RubbingData.phase` (value -> name).
PHASES: dict[int, str] = {
    0: "approach",  # pressed but no tangential motion commanded yet
    1: "presliding",  # motion under way, the contact is not (or no longer) fully sliding
    2: "sliding",  # gross sliding: the whole contact slides
    3: "rest",  # motion stopped for good, the contact stays loaded
}

_LOG_NAME = "log"
_LABELS_NAME = "labels.npz"
_TRUTH_NAME = "truth.json"


@dataclasses.dataclass(frozen=True)
class RigTruth:
    """What is true in a rubbing plant, stated by the plant from its own physics.

    Attributes:
        name: plant name (e.g. ``"grid-stribeck"``).
        mu_static: static (breakaway) friction coefficient [-].
        mu_kinetic: kinetic friction coefficient at full sliding [-].
        mu: the nominal Coulomb coefficient a limit-surface model should find [-]: for a
            Coulomb plant its only value, for a Stribeck plant the kinetic one.
        beta_a: viscous shear per unit area and unit sliding speed [N s/m^3], uniform over
            the patch; None when the plant has none.
        viscous: True when the sliding wrench carries speed information (a viscous term
            large enough to be seen), False for Coulomb or Stribeck contacts.
        delta: true contact-radius law coefficient, rho = delta * f_n**gamma [m/N^gamma].
        gamma: true contact-radius law exponent [-].
        pressure: the plant's pressure distribution, in words (e.g. ``"Hertzian"``).
        tau_max_points: (f_n [N], tau_max [N m]) pairs of the plant's torsional capacity in
            pure rotation about the patch centre at kinetic friction, computed by the plant
            from its own contact (for the grid plant: the sum of mu_k p_i A_i r_i over its
            cells); :meth:`tau_max` interpolates them.
        notes: free text about the plant (what is and what is not modelled).
    """

    name: str
    mu_static: float
    mu_kinetic: float
    mu: float
    beta_a: float | None
    viscous: bool
    delta: float
    gamma: float
    pressure: str
    tau_max_points: tuple[tuple[float, float], ...]
    notes: str = ""

    def __post_init__(self):
        pts = tuple((float(f), float(t)) for f, t in self.tau_max_points)
        if len(pts) < 1:
            raise ValueError("RigTruth.tau_max_points: at least one (f_n, tau_max) pair needed")
        if any(not (f > 0.0 and t > 0.0 and math.isfinite(f) and math.isfinite(t))
               for f, t in pts):
            raise ValueError("RigTruth.tau_max_points: f_n and tau_max must be finite and > 0")
        pts = tuple(sorted(pts))
        if len({f for f, _ in pts}) != len(pts):
            raise ValueError("RigTruth.tau_max_points: repeated f_n")
        object.__setattr__(self, "tau_max_points", pts)
        for name in ("mu_static", "mu_kinetic", "mu", "delta", "gamma"):
            v = float(getattr(self, name))
            if not (math.isfinite(v) and v > 0.0):
                raise ValueError(f"RigTruth.{name} = {v!r}: must be finite and > 0")
            object.__setattr__(self, name, v)
        if self.beta_a is not None:
            object.__setattr__(self, "beta_a", float(self.beta_a))
        object.__setattr__(self, "viscous", bool(self.viscous))

    @classmethod
    def coulomb(cls, name: str, mu: float, *, delta: float, gamma: float, pressure: str,
                tau_max_points, notes: str = "") -> RigTruth:
        """The truth of an engine's Coulomb pad (MuJoCo's, Drake's): one friction coefficient
        ``mu`` (static = kinetic = nominal), no viscous shear."""
        return cls(name=name, mu_static=mu, mu_kinetic=mu, mu=mu, beta_a=None, viscous=False,
                   delta=delta, gamma=gamma, pressure=pressure,
                   tau_max_points=tuple(tau_max_points), notes=notes)

    def rho(self, f_n) -> np.ndarray | float:
        """True contact radius delta * f_n**gamma [m]."""
        out = self.delta * np.asarray(f_n, dtype=float) ** self.gamma
        return float(out) if np.ndim(out) == 0 else out

    def tau_max(self, f_n) -> np.ndarray | float:
        """Torsional capacity [N m] in pure rotation about the patch centre at kinetic
        friction, interpolated log-log between the plant's own points (exact for a power
        law; extrapolated with the end segments' slopes, or with slope 1 + gamma when the
        plant gave a single point)."""
        f = np.asarray(f_n, dtype=float)
        if np.any(~(f > 0.0)):
            raise ValueError("RigTruth.tau_max: f_n must be > 0")
        lf = np.array([math.log(p[0]) for p in self.tau_max_points])
        lt = np.array([math.log(p[1]) for p in self.tau_max_points])
        x = np.log(f)
        if len(lf) == 1:
            out = np.exp(lt[0] + (1.0 + self.gamma) * (x - lf[0]))
        else:
            y = np.interp(x, lf, lt)
            lo_slope = (lt[1] - lt[0]) / (lf[1] - lf[0])
            hi_slope = (lt[-1] - lt[-2]) / (lf[-1] - lf[-2])
            y = np.where(x < lf[0], lt[0] + lo_slope * (x - lf[0]), y)
            y = np.where(x > lf[-1], lt[-1] + hi_slope * (x - lf[-1]), y)
            out = np.exp(y)
        return float(out) if np.ndim(out) == 0 else out

    def to_dict(self) -> dict[str, Any]:
        d = dataclasses.asdict(self)
        d["tau_max_points"] = [list(p) for p in self.tau_max_points]
        return d

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> RigTruth:
        d = dict(d)
        d["tau_max_points"] = tuple(tuple(p) for p in d["tau_max_points"])
        return cls(**d)


def _labels(name: str, values, n: int, dtype) -> np.ndarray:
    a = np.array(values, dtype=dtype, copy=True)
    if a.shape != (n,):
        raise ValueError(f"RubbingData.{name}: shape {a.shape}, expected ({n},) like the log")
    a.setflags(write=False)
    return a


@dataclasses.dataclass(frozen=True)
class RubbingData:
    """One rubbing run: the sensor log, per-sample ground truth and the plant's truth.

    Attributes:
        log: the sensor log (wrench the slider exerts on the fingertip, true ``omega`` of the
            slider relative to the fingertip about the sensor z, ``maneuver`` ids).
        phase: int8 per sample, :data:`PHASES`: 0 approach (pressed, no motion yet),
            1 presliding (motion started, contact not fully sliding), 2 gross sliding,
            3 loaded rest after the motion stopped.
        load_ratio: the plant's true friction utilisation per sample [-]: the friction torque
            about the prescribed CoR divided by the plant's full-sliding torque about that
            CoR at static friction (0 unloaded, about 1 at breakaway; may exceed 1 slightly
            with a viscous shear).
        c_tilde_true: prescribed CoR divided by the true contact radius, signed as in the
            sensor frame (y along the in-plane force, x = y cross z: sign(c~) = -sign(omega)).
        v_true: true translational slip speed of the patch centre [m/s] (>= 0).
        truth: what is true in the plant (:class:`RigTruth`).
        meta: free information (design, seed, plant settings, generation time).
    """

    log: SlidingLog
    phase: np.ndarray
    load_ratio: np.ndarray
    c_tilde_true: np.ndarray
    v_true: np.ndarray
    truth: RigTruth
    meta: Mapping[str, Any] = dataclasses.field(default_factory=dict)

    def __post_init__(self):
        n = len(self.log)
        object.__setattr__(self, "phase", _labels("phase", self.phase, n, np.int8))
        object.__setattr__(self, "load_ratio", _labels("load_ratio", self.load_ratio, n, float))
        object.__setattr__(self, "c_tilde_true",
                           _labels("c_tilde_true", self.c_tilde_true, n, float))
        object.__setattr__(self, "v_true", _labels("v_true", self.v_true, n, float))
        if np.any((self.phase < 0) | (self.phase > 3)):
            raise ValueError("RubbingData.phase: labels must be 0, 1, 2 or 3")
        object.__setattr__(self, "meta", dict(self.meta))

    def __len__(self) -> int:
        return len(self.log)

    @property
    def gross_sliding(self) -> np.ndarray:
        """Mask of the gross-sliding samples (phase 2)."""
        return self.phase == 2

    def presliding_durations(self) -> np.ndarray:
        """Time from the motion start (first presliding sample) to the first gross-sliding
        sample, per maneuver that reaches gross sliding [s]."""
        out = []
        for m in np.unique(self.log.maneuver):
            sel = self.log.maneuver == m
            ph, t = self.phase[sel], self.log.t[sel]
            if np.any(ph == 2):
                out.append(t[np.flatnonzero(ph == 2)[0]] - t[np.flatnonzero(ph == 1)[0]])
        return np.asarray(out)

    def stick_below(self, ratio: float = 0.7) -> np.ndarray:
        """Mask of the samples not in gross sliding (phases 0, 1, 3) whose true load ratio is
        below ``ratio`` of the static friction limit."""
        return (self.phase != 2) & (self.load_ratio < float(ratio))

    def select_maneuvers(self, ids: Sequence[int]) -> RubbingData:
        """The samples of the given maneuver ids (e.g. a held-out set)."""
        mask = np.isin(self.log.maneuver, np.asarray(list(ids), dtype=np.int64))
        return dataclasses.replace(
            self, log=self.log.select(mask), phase=self.phase[mask],
            load_ratio=self.load_ratio[mask], c_tilde_true=self.c_tilde_true[mask],
            v_true=self.v_true[mask])

    def save(self, directory: str | Path, *, overwrite: bool = False,
             format: str | None = None) -> Path:
        """Write the run into ``directory``: ``log.parquet`` (``log.csv`` when pyarrow is
        missing or ``format="csv"``) via :func:`lugrip.write_log`, ``labels.npz`` (phase,
        load_ratio, c_tilde_true, v_true) and ``truth.json`` (truth and meta)."""
        d = Path(directory)
        d.mkdir(parents=True, exist_ok=True)
        if format is None:
            try:
                import pyarrow  # noqa: F401
                format = "parquet"
            except ImportError:
                format = "csv"
        if format not in ("csv", "parquet"):
            raise ValueError(f"RubbingData.save: format must be 'csv' or 'parquet', not {format!r}")
        targets = [d / f"{_LOG_NAME}.{format}", d / _LABELS_NAME, d / _TRUTH_NAME]
        if not overwrite:
            for p in targets:
                if p.exists():
                    raise FileExistsError(f"{p} exists (pass overwrite=True to replace it)")
        for stale in (d / f"{_LOG_NAME}.csv", d / f"{_LOG_NAME}.parquet"):
            if stale != targets[0] and stale.exists() and overwrite:
                stale.unlink()
        write_log(self.log, targets[0], overwrite=overwrite)
        np.savez(targets[1], phase=self.phase, load_ratio=self.load_ratio,
                 c_tilde_true=self.c_tilde_true, v_true=self.v_true)
        targets[2].write_text(json.dumps({"truth": self.truth.to_dict(),
                                          "meta": _jsonable(self.meta)}, indent=2) + "\n")
        return d

    @classmethod
    def load(cls, directory: str | Path) -> RubbingData:
        """Read a run written by :meth:`save`."""
        d = Path(directory)
        logs = [p for p in (d / f"{_LOG_NAME}.parquet", d / f"{_LOG_NAME}.csv") if p.exists()]
        if not logs:
            raise FileNotFoundError(f"{d}: no {_LOG_NAME}.parquet or {_LOG_NAME}.csv")
        log = read_log(logs[0])
        with np.load(d / _LABELS_NAME) as z:
            labels = {k: z[k] for k in ("phase", "load_ratio", "c_tilde_true", "v_true")}
        info = json.loads((d / _TRUTH_NAME).read_text())
        return cls(log=log, truth=RigTruth.from_dict(info["truth"]),
                   meta=info.get("meta", {}), **labels)


def _jsonable(x):
    if isinstance(x, Mapping):
        return {str(k): _jsonable(v) for k, v in x.items()}
    if dataclasses.is_dataclass(x) and not isinstance(x, type):
        return _jsonable(dataclasses.asdict(x))
    if isinstance(x, (list, tuple)):
        return [_jsonable(v) for v in x]
    if isinstance(x, np.ndarray):
        return x.tolist()
    if isinstance(x, (np.floating, np.integer, np.bool_)):
        return x.item()
    if isinstance(x, float) and not math.isfinite(x):
        return str(x)
    return x
