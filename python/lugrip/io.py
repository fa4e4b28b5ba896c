"""Sliding logs: one fingertip's wrench over time, read from and written to files.

The format (docs/sliding_log.md) is one table per file, SI units, one row per sensor sample:

========  =======  ========  ===========================================================
column    unit     required  meaning
========  =======  ========  ===========================================================
t         s        yes       sample time, strictly increasing
f_n       N        yes       normal force, > 0 in contact (z along the contact normal)
f_x, f_y  N        [1]_      in-plane force in the fingertip frame
f_t       N        [1]_      tangential force magnitude, >= 0
tau       N m      yes       torsional moment about the contact normal (z)
omega     rad/s    no        ground-truth sliding velocity about z (NaN: unknown)
maneuver  integer  no        maneuver id (default 0)
========  =======  ========  ===========================================================

.. [1] either ``f_x`` and ``f_y`` (then ``f_t = hypot(f_x, f_y)``) or ``f_t``.

All forces are the wrench the object exerts on the fingertip, i.e. what the fingertip sensor
reads (MODEL.md section 7.2). :func:`read_log` reads CSV and Parquet tables, MCAP files and
ROS 1 / ROS 2 bags holding ``geometry_msgs/WrenchStamped`` messages (no ROS installation
needed: ``mcap`` and ``rosbags`` from PyPI); :func:`write_log` writes CSV, Parquet and MCAP
(ROS 2 CDR). Malformed files raise :class:`LogError`, whose message names the file, the row
(spreadsheet numbering: header = row 1) or message, and the column.
"""

from __future__ import annotations

import csv
import dataclasses
import errno
import functools
import io
import json
import math
import os
import re
import struct
import tempfile
import warnings
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path
from typing import Any

import numpy as np

__all__ = [
    "COLUMNS",
    "FORMATS",
    "UNITS",
    "LogError",
    "LogWarning",
    "SlidingLog",
    "read_log",
    "write_log",
]

#: Column names of the format, in the order they are written.
COLUMNS = ("t", "f_n", "f_x", "f_y", "f_t", "tau", "omega", "maneuver")
#: SI unit of each column.
UNITS = {"t": "s", "f_n": "N", "f_x": "N", "f_y": "N", "f_t": "N", "tau": "N m",
         "omega": "rad/s", "maneuver": "-"}
#: ``format=`` names accepted by :func:`read_log` / :func:`write_log`.
FORMATS = ("csv", "parquet", "mcap", "ros1", "ros2")

_SUFFIXES = {".csv": "csv", ".parquet": "parquet", ".pq": "parquet", ".mcap": "mcap",
             ".bag": "ros1", ".db3": "ros2"}
_WRITABLE = ("csv", "parquet", "mcap")
_SIGNALS = ("f_n", "f_t", "f_x", "f_y", "tau")  # a non-finite value makes the sample invalid
_FORCES = ("f_n", "f_t", "f_x", "f_y")
_MCAP_META = "lugrip.sliding_log"
_DEFAULT_WRENCH_TOPIC = "/lugrip/wrench"
_DEFAULT_OMEGA_TOPIC = "/lugrip/omega"
_DEFAULT_MANEUVER_TOPIC = "/lugrip/maneuver"

# Unit thresholds of the magnitude checks (docs/sliding_log.md, "Unit checks").
_MAX_FORCE_MEDIAN = 200.0  # [N] median |force| above this is not a fingertip in newtons
_MAX_TAU_PER_FORCE = 0.1  # [m] |tau|/f_n is at most mu*xi*rho, a few cm at most
_GAP_FACTOR = 5.0  # default segments() gap: this many median sample periods


class LogError(ValueError):
    """A sliding log that cannot be used as it is.

    The message reads ``<file>: <where>: <problem>``. Attributes: ``file`` (str or None for
    in-memory arrays), ``row`` (1-based row as a spreadsheet shows it, header = row 1; for
    ROS sources the 1-based message number on the topic; None when the problem is not one
    row), ``column`` (column name or None), ``index`` (0-based sample index or None).
    """

    def __init__(self, file: str | os.PathLike | None, problem: str, *, where: str = "",
                 row: int | None = None, column: str | None = None,
                 index: int | None = None):
        self.file = None if file is None else str(file)
        self.problem = problem
        self.row = row
        self.column = column
        self.index = index
        head = self.file if self.file is not None else "<arrays>"
        super().__init__(f"{head}: {where}: {problem}" if where else f"{head}: {problem}")


class LogWarning(UserWarning):
    """Something in a sliding log that is kept but worth knowing (isolated NaNs, f_n <= 0)."""


# ---------------------------------------------------------------------------------------------
# Locating a sample in its source, for messages
# ---------------------------------------------------------------------------------------------

class _Locator:
    """Turns a 0-based sample index into the words a user finds the sample by."""

    def __init__(self, file: str | None, *, rows: np.ndarray | None = None,
                 topic: str | None = None, fields: Mapping[str, str] | None = None,
                 kind: str = "table"):
        self.file = file
        self.rows = rows  # physical row (line) per sample, tables only
        self.topic = topic
        self.fields = dict(fields or {})
        self.kind = kind  # "table" | "ros" | "arrays"

    def row(self, i: int) -> int | None:
        if self.kind == "table":
            return int(self.rows[i]) if self.rows is not None else i + 2
        if self.kind == "ros":
            return i + 1
        return None

    def where(self, i: int | None, column: str | None) -> str:
        col = f"column '{column}'" if column else ""
        if i is None:
            return col
        if self.kind == "table":
            here = f"row {self.row(i)}"
        elif self.kind == "ros":
            here = f"message {i + 1} on topic '{self.topic}'"
            if column and column in self.fields:
                col = f"field {self.fields[column]} (column '{column}')"
        else:
            here = f"sample {i} (0-based index)"
        return f"{here}, {col}" if col else here

    def rows_text(self, i: int, j: int) -> str:
        """Words for the inclusive sample range i..j."""
        if i == j:
            return self.where(i, None)
        if self.kind == "table":
            return f"rows {self.row(i)}-{self.row(j)}"
        if self.kind == "ros":
            return f"messages {i + 1}-{j + 1} on topic '{self.topic}'"
        return f"samples {i}-{j} (0-based indices)"

    def error(self, problem: str, i: int | None = None, column: str | None = None) -> LogError:
        i = None if i is None else int(i)
        return LogError(self.file, problem, where=self.where(i, column),
                        row=None if i is None else self.row(i), column=column, index=i)


# ---------------------------------------------------------------------------------------------
# Units
# ---------------------------------------------------------------------------------------------

_G0 = 9.80665  # standard gravity [m/s^2], for gram-force
_UNIT_FACTORS: dict[str, dict[str, float]] = {
    "time": {"s": 1.0, "sec": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9},
    "force": {"n": 1.0, "mn": 1e-3, "kn": 1e3, "gf": 1e-3 * _G0, "g": 1e-3 * _G0,
              "kgf": _G0, "lbf": 4.4482216152605},
    "torque": {"nm": 1.0, "nmm": 1e-3, "ncm": 1e-2, "mnm": 1e-3, "mnmm": 1e-6},
    "angular velocity": {"rad/s": 1.0, "deg/s": math.pi / 180.0, "°/s": math.pi / 180.0,
                         "rpm": 2.0 * math.pi / 60.0},
    "count": {"": 1.0, "-": 1.0, "1": 1.0},
}
_QUANTITY = {"t": "time", "f_n": "force", "f_x": "force", "f_y": "force", "f_t": "force",
             "tau": "torque", "omega": "angular velocity", "maneuver": "count"}


def _unit_key(unit: str) -> str:
    key = unit.strip()
    for ch in (" ", "·", "⋅", "*", "."):
        key = key.replace(ch, "")
    return key.replace("µ", "u").replace("μ", "u").lower()


def _unit_factor(column: str, unit: str, file: str | None, where: str = "") -> float:
    """Factor from ``unit`` to the SI unit of ``column``; LogError for an unknown unit."""
    quantity = _QUANTITY[column]
    table = _UNIT_FACTORS[quantity]
    key = _unit_key(unit)
    if key not in table:
        known = ", ".join(repr(u) for u in _unit_names(quantity))
        raise LogError(file, f"unknown {quantity} unit {unit!r} for column '{column}' "
                       f"(known: {known})", where=where, row=1 if where else None,
                       column=column)
    return table[key]


def _unit_names(quantity: str) -> list[str]:
    return {"time": ["s", "ms", "us", "ns"],
            "force": ["N", "mN", "kN", "gf", "kgf", "lbf"],
            "torque": ["N m", "N mm", "N cm", "mN m"],
            "angular velocity": ["rad/s", "deg/s", "rpm"],
            "count": ["-"]}[quantity]


