"""Rubbing rigs: plants written from their own physics (not from lugrip's model equations)
that a robot would rub against a fingertip, producing sliding logs with ground truth.

* :mod:`lugrip.rigs.motion`: the prescribed-motion design (:class:`RubbingDesign`,
  :func:`plan_maneuvers`) every rig is driven with;
* :mod:`lugrip.rigs._data`: the common result types (:class:`RubbingData`,
  :class:`RigTruth`);
* :mod:`lugrip.rigs.grid`: a distributed grid-of-cells LuGre contact (Stribeck friction,
  Hertzian pressure, optional viscous shear);
* :mod:`lugrip.rigs.model_rigs`: lugrip's lumped model and the simulator's pressure patch
  under the same prescribed motion (for comparison);
* :mod:`lugrip.rigs.mujoco_rig`: a MuJoCo pad rubbing a fixed slider (needs ``mujoco``).

See docs/rigs.md.
"""

from ._data import PHASES, RigTruth, RubbingData
from .motion import ManeuverPlan, RubbingDesign, plan_maneuvers, stack_times
from .grid import GridContactRig
from .registry import PLANTS, make_rig

__all__ = [
    "GridContactRig",
    "PHASES",
    "PLANTS",
    "ManeuverPlan",
    "RigTruth",
    "RubbingData",
    "RubbingDesign",
    "make_rig",
    "plan_maneuvers",
    "stack_times",
]


def __getattr__(name: str):
    # the MuJoCo rig imports MuJoCo only when asked for
    if name == "MujocoRubbingRig":
        from .mujoco_rig import MujocoRubbingRig

        return MujocoRubbingRig
    raise AttributeError(f"module 'lugrip.rigs' has no attribute {name!r}")
