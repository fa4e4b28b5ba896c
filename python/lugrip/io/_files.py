"""The readers and writers behind :mod:`lugrip.io` (read_log, write_log, the format detection,
maneuver segmentation and atomic writes), in a module of their own so that the package's other
modules (``_grasp``) import them without importing the package itself."""

from __future__ import annotations

import errno
import math
import os
import tempfile
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

import numpy as np

from ._csv import _read_csv, _write_csv
from ._extras import need
from ._log import (
    COLUMNS,
    UNITS,
    LogError,
    SlidingLog,
    _validate,
)
from ._units import _expand_units, _unit_factor

#: ``format=`` names accepted by :func:`read_log` / :func:`write_log`.
FORMATS = ("csv", "parquet", "mcap", "ros1", "ros2")

_SUFFIXES = {".csv": "csv", ".parquet": "parquet", ".pq": "parquet", ".mcap": "mcap",
             ".bag": "ros1", ".db3": "ros2"}
_WRITABLE = ("csv", "parquet", "mcap")
_EXTRA_FOR = {"parquet": "reading Parquet", "mcap": "reading MCAP",
              "ros1": "reading ROS 1 bags", "ros2": "reading ROS 2 bags"}
_MODULE_FOR = {"parquet": "pyarrow.parquet", "mcap": "mcap.stream_reader",
               "ros1": "rosbags.highlevel", "ros2": "rosbags.highlevel"}


# ---------------------------------------------------------------------------------------------
# Maneuvers that the file does not mark
# ---------------------------------------------------------------------------------------------

def maneuvers_from_windows(t: np.ndarray, windows: Sequence[tuple[float, float]],
                           file: str | None = None) -> np.ndarray:
    """Maneuver id per sample from time windows ``[(t_start, t_end), ...]`` [s] on the log's
    time axis: samples with t_start <= t < t_end get id k + 1 for the k-th window (in the order
    given), every other sample id 0. Windows must be finite, non-empty and must not overlap."""
    t = np.asarray(t, dtype=np.float64)
    ids = np.zeros(len(t), dtype=np.int64)
    spans = []
    for k, win in enumerate(windows):
        try:
            a, b = (float(x) for x in win)
        except (TypeError, ValueError):
            raise LogError(file, f"maneuver window {k + 1}: expected (t_start, t_end), got "
                           f"{win!r}") from None
        if not (math.isfinite(a) and math.isfinite(b) and b > a):
            raise LogError(file, f"maneuver window {k + 1}: [{a!r}, {b!r}) must be finite with "
                           "t_end > t_start")
        for j, (a2, b2) in enumerate(spans):
            if a < b2 and a2 < b:
                raise LogError(file, f"maneuver windows {j + 1} and {k + 1} overlap")
        spans.append((a, b))
        ids[(t >= a) & (t < b)] = k + 1
    return ids


def _noise_std(x: np.ndarray) -> float:
    """White-noise std of a signal from its first differences (robust: median absolute)."""
    d = np.diff(x[np.isfinite(x)])
    return float(np.median(np.abs(d))) / 0.6745 / math.sqrt(2.0) if d.size else 0.0


