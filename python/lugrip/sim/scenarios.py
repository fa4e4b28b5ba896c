"""The paper's experiments as closed-loop scenarios: YAML loading, runner, baselines, metrics and
pass criteria (docs/model.md 10). The file format and loader live in
:mod:`lugrip.sim.scenario_file`, the metrics in :mod:`lugrip.sim.metrics`, the judging in
:mod:`lugrip.sim.judge`; this module runs a scenario on a plant with its baselines and
re-exports the rest.

A scenario file (``scenarios/<name>.yaml``) holds::

    name: exp1_big_resin_block
    title: ...                       # one line
    figure: 11                       # the paper's figure it reproduces
    group: null                      # scenarios sharing one figure (exp4 full + empty)
    description: ...                 # what is shown
    choices: {...}                   # documented choice of mass, geometry, loads (free mapping)
    duration: 22.0                   # [s]
    plant: {...}                     # PlantConfig.from_dict layout (object, lift, disturbances);
                                     # contact: a preset, a mapping or a parameter file
                                     # (fit.yaml of lugrip identify; relative: next to the
                                     # scenario, else the shipped objects/)
    controller: {...}                # GraspController settings
    observer: {...}                  # Observer settings
    estimator: {patch: {...}}        # per plant model: contact parameters of observers + controller
                                     # (estimator_params forms; a model not listed: the plant's)
    schedule: [{time: 11.5, action: pivot}]
    hold_start: null                 # [s] default: start of the first gripper move (the lift)
    steady_window: [10.0, 13.9]      # [s] where the steady force is measured
    criteria: {...}                  # see CRITERIA
    baselines: {constant_force: true, friction_cone: true}
    short: {...}                     # overrides for --short (top-level keys; plant merged)
    faults: {inject: [...], ...}     # injected sensor/actuator faults (lugrip.sim.faults)
    known_limits: {mujoco: "why"}    # plant -> why the scenario is known to fail there (demo)
    <engine>: {...}                  # a registered engine's own block (mujoco: see SceneSpec)

Slip and rotation are measured in the *hold* phases: from ``hold_start`` (by default the start of
the lift, so the lift-off, where the load arrives, counts) to the end, minus the pivoting
manoeuvre; after a pivot the reference pose is the one at its end. The slip and rotation of the
lift itself (lift start to lift end) are also reported on their own.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from .. import __version__
from .._controller import controller_settings
from .._params import ContactParams  # noqa: F401  (part of this module's namespace before the split)
from ._closed_loop import ClosedLoopRun
from ._plant import PlantConfig
from .plant import make_plant
from .runner import run_plant_loop

# the loader, the metrics and the judge (lugrip.sim.scenarios stays the public name of all three)
from .judge import _criterion, _evaluate, _survives, evaluate_cross  # noqa: F401
from .metrics import compute_metrics  # noqa: F401
from .scenario_file import (  # noqa: F401
    CRITERIA,
    GRIPPER_RANGE,
    PLANT_MODELS,
    SUITES,
    _merge,
    Scenario,
    disturbance_reserve,
    expand_disturbances,
    find_scenario,
    list_scenarios,
    load_scenario,
    scenario_dir,
)

__all__ = [
    "CRITERIA",
    "PLANT_MODELS",
    "Scenario",
    "ScenarioResult",
    "compute_metrics",
    "constant_force_search",
    "evaluate_cross",
    "expand_disturbances",
    "find_scenario",
    "list_scenarios",
    "load_scenario",
    "metrics_document",
    "run_scenario",
    "scenario_dir",
    "simulate",
]


def simulate(
    scenario: Scenario,
    cfg: PlantConfig,
    model: str,
    schedule,
    *,
    kind: str = "lugrip",
    frame_callback=None,
    **options,
) -> ClosedLoopRun:
    """One closed-loop run of `scenario` on the registered plant `model`
    (:func:`lugrip.sim.runner.run_plant_loop` on :func:`lugrip.sim.plant.make_plant`'s plant,
    `frame_callback` among its options) with controller `kind`."""
    est = scenario.estimator_for(model)
    if scenario.faults:
        options = dict(
            options,
            faults=scenario.faults["inject"],
            stuck_samples=scenario.faults.get("stuck_samples", 0),
            healthy_finger_fallback=scenario.faults.get("healthy_finger_fallback", False),
        )
    plant = make_plant(model, **({} if frame_callback is None else
                                 {"frame_callback": frame_callback}))
    return run_plant_loop(
        plant,
        scenario,
        cfg,
        scenario.controller,
        scenario.observer,
        schedule,
        scenario.duration,
        kind=kind,
        estimator=est,
        **options,
    )


def constant_force_search(
    scenario: Scenario,
    cfg: PlantConfig,
    *,
    start: float,
    reference: Mapping[str, Any] | None = None,
    tolerance: float = 0.01,
    f_max: float | None = None,
    max_runs: int = 24,
    model: str | None = None,
) -> dict[str, Any]:
    """Minimum constant grasp force [N] with which the scenario (without pivoting) is survived
    (:func:`_survives`, compared with the `reference` metrics), by bisection on log(force) to a
    relative `tolerance`, starting from `start` [N].

    Returns {force, run, metrics, history: [[force, survived], ...], found}. ``force`` is the
    smallest surviving force tried (None when even f_max fails).
    """
    if f_max is None:
        f_max = scenario.controller.get("f_max", controller_settings()["f_max"])
    f_max = float(f_max)
    history: list[list[Any]] = []
    cache: dict[float, tuple[bool, ClosedLoopRun, dict]] = {}

    def attempt(f: float):
        if f not in cache:
            run = simulate(
                scenario, cfg, model or cfg.model, None, kind="constant_force", constant_force=f
            )
            m = compute_metrics(scenario, run, cfg=cfg, pivot=False)
            ok = _survives(scenario, m, reference)
            history.append([f, ok])
            cache[f] = (ok, run, m)
        return cache[f]

    hi = f_max
    if not attempt(hi)[0]:
        return {
            "force": None,
            "run": cache[hi][1],
            "metrics": cache[hi][2],
            "history": history,
            "found": False,
        }
    lo = min(max(start, 1e-3), hi)
    while attempt(lo)[0] and len(history) < max_runs:
        hi, lo = lo, lo / 2.0
    while hi / lo > 1.0 + tolerance and len(history) < max_runs:
        mid = math.sqrt(lo * hi)
        if attempt(mid)[0]:
            hi = mid
        else:
            lo = mid
    _, run, m = cache[hi]
    return {"force": hi, "run": run, "metrics": m, "history": history, "found": True}


@dataclasses.dataclass
class ScenarioResult:
    """Runs, metrics and criteria of one scenario.

    runs/metrics keys: ``lugrip``, ``lugrip_no_pivot`` (scenarios with a pivot), ``constant_force``
    and ``friction_cone`` (when enabled). criteria: name -> {value, limit, pass} (pass None when
    not evaluated, e.g. a cross-scenario ratio without its reference).
    """

    scenario: Scenario
    plant_model: str
    short: bool
    runs: dict[str, ClosedLoopRun]
    metrics: dict[str, dict[str, Any]]
    search: dict[str, Any] | None
    criteria: dict[str, dict[str, Any]]
    elapsed: float

    @property
    def name(self) -> str:
        return self.scenario.name

    @property
    def passed(self) -> bool:
        return all(c["pass"] is not False for c in self.criteria.values())

    def to_json(self) -> dict[str, Any]:
        s = self.scenario
        search = None
        if self.search is not None:
            search = {k: v for k, v in self.search.items() if k not in ("run", "metrics")}
        return {
            "title": s.title,
            "figure": s.figure,
            "source": str(s.source) if s.source else None,
            "plant_model": self.plant_model,
            "short": self.short,
            "duration": s.duration,
            "pass": self.passed,
            "criteria": self.criteria,
            "metrics": self.metrics,
            "constant_force_search": search,
            "choices": s.choices,
            "elapsed_s": self.elapsed,
        }


def run_scenario(
    scenario: Scenario | str | Path,
    *,
    plant_model: str | None = None,
    short: bool = False,
    baselines: bool = True,
    seed: int | None = None,
    frame_callback=None,
) -> ScenarioResult:
    """Run a scenario with lugrip's controller and (optionally) the baselines.

    Args:
        scenario: a Scenario, a name or a YAML path.
        plant_model: "patch" (default of the files), "lumped" (faster; no translational slip)
            or "mujoco" (the MuJoCo gripper of the file's ``mujoco`` block; the criteria of
            ``criteria_by_plant.mujoco`` when given).
        short: apply the scenario's ``short`` overrides and a coarser constant-force search (5 %
            instead of 1 %), for CI.
        baselines: also run the constant-force search and the friction-cone baseline (as the
            scenario's ``baselines`` block enables them; both without the pivoting schedule).
        seed: override the plant's noise seed.
        frame_callback: MuJoCo plant: f(model, data, t) at every sensor sample of lugrip's
            run (rendering frames).
    """
    t_start = time.perf_counter()
    scn = scenario if isinstance(scenario, Scenario) else load_scenario(scenario)
    if short:
        scn = scn.shortened()
    model = scn.plant_model(plant_model)
    scn = scn.for_plant(model)
    cfg = scn.plant_config(model, seed)
    runs: dict[str, ClosedLoopRun] = {}
    metrics: dict[str, dict] = {}
    runs["lugrip"] = simulate(scn, cfg, model, scn.schedule, frame_callback=frame_callback)
    metrics["lugrip"] = compute_metrics(scn, runs["lugrip"], cfg=cfg)
    if scn.has_pivot:
        runs["lugrip_no_pivot"] = simulate(scn, cfg, model, None)
        metrics["lugrip_no_pivot"] = compute_metrics(
            scn, runs["lugrip_no_pivot"], cfg=cfg, pivot=False
        )
    search = None
    if baselines and scn.baselines.get("constant_force", True):
        steady = metrics.get("lugrip_no_pivot", metrics["lugrip"]).get("steady_force") or 1.0
        reference = metrics.get("lugrip_no_pivot", metrics["lugrip"])
        search = constant_force_search(
            scn,
            cfg,
            start=0.5 * steady,
            reference=reference,
            tolerance=0.05 if short else 0.01,
            model=model,
        )
        runs["constant_force"] = search["run"]
        metrics["constant_force"] = dict(search["metrics"], constant_force=search["force"])
    if baselines and scn.baselines.get("friction_cone", True):
        cone = scn.baselines.get("friction_cone")
        opts = dict(cone) if isinstance(cone, Mapping) else {}
        runs["friction_cone"] = simulate(scn, cfg, model, None, kind="friction_cone", **opts)
        metrics["friction_cone"] = compute_metrics(scn, runs["friction_cone"], cfg=cfg, pivot=False)
    criteria = _evaluate(scn, metrics, search)
    return ScenarioResult(
        scn, model, short, runs, metrics, search, criteria, time.perf_counter() - t_start
    )


def metrics_document(results: Sequence[ScenarioResult]) -> dict[str, Any]:
    """The metrics.json content: per scenario its metrics and a pass flag per criterion."""
    scenarios = {r.name: r.to_json() for r in results}
    return {
        "lugrip_version": __version__,
        "criteria_meaning": CRITERIA,
        "scenarios": scenarios,
        "pass": all(s["pass"] for s in scenarios.values()),
    }
