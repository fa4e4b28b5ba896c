"""The staged estimate as a start point and prior for the eq. 32 refinement, with the
decision whether the sliding speed is observable on the data (docs/model.md §8)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .._contact import sigma_1 as _sigma_1
from .._params import ContactParams
from ._common import DEFAULT_BOUNDS, IdentificationError
from ._data import _Maneuver
from ._optimize import Prior
from ._phases import LOADING, SLIDING, STILL, Noise, estimate_noise, find_phases
from ._stages import (
    ELLIPSE_K,
    LimitSurfaceFit,
    PreslidingFit,
    fit_limit_surface,
    fit_presliding,
    sliding_points,
)

__all__ = ["StageEstimate", "staged_estimate"]

VISCOUS_T = 3.0  # one-sided t statistic above which the viscous excess counts as measured
RESOLUTION_MAX = 0.02  # [rad/s] the observer's default speed_observable threshold
_NO_SLIDING = (
    "no gross sliding in the data (all-stick or presliding only): in no run of motion did "
    "the friction stop growing while the motion went on, so mu and the limit surface are not "
    "identifiable (stick gives only a lower bound on mu); rub beyond the presliding distance, "
    "or fit only sigma0/sigma_z with free=('sigma0', 'sigma_z') and params0"
)
SIGMA_Z_TIME = 0.01  # [s] sigma_z / sigma0 where the loading runs show no micro-damping
_REL_FLOOR = 0.02  # smallest relative prior spread of a stage value in the refinement [-]


@dataclasses.dataclass(frozen=True)
class StageEstimate:
    """What the stages found.

    Attributes:
        params: the staged parameters (beta_A set by the observability rule when the speed is
            not observable).
        prior: the refinement's regularisation (:class:`Prior`): the limit-surface stage's
            sandwich covariance at its k (mu, delta, gamma and beta_A jointly, so that a
            well-determined combination such as tau_max stays put) plus a 2 % floor, and the
            presliding stage's spreads.
        fixed: {name: reason} parameters the refinement must not move.
        noise: sensor noise from the still samples.
        speed_observable: the viscous excess is significant and the resolution
            torque_noise / sigma_1 is below ``resolution_max`` on most sliding samples.
        omega_resolution: median torque_noise / sigma_1 over the gross-sliding samples [rad/s].
        ls: stage (a)+(c) fit; presliding: stage (b) fit (None when no loading run was usable).
        counts: samples per phase found (still, loading, sliding); maneuvers with sliding.
        phases: per maneuver, the phase of every sample.
        report: per-stage lines (which samples, what was found).
    """

    params: ContactParams
    prior: Prior
    fixed: dict
    noise: Noise
    speed_observable: bool
    omega_resolution: float
    ls: LimitSurfaceFit
    presliding: PreslidingFit | None
    counts: dict
    phases: list
    report: tuple


def _beta_unobservable(
    noise_torque: float, ls: LimitSurfaceFit, f_max: float, c_max: float, resolution_max: float
) -> float:
    """beta_A whose sigma_1 at the largest force and the CoR clip gives a speed resolution
    of twice resolution_max: the observer then reports speed_observable = False everywhere
    in the data's range."""
    rho = ls.delta * f_max**ls.gamma
    return noise_torque / (2.0 * resolution_max * math.pi * rho**4 * (c_max**2 + 0.5))


