"""Contact parameters (paper Tables 1 and 2) with validation and YAML I/O."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from typing import Any

from . import _core
from ._observer_fields import _COR_FIELDS, _OBS_KINDS, GAIN_MODES, INTEGRATORS
from ._yaml import describe_kind, field_path, load_yaml, to_number

__all__ = ["PRESETS", "ContactParams"]

# Names, units and the fields a file must give, from the C++ field table
# (include/lugrip/settings_fields.hpp): required are those a default-constructed struct leaves
# out of range (its validate() names them, in the table's order).
_FIELDS = tuple(p["name"] for p in _core.ContactParams.params)
_UNITS = {p["name"]: p["unit"] for p in _core.ContactParams.params}
_REQUIRED = tuple(line.split(" = ")[0] for line in _core.validate_params(_core.ContactParams()).splitlines())
#: fields written to a parameter file only when they differ from their default (files without
#: friction levels or a Stribeck speed stay as they were)
_OPTIONAL = {"static_ratio": 1.0, "kinetic_ratio": 1.0, "stribeck_speed": 0.0}


@dataclasses.dataclass(frozen=True)
class ContactParams:
    """Physical parameters of one fingertip/object contact, SI units.

    Args:
        mu: friction coefficient of the limit surface [-] (identification fits it to the
            gross-sliding wrenches).
        beta_a: viscous friction per unit contact area and unit sliding speed [N s/m^3]. The
            paper prints "Ns/m"; eq. 7 (f_tv = pi beta_A rho^2 omega c) needs N s/m^3, so the
            printed numbers are used unchanged with the unit corrected (docs/model.md section 11).
        sigma0: micro-asperity stiffness [N m/rad].
        sigma_z: micro-asperity damping [N m s/rad].
        delta, gamma: contact radius rho = delta * f_n**gamma [m], 0 < gamma < 1/3.
        k: pressure exponent (2 Hertz, 4 the paper's xi = 0.6354, inf uniform); 0 selects
            the elliptic limit surface (f_t/(mu f_n))^2 + (tau/tau_max)^2 = 1 of a point
            contact on an elliptic friction cone, with xi fixed at its k = 4 value
            (docs/model.md §3.5).
        c_max: saturation of the normalized CoR |c~| (paper: 1.5).
        static_ratio: break-away friction over mu, mu_s / mu, in [0.5, 3]: the capacity the
            observer judges S against in stick.
        kinetic_ratio: sliding friction level over mu, mu_k / mu, in [0.5, 3]: the capacity
            S is judged against once sliding has started. Both 1 (default, the paper's
            model): no Stribeck term, S as in the paper (docs/model.md §7.5).
        stribeck_speed: Stribeck speed v_s [m/s], in [0, 1]; > 0: once sliding, the
            observer's update uses the capacity g (1 + (static_ratio - 1) exp(-(v/v_s)^2)),
            v the RMS sliding speed over the patch from its speed state, mu then being the
            sliding friction at speed (identified where the speed is observable and the
            sliding friction falls with it); 0 (default): the update uses g once sliding.

    Raises:
        ValueError: naming every invalid field.
    """

    mu: float
    beta_a: float
    sigma0: float
    sigma_z: float
    delta: float
    gamma: float
    k: float = 4.0
    c_max: float = 1.5
    static_ratio: float = 1.0
    kinetic_ratio: float = 1.0
    stribeck_speed: float = 0.0

    def __post_init__(self) -> None:
        for name in _FIELDS:
            # ValueError naming the field for booleans, text, collections, huge integers
            object.__setattr__(self, name, to_number(getattr(self, name), f"ContactParams.{name}"))
        message = _core.validate_params(self.to_core())
        if message:
            raise ValueError("invalid ContactParams:\n" + message.rstrip())

    # --- conversions -------------------------------------------------------------------
    def to_core(self) -> _core.ContactParams:
        p = _core.ContactParams()
        for name in _FIELDS:
            setattr(p, name, getattr(self, name))
        return p

    def to_dict(self) -> dict[str, float]:
        return {name: getattr(self, name) for name in _FIELDS}

    def replace(self, **changes: float) -> "ContactParams":
        return dataclasses.replace(self, **changes)

    @property
    def xi(self) -> float:
        """Torsional shape factor xi(k) (the k = 4 value for the ellipse, k = 0)."""
        return _core.shape_factor(self.k)

    # --- presets -----------------------------------------------------------------------
    @classmethod
    def table1(cls) -> "ContactParams":
        """Paper Table 1 (cardboard slider, k = 4)."""
        return cls.from_core(_core.table1_params())

    @classmethod
    def preset(cls, name: str) -> "ContactParams":
        """'table1' or one of the Table 2 objects: big_resin_block, small_resin_block,
        plastic_bottle, aluminium_can (Table 1 with the object's mu and beta_A)."""
        key = name.lower().replace("-", "_").replace(" ", "_")
        if key == "table1":
            return cls.table1()
        if key == "aluminum_can":
            key = "aluminium_can"
        try:
            return cls.from_core(_core.object_params(key))
        except ValueError as err:
            raise ValueError(f"unknown preset {name!r}; known: {', '.join(PRESETS)}") from err

    @classmethod
    def from_core(cls, p: _core.ContactParams) -> "ContactParams":
        return cls(**{name: getattr(p, name) for name in _FIELDS})

    # --- YAML --------------------------------------------------------------------------
    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> "ContactParams":
        """From a mapping; accepts either flat fields or the YAML layout of to_yaml().

        Raises:
            ValueError: naming the path of the bad field (``contact.mu: ...``); values are not
                echoed.
        """
        if not isinstance(data, dict):
            raise ValueError(f"expected a mapping of parameters, not {describe_kind(data)}")
        if "contact" in data:
            data, prefix = data["contact"], "contact."
            if not isinstance(data, dict):
                raise ValueError(f"contact: must be a mapping of parameters, not {describe_kind(data)}")
        else:  # flat layout: the observer block of an identification result is not a field
            data, prefix = {k: v for k, v in data.items() if k != "observer"}, ""
        values = {}
        for name, value in data.items():
            if not isinstance(name, str) or name not in _FIELDS:
                key = field_path(name) if isinstance(name, str) else f"a {type(name).__name__} key"
                raise ValueError(f"unknown parameter '{prefix}{key}'; expected {', '.join(_FIELDS)}")
            where = prefix + name
            if isinstance(value, dict):
                if "value" not in value:
                    raise ValueError(f"{where}: a mapping needs a 'value' entry")
                value, where = value["value"], where + ".value"
            values[name] = to_number(value, where)
        missing = [n for n in _REQUIRED if n not in values]
        if missing:
            raise ValueError(f"missing parameter(s): {', '.join(prefix + m for m in missing)}")
        try:
            return cls(**values)
        except ValueError as err:  # C++ validation: one line per field, without the prefix
            lines = [ln.strip() for ln in str(err).splitlines()[1:] if ln.strip()]
            raise ValueError("; ".join(prefix + ln for ln in lines) or str(err)) from None

    @classmethod
    def from_yaml(cls, path: str | Path) -> "ContactParams":
        """From a parameter YAML file (read with the limits of :func:`lugrip._yaml.load_yaml`).

        Raises:
            ValueError: ``<file>: <field path>: <problem>`` for an unreadable, oversized,
                invalid or hostile file or field.
        """
        path = Path(path)
        data = load_yaml(path)
        if not isinstance(data, dict):
            what = "an empty file" if data is None else describe_kind(data)
            raise ValueError(f"{path}: expected a mapping of parameters, found {what}")
        try:
            return cls.from_dict(data)
        except ValueError as err:
            raise ValueError(f"{path}: {err}") from None

    def to_yaml(
        self,
        path: str | Path | None = None,
        comment: str = "",
        observer: dict[str, Any] | None = None,
    ) -> str:
        """YAML text (value and unit per field); written to `path` when given. ``observer``:
        the observer settings these parameters belong to (keywords of
        :class:`lugrip.Observer`), written as the ``observer:`` block that
        :func:`read_observer_settings` and ``lugrip observe --params`` use."""
        import yaml

        body: dict[str, Any] = {
            "contact": {
                name: {"value": getattr(self, name) if math.isfinite(getattr(self, name)) else ".inf",
                       "unit": _UNITS[name]}
                for name in _FIELDS
                if name not in _OPTIONAL or getattr(self, name) != _OPTIONAL[name]
            }
        }
        if observer is not None:
            body["observer"] = _plain_observer_block(dict(observer), "observer")
        text = (f"# {comment}\n" if comment else "") + yaml.safe_dump(body, sort_keys=False)
        if path is not None:
            Path(path).write_text(text)
        return text


def _plain_observer_block(block: Any, where: str) -> dict[str, Any]:
    """An observer block (keywords of lugrip.Observer) with plain Python values: its keys, the
    kind of each value and the enumerations checked (the ranges are checked by
    :func:`lugrip._observer._check_observer_block`, which builds the observer). Errors name
    ``where`` and the key, never the value."""

    if not isinstance(block, dict):
        raise ValueError(f"{where}: expected a mapping of observer settings, not {describe_kind(block)}")
    enums = {"integrator": INTEGRATORS, "gain_mode": GAIN_MODES}
    known = set(_OBS_KINDS) | set(_COR_FIELDS) | set(enums) | {"gain", "bandwidth", "dt"}
    plain: dict[str, Any] = {}
    for k, v in block.items():
        if not isinstance(k, str) or k not in known:
            key = field_path(k) if isinstance(k, str) else f"a {type(k).__name__} key"
            raise ValueError(f"{where}.{key}: unknown observer setting")
        field = f"{where}.{k}"
        if hasattr(v, "item") and not isinstance(v, (list, dict, str)):
            v = v.item()  # numpy scalars
        if k in enums:
            if isinstance(v, str) and v.lower().replace("-", "_") in enums[k]:
                plain[k] = v
                continue
            names = [name for name, value in enums[k].items() if value is v]  # a C++ enum value
            if names:
                plain[k] = names[0]
                continue
            raise ValueError(f"{field}: expected one of {', '.join(enums[k])}")
        kind = _OBS_KINDS.get(k, "float")
        if kind == "bool":
            if not isinstance(v, bool):
                raise ValueError(f"{field}: must be true or false")
            plain[k] = v
        elif kind == "int":
            x = to_number(v, field)
            if not (math.isfinite(x) and x == int(x) and abs(x) < 2**31):
                raise ValueError(f"{field}: must be an integer")
            plain[k] = int(x)
        else:
            plain[k] = to_number(v, field)
    return plain


PRESETS = ("table1", "big_resin_block", "small_resin_block", "plastic_bottle", "aluminium_can")
