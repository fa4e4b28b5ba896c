"""Names shared by every stage of the identification: the parameters, their physical bounds,
the exceptions and warnings."""

from __future__ import annotations

PARAMETERS: tuple[str, ...] = ("mu", "beta_a", "sigma0", "sigma_z", "delta", "gamma")
"""The parameters of the eq. 32 cost, in the order of its gradient and matrices."""

DEFAULT_BOUNDS: dict[str, tuple[float, float]] = {
    "mu": (0.05, 2.0),
    "beta_a": (1.0e3, 1.0e12),  # N s/m^3; Table 2 ~1e7, Table 1 4.9e9
    "sigma0": (1.0e-3, 1.0e4),  # N m/rad; Table 1 16.66
    "sigma_z": (1.0e-5, 1.0e3),  # N m s/rad; Table 1 2
    "delta": (1.0e-4, 1.0e-2),  # m/N^gamma
    "gamma": (0.01, 1.0 / 3.0 - 1.0e-6),  # 0 < gamma < 1/3 (paper, ref. [24])
}
"""Physical bounds (all parameters are optimised in log scale, so every bound is > 0)."""

_DEFAULT_SLIP = 2.0e-3  # [rad/s] |omega| above which a sample counts as sliding (checks, guess)


class IdentificationError(ValueError):
    """Data or arguments that cannot give a meaningful fit (the message says why and what to do)."""


class IdentificationWarning(UserWarning):
    """Something in the data or the fit worth knowing (gaps, a single maneuver, bounds hit)."""


class IdentifiabilityWarning(IdentificationWarning):
    """A parameter (combination) the data cannot determine; fixed or reported."""
