"""Units of the sliding-log columns: names a file or the caller may give, and their factor to
SI."""

from __future__ import annotations

import math
from collections.abc import Mapping

from ._log import _FORCES, COLUMNS, LogError

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
             "tau": "torque", "omega": "angular velocity", "maneuver": "count",
             "command": "force"}


def _unit_key(unit: str) -> str:
    key = unit.strip()
    for ch in (" ", "_", "·", "⋅", "*", "."):
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

