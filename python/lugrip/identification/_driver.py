"""The driver of the identification: the staged estimate from the data, then the eq. 32
refinement regularised toward it (docs/model.md §8)."""

from __future__ import annotations

import dataclasses
import math
import time
import warnings
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np

from .. import _core
from .._observer import Observer
from .._params import ContactParams
from ._checks import check_data, force_range_too_small, rotation_only
from ._common import (
    _DEFAULT_SLIP,
    PARAMETERS,
    IdentifiabilityWarning,
    IdentificationError,
    IdentificationWarning,
)
from ._data import _Maneuver, _observer_settings, _Problem, load_maneuvers
from ._guess import _clip
from ._optimize import _refit, minimise
from ._result import IdentificationResult, ParameterEstimate, estimates_of, evaluate_split
from ._setup import _bounds, _parse_free, _split, check_options, read_params0
from ._friction import friction_levels
from ._start import staged_estimate
from ._uncertainty import covariance, finite_difference_covariance, resampled

__all__ = ["identify"]

CUTOFFS = (2.0, 5.0, 10.0, 20.0)  # [Hz] candidates of the CoR torque filter (speed observable)


def identify(
    logs,
    params0=None,
    free: Sequence[str] | str = PARAMETERS,
    bounds: Mapping[str, tuple[float, float]] | None = None,
    *,
    observer: Mapping[str, Any] | Observer | None = None,
    validation: float | Sequence = 0.2,
    seed: int = 0,
    loss: str = "squared",
    huber_scale: float = 0.05,
    weighting: str = "maneuver",
    method: str = "gauss-newton",
    max_iterations: int = 200,
    tolerance: float | None = None,
    uncertainty: str = "sandwich",
    n_bootstrap: int = 20,
    start: str | None = None,
    refine: bool = True,
    slip_threshold: float = _DEFAULT_SLIP,
    max_gap: float | None = None,
    fix_unidentifiable: bool = True,
    score_saturated: bool = False,
    threads: int = 0,
    k: float | None = None,
    c_max: float | None = None,
    progress: Callable[[int, float, ContactParams], None] | None = None,
) -> IdentificationResult:
    """Identify contact parameters from sliding logs with ground-truth velocity.

    Without ``params0`` (``start="data"``) the parameters come from stages, each from what
    the data carry (docs/model.md §8): the phases of every sample from the wrench and the
    motion together, the sensor noise from the still samples, (a) the limit surface (mu,
    delta, gamma and the shape: the pressure exponent k, or the elliptic limit surface, k = 0,
    whichever lies closer to the points) from the gross-sliding wrench, (c) beta_A from its
    speed dependence with a significance test (not significant: "sliding speed not
    observable", beta_A set so that the observer reports speed_observable = False, and kept
    fixed), (b) sigma0 and sigma_z from the loading runs. Then (``refine``) the paper's eq. 32
    (the online observer's velocity error, C++ cost and exact gradient) refines them,
    regularised toward the stage values within their standard errors. A parameter that ends
    at a bound makes the status "failed".

    With ``params0`` (``start="params0"``) only eq. 32 is minimised from it, without
    regularisation (the per-object refit of the paper is ``free=("mu", "beta_a")``).

    Args:
        logs: :class:`lugrip.SlidingLog`, a path, a mapping of arrays or a sequence of these;
            needs ``omega``. Each maneuver and gap-free stretch is a separate observer run.
        params0: start point and values of the fixed parameters (ContactParams, preset name,
            dict or YAML path; a YAML also gives its observer block).
        free: parameters to identify; bounds: {name: (lower, upper)} for eq. 32.
        observer: settings of the online observer (keywords of :class:`lugrip.Observer`); the
            result records them, with the torque noise measured on the data when the
            stages ran and ``torque_noise`` was not given, and, where the stages found the
            speed observable and ``torque_cutoff`` was not given, the CoR torque filter's
            cutoff among 2, 5, 10 and 20 Hz with the smallest eq. 32 cost at the stage values.
        validation: fraction of maneuvers held out (random, ``seed``) or their keys/indices.
        loss, huber_scale, weighting, method, max_iterations, tolerance: the eq. 32 fit
            ("squared"/"huber", "maneuver"/"sample", "gauss-newton"/"slsqp"/"trust-constr").
        uncertainty: "sandwich" (default, clustered by maneuver), "gauss-newton" or
            "bootstrap" (``n_bootstrap`` refits); also the method of the Stribeck joint fit's
            standard errors (``result.friction_estimates``, docs/identification.md).
        start: "data" or "params0" (default: params0 when given). refine: run eq. 32.
        slip_threshold: |omega| [rad/s] for the all-stick check of a params0 start and the
            clipped-CoR exclusion.
        max_gap: split segments at larger time steps [s].
        fix_unidentifiable: fix gamma when the normal force hardly varies and delta on
            rotation-only data (warned either way).
        score_saturated: also score sliding samples whose CoR the observer clips at c_max.
        threads: C++ threads (0: all cores). k, c_max: pressure exponent (None: identified
            by the stages, the pressure family and the elliptic limit surface compared; 0:
            the ellipse; 4 for a params0-less fit without stages) and CoR clip (1.5).
        progress: called as progress(iteration, cost, params).

    Raises:
        IdentificationError: data that cannot give a fit (no ground truth, omega apparently
            in deg/s, no gross sliding, sliding in fewer than three maneuvers, ...).
        ValueError: bad arguments.
    """
    t_start = time.perf_counter()
    free = _parse_free(free)
    bnds = _bounds(bounds)
    tolerance = check_options(
        loss=loss, weighting=weighting, method=method, tolerance=tolerance, uncertainty=uncertainty
    )
    p_given, observer = read_params0(params0, observer)
    if p_given is None and len(free) < len(PARAMETERS):
        fixed = [n for n in PARAMETERS if n not in free]
        raise IdentificationError(
            f"params0 is needed for the fixed parameter(s) {', '.join(fixed)} (e.g. the "
            "fingertip's identified parameters for an object refit)"
        )
    start = start or ("params0" if p_given is not None else "data")
    if start not in ("data", "params0"):
        raise ValueError(f"start = {start!r}: 'data' or 'params0'")
    if start == "params0" and p_given is None:
        raise ValueError("start = 'params0' needs params0")
    cm = p_given.c_max if p_given is not None else (1.5 if c_max is None else float(c_max))

    mans = load_maneuvers(logs, max_gap=max_gap)
    staged = start == "data"
    notes = check_data(mans, free, slip_threshold, staged=staged)
    fixed_notes: dict[str, str] = {}
    free_list = list(free)
    short = force_range_too_small(mans)
    fix_gamma = None
    if short and "gamma" in free_list and "delta" in free_list:
        g_fix = p_given.gamma if p_given is not None else 0.25
        if fix_unidentifiable:
            free_list.remove("gamma")
            fix_gamma = g_fix
            fixed_notes["gamma"] = f"fixed at {g_fix:.4g}: too little normal-force range"
            short += f"; gamma fixed at {g_fix:.4g}"
        warnings.warn(short, IdentifiabilityWarning, stacklevel=2)
        notes.append(short)

    # --- the start point: stages from the data, or params0
    stage = None
    guess_notes: dict[str, str] = {n: "params0" for n in PARAMETERS}
    if staged:
        kk = k if k is not None else (p_given.k if p_given is not None else None)
        o_given = (
            {n: v for n, v in observer.items() if v is not None}
            if isinstance(observer, Mapping)
            else observer
        )
        p_any = p_given if p_given is not None else ContactParams(0.5, 1e6, 1.0, 0.01, 1e-3, 0.25)
        _, od = _observer_settings(o_given, p_any)  # the settings only: any valid parameters
        # the largest gain the observer may use: its gain_max in bandwidth mode, else its gain
        l_max = float(od["gain_max"] if od.get("gain_mode") == "bandwidth" else od["gain"])
        # an object refit from the fingertip's parameters (params0, delta and gamma not
        # free): the limit surface is fitted with the fingertip's delta and gamma held, so
        # that mu is the one that fits this object's sliding wrench with them (the paper's
        # Table 2 step); with delta free the stage would split mu delta differently
        hold = p_given is not None and "delta" not in free_list and "gamma" not in free_list
        stage = staged_estimate(
            mans,
            k=kk,
            c_max=cm,
            fix_gamma=p_given.gamma if hold else fix_gamma,
            fix_delta=p_given.delta if hold else None,
            gain_max=l_max,
        )
        base = stage.params if p_given is None else p_given.replace(k=stage.params.k)
        p0 = base.replace(**{n: getattr(stage.params, n) for n in free})
        guess_notes = {n: "stages" for n in PARAMETERS}
        for n, why in stage.fixed.items():
            if n in free_list:
                free_list.remove(n)
                fixed_notes[n] = f"fixed at {getattr(p0, n):.4g}: {why}"
    else:
        p0 = p_given
    for n in free_list:  # inside the bounds
        v = getattr(p0, n)
        lo, hi = bnds[n]
        if not (lo < v < hi):
            p0 = p0.replace(**{n: _clip(n, v, bnds)})
            notes.append(
                f"{n}: start {v:.4g} outside the bounds [{lo:.3g}, {hi:.3g}], moved inside"
            )
    if (
        "delta" in free_list
        and ("mu" in free_list or "beta_a" in free_list)
        and not staged
        and rotation_only(mans, p0, slip_threshold)
    ):
        msg = (
            "the data hold only rotations (estimated |c~| < 0.15 on 95 % of the sliding "
            "samples): mu and delta enter only as mu delta (tau_max) and beta_A only as "
            "beta_A delta^4, so delta is not separately identifiable"
        )
        if fix_unidentifiable:
            free_list.remove("delta")
            fixed_notes["delta"] = f"fixed at {p0.delta:.4g}: rotation-only data"
            msg += f"; delta fixed at {p0.delta:.4g}"
        warnings.warn(msg, IdentifiabilityWarning, stacklevel=2)
        notes.append(msg)
    free_t = tuple(n for n in PARAMETERS if n in free_list)
    if not free_t and refine:
        refine = False
        notes.append("no parameter left for the eq. 32 refinement")

    # --- the observer inside the cost
    observer = {} if observer is None else observer
    given = set(observer) if isinstance(observer, Mapping) else None
    if isinstance(observer, Mapping):
        observer = dict(observer)
        if observer.get("dt") is None:
            steps = np.concatenate([m.dt[m.dt > 0] for m in mans] or [np.zeros(0)])
            if steps.size:
                observer["dt"] = float(np.median(steps))
        if (
            stage is not None
            and "torque_noise" not in observer
            and math.isfinite(stage.noise.torque)
        ):
            observer["torque_noise"] = float(stage.noise.torque)
    osettings, odict = _observer_settings(observer, p0)
    settings = _core.IdentificationSettings()
    settings.observer = osettings
    settings.loss = _core.IdLoss.Huber if loss == "huber" else _core.IdLoss.Squared
    settings.huber_scale = float(huber_scale)
    settings.threads = int(threads)
    msg = _core.validate_identification_settings(settings)
    if msg:
        raise ValueError("invalid identification settings:\n" + msg.rstrip())

    keys = [m.key for m in mans]
    val_idx = set(_split(keys, validation, seed))
    prior = stage.prior if stage is not None else None
    n_train = len(mans) - len(val_idx)

    def scored_copies(p_clip: ContactParams):
        """Maneuvers with the clipped-CoR sliding samples left unscored (at p_clip)."""
        out, n_clip = [], 0
        online = Observer(p_clip, **odict) if not score_saturated else None
        for m in mans:
            om = m.omega
            if online is not None:
                mask = _clipped_sliding(m, online, slip_threshold)
                n_clip += int(mask.sum())
                om = np.where(mask, np.nan, om)
            out.append(dataclasses.replace(m, omega=om))
        return out, n_clip

    def fit(p_clip: ContactParams):
        ms, n_clip = scored_copies(p_clip)
        train_m = [m for i, m in enumerate(ms) if i not in val_idx]
        val_m = [ms[i] for i in sorted(val_idx)]
        train = _Problem(train_m, settings, weighting)
        val = _Problem(val_m, settings, weighting) if val_m else None
        mn = minimise(
            train,
            p0,
            free_t,
            bnds,
            method=method,
            max_iterations=max_iterations if refine else 0,
            tolerance=tolerance,
            prior=prior,
            prior_weight=1.0 / max(n_train, 1) if prior else 0.0,
            progress=progress,
        )
        return train, val, train_m, val_m, mn, n_clip

    if (
        stage is not None
        and stage.speed_observable
        and given is not None
        and "torque_cutoff" not in given
    ):
        # the CoR torque filter: where the speed is observable, the cutoff whose observer
        # has the smallest eq. 32 cost at the stage values (same scored samples for all)
        ms, _ = scored_copies(p0)
        train_c = [m for i, m in enumerate(ms) if i not in val_idx]
        costs = {}
        for cut in CUTOFFS:
            st = _core.IdentificationSettings()
            st.observer = _observer_settings({**observer, "torque_cutoff": cut}, p0)[0]
            st.loss, st.huber_scale, st.threads = (
                settings.loss,
                settings.huber_scale,
                settings.threads,
            )
            costs[cut] = float(_Problem(train_c, st, weighting).evaluate(p0, False)["cost"])
        best = min(costs, key=lambda c: costs[c] if math.isfinite(costs[c]) else math.inf)
        observer["torque_cutoff"] = float(best)
        osettings, odict = _observer_settings(observer, p0)
        settings.observer = osettings
        notes.append(
            "CoR torque filter: cutoff "
            + ", ".join(f"{c:g} Hz RMSE {math.sqrt(max(v, 0.0)):.3g}" for c, v in costs.items())
            + f" at the stage values: {best:g} Hz"
        )

    if not free_t:
        free_t = ("mu",)  # evaluation only: the minimiser runs no iteration
        max_iterations, refine = 0, False
    train, val, train_m, val_m, mn, n_clip = fit(p0)
    fits, fit_time = 1, mn.fit_time
    while refine and not score_saturated and fits < 4:
        _, n_at = scored_copies(mn.params)
        if n_at == n_clip:
            break
        train, val, train_m, val_m, mn, n_clip = fit(mn.params)
        fits += 1
        fit_time += mn.fit_time
    if fits > 1:
        notes.append(
            f"{fits} fits: the clipped-CoR samples were located again at each "
            "fit's result until the set settled"
        )
    p_hat = mn.params
    res = mn.result
    ev, split = evaluate_split(train, val, train_m, val_m, p_hat)
    if not free_list:
        free_t = ()

    def refit(ms):
        return _refit(
            _Problem(ms, settings, weighting), p_hat, free_t, bnds, max_iterations, tolerance
        )

    if free_t:
        stderr_log, corr, weak, unc_notes = covariance(
            train,
            ev,
            mn,
            free_t,
            loss=loss,
            uncertainty=uncertainty,
            sse=split["sse"],
            refit=refit,
            n_bootstrap=n_bootstrap,
            seed=seed,
        )
    else:
        stderr_log, corr, weak, unc_notes = np.zeros(0), np.zeros((0, 0)), (), []
    ident = notes + unc_notes
    if n_clip:
        n_all = sum(m.n for m in mans)
        ident.append(
            f"{n_clip} samples ({100 * n_clip / max(n_all, 1):.1f} %) not scored: "
            "sliding with the CoR clipped at c_max (translation beyond the clip), "
            "where omega_hat is the slip about the clipped CoR, not the object's rotation"
        )
    if int(ev["truncated"]):
        ident.append(
            f"gradient truncated on {int(ev['truncated'])} samples where the observer "
            "chatters (its discrete map is locally chaotic there)"
        )
    estimates, bound_notes = estimates_of(
        p_hat, p0, free_t, mn, bnds, stderr_log, guess_notes, fixed_notes, stage
    )
    ident += bound_notes
    if stage is not None and kk is None and free_t and any(n in free_t for n in ("delta", "beta_a")):
        ident.append(
            f"the standard errors hold the limit-surface shape of stage (a) fixed ("
            f"{'the elliptic limit surface' if p_hat.k == 0.0 else f'k = {p_hat.k:.3g}'}): "
            "they do not include its uncertainty. Where the pressure lies outside the family "
            "the shape chosen varies between data sets, and delta and beta_A with it, by many "
            "times their standard errors (docs/identification.md); hold k (--k) to compare"
        )
    at_bound = [(e.name, e.at_bound) for e in estimates if e.at_bound]
    if stage is not None:
        at_bound += [
            (n, "limit-surface stage")
            for n in stage.ls.at_bound
            if n not in {name for name, _ in at_bound}
        ]
    if not refine:
        status, message = "stages", "stage values (no eq. 32 refinement)"
    elif res.success:
        status, message = "converged", str(res.message)
    elif "iteration" in str(res.message).lower():
        status, message = "max_iterations", str(res.message)
    else:
        status, message = "failed", str(res.message)
    if at_bound:
        status = "failed"
        message = "parameter(s) at a bound: " + ", ".join(f"{n} ({where})" for n, where in at_bound)
        if any(n == "k" for n, _ in at_bound):
            message += (
                " (k at 0.5: the sliding wrench lies outside every pressure profile of the "
                "limit-surface family, yet the elliptic limit surface fits it worse; hold k "
                "with k=0.5 / --k 0.5 or k=0 / --k ellipse to accept one of them)"
            )
        warnings.warn(message, IdentificationWarning, stacklevel=2)
    elif status not in ("converged", "stages"):
        warnings.warn(
            f"the optimiser stopped without convergence: {res.message}",
            IdentificationWarning,
            stacklevel=2,
        )
    friction: tuple = ()  # estimates of the Stribeck curve fitted jointly (stage 7)
    if stage is not None and refine:
        # (d) the friction levels S is judged against (break-away, sliding), at the result
        keys = {m.key for m in train_m}
        pairs = [(m, ph) for m, ph in zip(mans, stage.phases) if m.key in keys]
        levels = friction_levels(
            [m for m, _ in pairs], [ph for _, ph in pairs], p_hat, dict(odict)
        )
        p_hat = p_hat.replace(static_ratio=levels.static_ratio, kinetic_ratio=levels.kinetic_ratio)
        lines = (levels.line,)
        if levels.curve is not None and stage.speed_observable:
            joint = _stribeck_joint(
                train, val, p_hat, levels.curve, free_t, bnds, method, max_iterations, tolerance,
                loss=loss, uncertainty=uncertainty, n_bootstrap=n_bootstrap, seed=seed,
                problem_of=lambda ms: _Problem(ms, settings, weighting))
            lines += (joint.line,)
            fit_time += joint.fit_time
            if joint.accepted:
                p_hat = joint.params
                lines += (joint.stderr_line,)
                estimates = [
                    dataclasses.replace(
                        e, value=getattr(p_hat, e.name), stderr=joint.stderr[e.name],
                        note=(e.note + "; " if e.note else "")
                        + "refitted with the Stribeck curve (stage 7)"
                        + (f", no standard error: {joint.why[e.name]}"
                           if e.name in joint.why else ""))
                    if e.name in joint.free else e
                    for e in estimates
                ]
                friction = _curve_estimates(p_hat, levels, joint)
                ev, split = evaluate_split(train, val, train_m, val_m, p_hat)
                at_bound = [(n, "Stribeck joint fit") for n in joint.at_bound]
                if at_bound:
                    status = "failed"
                    message = "parameter(s) at a bound: " + ", ".join(
                        f"{n} ({where})" for n, where in at_bound)
                    warnings.warn(message, IdentificationWarning, stacklevel=2)
        stage = dataclasses.replace(stage, report=stage.report + lines)
        ident.extend(lines)
    data_warnings = _data_warnings(split, stage)
    for w in data_warnings:
        warnings.warn(w, IdentificationWarning, stacklevel=2)
    return IdentificationResult(
        status=status,
        message=message,
        params=p_hat,
        params0=p0,
        estimates=tuple(estimates),
        free=free_t,
        cost_trace=tuple(mn.trace),
        rmse_train=split["rmse_train"],
        rmse_validation=split["rmse_val"],
        rms_omega_train=split["rms_train"],
        rms_omega_validation=split["rms_val"],
        maneuver_rmse=split["maneuver_rmse"],
        validation_keys=tuple(m.key for m in val_m),
        correlation=corr,
        identifiability=tuple(ident),
        weak_directions=tuple(weak),
        uncertainty=uncertainty,
        wall_time=time.perf_counter() - t_start,
        fit_time=fit_time,
        iterations=mn.iterations,
        evaluations=train.evaluations,
        samples_train=split["n_train"],
        samples_validation=split["n_val"],
        truncated=int(ev["truncated"]),
        samples_saturated=n_clip,
        settings={
            "loss": loss,
            "huber_scale": float(huber_scale),
            "weighting": weighting,
            "method": method,
            "start": start,
            "refine": bool(refine),
            "validation": len(val_m),
            "seed": int(seed),
            "slip_threshold": float(slip_threshold),
            "score_saturated": bool(score_saturated),
            "observer": dict(odict),
            "bounds": {n: list(bnds[n]) for n in free_t},
            "threads": int(threads),
            "maneuvers": len(mans),
        },
        validation_trace=split["trace"],
        stages=stage,
        warnings=tuple(data_warnings),
        friction_estimates=friction,
    )