def _expand_units(units: Mapping[str, str] | None, file: str | None) -> dict[str, str]:
    """``units=`` with the shorthand key 'force' expanded to every force column."""
    out: dict[str, str] = {}
    for key, unit in (units or {}).items():
        names = _FORCES if key == "force" else (key,)
        for name in names:
            if name not in _QUANTITY:
                raise LogError(file, f"units= names unknown column {key!r} (columns: "
                               f"{', '.join(COLUMNS)}, or 'force' for all forces)")
            out[name] = unit
    return out


# ---------------------------------------------------------------------------------------------
# The log
# ---------------------------------------------------------------------------------------------

def _as_float(name: str, value: Any) -> np.ndarray:
    arr = np.array(value, dtype=np.float64, copy=True)
    if arr.ndim != 1:
        raise ValueError(f"SlidingLog.{name} must be 1-D, got shape {arr.shape}")
    arr.setflags(write=False)
    return arr


@dataclasses.dataclass(frozen=True, eq=False)
class SlidingLog:
    """One fingertip's measured wrench over time, SI units, one entry per sample.

    Build it with :meth:`from_arrays` (computes ``f_t``, validates) or :func:`read_log`; the
    plain constructor only checks shapes. Arrays are read-only copies.

    Attributes:
        t: sample times [s], shape (n,), strictly increasing in a validated log.
        f_n: normal force [N], (n,); <= 0 marks a no-contact sample.
        f_t: tangential force magnitude [N], (n,); always present.
        tau: torsional moment about the contact normal [N m], (n,).
        f_x, f_y: in-plane force components [N], (n,) each, or both None.
        omega: ground-truth sliding velocity [rad/s], (n,) or None; NaN = unknown sample.
        maneuver: maneuver id per sample, int64 (n,); zeros when the source has none.
        source: the file the log was read from, or None.
        meta: units, source format, topic names and similar (plain JSON-able values).
    """

    t: np.ndarray
    f_n: np.ndarray
    f_t: np.ndarray
    tau: np.ndarray
    f_x: np.ndarray | None = None
    f_y: np.ndarray | None = None
    omega: np.ndarray | None = None
    maneuver: np.ndarray | None = None
    source: str | None = None
    meta: dict = dataclasses.field(default_factory=dict)

    def __post_init__(self) -> None:
        fields = {"t": self.t, "f_n": self.f_n, "f_t": self.f_t, "tau": self.tau}
        for name in ("f_x", "f_y", "omega"):
            if getattr(self, name) is not None:
                fields[name] = getattr(self, name)
        if (self.f_x is None) != (self.f_y is None):
            raise ValueError("SlidingLog: give both f_x and f_y or neither")
        arrays = {name: _as_float(name, value) for name, value in fields.items()}
        n = len(arrays["t"])
        if self.maneuver is None:
            man = np.zeros(n, dtype=np.int64)
        else:
            raw = np.asarray(self.maneuver)
            if raw.ndim != 1:
                raise ValueError(f"SlidingLog.maneuver must be 1-D, got shape {raw.shape}")
            if raw.dtype.kind not in "iub":
                as_f = raw.astype(np.float64)
                if not np.all(np.isfinite(as_f)) or np.any(as_f != np.round(as_f)):
                    raise ValueError("SlidingLog.maneuver must hold integers")
            man = raw.astype(np.int64, copy=True)
        man.setflags(write=False)
        arrays["maneuver"] = man
        bad = {name: len(a) for name, a in arrays.items() if len(a) != n}
        if bad:
            raise ValueError(f"SlidingLog: arrays differ in length: t has {n}, " + ", ".join(
                f"{name} has {m}" for name, m in bad.items()))
        for name, arr in arrays.items():
            object.__setattr__(self, name, arr)
        object.__setattr__(self, "source", None if self.source is None else str(self.source))
        object.__setattr__(self, "meta", dict(self.meta or {}))

    # -- constructors -------------------------------------------------------------------------

    @classmethod
    def from_arrays(cls, t, f_n, tau, *, f_t=None, f_x=None, f_y=None, omega=None,
                    maneuver=None, source: str | None = None, meta: Mapping | None = None,
                    validate: bool = True, check_units: bool = True, max_nan_run: int = 3,
                    allow_gaps: bool = False) -> SlidingLog:
        """Build a log from SI arrays of equal length (n,).

        Give the in-plane force as ``f_x`` and ``f_y`` (``f_t`` = hypot, or checked against
        it when given too) or as the magnitude ``f_t``. With ``validate`` (default) the same
        checks as :func:`read_log` run (time strictly increasing, NaN runs, unit magnitudes,
        f_n sign; see there), with errors naming the 0-based sample index.

        Raises:
            ValueError: shapes or a missing force description.
            LogError: validation failed.
        """
        if f_x is None and f_y is None and f_t is None:
            raise ValueError("SlidingLog.from_arrays: give f_x and f_y, or f_t")
        if (f_x is None) != (f_y is None):
            raise ValueError("SlidingLog.from_arrays: give both f_x and f_y or neither")
        cols: dict[str, np.ndarray] = {}
        for name, value in (("t", t), ("f_n", f_n), ("tau", tau), ("f_t", f_t), ("f_x", f_x),
                            ("f_y", f_y), ("omega", omega), ("maneuver", maneuver)):
            if value is not None:
                arr = np.asarray(value, dtype=np.float64)
                if arr.ndim != 1:
                    raise ValueError(f"SlidingLog.from_arrays: {name} must be 1-D, "
                                     f"got shape {arr.shape}")
                cols[name] = arr
        lengths = {name: len(a) for name, a in cols.items()}
        if len(set(lengths.values())) > 1:
            raise ValueError("SlidingLog.from_arrays: arrays differ in length: "
                             + ", ".join(f"{k}={v}" for k, v in lengths.items()))
        loc = _Locator(source, kind="arrays")
        if validate:
            _validate(cols, loc, max_nan_run=max_nan_run, allow_gaps=allow_gaps,
                      check_units=check_units, explicit=set(), stacklevel=3)
        return cls._from_columns(cols, source=source, meta=dict(meta or {}))

    @classmethod
    def _from_columns(cls, cols: Mapping[str, np.ndarray], *, source, meta) -> SlidingLog:
        f_t = cols.get("f_t")
        if "f_x" in cols:
            f_t = np.hypot(cols["f_x"], cols["f_y"])
        meta = dict(meta)
        meta.setdefault("units", {c: UNITS[c] for c in COLUMNS
                                  if c in cols or c == "f_t" or c == "maneuver"})
        return cls(t=cols["t"], f_n=cols["f_n"], f_t=f_t, tau=cols["tau"],
                   f_x=cols.get("f_x"), f_y=cols.get("f_y"), omega=cols.get("omega"),
                   maneuver=None if "maneuver" not in cols else cols["maneuver"].astype(np.int64),
                   source=source, meta=meta)

    # -- views ----------------------------------------------------------------------------------

    def __len__(self) -> int:
        return len(self.t)

    def __repr__(self) -> str:
        parts = [f"n={len(self)}"]
        if len(self):
            parts.append(f"t=[{self.t[0]:g}, {self.t[-1]:g}] s")
        parts.append("f_x/f_y" if self.has_force_vector else "f_t")
        if self.omega is not None:
            parts.append("omega")
        n_man = len(np.unique(self.maneuver)) if len(self) else 0
        if n_man > 1:
            parts.append(f"{n_man} maneuvers")
        if self.source:
            parts.append(f"source={self.source!r}")
        return f"SlidingLog({', '.join(parts)})"

    @property
    def has_force_vector(self) -> bool:
        """True when f_x and f_y are present."""
        return self.f_x is not None

    @property
    def dt(self) -> np.ndarray:
        """Sample steps ``t[i+1] - t[i]`` [s], shape (n-1,)."""
        return np.diff(self.t)

    @property
    def sample_period(self) -> float:
        """Median sample step [s] (NaN for fewer than 2 samples)."""
        return float(np.median(self.dt)) if len(self) > 1 else math.nan

    @property
    def valid(self) -> np.ndarray:
        """Per sample: every force and torque value is finite (the observer may use it)."""
        ok = np.isfinite(self.f_n) & np.isfinite(self.f_t) & np.isfinite(self.tau)
        if self.f_x is not None:
            ok &= np.isfinite(self.f_x) & np.isfinite(self.f_y)
        return ok

    def columns(self) -> dict[str, np.ndarray]:
        """The columns as written to a file: f_x/f_y when present, else f_t."""
        out = {"t": self.t, "f_n": self.f_n}
        if self.has_force_vector:
            out["f_x"], out["f_y"] = self.f_x, self.f_y
        else:
            out["f_t"] = self.f_t
        out["tau"] = self.tau
        if self.omega is not None:
            out["omega"] = self.omega
        out["maneuver"] = self.maneuver
        return out

    def select(self, which) -> SlidingLog:
        """A new log with the samples ``which`` picks: a boolean mask of shape (n,), an integer
        index array, or a slice. ``source`` and ``meta`` are kept."""
        if isinstance(which, slice):
            idx = which
        else:
            idx = np.asarray(which)
            if idx.dtype == bool:
                if idx.shape != (len(self),):
                    raise ValueError(f"select: mask has shape {idx.shape}, the log has "
                                     f"{len(self)} samples")
            elif idx.dtype.kind not in "iu":
                raise TypeError("select: give a boolean mask, integer indices or a slice")
        pick = {name: (None if getattr(self, name) is None else getattr(self, name)[idx])
                for name in ("t", "f_n", "f_t", "tau", "f_x", "f_y", "omega", "maneuver")}
        return SlidingLog(**pick, source=self.source, meta=self.meta)

    def maneuvers(self) -> Iterator[tuple[int, SlidingLog]]:
        """Yield ``(maneuver_id, sub_log)`` for each contiguous block of equal maneuver id, in
        order (an id that reappears later yields a second block)."""
        n = len(self)
        if n == 0:
            return
        cut = np.flatnonzero(self.maneuver[1:] != self.maneuver[:-1]) + 1
        bounds = np.concatenate(([0], cut, [n]))
        for a, b in zip(bounds[:-1], bounds[1:]):
            yield int(self.maneuver[a]), self.select(slice(int(a), int(b)))

    def segments(self, max_gap: float | None = None, *, by_maneuver: bool = True,
                 min_length: int = 1) -> list[tuple[int, int]]:
        """Half-open index ranges ``(start, stop)`` of the stretches an integrator may run over.

        A segment holds only valid samples (:attr:`valid`) and ends where the next sample is
        invalid, where the time step exceeds ``max_gap`` [s] (default: 5 median sample
        periods) and, with ``by_maneuver``, where the maneuver id changes. Identification and
        the observer must restart at each segment start. Segments shorter than ``min_length``
        samples are dropped.
        """
        n = len(self)
        if n == 0:
            return []
        if max_gap is None:
            max_gap = _GAP_FACTOR * self.sample_period if n > 1 else math.inf
        valid = self.valid
        breaks = self.dt > max_gap  # between i and i+1
        if by_maneuver:
            breaks |= self.maneuver[1:] != self.maneuver[:-1]
        cont = np.zeros(n, dtype=bool)  # sample i continues the segment of sample i-1
        cont[1:] = valid[1:] & valid[:-1] & ~breaks
        starts = np.flatnonzero(valid & ~cont)
        stops = np.flatnonzero(valid & ~np.append(cont[1:], False)) + 1
        return [(int(a), int(b)) for a, b in zip(starts, stops) if b - a >= min_length]

    def split(self, max_gap: float | None = None, *, by_maneuver: bool = True,
              min_length: int = 1) -> list[SlidingLog]:
        """The :meth:`segments` as sub-logs."""
        return [self.select(slice(a, b))
                for a, b in self.segments(max_gap, by_maneuver=by_maneuver,
                                          min_length=min_length)]


