"""The identification result: parameter table, summary, YAML."""

from __future__ import annotations

import dataclasses
import math
import os
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

from .._observer import Observer
from .._params import _OPTIONAL, _UNITS, ContactParams


@dataclasses.dataclass(frozen=True)
class ParameterEstimate:
    """One parameter of an identification.

    Attributes:
        name, unit: as in :class:`lugrip.ContactParams`.
        value: estimate (the fixed value when not free).
        initial: start value.
        lower, upper: bounds used (free parameters).
        free: optimised (False: held at ``initial``).
        at_bound: "lower", "upper" or None.
        stderr: standard error (NaN when not free or not available).
        note: how the start value was obtained, or why the parameter was fixed.
    """

    name: str
    unit: str
    value: float
    initial: float
    lower: float
    upper: float
    free: bool
    at_bound: str | None
    stderr: float
    note: str = ""

    @property
    def relative_stderr(self) -> float:
        return self.stderr / abs(self.value) if self.value else math.nan


@dataclasses.dataclass(frozen=True)
class IdentificationResult:
    """Result of :func:`identify`.

    Attributes:
        status: "converged", "stages" (no refinement asked), "max_iterations" or "failed"
            (the optimiser failed, or a parameter ended at a bound); success: "converged" or
            "stages".
        message: the optimiser's message.
        params: identified :class:`lugrip.ContactParams`; params0: the start point.
        estimates: per parameter (:class:`ParameterEstimate`), in :data:`PARAMETERS` order.
        free: the optimised parameters.
        cost_trace: cost (eq. 32 with weights and loss) at the start and after every iteration.
        rmse_train, rmse_validation: RMSE of omega_hat [rad/s] over the scored samples of the
            training / validation maneuvers (per sample, the paper's metric; NaN without
            validation maneuvers).
        rms_omega_train, rms_omega_validation: RMS of the ground truth there [rad/s] (scale).
        maneuver_rmse: RMSE per maneuver key [rad/s]; validation_keys: the validation ones.
        correlation: correlation matrix of the free log-parameters (Gauss-Newton).
        identifiability: notes on parameters (combinations) the data cannot fix.
        weak_directions: principal axes of the covariance of the log-parameters, least
            determined first: (standard error along the axis, {parameter: exponent}), the
            axis normalised so that its largest exponent is 1 (relative spread of the product
            of powers).
        uncertainty: method of the standard errors.
        wall_time: seconds for the whole call; fit_time: optimiser only.
        iterations, evaluations: optimiser iterations and cost evaluations.
        samples_train, samples_validation: scored samples.
        truncated: samples where the gradient guard restarted the sensitivities (the
            observer's discrete map was locally chaotic) at the final point.
        samples_saturated: sliding samples (training and validation) left unscored because
            the observer's CoR was clipped at c_max there (``score_saturated=False``).
        settings: loss, weighting, method, observer settings, ...
        validation_trace: arrays for the Figure-5 plot of the validation maneuvers (t, omega,
            omega_hat, maneuver index, f_n, f_t, tau) or None.
        stages: the staged estimate (:class:`lugrip.identification.StageEstimate`: phases,
            noise, limit-surface and presliding fits, observability, per-stage report) or None
            (params0 start).
        warnings: warnings that look at the data and the fit (also issued as
            :class:`IdentificationWarning`).
        friction_estimates: where stage 7 put a Stribeck curve into the observer and kept the
            joint fit, its rest level ``static_ratio`` and ``stribeck_speed`` as estimates
            with the joint fit's standard errors (NaN with the reason in ``note`` where the
            data do not determine them); empty otherwise.
    """

    status: str
    message: str
    params: ContactParams
    params0: ContactParams
    estimates: tuple[ParameterEstimate, ...]
    free: tuple[str, ...]
    cost_trace: tuple[float, ...]
    rmse_train: float
    rmse_validation: float
    rms_omega_train: float
    rms_omega_validation: float
    maneuver_rmse: dict[str, float]
    validation_keys: tuple[str, ...]
    correlation: np.ndarray
    identifiability: tuple[str, ...]
    weak_directions: tuple[tuple[float, dict[str, float]], ...]
    uncertainty: str
    wall_time: float
    fit_time: float
    iterations: int
    evaluations: int
    samples_train: int
    samples_validation: int
    truncated: int
    settings: dict
    validation_trace: dict | None = None
    samples_saturated: int = 0
    stages: Any = None
    warnings: tuple[str, ...] = ()
    friction_estimates: tuple[ParameterEstimate, ...] = ()

    @property
    def success(self) -> bool:
        return self.status in ("converged", "stages")

    @property
    def speed_observable(self) -> bool | None:
        """Whether the stages found the sliding speed observable (None: no stages)."""
        return None if self.stages is None else bool(self.stages.speed_observable)

    @property
    def observer(self) -> dict:
        """Settings of the observer inside the cost (keywords of :class:`lugrip.Observer`):
        run online with exactly these, ``lugrip.Observer(result.params, **result.observer)``;
        :meth:`save_yaml` writes them as the ``observer:`` block."""
        return dict(self.settings.get("observer", {}))

    def make_observer(self) -> Observer:
        """The online observer the parameters were identified for."""
        return Observer(self.params, **self.observer)

    def __getitem__(self, name: str) -> ParameterEstimate:
        for e in self.estimates + self.friction_estimates:
            if e.name == name:
                return e
        raise KeyError(name)

    def table(self) -> str:
        """Plain-text parameter table: value, unit, bounds, standard error, start."""
        rows = self.estimates + self.friction_estimates
        w = max([10] + [len(e.name) for e in rows])
        head = (
            f"{'parameter':{w}s} {'value':>12s} {'std.err':>10s} {'rel':>7s}  "
            f"{'bounds':>23s} {'start':>12s}  unit"
        )
        lines = [head, "-" * len(head)]
        for e in rows:
            if e.free:
                se = f"{e.stderr:10.3g}" if math.isfinite(e.stderr) else f"{'n/a':>10s}"
                rel = f"{100 * e.relative_stderr:6.2f}%" if math.isfinite(e.stderr) else f"{'':>7s}"
                bnd = f"[{e.lower:.3g}, {e.upper:.3g}]"
                if e.at_bound:
                    bnd = f"{e.at_bound.upper()} {bnd}"
            else:
                se, rel, bnd = f"{'fixed':>10s}", f"{'':>7s}", ""
            lines.append(
                f"{e.name:{w}s} {e.value:12.6g} {se} {rel}  {bnd:>23s} {e.initial:12.6g}  {e.unit}"
            )
        return "\n".join(lines)

    def summary(self) -> str:
        """Status, RMSE, timing, the table and the identifiability notes."""
        out = [
            (
                f"status: {self.status} ({self.message}); {self.iterations} iterations, "
                f"{self.evaluations} evaluations, fit {self.fit_time:.2f} s, total "
                f"{self.wall_time:.2f} s"
            ),
            (
                f"RMSE omega_hat: train {self.rmse_train:.4g} rad/s (RMS omega "
                f"{self.rms_omega_train:.3g}, {self.samples_train} samples), validation "
                f"{self.rmse_validation:.4g} rad/s (RMS omega {self.rms_omega_validation:.3g}, "
                f"{self.samples_validation} samples, {len(self.validation_keys)} maneuvers)"
            ),
            self.table(),
        ]
        if self.stages is not None:
            out.append("stages:")
            out.extend(f"  {line}" for line in self.stages.report)
        if self.warnings:
            out.append("warnings:")
            out.extend(f"  - {w}" for w in self.warnings)
        if self.identifiability:
            out.append("identifiability:")
            out.extend(f"  - {s}" for s in self.identifiability)
        return "\n".join(out)

    def to_dict(self) -> dict:
        """JSON/YAML-able summary (no arrays except the correlation as nested lists)."""
        return {
            "contact": {
                e.name: {
                    k: v
                    for k, v in {
                        "value": e.value,
                        "unit": e.unit,
                        "free": e.free,
                        "stderr": e.stderr if math.isfinite(e.stderr) else None,
                        "initial": e.initial,
                        "bounds": [e.lower, e.upper] if e.free else None,
                        "at_bound": e.at_bound,
                        "note": e.note or None,
                    }.items()
                    if v is not None
                }
                for e in self.estimates
            }
            | {
                "k": {
                    "value": self.params.k if math.isfinite(self.params.k) else ".inf",
                    "unit": "-",
                }
                | ({"note": "0: the elliptic limit surface"} if self.params.k == 0.0 else {}),
                "c_max": {"value": self.params.c_max, "unit": "-"},
            }
            # the friction levels of stage 7 (docs/model.md 7.5), written like
            # ContactParams.to_yaml does: only when not at their default
            | {
                name: {"value": getattr(self.params, name), "unit": _UNITS[name]}
                | self._curve_entry(name)
                for name, default in _OPTIONAL.items()
                if getattr(self.params, name) != default
            },
            # the observer inside the cost: the parameters are identified FOR it (docs/model.md
            # 8.1), so online use must run the same one (lugrip observe --params reads this)
            "observer": dict(self.observer),
            "identification": {
                "status": self.status,
                "message": self.message,
                "free": list(self.free),
                "rmse_train": self.rmse_train,
                "rmse_validation": None
                if math.isnan(self.rmse_validation)
                else self.rmse_validation,
                "rms_omega_train": self.rms_omega_train,
                "rms_omega_validation": None
                if math.isnan(self.rms_omega_validation)
                else self.rms_omega_validation,
                "samples_train": self.samples_train,
                "samples_validation": self.samples_validation,
                "validation_maneuvers": list(self.validation_keys),
                "iterations": self.iterations,
                "evaluations": self.evaluations,
                "wall_time": self.wall_time,
                "fit_time": self.fit_time,
                "cost_trace": list(self.cost_trace),
                "uncertainty": self.uncertainty,
                "correlation": {
                    "parameters": list(self.free),
                    "matrix": np.round(self.correlation, 6).tolist(),
                },
                "identifiability": list(self.identifiability),
                "warnings": list(self.warnings),
                "stages": None if self.stages is None else _stage_dict(self.stages),
                "truncated_gradient_samples": self.truncated,
                "saturated_samples_unscored": self.samples_saturated,
                "settings": self.settings,
            },
        }

    def _curve_entry(self, name: str) -> dict:
        """The standard error and note of a friction-level field the joint fit estimated."""
        for e in self.friction_estimates:
            if e.name == name:
                return {"stderr": e.stderr if math.isfinite(e.stderr) else None,
                        "note": e.note}
        return {}

    def save_yaml(self, path: str | Path) -> Path:
        """Write the identified parameters with units, standard errors, bounds, the
        ``observer:`` block (the settings of the observer inside the cost) and the fit
        summary. :meth:`lugrip.ContactParams.from_yaml` reads the parameters back (the
        ``contact`` block), :func:`lugrip.read_observer_settings` the observer block;
        ``lugrip observe --params`` and ``lugrip identify --params0`` use both."""
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        text = self.yaml_text()
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
        try:
            with os.fdopen(fd, "w") as fh:
                fh.write(text)
            os.replace(tmp, path)
        finally:  # no temporary left behind when the write fails (disk full, ...)
            if os.path.exists(tmp):
                os.unlink(tmp)
        return path

    def yaml_text(self) -> str:
        """The text :meth:`save_yaml` writes."""
        import yaml

        return (
            "# lugrip identification (paper Section 4, docs/model.md §8): contact parameters\n"
            "# value [unit], standard error, bounds; the observer they were identified with\n"
            "# (use it online: lugrip observe --params reads the observer block); fit summary\n"
            + yaml.safe_dump(_plain(self.to_dict()), sort_keys=False)
        )