#: parameters the joint fit with the Stribeck curve refits by eq. 32 (docs/model.md §8.3, stage
#: 7): the sliding level and what a speed-dependent friction biases when it is fitted with one
#: level
STRIBECK_JOINT = ("mu", "delta", "gamma", "beta_a")
#: the joint fit is kept when the log of the per-maneuver cost falls with t >= this (paired over
#: the maneuvers)
STRIBECK_T_JOINT = 3.0
#: cost evaluations of the Nelder-Mead search of the curve's rest level and speed
STRIBECK_EVALUATIONS = 20
#: iterations of each Gauss-Newton fit of the joint fit (it starts near its minimum)
STRIBECK_ITERATIONS = 8
#: central-difference step of the joint fit's standard errors on the curve's coordinates
#: ln(static_ratio - 1) and ln(stribeck_speed): the cost is kinked at the joint fit's result
#: (the observer's switching between modes), so second differences on a small step measure
#: the kink, not the valley the estimate moves in between data sets (on the viscous Stribeck
#: grid plant: the spread of ln stribeck_speed over seeds 3.9 times the standard error with
#: a step of 0.2, 1.3 times with 0.3, 1.6 with 0.4 where the cross terms turn noisy)
STRIBECK_FD_STEP = 0.3
#: a curve coordinate (natural log) with a standard error above this is reported as not
#: determined (NaN): the data do not fix it within a factor e
STRIBECK_UNDETERMINED = 1.0
_CURVE = ("static_ratio", "stribeck_speed")
_CURVE_COORD = ("static_ratio - 1", "stribeck_speed")
# the ranges of the friction ratios and the Stribeck speed, from the C++ field table
_LIMITS = {p["name"]: (p["lo"]["value"], p["hi"]["value"]) for p in _core.ContactParams.params}
_MIN_RATIO, _MAX_RATIO = _LIMITS["static_ratio"]
_MAX_STRIBECK = _LIMITS["stribeck_speed"][1]