# ---------------------------------------------------------------------------------------------
# Validation (shared by every reader and from_arrays)
# ---------------------------------------------------------------------------------------------

def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """Inclusive (first, last) index of each run of True."""
    if not mask.any():
        return []
    edges = np.diff(np.concatenate(([0], mask.astype(np.int8), [0])))
    starts = np.flatnonzero(edges == 1)
    ends = np.flatnonzero(edges == -1) - 1
    return list(zip(starts.tolist(), ends.tolist()))


def _near(x: np.ndarray, value: float) -> int:
    """Index of the finite entry of x closest to value (an example row for a message)."""
    d = np.abs(x - value)
    d[~np.isfinite(d)] = np.inf
    return int(np.argmin(d))


def _validate(cols: dict[str, np.ndarray], loc: _Locator, *, max_nan_run: int,
              allow_gaps: bool, check_units: bool, explicit: set[str],
              stacklevel: int) -> None:
    """Raise LogError for anything that makes the log unusable; warn for what is kept."""
    t = cols["t"]
    n = len(t)
    if n == 0:
        raise loc.error("no data rows")

    bad = np.flatnonzero(~np.isfinite(t))
    if bad.size:
        raise loc.error(f"time is {float(t[bad[0]])!r}; every sample needs a finite time",
                        bad[0], "t")
    if n > 1:
        step = np.diff(t)
        back = np.flatnonzero(step <= 0)
        if back.size:
            i = int(back[0]) + 1
            prev = loc.where(i - 1, None)
            if step[i - 1] == 0:
                raise loc.error(f"duplicated time t = {float(t[i])!r} s (same as {prev}); "
                                "time must increase strictly", i, "t")
            raise loc.error(f"time goes backwards: t = {float(t[i])!r} s after "
                            f"t = {float(t[i - 1])!r} s at {prev}; time must increase "
                            "strictly (sort the samples, or write one file per recording)",
                            i, "t")

    if "maneuver" in cols:
        m = cols["maneuver"]
        bad = np.flatnonzero(~np.isfinite(m) | (m != np.round(m)))
        if bad.size:
            raise loc.error(f"maneuver id {float(m[bad[0]])!r} is not an integer", bad[0],
                            "maneuver")

    if "omega" in cols:
        bad = np.flatnonzero(np.isinf(cols["omega"]))
        if bad.size:
            raise loc.error(f"omega is {float(cols['omega'][bad[0]])!r} (use NaN for 'unknown')",
                            bad[0], "omega")

    if "f_t" in cols:
        f_t = cols["f_t"]
        bad = np.flatnonzero(f_t < 0)
        if bad.size:
            raise loc.error(f"f_t = {float(f_t[bad[0]])!r} N is negative; f_t is the magnitude "
                            "of the in-plane force (give f_x and f_y for the vector)",
                            bad[0], "f_t")
        if "f_x" in cols:
            mag = np.hypot(cols["f_x"], cols["f_y"])
            off = np.abs(mag - f_t) > 1e-6 + 1e-4 * np.abs(mag)
            bad = np.flatnonzero(off & np.isfinite(mag) & np.isfinite(f_t))
            if bad.size:
                i = int(bad[0])
                raise loc.error(f"f_t = {float(f_t[i])!r} N but hypot(f_x, f_y) = "
                                f"{float(mag[i])!r} N; give either f_t or f_x and f_y, or "
                                "make them agree", i, "f_t")

    if check_units:
        _check_units(cols, loc, explicit)

    present = [c for c in _SIGNALS if c in cols]
    nonfinite = {c: ~np.isfinite(cols[c]) for c in present}
    invalid = np.zeros(n, dtype=bool)
    for mask in nonfinite.values():
        invalid |= mask
    runs = _runs(invalid)
    if runs:
        def first_col(i: int) -> str:
            return next(c for c in present if nonfinite[c][i])

        long_runs = [(a, b) for a, b in runs if b - a + 1 > max_nan_run]
        if long_runs and not allow_gaps:
            a, b = long_runs[0]
            col = first_col(a)
            raise loc.error(f"{b - a + 1} consecutive non-finite samples (NaN/Inf) in "
                            f"{loc.rows_text(a, b)} (more than max_nan_run={max_nan_run}); "
                            "a sensor dropout? Pass allow_gaps=True to keep it as a gap, which "
                            "segments() splits at", a, col)
        examples = "; ".join(f"{loc.rows_text(a, b)} ({first_col(a)})" for a, b in runs[:5])
        more = f" and {len(runs) - 5} more" if len(runs) > 5 else ""
        where = loc.file if loc.file is not None else "<arrays>"
        warnings.warn(f"{where}: {int(invalid.sum())} non-finite sample(s) in {len(runs)} "
                      f"run(s): {examples}{more}; flagged invalid, segments() splits there",
                      LogWarning, stacklevel=stacklevel)

    f_n = cols["f_n"]
    finite = np.isfinite(f_n)
    if finite.any():
        med = float(np.median(f_n[finite]))
        if med < 0:
            i = _near(f_n, med)
            raise loc.error(f"f_n is negative in most samples (median {med:.4g} N): the "
                            "sensor's z axis points toward the object; pass flip_normal=True "
                            "(or negate f_n, f_y, tau and omega)", i, "f_n")
        low = np.flatnonzero(finite & (f_n <= 0))
        if low.size:
            where = loc.file if loc.file is not None else "<arrays>"
            warnings.warn(f"{where}: {low.size} sample(s) with f_n <= 0, first at "
                          f"{loc.where(int(low[0]), 'f_n')}: kept as no-contact samples",
                          LogWarning, stacklevel=stacklevel)