def staged_estimate(
    mans: list[_Maneuver],
    *,
    k: float | None,
    c_max: float,
    fix_gamma: float | None,
    fix_delta: float | None = None,
    resolution_max: float = RESOLUTION_MAX,
    gain_max: float = 1.0e7,
) -> StageEstimate:
    """Run stages (a)-(c) and (b) on the maneuvers (``gain_max``: the largest observer gain
    l [1/(kg m^2)], for the stick-mode damping of a sigma_z the loading runs leave open).

    Raises:
        IdentificationError: no gross sliding found, or sliding in fewer than three maneuvers
            (the limit surface needs several CoRs and forces).
    """
    lines: list[str] = []
    ph0 = [find_phases(m, Noise(math.nan, math.nan, 0)) for m in mans]
    noise = estimate_noise(mans, ph0)
    phases = [find_phases(m, noise) for m in mans]
    allph = np.concatenate(phases)
    counts = {
        "still": int(np.count_nonzero(allph == STILL)),
        "loading": int(np.count_nonzero(allph == LOADING)),
        "sliding": int(np.count_nonzero(allph == SLIDING)),
        "maneuvers_sliding": int(sum(bool(np.any(p == SLIDING)) for p in phases)),
    }
    lines.append(
        f"phases (from the wrench and the motion): {counts['still']} still, "
        f"{counts['loading']} loading (presliding), {counts['sliding']} gross-sliding samples; "
        f"gross sliding in {counts['maneuvers_sliding']} of {len(mans)} maneuvers"
    )
    if math.isfinite(noise.torque):
        lines.append(
            f"noise (still samples, {noise.samples}): torque {noise.torque:.3g} N m, "
            f"in-plane force {noise.force:.3g} N"
        )
    else:
        lines.append("noise: no still stretch of >= 20 samples; the observer default is kept")
    if counts["sliding"] == 0:
        raise IdentificationError(_NO_SLIDING)
    if counts["maneuvers_sliding"] < 3:
        raise IdentificationError(
            f"gross sliding in only {counts['maneuvers_sliding']} maneuver(s): the limit "
            "surface needs several CoRs and normal forces; record more maneuvers, or split "
            "a log that holds several into maneuvers (lugrip identify --maneuvers motion or "
            "START:END windows; read_log(..., maneuvers='motion'))"
        )
    pts = sliding_points(mans, phases)
    # first pass at k = 4 (or the given k): it only has to find sigma0 for the second pass
    ls = fit_limit_surface(
        pts, gamma=fix_gamma, k=K_DEFAULT if k is None else k, viscous=True, delta=fix_delta
    )
    lines.append(_ls_line(ls, pts, fix_gamma, fix_delta))
    # (c) viscous shear: significance and observability
    tn = noise.torque if math.isfinite(noise.torque) else 1.0e-5
    _, resolution, observable, beta, line = _viscous(ls, pts, tn, c_max, resolution_max)
    lines.append(line)
    probe = _probe(ls, c_max)
    p_ls = probe.replace(beta_a=beta)
    pre = fit_presliding(mans, phases, p_ls)
    second = False
    if pre is not None:
        # second pass: every run must have slipped far enough for the bristles to reach their
        # bound (4.6 g / sigma0 from the start of its build-up), which the load alone cannot
        # show where a viscous part dominates it; then stages (a), (c), (b) again
        p_pre = p_ls.replace(sigma0=pre.sigma0, sigma_z=max(pre.sigma_z, 1e-6))
        phases2 = [find_phases(m, noise, _min_slip(p_pre)) for m in mans]
        n2 = int(sum(int(np.count_nonzero(p == SLIDING)) for p in phases2))
        m2 = int(sum(bool(np.any(p == SLIDING)) for p in phases2))
        second = m2 >= 3
        if second:
            phases = phases2
            counts["loading"] += counts["sliding"] - n2
            counts["sliding"], counts["maneuvers_sliding"] = n2, m2
            lines.append(
                f"phases, second pass (slip >= 4.6 g/sigma0 with sigma0 {pre.sigma0:.3g}): "
                f"{n2} gross-sliding samples in {m2} maneuvers"
            )
        else:
            lines.append(
                f"phases, second pass (slip >= 4.6 g/sigma0 with sigma0 {pre.sigma0:.3g}) "
                f"would leave gross sliding in {m2} maneuver(s): the first pass is kept"
            )
    if k is None and not second:  # no second pass: decide about k on the first one's points
        ls = _fit_ls(pts, fix_gamma, k, lines, fix_delta)
        lines.append(_ls_line(ls, pts, fix_gamma, fix_delta))
        _, resolution, observable, beta, line = _viscous(ls, pts, tn, c_max, resolution_max)
        lines.append(line)
        probe = probe.replace(mu=ls.mu, delta=ls.delta, gamma=ls.gamma, k=ls.k)
        p_ls = probe.replace(beta_a=beta)
        pre = fit_presliding(mans, phases, p_ls)
    if pre is not None and second:
        pts = sliding_points(mans, phases)
        ls = _fit_ls(pts, fix_gamma, k, lines, fix_delta)
        lines.append(_ls_line(ls, pts, fix_gamma, fix_delta))
        _, resolution, observable, beta, line = _viscous(ls, pts, tn, c_max, resolution_max)
        lines.append(line)
        probe = probe.replace(mu=ls.mu, delta=ls.delta, gamma=ls.gamma, k=ls.k)
        p_ls = probe.replace(beta_a=beta)
        pre = fit_presliding(mans, phases, p_ls)
    diag: dict = {}
    fixed: dict = {}
    if pre is None:
        sigma0, sigma_z = 1.0, 0.01
        lines.append("(b) no usable loading run: sigma0 and sigma_z not identified (1, 0.01)")
        fixed["sigma0"] = fixed["sigma_z"] = "no usable loading run"
    else:
        sigma0 = pre.sigma0
        sz_sig = pre.stderr["sigma_z"] > 0 and pre.sigma_z >= 2.0 * pre.stderr["sigma_z"]
        # without measurable micro-damping (docs/identification.md, stage (b)): where the
        # loading runs bound sigma_z (upper two-sigma value below a bristle time constant
        # sigma_z / sigma0 of 10 ms), the smallest sigma_z that damps the observer's stick mode
        # critically at its largest gain, (sigma_z + sigma_1) sqrt(l / sigma0) / 2 = 1 with
        # sigma_1 -> 0, kept inside that bound; where they leave it open, the 10 ms value
        sz_upper = max(pre.sigma_z, 0.0) + 2.0 * pre.stderr["sigma_z"]
        sz_rule = SIGMA_Z_TIME * sigma0
        sz_damp = 2.0 * math.sqrt(sigma0 / gain_max)
        bounded = not sz_sig and sz_upper < sz_rule
        sigma_z = pre.sigma_z if sz_sig else (min(sz_damp, sz_upper) if bounded else sz_rule)
        lines.append(
            f"(b) presliding from {pre.runs} loading runs ({pre.samples} samples): sigma0 "
            f"{sigma0:.4g} +- {pre.stderr['sigma0']:.2g} N m/rad, sigma_z "
            f"{pre.sigma_z:.3g} +- {pre.stderr['sigma_z']:.2g} N m s/rad"
            + (
                ""
                if sz_sig
                else f" (not significant, at most {sz_upper:.3g} at two sigma: set to "
                f"{sigma_z:.3g}, the observer's stick mode critically damped at its gain "
                f"{gain_max:.3g})"
                if bounded
                else f" (not significant: set to {sigma_z:.3g}, a bristle time constant of "
                f"{1e3 * SIGMA_Z_TIME:g} ms)"
            )
            + f"; RMS residual {pre.residual_rms:.3g} of g"
        )
        # the spread includes the misfit of the one-state bristle model to the loading runs
        # (twice the RMS residual, relative to g), not only the statistical error
        misfit = 2.0 * pre.residual_rms
        diag["sigma0"] = (sigma0, max(pre.stderr["sigma0"] / sigma0, misfit, _REL_FLOOR))
        diag["sigma_z"] = (
            sigma_z,
            max(pre.stderr["sigma_z"] / max(sigma_z, 1e-300), misfit, 0.5) if sz_sig else 1.0,
        )
        if bounded:  # the eq. 32 cost would move it for omega_hat's noise, not for the data
            fixed["sigma_z"] = (
                f"not significant on the loading runs (at most {sz_upper:.3g} at two sigma); "
                "the observer's stick mode critically damped at its largest gain "
                f"{gain_max:.3g} (a bristle time constant of {1e3 * sigma_z / sigma0:.2g} ms)"
            )
    params = p_ls.replace(sigma0=sigma0, sigma_z=sigma_z)
    if not observable:
        fixed["beta_a"] = "sliding speed not observable on these data"
    prior = _prior(ls, beta, observable, fix_gamma, diag)
    return StageEstimate(
        params=params,
        prior=prior,
        fixed=fixed,
        noise=noise,
        speed_observable=observable,
        omega_resolution=resolution,
        ls=ls,
        presliding=pre,
        counts=counts,
        phases=phases,
        report=tuple(lines),
    )