def find_maneuvers(log: SlidingLog, *, min_rest: float = 0.05,
                   omega_threshold: float = 0.01) -> np.ndarray:
    """Maneuver ids found from the motion, for logs that do not mark them.

    A maneuver of a prescribed-motion recording starts from an unloaded rest (the observer
    restarts with z = 0, which holds only without a friction load). A sample is at rest when
    the torsional moment and the tangential force are at their noise level (|tau| and f_t at
    most five noise deviations, estimated from first differences, or 0.1 % of their 99th
    percentile) and,
    when the log carries ground-truth ``omega``, the motion is still (|omega| <=
    ``omega_threshold`` [rad/s]). Every run of rest samples lasting ``min_rest`` [s] or more
    ends a maneuver; the next one starts at the run's middle. Samples without contact
    (f_n <= 0 or invalid) split maneuvers too. Returns int64 ids 0, 1, ... of shape (n,).
    """
    n = len(log)
    ids = np.zeros(n, dtype=np.int64)
    if n < 3:
        return ids
    rest = np.ones(n, dtype=bool)
    for x in (np.asarray(log.tau, dtype=np.float64), np.asarray(log.f_t, dtype=np.float64)):
        finite = np.isfinite(x)
        level = 1e-3 * float(np.percentile(np.abs(x[finite]), 99)) if finite.any() else 0.0
        rest &= finite & (np.abs(x) <= max(5.0 * _noise_std(x), level))
    if log.omega is not None:
        om = np.asarray(log.omega, dtype=np.float64)
        rest &= ~(np.isfinite(om) & (np.abs(om) > omega_threshold))
    contact = log.valid & (np.asarray(log.f_n) > 0)
    starts = np.zeros(n, dtype=bool)
    t = np.asarray(log.t, dtype=np.float64)
    edges = np.diff(np.concatenate(([0], rest.astype(np.int8), [0])))
    for a, b in zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)):
        if t[b - 1] - t[a] >= min_rest and a > 0 and b < n:
            starts[(a + b) // 2] = True
    regain = np.zeros(n, dtype=bool)
    regain[1:] = contact[1:] & ~contact[:-1]
    starts |= regain
    starts[0] = False
    return np.cumsum(starts).astype(np.int64)


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
                       f"{known}); [[alt:pass format= to choose one|give the file one of these suffixes]]")
    if fmt == "mcap" and (path.parent / "metadata.yaml").exists():
        return "ros2"  # the storage file of a ROS 2 bag: read the bag (its metadata)
    return fmt


