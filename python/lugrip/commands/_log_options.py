"""Command-line options for reading a sliding log, shared by every subcommand that reads one
(``observe``, ``replay``, ...): :func:`add_log_options` adds them to a parser,
:func:`log_kwargs` turns the parsed options into :func:`lugrip.read_log` keywords and
:func:`read_log_from_args` reads the log."""

from __future__ import annotations

import argparse
import math
from pathlib import Path

__all__ = ["add_log_options", "log_kwargs", "parse_columns", "parse_maneuvers", "parse_units",
           "read_log_from_args"]

_UNIT_KEYS = ("t", "f_n", "f_x", "f_y", "f_t", "tau", "omega", "force", "command")


def _key_values(text: str, keys, what: str, example: str) -> dict[str, str]:
    """``KEY=VALUE[,KEY=VALUE...]`` with KEY among ``keys``; ``what`` names the two parts
    (``COLUMN=UNIT``) in the messages, ``example`` shows a valid value."""
    out: dict[str, str] = {}
    key_word = what.split("=")[0].lower()
    for item in text.split(","):
        key, sep, value = item.partition("=")
        key, value = key.strip(), value.strip()
        if not sep or not key or not value:
            raise argparse.ArgumentTypeError(
                f"invalid value {item!r}: expected {what}, e.g. {example}")
        if key not in keys:
            raise argparse.ArgumentTypeError(
                f"invalid {key_word} {key!r}: expected one of {', '.join(keys)}")
        out[key] = value
    return out


def parse_units(text: str) -> dict[str, str]:
    """argparse type for ``--units``: ``COLUMN=UNIT[,COLUMN=UNIT...]``, an underscore standing
    for a space in the unit (``tau=N_mm``); COLUMN 'force' sets every force column, 'command'
    is a two-finger log's recorded command."""
    units = _key_values(text, _UNIT_KEYS, "COLUMN=UNIT", "tau=N_mm")
    return {key: unit.replace("_", " ") for key, unit in units.items()}


def parse_columns(text: str) -> dict[str, str]:
    """argparse type for ``--columns``: ``NAME=COLUMN[,NAME=COLUMN...]``, NAME one of the
    format's columns (t, f_n, f_x, f_y, f_t, tau, omega, maneuver), COLUMN the file's header."""
    from ..io._log import COLUMNS

    return _key_values(text, COLUMNS, "NAME=COLUMN", "f_n=Fz,tau=Mz")


def parse_maneuvers(text: str):
    """argparse type for ``--maneuvers``: 'auto' (the file's ids when a column or topic marks
    them, else found from the motion), 'file' (the file's own ids), 'motion' (found from the
    motion) or time windows ``START:END[,START:END...]`` in seconds."""
    key = text.strip().lower()
    if key in ("auto", "file", "motion"):
        return key
    windows = []
    for item in text.split(","):
        a, sep, b = item.partition(":")
        try:
            start, end = float(a), float(b)
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"invalid value {item!r}: expected 'auto', 'file', 'motion' or START:END windows in "
                "seconds, e.g. 0:2.5,3:5.5") from None
        if not sep or not (math.isfinite(start) and math.isfinite(end) and end > start):
            raise argparse.ArgumentTypeError(
                f"invalid window {item!r}: need finite START < END [s]")
        windows.append((start, end))
    return windows


def _non_negative(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"invalid value {text!r}: expected a number") from None
    if not (math.isfinite(value) and value >= 0.0):
        raise argparse.ArgumentTypeError(f"invalid value {text!r}: must be finite and >= 0")
    return value


