"""Sensor and actuator faults in the closed loop: the scenarios' ``faults:`` block, the metrics
of a faulty run and the report row per fault.

A scenario's ``faults:`` block::

    faults:
      inject:                        # lugrip._core.FaultSpec fields (sim._closed_loop.fault_specs)
        - {kind: nan_burst, finger: -1, t_start: 6.0, duration: 2.0, burst: 20, every: 200}
      stuck_samples: 25              # SlipControl's frozen-sensor check (0: off; default:
                                     # SlipControl's, 25)
      healthy_finger_fallback: false # one faulty finger: the other computes the command
      expect_status: [invalid_sample, sensor_fault]  # statuses that count as "fault raised"
      onset: 6.0                     # [s] default: the earliest t_start of `inject`

The faults act on what the observers read (sensor faults) or on what the gripper receives
(actuator faults); the plant itself never changes. The metrics (:func:`fault_metrics`):

* ``fault_status_latency``: samples from the onset to the first cycle whose status is one of
  ``expect_status`` (None: never raised; a fault that no status can reveal lists none);
* ``fault_min_command`` / ``fault_min_force``: the smallest command from the onset on and the
  force at which the object starts to slip under the true loads just before the onset
  (``static_grasp_force`` with S = 1);
* ``fault_command_lowered``: the largest decrease of the command between consecutive samples
  whose cycle status is not valid (0 when every flagged cycle held the command); with
  ``healthy_finger_fallback`` only samples where neither finger has a valid estimate count.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from .. import _core
from .._controller import static_grasp_force
from ._closed_loop import ClosedLoopRun, fault_specs

__all__ = ["FAULT_CRITERIA", "STATUS_CODES", "fault_block", "fault_metrics", "fault_table"]

#: Status names accepted in ``expect_status`` (include/lugrip/status.hpp codes).
STATUS_CODES = {
    "ok": 0,
    "saturated": 1,
    "degenerate": 2,
    "no_contact": 3,
    "invalid_sample": 4,
    "sensor_fault": 5,
    "reinitialized": 6,
}
_VALID = (0, 1, 2, 6)

#: Criteria of the fault scenarios (merged into sim.scenarios.CRITERIA).
FAULT_CRITERIA = {
    "fault_status_within": (
        "a status of the faults block's expect_status is raised within limit samples of the "
        "fault onset"
    ),
    "fault_command_floor": (
        "min command from the fault onset on / the force at which the object starts to slip "
        "(true loads before the onset, S = 1) >= limit"
    ),
    "fault_command_held": (
        "while the cycle status is not valid (with healthy_finger_fallback: while neither finger "
        "is valid) the command is never lowered (largest decrease between such samples <= 1e-9 N)"
    ),
}

_BLOCK_KEYS = {"inject", "stuck_samples", "expect_status", "onset", "healthy_finger_fallback"}


def fault_block(value: Any, where: str) -> dict:
    """The validated ``faults:`` block (empty dict when absent or empty)."""
    if value is None or (isinstance(value, Mapping) and not value):
        return {}
    if not isinstance(value, Mapping):
        raise ValueError(f"{where}: faults: expected a mapping with 'inject'")  # noqa: TRY004 (file content)
    unknown = sorted(set(value) - _BLOCK_KEYS)
    if unknown:
        raise ValueError(f"{where}: faults: unknown key(s) {', '.join(map(str, unknown))}")
    d = copy.deepcopy(dict(value))
    inject = d.get("inject") or []
    if not isinstance(inject, Sequence) or isinstance(inject, (str, bytes)) or not inject:
        raise ValueError(f"{where}: faults.inject: expected a non-empty list of faults")
    try:
        specs = fault_specs(inject)
    except ValueError as err:
        raise ValueError(f"{where}: faults.{err}") from None
    # the C++ checks of the fault fields, now (a default config: only its fault lines count)
    probe = _core.ClosedLoopConfig()
    for f in specs:
        probe.add_fault(f)
    bad = [
        x for x in _core.validate_closed_loop_config(probe).splitlines() if x.startswith("faults")
    ]
    if bad:
        raise ValueError(f"{where}: {bad[0]}")
    stuck = d.get("stuck_samples", _core.SlipControlSettings().stuck_samples)
    if isinstance(stuck, bool) or not isinstance(stuck, int) or stuck < 0:
        raise ValueError(f"{where}: faults.stuck_samples = {stuck!r}: must be an integer >= 0")
    expect = d.get("expect_status") or []
    if isinstance(expect, str):
        expect = [expect]
    for e in expect:
        if str(e) not in STATUS_CODES or STATUS_CODES[str(e)] in _VALID:
            raise ValueError(
                f"{where}: faults.expect_status {e!r}: expected among no_contact, "
                "invalid_sample, sensor_fault"
            )
    d["expect_status"] = [str(e) for e in expect]
    onset = d.get("onset")
    if onset is None:
        onset = min(float(f.get("t_start", 0.0)) for f in inject)
    if isinstance(onset, bool) or not isinstance(onset, (int, float)) or not math.isfinite(onset):
        raise ValueError(f"{where}: faults.onset = {onset!r}: must be a finite number [s]")
    d["onset"] = float(onset)
    d["stuck_samples"] = int(stuck)
    fallback = d.get("healthy_finger_fallback", False)
    if not isinstance(fallback, bool):
        raise ValueError(  # noqa: TRY004 (file content)
            f"{where}: faults.healthy_finger_fallback = {fallback!r}: must be true or false"
        )
    d["healthy_finger_fallback"] = fallback
    d["inject"] = [dict(f) for f in inject]
    return d


def fault_metrics(block: Mapping[str, Any], run: ClosedLoopRun, cfg) -> dict[str, Any]:
    """Metrics of a run with injected faults (see the module docstring)."""
    t = run["t"]
    onset = float(block["onset"])
    i0 = run.index(onset)
    if t[i0] < onset - 1e-9 and i0 + 1 < len(t):
        i0 += 1
    status = np.asarray(run["status"], dtype=int)
    expect = [STATUS_CODES[e] for e in block.get("expect_status", [])]
    latency = None
    if expect:
        hit = np.flatnonzero(np.isin(status[i0:], expect))
        latency = int(hit[0]) if hit.size else None
    # force at which the object starts to slip, from the true loads over 1 s before the onset
    pre = run.window(max(onset - 1.0, 0.0), onset)
    min_force = None
    if pre.stop > pre.start:
        ft = float(np.mean(0.5 * (run["f_t_true_0"][pre] + run["f_t_true_1"][pre])))
        tau = float(
            np.mean(0.5 * (np.abs(run["tau_true_0"][pre]) + np.abs(run["tau_true_1"][pre])))
        )
        min_force = float(static_grasp_force(cfg.contact, ft, tau, 1.0))
    cmd = np.asarray(run["command"], dtype=float)
    after = cmd[i0:]
    flagged = ~np.isin(status, _VALID)
    if block.get("healthy_finger_fallback"):
        # one faulty finger: the other one drives the command; held only when neither is valid
        for k in (0, 1):
            flagged &= ~np.isin(np.asarray(run[f"observer_status_{k}"], dtype=int), _VALID)
    drops = np.diff(cmd)
    lowered = drops[flagged[1:] & flagged[:-1]]
    counts = {
        name: int(np.sum(status[i0:] == code))
        for name, code in STATUS_CODES.items()
        if code not in _VALID and np.any(status[i0:] == code)
    }
    return {
        "fault_kinds": [str(f["kind"]) for f in block["inject"]],
        "fault_onset": onset,
        "fault_samples": int(np.sum(run["fault_active"])),
        "fault_expect_status": list(block.get("expect_status", [])),
        "fault_status_latency": latency,
        "fault_status_counts": counts,
        "fault_min_command": float(np.min(after)) if after.size else None,
        "fault_min_force": min_force,
        "fault_command_floor": (
            float(np.min(after)) / min_force if after.size and min_force else None
        ),
        "fault_command_lowered": float(max(0.0, -np.min(lowered))) if lowered.size else 0.0,
        "fault_max_actuator_gap": float(np.max(np.abs(cmd - run["actuator_command"]))),
    }


def evaluate(name: str, limit: Any, m: Mapping[str, Any]) -> dict[str, Any] | None:
    """{value, limit, pass} of a fault criterion (None: not a fault criterion)."""
    if name == "fault_status_within":
        v = m.get("fault_status_latency")
        return {"value": v, "limit": limit, "pass": v is not None and v <= int(limit)}
    if name == "fault_command_floor":
        v = m.get("fault_command_floor")
        return {"value": v, "limit": limit, "pass": v is not None and v >= float(limit)}
    if name == "fault_command_held":
        v = m.get("fault_command_lowered")
        return {"value": v, "limit": 1e-9, "pass": v is not None and v <= 1e-9}
    return None


def fault_table(results) -> str:
    """Markdown table, one row per fault scenario (results whose metrics carry fault metrics)."""
    rows = [
        (
            "| scenario | faults | expected status | status latency [samples] | statuses raised "
            "| dropped | hold slip [mm] | hold rotation [°] | min command [N] | slip force [N] "
            "| min command / slip force | pass |"
        ),
        "|" + "---|" * 12,
    ]
    for r in results:
        m = r.metrics.get("lugrip", {})
        if "fault_onset" not in m:
            continue
        lat = m["fault_status_latency"]
        expect = ", ".join(m["fault_expect_status"]) or "none (not observable)"
        raised = ", ".join(f"{k} ×{v}" for k, v in m["fault_status_counts"].items()) or "—"
        floor = m.get("fault_command_floor")
        rows.append(
            f"| {r.name} | {', '.join(m['fault_kinds'])} | {expect} "
            f"| {'—' if lat is None else lat} | {raised} | {'yes' if m['dropped'] else 'no'} "
            f"| {m['hold_slip_mm']:.3f} | {m['hold_rotation_deg']:.3f} "
            f"| {m['fault_min_command']:.2f} "
            f"| {'—' if m['fault_min_force'] is None else format(m['fault_min_force'], '.2f')} "
            f"| {'—' if floor is None else format(floor, '.2f')} "
            f"| {'pass' if r.passed else 'FAIL'} |"
        )
    return "\n".join(rows) if len(rows) > 2 else ""
