"""The identification result: parameter table, summary, YAML."""

from __future__ import annotations

import dataclasses
import math
import os
from pathlib import Path

import numpy as np

from .._observer import Observer
from .._params import ContactParams


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
        status: "converged", "max_iterations" or "failed"; success: status == "converged".
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
            omega_hat, maneuver index) or None.
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

    @property
    def success(self) -> bool:
        return self.status == "converged"

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
        for e in self.estimates:
            if e.name == name:
                return e
        raise KeyError(name)

    def table(self) -> str:
        """Plain-text parameter table: value, unit, bounds, standard error, start."""
        head = (
            f"{'parameter':10s} {'value':>12s} {'std.err':>10s} {'rel':>7s}  "
            f"{'bounds':>23s} {'start':>12s}  unit"
        )
        lines = [head, "-" * len(head)]
        for e in self.estimates:
            if e.free:
                se = f"{e.stderr:10.3g}" if math.isfinite(e.stderr) else f"{'n/a':>10s}"
                rel = f"{100 * e.relative_stderr:6.2f}%" if math.isfinite(e.stderr) else f"{'':>7s}"
                bnd = f"[{e.lower:.3g}, {e.upper:.3g}]"
                if e.at_bound:
                    bnd = f"{e.at_bound.upper()} {bnd}"
            else:
                se, rel, bnd = f"{'fixed':>10s}", f"{'':>7s}", ""
            lines.append(
                f"{e.name:10s} {e.value:12.6g} {se} {rel}  {bnd:>23s} {e.initial:12.6g}  {e.unit}"
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
                },
                "c_max": {"value": self.params.c_max, "unit": "-"},
            },
            # the observer inside the cost: the parameters are identified FOR it (MODEL.md
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
                "truncated_gradient_samples": self.truncated,
                "saturated_samples_unscored": self.samples_saturated,
                "settings": self.settings,
            },
        }

    def save_yaml(self, path: str | Path) -> Path:
        """Write the identified parameters with units, standard errors, bounds, the
        ``observer:`` block (the settings of the observer inside the cost) and the fit
        summary. :meth:`lugrip.ContactParams.from_yaml` reads the parameters back (the
        ``contact`` block), :func:`lugrip.read_observer_settings` the observer block;
        ``lugrip observe --params`` and ``lugrip identify --params0`` use both."""
        import yaml

        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        text = (
            "# lugrip identification (paper Section 4, MODEL.md 8): contact parameters\n"
            "# value [unit], standard error, bounds; the observer they were identified with\n"
            "# (use it online: lugrip observe --params reads the observer block); fit summary\n"
            + yaml.safe_dump(_plain(self.to_dict()), sort_keys=False)
        )
        tmp = path.with_name(path.name + ".tmp")
        tmp.write_text(text)
        os.replace(tmp, path)
        return path


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
