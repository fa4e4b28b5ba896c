"""lugrip: model-based slip detection, slip avoidance and pivoting for parallel grippers with
force/torque fingertips (limit surface + revisited LuGre friction, docs/model.md).

The real-time core is C++17 (``lugrip._core``); this package is numpy in, numpy out.

Parameters and the observer they belong to: ``lugrip identify`` (:func:`identify`,
:meth:`IdentificationResult.save_yaml`) writes the identified :class:`ContactParams` together
with the settings of the observer inside its cost as an ``observer:`` block of the YAML.
:func:`read_observer_settings` returns that block as keywords of :class:`Observer` (None for
files without it, e.g. ``objects/*.yaml``), and ``Observer("fit.yaml")`` starts from it
(keywords given to Observer override it), so the observer run online is the one the
parameters were identified for.
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
from ._observer import read_observer_settings
from ._params import PRESETS, ContactParams
from ._controller import (
    PAPER_SETTINGS,
    ControllerMode,
    GraspController,
    PivotEnd,
    controller_settings,
    static_grasp_force,
    static_slippage,
)
from ._slip_control import SlipControl, SlipControlRun
from .io import LogError, LogWarning, SlidingLog, read_log, write_log
from .sim.sliding import simulate_sliding

# lugrip.identify is the function; its subpackage is lugrip.identification
from .identification import (
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
    "read_observer_settings",
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
    "PAPER_SETTINGS",
    "static_grasp_force",
    "static_slippage",
    "SlipControl",
    "SlipControlRun",
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
