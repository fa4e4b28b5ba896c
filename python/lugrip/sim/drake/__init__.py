"""Drake as an independent grasp engine: a parallel gripper whose two pads are compliant-
hydroelastic (the contact patch carries a pressure field, so the limit surface emerges from the
engine), its plant for lugrip's closed loop (:mod:`lugrip.sim.drake.plant`) and a rubbing rig
for identification (:mod:`lugrip.sim.drake.rig`).

Needs the ``drake`` package (``pip install "lugrip[drake]"``); importing this package does not
import Drake, building a model does.
"""

from .pad import DrakePad

__all__ = ["DrakePad"]
