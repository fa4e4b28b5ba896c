"""Offline identification of the contact parameters (paper Section 4, docs/model.md §8) and the
per-object "rubbing" estimate of mu and beta_A (paper Section 6).

    >>> import lugrip
    >>> result = lugrip.identify(logs)                      # stages, then eq. 32
    >>> print(result.summary())                             # per stage: samples, findings
    >>> result.save_yaml("fingertip.yaml")
    >>> obj = lugrip.identify(object_logs, "fingertip.yaml", free=("mu", "beta_a"))

Without a start point the parameters come from stages, each from what the data carry
(modules: ``_phases`` still / loading / gross-sliding samples and the noise, ``_stages`` the
limit-surface + viscous fit and the presliding fit, ``_start`` the observability decision and
the prior); then the paper's eq. 32 refines them, regularised toward the stage values
(``_optimize``; ``_uncertainty`` sandwich standard errors; ``_result`` the result and YAML;
``_driver`` the sequence; docs/identification.md).

The eq. 32 cost and its exact gradient run in C++ over all maneuvers in parallel; the observer inside
the cost is the online one (:class:`lugrip.Observer`, default settings unless ``observer=`` is
given). The parameters are identified FOR that observer: the result records its settings
(``result.observer``, the ``observer:`` block of the YAML, :func:`read_observer_settings`) and
``lugrip observe --params`` runs with them.
"""

from .._observer import read_observer_settings
from ._common import (
    DEFAULT_BOUNDS,
    PARAMETERS,
    IdentifiabilityWarning,
    IdentificationError,
    IdentificationWarning,
)
from ._data import load_maneuvers
from ._driver import identify
from ._guess import InitialGuess, initial_guess
from ._result import IdentificationResult, ParameterEstimate
from ._rubbing import RubbingEstimate, estimate_rubbing
from ._start import StageEstimate

__all__ = [
    "DEFAULT_BOUNDS",
    "PARAMETERS",
    "IdentifiabilityWarning",
    "IdentificationError",
    "IdentificationResult",
    "IdentificationWarning",
    "InitialGuess",
    "ParameterEstimate",
    "RubbingEstimate",
    "StageEstimate",
    "estimate_rubbing",
    "identify",
    "initial_guess",
    "load_maneuvers",
    "read_observer_settings",
]