def _check_units(cols: dict[str, np.ndarray], loc: _Locator, explicit: set[str]) -> None:
    """LogError when a column's magnitudes say it is not in SI units (docs: Unit checks)."""
    t = cols["t"]
    n = len(t)
    override = "; if the values really are in {si}, pass units={{'{c}': '{si}'}}"
    if "t" not in explicit and n > 1:
        dt = float(np.median(np.diff(t)))
        tmax = float(np.max(np.abs(t)))
        if tmax > 1e11 or dt > 100.0 or (n > 1000 and dt > 0.5):
            unit, scale = "ns", 1e-9
            for u, s in (("ms", 1e-3), ("us", 1e-6), ("ns", 1e-9)):
                if dt * s <= 0.5:
                    unit, scale = u, s
                    break
            raise loc.error(f"t does not look like seconds (median step {dt:.4g} over {n} "
                            f"samples, |t| up to {tmax:.4g}); it looks like {unit}: multiply by "
                            f"{scale:g} or pass units={{'t': '{unit}'}}"
                            + override.format(si="s", c="t"), 1, "t")
    for c in _FORCES:
        if c in cols and c not in explicit:
            x = cols[c][np.isfinite(cols[c])]
            if x.size and (med := float(np.median(np.abs(x)))) > _MAX_FORCE_MEDIAN:
                i = _near(np.abs(cols[c]), med)
                raise loc.error(f"{c} does not look like newtons (median |{c}| = {med:.4g}, "
                                f"more than a fingertip carries); mN? divide by 1000 or pass "
                                f"units={{'{c}': 'mN'}} (or {{'force': 'mN'}}); gram-force? "
                                f"pass units={{'force': 'gf'}}" + override.format(si="N", c=c),
                                i, c)
    if "tau" not in explicit:
        tau, f_n = cols["tau"], cols["f_n"]
        ok = np.isfinite(tau) & np.isfinite(f_n)
        if ok.any():
            med_tau = float(np.median(np.abs(tau[ok])))
            med_fn = float(np.median(f_n[ok]))
            contact = ok & (f_n > max(0.1 * med_fn, 1e-3))
            ratio = np.abs(tau[contact]) / f_n[contact]
            p90 = float(np.percentile(ratio, 90)) if ratio.size else 0.0
            if (med_tau > 0.5 and med_fn < 50.0) or p90 > _MAX_TAU_PER_FORCE:
                i = _near(np.abs(tau), med_tau)
                raise loc.error(f"tau does not look like N m (median |tau| = {med_tau:.4g} at "
                                f"median f_n = {med_fn:.4g} N; |tau|/f_n reaches {p90:.3g} m, "
                                f"a fingertip contact gives at most a few cm); it looks like "
                                f"N mm: divide by 1000 or pass units={{'tau': 'N mm'}}"
                                + override.format(si="N m", c="tau"), i, "tau")


# ---------------------------------------------------------------------------------------------
# Tables: CSV and Parquet
# ---------------------------------------------------------------------------------------------

_HEADER_RE = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_]*)\s*(?:[\[(]\s*([^\])]*?)\s*[\])])?\s*$")


def _parse_header(names: list[str], file: str) -> tuple[dict[str, int], dict[str, str], list[str]]:
    """Map column name -> position, column -> unit from ``name [unit]``, ignored names."""
    index: dict[str, int] = {}
    units: dict[str, str] = {}
    ignored: list[str] = []
    for pos, raw in enumerate(names):
        m = _HEADER_RE.match(str(raw))
        name = m.group(1).lower() if m else None
        if name not in UNITS:
            ignored.append(str(raw))
            continue
        if name in index:
            raise LogError(file, f"column '{name}' appears twice (columns {index[name] + 1} "
                           f"and {pos + 1})", where=f"row 1, column '{name}'", row=1,
                           column=name)
        index[name] = pos
        if m.group(2) is not None:
            units[name] = m.group(2)
    return index, units, ignored


def _check_required(index: Mapping[str, Any], names: list[str], file: str) -> None:
    have = ", ".join(str(n) for n in names) or "(none)"
    expected = ("expected t [s], f_n [N], f_x and f_y [N] (or f_t [N]), tau [N m]; optional "
                "omega [rad/s], maneuver")
    missing = [c for c in ("t", "f_n", "tau") if c not in index]
    if "f_x" in index and "f_y" not in index:
        missing.append("f_y")
    elif "f_y" in index and "f_x" not in index:
        missing.append("f_x")
    elif not any(c in index for c in ("f_x", "f_y", "f_t")):
        missing.append("f_x/f_y or f_t")
    if missing:
        names_ = ", ".join(f"'{c}'" for c in missing)
        raise LogError(file, f"missing required column(s) {names_}; the file has: {have}; "
                       f"{expected}", where=f"row 1, column '{missing[0]}'", row=1,
                       column=missing[0])


def _cells_to_float(cells, column: str, loc: _Locator) -> np.ndarray:
    """Text cells -> float64; empty cells are NaN; LogError names the first bad cell."""
    cleaned = ["nan" if c is None or not str(c).strip() else c for c in cells]
    try:
        return np.array(cleaned, dtype=np.float64)
    except (ValueError, TypeError):
        pass
    for i, cell in enumerate(cleaned):
        try:
            float(cell)
        except (ValueError, TypeError):
            hint = ""
            if re.fullmatch(r"\s*[-+]?\d+,\d+\s*", str(cell)):
                hint = " (decimal comma? use '.' as decimal separator)"
            raise loc.error(f"{str(cell)!r} is not a number{hint}", i, column) from None
    raise loc.error("column is not numeric", None, column)  # pragma: no cover


def _read_csv(path: Path, file: str) -> tuple[dict[str, np.ndarray], dict[str, str], _Locator,
                                               dict]:
    with open(path, newline="", encoding="utf-8-sig") as fh:
        text = fh.read()
    if not text.strip():
        raise LogError(file, "empty file (expected a header row and data rows)")
    first = next(line for line in text.splitlines() if line.strip())
    delim = next((d for d in (",", ";", "\t") if d in first), ",")
    fast = _read_csv_fast(text, delim, file)
    if fast is not None:
        return fast
    reader = csv.reader(io.StringIO(text, newline=""), delimiter=delim,
                        skipinitialspace=True)
    header: list[str] | None = None
    rows: list[list[str]] = []
    lines: list[int] = []
    for record in reader:
        if not record or all(not c.strip() for c in record) and len(record) <= 1:
            continue  # blank line
        if header is None:
            header = [c.strip() for c in record]
            header_line = reader.line_num
            continue
        rows.append(record)
        lines.append(reader.line_num)
    assert header is not None
    index, units, ignored = _parse_header(header, file)
    if not index and all(_is_number(c) for c in header if c):
        raise LogError(file, f"no header row: row {header_line} holds numbers; the first row "
                       "must name the columns (t, f_n, f_x, f_y or f_t, tau, omega, maneuver)",
                       where=f"row {header_line}", row=header_line)
    _check_required(index, header, file)
    if not rows:
        raise LogError(file, "no data rows (only the header)")
    loc = _Locator(file, rows=np.asarray(lines))
    width = len(header)
    for k, record in enumerate(rows):
        if len(record) != width:
            raise loc.error(f"{len(record)} cells, but the header has {width} columns "
                            f"(delimiter {delim!r})", k, None)
    cols = {}
    for name, pos in index.items():
        cols[name] = _cells_to_float([r[pos] for r in rows], name, loc)
    meta = {"format": "csv", "columns": [str(h) for h in header], "ignored_columns": ignored}
    return cols, units, loc, meta


def _read_csv_fast(text: str, delim: str, file: str):
    """pyarrow's CSV parser for clean files (no blank lines, every cell a number); None to
    fall back to the line-by-line reader, which finds and names any problem."""
    try:
        import pyarrow as pa
        import pyarrow.csv as pacsv
    except ImportError:
        return None
    lines = text.splitlines()
    if len(lines) < 2 or any(not line.strip() for line in lines):
        return None
    header = [c.strip() for c in next(csv.reader([lines[0]], delimiter=delim))]
    index, units, ignored = _parse_header(header, file)
    if not index:
        return None
    _check_required(index, header, file)
    names = [f"c{i}" for i in range(len(header))]
    try:
        table = pacsv.read_csv(
            io.BytesIO(text.encode("utf-8")),
            read_options=pacsv.ReadOptions(skip_rows=1, column_names=names),
            parse_options=pacsv.ParseOptions(delimiter=delim),
            convert_options=pacsv.ConvertOptions(
                column_types={names[pos]: pa.float64() for pos in index.values()},
                include_columns=[names[pos] for pos in index.values()],
                null_values=[""], strings_can_be_null=False))
    except (pa.ArrowException, ValueError):
        return None
    if table.num_rows != len(lines) - 1:
        return None
    cols = {name: np.asarray(table.column(names[pos]).fill_null(math.nan).to_numpy(),
                             dtype=np.float64) for name, pos in index.items()}
    meta = {"format": "csv", "columns": header, "ignored_columns": ignored}
    return cols, units, _Locator(file), meta


