"""Per-object friction from a "rubbing" exploration (paper Section 6): the robot rubs the
fingertip on the object at a KNOWN sliding velocity and the measured friction is compared with
it. In steady sliding the friction is the limit-surface value plus the viscous part (docs/model.md
§5.1, eqs. 3-4, 7-8):

* translation (CoR at infinity, sliding speed v [m/s]):
  ``f_t = mu f_n + beta_A pi rho^2 |v|``;
* rotation about the patch centre (angular speed omega [rad/s]):
  ``|tau| = mu xi rho f_n + beta_A (pi/2) rho^4 |omega|``,

with rho = delta f_n^gamma from the fingertip's parameters. Both are linear in (mu, beta_A):
ordinary least squares over the steady samples gives the two and their standard errors (with
the force regressor as intercept-like term: at one normal force the intercept is mu f_n and
the slope against speed is beta_A pi rho^2, resp. beta_A (pi/2) rho^4). Rubbing at two or more
speeds is required to tell mu from beta_A.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .._contact import _as_params
from .._params import ContactParams
from ..io import SlidingLog
from ._common import IdentificationError

__all__ = ["RubbingEstimate", "estimate_rubbing"]


@dataclasses.dataclass(frozen=True)
class RubbingEstimate:
    """Result of :func:`estimate_rubbing`.

    Attributes:
        mu, beta_a: estimates [-], [N s/m^3].
        mu_stderr, beta_a_stderr: standard errors (OLS, inflated for AR(1) autocorrelation of
            the residuals).
        correlation: correlation of the two estimates.
        mode: "translation" or "rotation".
        samples: steady samples used; speed_range: smallest and largest |speed| among them
            ([m/s] or [rad/s]).
        residual_rms: RMS of the fit residual [N] (translation) or [N m] (rotation).
        r_squared: coefficient of determination of the fit.
    """

    mu: float
    beta_a: float
    mu_stderr: float
    beta_a_stderr: float
    correlation: float
    mode: str
    samples: int
    speed_range: tuple[float, float]
    residual_rms: float
    r_squared: float

    def params(self, fingertip) -> ContactParams:
        """The fingertip's parameters with this object's mu and beta_A (Table 2 style)."""
        return _as_params(fingertip).replace(mu=self.mu, beta_a=self.beta_a)

    def __str__(self) -> str:
        return (
            f"rubbing ({self.mode}, {self.samples} samples, speed {self.speed_range[0]:.3g}-"
            f"{self.speed_range[1]:.3g}): mu = {self.mu:.4g} +- {self.mu_stderr:.2g}, "
            f"beta_A = {self.beta_a:.4g} +- {self.beta_a_stderr:.2g} N s/m^3 "
            f"(corr {self.correlation:+.2f}, R^2 {self.r_squared:.4f})"
        )


def _steady(speed: np.ndarray, dt: np.ndarray, settle: float, tol: float) -> np.ndarray:
    """Samples whose speed stayed within a relative `tol` of its current value (same sign) for
    the preceding `settle` seconds: bristle transients and accelerations are left out."""
    n = speed.size
    keep = np.zeros(n, dtype=bool)
    if n == 0:
        return keep
    step = float(np.median(dt[1:])) if n > 1 else 0.002
    w = max(round(settle / step) if step > 0 else 1, 1) + 1
    if n < w:
        return keep
    from numpy.lib.stride_tricks import sliding_window_view

    win = sliding_window_view(speed, w)  # windows ending at samples w-1 .. n-1
    cur = speed[w - 1 :]
    lo, hi = win.min(axis=1), win.max(axis=1)
    mag = np.abs(cur)
    ok = (mag > 0) & (np.sign(lo) == np.sign(cur)) & (np.sign(hi) == np.sign(cur))
    ok &= (hi - lo) <= tol * mag
    keep[w - 1 :] = ok
    return keep


def estimate_rubbing(
    log: SlidingLog | None = None,
    params=None,
    *,
    mode: str = "auto",
    velocity=None,
    f_n=None,
    f_t=None,
    tau=None,
    t=None,
    min_speed: float | None = None,
    settle: float = 0.05,
    steady_tol: float = 0.02,
) -> RubbingEstimate:
    """mu and beta_A of an object from a rubbing log with known sliding velocity.

    Args:
        log: a :class:`lugrip.SlidingLog` (f_n, f_t, tau, t; for ``mode='rotation'`` its
            ``omega`` is the known angular velocity unless ``velocity`` is given); or None and
            the arrays ``f_n``, ``f_t``, ``tau``, ``t``.
        params: the fingertip's parameters (delta, gamma, k are used): ContactParams, preset,
            dict or YAML path.
        mode: "translation" (``velocity`` = sliding speed of the contact [m/s]), "rotation"
            (angular velocity about the patch centre [rad/s]) or "auto" (rotation when only
            the log's omega is available).
        velocity: known sliding velocity per sample (the robot's commanded/encoder velocity).
        min_speed: samples slower than this are not used (default 10 % of the largest).
        settle: a sample is used only when the speed was constant (within ``steady_tol``,
            relative) for the preceding ``settle`` seconds.

    Returns:
        :class:`RubbingEstimate`.

    Raises:
        IdentificationError: no known velocity, too few steady samples, or a single speed and
            force (mu and beta_A cannot be told apart).
    """
    if params is None:
        raise IdentificationError(
            "params: the fingertip's parameters (delta, gamma) are needed "
            "to turn the contact radius into viscous friction"
        )
    if isinstance(params, str) and params.endswith((".yaml", ".yml")):
        params = ContactParams.from_yaml(params)
    p = _as_params(params)
    if log is not None:
        f_n, f_t, tau, t = log.f_n, log.f_t, log.tau, log.t
        if velocity is None and mode in ("auto", "rotation"):
            if log.omega is None:
                raise IdentificationError(
                    f"{log.source or 'log'}: no known velocity: pass velocity= (sliding speed "
                    "[m/s] for translation, angular velocity [rad/s] for rotation) or a log "
                    "with omega"
                )
            velocity = log.omega
            mode = "rotation"
    if f_n is None or velocity is None or (f_t is None and tau is None):
        raise IdentificationError("give a log or the arrays f_n, f_t/tau and velocity")
    if mode == "auto":
        raise IdentificationError(
            "mode='auto' needs a log with omega; say mode='translation' "
            "(velocity in m/s) or mode='rotation' (rad/s)"
        )
    if mode not in ("translation", "rotation"):
        raise ValueError(f"mode = {mode!r}: 'translation' or 'rotation'")
    f_n = np.asarray(f_n, dtype=float)
    v = np.asarray(velocity, dtype=float)
    raw = f_t if mode == "translation" else tau
    if raw is None:
        raise IdentificationError(
            f"mode={mode!r} needs {'f_t' if mode == 'translation' else 'tau'}"
        )
    meas = np.asarray(raw, dtype=float)
    if meas.shape != f_n.shape or v.shape != f_n.shape:
        raise ValueError("f_n, the measured friction and velocity must have the same length")
    n = f_n.size
    dt = np.diff(np.asarray(t, dtype=float), prepend=np.nan) if t is not None else np.full(n, 0.002)
    dt[0] = 0.0
    ok = np.isfinite(f_n) & np.isfinite(v) & np.isfinite(meas) & (f_n > 0)
    speed = np.where(ok, v, np.nan)
    vmax = np.nanmax(np.abs(speed)) if np.any(ok) else 0.0
    if not vmax > 0:
        raise IdentificationError(
            "the known velocity is zero everywhere: no sliding to compare the friction with"
        )
    vmin = 0.1 * vmax if min_speed is None else float(min_speed)
    keep = ok & (np.abs(v) >= vmin) & _steady(np.where(ok, v, 0.0), dt, settle, steady_tol)
    # a step of the normal force restarts the bristles too (noise-tolerant: 10 %)
    keep &= _steady(np.where(ok, f_n, 0.0), dt, settle, 0.1)
    m = int(np.count_nonzero(keep))
    if m < 10:
        raise IdentificationError(
            f"only {m} steady sliding samples (|speed| >= {vmin:.3g}, "
            f"constant for {settle:g} s): rub longer at constant speeds"
        )
    fn, sp, y = f_n[keep], np.abs(v[keep]), np.abs(meas[keep])
    rho = p.delta * fn**p.gamma
    if mode == "translation":
        X = np.column_stack([fn, math.pi * rho**2 * sp])
    else:
        X = np.column_stack([p.xi * rho * fn, 0.5 * math.pi * rho**4 * sp])
    scale = np.linalg.norm(X, axis=0)
    Xs = X / scale
    sv = np.linalg.svd(Xs, compute_uv=False)
    if sv[-1] < 1e-6 * sv[0] or (np.ptp(sp) <= 0.05 * sp.mean() and np.ptp(fn) <= 0.05 * fn.mean()):
        raise IdentificationError(
            "rubbing at a single speed and normal force: mu and beta_A cannot be told apart "
            "(one equation, two unknowns); rub at two or more speeds"
        )
    coef_s, *_ = np.linalg.lstsq(Xs, y, rcond=None)
    coef = coef_s / scale
    res = y - X @ coef
    dof = max(m - 2, 1)
    s2 = float(res @ res) / dof
    cov = s2 * np.linalg.inv(X.T @ X)
    if m > 3:
        r0, r1 = res[:-1] - res.mean(), res[1:] - res.mean()
        denom = float(np.sqrt((r0 @ r0) * (r1 @ r1)))
        rho1 = float(r0 @ r1) / denom if denom > 0 else 0.0
        if rho1 > 0:
            cov *= min((1 + rho1) / (1 - rho1 + 1e-12), float(m))
    se = np.sqrt(np.abs(np.diag(cov)))
    corr = float(cov[0, 1] / (se[0] * se[1])) if se[0] > 0 and se[1] > 0 else math.nan
    ss_tot = float(((y - y.mean()) ** 2).sum())
    return RubbingEstimate(
        mu=float(coef[0]),
        beta_a=float(coef[1]),
        mu_stderr=float(se[0]),
        beta_a_stderr=float(se[1]),
        correlation=corr,
        mode=mode,
        samples=m,
        speed_range=(float(sp.min()), float(sp.max())),
        residual_rms=float(np.sqrt(np.mean(res**2))),
        r_squared=1.0 - float(res @ res) / ss_tot if ss_tot > 0 else math.nan,
    )
