"""The sliding-log type: :class:`SlidingLog`, its errors and the checks every reader runs.

Columns, units and the validation rules are described in docs/sliding_log.md.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import re
import warnings
from collections.abc import Iterator, Mapping
from typing import Any

import numpy as np

#: Column names of the format, in the order they are written.
COLUMNS = ("t", "f_n", "f_x", "f_y", "f_t", "tau", "omega", "maneuver")
#: SI unit of each column.
UNITS = {"t": "s", "f_n": "N", "f_x": "N", "f_y": "N", "f_t": "N", "tau": "N m",
         "omega": "rad/s", "maneuver": "-"}
_SIGNALS = ("f_n", "f_t", "f_x", "f_y", "tau")  # a non-finite value makes the sample invalid
_FORCES = ("f_n", "f_t", "f_x", "f_y")

# Unit thresholds of the magnitude checks (docs/sliding_log.md, "Unit checks").
_MAX_FORCE_MEDIAN = 200.0  # [N] median |force| above this is not a fingertip in newtons
_MAX_TAU_PER_FORCE = 0.1  # [m] |tau|/f_n is at most mu*xi*rho, a few cm at most
_GAP_FACTOR = 5.0  # default segments() gap: this many median sample periods
# [-] f_t/f_n per block: mu plus the viscous term (beta_A) at high slip speed; synthetic
# Table 1 maneuvers reach 14, a block of f_t in mN against f_n in N several hundred
_MAX_FRICTION_RATIO = 100.0
_UNIT_BLOCK = 200  # [rows] window of the per-block unit checks (docs/sliding_log.md)


_HINT_RE = re.compile(r"\[\[(units|flag|opt|alt):([^\]]*)\]\]")


def _render_hints(text: str, cli: bool) -> str:
    """Replace the hint marks of a message by Python or command-line syntax.

    ``[[units:tau=N mm]]`` becomes ``units={'tau': 'N mm'}`` or ``--units tau=N_mm``;
    ``[[flag:flip_normal]]`` becomes ``flip_normal=True`` or ``--flip-normal``;
    ``[[opt:wrench_topic]]`` becomes ``wrench_topic=`` or ``--wrench-topic``;
    ``[[alt:python words|command-line words]]`` picks one of its two texts.
    """
    def one(m: re.Match) -> str:
        kind, body = m.group(1), m.group(2)
        if kind == "flag":
            return f"--{body.replace('_', '-')}" if cli else f"{body}=True"
        if kind == "opt":
            return f"--{body.replace('_', '-')}" if cli else f"{body}="
        if kind == "alt":
            python, _, command_line = body.partition("|")
            return command_line if cli else python
        pairs = [item.split("=", 1) for item in body.split(",")]
        if cli:
            return "--units " + ",".join(f"{k}={v.replace(' ', '_')}" for k, v in pairs)
        return "units={" + ", ".join(f"'{k}': '{v}'" for k, v in pairs) + "}"

    return _HINT_RE.sub(one, text)


class LogError(ValueError):
    """A sliding log that cannot be used as it is.

    The message reads ``<file>: <where>: <problem>``; hints in it use Python keywords
    (``units={'tau': 'N mm'}``), :attr:`cli_message` is the same text with command-line
    options (``--units tau=N_mm``). Attributes: ``file`` (str or None for in-memory arrays),
    ``row`` (1-based row as a spreadsheet shows it, header = row 1; for ROS sources the 1-based
    message number on the topic; None when the problem is not one row), ``column`` (column
    name or None), ``index`` (0-based sample index or None).
    """

    def __init__(self, file: str | os.PathLike | None, problem: str, *, where: str = "",
                 row: int | None = None, column: str | None = None,
                 index: int | None = None):
        self.file = None if file is None else str(file)
        self.row = row
        self.column = column
        self.index = index
        head = self.file if self.file is not None else "<arrays>"
        raw = f"{head}: {where}: {problem}" if where else f"{head}: {problem}"
        self.problem = _render_hints(problem, cli=False)
        self.cli_message = _render_hints(raw, cli=True)
        super().__init__(_render_hints(raw, cli=False))


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
        self.rows = rows  # row (line) of a table / message number of a topic per sample
        self.topic = topic
        self.fields = dict(fields or {})
        self.kind = kind  # "table" | "ros" | "arrays"

    def row(self, i: int) -> int | None:
        if self.kind == "table":
            return int(self.rows[i]) if self.rows is not None else i + 2
        if self.kind == "ros":  # message number on the topic, as recorded
            return int(self.rows[i]) if self.rows is not None else i + 1
        return None

    def where(self, i: int | None, column: str | None) -> str:
        col = f"column '{column}'" if column else ""
        if i is None:
            return col
        if self.kind == "table":
            here = f"row {self.row(i)}"
        elif self.kind == "ros":
            here = f"message {self.row(i)} on topic '{self.topic}'"
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
            return f"messages {self.row(i)}-{self.row(j)} on topic '{self.topic}'"
        return f"samples {i}-{j} (0-based indices)"

    def error(self, problem: str, i: int | None = None, column: str | None = None) -> LogError:
        i = None if i is None else int(i)
        return LogError(self.file, problem, where=self.where(i, column),
                        row=None if i is None else self.row(i), column=column, index=i)

# ---------------------------------------------------------------------------------------------
# The log
# ---------------------------------------------------------------------------------------------

class _Owned:
    """An array a reader built and hands over: :class:`SlidingLog` keeps it without a copy
    (a 10**7-row log holds each column once)."""

    __slots__ = ("array",)

    def __init__(self, array: np.ndarray):
        self.array = array


def _as_float(name: str, value: Any) -> np.ndarray:
    if isinstance(value, _Owned) and value.array.dtype == np.float64:
        arr = value.array
    else:
        arr = np.array(value.array if isinstance(value, _Owned) else value, dtype=np.float64,
                       copy=True)
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
        elif isinstance(self.maneuver, _Owned) and self.maneuver.array.dtype == np.int64:
            man = self.maneuver.array
        else:
            raw = np.asarray(self.maneuver)
            if raw.ndim != 1:
                raise ValueError(f"SlidingLog.maneuver must be 1-D, got shape {raw.shape}")
            if raw.dtype.kind not in "iub":
                as_f = raw.astype(np.float64)
                if not np.all(np.isfinite(as_f)) or np.any(as_f != np.round(as_f)):
                    raise ValueError("SlidingLog.maneuver must hold integers")
            man = raw.astype(np.int64, copy=True)
        if man.ndim != 1:
            raise ValueError(f"SlidingLog.maneuver must be 1-D, got shape {man.shape}")
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
    def _from_columns(cls, cols: Mapping[str, np.ndarray], *, source, meta,
                      owned: bool = False) -> SlidingLog:
        """The log of a reader's columns; ``owned``: the arrays are the caller's to hand over
        (kept without a copy and made read-only; nothing else may write to them)."""
        f_t = cols.get("f_t")
        if "f_x" in cols:
            f_t = np.hypot(cols["f_x"], cols["f_y"])
        meta = dict(meta)
        meta.setdefault("units", {c: UNITS[c] for c in COLUMNS
                                  if c in cols or c == "f_t" or c == "maneuver"})
        own = _Owned if owned else (lambda a: a)
        opt = {k: own(cols[k]) if k in cols else None for k in ("f_x", "f_y", "omega")}
        return cls(t=own(cols["t"]), f_n=own(cols["f_n"]), f_t=_Owned(f_t) if "f_x" in cols
                   else own(f_t), tau=own(cols["tau"]), **opt,
                   maneuver=None if "maneuver" not in cols
                   else _Owned(cols["maneuver"].astype(np.int64)),
                   source=source, meta=meta)

    def _without_force_vector(self) -> SlidingLog:
        """The same log without f_x and f_y (f_t kept), sharing the other arrays (read-only):
        for a replay that reads f_t only, two columns fewer in memory."""
        if self.f_x is None:
            return self
        keep = {k: _Owned(getattr(self, k)) for k in ("t", "f_n", "f_t", "tau", "maneuver")}
        if self.omega is not None:
            keep["omega"] = _Owned(self.omega)
        return SlidingLog(**keep, source=self.source, meta=self.meta)

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
        step = step[back[:1]] if back.size else None  # the first backward step only
        if back.size:
            i = int(back[0]) + 1
            prev = loc.where(i - 1, None)
            if step[0] == 0:
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
        _check_unit_blocks(cols, loc, explicit)

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
                            "a sensor dropout? Pass [[flag:allow_gaps]] to keep it as a gap, which "
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
                            "sensor's z axis points toward the object; pass [[flag:flip_normal]] "
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
    override = "; if the values really are in {si}, pass [[units:{c}={si}]]"
    if "t" not in explicit and n > 1:
        dt = float(np.median(np.diff(t), overwrite_input=True))
        tmax = max(abs(float(np.max(t))), abs(float(np.min(t))))
        if tmax > 1e11 or dt > 100.0 or (n > 1000 and dt > 0.5):
            unit, scale = "ns", 1e-9
            for u, s in (("ms", 1e-3), ("us", 1e-6), ("ns", 1e-9)):
                if dt * s <= 0.5:
                    unit, scale = u, s
                    break
            raise loc.error(f"t does not look like seconds (median step {dt:.4g} over {n} "
                            f"samples, |t| up to {tmax:.4g}); it looks like {unit}: multiply by "
                            f"{scale:g} or pass [[units:t={unit}]]"
                            + override.format(si="s", c="t"), 1, "t")
    for c in _FORCES:
        if c in cols and c not in explicit:
            x = cols[c][np.isfinite(cols[c])]
            np.abs(x, out=x)
            if x.size and (med := float(np.median(x, overwrite_input=True))) > _MAX_FORCE_MEDIAN:
                i = _near(np.abs(cols[c]), med)
                raise loc.error(f"{c} does not look like newtons (median |{c}| = {med:.4g}, "
                                f"more than a fingertip carries); mN? divide by 1000 or pass "
                                f"[[units:{c}=mN]] (or [[units:force=mN]]); gram-force? "
                                f"pass [[units:force=gf]]" + override.format(si="N", c=c),
                                i, c)
    if "tau" not in explicit:
        tau, f_n = cols["tau"], cols["f_n"]
        ok = np.isfinite(tau) & np.isfinite(f_n)
        if ok.any():
            x = tau[ok]
            np.abs(x, out=x)
            med_tau = float(np.median(x, overwrite_input=True))
            del x
            med_fn = float(np.median(f_n[ok], overwrite_input=True))
            contact = ok & (f_n > max(0.1 * med_fn, 1e-3))
            ratio = np.abs(tau[contact])
            ratio /= f_n[contact]
            del contact
            p90 = float(np.percentile(ratio, 90, overwrite_input=True)) if ratio.size else 0.0
            if (med_tau > 0.5 and med_fn < 50.0) or p90 > _MAX_TAU_PER_FORCE:
                i = _near(np.abs(tau), med_tau)
                raise loc.error(f"tau does not look like N m (median |tau| = {med_tau:.4g} at "
                                f"median f_n = {med_fn:.4g} N; |tau|/f_n reaches {p90:.3g} m, "
                                f"a fingertip contact gives at most a few cm); it looks like "
                                f"N mm: divide by 1000 or pass [[units:tau=N mm]]"
                                + override.format(si="N m", c="tau"), i, "tau")


def _window_stat(x: np.ndarray, use: np.ndarray, width: int, q: float) -> tuple[np.ndarray,
                                                                                np.ndarray]:
    """(starts, stat): the q-th percentile of x over the samples ``use`` of each window of
    ``width`` rows (windows at 0, width, 2 width, ... and one ending at the last row); NaN
    where fewer than a quarter of a window's samples are used. x is overwritten (NaN where
    not used)."""
    n = len(x)
    k = n // width
    starts = np.arange(k) * width
    if n % width:
        starts = np.append(starts, n - width)
    stat = np.full(len(starts), np.nan)
    vals = x  # x is the caller's temporary: the unused samples become NaN in place
    np.copyto(vals, np.nan, where=~use)
    chunk = max(1, 1_000_000 // width)  # windows per pass: bounded temporary memory
    for a in range(0, len(starts), chunk):
        idx = starts[a:a + chunk, None] + np.arange(width)
        block = np.sort(vals[idx], axis=1)  # NaN last
        count = np.sum(np.isfinite(block), axis=1)
        enough = count >= width // 4
        if enough.any():
            # np.nanpercentile's linear interpolation, on the sorted finite values of each row
            b, k = block[enough], count[enough]
            pos = (q / 100.0) * (k - 1)
            lo = np.floor(pos).astype(np.int64)
            hi = np.minimum(lo + 1, k - 1)
            rows = np.arange(len(b))
            frac = pos - lo
            stat[a:a + chunk][enough] = (b[rows, lo] * (1.0 - frac) + b[rows, hi] * frac)
    return starts, stat


def _check_unit_blocks(cols: dict[str, np.ndarray], loc: _Locator,
                       explicit: set[str]) -> None:
    """LogError when a block of rows is in other units than the rest (the whole-file checks
    of :func:`_check_units` pass a 5 % block in N mm): per window of ``_UNIT_BLOCK`` rows in
    contact, the 90th percentile of |tau|/f_n against the contact-size bound, of f_t/f_n
    against the friction bound, and the median f_n against the force bound. The message names
    the field and the rows of the first and last flagged windows."""
    f_n = cols["f_n"]
    n = len(f_n)
    width = _UNIT_BLOCK
    if n < 2 * width:
        return  # one or two windows: the whole-file checks are the block checks
    finite = np.isfinite(f_n)
    if not finite.any():
        return
    med_fn = float(np.median(f_n[finite], overwrite_input=True))
    contact = finite & (f_n > max(0.1 * med_fn, 1e-3))

    # each checked quantity is computed when its check runs (one at a time in memory)
    def tau_per_force():
        return np.abs(cols["tau"]) / f_n

    def friction_ratio():
        if "f_t" in cols:
            return cols["f_t"] / f_n
        x = np.hypot(cols["f_x"], cols["f_y"])
        x /= f_n
        return x

    with np.errstate(divide="ignore", invalid="ignore"):
        checks = []
        if "f_n" not in explicit:
            checks.append(("f_n", lambda: np.abs(f_n), finite, 50.0, _MAX_FORCE_MEDIAN, "N",
                           "median f_n", "N", "mN or gram-force"))
        if "tau" in cols and "tau" not in explicit:
            checks.append(("tau", tau_per_force, contact, 90.0, _MAX_TAU_PER_FORCE,
                           "N m", "|tau|/f_n", "m", "N mm"))
        ft_col = "f_t" if "f_t" in cols else ("f_y" if "f_y" in cols else None)
        if ft_col is not None and ft_col not in explicit and "f_n" not in explicit:
            checks.append((ft_col, friction_ratio, contact, 90.0, _MAX_FRICTION_RATIO, "N",
                           "f_t/f_n", "", "mN (f_n in N)"))
        for col, quantity, use, q, bound, si, what, unit, likely in checks:
            x = quantity()
            starts, stat = _window_stat(x, use & np.isfinite(x), width, q)
            del x
            bad = np.flatnonzero(stat > bound)
            if not bad.size:
                continue
            ok = stat[np.isfinite(stat) & ~(stat > bound)]
            a, b = int(starts[bad[0]]), int(starts[bad[-1]]) + width - 1
            rest = (f"; {float(np.max(ok)):.3g}{' ' + unit if unit else ''} at most in the "
                    "other blocks") if ok.size else ""
            raise loc.error(
                f"mixed units: {col} in {loc.rows_text(a, b)} ({bad.size} block(s) of {width} "
                f"rows, {100.0 * bad.size * width / n:.2g} % of the file) is not in {si}: "
                f"{what} reaches {float(np.nanmax(stat[bad])):.3g}{' ' + unit if unit else ''} "
                f"there, over the {bound:g}{' ' + unit if unit else ''} a fingertip gives{rest}; "
                f"it looks like {likely}: convert those rows", a, col)


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
