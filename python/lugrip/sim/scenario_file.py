"""Scenario files: the YAML layout of :mod:`lugrip.sim.scenarios` (keys, criteria names, plant
blocks, known limits), loading, listing and checking them, and a rule that computes a standing
reserve from an expected pulse list (a tool for stating a task's envelope; no scene derives its
own)."""

from __future__ import annotations

import copy
import dataclasses
import math
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any


from .._controller import static_grasp_force
from .._params import ContactParams
from .._yaml import load_yaml, to_number
from . import faults as _faults
from ._closed_loop import estimator_params
from ._plant import PlantConfig
from .plant import builds_scene, plant_kind, plant_names


#: Controller settings every scenario states: the gripper's force range [N] and rate limits [N/s].
GRIPPER_RANGE = ("f_min", "f_max", "max_rate")


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
    "known_limits",
}


#: Plant models a scenario runs on when this module was imported: the registered kinds
#: (lugrip.sim.plant; the checks below ask the registry).
PLANT_MODELS = plant_names()


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
    #: the blocks of registered engines other than MuJoCo, by plant name (see :meth:`block`)
    engines: dict = dataclasses.field(default_factory=dict)
    #: plant name -> why this scenario is known to fail its criteria on that plant (the demo
    #: reports such a failure as a documented limit, not an error)
    known_limits: dict = dataclasses.field(default_factory=dict)

    def block(self, name: str) -> dict:
        """The scenario's own block for engine ``name`` (its top-level key of that name; the
        ``mujoco`` block for MuJoCo), empty when the file has none."""
        own = getattr(self, name, None) if name not in ("plant", "engines") else None
        return dict(own) if isinstance(own, dict) else dict(self.engines.get(name) or {})

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], source: Path | None = None) -> Scenario:
        where = str(source) if source else "scenario"
        if not isinstance(data, Mapping):
            raise ValueError(f"{where}: expected a mapping at the top level")  # noqa: TRY004 (file content)
        # a registered engine's own block (lugrip.sim.plant) is a top-level key of its name
        unknown = sorted(set(data) - _KEYS - set(plant_names()))
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
                f"{where}: criteria_by_plant: keys must be among {', '.join(plant_names())}"
            )
        plant = data["plant"]
        if not isinstance(plant, Mapping):
            raise ValueError(f"{where}: plant: expected a mapping (model: patch | lumped | mujoco | drake, ...)")  # noqa: TRY004 (file content)
        model = plant.get("model", "patch")
        if not isinstance(model, str) or model not in plant_names():
            raise ValueError(f"{where}: plant.model: must be one of {', '.join(plant_names())}")
        sw = data.get("steady_window")
        if sw is not None and (not isinstance(sw, Sequence) or isinstance(sw, str) or len(sw) != 2):
            raise ValueError(f"{where}: steady_window: expected [start, end] in seconds")
        plant = dict(plant)
        contact = plant.get("contact")
        if isinstance(contact, str) and Path(contact).suffix.lower() in (".yaml", ".yml"):
            # an identified parameter file: its contact parameters, read now (relative to the
            # scenario) so the plant block stays self-contained
            path = _estimator_file(contact, source, f"{where}: plant.contact")
            plant["contact"] = ContactParams.from_yaml(path).to_dict()
        s = cls(
            name=str(data["name"]),
            title=str(data["title"]),
            duration=to_number(data["duration"], f"{where}: duration"),
            plant=plant,
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
            engines={str(k): dict(v or {}) for k, v in data.items()
                     if k not in _KEYS and builds_scene(k)},
            known_limits=_known_limits(data.get("known_limits"), where),
        )
        if s.suite not in SUITES:
            raise ValueError(f"{where}: suite {s.suite!r}: expected one of {', '.join(SUITES)}")
        if "reserve" in s.controller:
            raise ValueError(
                f"{where}: controller.reserve: {s.controller['reserve']!r}: a scene does not "
                "derive its reserve from its own pulses; state the task's envelope as numbers, "
                "reserve_force [N] and reserve_torque [N m] per finger "
                "(lugrip.sim.scenarios.disturbance_reserve computes them from an expected pulse "
                "list), or leave it to the reserve the controller learns from the pushes"
            )
        s.plant_config()  # validates the plant block now, naming bad fields
        if s.mujoco:
            s.scene_spec()  # and the MuJoCo scene
        for m in s.estimator:
            s.estimator_for(m)  # and that parameter files exist
        return s

    def to_dict(self) -> dict:
        d = dataclasses.asdict(self)
        d.pop("source")
        d.update(d.pop("engines"))
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
        d["model"] = plant_kind(d.get("model", "patch")).config_model  # an engine: "patch"
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


def _estimator_file(name: str, source: Path | None, what: str = "estimator") -> Path:
    """The parameter file `name` of an estimator block (or, ``what``, of plant.contact): as
    given when absolute, else next to the scenario file `source`, else in the shipped objects
    directory."""
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
    raise ValueError(f"{what} parameter file {name!r} not found (looked in {where})")


def _known_limits(value: Any, where: str) -> dict:
    """The ``known_limits`` block: plant name -> the reason (text) the scenario fails there."""
    if value is None:
        return {}
    if not isinstance(value, Mapping) or not set(value) <= set(plant_names()):
        raise ValueError(f"{where}: known_limits: expected a mapping with keys among "
                         f"{', '.join(plant_names())} (plant -> reason)")
    bad = [k for k, v in value.items() if not isinstance(v, str) or not v.strip()]
    if bad:
        raise ValueError(f"{where}: known_limits.{bad[0]}: expected the reason as text")
    return {str(k): str(v).strip() for k, v in value.items()}


def _estimator_block(value: Any, where: str) -> dict:
    """The ``estimator`` block: a mapping from plant model (patch, lumped) to the contact
    parameters the estimator side uses with that plant."""
    if value is None:
        return {}
    if not isinstance(value, Mapping) or not set(value) <= set(plant_names()):
        raise ValueError(
            f"{where}: estimator: expected a mapping with keys among {', '.join(plant_names())}"
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
