"""The paper's experiments as closed-loop scenarios: YAML loading, runner, baselines, metrics and
pass criteria (docs/model.md 10).

A scenario file (``scenarios/<name>.yaml``) holds::

    name: exp1_big_resin_block
    title: ...                       # one line
    figure: 11                       # the paper's figure it reproduces
    group: null                      # scenarios sharing one figure (exp4 full + empty)
    description: ...                 # what is shown
    choices: {...}                   # documented choice of mass, geometry, loads (free mapping)
    duration: 22.0                   # [s]
    plant: {...}                     # PlantConfig.from_dict layout (object, lift, disturbances)
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

Slip and rotation are measured in the *hold* phases: from ``hold_start`` (by default the start of
the lift, so the lift-off, where the load arrives, counts) to the end, minus the pivoting
manoeuvre; after a pivot the reference pose is the one at its end. The slip and rotation of the
lift itself (lift start to lift end) are also reported on their own.
"""

from __future__ import annotations

import copy
import dataclasses
import math
import os
import time
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from .. import __version__
from .._controller import controller_settings, static_grasp_force
from .._params import ContactParams
from .._yaml import load_yaml, to_number
from . import faults as _faults
from ._closed_loop import ClosedLoopRun, estimator_params, run_closed_loop
from ._plant import PlantConfig
from .plant import plant_names, registered

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

#: Controller settings every scenario states: the gripper's force range [N] and rate limits [N/s].
GRIPPER_RANGE = ("f_min", "f_max", "max_rate_up", "max_rate_down")

#: Criteria a scenario may list, with their meaning (value compared with the YAML limit).
CRITERIA = {
    "no_drop": "the object is never dropped (plant drop criteria: slip, rotation, contact)",
    "no_nan": "every logged value is finite",
    "command_in_limits": "the command stays finite and inside [f_min, f_max]",
    "max_hold_slip_mm": (
        "max translational slip while holding, from the lift start (lift-off and disturbances "
        "included) [mm] <= limit"
    ),
    "max_hold_rotation_deg": (
        "max rotational slip while holding, from the lift start (lift-off and disturbances "
        "included) [deg] <= limit"
    ),
    "steady_slippage": "mean S in the steady window inside [lo, hi]",
    "steady_force_range": "steady grasp force inside [lo, hi] [N] (the paper's range)",
    "static_force_tolerance": "|steady / static_grasp_force - 1| <= limit",
    "pivot_final_hang_deg": (
        "after pivoting the CoG hangs below the grasp point within limit [deg] (at the end, or "
        "before a wrist roll tilts the held object)"
    ),
    "pivot_returns_to_avoidance": "pivoting ends on |c~| > threshold and avoidance resumes",
    "force_ratio": "steady force / steady force of `reference` >= min",
    "constant_force_exceeds_steady": "the constant-force baseline needs more than lugrip's steady force",
    "friction_cone_fails": "the friction-cone baseline fails (drop or hold slip) where lugrip holds",
    "scene_ok": (
        "the scene itself worked: both pads reached the object and kept contact (MuJoCo plant; "
        "the status names the fault: object_not_reached, closed_on_nothing, lost_contact)"
    ),
    "max_steady_command_ptp": (
        "peak-to-peak of the command in the steady window / its mean <= limit (no sustained "
        "oscillation)"
    ),
    "mean_force_below_constant": (
        "mean grip force from the lift start on < the smallest constant force that survives "
        "the scenario (bisection)"
    ),
    **_faults.FAULT_CRITERIA,
}


def scenario_dir() -> Path | None:
    """Directory of the bundled scenario files: $LUGRIP_SCENARIOS, ./scenarios, or the
    scenarios shipped with lugrip (the installed copy, or the repository's scenarios/ next to
    an in-tree package). None when none exists."""
    from .._data import data_dir

    env = os.environ.get("LUGRIP_SCENARIOS")
    candidates = [Path(env)] if env else []
    candidates += [Path.cwd() / "scenarios", data_dir("scenarios")]
    for c in candidates:
        if c is not None and c.is_dir() and any(c.glob("*.yaml")):
            return c
    return None


def list_scenarios(directory: str | Path | None = None, suite: str = "paper") -> list[str]:
    """Names of the scenario files in `directory` (default: :func:`scenario_dir`), sorted:
    suite "paper" the files in it, "unseen" those in its unseen/ folder, "all" both."""
    d = Path(directory) if directory is not None else scenario_dir()
    if d is None:
        return []
    if suite not in (*SUITES, "all"):
        raise ValueError(f"suite {suite!r}: expected paper, unseen or all")
    names = []
    if suite in ("paper", "all"):
        names += sorted(p.stem for p in d.glob("*.yaml"))
    if suite in ("unseen", "all"):
        names += sorted(p.stem for p in (d / "unseen").glob("*.yaml"))
    if suite == "faults":
        names += sorted(p.stem for p in (d / "faults").glob("*.yaml"))
    return names


