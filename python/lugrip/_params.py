"""Contact parameters (paper Tables 1 and 2) with validation and YAML I/O."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from typing import Any

from . import _core

__all__ = ["ContactParams", "PRESETS", "read_observer_settings"]

_FIELDS = ("mu", "beta_a", "sigma0", "sigma_z", "delta", "gamma", "k", "c_max")
_UNITS = {
    "mu": "-",
    "beta_a": "N s/m^3",
    "sigma0": "N m/rad",
    "sigma_z": "N m s/rad",
    "delta": "m/N^gamma",
    "gamma": "-",
    "k": "-",
    "c_max": "-",
}


@dataclasses.dataclass(frozen=True)
class ContactParams:
    """Physical parameters of one fingertip/object contact, SI units.

    Args:
        mu: Coulomb friction coefficient [-].
        beta_a: viscous friction per unit contact area and unit sliding speed [N s/m^3]. The
            paper prints "Ns/m"; eq. 7 (f_tv = pi beta_A rho^2 omega c) needs N s/m^3, so the
            printed numbers are used unchanged with the unit corrected (MODEL.md section 11).
        sigma0: micro-asperity stiffness [N m/rad].
        sigma_z: micro-asperity damping [N m s/rad].
        delta, gamma: contact radius rho = delta * f_n**gamma [m], 0 < gamma < 1/3.
        k: pressure exponent (2 Hertz, 4 the paper's xi = 0.6354, inf uniform).
        c_max: saturation of the normalized CoR |c~| (paper: 1.5).

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

    def __post_init__(self) -> None:
        for name in _FIELDS:
            value = getattr(self, name)
            try:
                object.__setattr__(self, name, float(value))
            except (TypeError, ValueError):
                raise ValueError(f"ContactParams.{name} = {value!r}: must be a number") from None
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
        """Torsional shape factor xi(k)."""
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
        """From a mapping; accepts either flat fields or the YAML layout of to_yaml()."""
        if "contact" in data:
            data = data["contact"]
        else:  # flat layout: the observer block of an identification result is not a field
            data = {k: v for k, v in data.items() if k != "observer"}
        values = {}
        for name, value in data.items():
            if name not in _FIELDS:
                raise ValueError(f"unknown parameter {name!r}; expected {', '.join(_FIELDS)}")
            if isinstance(value, dict):
                value = value.get("value")
            if isinstance(value, str) and value.strip().lower() in ("inf", ".inf", "infinity"):
                value = math.inf
            values[name] = value
        missing = [n for n in _FIELDS[:6] if n not in values]
        if missing:
            raise ValueError(f"missing parameter(s): {', '.join(missing)}")
        return cls(**values)

    @classmethod
    def from_yaml(cls, path: str | Path) -> "ContactParams":
        import yaml

        path = Path(path)
        try:
            data = yaml.safe_load(path.read_text())
        except yaml.YAMLError as err:
            raise ValueError(f"{path}: not valid YAML: {err}") from None
        if not isinstance(data, dict):
            raise ValueError(f"{path}: expected a mapping of parameters")
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
            }
        }
        if observer is not None:
            body["observer"] = _check_observer_block(dict(observer), "observer")
        text = (f"# {comment}\n" if comment else "") + yaml.safe_dump(body, sort_keys=False)
        if path is not None:
            Path(path).write_text(text)
        return text


def _check_observer_block(block: Any, where: str) -> dict[str, Any]:
    """Validates an observer block (keywords of lugrip.Observer) by building the settings;
    returns it with plain Python values."""
    from ._observer import Observer

    if not isinstance(block, dict):
        raise ValueError(f"{where}: expected a mapping of observer settings")
    plain = {}
    for k, v in block.items():
        if hasattr(v, "item"):  # numpy scalars
            v = v.item()
        plain[str(k)] = v
    try:
        Observer(ContactParams.table1(), **plain)
    except (TypeError, ValueError) as err:
        raise ValueError(f"{where}: {str(err).replace(chr(10), '; ')}") from None
    return plain


def read_observer_settings(path: str | Path) -> dict[str, Any] | None:
    """The ``observer:`` block of a parameter YAML (written by ``lugrip identify`` /
    :meth:`lugrip.identification.IdentificationResult.save_yaml`): the settings of the observer the
    parameters were identified with, as keywords of :class:`lugrip.Observer`, so that the
    observer used online is the one inside the identification cost (MODEL.md 8.1). None when
    the file has no such block (e.g. ``objects/*.yaml``, ``lugrip params`` output).
    ``lugrip.Observer(path)`` starts from this block (its keywords override it), as do
    ``lugrip observe --params``, ``lugrip identify --params0`` and ``lugrip.identify`` with a
    YAML ``params0``.

    Raises:
        ValueError: the block is not a mapping or holds an unknown or invalid setting.
    """
    import yaml

    path = Path(path)
    try:
        data = yaml.safe_load(path.read_text())
    except yaml.YAMLError as err:
        raise ValueError(f"{path}: not valid YAML: {err}") from None
    if not isinstance(data, dict) or data.get("observer") is None:
        return None
    return _check_observer_block(data["observer"], f"{path}: observer")


PRESETS = ("table1", "big_resin_block", "small_resin_block", "plastic_bottle", "aluminium_can")