@dataclasses.dataclass(frozen=True)
class _Joint:
    params: ContactParams
    accepted: bool
    free: tuple
    at_bound: tuple
    fit_time: float
    line: str
    stderr: dict = dataclasses.field(default_factory=dict)  # name -> standard error (NaN: why)
    why: dict = dataclasses.field(default_factory=dict)  # name -> why it has none
    stderr_line: str = ""


def _maneuver_mse(problems, params: ContactParams) -> tuple[np.ndarray, float]:
    """Per maneuver of the problems: the mean squared omega_hat error of its scored samples;
    and the first problem's cost (eq. 32), from the same evaluation."""
    out = []
    cost = math.nan
    for k, prob in enumerate(problems):
        ev = prob.evaluate(params, False)
        if k == 0:
            cost = float(ev["cost"])
        sse, cnt = prob.per_maneuver(ev)
        out.append(np.where(cnt > 0, sse / np.maximum(cnt, 1), np.nan))
    return np.concatenate(out), cost


def _curve_at(q: ContactParams, x) -> ContactParams:
    """q with the Stribeck curve at the Nelder-Mead coordinates x = (ln(static_ratio - 1),
    ln stribeck_speed), clipped to their ranges (kinetic_ratio kept at most the rest level)."""
    r = min(1.0 + math.exp(x[0]), _MAX_RATIO)
    return q.replace(static_ratio=r, kinetic_ratio=min(q.kinetic_ratio, r),
                     stribeck_speed=min(math.exp(x[1]), _MAX_STRIBECK))


