"""Randomized grasp campaigns: many grasps drawn from stated distributions (object, contact,
pushes, sensors, controller-plant mismatch), every controller on each, run on a local process
pool or Ray, streamed to Parquet (resumable), reported with success rates and intervals, failure
maps and the worst runs (see docs/campaigns.md).

    >>> from lugrip.campaign import load_campaign, run_campaign, write_report
    >>> c = load_campaign("campaigns/patch_blocks.yaml")
    >>> run_campaign(c, runs=20, out="out/campaign", workers=2)   # doctest: +SKIP
    >>> write_report("out/campaign", c)                            # doctest: +SKIP
"""

from .definition import (
    CONTROLLERS,
    CRITERIA,
    DISTRIBUTIONS,
    PARAMETERS,
    Campaign,
    CampaignError,
    Distribution,
    load_campaign,
)
from .replay import load_results_campaign, replay
from .report import summarise, wilson, write_report
from .runner import BACKENDS, ResultStore, run_campaign, run_one

__all__ = [
    "BACKENDS",
    "CONTROLLERS",
    "CRITERIA",
    "DISTRIBUTIONS",
    "PARAMETERS",
    "Campaign",
    "CampaignError",
    "Distribution",
    "ResultStore",
    "load_campaign",
    "load_results_campaign",
    "replay",
    "run_campaign",
    "run_one",
    "summarise",
    "wilson",
    "write_report",
]
