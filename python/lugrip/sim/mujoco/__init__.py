"""MuJoCo building blocks shared by the project's MuJoCo models: the compliant fingertip pad
(:mod:`lugrip.sim.mujoco.pad`), its contact options, torsional-friction law and sensor.

Needs MuJoCo 3.x (``pip install "lugrip[validation]"``); importing this package does not import
MuJoCo, :class:`Pad` does when it is built.
"""

from .pad import (
    CONTACT_OPTIONS,
    FingertipSensor,
    Pad,
    PadSpec,
    contact_options_xml,
    model_xml,
    pad_body_xml,
    pair_xml,
)

__all__ = [
    "CONTACT_OPTIONS",
    "FingertipSensor",
    "Pad",
    "PadSpec",
    "contact_options_xml",
    "model_xml",
    "pad_body_xml",
    "pair_xml",
]