def _exc_text(exc: BaseException) -> str:
    text = str(exc).strip()
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _need(module: str, what: str):
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError as exc:
        package = module.split(".")[0]
        raise ImportError(f"{what} needs the '{package}' package: pip install {package} "
                          "(or pip install 'lugrip[io]')") from exc


def _read_parquet(path: Path, file: str):
    pa = _need("pyarrow", "reading Parquet")
    pq = _need("pyarrow.parquet", "reading Parquet")
    if path.stat().st_size == 0:
        raise LogError(file, "empty file (expected a Parquet table)")
    try:
        table = pq.read_table(path)
    except Exception as exc:  # noqa: BLE001 (pyarrow raises several types for bad files)
        raise LogError(file, f"not a readable Parquet file ({_exc_text(exc)})") from None
    names = list(table.column_names)
    index, units, ignored = _parse_header(names, file)
    _check_required(index, names, file)
    if table.num_rows == 0:
        raise LogError(file, "no data rows (the table is empty)")
    loc = _Locator(file)
    cols = {}
    for name, pos in index.items():
        col = table.column(pos)
        typ = col.type
        if pa.types.is_integer(typ) or pa.types.is_floating(typ) or pa.types.is_boolean(typ) \
                or pa.types.is_decimal(typ):
            arr = col.cast(pa.float64()).fill_null(math.nan).to_numpy()
            cols[name] = np.asarray(arr, dtype=np.float64)
        elif pa.types.is_string(typ) or pa.types.is_large_string(typ):
            cols[name] = _cells_to_float(col.to_pylist(), name, loc)
        else:
            raise loc.error(f"column type {typ} is not numeric (expected numbers in "
                            f"{UNITS[name]})", None, name)
    meta: dict[str, Any] = {"format": "parquet", "columns": names, "ignored_columns": ignored}
    stored = (table.schema.metadata or {}).get(b"lugrip")
    if stored:
        try:
            extra = json.loads(stored)
            meta.update({k: v for k, v in extra.items() if k not in meta})
        except ValueError:
            pass
    return cols, units, loc, meta


# ---------------------------------------------------------------------------------------------
# ROS messages: a small decoder for the few fixed-layout types we need
# ---------------------------------------------------------------------------------------------

# type -> (has std_msgs/Header, struct code, count, field -> position)
_VEC3 = {"x": 0, "y": 1, "z": 2}
_SIX = {f"{a}.{b}": 3 * i + j for i, a in enumerate(("force", "torque"))
        for j, b in enumerate("xyz")}
_TWIST = {f"{a}.{b}": 3 * i + j for i, a in enumerate(("linear", "angular"))
          for j, b in enumerate("xyz")}
_ROS_TYPES: dict[str, tuple[bool, str, int, dict[str, int]]] = {
    "geometry_msgs/WrenchStamped": (True, "d", 6, _SIX),
    "geometry_msgs/Wrench": (False, "d", 6, _SIX),
    "geometry_msgs/TwistStamped": (True, "d", 6, _TWIST),
    "geometry_msgs/Twist": (False, "d", 6, _TWIST),
    "geometry_msgs/Vector3Stamped": (True, "d", 3, _VEC3),
    "geometry_msgs/Vector3": (False, "d", 3, _VEC3),
    "std_msgs/Float64": (False, "d", 1, {"data": 0}),
    "std_msgs/Float32": (False, "f", 1, {"data": 0}),
    "std_msgs/Int32": (False, "i", 1, {"data": 0}),
}
_WRENCH_TYPES = ("geometry_msgs/WrenchStamped", "geometry_msgs/Wrench")
# omega type -> (field read as omega, position in the decoded values)
_OMEGA_FIELD = {"geometry_msgs/TwistStamped": ("twist.angular.z", 5),
                "geometry_msgs/Twist": ("angular.z", 5),
                "geometry_msgs/Vector3Stamped": ("vector.z", 2),
                "geometry_msgs/Vector3": ("z", 2),
                "std_msgs/Float64": ("data", 0), "std_msgs/Float32": ("data", 0)}
_CDR_KINDS = {b"\x00\x00": ">", b"\x00\x01": "<"}  # plain CDR big / little endian


def _norm_type(name: str) -> str:
    """'geometry_msgs/msg/WrenchStamped' and 'geometry_msgs/WrenchStamped' -> the latter."""
    return name.replace("/msg/", "/")


_HEAD = {"<": struct.Struct("<iII"), ">": struct.Struct(">iII"), "ros1": struct.Struct("<IIII")}


@functools.lru_cache(maxsize=64)
def _body(end: str, code: str, count: int) -> struct.Struct:
    return struct.Struct(f"{end}{count}{code}")


def _decode(data: bytes, encoding: str, typ: str) -> tuple[int | None, tuple]:
    """One message -> (header stamp [ns] or None, values). ROS 1 or plain CDR (ROS 2)."""
    stamped, code, count, _ = _ROS_TYPES[typ]
    if encoding == "cdr":
        end = _CDR_KINDS.get(bytes(data[:2]))
        if end is None:
            raise ValueError(f"unsupported CDR encapsulation 0x{bytes(data[:2]).hex()}")
        pos = 4
    elif encoding == "ros1":
        end, pos = "<", 0
    else:
        raise ValueError(f"unsupported message encoding {encoding!r}")
    stamp = None
    if stamped:
        if encoding == "ros1":
            _seq, sec, nsec, slen = _HEAD["ros1"].unpack_from(data, 0)
            pos = 16 + slen
        else:
            sec, nsec, slen = _HEAD[end].unpack_from(data, 4)
            pos = 16 + slen
        stamp = sec * 1_000_000_000 + nsec
    body = _body(end, code, count)
    if encoding == "cdr":  # CDR aligns each primitive to its size, counted after the 4-byte header
        size = body.size // count
        pos += -(pos - 4) % size
    if len(data) != pos + body.size and not (encoding == "cdr" and len(data) > pos + body.size
                                             and len(data) - (pos + body.size) < 4):
        raise ValueError(f"{len(data)} bytes, expected {pos + body.size} for {typ}")
    return stamp, body.unpack_from(data, pos)


def _encode_cdr(typ: str, values: tuple, stamp_ns: int | None = None, frame_id: str = "") -> bytes:
    """Plain little-endian CDR (what ROS 2 writes) of one of the fixed-layout types."""
    stamped, code, count, _ = _ROS_TYPES[typ]
    out = bytearray(b"\x00\x01\x00\x00")
    if stamped:
        sec, nsec = divmod(int(stamp_ns or 0), 1_000_000_000)
        name = frame_id.encode() + b"\x00"
        out += struct.pack("<iII", sec, nsec, len(name)) + name
    out += b"\x00" * (-(len(out) - 4) % struct.calcsize(code))
    out += struct.pack(f"<{count}{code}", *values)
    return bytes(out)


_MSGDEF_SEP = "\n" + "=" * 80 + "\n"
_MSGDEFS = {
    "std_msgs/Header": "builtin_interfaces/Time stamp\nstring frame_id\n",
    "builtin_interfaces/Time": "int32 sec\nuint32 nanosec\n",
    "geometry_msgs/Vector3": "float64 x\nfloat64 y\nfloat64 z\n",
    "geometry_msgs/Wrench": "Vector3 force\nVector3 torque\n",
    "geometry_msgs/Twist": "Vector3 linear\nVector3 angular\n",
    "geometry_msgs/WrenchStamped": "std_msgs/Header header\nWrench wrench\n",
    "geometry_msgs/TwistStamped": "std_msgs/Header header\nTwist twist\n",
    "std_msgs/Int32": "int32 data\n",
}
_MSGDEF_DEPS = {
    "geometry_msgs/WrenchStamped": ("std_msgs/Header", "builtin_interfaces/Time",
                                    "geometry_msgs/Wrench", "geometry_msgs/Vector3"),
    "geometry_msgs/TwistStamped": ("std_msgs/Header", "builtin_interfaces/Time",
                                   "geometry_msgs/Twist", "geometry_msgs/Vector3"),
    "std_msgs/Int32": (),
}