def find_scenario(name: str | Path) -> Path:
    """Path of a scenario given as a file path or a name in :func:`scenario_dir` (or its
    unseen/ folder)."""
    p = Path(name)
    if p.suffix in (".yaml", ".yml") or p.exists():
        if not p.is_file():
            raise ValueError(f"scenario file {p} does not exist")
        return p
    d = scenario_dir()
    if d is not None:
        for cand in (d / f"{name}.yaml", d / "unseen" / f"{name}.yaml", d / "faults" / f"{name}.yaml"):
            if cand.is_file():
                return cand
    known = ", ".join(list_scenarios(suite="all")) or "none found (set LUGRIP_SCENARIOS)"
    raise ValueError(f"unknown scenario {str(name)!r}; known: {known}")


def _merge(base: dict, over: Mapping) -> dict:
    out = copy.deepcopy(base)
    for k, v in over.items():
        if k == "plant" and isinstance(v, Mapping):
            plant = dict(out.get("plant", {}))
            plant.update(copy.deepcopy(dict(v)))
            out["plant"] = plant
        else:
            out[k] = copy.deepcopy(v)
    return out


_KEYS = {
    "name",
    "title",
    "figure",
    "group",
    "description",
    "choices",
    "duration",
    "plant",
    "controller",
    "observer",
    "estimator",
    "schedule",
    "hold_start",
    "steady_window",
    "criteria",
    "baselines",
    "short",
    "suite",
    "mujoco",
    "criteria_by_plant",
    "faults",
}

#: Plant models a scenario runs on: the two of lugrip's own simulator and MuJoCo's gripper.
PLANT_MODELS = ("patch", "lumped", "mujoco")
#: Scenario sets: the paper's experiments (scenarios/*.yaml) and objects the controller was not
#: tuned on (scenarios/unseen/*.yaml).
SUITES = ("paper", "unseen", "faults")