def _curve_coordinates(p: ContactParams) -> np.ndarray:
    return np.array([math.log(max(p.static_ratio - 1.0, 1.0e-3)), math.log(p.stribeck_speed)])


def _joint_fit(train, p, free, bnds, method, max_iterations, tolerance) -> ContactParams:
    """Eq. 32 over ``free`` and the curve from p (the curve in it): Gauss-Newton over ``free``
    (``STRIBECK_ITERATIONS``), Nelder-Mead over the curve's coordinates with them held
    (``STRIBECK_EVALUATIONS``), Gauss-Newton again where the search lowered the cost."""
    from scipy.optimize import minimize

    def gauss_newton(q):
        return minimise(train, q, free, bnds, method=method,
                        max_iterations=min(max_iterations, STRIBECK_ITERATIONS),
                        tolerance=tolerance).params

    p = gauss_newton(p)
    q = p

    def cost(x):
        try:
            c = float(train.evaluate(_curve_at(q, x), False)["cost"])
        except ValueError:  # outside the parameters' valid ranges
            return math.inf
        return c if math.isfinite(c) else math.inf

    x0 = _curve_coordinates(p)
    res = minimize(cost, x0, method="Nelder-Mead",
                   options={"initial_simplex": np.vstack([x0, x0 + [0.3, 0.0], x0 + [0.0, 0.3]]),
                            "maxfev": STRIBECK_EVALUATIONS, "xatol": 0.02, "fatol": 0.0})
    if math.isfinite(res.fun) and res.fun < cost(x0):
        p = gauss_newton(_curve_at(q, res.x))
    return p


