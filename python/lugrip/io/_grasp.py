"""Two-finger grasp logs: both fingertips' wrenches on one time axis and the grasp-force
command the gripper was sent, the input of ``lugrip replay`` (docs/sliding_log.md,
"Two-finger logs")."""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from ._log import LogError, SlidingLog

__all__ = ["GRASP_FIELDS", "GraspLog", "read_grasp_log", "write_grasp_log"]

GRASP_FIELDS = ("f_n", "f_x", "f_y", "tau")
"""Order of the last axis of :attr:`GraspLog.wrench` (what SlipControl takes per finger)."""


@dataclasses.dataclass(frozen=True, eq=False)
class GraspLog:
    """Both fingers of a recorded grasp on finger 0's time axis.

    Attributes:
        t: sample times [s], shape (n,), strictly increasing.
        wrench: (n, fingers, 4) per finger (f_n [N], f_x [N], f_y [N], tau [N m]), the wrench
            the object exerts on each fingertip; NaN where a finger has no sample yet.
        command: the grasp-force command recorded with the log [N], (n,), or None; NaN
            before its first value.
        maneuver: maneuver id per sample (finger 0's), int64 (n,).
        fingers: one :class:`SlidingLog` per finger on this time axis.
        source: the file read, or None.
        meta: format, topics, per-finger meta.
    """

    t: np.ndarray
    wrench: np.ndarray
    command: np.ndarray | None
    maneuver: np.ndarray
    fingers: tuple
    source: str | None = None
    meta: dict = dataclasses.field(default_factory=dict)

    def __len__(self) -> int:
        return len(self.t)


def _wrench_of(log: SlidingLog) -> np.ndarray:
    """(n, 4) f_n, f_x, f_y, tau of one finger; a log with only f_t gets f_x = 0, f_y = f_t."""
    if log.has_force_vector:
        fx, fy = log.f_x, log.f_y
    else:
        fx, fy = np.zeros(len(log)), log.f_t
    return np.stack([log.f_n, fx, fy, log.tau], axis=1)


def _hold(t_src: np.ndarray, y: np.ndarray, t_dst: np.ndarray) -> np.ndarray:
    """Latest source row at or before each destination time; NaN rows before the first."""
    k = np.searchsorted(t_src, t_dst, side="right") - 1
    out = y[np.maximum(k, 0)].astype(np.float64, copy=True)
    out[k < 0] = np.nan
    return out


