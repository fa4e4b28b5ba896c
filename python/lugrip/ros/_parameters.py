"""The node's settings parameters, generated at run time from the C++ field tables.

Every scalar field of the tables the bindings expose (``lugrip._core.<Struct>.fields``: name,
kind, doc with the unit in brackets) becomes one parameter:

* ``contact.<field>``: ContactParams (the identified contact model);
* ``observer.<field>`` and ``observer.cor.<field>``: ObserverSettings and its CorSettings
  (``dt`` excepted: it is always 1 / ``controller.sensor_rate``);
* ``controller.<field>``: GraspControllerSettings;
* ``<field>``: the scalar fields of SlipControlSettings (``fingers``, ...).

Nothing here lists a field by name, so a field added to or removed from a table appears or
disappears as a parameter with no change to this module. Which fields may change while the
node is active is found out from the core too: a controller field is run-time when
``SlipControl.update_settings`` accepts a change of it alone; of the contact model only mu has
a run-time setter (``SlipControl.set_mu``); the observer and SlipControl's own fields have none.

The ranges are not in the tables (several depend on other fields, e.g. f_max >= f_min), so the
descriptors carry no numeric range: every change is validated by building or updating the C++
objects, and a refused change returns the core's message as the reason.

This module needs no ROS installation.
"""

from __future__ import annotations

import functools
import math
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .. import _core
from .._controller import controller_settings
from .._observer import GAIN_MODES, INTEGRATORS, Observer
from .._params import ContactParams
from .._slip_control import SlipControl

__all__ = ["ParameterSpec", "build_slip_control", "settings_parameters", "split_values"]

#: The enum tables of the observer's settings (name -> C++ value), matched to a field by its
#: default value's type.
_ENUM_TABLES = (INTEGRATORS, GAIN_MODES)
_UNIT = re.compile(r"\[([^\]]+)\]")


@dataclass(frozen=True)
class ParameterSpec:
    """One parameter: ROS name, kind ("float", "int", "bool", "string"), default, the field's
    doc (description), unit ("" when the doc names none), whether it may change while the node
    is active, and the accepted strings of an enum."""

    name: str
    kind: str
    default: Any
    description: str
    unit: str
    while_active: bool
    choices: tuple[str, ...] = ()

    def constraint_text(self) -> str:
        """The descriptor's ``additional_constraints``."""
        parts = []
        if self.unit:
            parts.append(f"unit: {self.unit}")
        if self.choices:
            parts.append("one of " + ", ".join(self.choices))
        parts.append("may change while active" if self.while_active
                     else "fixed while active (deactivate to change)")
        parts.append("validated by lugrip's core; a refused change returns its reason")
        return "; ".join(parts)


def _unit(doc: str) -> str:
    found = _UNIT.findall(doc)
    return found[-1] if found else ""


def _enum_choice(value) -> tuple[str, tuple[str, ...]]:
    for table in _ENUM_TABLES:
        for name, member in table.items():
            if member == value:
                return name, tuple(table)
    raise LookupError(value)


def _probe_value(kind: str, value):
    """Candidate new values of a setting (all different from ``value``)."""
    if kind == "bool":
        return [not value]
    if kind == "int":
        return [value + 1, value - 1, 2 * value, 1]
    if not math.isfinite(value):
        return [10.0, 1.0, 0.0]
    return [value * 1.1, value * 0.9, value + 1.0, value - 1.0, 1.0, 0.5, 0.0]


@functools.lru_cache(maxsize=1)
def _runtime_controller_fields() -> frozenset[str]:
    """The controller fields ``SlipControl.update_settings`` accepts alone: for each, the first
    candidate value the validator accepts is sent to a fresh SlipControl; refused = fixed."""
    base = controller_settings()
    kinds = {name: kind for name, kind, _d in _core.GraspControllerSettings.fields}
    out = set()
    for name, value in base.items():
        for candidate in _probe_value(kinds[name], value):
            trial = _core.GraspControllerSettings()
            for k, v in base.items():
                setattr(trial, k, v)
            try:
                setattr(trial, name, candidate)
            except (TypeError, ValueError, OverflowError):
                continue
            if _core.validate_controller_settings(trial):
                continue  # not a valid value: try the next
            sc = SlipControl(ContactParams.table1())
            try:
                sc.update_settings(**{name: candidate})
            except ValueError:
                break  # valid but refused at run time: fixed
            out.add(name)
            break
    return frozenset(out)