K_DEFAULT = 4.0  # pressure exponent held when the data do not determine k (the paper's)
K_GAIN = 0.95  # a free k must lower the RMS distance to the surface below this fraction


def _fit_ls(pts, fix_gamma, k, lines: list, fix_delta=None) -> LimitSurfaceFit:
    """Stage (a)+(c), choosing the limit-surface shape. In the pressure family k is free and
    kept only when it lowers the RMS distance to the surface by more than 5 % against k = 4
    (else k is not determined by the data and held at 4). The elliptic limit surface (no
    shape parameter) is fitted too; the shape with the lower RMS distance is kept."""
    if k is not None:
        return fit_limit_surface(pts, gamma=fix_gamma, k=k, viscous=True, delta=fix_delta)
    free = fit_limit_surface(pts, gamma=fix_gamma, k=None, viscous=True, delta=fix_delta)
    held = fit_limit_surface(pts, gamma=fix_gamma, k=K_DEFAULT, viscous=True, delta=fix_delta)
    pressure = free
    if not free.residual_rms < K_GAIN * held.residual_rms:
        lines.append(
            f"k not determined by these data (free k = {free.k:.3g} lowers the distance to the "
            f"surface only to {free.residual_rms / held.residual_rms:.2f} of k = {K_DEFAULT:g}): "
            f"held at {K_DEFAULT:g}"
        )
        pressure = held
    ellipse = fit_limit_surface(pts, gamma=fix_gamma, k=ELLIPSE_K, viscous=True, delta=fix_delta)
    keep = ellipse if ellipse.residual_rms < pressure.residual_rms else pressure
    rms = {"pressure": pressure.residual_rms, "ellipse": ellipse.residual_rms}
    bound = f" (at its bound: {', '.join(pressure.at_bound)})" if pressure.at_bound else ""
    se_inv = pressure.stderr.get("inv_k", math.nan) if pressure is free else math.nan
    k_se = (f", 1/k {1.0 / pressure.k:.3g} +- {se_inv:.2g}"
            if math.isfinite(se_inv) and 0.0 < pressure.k < math.inf else "")
    lines.append(
        f"(a) limit-surface shape: pressure family (k {_k_text(pressure.k)}{k_se}){bound} RMS "
        f"distance {rms['pressure']:.3g}, elliptic limit surface {rms['ellipse']:.3g}: "
        + ("the ellipse is kept" if keep is ellipse else "the pressure family is kept")
    )
    return dataclasses.replace(keep, shape_rms=rms)


