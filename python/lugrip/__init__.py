"""lugrip: model-based slip detection, slip avoidance and pivoting for parallel grippers with
force/torque fingertips (limit surface + revisited LuGre friction, MODEL.md).

The real-time core is C++17 (``lugrip._core``); this package is numpy in, numpy out.
"""

from ._core import __version__
from ._contact import (
    CorEstimate,
    LimitSurface,
    Status,
    contact_radius,
    estimate_cor,
    g,
    normalized_wrench,
    shape_factor,
    sigma_1,
)
from ._observer import (
    Observability,
    Observer,
    ObserverRun,
    ObserverSample,
    SliderModel,
    SliderState,
    SliderTrajectory,
    observability,
    sensor_wrench,
)
from ._params import PRESETS, ContactParams
from ._controller import (
    ControllerMode,
    GraspController,
    PivotEnd,
    controller_settings,
    static_grasp_force,
    static_slippage,
)
from .io import LogError, LogWarning, SlidingLog, read_log, write_log
from .sliding import simulate_sliding

# lugrip.identify is the function (the subpackage stays importable: from lugrip.identify import ...)
from .identify import (
    IdentificationError,
    IdentificationResult,
    RubbingEstimate,
    estimate_rubbing,
    identify,
)

__all__ = [
    "__version__",
    "ContactParams",
    "PRESETS",
    "LimitSurface",
    "Status",
    "CorEstimate",
    "estimate_cor",
    "contact_radius",
    "g",
    "sigma_1",
    "normalized_wrench",
    "shape_factor",
    "GraspController",
    "ControllerMode",
    "PivotEnd",
    "controller_settings",
    "static_grasp_force",
    "static_slippage",
    "SlidingLog",
    "LogError",
    "LogWarning",
    "read_log",
    "write_log",
    "Observer",
    "ObserverSample",
    "ObserverRun",
    "SliderModel",
    "SliderState",
    "SliderTrajectory",
    "Observability",
    "observability",
    "sensor_wrench",
    "simulate_sliding",
    "identify",
    "IdentificationResult",
    "IdentificationError",
    "estimate_rubbing",
    "RubbingEstimate",
]
