"""Vectorized contact quantities and CoR estimation (numpy in, numpy out; loops in C++)."""

from __future__ import annotations

import atexit
import enum
import functools
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import _core
from ._params import ContactParams
from ._yaml import to_number

__all__ = [
    "Status",
    "LimitSurface",
    "CorEstimate",
    "estimate_cor",
    "contact_radius",
    "g",
    "sigma_1",
    "normalized_wrench",
    "shape_factor",
]


class Status(enum.IntEnum):
    """Per-sample status; values equal the C++ lugrip::Status."""

    OK = 0
    SATURATED = 1
    DEGENERATE = 2
    NO_CONTACT = 3
    INVALID_SAMPLE = 4
    SENSOR_FAULT = 5
    REINITIALIZED = 6

    @property
    def description(self) -> str:
        return _core.status_description(int(self))


def shape_factor(k: float) -> float:
    """Torsional shape factor xi(k): tau_max = mu * xi * rho * f_n (xi(4) = 0.6354)."""
    return _core.shape_factor(to_number(k, "k"))


def _as_float_array(a, name: str) -> np.ndarray:
    try:
        return np.asarray(a, dtype=np.float64)
    except (TypeError, ValueError, OverflowError):
        raise ValueError(f"{name}: must be a number or an array of numbers") from None


def _flat(*arrays, names=None):
    """Broadcast inputs to one shape; return contiguous float64 1-D views and the shape.
    ``names`` (one per input) name the argument in the ValueError for a non-numeric input or
    shapes that do not broadcast."""
    names = names or [f"argument {i + 1}" for i in range(len(arrays))]
    converted = [_as_float_array(a, n) for a, n in zip(arrays, names)]
    try:
        b = np.broadcast_arrays(*converted)
    except ValueError:
        shapes = ", ".join(f"{n} {x.shape}" for n, x in zip(names, converted))
        raise ValueError(f"shapes do not broadcast: {shapes}") from None
    shape = b[0].shape
    return [np.ascontiguousarray(x).reshape(-1) for x in b], shape


def _shaped(out: np.ndarray, shape):
    out = out.reshape(shape)
    return out[()] if out.ndim == 0 else out


class LimitSurface:
    """Normalized limit surface of a soft circular contact (paper Fig. 3, docs/model.md section 3).

    Tables are integrated at construction (~30 ms); evaluation is constant time in C++.
    `ft_star` is odd with the sign opposite to c~; `tau_star` is even and positive.

    Args:
        k: pressure exponent (> 0, ``float('inf')`` for uniform pressure).
    """

    def __init__(self, k: float = 4.0):
        k = to_number(k, "k")
        try:
            self._ls = _core.LimitSurface(k)
        except ValueError as err:
            raise ValueError(str(err)) from None

    @property
    def k(self) -> float:
        return self._ls.k

    @property
    def xi(self) -> float:
        return self._ls.xi

    def _map(self, fn, c):
        (x,), shape = _flat(c, names=["c_tilde"])
        return _shaped(fn(x), shape)

    def ft_star(self, c_tilde):
        """f~*_tLS(c~): normalized tangential friction on the LS."""
        return self._map(self._ls.ft_star, c_tilde)

    def tau_star(self, c_tilde):
        """tau~*_LS(c~): normalized torsional friction on the LS."""
        return self._map(self._ls.tau_star, c_tilde)

    def dft_star(self, c_tilde):
        return self._map(self._ls.dft_star, c_tilde)

    def dtau_star(self, c_tilde):
        return self._map(self._ls.dtau_star, c_tilde)

    def G(self, c_tilde):
        """Normalized torque capacity about the CoR, xi*T + |c~|*F (g = mu f_n rho G)."""
        return self._map(self._ls.G, c_tilde)

    def sigma_ls(self, c_tilde, gamma: float):
        """sigma_LS(|c~|) = F^(gamma+1)/T, the map inverted by the CoR estimator."""
        (x,), shape = _flat(c_tilde, names=["c_tilde"])
        return _shaped(self._ls.sigma_ls(x, to_number(gamma, "gamma")), shape)

    def integrate(self, c_tilde: float):
        """Direct quadrature (slow, no table) at one point: (F, T, dF/da, dT/da)."""
        return self._ls.integrate(to_number(c_tilde, "c_tilde"))

    def __repr__(self) -> str:
        return f"LimitSurface(k={self.k!r})"


@functools.lru_cache(maxsize=32)
def _model(params: ContactParams) -> _core.ContactModel:
    return _core.ContactModel(params.to_core())


# Release the cached C++ models before the interpreter tears the extension down (otherwise
# nanobind reports them as leaked at exit).
atexit.register(_model.cache_clear)


def _params_path(params) -> Path | None:
    """The YAML file `params` names (an os.PathLike, or a str ending in .yaml/.yml), else None
    (ContactParams, preset names, dicts)."""
    if isinstance(params, os.PathLike):
        return Path(params)
    if isinstance(params, str) and Path(params).suffix.lower() in (".yaml", ".yml"):
        return Path(params)
    return None


