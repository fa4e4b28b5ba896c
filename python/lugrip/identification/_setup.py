"""Arguments of :func:`identify`: free parameters, bounds, the validation split."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from ._common import DEFAULT_BOUNDS, PARAMETERS


def _parse_free(free) -> tuple[str, ...]:
    if isinstance(free, str):
        free = [f for f in free.replace(" ", "").split(",") if f]
    names = []
    for f in free:
        key = str(f).lower().replace("-", "_")
        key = {"beta": "beta_a", "betaa": "beta_a", "sigmaz": "sigma_z", "sigma_0": "sigma0"}.get(
            key, key
        )
        if key not in PARAMETERS:
            raise ValueError(f"free parameter {f!r}: expected some of {', '.join(PARAMETERS)}")
        if key not in names:
            names.append(key)
    if not names:
        raise ValueError("free: give at least one parameter to identify")
    return tuple(n for n in PARAMETERS if n in names)


def _bounds(bounds) -> dict[str, tuple[float, float]]:
    out = dict(DEFAULT_BOUNDS)
    for name, pair in (bounds or {}).items():
        if name not in PARAMETERS:
            raise ValueError(f"bounds: unknown parameter {name!r}")
        lo, hi = (float(v) for v in pair)
        if not (0.0 < lo < hi < math.inf):
            raise ValueError(
                f"bounds[{name!r}] = ({lo!r}, {hi!r}): need 0 < lower < upper < inf "
                "(parameters are optimised in log scale)"
            )
        if name == "gamma" and hi >= 1.0 / 3.0:
            raise ValueError(f"bounds['gamma'] upper = {hi!r}: gamma < 1/3 (contact mechanics)")
        out[name] = (lo, hi)
    return out


def _split(keys: Sequence[str], validation, seed) -> list[int]:
    m = len(keys)
    if validation is None or (
        isinstance(validation, (int, float))
        and not isinstance(validation, bool)
        and float(validation) == 0.0
    ):
        return []
    if isinstance(validation, (int, float)) and not isinstance(validation, bool):
        frac = float(validation)
        if not (0.0 < frac < 1.0):
            raise ValueError(f"validation = {validation!r}: a fraction in [0, 1) or maneuver keys")
        if m < 2:
            return []
        n_val = min(max(1, round(frac * m)), m - 1)
        rng = np.random.default_rng(seed)
        return sorted(rng.choice(m, size=n_val, replace=False).tolist())
    chosen = []
    for v in validation:
        if isinstance(v, (int, np.integer)):
            if not 0 <= int(v) < m:
                raise ValueError(f"validation maneuver index {v} out of range (0..{m - 1})")
            chosen.append(int(v))
        else:
            if str(v) not in keys:
                raise ValueError(
                    f"validation maneuver {v!r} not in the data (keys look like {keys[0]!r})"
                )
            chosen.append(keys.index(str(v)))
    if len(set(chosen)) >= m:
        raise ValueError("validation: leave at least one maneuver for training")
    return sorted(set(chosen))


def check_options(*, loss, weighting, method, tolerance, uncertainty) -> float:
    """Raise ValueError on a bad option; return the tolerance (method default when None)."""
    if loss not in ("squared", "huber"):
        raise ValueError(f"loss = {loss!r}: 'squared' or 'huber'")
    if weighting not in ("maneuver", "sample"):
        raise ValueError(f"weighting = {weighting!r}: 'maneuver' or 'sample'")
    if method not in ("slsqp", "trust-constr", "gauss-newton"):
        raise ValueError(f"method = {method!r}: 'gauss-newton', 'slsqp' or 'trust-constr'")
    if uncertainty not in ("gauss-newton", "sandwich", "bootstrap"):
        raise ValueError(
            f"uncertainty = {uncertainty!r}: 'gauss-newton', 'sandwich' or 'bootstrap'"
        )
    if tolerance is None:
        return 1e-8 if method == "gauss-newton" else 1e-10
    return float(tolerance)


def read_params0(params0, observer):
    """(ContactParams or None, observer settings): a YAML params0 also supplies the observer
    block (without its dt: the nominal sample period is the data's) unless one is given."""
    import os
    from pathlib import Path

    from .._contact import _as_params
    from .._observer import read_observer_settings
    from .._params import ContactParams

    if (
        params0 is not None
        and isinstance(params0, (str, os.PathLike))
        and Path(params0).suffix in (".yaml", ".yml")
    ):
        if observer is None:
            observer = read_observer_settings(params0)
            if observer is not None:
                observer.pop("dt", None)
        params0 = ContactParams.from_yaml(params0)
    return (None if params0 is None else _as_params(params0)), observer