@dataclasses.dataclass
class Scenario:
    """One experiment (see the module docstring for the YAML layout)."""

    name: str
    title: str
    duration: float
    plant: dict
    figure: int | None = None
    group: str | None = None
    description: str = ""
    choices: dict = dataclasses.field(default_factory=dict)
    controller: dict = dataclasses.field(default_factory=dict)
    observer: dict = dataclasses.field(default_factory=dict)
    estimator: dict = dataclasses.field(default_factory=dict)
    schedule: list = dataclasses.field(default_factory=list)
    hold_start: float | None = None
    steady_window: tuple[float, float] | None = None
    criteria: dict = dataclasses.field(default_factory=dict)
    baselines: dict = dataclasses.field(default_factory=dict)
    short: dict = dataclasses.field(default_factory=dict)
    suite: str = "paper"
    mujoco: dict = dataclasses.field(default_factory=dict)
    criteria_by_plant: dict = dataclasses.field(default_factory=dict)
    faults: dict = dataclasses.field(default_factory=dict)
    source: Path | None = None
    #: the standing reserve's derivation (controller ``reserve: disturbances``), else empty
    reserve: dict = dataclasses.field(default_factory=dict)

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], source: Path | None = None) -> Scenario:
        where = str(source) if source else "scenario"
        if not isinstance(data, Mapping):
            raise ValueError(f"{where}: expected a mapping at the top level")  # noqa: TRY004 (file content)
        unknown = sorted(set(data) - _KEYS)
        if unknown:
            raise ValueError(f"{where}: unknown key(s) {', '.join(unknown)}")
        for key in ("name", "title", "duration", "plant"):
            if key not in data:
                raise ValueError(f"{where}: missing key {key!r}")
        # The gripper's range is the user's, never a library default (a silent cap).
        missing = [k for k in GRIPPER_RANGE if k not in (data.get("controller") or {})]
        if missing:
            raise ValueError(
                f"{where}: controller: the gripper's range must be given ({', '.join(missing)} "
                "missing)"
            )
        by_plant = dict(data.get("criteria_by_plant") or {})
        for crit in [data.get("criteria") or {}, *by_plant.values()]:
            unknown = sorted(set(crit) - set(CRITERIA))
            if unknown:
                raise ValueError(f"{where}: unknown criteria {', '.join(unknown)}")
        if not set(by_plant) <= set(plant_names()):
            raise ValueError(
                f"{where}: criteria_by_plant: keys must be among {', '.join(PLANT_MODELS)}"
            )
        plant = data["plant"]
        if not isinstance(plant, Mapping):
            raise ValueError(f"{where}: plant: expected a mapping (model: patch | lumped | mujoco, ...)")  # noqa: TRY004 (file content)
        model = plant.get("model", "patch")
        if not isinstance(model, str) or model not in plant_names():
            raise ValueError(f"{where}: plant.model: must be one of {', '.join(PLANT_MODELS)}")
        sw = data.get("steady_window")
        if sw is not None and (not isinstance(sw, Sequence) or isinstance(sw, str) or len(sw) != 2):
            raise ValueError(f"{where}: steady_window: expected [start, end] in seconds")
        s = cls(
            name=str(data["name"]),
            title=str(data["title"]),
            duration=to_number(data["duration"], f"{where}: duration"),
            plant=dict(data["plant"]),
            figure=data.get("figure"),
            group=data.get("group"),
            description=str(data.get("description") or "").strip(),
            choices=dict(data.get("choices") or {}),
            controller=dict(data.get("controller") or {}),
            observer=dict(data.get("observer") or {}),
            estimator=_estimator_block(data.get("estimator"), where),
            schedule=list(data.get("schedule") or []),
            hold_start=(None if data.get("hold_start") is None
                        else to_number(data["hold_start"], f"{where}: hold_start")),
            steady_window=None if sw is None else (to_number(sw[0], f"{where}: steady_window[0]"),
                                                    to_number(sw[1], f"{where}: steady_window[1]")),
            criteria=dict(data.get("criteria") or {}),
            baselines=dict(data.get("baselines") or {}),
            short=dict(data.get("short") or {}),
            suite=str(data.get("suite") or "paper"),
            mujoco=dict(data.get("mujoco") or {}),
            criteria_by_plant={str(k): dict(v) for k, v in by_plant.items()},
            faults=_faults.fault_block(data.get("faults"), where),
            source=source,
        )
        if s.suite not in SUITES:
            raise ValueError(f"{where}: suite {s.suite!r}: expected one of {', '.join(SUITES)}")
        reserve = s.controller.pop("reserve", None)
        if reserve is not None:
            if reserve != "disturbances":
                raise ValueError(
                    f"{where}: controller.reserve: {reserve!r}: the only rule is 'disturbances' "
                    "(or give reserve_force / reserve_torque)"
                )
            crit = s.criteria_by_plant.get("mujoco", s.criteria)
            ratio = int(s.controller.get("command_ratio", 10))
            rate = float(s.controller.get("sensor_rate", 500.0))
            est = s.estimator_for("mujoco") if "mujoco" in s.estimator else s.estimator_for(
                s.plant_model()
            )
            plant_contact = s.plant_config().contact
            contact = estimator_params(plant_contact, est) or plant_contact
            s.reserve = disturbance_reserve(
                s.plant,
                crit,
                ratio / rate,
                contact=contact,
                rate_up=float(s.controller.get("max_rate_up", math.inf)),
            )
            for key in ("reserve_force", "reserve_torque"):
                s.controller.setdefault(key, s.reserve[key])
        s.plant_config()  # validates the plant block now, naming bad fields
        if s.mujoco:
            s.scene_spec()  # and the MuJoCo scene
        for m in s.estimator:
            s.estimator_for(m)  # and that parameter files exist
        return s

    def to_dict(self) -> dict:
        d = dataclasses.asdict(self)
        d.pop("source")
        d.pop("reserve")
        if d["steady_window"] is not None:
            d["steady_window"] = list(d["steady_window"])
        return d

    def shortened(self) -> Scenario:
        """The scenario with its ``short`` overrides applied (for CI)."""
        if not self.short:
            return self
        return Scenario.from_dict(_merge(self.to_dict() | {"short": {}}, self.short), self.source)

    def for_plant(self, model: str) -> Scenario:
        """The scenario with the criteria of plant `model` (``criteria_by_plant``, replacing
        ``criteria`` when given)."""
        if model not in self.criteria_by_plant:
            return self
        return dataclasses.replace(self, criteria=dict(self.criteria_by_plant[model]))

    def plant_model(self, model: str | None = None) -> str:
        """The plant model a run uses: `model`, else the file's ``plant.model`` (patch)."""
        m = str(model if model is not None else self.plant.get("model", "patch"))
        if m not in plant_names():
            raise ValueError(f"plant model {m!r}: expected one of {', '.join(plant_names())}")
        return m

    def plant_config(self, model: str | None = None, seed: int | None = None) -> PlantConfig:
        """The plant block as a PlantConfig. For the MuJoCo plant the same block (object,
        contact, actuator, sensors, moves, disturbances, drop limits) with model "patch": the
        MuJoCo scene reads what it needs from it and :meth:`scene_spec` adds the rest."""
        d = copy.deepcopy(self.plant)
        if model is not None:
            d["model"] = model
        if registered(str(d.get("model", "patch"))):  # an engine reads its scene itself
            d["model"] = "patch"
        if seed is not None:
            d["seed"] = int(seed)
        d["disturbances"] = expand_disturbances(d.get("disturbances") or [])
        return PlantConfig.from_dict(d)

    def scene_spec(self):
        """The MuJoCo scene of the ``mujoco:`` block (:class:`lugrip.sim.mujoco.SceneSpec`)."""
        if not self.mujoco:
            raise ValueError(
                f"scenario {self.name}: no 'mujoco' block (object shape and size), so it cannot "
                "run on the MuJoCo plant"
            )
        from .mujoco.gripper import SceneSpec

        return SceneSpec.from_dict(self.mujoco)

    @property
    def lift_end(self) -> float:
        """End of the lift, the first gripper move [s] (0 without moves); later moves (a wrist
        move after the pushes) belong to the hold."""
        cfg = self.plant_config()
        if not cfg.moves:
            return 0.0
        first = min(cfg.moves, key=lambda m: m.t_start)
        return first.t_start + first.duration

    @property
    def lift_start(self) -> float:
        cfg = self.plant_config()
        return min((m.t_start for m in cfg.moves), default=0.0)

    @property
    def hold_time(self) -> float:
        """Start of the first hold phase [s]: ``hold_start`` or the start of the lift."""
        return self.lift_start if self.hold_start is None else self.hold_start

    def estimator_for(self, model: str) -> Any:
        """What the observers and the controller believe about the contact with this plant model
        (``estimator_params`` forms), or None: the plant's own parameters. A relative parameter
        file (``mujoco/box.yaml``) names a file next to the scenario, else one of the shipped
        objects (``objects/mujoco/box.yaml``, written by ``lugrip identify``)."""
        value = self.estimator.get(model)
        if isinstance(value, str) and Path(value).suffix.lower() in (".yaml", ".yml"):
            return _estimator_file(value, self.source)
        return value

    @property
    def has_pivot(self) -> bool:
        return any(str(e.get("action", "")).startswith("pivot") for e in self.schedule)

    @property
    def params(self) -> ContactParams:
        return self.plant_config().contact


