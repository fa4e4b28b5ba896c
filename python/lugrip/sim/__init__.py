"""Grasp simulation: the planar grasp plant (distributed-contact or lumped slider), gripper
actuator, fingertip sensors, robot moves and disturbances (MODEL.md 10). The loops run in C++.

    >>> from lugrip.sim import GraspPlant, PlantConfig
    >>> plant = GraspPlant({"contact": "aluminium_can",
    ...                     "object": {"mass": 0.4, "inertia": 4e-4, "cog": [0.0, -0.03]},
    ...                     "actuator": {"f_init": 8.0}})
    >>> log = plant.run(2.0)            # open loop, 2 s, arrays at 500 Hz
    >>> float(log.max_slip[-1]) < 1e-4
    True
"""

from ._plant import (
    ActuatorConfig,
    Disturbance,
    DropConfig,
    GraspPlant,
    GripperMove,
    ObjectConfig,
    PatchContact,
    PatchSettings,
    PlantConfig,
    PlantLog,
    SensorConfig,
    lift,
)

__all__ = [
    "ActuatorConfig",
    "Disturbance",
    "DropConfig",
    "GraspPlant",
    "GripperMove",
    "ObjectConfig",
    "PatchContact",
    "PatchSettings",
    "PlantConfig",
    "PlantLog",
    "SensorConfig",
    "lift",
]