def read_log(path: str | os.PathLike, *, format: str | None = None,
             wrench_topic: str | None = None, omega_topic: str | None = None,
             maneuver_topic: str | None = None, maneuvers=None,
             flip_normal: bool = False, contact_offset: float | None = None,
             units: Mapping[str, str] | None = None, check_units: bool = True,
             max_nan_run: int = 3, allow_gaps: bool = False,
             time_source: str = "header",
             columns: Mapping[str, str] | None = None) -> SlidingLog:
    """Read a sliding log.

    Args:
        path: a ``.csv``, ``.parquet``/``.pq``, ``.mcap`` or ROS 1 ``.bag`` file, a ROS 2 bag
            directory (``metadata.yaml`` + storage) or one of its ``.db3``/``.mcap`` files.
        format: one of :data:`FORMATS` to override the suffix.
        wrench_topic: ROS sources: the ``geometry_msgs/WrenchStamped`` (or ``Wrench``) topic;
            default: the only wrench topic, or the one a lugrip-written MCAP names.
        omega_topic: ROS sources: ground-truth angular velocity about the sensor's z axis,
            ``TwistStamped``/``Twist`` (angular.z), ``Vector3[Stamped]`` (z),
            ``Float64``/``Float32``, or a ``PoseStamped`` of the object in the fingertip's frame
            (motion capture), differentiated: the rate of its twist angle about z,
            2 atan2(q_z, q_w) unwrapped, by central differences on the stamps; linearly
            resampled onto the wrench times (NaN outside its time span and across gaps longer
            than 10 of its median periods).
        maneuver_topic: ROS sources: a ``std_msgs`` integer (or float holding integers) topic
            whose latest message at or before each wrench sample is that sample's maneuver id
            (header stamps against header stamps when both have them, else log times;
            samples before the first message take its id); default: the one a
            lugrip-written MCAP names.
        maneuvers: replaces the file's maneuver ids: ``"motion"`` finds them from the wrench
            and omega (:func:`find_maneuvers`), ``"auto"`` keeps the file's when a column or
            topic marks them and finds them from the motion otherwise (the command line's
            default), a sequence of ``(t_start, t_end)`` windows [s] numbers them
            (:func:`maneuvers_from_windows`); None keeps the file's (all zeros when it has
            none).
        flip_normal: the sensor's z axis points toward the object (out of the pad), so its
            force z is negative while pressed: rotate the frame by pi about x (y and z of
            force and moment, and omega, change sign) so that f_n > 0 in contact.
        contact_offset: ROS sources whose wrench is measured at the sensor origin, not at the
            contact: distance [m] from that origin to the pad surface along the normal (> 0
            when the origin lies behind the surface). The centre of pressure is located from
            torque.x/y and the torsional moment moved to it (docs/sliding_log.md).
        units: units of the source columns, converted to SI, e.g. ``{'tau': 'N mm',
            't': 'ms'}``; key ``'force'`` sets every force column. A column given a unit here
            (or in a table header as ``tau [N mm]``) skips the magnitude check.
        check_units: run the magnitude checks that catch ms, mN, gram-force and N mm.
        max_nan_run: longest run of non-finite force/torque samples accepted (with a
            :class:`LogWarning`; the samples are flagged invalid and split segments).
        allow_gaps: accept longer runs too.
        time_source: ROS sources: ``"header"`` (default) orders the messages by their header
            stamps (the sensor's clock; log times for types without a header), ``"log"`` by
            the recorder's log times (for a sensor whose clock jumped).
        columns: CSV and Parquet tables whose columns have other names: {format name: the
            file's column}, e.g. ``{'t': 'time', 'f_n': 'Fz', 'tau': 'Mz'}`` (a header cell
            matches with or without its ``[unit]``, case-insensitively); a file column named
            like a mapped format column is then ignored.

    ROS header stamps that go backwards are an error (LogError naming the topic and the count
    of backward steps; ``time_source="log"`` reads such a recording by log time). Messages
    repeating the time of the one before are dropped with a warning (the first of each time
    kept) when they are at most 1 % of the topic's messages (at least one is tolerated), an
    error beyond (``lugrip.io._ros.MAX_DUPLICATE_FRACTION``). Log times out of order are sorted.

    Returns:
        SlidingLog with ``source`` = path and ``meta`` (format, units, topics, ...).

    Raises:
        FileNotFoundError: no such file.
        LogError: unknown type, empty or malformed file, missing column or topic, bad values
            (message names file, row or message, and column).
        MissingExtraError: the format needs a package of the ``[io]`` extra (an ImportError).
    """
    return _read(path, format=format, wrench_topic=wrench_topic, omega_topic=omega_topic,
                 maneuver_topic=maneuver_topic, maneuvers=maneuvers, flip_normal=flip_normal,
                 contact_offset=contact_offset, units=units, check_units=check_units,
                 max_nan_run=max_nan_run, allow_gaps=allow_gaps, stacklevel=4,
                 time_source=time_source, columns=columns)[0]


