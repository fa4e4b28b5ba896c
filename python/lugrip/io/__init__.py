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
reads (docs/model.md §7.2). :func:`read_log` reads CSV and Parquet tables, MCAP files and
ROS 1 / ROS 2 bags holding ``geometry_msgs/WrenchStamped`` messages, decoded by rosbags'
typestore and mcap (no ROS installation needed; the ``[io]`` extra); :func:`write_log` writes
CSV, Parquet and MCAP (ROS 2 CDR). Maneuver ids come from the file (a column or a topic), from
time windows, or are found from the motion (:func:`find_maneuvers`).

One module per concept: ``_log`` (the type and its checks), ``_units``, ``_csv``,
``_parquet``, ``_ros`` (topics to columns), ``_mcap``, ``_bags``, ``_grasp`` (two-finger
logs for ``lugrip replay``), ``_extras`` (optional packages).

Malformed files raise :class:`LogError`, whose message names the file, the row (spreadsheet
numbering: header = row 1) or message, and the column.
"""

from __future__ import annotations

from ._extras import MissingExtraError, need  # noqa: F401 (need: the commands check an extra through it)
from ._files import (
    FORMATS,
    find_maneuvers,
    maneuvers_from_windows,
    read_log,
    write_log,
)
from ._grasp import GRASP_FIELDS, GraspLog, read_grasp_log, write_grasp_log
from ._log import COLUMNS, UNITS, LogError, LogWarning, SlidingLog
from ._ros import contact_wrench

__all__ = [
    "COLUMNS",
    "FORMATS",
    "GRASP_FIELDS",
    "UNITS",
    "GraspLog",
    "LogError",
    "LogWarning",
    "MissingExtraError",
    "SlidingLog",
    "contact_wrench",
    "find_maneuvers",
    "maneuvers_from_windows",
    "read_grasp_log",
    "read_log",
    "write_grasp_log",
    "write_log",
]
