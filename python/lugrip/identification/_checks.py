"""Checks of the data before any fit: units, force range, sliding, number of maneuvers."""

from __future__ import annotations

import warnings

import numpy as np

from .._contact import estimate_cor
from .._params import ContactParams
from ._common import IdentifiabilityWarning, IdentificationError, IdentificationWarning
from ._data import _Maneuver

__all__ = ["OMEGA_PLAUSIBLE", "check_data", "force_range_too_small", "rotation_only"]

OMEGA_PLAUSIBLE = 20.0  # [rad/s] a fingertip rub faster than this is taken for deg/s data
_F_RANGE = 1.5  # max / min median normal force per maneuver needed for gamma [-]


def check_data(mans: list[_Maneuver], free: tuple, slip_threshold: float, *,
               staged: bool) -> list[str]:
    """Errors for data that cannot give a fit, warnings (returned as notes too) for data that
    give a weaker one."""
    notes: list[str] = []
    w = np.concatenate([np.abs(m.omega) for m in mans])
    w = w[np.isfinite(w)]
    if w.size and float(np.percentile(w, 99)) > OMEGA_PLAUSIBLE:
        raise IdentificationError(
            f"omega reaches {float(np.percentile(w, 99)):.3g} rad/s (99th percentile): "
            f"implausible for a fingertip rub (> {OMEGA_PLAUSIBLE:g} rad/s); the log's "
            "omega looks like deg/s: convert it to rad/s (--units omega=deg/s)"
        )
    if len(mans) == 1:
        msg = (
            "a single maneuver: no validation split is possible and one maneuver (one force, "
            "one CoR) cannot fix the limit surface; record several maneuvers at different "
            "forces and CoRs"
        )
        warnings.warn(msg, IdentificationWarning, stacklevel=3)
        notes.append("single maneuver: no validation set")
    if not staged:
        finite = np.isfinite(np.concatenate([m.omega for m in mans]))
        n_slide = int(np.count_nonzero(w > slip_threshold))
        if n_slide < max(10, int(0.002 * np.count_nonzero(finite))):
            msg = (
                f"no sliding in the data: |omega| <= {slip_threshold:g} rad/s on all but "
                f"{n_slide} of {int(np.count_nonzero(finite))} samples (all-stick). mu and "
                "beta_A are not identifiable from stick data (the friction never reaches its "
                "capacity: only a lower bound on mu). Record maneuvers that slide, or fit only "
                "sigma0/sigma_z with free=('sigma0', 'sigma_z') and params0."
            )
            if "mu" in free or "beta_a" in free:
                raise IdentificationError(msg)
            warnings.warn(msg, IdentifiabilityWarning, stacklevel=3)
    return notes


def force_range_too_small(mans: list[_Maneuver]) -> str | None:
    """A message when the normal force hardly varies between maneuvers (gamma unidentifiable)."""
    f_man = np.array([np.median(m.f_n) for m in mans])
    if f_man.max() / max(f_man.min(), 1e-12) < _F_RANGE:
        return (
            f"too little normal-force range for gamma (median per maneuver "
            f"{f_man.min():.3g}-{f_man.max():.3g} N, need a ratio of {_F_RANGE:g}): delta and "
            "gamma enter through rho = delta f_n^gamma only and are not separately identifiable"
        )
    return None


def rotation_only(mans: list[_Maneuver], p0: ContactParams, slip_threshold: float) -> bool:
    """True when the estimated |c~| is below 0.15 on 95 % of the sliding samples."""
    c_abs = []
    for m in mans:
        sel = np.isfinite(m.omega) & (np.abs(m.omega) > slip_threshold)
        if np.any(sel):
            c_abs.append(np.abs(estimate_cor(p0, m.f_n[sel], m.f_t[sel], m.tau[sel]).c_tilde))
    return bool(c_abs) and float(np.percentile(np.concatenate(c_abs), 95)) < 0.15