def _read(path, *, format, wrench_topic, omega_topic, maneuver_topic, maneuvers, flip_normal,
          contact_offset, units, check_units, max_nan_run, allow_gaps, stacklevel,
          finger: int | None = None, scalar_topics: Mapping[str, str] | None = None,
          time_source: str = "header", columns: Mapping[str, str] | None = None):
    """read_log's work; also returns the columns (with a two-finger table's ``command`` when
    ``finger`` is given, or the ``scalar_topics`` {column: topic} of a ROS source)."""
    path = Path(path)
    file = str(path)
    if not path.exists():
        raise FileNotFoundError(errno.ENOENT, "no such sliding log", file)
    fmt = _detect_format(path, format, file)
    if fmt in _MODULE_FOR:
        need(_MODULE_FOR[fmt], _EXTRA_FOR[fmt])
    if columns and fmt not in ("csv", "parquet"):
        raise LogError(file, f"[[opt:columns]] applies to CSV and Parquet tables, not to a {fmt} "
                       "recording (choose its topics with [[opt:wrench_topic]], "
                       "[[opt:omega_topic]], [[opt:maneuver_topic]])")
    ros_only = {"wrench_topic": wrench_topic, "omega_topic": omega_topic,
                "maneuver_topic": maneuver_topic, "contact_offset": contact_offset,
                "time_source": None if time_source == "header" else time_source}
    if fmt in ("csv", "parquet"):
        given_ros = [k for k, v in ros_only.items() if v is not None]
        if given_ros:
            raise LogError(file, f"[[opt:{given_ros[0]}]] applies to ROS recordings (MCAP, "
                           f"bags), not to a {fmt} table")
    if contact_offset is not None and not (math.isfinite(contact_offset)
                                           and contact_offset >= 0.0):
        raise LogError(file, f"contact_offset = {contact_offset!r} m: must be finite and >= 0")
    if fmt == "csv":
        cols, header_units, loc, meta = _read_csv(path, file, finger, columns)
    elif fmt == "parquet":
        from ._parquet import _read_parquet

        cols, header_units, loc, meta = _read_parquet(path, file, finger, columns)
    else:
        from ._ros import read_ros

        if fmt == "mcap":
            from ._mcap import McapSource

            src = McapSource(path, file)
        else:
            from ._bags import BagSource

            src = BagSource(path, file, ros1=(fmt == "ros1"))
        cols, header_units, loc, meta = read_ros(
            src, wrench_topic=wrench_topic, omega_topic=omega_topic,
            maneuver_topic=maneuver_topic, flip_normal=flip_normal,
            contact_offset=contact_offset, scalar_topics=scalar_topics,
            stacklevel=stacklevel, time_source=time_source)
        meta["format"] = fmt

    if columns:
        meta["columns"] = {k: str(v) for k, v in columns.items()}
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
    if isinstance(maneuvers, str) and maneuvers == "auto":
        maneuvers = None if "maneuver" in cols else "motion"
    if maneuvers is not None and not (isinstance(maneuvers, str) and maneuvers == "motion"):
        if isinstance(maneuvers, str):
            raise LogError(file, f"maneuvers={maneuvers!r}: give 'motion', 'auto' or a list of "
                           "(t_start, t_end) windows")
        cols["maneuver"] = maneuvers_from_windows(cols["t"], maneuvers, file).astype(float)
        meta["maneuvers_from"] = "windows"

    _validate(cols, loc, max_nan_run=max_nan_run, allow_gaps=allow_gaps,
              check_units=check_units, explicit=set(given), stacklevel=stacklevel)
    meta["units"] = {c: UNITS[c] for c in COLUMNS if c in cols or c in ("f_t", "maneuver")}
    if converted:
        meta["converted_from"] = converted
    log = SlidingLog._from_columns(cols, source=file, meta=meta, owned=True)
    if isinstance(maneuvers, str):
        log = SlidingLog(t=log.t, f_n=log.f_n, f_t=log.f_t, tau=log.tau, f_x=log.f_x,
                         f_y=log.f_y, omega=log.omega, maneuver=find_maneuvers(log),
                         source=log.source, meta={**log.meta, "maneuvers_from": "motion"})
    return log, cols


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
        need("pyarrow.parquet", "writing Parquet")
        from ._parquet import _write_parquet as body
    else:
        need("mcap.writer", "writing MCAP")
        need("rosbags.typesys", "writing MCAP")
        from ._mcap import write_mcap

        def body(lg, fh):
            write_mcap(lg, fh, wrench_topic, omega_topic, frame_id)
    _atomic_write(path, overwrite, lambda fh: body(log, fh))
    return path


def _atomic_write(path: Path, overwrite: bool, body: Callable) -> None:
    """Write through a temporary file in the same directory, then rename into place."""
    def exists_error() -> FileExistsError:
        return FileExistsError(errno.EEXIST, "file exists, not overwriting (pass "
                               "overwrite=True to replace it)", str(path))

    if path.is_dir():
        raise IsADirectoryError(errno.EISDIR, "is a directory", str(path))
    if path.exists() and not path.is_file():  # a device or FIFO: a rename would replace it
        raise OSError(errno.EINVAL, "not a regular file, not replaced (also with "
                      "overwrite=True)", str(path))
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
