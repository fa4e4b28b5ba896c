"""Grasp simulation: the planar grasp plant (distributed-contact or lumped slider), gripper
actuator, fingertip sensors, robot moves and disturbances (docs/model.md 10), and the closed loop with
the observers and the grasp-force controller or a baseline (``run_closed_loop``; the paper's
experiments as scenarios in :mod:`lugrip.sim.scenarios`). The loops run in C++.

    >>> from lugrip.sim import GraspPlant, PlantConfig
    >>> plant = GraspPlant({"contact": "aluminium_can",
    ...                     "object": {"mass": 0.4, "inertia": 4e-4, "cog": [0.0, -0.03]},
    ...                     "actuator": {"f_init": 8.0}})
    >>> log = plant.run(2.0)            # open loop, 2 s, arrays at 500 Hz
    >>> float(log.max_slip[-1]) < 1e-4
    True
"""

from ._closed_loop import ClosedLoopRun, closed_loop_config, estimator_params, run_closed_loop
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
    "ClosedLoopRun",
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
    "closed_loop_config",
    "estimator_params",
    "lift",
    "run_closed_loop",
]
