"""``lugrip.sliding``: the synthetic sliding maneuvers and their scoring, kept importable under
this name because examples, scripts and the metadata of logs written by earlier versions
(``generator: lugrip.sliding.simulate_maneuvers``) name it. The simulator lives in
:mod:`lugrip.sim.sliding`; this module re-exports it."""

from .sim.sliding import *  # noqa: F403
from .sim.sliding import __all__  # noqa: F401