def _estimator_file(name: str, source: Path | None) -> Path:
    """The parameter file `name` of an estimator block: as given when absolute, else next to
    the scenario file `source`, else in the shipped objects directory."""
    from .._data import data_dir

    p = Path(name)
    if p.is_absolute():
        return p
    candidates = [] if source is None else [Path(source).parent / p]
    objects = data_dir("objects")
    candidates += [] if objects is None else [objects / p]
    for c in candidates:
        if c.is_file():
            return c
    where = ", ".join(str(c.parent) for c in candidates) or "no scenario or objects directory"
    raise ValueError(f"estimator parameter file {name!r} not found (looked in {where})")


def _estimator_block(value: Any, where: str) -> dict:
    """The ``estimator`` block: a mapping from plant model (patch, lumped) to the contact
    parameters the estimator side uses with that plant."""
    if value is None:
        return {}
    if not isinstance(value, Mapping) or not set(value) <= set(plant_names()):
        raise ValueError(
            f"{where}: estimator: expected a mapping with keys among {', '.join(PLANT_MODELS)}"
        )
    return {str(k): copy.deepcopy(v) for k, v in value.items()}


def expand_disturbances(items: Sequence[Mapping[str, Any]]) -> list[dict]:
    """The plant's pulse list with every ``shape: trapezoid`` pulse (rise and fall over
    ``edge`` [s], flat in between) written as the plant's own shapes: a ramp up over the rising
    edge, a rectangle from its end to the pulse end, and a negative ramp over the falling edge
    (they add up to the trapezoid exactly)."""
    out = []
    for k, q in enumerate(items):
        q = dict(q)
        if str(q.get("shape", "")).lower() != "trapezoid":
            if "edge" in q:
                raise ValueError(f"disturbances[{k}]: 'edge' is only for shape trapezoid")
            out.append(q)
            continue
        edge = float(q.pop("edge", 0.02))
        t0, dur = float(q.get("t_start", 0.0)), float(q.get("duration", 0.1))
        if not (edge > 0.0 and 2.0 * edge <= dur):
            raise ValueError(f"disturbances[{k}]: trapezoid edge {edge} must be in (0, duration/2]")
        force = [float(v) for v in q.get("force", (0.0, 0.0))]
        torque = float(q.get("torque", 0.0))
        base = {key: v for key, v in q.items() if key not in ("shape", "t_start", "duration")}
        neg = dict(base, force=[-force[0], -force[1]], torque=-torque)
        out += [
            dict(base, shape="ramp", t_start=t0, duration=edge),
            dict(base, shape="rectangular", t_start=t0 + edge, duration=dur - edge),
            dict(neg, shape="ramp", t_start=t0 + dur - edge, duration=edge),
        ]
    return out