def _stage_dict(st) -> dict:
    ls = st.ls
    d = {
        "report": list(st.report),
        "samples": dict(st.counts),
        "noise": {"torque": st.noise.torque, "force": st.noise.force,
                  "samples": int(st.noise.samples)},
        "speed_observable": bool(st.speed_observable),
        "omega_resolution": st.omega_resolution,
        "limit_surface": {
            "mu": ls.mu, "delta": ls.delta, "gamma": ls.gamma,
            "k": ls.k if math.isfinite(ls.k) else ".inf",
            "beta_a": ls.beta_a, "viscous_t": ls.viscous_t,
            "stderr": {k: v for k, v in ls.stderr.items()},
            "points": len(ls.points), "at_bound": list(ls.at_bound),
            "rms_distance": ls.residual_rms,
            "shape": "ellipse" if ls.k == 0.0 else "pressure",
            "rms_distance_by_shape": dict(ls.shape_rms),
        },
    }
    if st.presliding is not None:
        pr = st.presliding
        d["presliding"] = {"sigma0": pr.sigma0, "sigma_z": pr.sigma_z, "stderr": dict(pr.stderr),
                           "runs": pr.runs, "samples": pr.samples,
                           "rms_residual": pr.residual_rms}
    return d


def _plain(obj):
    """Python scalars/lists for yaml.safe_dump."""
    if isinstance(obj, dict):
        return {str(k): _plain(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_plain(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _plain(obj.tolist())
    if isinstance(obj, (np.floating, float)):
        v = float(obj)
        return v if math.isfinite(v) else (".nan" if math.isnan(v) else ".inf")
    if isinstance(obj, (np.integer,)):
        return int(obj)
    if isinstance(obj, np.bool_):
        return bool(obj)
    return obj


def evaluate_split(train, val, train_m, val_m, p_hat):
    """Final evaluation at p_hat: RMSE per maneuver and per split, the validation trace."""
    ev = train.evaluate(p_hat, True, True)
    if not math.isfinite(ev["cost"]):
        from ._common import IdentificationError

        raise IdentificationError("the cost at the identified point is not finite")
    sse, cnt = train.per_maneuver(ev)
    m_rmse = {m.key: float(math.sqrt(s / c)) if c else math.nan
              for m, s, c in zip(train_m, sse, cnt)}
    out = {
        "sse": sse,
        "n_train": int(cnt.sum()),
        "rmse_train": float(math.sqrt(sse.sum() / max(cnt.sum(), 1))),
        "rms_train": float(np.sqrt(np.nanmean(train.omega[np.isfinite(train.omega)] ** 2))),
        "rmse_val": math.nan, "rms_val": math.nan, "trace": None, "n_val": 0,
    }
    if val is not None:
        evv = val.evaluate(p_hat, False, True)
        s_v, c_v = val.per_maneuver(evv)
        m_rmse.update({m.key: float(math.sqrt(s / c)) if c else math.nan
                       for m, s, c in zip(val_m, s_v, c_v)})
        out["n_val"] = int(c_v.sum())
        out["rmse_val"] = float(math.sqrt(s_v.sum() / max(out["n_val"], 1)))
        fin = np.isfinite(val.omega)
        out["rms_val"] = float(np.sqrt(np.mean(val.omega[fin] ** 2))) if fin.any() else math.nan
        out["trace"] = {
            "t": np.concatenate([m.t for m in val_m]),
            "omega": val.omega,
            "omega_hat": np.asarray(evv["omega_hat"]),
            "maneuver": np.repeat(np.arange(len(val_m)), [m.n for m in val_m]),
            "keys": [m.key for m in val_m],
            "f_n": np.concatenate([m.f_n for m in val_m]),
            "f_t": np.concatenate([m.f_t for m in val_m]),
            "tau": np.concatenate([m.tau for m in val_m]),
        }
    out["maneuver_rmse"] = m_rmse
    return ev, out


def estimates_of(p_hat, p0, free_t, mn, bnds, stderr_log, guess_notes, fixed_notes, stage):
    """Per-parameter estimates (standard errors from the refinement, or from the stages for
    parameters the refinement did not move) and the at-bound notes."""
    from .._params import _UNITS
    from ._common import PARAMETERS

    out, notes = [], []
    for n in PARAMETERS:
        v = getattr(p_hat, n)
        if n in free_t:
            i = free_t.index(n)
            lo_n, hi_n = bnds[n]
            x, lo, hi = mn.x, mn.lo, mn.hi
            at = "lower" if x[i] <= lo[i] + 1e-6 else "upper" if x[i] >= hi[i] - 1e-6 else None
            if at:
                notes.append(f"{n} at its {at} bound ({v:.4g}): the data push it outside the "
                             "physical range, or the bound is too tight (a failure)")
            out.append(ParameterEstimate(n, _UNITS[n], v, getattr(p0, n), lo_n, hi_n, True, at,
                                         float(v * stderr_log[i]), guess_notes.get(n, "")))
        else:
            se = math.nan
            at = None
            if stage is not None and n in fixed_notes and n != "beta_a":
                se = stage_stderr(stage, n)
            out.append(ParameterEstimate(n, _UNITS[n], v, getattr(p0, n), math.nan, math.nan,
                                         False, at, se, fixed_notes.get(n, "fixed (params0)")))
    if stage is not None:
        for name in stage.ls.at_bound:
            what = {"k": "k at 0.5"}.get(name, name)
            notes.append(f"limit-surface stage: {what}, the bound of its range (a failure)")
            out = [dataclasses.replace(e, at_bound="stage") if e.name == name else e for e in out]
    return out, notes


def stage_stderr(stage, n: str) -> float:
    if n in ("mu", "delta", "gamma", "beta_a"):
        return float(stage.ls.stderr.get(n, math.nan))
    if stage.presliding is not None and n in ("sigma0", "sigma_z"):
        return float(stage.presliding.stderr.get(n, math.nan))
    return math.nan