def add_log_options(parser: argparse.ArgumentParser, *, wrench_topic: bool = True,
                    omega_topic: bool = True, maneuvers: bool = True, columns: bool = True):
    """Add the log-reading options in their own group; returns the group. ``wrench_topic``,
    ``omega_topic``, ``maneuvers``, ``columns`` = False leave out ``--wrench-topic`` (for
    commands that read several wrench topics), ``--omega-topic`` (no ground truth used),
    ``--maneuver-topic``/``--maneuvers`` (no observer restarts) and ``--columns`` (tables
    with a fixed layout)."""
    r = parser.add_argument_group("reading the log (ROS recordings, units, maneuvers, damage)")
    if columns:
        r.add_argument("--columns", type=parse_columns, action="append", metavar="NAME=COLUMN",
                       help="CSV/Parquet: the file's names of the columns, e.g. --columns "
                            "t=time,f_n=Fz,f_x=Fx,f_y=Fy,tau=Mz,omega=wz; repeatable")
    if wrench_topic:
        r.add_argument("--wrench-topic", metavar="TOPIC",
                       help="WrenchStamped topic (MCAP, bags; default: the only one)")
    if omega_topic:
        r.add_argument("--omega-topic", metavar="TOPIC",
                       help="ground truth: an angular velocity topic (Twist[Stamped] "
                            "angular.z, Vector3[Stamped] z, Float64) or a pose topic "
                            "(PoseStamped of the object in the fingertip frame, e.g. motion "
                            "capture; its twist angle about z differentiated)")
    if maneuvers:
        r.add_argument("--maneuver-topic", metavar="TOPIC",
                       help="std_msgs integer topic of maneuver ids (MCAP, bags)")
        r.add_argument("--maneuvers", type=parse_maneuvers, default="auto", metavar="SPEC",
                       help="where maneuvers (observer restarts) come from: 'auto' (default: "
                            "the file's maneuver column or topic, else 'motion'), 'file' (the "
                            "column or topic; one maneuver without), 'motion' (found from "
                            "unloaded rests), or windows START:END[,START:END...] in seconds")
    r.add_argument("--flip-normal", action="store_true",
                   help="the sensor's z axis points out of the pad (f_n = -force.z, ...)")
    r.add_argument("--contact-offset", type=_non_negative, metavar="M",
                   help="the wrench is measured at the sensor origin M metres behind the pad "
                        "surface: move it to the contact (uses torque.x/y; ROS sources)")
    r.add_argument("--units", type=parse_units, action="append", metavar="COL=UNIT",
                   help="units of the log's columns, e.g. --units tau=N_mm,t=ms (force=mN "
                        "sets every force); repeatable")
    r.add_argument("--allow-gaps", action="store_true",
                   help="accept long NaN runs (the observer restarts after them)")
    r.add_argument("--time-source", choices=("header", "log"), default=None,
                   help="ROS sources: order the messages by their header stamps (default; a "
                        "clock that jumps back or stamps repeated on over 1 %% of the messages "
                        "is an error) or by the recorder's log times")
    return r


def log_kwargs(args: argparse.Namespace) -> dict:
    """:func:`lugrip.read_log` keywords from options added by :func:`add_log_options` (options
    a parser left out read as their defaults)."""
    units: dict[str, str] = {}
    for part in getattr(args, "units", None) or []:
        units.update(part)
    columns: dict[str, str] = {}
    for part in getattr(args, "columns", None) or []:
        columns.update(part)
    maneuvers = getattr(args, "maneuvers", "file")
    return {
        "wrench_topic": getattr(args, "wrench_topic", None),
        "omega_topic": getattr(args, "omega_topic", None),
        "maneuver_topic": getattr(args, "maneuver_topic", None),
        "maneuvers": None if maneuvers == "file" else maneuvers,
        "flip_normal": bool(getattr(args, "flip_normal", False)),
        "contact_offset": getattr(args, "contact_offset", None),
        "units": units or None,
        "allow_gaps": bool(getattr(args, "allow_gaps", False)),
        "time_source": getattr(args, "time_source", None) or "header",
        "columns": columns or None,
    }


def read_log_from_args(path, args: argparse.Namespace, **overrides):
    """Read the log at ``path`` with the options of :func:`add_log_options` (``overrides``
    replace single keywords). Errors are :class:`lugrip.LogError` (exit 2; its hints read as
    these options) or a missing-extra ImportError (exit 2)."""
    from ..commands import CliError
    from ..io import read_log

    if not Path(path).exists():
        raise CliError(f"{path}: no such file or directory")
    kwargs = log_kwargs(args)
    kwargs.update(overrides)
    return read_log(path, **kwargs)