def _k_text(k: float) -> str:
    if k == ELLIPSE_K:
        return "0 (elliptic limit surface)"
    return "inf" if math.isinf(k) else f"{k:.3g}"


def _ls_line(ls: LimitSurfaceFit, pts, fix_gamma, fix_delta=None) -> str:
    kk = _k_text(ls.k)
    return (
        f"(a) limit surface from {len(pts)} sliding points ({int(pts.samples.sum())} samples, "
        f"{np.unique(pts.maneuver).size} maneuvers, |c~| {np.min(ls.c_abs):.2g}-"
        f"{np.max(ls.c_abs):.2g}, f_n {pts.f_n.min():.3g}-{pts.f_n.max():.3g} N): "
        f"mu {ls.mu:.4g} +- {ls.stderr['mu']:.2g}, delta {ls.delta:.4g}"
        + (f" +- {ls.stderr['delta']:.2g}" if fix_delta is None else " (fixed)")
        + f", gamma {ls.gamma:.4g}"
        + ("" if fix_gamma is None else " (fixed)")
        + f", k {kk}; RMS distance to the surface {ls.residual_rms:.3g} (normalised)"
    )


def _probe(ls: LimitSurfaceFit, c_max: float) -> ContactParams:
    """Contact parameters with the limit-surface stage's mu, delta, gamma, k and beta_A (at
    least 1) and placeholder bristle values, for evaluating the stage's contact model."""
    return ContactParams(
        mu=ls.mu,
        beta_a=max(ls.beta_a, 1.0),
        sigma0=1.0,
        sigma_z=0.01,
        delta=ls.delta,
        gamma=ls.gamma,
        k=ls.k,
        c_max=c_max,
    )


