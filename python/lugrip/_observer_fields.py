"""The observer's setting names, kinds and enumerations, from the C++ field tables
(include/lugrip/settings_fields.hpp; defaults stay in C++): shared by :mod:`lugrip._observer` and the parameter
files' ``observer:`` block (:mod:`lugrip._params`), which must not import the observer."""

from __future__ import annotations

from . import _core

__all__ = ["GAIN_MODES", "INTEGRATORS"]


def _choices(name: str, enum) -> dict:
    """{file spelling: enum value} of an enumeration field of ObserverSettings (value i is
    named choices[i] in the table)."""
    param = next(p for p in _core.ObserverSettings.params if p["name"] == name)
    return {text: enum(i) for i, text in enumerate(param["choices"])}


INTEGRATORS = _choices("integrator", _core.Integrator)
GAIN_MODES = _choices("gain_mode", _core.GainMode)
_COR_FIELDS = tuple(name for name, _kind, _doc in _core.CorSettings.fields)
_OBS_KINDS = {
    name: kind for name, kind, _doc in _core.ObserverSettings.fields if kind in ("float", "int", "bool")
}
_OBS_FIELDS = tuple(_OBS_KINDS)