def _table_specs(prefix: str, fields, defaults: dict[str, Any], runtime) -> list[ParameterSpec]:
    out = []
    for name, kind, doc in fields:
        if name not in defaults:
            continue
        value = defaults[name]
        choices: tuple[str, ...] = ()
        if kind == "enum":
            if not isinstance(value, str):
                value, choices = _enum_choice(value)
            else:
                choices = _enum_choice(next(t[value] for t in _ENUM_TABLES if value in t))[1]
            kind = "string"
        elif kind not in ("float", "int", "bool"):
            continue
        if kind == "float":
            value = float(value)
        elif kind == "int":
            value = int(value)
        out.append(ParameterSpec(prefix + name, kind, value, doc, _unit(doc), runtime(name),
                                 choices))
    return out


def settings_parameters(params_file: str | Path | None = None) -> list[ParameterSpec]:
    """Every settings parameter with its default: the contact model and the observer of
    ``params_file`` (a ``lugrip identify`` YAML, or any parameter YAML ``lugrip.SlipControl``
    reads) when given, else ContactParams.table1() and the core's observer defaults; the
    controller's and SlipControl's defaults from the core."""
    source = Path(params_file) if params_file else ContactParams.table1()
    contact = ContactParams.from_yaml(source) if isinstance(source, Path) else source
    observer = Observer(source).settings  # the file's observer block over the core defaults
    observer.pop("dt", None)
    cor_names = {name for name, _k, _d in _core.CorSettings.fields}
    cor = {name: observer.pop(name) for name in list(observer) if name in cor_names}
    top = _core.SlipControlSettings()
    specs = _table_specs("contact.", _core.ContactParams.fields, contact.to_dict(),
                         lambda name: name == "mu")
    specs += _table_specs("observer.", _core.ObserverSettings.fields,
                          {k: v for k, v in observer.items() if k != "dt"}, lambda name: False)
    specs += _table_specs("observer.cor.", _core.CorSettings.fields, cor, lambda name: False)
    runtime = _runtime_controller_fields()
    specs += _table_specs("controller.", _core.GraspControllerSettings.fields,
                          controller_settings(), lambda name: name in runtime)
    specs += _table_specs("", _core.SlipControlSettings.fields,
                          {name: getattr(top, name) for name, kind, _d
                           in _core.SlipControlSettings.fields if kind != "struct"},
                          lambda name: False)
    return specs


def split_values(values: dict[str, Any]) -> dict[str, dict[str, Any]]:
    """Parameter values by group: {"contact", "observer" (cor fields flat, as lugrip.Observer
    takes them), "controller", "top"}; names outside the groups are left out."""
    cor_names = {name for name, _k, _d in _core.CorSettings.fields}
    top_names = {name for name, kind, _d in _core.SlipControlSettings.fields if kind != "struct"}
    out: dict[str, dict[str, Any]] = {"contact": {}, "observer": {}, "controller": {}, "top": {}}
    for name, value in values.items():
        head, _, rest = name.partition(".")
        if head == "observer" and rest.startswith("cor.") and rest[4:] in cor_names:
            out["observer"][rest[4:]] = value
        elif head in ("contact", "observer", "controller") and rest and "." not in rest:
            out[head][rest] = value
        elif not rest and name in top_names:
            out["top"][name] = value
    return out


def build_slip_control(values: dict[str, Any]) -> SlipControl:
    """A SlipControl from parameter values (all the settings parameters); the observer's dt is
    1 / controller.sensor_rate.

    Raises:
        ValueError: the core's reason for refusing the settings.
    """
    groups = split_values(values)
    params = ContactParams(**groups["contact"])
    ctrl = groups["controller"]
    sensor_rate = ctrl.get("sensor_rate", controller_settings()["sensor_rate"])
    if not (isinstance(sensor_rate, (int, float)) and math.isfinite(sensor_rate) and sensor_rate > 0):
        raise ValueError(f"controller.sensor_rate = {sensor_rate!r}: must be finite and > 0")
    observer = dict(groups["observer"], dt=1.0 / float(sensor_rate))
    try:
        return SlipControl(params, observer=observer, **groups["top"], **ctrl)
    except TypeError as err:
        raise ValueError(str(err)) from None