def _viscous(ls: LimitSurfaceFit, pts, tn: float, c_max: float, resolution_max: float):
    """(significant, resolution, observable, beta_A, report line) of stage (c)."""
    significant = ls.kappa > 0 and math.isfinite(ls.viscous_t) and ls.viscous_t >= VISCOUS_T
    probe = _probe(ls, c_max)
    c_pts = np.minimum(ls.c_abs, c_max)
    res_pts = tn / np.maximum(np.asarray(_sigma_1(probe, pts.f_n, c_pts), float), 1e-300)
    resolution = float(np.median(np.repeat(res_pts, pts.samples)))
    observable = bool(significant and resolution <= resolution_max)
    if observable:
        beta = ls.beta_a
        line = (
            f"(c) viscous shear measured: beta_A {beta:.4g} +- {ls.stderr['beta_a']:.2g} "
            f"N s/m^3 (t = {ls.viscous_t:.1f}); speed resolution torque_noise/sigma_1 "
            f"{resolution:.3g} rad/s (median over the sliding samples): sliding speed observable"
        )
        return significant, resolution, observable, beta, line
    why = (
        f"no significant speed dependence of the sliding wrench (t = {ls.viscous_t:.1f} "
        f"< {VISCOUS_T:g})"
        if not significant
        else f"the viscous part is too small against the torque noise (resolution "
        f"{resolution:.3g} rad/s > {resolution_max:g})"
    )
    beta = _beta_unobservable(tn, ls, float(pts.f_n.max()) * 1.5, c_max, resolution_max)
    if significant:
        beta = min(beta, ls.beta_a)
    beta = max(beta, 1.001 * DEFAULT_BOUNDS["beta_a"][0])
    line = (
        f"(c) sliding speed not observable on these data: {why}; beta_A set to "
        f"{beta:.3g} N s/m^3, which makes the observer report speed_observable = False"
    )
    return significant, resolution, observable, beta, line


def _min_slip(p: ContactParams):
    """Slip angle a run needs from the start of its build-up: 4.6 g / sigma0 at its plateau
    wrench (the mean of its second half)."""
    from .._contact import estimate_cor

    def req(m, a, b):
        h = a + (b - a) // 2
        est = estimate_cor(
            p,
            np.array([np.mean(m.f_n[h:b])]),
            np.array([np.mean(m.f_t[h:b])]),
            np.array([np.mean(m.tau[h:b])]),
        )
        return 4.6 * float(np.asarray(est.g)[0]) / p.sigma0

    return req


def _prior(ls: LimitSurfaceFit, beta: float, observable: bool, fix_gamma, diag: dict) -> Prior:
    """Joint log-space prior of (mu, delta, gamma[, beta_A]) from the limit-surface fit,
    conditioned on its k (k is not refined), plus the diagonal entries in ``diag``."""
    fitted = list(ls.free)
    keep = [n for n in ("mu", "delta", "gamma", "kappa") if n in fitted]
    if not observable and "kappa" in keep:
        keep.remove("kappa")
    cov = np.asarray(ls.cov, dtype=float)
    if np.all(np.isfinite(cov)):
        P = np.linalg.pinv(cov)
        idx = [fitted.index(n) for n in keep]
        cond = np.linalg.pinv(P[np.ix_(idx, idx)])  # covariance given the fitted 1/k
    else:
        cond = np.diag([1.0] * len(keep))
    # to ln-space of the parameters: gamma -> ln gamma, kappa -> ln beta_A
    names, values = [], []
    J = np.zeros((len(keep), len(keep)))
    for r, n in enumerate(keep):
        if n == "mu":
            names.append("mu")
            values.append(ls.mu)
            J[r, r] = 1.0
        elif n == "delta":
            names.append("delta")
            values.append(ls.delta)
            J[r, r] = 1.0
        elif n == "gamma":
            names.append("gamma")
            values.append(ls.gamma)
            J[r, r] = 1.0 / max(ls.gamma, 1e-6)
        else:  # ln beta = ln kappa + ln mu - 3 ln delta
            names.append("beta_a")
            values.append(beta)
            J[r, r] = 1.0 / max(ls.kappa, 1e-300)
            if "mu" in keep:
                J[r, keep.index("mu")] = 1.0
            if "delta" in keep:
                J[r, keep.index("delta")] = -3.0
    C = J @ cond @ J.T + _REL_FLOOR**2 * np.eye(len(keep))
    full = len(names) + len(diag)
    cov_all = np.zeros((full, full))
    cov_all[: len(names), : len(names)] = C
    for i, (n, (v, s)) in enumerate(diag.items()):
        names.append(n)
        values.append(v)
        cov_all[len(keep) + i, len(keep) + i] = s * s
    return Prior(names=tuple(names), values=np.asarray(values, float), cov=cov_all)
