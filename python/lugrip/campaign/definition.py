"""Campaign definitions: a base scenario, distributions over the things a robot does not control
(object, contact, pushes, sensors, what the controller believes), the controllers to compare and
a master seed.

A campaign file (``campaigns/<name>.yaml``)::

    name: patch_blocks
    description: ...
    scenario: exp2_small_resin_block   # base scenario: a name or a YAML path (relative to this file)
    plant: patch                       # patch, lumped or mujoco
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

Run ``i`` draws every parameter from its own random stream seeded by (seed, i, parameter name),
so a run is reproducible from (campaign, run index) alone, whatever ran before it, on whichever
worker; adding a parameter does not change the draws of the others. The plant's noise seed is
drawn the same way, and every controller of a run sees the same plant and the same noise.
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
    "PARAMETERS",
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
    "push_duration": _Param("s", 0.0, True, "length of the (half-sine) push"),
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
}


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
        if p.lower is None:
            return
        lo, _ = self.support()
        bad = lo <= p.lower if p.strict else lo < p.lower
        if bad:
            rel = ">" if p.strict else ">="
            field = "low" if self.kind in ("uniform", "loguniform", "normal") else (
                "values" if self.kind == "choice" else "value"
            )
            what = f"can be {lo:g}" if math.isfinite(lo) else "is unbounded below (set low)"
            raise CampaignError(
                f"{where}.{field}: {name} must be {rel} {p.lower:g} [{p.unit}], but the "
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
        from ..sim.scenarios import PLANT_MODELS

        plant = str(data.get("plant", "patch"))
        if plant not in PLANT_MODELS:
            raise CampaignError(f"plant: {plant!r}: expected one of {', '.join(PLANT_MODELS)}")
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
        pads = sorted(k for k in parameters if k.startswith("pad_"))
        if pads and plant != "mujoco":
            raise CampaignError(f"parameters.{pads[0]}: only for plant mujoco (MuJoCo's pads)")
        crit = dict(_DEFAULT_CRITERIA)
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
        if plant == "mujoco":
            crit.setdefault("scene_ok", True)
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
        )
        c.base_scenario()  # the base scenario exists and the overrides are valid
        return c

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
        out = {name: d.draw(_stream(self.seed, index, name)) for name, d in self.parameters.items()}
        out["plant_seed"] = int(_stream(self.seed, index, "plant_seed").integers(2**31 - 1))
        return out

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
        if "push_force" in p or "push_torque" in p:
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
        pad = {k[len("pad_"):]: p[k] for k in ("pad_k_slide", "pad_k_twist") if k in p}
        if pad:
            mj = dict(d.get("mujoco") or {})
            mj["pad"] = dict(mj.get("pad") or {}) | pad
            d["mujoco"] = mj
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
        plant_contact = tmp.plant_config(self.plant if self.plant != "mujoco" else None).contact
        est = estimator_params(plant_contact, base.estimator_for(self.plant)) or plant_contact
        if drawn_mu:
            est = est.replace(mu=plant_contact.mu)
        return est.replace(**{k: getattr(est, k) * (1.0 + e) for k, e in mism.items()}).to_dict()

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