def _stribeck_joint(train, val, p_hat, curve, free_t, bnds, method, max_iterations,
                    tolerance, *, loss="squared", uncertainty="sandwich", n_bootstrap=20,
                    seed=0, problem_of=None) -> _Joint:
    """Stage 7's Stribeck curve put into the observer (mu the level at speed, static_ratio the
    level at rest over it, stribeck_speed its speed; kinetic_ratio kept as the same absolute
    level) and eq. 32 minimised again over the sliding level, delta, gamma and beta_A together
    with the curve, unregularised (:func:`_joint_fit`). The refinement fitted them with one
    dry level, which a falling friction biases: a slow slide's excess friction read as speed,
    the shape and the viscous term bent to absorb it. Kept only where the per-maneuver cost
    (mean squared omega_hat error of each training and validation maneuver) falls
    significantly against the refined parameters with the friction levels: the log of its
    ratio, paired over the maneuvers, with t >= ``STRIBECK_T_JOINT``. Where kept, the standard
    errors of the refitted parameters and of the curve come from :func:`_joint_stderr`
    (``problem_of(maneuvers)`` builds a training problem for the bootstrap)."""
    t0 = time.perf_counter()
    a, b, v_s = curve
    rest = min(b / a, _MAX_RATIO)
    p = p_hat.replace(
        mu=p_hat.mu * a, static_ratio=rest,
        kinetic_ratio=min(max(p_hat.kinetic_ratio / a, _MIN_RATIO), rest), stribeck_speed=v_s)
    free = tuple(n for n in STRIBECK_JOINT if n in free_t)
    if not free:
        return _Joint(p_hat, False, (), (), 0.0,
                      "(d) Stribeck curve: no free parameter to refit with it")
    p_start = p
    p = _joint_fit(train, p, free, bnds, method, max_iterations, tolerance)
    problems = [train] + ([val] if val is not None else [])
    (before, c_one), (after, c_joint) = _maneuver_mse(problems, p_hat), _maneuver_mse(problems, p)
    ok = (before > 0.0) & (after > 0.0)  # NaN (nothing scored) compares False
    d = np.log(before[ok] / after[ok])  # scale-free: a few fast maneuvers do not dominate
    t = (float(np.mean(d)) / (float(np.std(d, ddof=1)) / math.sqrt(d.size))
         if d.size > 2 and np.std(d) > 0 else 0.0)
    accepted = t >= STRIBECK_T_JOINT
    at_bound = tuple(
        n for n in free
        if math.isclose(getattr(p, n), bnds[n][0], rel_tol=1e-6)
        or math.isclose(getattr(p, n), bnds[n][1], rel_tol=1e-6)
    )
    elapsed = time.perf_counter() - t0
    line = (
        f"(d) Stribeck curve in the observer and eq. 32 refitted over {', '.join(free)} "
        f"together with it ({elapsed:.1f} s): stribeck_speed {p.stribeck_speed:.3g} m/s, "
        f"static_ratio {p.static_ratio:.3g} (the level at rest over mu), mu {p_hat.mu:.4g} -> "
        f"{p.mu:.4g}, delta {p_hat.delta:.4g} -> {p.delta:.4g}, gamma {p_hat.gamma:.4g} -> "
        f"{p.gamma:.4g}, beta_a {p_hat.beta_a:.4g} -> {p.beta_a:.4g}; training cost "
        f"{c_one:.4g} with one sliding level, {c_joint:.4g} with the curve, log per-maneuver "
        f"cost lower with t = {t:.3g} over {d.size} maneuvers: "
        + ("kept" if accepted else f"not kept (needs t >= {STRIBECK_T_JOINT:g})")
    )
    if not accepted:
        return _Joint(p_hat, False, free, (), elapsed, line)
    stderr, why, unc_line = _joint_stderr(
        train, p, free, bnds, at_bound, loss=loss, uncertainty=uncertainty,
        n_bootstrap=n_bootstrap, seed=seed, problem_of=problem_of,
        refit=lambda prob: _joint_fit(prob, p_start, free, bnds, method, max_iterations,
                                      tolerance))
    return _Joint(p, True, free, at_bound, elapsed, line, stderr, why, unc_line)


