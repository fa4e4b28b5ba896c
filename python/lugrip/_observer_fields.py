"""The observer's setting names, kinds and enumerations, from the C++ field tables
(bindings/tables.hpp; defaults stay in C++): shared by :mod:`lugrip._observer` and the parameter
files' ``observer:`` block (:mod:`lugrip._params`), which must not import the observer."""

from __future__ import annotations

from . import _core

__all__ = ["GAIN_MODES", "INTEGRATORS"]

INTEGRATORS = {
    "implicit": _core.Integrator.Implicit,
    "rk4": _core.Integrator.Rk4,
    "rk4_adaptive": _core.Integrator.Rk4Adaptive,
    "rosenbrock": _core.Integrator.Rosenbrock,
}
GAIN_MODES = {"fixed": _core.GainMode.Fixed, "bandwidth": _core.GainMode.Bandwidth}
_COR_FIELDS = tuple(name for name, _kind, _doc in _core.CorSettings.fields)
_OBS_KINDS = {
    name: kind for name, kind, _doc in _core.ObserverSettings.fields if kind in ("float", "int", "bool")
}
_OBS_FIELDS = tuple(_OBS_KINDS)
