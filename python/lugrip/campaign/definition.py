"""Campaign definitions: a base scenario, distributions over the things a robot does not control
(object, contact, pushes, sensors, what the controller believes), the controllers to compare and
a master seed.

A campaign file (``campaigns/<name>.yaml``)::

    name: patch_blocks
    description: ...
    scenario: exp2_small_resin_block   # base scenario: a name or a YAML path (relative to this file)
    plant: patch                       # a registered plant: patch, lumped, mujoco, drake
    seed: 20261201                     # master seed
    duration: 8.0                      # [s] overrides of the base scenario (top-level keys, the
    steady_window: [3.5, 4.4]          #     plant block merged key by key)
    overrides: {plant: {lift: {t_start: 1.0, duration: 2.0, height: 0.1}, disturbances: []}}
    controllers:                       # any of CONTROLLERS, with their options
      lugrip: {}
      paper: {}
      constant_force: {force: 5.0}
      friction_cone: {}
    criteria: {max_hold_slip_mm: 1.0, max_hold_rotation_deg: 2.0}
    parameters:                        # any of PARAMETERS, each with one distribution
      mass: {distribution: uniform, low: 0.1, high: 0.4}
      mismatch_mu: {distribution: normal, mean: 0.0, std: 0.1, low: -0.5, high: 0.5}
      crush_factor: {distribution: uniform, low: 1.5, high: 5.0}   # fragile objects
      push_count: {distribution: choice, values: [1, 2, 3]}         # randomized pushes
    evaluation_seed: 20271201          # optional: the seed of the evaluation set (--evaluation)
    frontier: true                     # optional: per run, the smallest passing constant force
    gripper: {f_max: 40.0}             # optional: the gripper's range on top of the scenario's
    twist_lever: 0.005                 # [m] optional: lever of the twist reference (below)

Run ``i`` draws every parameter from its own random stream seeded by (seed, i, parameter name),
so a run is reproducible from (campaign, run index) alone, whatever ran before it, on whichever
worker; adding a parameter does not change the draws of the others. The plant's noise seed is
drawn the same way, and every controller of a run sees the same plant and the same noise.

Tuning and evaluation: ``seed`` draws the tuning set; ``evaluation_seed`` (when given) draws the
evaluation set, which a campaign run with ``set="evaluation"`` (``lugrip campaign
--evaluation``) uses instead. The two sets are the same distributions with independent draws.

Pushes: without any of PUSH_NEW, the ``push_*`` parameters describe one half-sine push (the
original form). With ``push_count`` (or any other of PUSH_NEW) every ``push_*`` parameter is
drawn once per push, push ``k`` from its own stream named ``<parameter>#<k>``; the pushes are
sorted by their drawn ``push_time``, each starts no earlier than the end of the one before, and
with ``push_phase`` the start is moved to that fraction of the 50 Hz command period after the
next command instant (the grid of ``plant.actuator.command_rate`` from t = 0). A push's force is
``push_force`` + ``push_weight_fraction`` m g along ``push_angle``; its torque ``push_torque`` +
``push_twist_fraction`` m g max(|offset_x|, twist_lever) (a fraction of the gravity torque about
the grasp point, or of m g times the lever when the CoG lies near the grasp point). With
``push_edge`` a push is a trapezoid (rise and fall over the edge, flat for ``push_duration`` in
between), else a half-sine of length ``push_duration``.

Fragile objects: with ``crush_factor`` drawn, a run's crush force is crush_factor times its
minimum static force, the per-finger static grasp force at S = 1 of the plant's TRUE contact
(the drawn mu, not the controller's belief) for the load each finger carries while the object
hangs still: half its weight and half the gravity torque m g |offset_x| about the grasp point
(:meth:`Campaign.run_limits`). The criterion ``no_crush`` (on by default then) fails a run whose
command exceeds the crush force at any time.
"""

from __future__ import annotations

import copy
import dataclasses
import hashlib
import json
import math
import zlib
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

__all__ = [
    "CONTROLLERS",
    "CRITERIA",
    "DISTRIBUTIONS",
    "FRONTIER_DEFAULTS",
    "PARAMETERS",
    "SETS",
    "Campaign",
    "CampaignError",
    "Distribution",
    "load_campaign",
]


@dataclasses.dataclass(frozen=True)
class _Param:
    unit: str
    lower: float | None  # None: unbounded below
    strict: bool  # lower bound excluded (> instead of >=)
    meaning: str
    upper: float | None = None  # None: unbounded above; else the support must stay <= upper
    integer: bool = False  # only integer values (choice or constant)