def _joint_stderr(train, p, free, bnds, at_bound, *, loss, uncertainty, n_bootstrap, seed,
                  problem_of, refit):
    """Standard errors of the joint fit's result p: the refitted parameters ``free`` (log
    coordinates) and the curve (Nelder-Mead coordinates ln(static_ratio - 1), ln
    stribeck_speed), together, from :func:`finite_difference_covariance` of eq. 32 at p
    (sandwich or Gauss-Newton formula), or from ``n_bootstrap`` joint fits on resampled
    training maneuvers (``refit(problem)``: the whole joint fit from its start). NaN, with
    the reason, for a parameter at a bound, a curve coordinate along which the cost's
    curvature is not positive, or one whose standard error exceeds ``STRIBECK_UNDETERMINED``
    (the data do not fix it within a factor e). Returns ({name: standard error}, {name: why
    NaN}, the report line)."""
    t0 = time.perf_counter()
    names = free + _CURVE
    x0 = _curve_coordinates(p)
    # the refitted parameters are not varied (their block is the C++ one): NaN marks a bound
    steps = np.array([1.0] * len(free) + [STRIBECK_FD_STEP] * 2)
    why: dict[str, str] = {}
    for i, n in enumerate(free):
        if n in at_bound:
            steps[i] = math.nan
            why[n] = "at a bound"
    limits = (math.log(_MAX_RATIO - 1.0), math.log(_MAX_STRIBECK))
    for j in range(2):
        if not x0[j] + steps[len(free) + j] < limits[j]:
            steps[len(free) + j] = math.nan
            why[_CURVE[j]] = "at (or within the difference step of) the top of its range"

    def at(u):
        q = p.replace(**{n: getattr(p, n) * math.exp(u[i]) for i, n in enumerate(free)})
        return _curve_at(q, x0 + u[len(free):])

    def coordinates(q):
        return np.concatenate([np.log([getattr(q, n) / getattr(p, n) for n in free]),
                               _curve_coordinates(q) - x0])

    samples = None
    if uncertainty == "bootstrap":
        ms = train.maneuvers
        if problem_of is not None and len(ms) >= 2:
            samples = [coordinates(refit(problem_of(draw)))
                       for draw in resampled(ms, n_bootstrap, seed)]
        else:
            why.update({n: "the bootstrap needs two or more training maneuvers"
                        for n in names if n not in why})
    # the refitted parameters' block: the C++ Gauss-Newton matrix, per-maneuver gradients and
    # gradient (pathwise; the curve's factor on the speed state is not differentiated)
    idx = [PARAMETERS.index(n) for n in free]

    def known(e, q):
        s = np.array([getattr(q, n) for n in free])
        w_sum = float(e["weight_sum"])
        return (np.asarray(e["gauss_newton"]).reshape(6, 6)[np.ix_(idx, idx)] * np.outer(s, s)
                * w_sum, train.maneuver_gradients(e)[:, idx] * s,
                np.asarray(e["gradient"])[idx] * s * w_sum)

    cov, flat, n_ev, step = finite_difference_covariance(
        train, at, steps, loss=loss, uncertainty=uncertainty, samples=samples, known=known)
    if samples:
        for j in np.flatnonzero(np.ptp(np.asarray(samples), axis=0) == 0.0):
            why.setdefault(names[j], "the bootstrap's joint fits all returned it unchanged: "
                                     "no spread measured")
    for j in flat:
        why[names[j]] = ("not determined by these data: the cost's curvature is not positive "
                         "along it (flat, or rougher than curved on the difference step)")
    se_log = np.sqrt(np.abs(np.diag(cov)))
    for j, n in enumerate(_CURVE):
        s = se_log[len(free) + j]
        if n not in why and math.isfinite(s) and s > STRIBECK_UNDETERMINED:
            why[n] = (f"not determined by these data: one standard error of ln({_CURVE_COORD[j]}) "
                      f"is {s:.2g} (a factor {math.exp(s):.3g})")
    stderr = {}
    for j, n in enumerate(names):
        if n in why or not math.isfinite(se_log[j]):
            why.setdefault(n, "no standard error: the covariance is not finite")
            stderr[n] = math.nan
        elif n in free:
            stderr[n] = getattr(p, n) * float(se_log[j])
        else:  # d static_ratio = (r - 1) d ln(r - 1), d v_s = v_s d ln v_s
            scale = p.static_ratio - 1.0 if n == "static_ratio" else p.stribeck_speed
            stderr[n] = scale * float(se_log[j])
    how = (f"{int(n_bootstrap)} joint fits on resampled training maneuvers" if samples
           else f"{uncertainty}: the refitted parameters' block from the Gauss-Newton matrix, "
                f"the curve's rows from central differences of eq. 32 at the result ({n_ev} "
                "cost evaluations)")
    parts = [f"{n} {getattr(p, n):.4g} +- {stderr[n]:.2g}" if math.isfinite(stderr[n])
             else f"{n} {getattr(p, n):.4g} (no standard error: {why[n]})" for n in names]
    line = (f"(d) standard errors of the joint fit ({how}, {time.perf_counter() - t0:.1f} s): "
            + ", ".join(parts))
    newton = step[len(free):]
    if np.all(np.isfinite(newton)):
        line += (f"; the Nelder-Mead result lies {newton[0]:+.2g} in ln({_CURVE_COORD[0]}) and "
                 f"{newton[1]:+.2g} in ln stribeck_speed from the minimum of the cost's quadratic "
                 "model along the curve, the other parameters held (the search's stopping error, "
                 "not in the standard errors)")
    return stderr, why, line