def disturbance_reserve(
    plant: Mapping[str, Any],
    criteria: Mapping[str, Any],
    command_period: float = 0.02,
    *,
    contact: ContactParams | None = None,
    rate_up: float = math.inf,
) -> dict[str, Any]:
    """Per-finger standing reserve (``reserve_force`` [N], ``reserve_torque`` [N m]) for the
    scenario's pulses: the largest rise of the load's magnitude any one pulse causes (force
    against the weight, torque about the grasp point), less what the object may take before the
    reaction arrives without leaving the slip budget (docs/controller.md §8).

    The allowance is the excess that moves the free object by the budget within the reaction
    time t_r: 2 m x_max / t_r^2 for the force and 2 I_grasp theta_max / t_r^2 for the torque
    (I_grasp = I + m |cog|^2), both split over the two fingers. t_r is one command period plus the
    actuator's time constant, plus, with `contact` and a finite `rate_up` [N/s], the time the
    rate limit takes from the reserve's force to the force the whole pulse needs (static grasp
    forces of `contact` at S = 1 for the per-finger loads; t_r and the reserve are solved
    together). Wrist moves are slow and left to the feedback.
    """
    g = 9.81
    obj = plant.get("object") or {}
    m = float(obj.get("mass", 0.0))
    inertia = float(obj.get("inertia", 0.0))
    cog = [float(v) for v in obj.get("cog", (0.0, 0.0))]
    t_0 = float(command_period) + float((plant.get("actuator") or {}).get("time_constant", 0.0))
    x_max = float(criteria.get("max_hold_slip_mm", 1.0)) * 1e-3
    th_max = math.radians(float(criteria.get("max_hold_rotation_deg", 1.0)))
    i_grasp = inertia + m * (cog[0] ** 2 + cog[1] ** 2)
    weight = (0.0, -m * g)
    tau_g = cog[0] * weight[1] - cog[1] * weight[0]  # about the grasp point
    d_force = d_torque = 0.0
    for q in plant.get("disturbances") or []:
        f = [float(v) for v in q.get("force", (0.0, 0.0))]
        pt = [float(v) for v in q.get("point", (0.0, 0.0))]
        r = (cog[0] + pt[0], cog[1] + pt[1])
        tau = float(q.get("torque", 0.0)) + r[0] * f[1] - r[1] * f[0]
        d_force = max(d_force, math.hypot(weight[0] + f[0], weight[1] + f[1]) - abs(weight[1]))
        d_torque = max(d_torque, abs(tau_g + tau) - abs(tau_g))

    def allowances(t_r: float) -> tuple[float, float]:
        return 2.0 * m * x_max / t_r**2, 2.0 * i_grasp * th_max / t_r**2

    def reserve(t_r: float) -> tuple[float, float]:
        allow_f, allow_t = allowances(t_r)
        return max(0.0, 0.5 * (d_force - allow_f)), max(0.0, 0.5 * (d_torque - allow_t))

    load_f, load_t = 0.5 * m * g, 0.5 * abs(tau_g)  # per finger
    ramp = 0.0
    t_r = t_0
    if t_0 > 0 and contact is not None and math.isfinite(rate_up) and (d_force > 0 or d_torque > 0):

        def force(df: float, dt: float) -> float:
            return static_grasp_force(contact, load_f + df, load_t + dt, 1.0)

        # the forces the whole push needs (fixed; only the reserve's force moves with t)
        full_f, full_t = force(0.5 * d_force, 0.0), force(0.0, 0.5 * d_torque)

        def excess(t: float) -> float:
            # reaction time the ramp adds at t minus what t already assumes (decreasing in t)
            rf, rt = reserve(t)
            step = max(full_f - force(rf, 0.0), full_t - force(0.0, rt), 0.0)
            return t_0 + step / rate_up - t

        lo, hi = t_0, t_0 + max(full_f, full_t) / rate_up
        if excess(lo) > 0.0:
            for _ in range(60):  # bisection: the step shrinks as t (and the reserve) grows
                mid = 0.5 * (lo + hi)
                lo, hi = (mid, hi) if excess(mid) > 0.0 else (lo, mid)
            t_r = hi
        ramp = t_r - t_0
    rf, rt = reserve(t_r) if t_r > 0 else (0.5 * d_force, 0.5 * d_torque)
    allow_f, allow_t = allowances(t_r) if t_r > 0 else (0.0, 0.0)
    t_r, ramp, rf, rt = float(t_r), float(ramp), float(rf), float(rt)
    return {
        "reserve_force": rf,
        "reserve_torque": rt,
        "largest_force_rise": d_force,
        "largest_torque_rise": d_torque,
        "allowance_force": float(allow_f),
        "allowance_torque": float(allow_t),
        "reaction_time": t_r,
        "ramp_time": ramp,
    }


def load_scenario(name: str | Path) -> Scenario:
    """Load a scenario from a YAML file or by name (``exp1_big_resin_block``)."""
    path = find_scenario(name)
    return Scenario.from_dict(load_yaml(path), source=path)


# --- metrics ---------------------------------------------------------------------------------


def _axis_deg(run: ClosedLoopRun, cfg: PlantConfig) -> np.ndarray:
    """Angle of the object's grasp-point -> CoG axis (object frame, fixed) from the downward
    vertical [deg], wrapped to (-180, 180]."""
    cx, cy = cfg.object.cog
    a = np.degrees(run["theta"] + math.atan2(cy, cx)) + 90.0
    return (a + 180.0) % 360.0 - 180.0


def _hold_increment(run: ClosedLoopRun, phases, lumped: bool) -> tuple[float, float]:
    """Max slip [mm] and rotation [deg] relative to the pose at each phase start."""
    slip = rot = 0.0
    for t0, t1 in phases:
        sl = run.window(t0, t1)
        if sl.stop <= sl.start:
            continue
        i0 = sl.start
        if lumped:
            ds = run["slip"][sl] - run["slip"][i0]
        else:
            ds = np.hypot(
                run["slip_x"][sl] - run["slip_x"][i0], run["slip_y"][sl] - run["slip_y"][i0]
            )
        slip = max(slip, float(np.max(np.abs(ds))) * 1e3)
        rot = max(rot, float(np.degrees(np.max(np.abs(run["rotation"][sl] - run["rotation"][i0])))))
    return slip, rot