#: Parameters a campaign may draw: unit, lower bound of the support and meaning.
PARAMETERS: dict[str, _Param] = {
    "mass": _Param("kg", 0.0, True, "object mass"),
    "length": _Param(
        "m", 0.0, True,
        "object extent along the horizontal of the finger plane (inertia; MuJoCo box size)",
    ),
    "height": _Param(
        "m", 0.0, True,
        "object extent along the vertical of the finger plane (inertia; MuJoCo box size)",
    ),
    "offset_x": _Param("m", None, False, "CoG offset from the grasp point, horizontal"),
    "offset_y": _Param("m", None, False, "CoG offset from the grasp point, vertical"),
    "mu": _Param("-", 0.0, True, "Coulomb friction of the pads (plant)"),
    "beta_a": _Param("N s/m^3", 0.0, False, "viscous friction per unit area (plant)"),
    "sigma0": _Param("N m/rad", 0.0, True, "micro-asperity stiffness (plant)"),
    "sigma_z": _Param("N m s/rad", 0.0, False, "micro-asperity damping (plant)"),
    "delta": _Param("m", 0.0, True, "contact radius law rho = delta f_n^gamma (plant)"),
    "pad_k_slide": _Param("N/m", 0.0, True, "MuJoCo plant: in-plane stiffness of each pad"),
    "pad_k_twist": _Param("N m/rad", 0.0, True, "MuJoCo plant: twist stiffness of each pad"),
    "push_force": _Param("N", 0.0, False, "magnitude of the disturbance push"),
    "push_angle": _Param("deg", None, False, "direction of the push from +x (-90: down)"),
    "push_torque": _Param("N m", None, False, "pure torque of the push"),
    "push_time": _Param("s", 0.0, False, "start of the push"),
    "push_duration": _Param(
        "s", 0.0, True,
        "length of the half-sine push, or of the trapezoid's flat top (with push_edge)",
    ),
    "push_count": _Param("-", 1.0, False, "number of pushes per run", integer=True),
    "push_phase": _Param(
        "-", 0.0, False, "push start as a fraction of the command period after a command instant",
        upper=1.0,
    ),
    "push_weight_fraction": _Param("-", 0.0, False, "push force as a fraction of m g"),
    "push_twist_fraction": _Param(
        "-", None, False, "push torque as a fraction of m g max(|offset_x|, twist_lever)"
    ),
    "push_edge": _Param("s", 0.0, True, "rise and fall time of a trapezoid push"),
    "crush_factor": _Param(
        "-", 1.0, True, "crush force over the run's minimum static force (fragile objects)"
    ),
    "force_noise": _Param("N", 0.0, False, "white noise std of the force sensors"),
    "torque_noise": _Param("N m", 0.0, False, "white noise std of the torque sensors"),
    "normal_bias": _Param("N", None, False, "offset of both fingers' normal force"),
    "force_bias": _Param("N", None, False, "offset of both fingers' tangential forces (x, y)"),
    "torque_bias": _Param("N m", None, False, "offset of both fingers' torque"),
}
#: Contact fields whose estimator value may be off: ``mismatch_<field>`` is the relative error
#: of what the observers and the controller use, (estimate - plant) / plant, > -1.
MISMATCH_FIELDS = ("mu", "beta_a", "sigma0", "sigma_z", "delta", "gamma")
for _f in MISMATCH_FIELDS:
    PARAMETERS[f"mismatch_{_f}"] = _Param(
        "-", -1.0, True, f"relative error of the controller's {_f} against the plant's"
    )

#: The push parameters (drawn once per push when pushes are counted, see the module docstring).
PUSH_PARAMETERS = tuple(k for k in PARAMETERS if k.startswith("push_") and k != "push_count")
#: Their presence selects the counted pushes (without them: the original single half-sine push).
PUSH_NEW = ("push_count", "push_phase", "push_weight_fraction", "push_twist_fraction", "push_edge")

#: Distributions and their fields (required, optional).
DISTRIBUTIONS: dict[str, tuple[tuple[str, ...], tuple[str, ...]]] = {
    "uniform": (("low", "high"), ()),
    "loguniform": (("low", "high"), ()),
    "normal": (("mean", "std"), ("low", "high")),
    "choice": (("values",), ()),
    "constant": (("value",), ()),
}

#: Controllers a campaign compares: command law and settings on top of the scenario's.
CONTROLLERS: dict[str, str] = {
    "lugrip": "lugrip's controller with the scenario's settings (lugrip's defaults)",
    "paper": (
        "the paper's law: lugrip's controller with every addition that is not in the paper "
        "off (lugrip.PAPER_SETTINGS)"
    ),
    "constant_force": "constant grasp force `force` [N] (a gripper that does not sense slip)",
    "friction_cone": "friction-cone baseline (raises |f_t| / mu f_n above a margin; torsion-blind)",
}
_CONTROLLER_OPTIONS = {
    "lugrip": {"controller", "observer"},
    "paper": {"controller", "observer"},
    "constant_force": {"force"},
    "friction_cone": {"cone_margin", "cone_release_rate"},
}

#: Per-run pass criteria a campaign may set (all must pass for success).
CRITERIA = {
    "no_drop": "the object is never dropped",
    "no_nan": "every logged value is finite",
    "command_in_limits": "the command stays inside [f_min, f_max]",
    "max_hold_slip_mm": "max translational slip from the lift start on [mm] <= limit",
    "max_hold_rotation_deg": "max rotation from the lift start on [deg] <= limit",
    "scene_ok": "MuJoCo plant: both pads reached the object and kept contact",
    "no_crush": (
        "the command never exceeds the run's crush force (from t = 0; default true when "
        "crush_factor is drawn)"
    ),
}
_DEFAULT_CRITERIA = {
    "no_drop": True,
    "no_nan": True,
    "command_in_limits": True,
    "max_hold_slip_mm": 1.0,
    "max_hold_rotation_deg": 2.0,
}

