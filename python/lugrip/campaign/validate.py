"""A campaign definition checked completely at load, before any run (docs/reliability.md).

:func:`Campaign.from_dict` checks the fields one by one; what it cannot see is whether the
simulator accepts the grasps the distributions draw (a duration of -1 s, an estimator file that
is not a parameter file, a mass of 1e-300 kg were stored as failed runs, 0 % success, exit 0).
:func:`validate_campaign` builds those grasps without simulating them:

* the seed (stored as a 64-bit integer with the results) and the base scenario's duration;
* run 0 with every controller: the plant, the estimator, the controller and the observer are
  built (an engine's scene by its plant's reset), and on a plant that runs the loop in C++
  (patch, lumped) the closed loop steps a few samples; the static grasp force of the object's weight, which the run's
  metrics evaluate, is in the solver's range;
* each drawn parameter at each end of its distribution's support (the others as in run 0),
  with the first controller.

The first failure is a :class:`CampaignError` naming the file and the field; a campaign
that passes can still have grasps that drop (results, not errors).
"""

from __future__ import annotations

import math
from typing import Any

from .definition import PUSH_PARAMETERS, Campaign, CampaignError

__all__ = ["CHECK_DURATION", "validate_campaign"]

CHECK_DURATION = 0.01
"""[s] simulated per checked grasp (a few samples: the loop is built and stepped)."""


class _Drawn:
    """A campaign whose draw() returns fixed values (the rest delegated to the campaign), for
    Campaign.run_scenario on a chosen point of the parameter space."""

    def __init__(self, campaign: Campaign, values: dict[str, float]):
        self._campaign = campaign
        self._values = values

    def draw(self, index: int) -> dict[str, float]:
        return dict(self._values)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._campaign, name)


def _one_line(err: BaseException) -> str:
    text = str(err).strip().splitlines()
    return f"{type(err).__name__}: {text[0] if text else ''}"[:300]


G = 9.81  # [m/s^2]


def _check_load(cfg, field: str) -> None:
    """The metrics of a run evaluate the static grasp force of the held object (its weight
    shared by the two fingers, the moment of its CoG offset): it must be in the solver's range
    (a mass of 1e-300 kg is not; the run itself would simulate and fail there). ``field``
    names where the mass comes from."""
    from .._controller import static_grasp_force

    mass = float(cfg.object.mass)
    if not (math.isfinite(mass) and mass > 0.0):
        raise CampaignError(f"{field}: {mass:g} kg; must be finite and > 0")
    ft = 0.5 * mass * G
    tau = 0.5 * mass * G * abs(float(cfg.object.cog[0]))
    try:
        static_grasp_force(cfg.contact, ft, tau, 1.0)
    except ValueError as err:
        raise CampaignError(f"{field}: {mass:g} kg gives a load whose static grasp force is "
                            f"outside what the run's metrics can evaluate ({_one_line(err)})"
                            ) from None


def _build(campaign: Campaign, values: dict[str, float], controllers) -> None:
    """Build the grasp of ``values`` for each of ``controllers`` (raises what a run would)."""
    from ..sim.plant import make_plant
    from ..sim.scenarios import Scenario, simulate
    from .definition import _controller_call

    scn, _ = Campaign.run_scenario(_Drawn(campaign, values), 0)
    cfg = scn.plant_config(campaign.plant)
    _check_load(cfg, f"parameters.mass = {values['mass']:g}" if "mass" in values
                else "the base scenario's plant.object.mass")
    plant = make_plant(campaign.plant)
    plant.reset(scn, config=cfg)  # the plant (an engine: its scene) is built and checked
    scn.estimator_for(campaign.plant)
    if not callable(getattr(plant, "closed_loop", None)):
        return  # an engine's run costs seconds: its build is the check
    for name in controllers:
        kind, ctrl, obs, opts = _controller_call(name, campaign.controllers[name], scn)
        s = Scenario.from_dict(scn.to_dict() | {"controller": ctrl, "observer": obs,
                                                "duration": CHECK_DURATION}, scn.source)
        simulate(s, cfg, campaign.plant, s.schedule if kind == "lugrip" else None, kind=kind,
                 **opts)


def validate_campaign(campaign: Campaign) -> None:
    """Raise CampaignError (file and field named) when a run of ``campaign`` would fail for a
    reason in its definition; see the module docstring for what is built."""
    where = str(campaign.source) if campaign.source else "campaign"
    if campaign.seed >= 2**63:  # stored in the results' int64 column (it failed there)
        raise CampaignError(f"{where}: seed: an integer of {campaign.seed.bit_length()} bits; "
                            "must be < 2**63 (the results store it as a 64-bit integer)")
    base = campaign.base_scenario()
    duration = float(base.duration)
    if not (math.isfinite(duration) and duration > 0.0):
        raise CampaignError(f"{where}: duration: {duration:g} s; must be finite and > 0")
    values = campaign.draw(0)
    try:
        _build(campaign, values, list(campaign.controllers))
    except CampaignError as err:
        raise CampaignError(f"{where}: {err}") from None
    except Exception as err:  # noqa: BLE001 (whatever the simulator raises names the problem)
        raise CampaignError(f"{where}: run 0 cannot be simulated (scenario, overrides, "
                            f"estimator or controllers): {_one_line(err)}") from None
    first = [next(iter(campaign.controllers))]
    for name, dist in campaign.parameters.items():
        lo, hi = dist.support()
        for which, v in (("low", lo), ("high", hi)):
            if not math.isfinite(v) or v == values[name]:
                continue
            trial = values | {name: float(v)}
            if campaign.counted_pushes:
                if name == "push_count":  # that many pushes, drawn as a run would draw them
                    trial.update(campaign._draw_pushes(campaign.draw_seed, 0, int(v)))
                elif name in PUSH_PARAMETERS:  # every push of run 0 at the bound
                    for k in range(campaign.max_pushes):
                        if trial.get(f"{name}_{k}") is not None:
                            trial[f"{name}_{k}"] = float(v)
            try:
                _build(campaign, trial, first)
            except CampaignError as err:
                raise CampaignError(f"{where}: {err} (the {which} bound of parameters.{name})"
                                    ) from None
            except Exception as err:  # noqa: BLE001
                raise CampaignError(f"{where}: parameters.{name}: the grasp at its {which} "
                                    f"bound {v:g} cannot be simulated: {_one_line(err)}") from None
