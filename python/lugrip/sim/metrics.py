"""The metrics of a closed-loop run of a scenario (slip and rotation in the hold phases, forces,
the pivot, faults; docs/model.md 10), for every plant."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from .._controller import controller_settings, static_grasp_force
from . import faults as _faults
from ._closed_loop import ClosedLoopRun
from ._plant import PlantConfig
from .scenario_file import Scenario


def _axis_deg(run: ClosedLoopRun, cfg: PlantConfig) -> np.ndarray:
    """Angle of the object's grasp-point -> CoG axis (object frame, fixed) from the downward
    vertical [deg], wrapped to (-180, 180]."""
    cx, cy = cfg.object.cog
    a = np.degrees(run["theta"] + math.atan2(cy, cx)) + 90.0
    return (a + 180.0) % 360.0 - 180.0


def _hold_increment(run: ClosedLoopRun, phases, lumped: bool) -> tuple[float, float]:
    """Max slip [mm] and rotation [deg] relative to the pose at each phase start."""
    slip = rot = 0.0
    for t0, t1 in phases:
        sl = run.window(t0, t1)
        if sl.stop <= sl.start:
            continue
        i0 = sl.start
        if lumped:
            ds = run["slip"][sl] - run["slip"][i0]
        else:
            ds = np.hypot(
                run["slip_x"][sl] - run["slip_x"][i0], run["slip_y"][sl] - run["slip_y"][i0]
            )
        slip = max(slip, float(np.max(np.abs(ds))) * 1e3)
        rot = max(rot, float(np.degrees(np.max(np.abs(run["rotation"][sl] - run["rotation"][i0])))))
    return slip, rot


def compute_metrics(
    scenario: Scenario,
    run: ClosedLoopRun,
    *,
    cfg: PlantConfig | None = None,
    controller: Mapping[str, Any] | None = None,
    pivot: bool = True,
) -> dict[str, Any]:
    """Metrics of one run: slip and rotation (lift and hold), forces (peak, steady, static
    references), pivoting, drop, finiteness. Forces per finger [N]."""
    cfg = cfg or scenario.plant_config()
    ctrl = dict(controller if controller is not None else scenario.controller)
    defaults = controller_settings()
    f_min = float(ctrl.get("f_min", defaults["f_min"]))
    f_max = float(ctrl.get("f_max", defaults["f_max"]))
    s_ref = float(ctrl.get("s_ref", defaults["s_ref"]))
    t = run["t"]
    end = float(t[-1]) + (t[1] - t[0] if len(t) > 1 else 0.0)
    hold = scenario.hold_time
    lumped = cfg.model == "lumped"
    m: dict[str, Any] = {}

    # pivoting manoeuvre (lugrip with a pivot in the schedule)
    pivot_t = [
        float(e["time"]) for e in scenario.schedule if str(e.get("action", "")).startswith("pivot")
    ]
    pivoting = pivot and bool(pivot_t) and bool(np.any(run["mode"] == 1))
    phases = [(hold, end)]
    if pivoting:
        p0 = pivot_t[0]
        fin = np.flatnonzero(run["pivot_finished"])
        fin = fin[t[fin] >= p0]
        p1 = float(t[fin[0]]) if fin.size else math.inf
        reason = int(run["pivot_end"][fin[0]]) if fin.size else 0
        phases = [(hold, p0)] + ([(p1, end)] if math.isfinite(p1) else [])
        axis = _axis_deg(run, cfg)
        # the hang the pivot left: at the end, or before a later wrist roll (MuJoCo plant) tilts
        # the held object with the hand
        i_hang = len(t) - 1
        if "roll" in run:
            rolls = [
                float(w["t_start"])
                for w in scenario.mujoco.get("wrist") or []
                if float(w.get("roll_deg", 0.0)) != 0.0
            ]
            if rolls:
                i_hang = max(run.index(min(rolls)) - 1, 0)
        m.update(
            pivot_start=p0,
            pivot_end=p1 if math.isfinite(p1) else None,
            pivot_duration=(p1 - p0) if math.isfinite(p1) else None,
            pivot_end_reason={
                0: "none", 1: "cor_threshold", 2: "timeout", 3: "requested", 4: "at_floor"
            }[reason],
            pivot_rotation_deg=float(np.degrees(run["theta"][-1] - run["theta"][run.index(p0)])),
            final_hang_deg=float(abs(run.hang_deg[i_hang])),
            final_hang_time=float(t[i_hang]),
            final_axis_deg=float(abs(axis[-1])),
            initial_axis_deg=float(abs(axis[run.index(p0)])),
            final_mode="slipping_avoidance" if int(run["mode"][-1]) == 0 else "pivoting",
            # ended by itself (hanging: c~ criterion, or held at the floor), then avoiding again
            returned_to_avoidance=bool(fin.size and reason in (1, 4) and int(run["mode"][-1]) == 0),
        )
    hold_slip, hold_rot = _hold_increment(run, phases, lumped)
    lift_slip, lift_rot = _hold_increment(run, [(scenario.lift_start, scenario.lift_end)], lumped)
    faulty = np.asarray(run["fault_active"], dtype=bool) if "fault_active" in run else None
    finite = all(
        np.all(np.isfinite(np.asarray(v, dtype=float))[~faulty])
        if faulty is not None and k.startswith(("f_n_meas", "f_t_meas", "tau_meas"))
        else np.all(np.isfinite(np.asarray(v, dtype=float)))
        for k, v in run.items()
    )
    cmd = run["command"]
    m.update(
        dropped=bool(run["dropped"][-1]),
        drop_time=float(t[np.argmax(run["dropped"] > 0)]) if run["dropped"][-1] else None,
        max_slip_mm=float(np.max(run["slip"]) * 1e3),
        max_rotation_deg=float(np.degrees(np.max(np.abs(run["rotation"])))),
        lift_slip_mm=lift_slip,
        lift_rotation_deg=lift_rot,
        hold_slip_mm=hold_slip,
        hold_rotation_deg=hold_rot,
        hold_phases=[[a, b] for a, b in phases],
        # after the lift starts (before it the command is the initial grasp force decaying)
        peak_force=float(np.max(cmd[run.window(scenario.lift_start, end)])),
        peak_normal_force=float(np.max(run["f_n"][run.window(scenario.lift_start, end)])),
        finite=bool(finite and np.all(run["finite"])),
        command_in_limits=bool(
            np.all(np.isfinite(cmd))
            and np.all(cmd >= f_min - 1e-12)
            and np.all(cmd <= f_max + 1e-12)
        ),
    )
    if "mu_belief" in run:  # the controller's friction belief, as told and at the end
        belief = np.asarray(run["mu_belief"], dtype=float)
        if belief.size and np.all(np.isfinite(belief)):
            m.update(mu_belief_start=float(belief[0]), mu_belief_end=float(belief[-1]))
    if scenario.steady_window is not None:
        sw = run.window(*scenario.steady_window)
        ft = float(np.mean(0.5 * (run["f_t_true_0"][sw] + run["f_t_true_1"][sw])))
        tau = float(np.mean(0.5 * (np.abs(run["tau_true_0"][sw]) + np.abs(run["tau_true_1"][sw]))))
        static = float(static_grasp_force(cfg.contact, ft, tau, s_ref))
        minimum = float(static_grasp_force(cfg.contact, ft, tau, 1.0))
        steady = float(np.mean(cmd[sw]))
        c_tilde = 0.5 * (np.abs(run["c_tilde_0"][sw]) + np.abs(run["c_tilde_1"][sw]))
        m.update(
            steady_window=list(scenario.steady_window),
            steady_force=steady,
            steady_slippage=float(np.mean(run.S[sw])),
            steady_c_tilde=float(np.mean(c_tilde)),
            steady_f_t=ft,
            steady_tau_nmm=tau * 1e3,
            static_force=static,
            min_force=minimum,
            steady_over_static=steady / static if static > 0 else None,
            steady_over_min=steady / minimum if minimum > 0 else None,
        )
        if sw.stop > sw.start:
            ptp = float(np.ptp(cmd[sw]))
            m.update(
                steady_command_ptp=ptp,
                steady_command_ptp_ratio=ptp / steady if steady > 0 else None,
            )
    hw = run.window(scenario.lift_start, end)
    if hw.stop > hw.start:
        m["mean_force"] = float(np.mean(run["f_n"][hw]))
        err = [run[f"omega_hat_{k}"][hw] - run[f"omega_true_{k}"][hw] for k in (0, 1)]
        m["omega_rmse"] = float(np.sqrt(np.mean(np.square(err))))
        m["omega_hat_peak"] = float(
            max(np.max(np.abs(run[f"omega_hat_{k}"][hw])) for k in (0, 1))
        )
        m["omega_true_peak"] = float(
            max(np.max(np.abs(run[f"omega_true_{k}"][hw])) for k in (0, 1))
        )
    scene = getattr(run, "scene", None)
    if scene and scenario.steady_window is not None:
        # the plant's own slip force for the steady loads of each finger: MuJoCo's elliptic cone
        from .mujoco.loop import cone_slip_force

        sw = run.window(*scenario.steady_window)
        if sw.stop > sw.start:
            m["min_force_plant"] = max(
                cone_slip_force(
                    cfg.contact,
                    float(np.mean(run[f"f_t_true_{k}"][sw])),
                    float(np.mean(np.abs(run[f"tau_true_{k}"][sw]))),
                )
                for k in (0, 1)
            )
    elif "min_force" in m:
        m["min_force_plant"] = m["min_force"]  # the patch follows lugrip's limit surface
    if scenario.faults:
        m.update(_faults.fault_metrics(scenario.faults, run, cfg))
    m["scene_status"] = scene["status"] if scene else "ok"
    if scene:
        m["scene"] = dict(scene)
    return m