def _ros2_msgdef(typ: str) -> str:
    """The ros2msg schema text (the type's definition followed by its dependencies)."""
    parts = [_MSGDEFS[typ]]
    for dep in _MSGDEF_DEPS[typ]:
        parts.append(f"MSG: {dep}\n{_MSGDEFS[dep]}")
    return _MSGDEF_SEP.join(parts)


class _Topic:
    """All messages of one topic: log times [ns], header stamps [ns] or None, values."""

    def __init__(self, name: str, typ: str):
        self.name = name
        self.type = typ
        self.log_ns: list[int] = []
        self.stamp_ns: list[int] = []
        self.values: list[tuple] = []

    def times(self) -> tuple[np.ndarray, str]:
        """Header stamps when the type has them and they are set, else the log times."""
        stamps = np.asarray(self.stamp_ns, dtype=np.int64)
        if _ROS_TYPES[self.type][0] and stamps.size and np.any(stamps != 0):
            return stamps, "header"
        return np.asarray(self.log_ns, dtype=np.int64), "log"


class _RosSource:
    """Topics of an MCAP file or a ROS bag, and their messages decoded on request."""

    def __init__(self, file: str):
        self.file = file
        self.topics: dict[str, tuple[str, str, int | None]] = {}  # name -> (type, enc, count)
        self.metadata: dict[str, str] = {}

    def describe(self) -> str:
        if not self.topics:
            return "(no topics)"
        out = []
        for name, (typ, _enc, count) in sorted(self.topics.items()):
            n = "" if count is None else f", {count} messages"
            out.append(f"{name} ({typ}{n})")
        return ", ".join(out)

    def read(self, names: list[str]) -> dict[str, _Topic]:
        raise NotImplementedError

    def _decode_into(self, topic: _Topic, encoding: str, data: bytes, log_ns: int) -> None:
        try:
            stamp, values = _decode(data, encoding, topic.type)
        except (struct.error, ValueError) as exc:
            raise LogError(self.file, f"cannot decode {topic.type} ({exc})",
                           where=f"message {len(topic.values) + 1} on topic '{topic.name}'",
                           row=len(topic.values) + 1) from None
        topic.log_ns.append(int(log_ns))
        topic.stamp_ns.append(0 if stamp is None else stamp)
        topic.values.append(values)


class _McapSource(_RosSource):
    """One sequential pass over the file (no summary needed, so a recording cut short by a
    crash is read up to its last complete chunk, with a warning). Message bytes are kept only
    for the types we can decode."""

    def __init__(self, path: Path, file: str):
        super().__init__(file)
        stream_reader = _need("mcap.stream_reader", "reading MCAP")
        records = _need("mcap.records", "reading MCAP")
        if path.stat().st_size == 0:
            raise LogError(file, "empty file (expected an MCAP recording)")
        schemas: dict[int, str] = {}
        channels: dict[int, tuple[str, str, str]] = {}  # id -> topic, type, encoding
        counts: dict[str, int] = {}
        self._messages: dict[str, list[tuple[int, bytes]]] = {}
        with open(path, "rb") as fh:
            try:
                for rec in stream_reader.StreamReader(fh).records:
                    if isinstance(rec, records.Message):
                        topic, typ, _enc = channels[rec.channel_id]
                        counts[topic] += 1
                        if typ in _ROS_TYPES:
                            self._messages[topic].append((rec.log_time, rec.data))
                    elif isinstance(rec, records.Schema):
                        schemas[rec.id] = _norm_type(rec.name)
                    elif isinstance(rec, records.Channel):
                        typ = schemas.get(rec.schema_id, "(no schema)")
                        channels[rec.id] = (rec.topic, typ, rec.message_encoding)
                        counts.setdefault(rec.topic, 0)
                        self._messages.setdefault(rec.topic, [])
                    elif isinstance(rec, records.Metadata) and rec.name == _MCAP_META:
                        self.metadata = dict(rec.metadata)
            except Exception as exc:  # noqa: BLE001 (any reader failure: a bad file)
                if not channels:
                    raise LogError(file, f"not a readable MCAP file ({_exc_text(exc)})") from None
                warnings.warn(f"{file}: truncated or damaged MCAP ({_exc_text(exc)}); read the "
                              f"{sum(counts.values())} messages before the damage",
                              LogWarning, stacklevel=4)
        for topic, typ, enc in channels.values():
            self.topics[topic] = (typ, enc, counts[topic])

    def read(self, names):
        out = {}
        for name in names:
            topic = out[name] = _Topic(name, self.topics[name][0])
            enc = self.topics[name][1]
            # file order is chunk order; sort by log time (stable) as a recorder would play it
            for log_ns, data in sorted(self._messages[name], key=lambda m: m[0]):
                self._decode_into(topic, enc, data, log_ns)
        return out


class _BagSource(_RosSource):
    def __init__(self, path: Path, file: str, ros1: bool):
        super().__init__(file)
        mod = "rosbags.rosbag1" if ros1 else "rosbags.rosbag2"
        rb = _need(mod, "reading ROS 1 bags" if ros1 else "reading ROS 2 bags")
        self._encoding = "ros1" if ros1 else "cdr"
        if path.is_file() and path.stat().st_size == 0:
            raise LogError(file, "empty file (expected a ROS bag)")
        try:
            self._reader = rb.Reader(path)
            self._reader.open()
        except Exception as exc:  # noqa: BLE001 (any reader failure: a bad file)
            raise LogError(file, f"not a readable ROS {1 if ros1 else 2} bag "
                           f"({_exc_text(exc)})") from None
        for conn in self._reader.connections:
            typ = _norm_type(conn.msgtype)
            count = getattr(conn, "msgcount", None)
            old = self.topics.get(conn.topic)
            if old is not None and old[2] is not None and count is not None:
                count += old[2]
            self.topics[conn.topic] = (typ, self._encoding, count)

    def read(self, names):
        out = {name: _Topic(name, self.topics[name][0]) for name in names}
        try:
            conns = [c for c in self._reader.connections if c.topic in out]
            for conn, log_ns, data in self._reader.messages(connections=conns):
                self._decode_into(out[conn.topic], self._encoding, data, log_ns)
        except LogError:
            raise
        except Exception as exc:  # noqa: BLE001 (any reader failure: a bad file)
            raise LogError(self.file, f"cannot read the bag ({_exc_text(exc)})") from None
        finally:
            self._reader.close()
        return out


def _resample(t_src: np.ndarray, y_src: np.ndarray, t_dst: np.ndarray,
              max_gap: float) -> np.ndarray:
    """Linear interpolation of (t_src, y_src) at t_dst; NaN outside the source's time span
    and between source samples further apart than max_gap."""
    m = len(t_src)
    out = np.full(len(t_dst), np.nan)
    if m == 0:
        return out
    idx = np.searchsorted(t_src, t_dst, side="left")
    inside = idx < m
    exact = np.zeros(len(t_dst), dtype=bool)
    exact[inside] = t_src[idx[inside]] == t_dst[inside]
    out[exact] = y_src[idx[exact]]
    mid = (idx > 0) & inside & ~exact
    lo, hi = idx[mid] - 1, idx[mid]
    span = t_src[hi] - t_src[lo]
    w = (t_dst[mid] - t_src[lo]) / span
    val = y_src[lo] + w * (y_src[hi] - y_src[lo])
    val[span > max_gap] = np.nan
    out[mid] = val
    return out


def _pick_wrench_topic(src: _RosSource, wrench_topic: str | None) -> str:
    if wrench_topic is None:
        wrench_topic = src.metadata.get("wrench_topic")
    if wrench_topic is None:
        found = [n for n, (typ, _, _) in src.topics.items() if typ in _WRENCH_TYPES]
        if len(found) == 1:
            return found[0]
        if not found:
            raise LogError(src.file, "no geometry_msgs/WrenchStamped topic; topics present: "
                           f"{src.describe()}")
        raise LogError(src.file, f"{len(found)} wrench topics ({', '.join(sorted(found))}); "
                       "choose one with wrench_topic=")
    _check_topic(src, wrench_topic, _WRENCH_TYPES, "wrench_topic")
    return wrench_topic


def _check_topic(src: _RosSource, topic: str, types, what: str) -> None:
    if topic not in src.topics:
        raise LogError(src.file, f"no topic '{topic}' ({what}); topics present: "
                       f"{src.describe()}")
    typ, enc, _count = src.topics[topic]
    if typ not in types:
        raise LogError(src.file, f"topic '{topic}' has type {typ}; {what} must be one of "
                       f"{', '.join(types)}")
    if enc not in ("cdr", "ros1"):
        raise LogError(src.file, f"topic '{topic}' is encoded as {enc!r}; only ROS 1 and "
                       "ROS 2 (CDR) messages can be read")


