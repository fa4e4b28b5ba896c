"""Judging a scenario's runs: each criterion of the file against the metrics of lugrip's run
and its baselines, the cross-scenario criteria, and the survival test of the constant-force
search."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any


from . import faults as _faults
from .scenario_file import Scenario


def _survives(
    scenario: Scenario, metrics: Mapping[str, Any], reference: Mapping[str, Any] | None = None
) -> bool:
    """The run held the object: no drop, finite, hold slip/rotation within the criteria and,
    given the `reference` run (lugrip without pivoting), a whole-run slip and rotation at most
    the reference's plus the same limits (a baseline must hold the object at least as well as
    lugrip, including the lift; otherwise a weak constant force "survives" by letting the object
    swing into a pose with less torque)."""
    c = scenario.criteria
    slip_lim = float(c.get("max_hold_slip_mm", 1.0))
    rot_lim = float(c.get("max_hold_rotation_deg", 1.0))
    ok = (
        not metrics["dropped"]
        and metrics["finite"]
        and metrics["hold_slip_mm"] <= slip_lim
        and metrics["hold_rotation_deg"] <= rot_lim
    )
    if ok and reference is not None:
        ok = (
            metrics["max_slip_mm"] <= reference["max_slip_mm"] + slip_lim
            and metrics["max_rotation_deg"] <= reference["max_rotation_deg"] + rot_lim
        )
    return ok


def _criterion(value, limit, ok) -> dict[str, Any]:
    return {"value": value, "limit": limit, "pass": None if ok is None else bool(ok)}


def _evaluate(scenario: Scenario, metrics: dict[str, dict[str, Any]], search) -> dict[str, dict]:
    c = scenario.criteria
    m = metrics["lugrip"]
    out: dict[str, dict] = {}
    for name, limit in c.items():
        fault = _faults.evaluate(name, limit, m)
        if fault is not None:
            out[name] = fault
        elif name == "no_drop":
            out[name] = _criterion(m["dropped"], False, not m["dropped"])
        elif name == "no_nan":
            ok = all(mm["finite"] for mm in metrics.values())
            out[name] = _criterion(ok, True, ok)
        elif name == "command_in_limits":
            out[name] = _criterion(m["command_in_limits"], True, m["command_in_limits"])
        elif name == "max_hold_slip_mm":
            out[name] = _criterion(m["hold_slip_mm"], limit, m["hold_slip_mm"] <= float(limit))
        elif name == "max_hold_rotation_deg":
            out[name] = _criterion(
                m["hold_rotation_deg"], limit, m["hold_rotation_deg"] <= float(limit)
            )
        elif name == "steady_slippage":
            v = m.get("steady_slippage")
            out[name] = _criterion(v, list(limit), v is not None and limit[0] <= v <= limit[1])
        elif name == "steady_force_range":
            v = m.get("steady_force")
            out[name] = _criterion(v, list(limit), v is not None and limit[0] <= v <= limit[1])
        elif name == "static_force_tolerance":
            v = m.get("steady_over_static")
            ok = v is not None and abs(v - 1.0) <= float(limit)
            out[name] = _criterion(v, limit, ok)
        elif name == "pivot_final_hang_deg":
            v = m.get("final_hang_deg")
            out[name] = _criterion(v, limit, v is not None and v <= float(limit))
        elif name == "pivot_returns_to_avoidance":
            v = m.get("returned_to_avoidance", False)
            out[name] = _criterion(v, True, v)
        elif name == "force_ratio":
            out[name] = _criterion(None, dict(limit), None)  # filled by evaluate_cross
        elif name == "constant_force_exceeds_steady":
            f = None if search is None else search["force"]
            steady = metrics.get("lugrip_no_pivot", m).get("steady_force")
            ok = None if search is None else (f is None or (steady is not None and f > steady))
            if limit == "group":  # one constant force for the whole group: filled by evaluate_cross
                ok = None
            out[name] = _criterion(
                {"constant_force": f, "lugrip_steady_force": steady},
                "group constant > steady" if limit == "group" else "constant > steady",
                ok,
            )
        elif name == "scene_ok":
            st = m.get("scene_status", "ok")
            out[name] = _criterion(st, "ok", st == "ok")
        elif name == "max_steady_command_ptp":
            v = m.get("steady_command_ptp_ratio")
            out[name] = _criterion(v, limit, v is not None and v <= float(limit))
        elif name == "mean_force_below_constant":
            f = None if search is None else search["force"]
            mean = metrics.get("lugrip_no_pivot", m).get("mean_force")
            ok = None if search is None else (f is None or (mean is not None and mean < f))
            out[name] = _criterion(
                {"mean_force": mean, "constant_force": f}, "mean < constant", ok
            )
        elif name == "friction_cone_fails":
            cone = metrics.get("friction_cone")
            hold = metrics.get("lugrip_no_pivot", m)
            if cone is None:
                out[name] = _criterion(None, True, None)
            else:
                cone_fails = not _survives(scenario, cone, hold)
                lugrip_holds = _survives(scenario, hold)
                out[name] = _criterion(
                    {
                        "friction_cone_fails": cone_fails,
                        "lugrip_holds": lugrip_holds,
                        "cone_dropped": cone["dropped"],
                        "cone_hold_slip_mm": cone["hold_slip_mm"],
                        "cone_max_rotation_deg": cone["max_rotation_deg"],
                    },
                    "cone fails, lugrip holds",
                    cone_fails and lugrip_holds,
                )
    return out


def evaluate_cross(results: Mapping[str, Any] | Sequence[Any]) -> None:
    """Fill the cross-scenario criteria of results whose partners ran too: ``force_ratio``
    (steady force / the reference scenario's) and ``constant_force_exceeds_steady: group`` (a
    constant-force gripper does not know which object of the group it holds: the constant force
    that survives every member, i.e. the largest of their minima, against each member's steady
    force)."""
    by_name = {r.name: r for r in (results.values() if isinstance(results, Mapping) else results)}
    groups: dict[str, list[Any]] = {}
    for r in by_name.values():
        if r.scenario.group:
            groups.setdefault(r.scenario.group, []).append(r)
    for r in by_name.values():
        if r.scenario.criteria.get("constant_force_exceeds_steady") != "group" or r.search is None:
            continue
        members = groups.get(r.scenario.group, [r])
        forces = [x.search["force"] if x.search is not None else None for x in members]
        crit = r.criteria["constant_force_exceeds_steady"]
        steady = crit["value"]["lugrip_steady_force"]
        if any(f is None for f in forces) or steady is None:
            group_force = None
            ok = None if any(x.search is None for x in members) else True
        else:
            group_force = max(forces)
            ok = group_force > steady
        crit["value"] = dict(
            crit["value"], group_constant_force=group_force, group=[x.name for x in members]
        )
        crit["pass"] = ok
    for r in by_name.values():
        spec = r.scenario.criteria.get("force_ratio")
        if spec is None:
            continue
        ref = by_name.get(spec["reference"])
        own = r.metrics["lugrip"].get("steady_force")
        if ref is None or own is None:
            r.criteria["force_ratio"] = _criterion(None, dict(spec), None)
            continue
        other = ref.metrics["lugrip"].get("steady_force")
        ratio = own / other if other else math.inf
        r.criteria["force_ratio"] = _criterion(ratio, dict(spec), ratio >= float(spec["min"]))