def _as_params(params) -> ContactParams:
    """ContactParams from ContactParams, a preset name, a dict (flat or the YAML layout) or a
    parameter YAML file (a path, or a str ending in .yaml/.yml)."""
    if isinstance(params, ContactParams):
        return params
    path = _params_path(params)
    if path is not None:
        return ContactParams.from_yaml(path)
    if isinstance(params, str):
        return ContactParams.preset(params)
    if isinstance(params, dict):
        return ContactParams.from_dict(params)
    raise TypeError(
        "expected ContactParams, a preset name, a dict or a .yaml file, "
        f"got {type(params).__name__}"
    )


def contact_radius(params, f_n):
    """rho = delta * f_n**gamma [m]."""
    p = _as_params(params)
    (fn,), shape = _flat(f_n, names=["f_n"])
    return _shaped(_model(p).rho(fn), shape)


def g(params, f_n, c_tilde):
    """Maximum dry friction torque about the CoR, g(f_n, c) = mu f_n rho G(|c~|) [N m] (eq. 18)."""
    p = _as_params(params)
    (fn, c), shape = _flat(f_n, c_tilde, names=["f_n", "c_tilde"])
    return _shaped(_model(p).g(fn, c), shape)


def sigma_1(params, f_n, c_tilde):
    """Viscous coefficient about the CoR, pi beta_A rho^4 (c~^2 + 1/2) [N m s/rad] (eq. 17)."""
    p = _as_params(params)
    (fn, c), shape = _flat(f_n, c_tilde, names=["f_n", "c_tilde"])
    return _shaped(_model(p).sigma_1(fn, c), shape)


def normalized_wrench(params, f_n, f_t, tau):
    """(f_t / (mu f_n), tau / tau_max(f_n)): the normalized measured friction (eqs. 11-12)."""
    p = _as_params(params)
    (fn, ft, tq), shape = _flat(f_n, f_t, tau, names=["f_n", "f_t", "tau"])
    m = _model(p)
    return _shaped(ft / m.ft_max(fn), shape), _shaped(tq / m.tau_max(fn), shape)


@dataclass(frozen=True)
class CorEstimate:
    """CoR estimates per sample. Unpacks as ``c_tilde, inside = estimate_cor(...)``.

    Attributes:
        c_tilde: signed normalized CoR [-], |c_tilde| <= c_max.
        inside: wrench strictly inside the limit surface (virtual CoR).
        c: CoR position [m]; g: max dry torque about the CoR [N m]; sigma_1: viscous
            coefficient [N m s/rad]; y: tau - c f_t [N m]; ft_tilde, tau_tilde: normalized wrench;
        saturated: |c~| clipped at c_max; iterations: root-finding iterations;
        status: Status codes (int array); samples without contact or invalid hold the previous
            estimate;
        c_tilde_unclipped: the same estimate before the clip at c_max [-] (equal to c_tilde
            below it; a pure translation reads as the largest value reported, 1e6).
    """

    c_tilde: np.ndarray
    inside: np.ndarray
    c: np.ndarray
    g: np.ndarray
    sigma_1: np.ndarray
    y: np.ndarray
    ft_tilde: np.ndarray
    tau_tilde: np.ndarray
    sigma: np.ndarray
    saturated: np.ndarray
    iterations: np.ndarray
    status: np.ndarray
    c_tilde_unclipped: np.ndarray

    def __iter__(self):
        return iter((self.c_tilde, self.inside))

    def __len__(self) -> int:
        return 2

    def __getitem__(self, i):
        return (self.c_tilde, self.inside)[i]


def estimate_cor(params, f_n, f_t, tau, *, f_n_min: float | None = None,
                 zero_force: float | None = None, zero_torque: float | None = None,
                 force_limit: float | None = None, torque_limit: float | None = None) -> CorEstimate:
    """Estimate the signed normalized CoR c~ for each sample (paper eqs. 13-15, docs/model.md 5.7).

    Samples are processed in order (flattened, C order) by one C++ estimator, so undefined
    samples (zero wrench, torque below `zero_torque`) hold the previous value / side. Never
    raises on bad samples: NaN/Inf/out-of-range give Status.INVALID_SAMPLE, f_n < f_n_min gives
    Status.NO_CONTACT, and outputs stay finite.

    Args:
        params: ContactParams, a preset name or a dict.
        f_n: normal force [N]; f_t: tangential force [N] (magnitude or signed); tau: torsional
            moment [N m]. Broadcast against each other.
        f_n_min, zero_force, zero_torque, force_limit, torque_limit: see CorSettings (C++);
            None: the C++ default.

    Returns:
        CorEstimate (unpacks to ``c_tilde, inside``).
    """
    p = _as_params(params)
    settings = _core.CorSettings()
    given = {"f_n_min": f_n_min, "zero_force": zero_force, "zero_torque": zero_torque,
             "force_limit": force_limit, "torque_limit": torque_limit}
    for name, value in given.items():
        if value is not None:
            setattr(settings, name, to_number(value, name))
    message = _core.validate_cor_settings(settings)
    if message:
        raise ValueError("invalid CoR settings:\n" + message.rstrip())
    (fn, ft, tq), shape = _flat(f_n, f_t, tau, names=["f_n", "f_t", "tau"])
    est = _core.CorEstimator(_model(p), settings)
    r = est.run(fn, ft, tq)
    return CorEstimate(**{k: _shaped(v, shape) for k, v in r.items() if k != "rho"})