def _read_ros(src: _RosSource, wrench_topic: str | None, omega_topic: str | None,
              flip_normal: bool):
    file = src.file
    wrench_topic = _pick_wrench_topic(src, wrench_topic)
    if omega_topic is None:
        omega_topic = src.metadata.get("omega_topic") or None
    if omega_topic is not None:
        _check_topic(src, omega_topic, tuple(_OMEGA_FIELD), "omega_topic")
    maneuver_topic = src.metadata.get("maneuver_topic") or None
    if maneuver_topic is not None:
        _check_topic(src, maneuver_topic, ("std_msgs/Int32",), "maneuver topic")
    names = [n for n in dict.fromkeys((wrench_topic, omega_topic, maneuver_topic)) if n]
    topics = src.read(names)

    wrench = topics[wrench_topic]
    if not wrench.values:
        raise LogError(file, f"topic '{wrench_topic}' has no messages")
    stamps, time_source = wrench.times()
    if "t0_ns" in src.metadata:
        t0 = int(src.metadata["t0_ns"])
    else:
        t0 = int(stamps[0])
    t = (stamps - t0) / 1e9
    v = np.asarray(wrench.values, dtype=np.float64)
    sign = -1.0 if flip_normal else 1.0  # rotation by pi about x: y, z and moments about z flip
    cols = {"t": t, "f_x": v[:, 0], "f_y": sign * v[:, 1], "f_n": sign * v[:, 2],
            "tau": sign * v[:, 5]}
    if src.metadata.get("force_vector") == "false":
        cols["f_t"] = np.hypot(cols.pop("f_x"), cols.pop("f_y"))
    prefix = "wrench." if _ROS_TYPES[wrench.type][0] else ""
    fields = {"t": "header.stamp" if time_source == "header" else "log time",
              "f_x": prefix + "force.x", "f_y": prefix + "force.y",
              "f_t": f"|{prefix}force.xy|", "f_n": prefix + "force.z",
              "tau": prefix + "torque.z"}
    meta: dict[str, Any] = {"format": None, "wrench_topic": wrench_topic,
                            "wrench_type": wrench.type, "time_source": time_source,
                            "t0_ns": t0, "flip_normal": bool(flip_normal)}

    if omega_topic is not None:
        om = topics[omega_topic]
        if not om.values:
            raise LogError(file, f"topic '{omega_topic}' has no messages")
        o_ns, o_source = om.times()
        o_t = (o_ns - t0) / 1e9
        step = np.diff(o_t)
        back = np.flatnonzero(step <= 0)
        if back.size:
            k = int(back[0]) + 1
            raise LogError(file, f"time does not increase strictly ({float(o_t[k])!r} s after "
                           f"{float(o_t[k - 1])!r} s)", where=f"message {k + 1} on topic "
                           f"'{omega_topic}'", row=k + 1, column="omega")
        field, pos = _OMEGA_FIELD[om.type]
        y = sign * np.asarray(om.values, dtype=np.float64)[:, pos]
        max_gap = 10.0 * float(np.median(step)) if step.size else 0.0
        cols["omega"] = _resample(o_t, y, t, max_gap)
        fields["omega"] = f"{field} of '{omega_topic}' resampled"
        meta.update(omega_topic=omega_topic, omega_type=om.type, omega_time_source=o_source)

    if maneuver_topic is not None:
        mt = topics[maneuver_topic]
        m_ns = np.asarray(mt.log_ns, dtype=np.int64)
        m_val = np.asarray([val[0] for val in mt.values], dtype=np.float64)
        order = np.argsort(m_ns, kind="stable")
        k = np.searchsorted(m_ns[order], stamps, side="right") - 1
        cols["maneuver"] = np.where(k >= 0, m_val[order][np.maximum(k, 0)], 0.0)
        meta["maneuver_topic"] = maneuver_topic

    loc = _Locator(file, topic=wrench_topic, fields=fields, kind="ros")
    return cols, {}, loc, meta


# ---------------------------------------------------------------------------------------------
# read_log / write_log
# ---------------------------------------------------------------------------------------------

def _detect_format(path: Path, format: str | None, file: str) -> str:
    if format is not None:
        if format not in FORMATS:
            raise LogError(file, f"unknown format {format!r} (known: {', '.join(FORMATS)})")
        return format
    if path.is_dir():
        if (path / "metadata.yaml").exists():
            return "ros2"
        raise LogError(file, "a directory that is not a ROS 2 bag (no metadata.yaml)")
    fmt = _SUFFIXES.get(path.suffix.lower())
    if fmt is None:
        known = ", ".join(sorted(_SUFFIXES)) + ", a ROS 2 bag directory"
        raise LogError(file, f"unknown file type {path.suffix or '(no suffix)'!r} (known: "
                       f"{known}); pass format= to choose one")
    if fmt == "mcap" and (path.parent / "metadata.yaml").exists():
        return "ros2"  # the storage file of a ROS 2 bag: read the bag (its metadata)
    return fmt


def read_log(path: str | os.PathLike, *, format: str | None = None,
             wrench_topic: str | None = None, omega_topic: str | None = None,
             flip_normal: bool = False, units: Mapping[str, str] | None = None,
             check_units: bool = True, max_nan_run: int = 3,
             allow_gaps: bool = False) -> SlidingLog:
    """Read a sliding log.

    Args:
        path: a ``.csv``, ``.parquet``/``.pq``, ``.mcap`` or ROS 1 ``.bag`` file, a ROS 2 bag
            directory (``metadata.yaml`` + storage) or one of its ``.db3``/``.mcap`` files.
        format: one of :data:`FORMATS` to override the suffix.
        wrench_topic: ROS sources: the ``geometry_msgs/WrenchStamped`` (or ``Wrench``) topic;
            default: the only wrench topic, or the one a lugrip-written MCAP names.
        omega_topic: ROS sources: ground-truth angular velocity about the sensor's z axis,
            ``TwistStamped``/``Twist`` (angular.z), ``Vector3[Stamped]`` (z) or
            ``Float64``/``Float32``; linearly resampled onto the wrench times (NaN outside its
            time span and across gaps longer than 10 of its median periods).
        flip_normal: the sensor's z axis points toward the object (out of the pad), so its
            force z is negative while pressed: rotate the frame by pi about x (f_n, f_y, tau
            and omega change sign) so that f_n > 0 in contact.
        units: units of the source columns, converted to SI, e.g. ``{'tau': 'N mm',
            't': 'ms'}``; key ``'force'`` sets every force column. A column given a unit here
            (or in a table header as ``tau [N mm]``) skips the magnitude check.
        check_units: run the magnitude checks that catch ms, mN, gram-force and N mm.
        max_nan_run: longest run of non-finite force/torque samples accepted (with a
            :class:`LogWarning`; the samples are flagged invalid and split segments).
        allow_gaps: accept longer runs too.

    Returns:
        SlidingLog with ``source`` = path and ``meta`` (format, units, topics, ...).

    Raises:
        FileNotFoundError: no such file.
        LogError: unknown type, empty or malformed file, missing column or topic, bad values
            (message names file, row or message, and column).
        ImportError: the optional package the format needs is missing.
    """
    path = Path(path)
    file = str(path)
    if not path.exists():
        raise FileNotFoundError(errno.ENOENT, "no such sliding log", file)
    fmt = _detect_format(path, format, file)
    if fmt == "csv":
        cols, header_units, loc, meta = _read_csv(path, file)
    elif fmt == "parquet":
        cols, header_units, loc, meta = _read_parquet(path, file)
    else:
        if fmt == "mcap":
            src: _RosSource = _McapSource(path, file)
        else:
            src = _BagSource(path, file, ros1=(fmt == "ros1"))
        cols, header_units, loc, meta = _read_ros(src, wrench_topic, omega_topic, flip_normal)
        meta["format"] = fmt

    given = dict(header_units)
    given.update(_expand_units(units, file))
    converted = {}
    for name, unit in given.items():
        if name not in cols:
            continue
        where = f"row 1, column '{name}'" if name in header_units else ""
        factor = _unit_factor(name, unit, file, where)
        if factor != 1.0:
            cols[name] = cols[name] * factor
            converted[name] = unit
    if flip_normal and fmt in ("csv", "parquet"):
        for name in ("f_n", "f_y", "tau", "omega"):
            if name in cols:
                cols[name] = -cols[name]
        meta["flip_normal"] = True

    _validate(cols, loc, max_nan_run=max_nan_run, allow_gaps=allow_gaps,
              check_units=check_units, explicit=set(given), stacklevel=3)
    meta["units"] = {c: UNITS[c] for c in COLUMNS if c in cols or c in ("f_t", "maneuver")}
    if converted:
        meta["converted_from"] = converted
    return SlidingLog._from_columns(cols, source=file, meta=meta)