def read_grasp_log(path: str | os.PathLike, *, finger_topics: Sequence[str] | None = None,
                   command_topic: str | None = None, maneuver_topic: str | None = None,
                   maneuvers=None, flip_normal: bool = False,
                   contact_offset: float | None = None, units: Mapping[str, str] | None = None,
                   check_units: bool = True, max_nan_run: int = 3,
                   allow_gaps: bool = False, format: str | None = None,
                   time_source: str = "header") -> GraspLog:
    """Read a two-finger log.

    A table (CSV, Parquet) has ``t``, per finger k = 0, 1 the sliding-log columns with the
    suffix ``_k`` (``f_n_0``, ``f_x_0``, ``f_y_0`` or ``f_t_0``, ``tau_0``, optional
    ``omega_0``; same for ``_1``), and optionally ``command`` [N] and ``maneuver``. A ROS
    recording has one WrenchStamped topic per finger (``finger_topics``, finger 0 first) and
    optionally a ``std_msgs/Float64`` command topic; finger 1 and the command are held at
    their latest value at or before each finger-0 sample (what a control loop running on
    finger 0's samples would have seen). The other keywords are those of
    :func:`lugrip.read_log`, applied to both fingers (units: the per-finger column names
    without suffix, and ``command``).

    Raises:
        LogError: as read_log, naming the finger's columns or topic.
    """
    from ._files import _detect_format, _read

    p = Path(path)
    file = str(p)
    if not p.exists():
        raise FileNotFoundError(2, "no such grasp log", file)
    fmt = _detect_format(p, format, file)
    table = fmt in ("csv", "parquet")
    if table and (finger_topics or command_topic):
        raise LogError(file, "[[opt:finger_topics]] and [[opt:command_topic]] apply to ROS "
                       "recordings; a table names its fingers by the column suffixes _0 and _1")
    if not table:
        if finger_topics is None or len(finger_topics) not in (1, 2):
            raise LogError(file, "a ROS recording needs the wrench topic of each finger "
                           "([[opt:finger_topics]] finger 0 first, one or two topics)")
        if len(set(finger_topics)) != len(finger_topics):
            raise LogError(file, f"the finger topics must differ (got {list(finger_topics)})")
    common = {"format": format, "omega_topic": None, "maneuver_topic": maneuver_topic,
              "maneuvers": maneuvers, "flip_normal": flip_normal,
              "contact_offset": contact_offset, "units": units, "check_units": check_units,
              "max_nan_run": max_nan_run, "allow_gaps": allow_gaps, "stacklevel": 4,
              "time_source": time_source}
    fingers: list[SlidingLog] = []
    command = None
    n_fingers = 2 if table else len(finger_topics)
    for k in range(n_fingers):
        if table:
            log, cols = _read(p, wrench_topic=None, finger=k, **common)
        else:
            scalars = {"command": command_topic} if (k == 0 and command_topic) else None
            log, cols = _read(p, wrench_topic=finger_topics[k], scalar_topics=scalars,
                              **{**common, "maneuver_topic": maneuver_topic if k == 0 else None,
                                 "maneuvers": maneuvers if k == 0 else None})
        if k == 0 and "command" in cols:
            command = np.asarray(cols["command"], dtype=np.float64)
        fingers.append(log)
    base = fingers[0]
    wrench = np.empty((len(base), n_fingers, 4))
    wrench[:, 0, :] = _wrench_of(base)
    meta = {"format": fmt, "fingers": [f.meta for f in fingers]}
    if n_fingers == 2:
        other = fingers[1]
        if table:
            wrench[:, 1, :] = _wrench_of(other)
        else:  # finger 1 on finger 0's clock (t0 of each read is its own first stamp)
            shift = (int(other.meta["t0_ns"]) - int(base.meta["t0_ns"])) / 1e9
            wrench[:, 1, :] = _hold(other.t + shift, _wrench_of(other), base.t)
            held = {name: _hold(other.t + shift, getattr(other, name), base.t)
                    for name in ("f_n", "f_t", "tau", "f_x", "f_y")
                    if getattr(other, name) is not None}
            other = SlidingLog(t=base.t, **held, maneuver=base.maneuver, source=other.source,
                               meta=other.meta)
            fingers[1] = other
    if command is not None:
        bad = np.flatnonzero(np.isinf(command))
        if bad.size:
            raise LogError(file, f"command is {float(command[bad[0]])!r} at sample {bad[0]}")
    return GraspLog(t=base.t, wrench=wrench, command=command, maneuver=base.maneuver,
                    fingers=tuple(fingers), source=file, meta=meta)


def write_grasp_log(glog: GraspLog, path: str | os.PathLike, *, overwrite: bool = False) -> Path:
    """Write a two-finger log as a CSV or Parquet table (columns of :func:`read_grasp_log`:
    t, f_n_k, f_x_k, f_y_k, tau_k per finger, command when present, maneuver)."""
    from ._extras import need
    from ._files import _atomic_write

    path = Path(path)
    suffix = path.suffix.lower()
    cols: dict[str, np.ndarray] = {"t": glog.t}
    for k in range(glog.wrench.shape[1]):
        for j, name in enumerate(GRASP_FIELDS):
            cols[f"{name}_{k}"] = glog.wrench[:, k, j]
    if glog.command is not None:
        cols["command"] = glog.command
    cols["maneuver"] = glog.maneuver
    if suffix == ".csv":
        def body(fh):
            lists = [c.tolist() for c in cols.values()]
            lines = [",".join(cols)] + [",".join(map(repr, row)) for row in zip(*lists)]
            fh.write(("\n".join(lines) + "\n").encode())
    elif suffix in (".parquet", ".pq"):
        pa = need("pyarrow", "writing Parquet")
        pq = need("pyarrow.parquet", "writing Parquet")

        def body(fh):
            pq.write_table(pa.table({k: v for k, v in cols.items()}), fh)
    else:
        raise LogError(str(path), f"cannot write a grasp log as {suffix or 'no suffix'!r}; "
                       "use .csv or .parquet")
    _atomic_write(path, overwrite, body)
    return path