def compute_metrics(
    scenario: Scenario,
    run: ClosedLoopRun,
    *,
    cfg: PlantConfig | None = None,
    controller: Mapping[str, Any] | None = None,
    pivot: bool = True,
) -> dict[str, Any]:
    """Metrics of one run: slip and rotation (lift and hold), forces (peak, steady, static
    references), pivoting, drop, finiteness. Forces per finger [N]."""
    cfg = cfg or scenario.plant_config()
    ctrl = dict(controller if controller is not None else scenario.controller)
    defaults = controller_settings()
    f_min = float(ctrl.get("f_min", defaults["f_min"]))
    f_max = float(ctrl.get("f_max", defaults["f_max"]))
    s_ref = float(ctrl.get("s_ref", defaults["s_ref"]))
    t = run["t"]
    end = float(t[-1]) + (t[1] - t[0] if len(t) > 1 else 0.0)
    hold = scenario.hold_time
    lumped = cfg.model == "lumped"
    m: dict[str, Any] = {}

    # pivoting manoeuvre (lugrip with a pivot in the schedule)
    pivot_t = [
        float(e["time"]) for e in scenario.schedule if str(e.get("action", "")).startswith("pivot")
    ]
    pivoting = pivot and bool(pivot_t) and bool(np.any(run["mode"] == 1))
    phases = [(hold, end)]
    if pivoting:
        p0 = pivot_t[0]
        fin = np.flatnonzero(run["pivot_finished"])
        fin = fin[t[fin] >= p0]
        p1 = float(t[fin[0]]) if fin.size else math.inf
        reason = int(run["pivot_end"][fin[0]]) if fin.size else 0
        phases = [(hold, p0)] + ([(p1, end)] if math.isfinite(p1) else [])
        axis = _axis_deg(run, cfg)
        # the hang the pivot left: at the end, or before a later wrist roll (MuJoCo plant) tilts
        # the held object with the hand
        i_hang = len(t) - 1
        if "roll" in run:
            rolls = [
                float(w["t_start"])
                for w in scenario.mujoco.get("wrist") or []
                if float(w.get("roll_deg", 0.0)) != 0.0
            ]
            if rolls:
                i_hang = max(run.index(min(rolls)) - 1, 0)
        m.update(
            pivot_start=p0,
            pivot_end=p1 if math.isfinite(p1) else None,
            pivot_duration=(p1 - p0) if math.isfinite(p1) else None,
            pivot_end_reason={
                0: "none", 1: "cor_threshold", 2: "timeout", 3: "requested", 4: "at_floor"
            }[reason],
            pivot_rotation_deg=float(np.degrees(run["theta"][-1] - run["theta"][run.index(p0)])),
            final_hang_deg=float(abs(run.hang_deg[i_hang])),
            final_hang_time=float(t[i_hang]),
            final_axis_deg=float(abs(axis[-1])),
            initial_axis_deg=float(abs(axis[run.index(p0)])),
            final_mode="slipping_avoidance" if int(run["mode"][-1]) == 0 else "pivoting",
            # ended by itself (hanging: c~ criterion, or held at the floor), then avoiding again
            returned_to_avoidance=bool(fin.size and reason in (1, 4) and int(run["mode"][-1]) == 0),
        )
    hold_slip, hold_rot = _hold_increment(run, phases, lumped)
    lift_slip, lift_rot = _hold_increment(run, [(scenario.lift_start, scenario.lift_end)], lumped)
    faulty = np.asarray(run["fault_active"], dtype=bool) if "fault_active" in run else None
    finite = all(
        np.all(np.isfinite(np.asarray(v, dtype=float))[~faulty])
        if faulty is not None and k.startswith(("f_n_meas", "f_t_meas", "tau_meas"))
        else np.all(np.isfinite(np.asarray(v, dtype=float)))
        for k, v in run.items()
    )
    cmd = run["command"]
    m.update(
        dropped=bool(run["dropped"][-1]),
        drop_time=float(t[np.argmax(run["dropped"] > 0)]) if run["dropped"][-1] else None,
        max_slip_mm=float(np.max(run["slip"]) * 1e3),
        max_rotation_deg=float(np.degrees(np.max(np.abs(run["rotation"])))),
        lift_slip_mm=lift_slip,
        lift_rotation_deg=lift_rot,
        hold_slip_mm=hold_slip,
        hold_rotation_deg=hold_rot,
        hold_phases=[[a, b] for a, b in phases],
        # after the lift starts (before it the command is the initial grasp force decaying)
        peak_force=float(np.max(cmd[run.window(scenario.lift_start, end)])),
        peak_normal_force=float(np.max(run["f_n"][run.window(scenario.lift_start, end)])),
        finite=bool(finite and np.all(run["finite"])),
        command_in_limits=bool(
            np.all(np.isfinite(cmd))
            and np.all(cmd >= f_min - 1e-12)
            and np.all(cmd <= f_max + 1e-12)
        ),
    )
    if scenario.steady_window is not None:
        sw = run.window(*scenario.steady_window)
        ft = float(np.mean(0.5 * (run["f_t_true_0"][sw] + run["f_t_true_1"][sw])))
        tau = float(np.mean(0.5 * (np.abs(run["tau_true_0"][sw]) + np.abs(run["tau_true_1"][sw]))))
        static = float(static_grasp_force(cfg.contact, ft, tau, s_ref))
        minimum = float(static_grasp_force(cfg.contact, ft, tau, 1.0))
        steady = float(np.mean(cmd[sw]))
        c_tilde = 0.5 * (np.abs(run["c_tilde_0"][sw]) + np.abs(run["c_tilde_1"][sw]))
        m.update(
            steady_window=list(scenario.steady_window),
            steady_force=steady,
            steady_slippage=float(np.mean(run.S[sw])),
            steady_c_tilde=float(np.mean(c_tilde)),
            steady_f_t=ft,
            steady_tau_nmm=tau * 1e3,
            static_force=static,
            min_force=minimum,
            steady_over_static=steady / static if static > 0 else None,
            steady_over_min=steady / minimum if minimum > 0 else None,
        )
        if sw.stop > sw.start:
            ptp = float(np.ptp(cmd[sw]))
            m.update(
                steady_command_ptp=ptp,
                steady_command_ptp_ratio=ptp / steady if steady > 0 else None,
            )
    hw = run.window(scenario.lift_start, end)
    if hw.stop > hw.start:
        m["mean_force"] = float(np.mean(run["f_n"][hw]))
        err = [run[f"omega_hat_{k}"][hw] - run[f"omega_true_{k}"][hw] for k in (0, 1)]
        m["omega_rmse"] = float(np.sqrt(np.mean(np.square(err))))
        m["omega_hat_peak"] = float(
            max(np.max(np.abs(run[f"omega_hat_{k}"][hw])) for k in (0, 1))
        )
        m["omega_true_peak"] = float(
            max(np.max(np.abs(run[f"omega_true_{k}"][hw])) for k in (0, 1))
        )
    scene = getattr(run, "scene", None)
    if scene and scenario.steady_window is not None:
        # the plant's own slip force for the steady loads of each finger: MuJoCo's elliptic cone
        from .mujoco.loop import cone_slip_force

        sw = run.window(*scenario.steady_window)
        if sw.stop > sw.start:
            m["min_force_plant"] = max(
                cone_slip_force(
                    cfg.contact,
                    float(np.mean(run[f"f_t_true_{k}"][sw])),
                    float(np.mean(np.abs(run[f"tau_true_{k}"][sw]))),
                )
                for k in (0, 1)
            )
    elif "min_force" in m:
        m["min_force_plant"] = m["min_force"]  # the patch follows lugrip's limit surface
    if scenario.faults:
        m.update(_faults.fault_metrics(scenario.faults, run, cfg))
    m["scene_status"] = scene["status"] if scene else "ok"
    if scene:
        m["scene"] = dict(scene)
    return m