_KEYS = {
    "name", "description", "scenario", "plant", "seed", "duration", "steady_window",
    "hold_start", "overrides", "controllers", "criteria", "parameters",
    "evaluation_seed", "set", "frontier", "gripper", "twist_lever",
}
#: Result sets: which seed draws the runs.
SETS = ("tuning", "evaluation")
#: Options of the constant-force frontier (``frontier:``) and their defaults.
FRONTIER_DEFAULTS = {
    "tolerance": 0.02,  # relative width of the final bracket
    "max_evaluations": 12,  # constant-force simulations per run at most
    "low_fraction": 0.5,  # bottom of the bracket: this times the minimum static force
}
#: The gripper's range a campaign may set on top of the scenario's controller block.
GRIPPER_KEYS = ("f_min", "f_max", "max_rate")


class CampaignError(ValueError):
    """A campaign file is invalid (the message names the field)."""


def _num(value: Any, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise CampaignError(f"{where}: {value!r} is not a number")
    v = float(value)
    if not math.isfinite(v):
        raise CampaignError(f"{where}: {value!r} is not finite")
    return v


@dataclasses.dataclass(frozen=True)
class Distribution:
    """One parameter's distribution (``kind`` in DISTRIBUTIONS; ``args`` its fields)."""

    kind: str
    args: dict

    @classmethod
    def from_dict(cls, name: str, spec: Any) -> Distribution:
        where = f"parameters.{name}"
        if name not in PARAMETERS:
            raise CampaignError(
                f"{where}: unknown parameter; expected one of {', '.join(PARAMETERS)}"
            )
        if not isinstance(spec, Mapping):
            spec = {"distribution": "constant", "value": spec}
        spec = dict(spec)
        kind = spec.pop("distribution", None)
        if kind not in DISTRIBUTIONS:
            raise CampaignError(
                f"{where}.distribution: unknown distribution {kind!r}; expected one of "
                f"{', '.join(DISTRIBUTIONS)}"
            )
        required, optional = DISTRIBUTIONS[kind]
        missing = [k for k in required if k not in spec]
        extra = sorted(set(spec) - set(required) - set(optional))
        if missing:
            raise CampaignError(f"{where}: {kind} needs {', '.join(missing)}")
        if extra:
            raise CampaignError(f"{where}: unknown field(s) {', '.join(extra)} for {kind}")
        args: dict[str, Any] = {}
        if kind == "choice":
            vals = spec["values"]
            if not isinstance(vals, (list, tuple)) or not vals:
                raise CampaignError(f"{where}.values: expected a non-empty list of numbers")
            args["values"] = [_num(v, f"{where}.values[{i}]") for i, v in enumerate(vals)]
        else:
            for k in (*required, *optional):
                if k in spec:
                    args[k] = _num(spec[k], f"{where}.{k}")
        d = cls(kind, args)
        d._check(name, where)
        return d

    def support(self) -> tuple[float, float]:
        """Smallest and largest value the distribution can give."""
        a = self.args
        if self.kind in ("uniform", "loguniform"):
            return a["low"], a["high"]
        if self.kind == "normal":
            return a.get("low", -math.inf), a.get("high", math.inf)
        if self.kind == "choice":
            return min(a["values"]), max(a["values"])
        return a["value"], a["value"]

    def _check(self, name: str, where: str) -> None:
        a = self.args
        if self.kind in ("uniform", "loguniform") and not a["low"] < a["high"]:
            raise CampaignError(
                f"{where}: empty range [{a['low']:g}, {a['high']:g}] (needs low < high; for a "
                "fixed value use distribution: constant)"
            )
        if self.kind == "loguniform" and a["low"] <= 0.0:
            raise CampaignError(f"{where}.low: loguniform needs low > 0, got {a['low']:g}")
        if self.kind == "normal":
            if a["std"] <= 0.0:
                raise CampaignError(f"{where}.std: must be > 0, got {a['std']:g}")
            lo, hi = a.get("low", -math.inf), a.get("high", math.inf)
            if not lo < hi:
                raise CampaignError(f"{where}: empty range [{lo:g}, {hi:g}] (needs low < high)")
            # truncation far in a tail would make rejection sampling endless
            z_lo, z_hi = (lo - a["mean"]) / a["std"], (hi - a["mean"]) / a["std"]
            if z_hi < -3.0 or z_lo > 3.0:
                raise CampaignError(
                    f"{where}: [low, high] lies more than 3 std from the mean (almost no mass)"
                )
        p = PARAMETERS[name]
        lo, hi = self.support()
        if p.integer:
            vals = a["values"] if self.kind == "choice" else [a.get("value")]
            if self.kind not in ("choice", "constant") or any(v != int(v) for v in vals):
                raise CampaignError(
                    f"{where}: {name} takes whole numbers: use distribution choice or constant "
                    "with integer values"
                )

        def field(bound: str) -> str:  # the key of this distribution that sets the bound
            if self.kind in ("uniform", "loguniform", "normal"):
                return bound
            return "values" if self.kind == "choice" else "value"

        if p.upper is not None and hi > p.upper:
            what = f"can be {hi:g}" if math.isfinite(hi) else "is unbounded above (set high)"
            raise CampaignError(
                f"{where}.{field('high')}: {name} must be <= {p.upper:g} [{p.unit}], but the "
                f"distribution {what}"
            )
        if p.lower is None:
            return
        bad = lo <= p.lower if p.strict else lo < p.lower
        if bad:
            rel = ">" if p.strict else ">="
            what = f"can be {lo:g}" if math.isfinite(lo) else "is unbounded below (set low)"
            raise CampaignError(
                f"{where}.{field('low')}: {name} must be {rel} {p.lower:g} [{p.unit}], but the "
                f"distribution {what}"
            )

    def draw(self, rng: np.random.Generator) -> float:
        a = self.args
        if self.kind == "uniform":
            return float(rng.uniform(a["low"], a["high"]))
        if self.kind == "loguniform":
            return float(math.exp(rng.uniform(math.log(a["low"]), math.log(a["high"]))))
        if self.kind == "normal":
            lo, hi = a.get("low", -math.inf), a.get("high", math.inf)
            while True:  # rejection: the support holds >= 0.13 % of the mass (checked)
                v = float(rng.normal(a["mean"], a["std"]))
                if lo <= v <= hi:
                    return v
        if self.kind == "choice":
            return float(a["values"][int(rng.integers(len(a["values"])))])
        return float(a["value"])

    def to_dict(self) -> dict:
        return {"distribution": self.kind, **self.args}


def _stream(seed: int, index: int, name: str) -> np.random.Generator:
    """The random stream of parameter `name` in run `index` (independent of every other)."""
    return np.random.default_rng(
        np.random.SeedSequence([int(seed), int(index), zlib.crc32(name.encode())])
    )


@dataclasses.dataclass
class Campaign:
    """A validated campaign (see the module docstring)."""

    name: str
    scenario: str | dict  # a name or path, or the base scenario itself (a mapping)
    plant: str
    seed: int
    controllers: dict[str, dict]
    parameters: dict[str, Distribution]
    criteria: dict[str, Any]
    scenario_overrides: dict
    description: str = ""
    source: Path | None = None
    evaluation_seed: int | None = None
    result_set: str = "tuning"  # which seed draws the runs (SETS)
    frontier: dict | None = None  # FRONTIER_DEFAULTS filled in, or None: no frontier
    gripper: dict = dataclasses.field(default_factory=dict)  # GRIPPER_KEYS on the scenario's
    twist_lever: float = 0.005  # [m] the twist reference's smallest lever

    @property
    def draw_seed(self) -> int:
        """The seed the runs are drawn with: ``seed`` (tuning) or ``evaluation_seed``."""
        if self.result_set == "evaluation":
            assert self.evaluation_seed is not None
            return self.evaluation_seed
        return self.seed

    def for_set(self, name: str) -> Campaign:
        """The same campaign drawing the tuning or the evaluation set (``name`` in SETS)."""
        if name not in SETS:
            raise CampaignError(f"set {name!r}: expected one of {', '.join(SETS)}")
        if name == "evaluation" and self.evaluation_seed is None:
            raise CampaignError(
                "evaluation_seed: missing (the campaign has no evaluation set; add "
                "evaluation_seed: <integer> to the campaign file)"
            )
        return dataclasses.replace(self, result_set=name)

    @property
    def counted_pushes(self) -> bool:
        """The pushes are counted (drawn once per push; see the module docstring)."""
        return any(k in self.parameters for k in PUSH_NEW)

    @property
    def max_pushes(self) -> int:
        if not self.counted_pushes:
            return 1 if any(k in self.parameters for k in ("push_force", "push_torque")) else 0
        d = self.parameters.get("push_count")
        return int(d.support()[1]) if d is not None else 1

    @classmethod
    def from_dict(cls, data: Any, source: Path | None = None) -> Campaign:
        where = str(source) if source else "campaign"
        try:
            return cls._from_dict(data, source)
        except CampaignError as err:
            raise CampaignError(f"{where}: {err}") from None

    @classmethod
    def _from_dict(cls, data: Any, source: Path | None) -> Campaign:
        if not isinstance(data, Mapping):
            raise CampaignError("expected a mapping at the top level")
        unknown = sorted(set(data) - _KEYS)
        if unknown:
            raise CampaignError(
                f"unknown key(s) {', '.join(unknown)}; expected {', '.join(sorted(_KEYS))}"
            )
        for key in ("name", "scenario", "seed", "controllers"):
            if key not in data:
                raise CampaignError(f"missing key {key!r}")
        seed = data["seed"]
        if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
            raise CampaignError(f"seed: {seed!r} must be an integer >= 0")
        from ..sim.plant import plant_kind, plant_names

        plant = str(data.get("plant", "patch"))
        if plant not in plant_names():
            raise CampaignError(f"plant: {plant!r}: expected one of {', '.join(plant_names())}")
        ctrl = data["controllers"]
        if isinstance(ctrl, (list, tuple)):
            ctrl = {str(c): {} for c in ctrl}
        if not isinstance(ctrl, Mapping) or not ctrl:
            raise CampaignError("controllers: expected a non-empty mapping name -> options")
        controllers = {}
        for name, opts in ctrl.items():
            if name not in CONTROLLERS:
                raise CampaignError(
                    f"controllers.{name}: unknown controller; expected one of "
                    f"{', '.join(CONTROLLERS)}"
                )
            opts = dict(opts or {})
            bad = sorted(set(opts) - _CONTROLLER_OPTIONS[name])
            if bad:
                raise CampaignError(f"controllers.{name}: unknown option(s) {', '.join(bad)}")
            if name == "constant_force":
                if "force" not in opts:
                    raise CampaignError("controllers.constant_force.force: missing [N]")
                if _num(opts["force"], "controllers.constant_force.force") <= 0.0:
                    raise CampaignError("controllers.constant_force.force: must be > 0 [N]")
            controllers[str(name)] = opts
        params = data.get("parameters") or {}
        if not isinstance(params, Mapping):
            raise CampaignError("parameters: expected a mapping name -> distribution")
        parameters = {str(k): Distribution.from_dict(str(k), v) for k, v in params.items()}
        kind = plant_kind(plant)
        for k in sorted(parameters):
            owners = [p for p in plant_names() if k in plant_kind(p).parameters]
            if owners and k not in kind.parameters:
                raise CampaignError(f"parameters.{k}: a parameter of the {', '.join(owners)} "
                                    f"plant, not of {plant}")
        crit = dict(_DEFAULT_CRITERIA)
        if "crush_factor" in parameters:
            crit["no_crush"] = True
        given = data.get("criteria") or {}
        if not isinstance(given, Mapping):
            raise CampaignError("criteria: expected a mapping")
        for k, v in given.items():
            if k not in CRITERIA:
                raise CampaignError(
                    f"criteria.{k}: unknown criterion; expected one of {', '.join(CRITERIA)}"
                )
            if k.startswith("max_"):
                if _num(v, f"criteria.{k}") <= 0.0:
                    raise CampaignError(f"criteria.{k}: must be > 0")
            elif not isinstance(v, bool):
                raise CampaignError(f"criteria.{k}: expected true or false")
        crit.update(given)
        if crit.get("no_crush") and "crush_factor" not in parameters:
            raise CampaignError(
                "criteria.no_crush: needs a crush force per run (draw parameters.crush_factor)"
            )
        if kind.scene:  # a plant that builds its own scene reports its scene status
            crit.setdefault("scene_ok", True)
        eval_seed = data.get("evaluation_seed")
        if eval_seed is not None and (
            isinstance(eval_seed, bool) or not isinstance(eval_seed, int) or eval_seed < 0
        ):
            raise CampaignError(f"evaluation_seed: {eval_seed!r} must be an integer >= 0")
        if eval_seed is not None and eval_seed == seed:
            raise CampaignError("evaluation_seed: must differ from seed (the tuning set's)")
        result_set = str(data.get("set", "tuning"))
        if result_set not in SETS:
            raise CampaignError(f"set: {result_set!r}: expected one of {', '.join(SETS)}")
        if result_set == "evaluation" and eval_seed is None:
            raise CampaignError("set: evaluation needs evaluation_seed")
        frontier = cls._frontier(data.get("frontier", False))
        gripper = data.get("gripper") or {}
        if not isinstance(gripper, Mapping):
            raise CampaignError(f"gripper: expected a mapping of {', '.join(GRIPPER_KEYS)}")
        bad = sorted(set(gripper) - set(GRIPPER_KEYS))
        if bad:
            raise CampaignError(
                f"gripper.{bad[0]}: unknown; expected any of {', '.join(GRIPPER_KEYS)}"
            )
        gripper = {str(k): _num(v, f"gripper.{k}") for k, v in gripper.items()}
        for k, v in gripper.items():
            if v <= 0.0:
                raise CampaignError(f"gripper.{k}: must be > 0, got {v:g}")
        lever = _num(data.get("twist_lever", 0.005), "twist_lever")
        if lever <= 0.0:
            raise CampaignError(f"twist_lever: must be > 0 [m], got {lever:g}")
        over = dict(data.get("overrides") or {})
        for key in ("duration", "steady_window", "hold_start"):
            if key in data:
                over[key] = data[key]
        c = cls(
            name=str(data["name"]),
            scenario=(
                dict(data["scenario"]) if isinstance(data["scenario"], Mapping)
                else str(data["scenario"])
            ),
            plant=plant,
            seed=int(seed),
            controllers=controllers,
            parameters=parameters,
            criteria=crit,
            scenario_overrides=over,
            description=str(data.get("description") or "").strip(),
            source=source,
            evaluation_seed=None if eval_seed is None else int(eval_seed),
            result_set=result_set,
            frontier=frontier,
            gripper=gripper,
            twist_lever=lever,
        )
        base = c.base_scenario()  # the base scenario exists and the overrides are valid
        c._check_pushes(base)
        return c

    @staticmethod
    def _frontier(value: Any) -> dict | None:
        if value is False or value is None:
            return None
        if value is True:
            return dict(FRONTIER_DEFAULTS)
        if not isinstance(value, Mapping):
            raise CampaignError("frontier: expected true, false or a mapping of options")
        bad = sorted(set(value) - set(FRONTIER_DEFAULTS))
        if bad:
            raise CampaignError(
                f"frontier.{bad[0]}: unknown option; expected any of {', '.join(FRONTIER_DEFAULTS)}"
            )
        out = dict(FRONTIER_DEFAULTS)
        for k, v in value.items():
            out[k] = _num(v, f"frontier.{k}")
        if not 0.0 < out["tolerance"] < 1.0:
            raise CampaignError("frontier.tolerance: must lie in (0, 1)")
        if not 0.0 < out["low_fraction"] < 1.0:
            raise CampaignError("frontier.low_fraction: must lie in (0, 1)")
        if out["max_evaluations"] < 2 or out["max_evaluations"] != int(out["max_evaluations"]):
            raise CampaignError("frontier.max_evaluations: must be an integer >= 2")
        out["max_evaluations"] = int(out["max_evaluations"])
        return out

    def _check_pushes(self, base) -> None:
        """Counted pushes must end inside the scenario, even all drawn at their latest."""
        if not self.counted_pushes:
            return
        par = self.parameters
        t_last = par["push_time"].support()[1] if "push_time" in par else 0.5 * base.duration
        dur = par["push_duration"].support()[1] if "push_duration" in par else 0.3
        edge = par["push_edge"].support()[1] if "push_edge" in par else 0.0
        period = 1.0 / self._command_rate(base.to_dict())
        end = t_last + self.max_pushes * (dur + 2.0 * edge + period)
        if end > base.duration:
            raise CampaignError(
                f"parameters.push_time: {self.max_pushes} push(es) starting as late as "
                f"{t_last:g} s and lasting up to {dur + 2.0 * edge:g} s each may end at "
                f"{end:g} s, after the scenario's end ({base.duration:g} s): shorten them or "
                "lengthen duration"
            )

    @staticmethod
    def _command_rate(d: Mapping) -> float:
        return float(((d.get("plant") or {}).get("actuator") or {}).get("command_rate", 50.0))

    # --- the base scenario and one run's scenario ----------------------------------------
    def _scenario_path(self) -> str | Path:
        if isinstance(self.scenario, dict):
            return "<inline>"
        p = Path(self.scenario)
        if p.suffix in (".yaml", ".yml") and not p.is_absolute() and self.source is not None:
            cand = self.source.parent / p
            if cand.is_file():
                return cand
        if p.suffix not in (".yaml", ".yml") and self.source is not None:
            # a name: the scenarios/ folder beside the campaign's folder (the repository
            # layout campaigns/ + scenarios/), else the scenario directory of lugrip.sim
            root = self.source.resolve().parent
            for d in (root / "scenarios", root.parent / "scenarios"):
                for cand in (d / f"{p.name}.yaml", d / "unseen" / f"{p.name}.yaml"):
                    if cand.is_file():
                        return cand
        return self.scenario

    def base_scenario(self):
        """The base scenario with the campaign's overrides (no drawn parameters)."""
        from ..sim.scenarios import Scenario, _merge, load_scenario

        cached = self.__dict__.get("_base")
        if cached is not None:
            return cached
        try:
            if isinstance(self.scenario, dict):
                base = Scenario.from_dict(self.scenario)
            else:
                base = load_scenario(self._scenario_path())
        except ValueError as err:
            raise CampaignError(f"scenario: {err}") from None
        d = _merge(base.to_dict(), self.scenario_overrides)
        d["short"] = {}
        if self.gripper:
            d["controller"] = dict(d.get("controller") or {}) | self.gripper
            if "f_max" in self.gripper:  # the actuator saturates no lower than the range
                plant = dict(d["plant"])
                act = dict(plant.get("actuator") or {})
                act["f_max"] = max(float(act.get("f_max", 80.0)), self.gripper["f_max"])
                plant["actuator"] = act
                d["plant"] = plant
        try:
            scn = Scenario.from_dict(d, base.source)
        except ValueError as err:
            raise CampaignError(f"overrides: {err}") from None
        self.__dict__["_base"] = scn
        return scn

    def draw(self, index: int) -> dict[str, float]:
        """The drawn parameters of run `index` (name -> value) and ``plant_seed``."""
        if isinstance(index, bool) or int(index) != index or index < 0:
            raise ValueError(f"run index {index!r}: must be an integer >= 0")
        seed = self.draw_seed
        counted = self.counted_pushes
        out: dict[str, Any] = {
            name: d.draw(_stream(seed, index, name))
            for name, d in self.parameters.items()
            if not (counted and name in PUSH_PARAMETERS)
        }
        if counted:
            out.update(self._draw_pushes(seed, index, int(out.get("push_count", 1))))
        out["plant_seed"] = int(_stream(seed, index, "plant_seed").integers(2**31 - 1))
        return out

    def _draw_pushes(self, seed: int, index: int, n: int) -> dict[str, Any]:
        """Counted pushes: push k's parameters from the streams ``<name>#<k>``, sorted by time,
        started no earlier than the previous push's end and, with push_phase, at that fraction
        of the command period after the next command instant. Returns ``<name>_<k>`` and
        ``push_start_<k>`` for k < max_pushes (None beyond n) and ``<name>``: the value of the
        push with the largest force (weight fraction, then force, then twist)."""
        names = [k for k in PUSH_PARAMETERS if k in self.parameters]
        raw = [
            {name: self.parameters[name].draw(_stream(seed, index, f"{name}#{k}"))
             for name in names}
            for k in range(n)
        ]
        base = self.base_scenario()
        t_default = 0.5 * float(base.duration)
        raw.sort(key=lambda q: q.get("push_time", t_default))
        period = 1.0 / self._command_rate(base.to_dict())
        prev_end = -math.inf
        for q in raw:
            t = max(q.get("push_time", t_default), prev_end)
            if "push_phase" in q:
                t = (math.ceil(t / period - 1e-9) + q["push_phase"]) * period
            q["push_start"] = t
            prev_end = t + q.get("push_duration", 0.3) + 2.0 * q.get("push_edge", 0.0)
        out: dict[str, Any] = {}
        for k in range(self.max_pushes):
            for name in (*names, "push_start"):
                out[f"{name}_{k}"] = raw[k][name] if k < n else None
        if n:
            def size(q):
                return (q.get("push_weight_fraction", 0.0), q.get("push_force", 0.0),
                        abs(q.get("push_twist_fraction", 0.0)))

            big = max(range(n), key=lambda k: size(raw[k]))
            out.update({name: raw[big][name] for name in names})
        return out

    def columns(self) -> list[str]:
        """The drawn values a result row carries as ``p_<column>`` (every parameter, and with
        counted pushes each push's values and start)."""
        cols = list(self.parameters)
        if self.counted_pushes:
            names = [k for k in PUSH_PARAMETERS if k in self.parameters]
            cols += [f"{name}_{k}" for k in range(self.max_pushes)
                     for name in (*names, "push_start")]
        return cols

    def run_scenario(self, index: int):
        """(scenario, drawn parameters) of run `index`: the base scenario with the draws
        applied (see :data:`PARAMETERS` for where each goes)."""
        from ..sim.scenarios import Scenario

        base = self.base_scenario()
        p = self.draw(index)
        d = base.to_dict()
        plant = d["plant"]
        obj = dict(plant["object"])
        base_mass = float(obj.get("mass", 0.0))
        mass = p.get("mass", base_mass)
        obj["mass"] = mass
        if "length" in p or "height" in p:
            size = list(d.get("mujoco", {}).get("size") or [])
            length = p.get("length", 2.0 * size[1] if len(size) == 3 else None)
            height = p.get("height", 2.0 * size[2] if len(size) == 3 else None)
            if length is None or height is None:
                raise CampaignError(
                    "parameters: length and height both needed (the base scenario has no box "
                    "size to take the other from)"
                )
            obj["inertia"] = mass * (length**2 + height**2) / 12.0
            if d.get("mujoco") and d["mujoco"].get("shape", "box") == "box":
                mj = dict(d["mujoco"])
                mj["size"] = [size[0] if size else 0.015, 0.5 * length, 0.5 * height]
                d["mujoco"] = mj
        elif base_mass > 0.0:
            obj["inertia"] = float(obj.get("inertia", 0.0)) * mass / base_mass  # same shape
        cog = list(obj.get("cog", (0.0, 0.0)))
        cog = [p.get("offset_x", cog[0]), p.get("offset_y", cog[1])]
        obj["cog"] = cog
        plant["object"] = obj
        contact_fields = {k: p[k] for k in ("mu", "beta_a", "sigma0", "sigma_z", "delta") if k in p}
        if contact_fields:
            c = plant["contact"]
            c = {"preset": c} if isinstance(c, str) else dict(c)
            c.update(contact_fields)
            plant["contact"] = c
        sensor = dict(plant.get("sensor") or {})
        for k in ("force_noise", "torque_noise"):
            if k in p:
                sensor[k] = p[k]
        if any(k in p for k in ("normal_bias", "force_bias", "torque_bias")):
            row = [
                p.get("normal_bias", 0.0),
                p.get("force_bias", 0.0),
                p.get("force_bias", 0.0),
                p.get("torque_bias", 0.0),
            ]
            sensor["bias"] = [row, row]
        plant["sensor"] = sensor
        if self.counted_pushes:
            g = float(plant.get("gravity", 9.81))
            tau_ref = mass * g * max(abs(cog[0]), self.twist_lever)
            pushes = []
            for k in range(int(p.get("push_count", 1))):
                def v(name, default, k=k):
                    x = p.get(f"{name}_{k}")
                    return default if x is None else x

                f = v("push_force", 0.0) + v("push_weight_fraction", 0.0) * mass * g
                ang = math.radians(v("push_angle", -90.0))
                push = {
                    "t_start": p[f"push_start_{k}"],
                    "force": [f * math.cos(ang), f * math.sin(ang)],
                    "torque": v("push_torque", 0.0) + v("push_twist_fraction", 0.0) * tau_ref,
                }
                edge = p.get(f"push_edge_{k}")
                if edge is not None:
                    push.update(shape="trapezoid", edge=edge,
                                duration=v("push_duration", 0.3) + 2.0 * edge)
                else:
                    push.update(shape="half_sine", duration=v("push_duration", 0.3))
                pushes.append(push)
            plant["disturbances"] = [*list(plant.get("disturbances") or []), *pushes]
        elif "push_force" in p or "push_torque" in p:
            ang = math.radians(p.get("push_angle", -90.0))
            f = p.get("push_force", 0.0)
            push = {
                "t_start": p.get("push_time", 0.5 * float(d["duration"])),
                "duration": p.get("push_duration", 0.3),
                "shape": "half_sine",
                "force": [f * math.cos(ang), f * math.sin(ang)],
                "torque": p.get("push_torque", 0.0),
            }
            plant["disturbances"] = [*list(plant.get("disturbances") or []), push]
        from ..sim.plant import plant_kind

        for k, path in plant_kind(self.plant).parameters.items():  # the plant's own draws
            if k in p:
                _set_path(d, path, p[k])
        plant["seed"] = p["plant_seed"]
        d["plant"] = plant
        mism = {k[len("mismatch_"):]: v for k, v in p.items() if k.startswith("mismatch_")}
        if mism or "mu" in p:
            d["estimator"] = dict(d.get("estimator") or {})
            d["estimator"][self.plant] = self._mismatched(base, d, mism, "mu" in p)
        d["name"] = f"{self.name}_run{index}"
        d["criteria"] = {}
        d["criteria_by_plant"] = {}
        try:
            return Scenario.from_dict(d, base.source), p
        except ValueError as err:
            raise CampaignError(f"run {index}: drawn parameters {p}: {err}") from None

    def _mismatched(self, base, d: dict, mism: Mapping[str, float], drawn_mu: bool = False):
        """The estimator block of one run: what the controller would believe without the
        mismatch (the base scenario's estimator for this plant, else the plant's contact), each
        listed field times (1 + relative error). With `drawn_mu` the belief's mu is the drawn
        object's: a base estimator that is an identified file carries the mu of the object it
        was fitted on, and a per-object refit (only mu free) would give the drawn object's, up
        to the mismatch."""
        from ..sim._closed_loop import estimator_params
        from ..sim.scenarios import Scenario

        tmp = Scenario.from_dict(d | {"estimator": {}}, base.source)
        plant_contact = tmp.plant_config(self.plant).contact
        est = estimator_params(plant_contact, base.estimator_for(self.plant)) or plant_contact
        if drawn_mu:
            est = est.replace(mu=plant_contact.mu)
        return est.replace(**{k: getattr(est, k) * (1.0 + e) for k, e in mism.items()}).to_dict()

    def run_limits(self, scenario, params: Mapping[str, Any]) -> dict[str, float | None]:
        """``min_static_force``: the per-finger static grasp force at S = 1 [N] of the plant's
        TRUE contact (drawn mu; for MuJoCo the contact the scene is built from) for the steady
        hanging load of each finger, half the weight and half the gravity torque m g |cog_x|
        about the grasp point; ``crush_force`` [N]: crush_factor times it (None when
        crush_factor is not drawn). `scenario`, `params`: a run's scenario and draws
        (:meth:`run_scenario`)."""
        from .._controller import static_grasp_force

        cfg = scenario.plant_config(self.plant)
        obj = cfg.object
        g = float(cfg.gravity)
        f_t = 0.5 * obj.mass * g
        tau = 0.5 * obj.mass * g * abs(float(obj.cog[0]))
        f_min = float(static_grasp_force(cfg.contact, f_t, tau, s_ref=1.0))
        factor = params.get("crush_factor")
        crush = None if factor is None else float(factor) * f_min
        return {"min_static_force": f_min, "crush_force": crush}

    # --- identity ---------------------------------------------------------------------------
    def to_dict(self) -> dict:
        return {
            "name": self.name,
            "description": self.description,
            "scenario": (
                copy.deepcopy(self.scenario) if isinstance(self.scenario, dict)
                else str(self._scenario_path())
            ),
            "plant": self.plant,
            "seed": self.seed,
            "controllers": copy.deepcopy(self.controllers),
            "criteria": dict(self.criteria),
            "parameters": {k: v.to_dict() for k, v in self.parameters.items()},
            "overrides": copy.deepcopy(self.scenario_overrides),
            # the later keys only when used: older campaigns keep their fingerprint
            **({"evaluation_seed": self.evaluation_seed} if self.evaluation_seed is not None
               else {}),
            **({"set": self.result_set} if self.result_set != "tuning" else {}),
            **({"frontier": dict(self.frontier)} if self.frontier is not None else {}),
            **({"gripper": dict(self.gripper)} if self.gripper else {}),
            **({"twist_lever": self.twist_lever} if self.twist_lever != 0.005 else {}),
        }

    def portable(self) -> dict:
        """:meth:`to_dict` with the base scenario written out (no file needed to rebuild it:
        what Ray ships to remote workers)."""
        from ..sim.scenarios import load_scenario

        d = self.to_dict()
        if not isinstance(self.scenario, dict):
            base = load_scenario(self._scenario_path()).to_dict()
            base["short"] = {}
            d["scenario"] = base
        return d

    def fingerprint(self) -> str:
        """Hash of everything that decides the runs' results (a results directory belongs to
        one fingerprint)."""
        d = self.portable()
        d.pop("description")
        text = json.dumps(d, sort_keys=True, default=str)
        return hashlib.sha256(text.encode()).hexdigest()[:16]


def load_campaign(path: str | Path) -> Campaign:
    """Load and validate a campaign file (raises CampaignError naming the bad field)."""
    p = Path(path)
    if not p.is_file():
        raise CampaignError(f"campaign file {p} does not exist")
    from .._yaml import load_yaml

    try:  # the limits every YAML file lugrip reads goes through (size, depth, aliases)
        data = load_yaml(p)
    except ValueError as err:  # YamlLimitError: names the file and the line
        raise CampaignError(str(err)) from None
    return Campaign.from_dict(data, source=p)


def _set_path(d: dict, path: tuple[str, ...], value) -> None:
    """Set ``d[path[0]][path[1]]...`` to ``value``, copying (or creating) each mapping on the
    way so that the base scenario's blocks are not changed."""
    head, *rest = path
    if not rest:
        d[head] = value
        return
    sub = dict(d.get(head) or {})
    _set_path(sub, tuple(rest), value)
    d[head] = sub


def _controller_call(name: str, opts: dict, scenario) -> tuple[str, dict, dict, dict]:
    """(kind, controller settings, observer settings, options of simulate) of a controller."""
    from .._controller import PAPER_SETTINGS

    ctrl = dict(scenario.controller)
    obs = dict(scenario.observer)
    if name in ("lugrip", "paper"):
        if name == "paper":
            ctrl.update(PAPER_SETTINGS)
        ctrl.update(opts.get("controller") or {})
        obs.update(opts.get("observer") or {})
        return "lugrip", ctrl, obs, {}
    if name == "constant_force":
        return "constant_force", ctrl, obs, {"constant_force": float(opts["force"])}
    return "friction_cone", ctrl, obs, dict(opts)