def _json_meta(meta: Mapping) -> dict:
    """The JSON-serialisable part of a log's meta."""
    out = {}
    for key, value in meta.items():
        try:
            json.dumps(value)
        except (TypeError, ValueError):
            continue
        out[key] = value
    return out


def _write_csv(log: SlidingLog, fh) -> None:
    cols = log.columns()
    text = io.TextIOWrapper(fh, encoding="utf-8", newline="")
    writer = csv.writer(text, lineterminator="\n")
    writer.writerow(list(cols))
    lists = [a.tolist() for a in cols.values()]  # Python floats: repr round-trips exactly
    writer.writerows(zip(*lists))
    text.flush()
    text.detach()


def _write_parquet(log: SlidingLog, fh) -> None:
    pa = _need("pyarrow", "writing Parquet")
    pq = _need("pyarrow.parquet", "writing Parquet")
    cols = log.columns()
    arrays = [pa.array(a, type=pa.int64() if name == "maneuver" else pa.float64())
              for name, a in cols.items()]
    # keep provenance (topics, t0_ns, ...), drop what describes one particular read
    skip = ("format", "columns", "ignored_columns", "converted_from", "flip_normal", "units")
    meta = _json_meta({k: v for k, v in log.meta.items() if k not in skip})
    meta["format_version"] = 1
    schema = pa.schema([pa.field(name, arr.type) for name, arr in zip(cols, arrays)],
                       metadata={b"lugrip": json.dumps(meta).encode()})
    pq.write_table(pa.Table.from_arrays(arrays, schema=schema), fh)


def _write_mcap(log: SlidingLog, fh, wrench_topic: str | None, omega_topic: str | None,
                frame_id: str) -> None:
    writer_mod = _need("mcap.writer", "writing MCAP")
    wrench_topic = wrench_topic or log.meta.get("wrench_topic") or _DEFAULT_WRENCH_TOPIC
    omega_topic = omega_topic or log.meta.get("omega_topic") or _DEFAULT_OMEGA_TOPIC
    if log.omega is not None and omega_topic == wrench_topic:
        raise ValueError("write_log: omega_topic and wrench_topic must differ")
    n = len(log)
    t0 = int(log.meta.get("t0_ns", 0) or 0)
    if n and not np.all(np.isfinite(log.t)):
        raise ValueError("write_log: MCAP needs finite times")
    offs = np.rint(log.t * 1e9).astype(np.int64) if n else np.zeros(0, np.int64)
    if n and t0 + int(offs.min()) < 0:
        t0 = -int(offs.min())  # MCAP times are unsigned: shift, the metadata keeps t0
    stamps = (t0 + offs).tolist()
    try:
        import zstandard  # noqa: F401

        compression = writer_mod.CompressionType.ZSTD
    except ImportError:
        compression = writer_mod.CompressionType.NONE
    w = writer_mod.Writer(fh, compression=compression)
    w.start(profile="ros2", library="lugrip")

    def channel(topic: str, typ: str) -> int:
        sid = w.register_schema(name=typ.replace("/", "/msg/", 1), encoding="ros2msg",
                                data=_ros2_msgdef(typ).encode())
        return w.register_channel(topic=topic, message_encoding="cdr", schema_id=sid)

    wid = channel(wrench_topic, "geometry_msgs/WrenchStamped")
    oid = channel(omega_topic, "geometry_msgs/TwistStamped") if log.omega is not None else None
    mid = channel(_DEFAULT_MANEUVER_TOPIC, "std_msgs/Int32")
    # metadata first: a file cut short by a crash still says how to read it
    w.add_metadata(_MCAP_META, {
        "format_version": "1", "wrench_topic": wrench_topic,
        "omega_topic": omega_topic if log.omega is not None else "",
        "maneuver_topic": _DEFAULT_MANEUVER_TOPIC,
        "force_vector": "true" if log.has_force_vector else "false", "t0_ns": str(t0),
        "frame_id": frame_id, "units": json.dumps(UNITS)})
    if log.has_force_vector:
        fx, fy = log.f_x.tolist(), log.f_y.tolist()
    else:
        fx, fy = [0.0] * n, log.f_t.tolist()
    fz, tz = log.f_n.tolist(), log.tau.tolist()
    om = log.omega.tolist() if log.omega is not None else None
    man = log.maneuver.tolist()
    for i in range(n):
        s = stamps[i]
        data = _encode_cdr("geometry_msgs/WrenchStamped", (fx[i], fy[i], fz[i], 0.0, 0.0, tz[i]),
                           s, frame_id)
        w.add_message(channel_id=wid, log_time=s, publish_time=s, data=data, sequence=i)
        if om is not None:
            data = _encode_cdr("geometry_msgs/TwistStamped", (0.0, 0.0, 0.0, 0.0, 0.0, om[i]),
                               s, frame_id)
            w.add_message(channel_id=oid, log_time=s, publish_time=s, data=data, sequence=i)
        if i == 0 or man[i] != man[i - 1]:
            w.add_message(channel_id=mid, log_time=s, publish_time=s,
                          data=_encode_cdr("std_msgs/Int32", (man[i],)), sequence=i)
    w.finish()


def write_log(log: SlidingLog, path: str | os.PathLike, *, format: str | None = None,
              overwrite: bool = False, wrench_topic: str | None = None,
              omega_topic: str | None = None, frame_id: str = "fingertip") -> Path:
    """Write a sliding log as CSV, Parquet or MCAP (chosen by suffix or ``format``).

    CSV and Parquet hold the columns of :meth:`SlidingLog.columns` (f_x/f_y when present,
    else f_t; omega when present; maneuver), floats at full precision; Parquet also stores
    ``meta`` as JSON. MCAP holds ROS 2 ``geometry_msgs/msg/WrenchStamped`` messages (CDR) on
    ``wrench_topic`` (default ``/lugrip/wrench``), omega as ``TwistStamped`` angular.z on
    ``omega_topic`` (default ``/lugrip/omega``), maneuver changes as ``std_msgs/Int32`` and a
    metadata record so :func:`read_log` restores the log (times to the nanosecond).

    The file is written to a temporary file beside ``path`` and renamed into place, so a
    failure leaves no partial file and an existing file is untouched.

    Raises:
        FileExistsError: ``path`` exists and ``overwrite`` is False.
        LogError: unknown or unwritable format.
    Returns:
        The path written.
    """
    path = Path(path)
    file = str(path)
    fmt = format or _SUFFIXES.get(path.suffix.lower())
    if fmt not in _WRITABLE:
        raise LogError(file, f"cannot write {fmt or path.suffix or 'a file without suffix'!r}"
                       f"; write_log writes {', '.join(_WRITABLE)} (suffixes .csv, .parquet, "
                       ".pq, .mcap)")
    if not isinstance(log, SlidingLog):
        raise TypeError(f"write_log: expected a SlidingLog, got {type(log).__name__}")
    if fmt == "csv":
        body: Callable = _write_csv
    elif fmt == "parquet":
        _need("pyarrow.parquet", "writing Parquet")
        body = _write_parquet
    else:
        _need("mcap.writer", "writing MCAP")

        def body(lg, fh):
            _write_mcap(lg, fh, wrench_topic, omega_topic, frame_id)
    _atomic_write(path, overwrite, lambda fh: body(log, fh))
    return path


def _atomic_write(path: Path, overwrite: bool, body: Callable) -> None:
    """Write through a temporary file in the same directory, then rename into place."""
    def exists_error() -> FileExistsError:
        return FileExistsError(errno.EEXIST, "file exists, not overwriting (pass "
                               "overwrite=True to replace it)", str(path))

    if path.is_dir():
        raise IsADirectoryError(errno.EISDIR, "is a directory", str(path))
    if path.exists() and not overwrite:
        raise exists_error()
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".part")
    try:
        with os.fdopen(fd, "wb") as fh:
            body(fh)
            fh.flush()
            os.fsync(fh.fileno())
        os.chmod(tmp, 0o644)
        if overwrite:
            os.replace(tmp, path)
        else:
            try:
                os.link(tmp, path)  # atomic and refuses to replace a file created meanwhile
            except FileExistsError:
                raise exists_error() from None
            except OSError:  # no hard links on this file system
                if path.exists():
                    raise exists_error() from None
                os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