def _survives(
    scenario: Scenario, metrics: Mapping[str, Any], reference: Mapping[str, Any] | None = None
) -> bool:
    """The run held the object: no drop, finite, hold slip/rotation within the criteria and,
    given the `reference` run (lugrip without pivoting), a whole-run slip and rotation at most
    the reference's plus the same limits (a baseline must hold the object at least as well as
    lugrip, including the lift; otherwise a weak constant force "survives" by letting the object
    swing into a pose with less torque)."""
    c = scenario.criteria
    slip_lim = float(c.get("max_hold_slip_mm", 1.0))
    rot_lim = float(c.get("max_hold_rotation_deg", 1.0))
    ok = (
        not metrics["dropped"]
        and metrics["finite"]
        and metrics["hold_slip_mm"] <= slip_lim
        and metrics["hold_rotation_deg"] <= rot_lim
    )
    if ok and reference is not None:
        ok = (
            metrics["max_slip_mm"] <= reference["max_slip_mm"] + slip_lim
            and metrics["max_rotation_deg"] <= reference["max_rotation_deg"] + rot_lim
        )
    return ok


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
    """One closed-loop run of `scenario` on plant `model` (patch, lumped: lugrip's C++ loop; a
    registered engine, mujoco, drake: :func:`lugrip.sim.runner.run_plant_loop` on its plant)
    with controller `kind`."""
    est = scenario.estimator_for(model)
    if scenario.faults:
        options = dict(
            options,
            faults=scenario.faults["inject"],
            stuck_samples=scenario.faults.get("stuck_samples", 0),
            healthy_finger_fallback=scenario.faults.get("healthy_finger_fallback", False),
        )
    if registered(model):  # an engine's plant through the one runner (MuJoCo: frames)
        from .plant import make_plant
        from .runner import run_plant_loop

        engine = make_plant(model, **({} if frame_callback is None
                                      else {"frame_callback": frame_callback}))
        return run_plant_loop(
            engine,
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
    return run_closed_loop(
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


def _criterion(value, limit, ok) -> dict[str, Any]:
    return {"value": value, "limit": limit, "pass": None if ok is None else bool(ok)}


def _evaluate(scenario: Scenario, metrics: dict[str, dict[str, Any]], search) -> dict[str, dict]:
    c = scenario.criteria
    m = metrics["lugrip"]
    out: dict[str, dict] = {}
    for name, limit in c.items():
        fault = _faults.evaluate(name, limit, m)
        if fault is not None:
            out[name] = fault
        elif name == "no_drop":
            out[name] = _criterion(m["dropped"], False, not m["dropped"])
        elif name == "no_nan":
            ok = all(mm["finite"] for mm in metrics.values())
            out[name] = _criterion(ok, True, ok)
        elif name == "command_in_limits":
            out[name] = _criterion(m["command_in_limits"], True, m["command_in_limits"])
        elif name == "max_hold_slip_mm":
            out[name] = _criterion(m["hold_slip_mm"], limit, m["hold_slip_mm"] <= float(limit))
        elif name == "max_hold_rotation_deg":
            out[name] = _criterion(
                m["hold_rotation_deg"], limit, m["hold_rotation_deg"] <= float(limit)
            )
        elif name == "steady_slippage":
            v = m.get("steady_slippage")
            out[name] = _criterion(v, list(limit), v is not None and limit[0] <= v <= limit[1])
        elif name == "steady_force_range":
            v = m.get("steady_force")
            out[name] = _criterion(v, list(limit), v is not None and limit[0] <= v <= limit[1])
        elif name == "static_force_tolerance":
            v = m.get("steady_over_static")
            ok = v is not None and abs(v - 1.0) <= float(limit)
            out[name] = _criterion(v, limit, ok)
        elif name == "pivot_final_hang_deg":
            v = m.get("final_hang_deg")
            out[name] = _criterion(v, limit, v is not None and v <= float(limit))
        elif name == "pivot_returns_to_avoidance":
            v = m.get("returned_to_avoidance", False)
            out[name] = _criterion(v, True, v)
        elif name == "force_ratio":
            out[name] = _criterion(None, dict(limit), None)  # filled by evaluate_cross
        elif name == "constant_force_exceeds_steady":
            f = None if search is None else search["force"]
            steady = metrics.get("lugrip_no_pivot", m).get("steady_force")
            ok = None if search is None else (f is None or (steady is not None and f > steady))
            if limit == "group":  # one constant force for the whole group: filled by evaluate_cross
                ok = None
            out[name] = _criterion(
                {"constant_force": f, "lugrip_steady_force": steady},
                "group constant > steady" if limit == "group" else "constant > steady",
                ok,
            )
        elif name == "scene_ok":
            st = m.get("scene_status", "ok")
            out[name] = _criterion(st, "ok", st == "ok")
        elif name == "max_steady_command_ptp":
            v = m.get("steady_command_ptp_ratio")
            out[name] = _criterion(v, limit, v is not None and v <= float(limit))
        elif name == "mean_force_below_constant":
            f = None if search is None else search["force"]
            mean = metrics.get("lugrip_no_pivot", m).get("mean_force")
            ok = None if search is None else (f is None or (mean is not None and mean < f))
            out[name] = _criterion(
                {"mean_force": mean, "constant_force": f}, "mean < constant", ok
            )
        elif name == "friction_cone_fails":
            cone = metrics.get("friction_cone")
            hold = metrics.get("lugrip_no_pivot", m)
            if cone is None:
                out[name] = _criterion(None, True, None)
            else:
                cone_fails = not _survives(scenario, cone, hold)
                lugrip_holds = _survives(scenario, hold)
                out[name] = _criterion(
                    {
                        "friction_cone_fails": cone_fails,
                        "lugrip_holds": lugrip_holds,
                        "cone_dropped": cone["dropped"],
                        "cone_hold_slip_mm": cone["hold_slip_mm"],
                        "cone_max_rotation_deg": cone["max_rotation_deg"],
                    },
                    "cone fails, lugrip holds",
                    cone_fails and lugrip_holds,
                )
    return out


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


def evaluate_cross(results: Mapping[str, ScenarioResult] | Sequence[ScenarioResult]) -> None:
    """Fill the cross-scenario criteria of results whose partners ran too: ``force_ratio``
    (steady force / the reference scenario's) and ``constant_force_exceeds_steady: group`` (a
    constant-force gripper does not know which object of the group it holds: the constant force
    that survives every member, i.e. the largest of their minima, against each member's steady
    force)."""
    by_name = {r.name: r for r in (results.values() if isinstance(results, Mapping) else results)}
    groups: dict[str, list[ScenarioResult]] = {}
    for r in by_name.values():
        if r.scenario.group:
            groups.setdefault(r.scenario.group, []).append(r)
    for r in by_name.values():
        if r.scenario.criteria.get("constant_force_exceeds_steady") != "group" or r.search is None:
            continue
        members = groups.get(r.scenario.group, [r])
        forces = [x.search["force"] if x.search is not None else None for x in members]
        crit = r.criteria["constant_force_exceeds_steady"]
        steady = crit["value"]["lugrip_steady_force"]
        if any(f is None for f in forces) or steady is None:
            group_force = None
            ok = None if any(x.search is None for x in members) else True
        else:
            group_force = max(forces)
            ok = group_force > steady
        crit["value"] = dict(
            crit["value"], group_constant_force=group_force, group=[x.name for x in members]
        )
        crit["pass"] = ok
    for r in by_name.values():
        spec = r.scenario.criteria.get("force_ratio")
        if spec is None:
            continue
        ref = by_name.get(spec["reference"])
        own = r.metrics["lugrip"].get("steady_force")
        if ref is None or own is None:
            r.criteria["force_ratio"] = _criterion(None, dict(spec), None)
            continue
        other = ref.metrics["lugrip"].get("steady_force")
        ratio = own / other if other else math.inf
        r.criteria["force_ratio"] = _criterion(ratio, dict(spec), ratio >= float(spec["min"]))


def metrics_document(results: Sequence[ScenarioResult]) -> dict[str, Any]:
    """The metrics.json content: per scenario its metrics and a pass flag per criterion."""
    scenarios = {r.name: r.to_json() for r in results}
    return {
        "lugrip_version": __version__,
        "criteria_meaning": CRITERIA,
        "scenarios": scenarios,
        "pass": all(s["pass"] for s in scenarios.values()),
    }