def _curve_estimates(p: ContactParams, levels, joint: _Joint) -> tuple:
    """The joint fit's Stribeck curve as estimates: the rest level static_ratio and the speed,
    started from stage 7's curve of the runs' dry levels, with the joint fit's standard
    errors."""
    from .._params import _UNITS

    a, b, v_s = levels.curve
    start = {"static_ratio": min(b / a, _MAX_RATIO), "stribeck_speed": v_s}
    top = {"static_ratio": _MAX_RATIO, "stribeck_speed": _MAX_STRIBECK}
    out = []
    for n in _CURVE:
        v = getattr(p, n)
        note = "Stribeck curve of stage 7, fitted with eq. 32 jointly with the model parameters"
        if n in joint.why:
            note += f"; no standard error: {joint.why[n]}"
        out.append(ParameterEstimate(
            n, _UNITS[n], v, start[n], 1.0 if n == "static_ratio" else 0.0, top[n], True,
            "upper" if math.isclose(v, top[n], rel_tol=1e-9) else None, joint.stderr[n], note))
    return tuple(out)


def _data_warnings(split: dict, stage) -> list[str]:
    """Warnings that look at the fit's outcome on the data."""
    out = []
    rmse, rms = split["rmse_val"], split["rms_val"]
    which = "validation"
    if not math.isfinite(rmse):
        rmse, rms, which = split["rmse_train"], split["rms_train"], "training"
    if math.isfinite(rmse) and math.isfinite(rms) and rmse >= 0.9 * rms:
        out.append(
            f"omega_hat is no better than predicting zero on the {which} maneuvers (RMSE "
            f"{rmse:.3g} rad/s against {rms:.3g} for omega_hat = 0)"
            + (
                ""
                if stage is None or stage.speed_observable
                else ": expected, the sliding speed is not observable on these data (S and the "
                "slip decision still are)"
            )
        )
    return out


def _clipped_sliding(m: _Maneuver, observer: Observer, slip_threshold: float) -> np.ndarray:
    """Samples of a maneuver where the online observer (restarted per segment, as in the cost)
    clips the CoR at c_max while the ground truth slides (|omega| > slip_threshold)."""
    mask = np.zeros(m.n, dtype=bool)
    for a, b in zip(m.starts[:-1], m.starts[1:]):
        run = observer.run({"f_n": m.f_n[a:b], "f_t": m.f_t[a:b], "tau": m.tau[a:b], "t": m.t[a:b]})
        mask[a:b] = np.asarray(run.saturated, dtype=bool)
    with np.errstate(invalid="ignore"):
        return mask & (np.abs(m.omega) > slip_threshold)
