"""Campaign report: success rate per controller with Wilson intervals, paired comparison with
lugrip, the constant-force frontier (campaigns with ``frontier``), failure maps (success and
mean force against each drawn parameter), the worst runs with the command that replays each one.

Writes DIR/report.md, DIR/report.json, DIR/failure_map.png and, with the frontier,
DIR/frontier.png.
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from .definition import PARAMETERS, Campaign

__all__ = ["belief_summary", "frontier_rate", "frontier_summary", "summarise", "wilson",
           "write_report"]


def wilson(successes: int, n: int, z: float = 1.959964) -> tuple[float, float]:
    """Wilson score interval of a binomial proportion (default 95 %); (0, 1) for n = 0."""
    if n <= 0:
        return 0.0, 1.0
    p = successes / n
    den = 1.0 + z * z / n
    centre = (p + z * z / (2 * n)) / den
    half = z * math.sqrt(p * (1.0 - p) / n + z * z / (4 * n * n)) / den
    return max(0.0, centre - half), min(1.0, centre + half)


def frontier_rate(f_pass: Sequence[float | None], crush: Sequence[float | None],
                  forces: Sequence[float] | float,
                  fail_above: Sequence[float | None] | None = None) -> np.ndarray:
    """Success rate of a constant force F over the runs, for each F in `forces`: the fraction
    of runs with f_pass <= F <= crush and F < fail_above (f_pass: the run's smallest passing
    constant, None when none passes; crush: its crush force, None for no limit; fail_above: a
    larger force found to fail, None when none was). Success of a constant is taken as monotone
    in the force between f_pass and the first of those limits (runner.constant_frontier)."""
    n = len(f_pass)
    fp = np.array([math.inf if v is None else float(v) for v in f_pass], dtype=float)
    cr = np.array([math.inf if v is None else float(v) for v in crush], dtype=float)
    fa = np.array([math.inf if v is None else float(v) for v in (fail_above or [None] * n)],
                  dtype=float)
    f = np.atleast_1d(np.asarray(forces, dtype=float))
    if n == 0:
        return np.full(f.shape, np.nan)
    ok = (fp[None, :] <= f[:, None]) & (f[:, None] <= cr[None, :]) & (f[:, None] < fa[None, :])
    return ok.sum(axis=1) / n


def _run_rows(rows: Sequence[dict]) -> list[dict]:
    """One row per run (the run-level columns are the same on each of its rows)."""
    seen: dict[int, dict] = {}
    for r in rows:
        seen.setdefault(int(r["run"]), r)
    return [seen[k] for k in sorted(seen)]


def frontier_summary(rows: Sequence[dict], campaign: Campaign, summary: dict | None = None,
                     n_grid: int = 200) -> dict[str, Any] | None:
    """The constant-force frontier of stored rows: its curve (success rate against force on a
    grid and at every run's smallest passing constant), its maximum and where, and for each
    controller its success rate (Wilson 95 %), mean force, the success rate of the constant of
    the same mean force and the difference. None without frontier columns."""
    runs = _run_rows(rows)
    if not runs or "frontier_force" not in runs[0]:
        return None
    n = len(runs)
    fp = [r.get("frontier_force") for r in runs]
    cr = [r.get("crush_force") for r in runs]
    fa = [r.get("frontier_fail_above") for r in runs]
    from .._controller import controller_settings

    f_max = float(campaign.base_scenario().controller.get("f_max", controller_settings()["f_max"]))
    # Runs some constant under the crush force passes, with their smallest passing force. A
    # command that never exceeds a run's crush force grips it at most as hard as the constant at
    # that force, so where holding grows with the grip no controller passes the other runs: their
    # share bounds every controller's success from above (checked below: each controller's
    # successes on those runs).
    held_by = {int(r["run"]): float(v) for r, v, c in zip(runs, fp, cr)
               if v is not None and (c is None or v <= c)}
    passing = sorted(held_by.values())
    passable = set(held_by)
    out: dict[str, Any] = {
        "runs": n,
        "passable": len(passable),
        "passable_rate": len(passable) / n,
        "passable_wilson95": list(wilson(len(passable), n)),
        "f_max": f_max,
        "no_constant_passes": sum(v is None for v in fp),
        # a force above the smallest passing one failed: success is not monotone there
        "non_monotone": sum(v is not None for v in fa),
        "floor_passed": sum(bool(r.get("frontier_floor_passed")) for r in runs),
        "errors": sum(bool(r.get("frontier_error")) for r in runs),
        "evaluations_mean": float(np.mean([r.get("frontier_evaluations") or 0 for r in runs])),
    }
    if passing:
        at = np.asarray(passing)
        rates = frontier_rate(fp, cr, at, fa)
        k = int(np.argmax(rates))  # the smallest force reaching the maximum
        best = int(round(rates[k] * n))
        lo_grid = max(min(passing) / 1.5, 1e-3)
        grid = np.unique(np.concatenate([np.geomspace(lo_grid, f_max, n_grid), at]))
        out.update(
            max_rate=float(rates[k]),
            max_successes=best,
            max_force=float(at[k]),
            # selected after the fact: the interval is optimistic for the best constant
            max_wilson95=list(wilson(best, n)),
            curve={"force": grid.tolist(), "rate": frontier_rate(fp, cr, grid, fa).tolist()},
        )
    else:
        out.update(max_rate=0.0, max_successes=0, max_force=None, max_wilson95=list(wilson(0, n)),
                   curve={"force": [], "rate": []})
    points = {}
    for c, s in (summary or {}).items():
        mf = s.get("mean_force")
        same = float(frontier_rate(fp, cr, mf, fa)[0]) if mf is not None else None
        # paired, run by run: the controller against the constant of its own mean force
        held = {int(r["run"]): bool(r["success"]) for r in rows if r["controller"] == c}
        const = {} if mf is None else {
            int(r["run"]): bool(frontier_rate([r.get("frontier_force")], [r.get("crush_force")],
                                              mf, [r.get("frontier_fail_above")])[0])
            for r in runs
        }
        both = sorted(set(held) & set(const))
        points[c] = {
            "held_where_no_constant_passes": sum(ok for i, ok in held.items() if i not in passable),
            "paired_runs": len(both),
            "holds_constant_fails": sum(held[i] and not const[i] for i in both),
            "constant_holds_it_fails": sum(const[i] and not held[i] for i in both),
            "success_rate": s.get("success_rate"),
            "wilson95": s.get("wilson95"),
            "mean_force": mf,
            "constant_same_mean_force": same,
            "minus_constant_same_mean_force": (
                s["success_rate"] - same if same is not None and s.get("success_rate") is not None
                else None
            ),
            "minus_frontier_max": (
                s["success_rate"] - out["max_rate"] if s.get("success_rate") is not None else None
            ),
        }
    out["controllers"] = points
    # the simulated constant_force controller against the frontier's verdict for its force,
    # run by run: a direct check of the monotonicity the frontier assumes
    if "constant_force" in campaign.controllers:
        force = float(campaign.controllers["constant_force"]["force"])
        sim = {int(r["run"]): bool(r["success"]) for r in rows
               if r["controller"] == "constant_force"}
        verdict = {int(r["run"]): bool(frontier_rate([r.get("frontier_force")],
                                                     [r.get("crush_force")], force,
                                                     [r.get("frontier_fail_above")])[0])
                   for r in runs if not r.get("frontier_error")}
        both = sorted(set(sim) & set(verdict))
        out["constant_force_check"] = {
            "force": force,
            "runs": len(both),
            "agree": sum(sim[i] == verdict[i] for i in both),
            "disagree_runs": [i for i in both if sim[i] != verdict[i]],
        }
    return out


def _severity(row: dict, campaign: Campaign) -> float:
    """How badly a run failed: the largest of slip and rotation over their limits (inf for a
    drop, an error or a non-finite run)."""
    if row.get("error") or row.get("m_dropped") or not row.get("m_finite", True):
        return math.inf
    c = campaign.criteria
    s = (row.get("m_hold_slip_mm") or 0.0) / float(c.get("max_hold_slip_mm") or 1.0)
    r = (row.get("m_hold_rotation_deg") or 0.0) / float(c.get("max_hold_rotation_deg") or 1.0)
    return max(s, r)


def _bins(values: np.ndarray, n_bins: int) -> np.ndarray:
    """Bin edges with about the same number of runs in each (quantiles); fewer bins for
    few distinct values."""
    distinct = np.unique(values)
    if distinct.size <= n_bins:
        mids = 0.5 * (distinct[1:] + distinct[:-1])
        return np.concatenate([[distinct[0]], mids, [distinct[-1]]])
    return np.unique(np.quantile(values, np.linspace(0.0, 1.0, n_bins + 1)))


def summarise(rows: Sequence[dict], campaign: Campaign, *, out_dir: str | Path | None = None,
              n_bins: int = 5, worst: int = 5) -> dict[str, Any]:
    """The report's numbers (JSON-ready)."""
    controllers = [c for c in campaign.controllers if any(r["controller"] == c for r in rows)]
    runs = sorted({int(r["run"]) for r in rows})
    by = {(int(r["run"]), r["controller"]): r for r in rows}
    summary: dict[str, Any] = {}
    for c in controllers:
        rr = [by[(i, c)] for i in runs if (i, c) in by]
        ok = sum(bool(r["success"]) for r in rr)
        lo, hi = wilson(ok, len(rr))
        forces = [r["m_mean_force"] for r in rr if r.get("m_mean_force") is not None]
        held = [r["m_mean_force"] for r in rr if r["success"] and r.get("m_mean_force") is not None]
        over_min = [
            r["m_mean_force"] / r["min_static_force"] for r in rr
            if r["success"] and r.get("m_mean_force") is not None and r.get("min_static_force")
        ]
        fails: dict[str, int] = {}
        for r in rr:
            for k in campaign.criteria:
                if r.get(f"pass_{k}") is False:
                    fails[k] = fails.get(k, 0) + 1
        summary[c] = {
            "runs": len(rr),
            "successes": ok,
            "success_rate": ok / len(rr) if rr else None,
            "wilson95": [lo, hi],
            "mean_force": float(np.mean(forces)) if forces else None,
            "mean_force_successes": float(np.mean(held)) if held else None,
            # mean over the held runs of (the run's mean force / its minimum static force)
            "mean_force_over_min_static": float(np.mean(over_min)) if over_min else None,
            "crushed": sum(1 for r in rr if r.get("pass_no_crush") is False),
            "errors": sum(1 for r in rr if r.get("error")),
            "failed_criteria": fails,
        }
    paired = {}
    if "lugrip" in controllers:
        for c in controllers:
            if c == "lugrip":
                continue
            both = [i for i in runs if (i, "lugrip") in by and (i, c) in by]
            lug_only = sum(by[(i, "lugrip")]["success"] and not by[(i, c)]["success"] for i in both)
            other_only = sum(by[(i, c)]["success"] and not by[(i, "lugrip")]["success"] for i in both)
            paired[c] = {
                "runs": len(both),
                "lugrip_holds_other_fails": int(lug_only),
                "other_holds_lugrip_fails": int(other_only),
            }
    fmap: dict[str, Any] = {}
    for name in campaign.parameters:
        col = f"p_{name}"
        vals = np.array([by[(i, controllers[0])][col] for i in runs], dtype=float)
        if vals.size == 0 or np.ptp(vals) == 0.0:
            continue
        edges = _bins(vals, n_bins)
        idx = np.clip(np.searchsorted(edges, vals, side="right") - 1, 0, len(edges) - 2)
        entry = {"edges": edges.tolist(), "unit": PARAMETERS[name].unit, "controllers": {}}
        for c in controllers:
            succ, force, ci, counts = [], [], [], []
            for b in range(len(edges) - 1):
                sel = [runs[j] for j in np.flatnonzero(idx == b) if (runs[j], c) in by]
                k = sum(bool(by[(i, c)]["success"]) for i in sel)
                f = [by[(i, c)]["m_mean_force"] for i in sel if by[(i, c)].get("m_mean_force") is not None]
                counts.append(len(sel))
                succ.append(k / len(sel) if sel else None)
                ci.append(list(wilson(k, len(sel))))
                force.append(float(np.mean(f)) if f else None)
            # a parameter "shows an effect" when two bins' 95 % intervals do not overlap
            lows = [iv[0] for iv, n in zip(ci, counts) if n]
            highs = [iv[1] for iv, n in zip(ci, counts) if n]
            effect = bool(lows and max(lows) > min(highs))
            entry["controllers"][c] = {
                "runs": counts, "success_rate": succ, "wilson95": ci, "mean_force": force,
                "effect": effect,
            }
        fmap[name] = entry
    worst_runs: dict[str, list] = {}
    for c in controllers:
        failed = [by[(i, c)] for i in runs if (i, c) in by and not by[(i, c)]["success"]]
        failed.sort(key=lambda r: (-_severity(r, campaign), r["run"]))
        worst_runs[c] = [
            {
                "run": int(r["run"]),
                # None: dropped, error or non-finite (worse than any finite ratio)
                "severity": None if math.isinf(_severity(r, campaign)) else _severity(r, campaign),
                "dropped": r.get("m_dropped"),
                "hold_slip_mm": r.get("m_hold_slip_mm"),
                "hold_rotation_deg": r.get("m_hold_rotation_deg"),
                "error": r.get("error"),
                "parameters": {k: r[f"p_{k}"] for k in campaign.parameters},
                "replay": (
                    f"lugrip campaign replay {out_dir if out_dir is not None else 'DIR'} "
                    f"--run {int(r['run'])} --controller {c}"
                ),
            }
            for r in failed[:worst]
        ]
    return {
        "campaign": campaign.name,
        "plant": campaign.plant,
        "set": campaign.result_set,
        "seed": campaign.draw_seed,
        "tuning_seed": campaign.seed,
        "evaluation_seed": campaign.evaluation_seed,
        "runs": len(runs),
        "frontier": frontier_summary(rows, campaign, summary) if campaign.frontier else None,
        "criteria": campaign.criteria,
        "summary": summary,
        "paired_with_lugrip": paired,
        "belief": belief_summary(rows, controllers),
        "failure_map": fmap,
        "worst_runs": worst_runs,
    }


def belief_summary(rows: Sequence[dict], controllers: Sequence[str]) -> dict[str, Any] | None:
    """The friction belief of the controllers that hold one (lugrip, paper) against each run's
    true mu (the drawn ``p_mu``): told / true and at the end / true (median and 10-90 %), how
    many runs moved the belief, and of the runs told at least 5 % wrong, how many ended with at
    most half the error. None without drawn mu or belief columns (older results)."""
    out: dict[str, Any] = {}
    for c in controllers:
        if c not in ("lugrip", "paper"):
            continue
        rr = [r for r in rows if r["controller"] == c and r.get("p_mu")
              and r.get("m_mu_belief_start") is not None and r.get("m_mu_belief_end") is not None]
        if not rr:
            continue
        told = np.array([r["m_mu_belief_start"] / r["p_mu"] for r in rr])
        end = np.array([r["m_mu_belief_end"] / r["p_mu"] for r in rr])
        wrong = np.abs(told - 1.0) >= 0.05
        halved = wrong & (np.abs(end - 1.0) <= 0.5 * np.abs(told - 1.0))
        out[c] = {
            "runs": len(rr),
            "told_over_true": [float(np.median(told)), float(np.quantile(told, 0.1)),
                               float(np.quantile(told, 0.9))],
            "end_over_true": [float(np.median(end)), float(np.quantile(end, 0.1)),
                              float(np.quantile(end, 0.9))],
            "moved": int(np.sum(end != told)),
            "told_wrong": int(np.sum(wrong)),
            "error_halved": int(np.sum(halved)),
        }
    return out or None


def _fmt(v: Any, digits: int = 3) -> str:
    if v is None:
        return "-"
    if isinstance(v, float):
        if math.isinf(v):
            return "inf"
        return f"{v:.{digits}g}"
    return str(v)


def failure_map_figure(data: dict[str, Any]):
    """Success rate (with 95 % intervals) and mean grip force per bin of every drawn parameter,
    one column per parameter, one line per controller."""
    from .. import plot

    names = list(data["failure_map"])
    if not names:
        return None
    cols = min(len(names), 4)
    groups = math.ceil(len(names) / cols)
    with plot.style():
        fig, axes = plot.new_figure(
            2 * groups, cols, col_width=3.2, row_height=2.0, squeeze=False,
            title=f"campaign {data['campaign']} ({data['plant']}, {data['runs']} runs): "
            "success and mean grip force per parameter bin",
        )
        for k, name in enumerate(names):
            g, j = divmod(k, cols)
            ax_s, ax_f = axes[2 * g, j], axes[2 * g + 1, j]
            e = data["failure_map"][name]
            edges = np.asarray(e["edges"])
            mids = 0.5 * (edges[1:] + edges[:-1])
            for i, (c, d) in enumerate(e["controllers"].items()):
                col = plot.color(i)
                s = np.array([np.nan if v is None else v for v in d["success_rate"]])
                lo = np.array([iv[0] for iv in d["wilson95"]])
                hi = np.array([iv[1] for iv in d["wilson95"]])
                ax_s.errorbar(mids, s, yerr=[np.maximum(s - lo, 0), np.maximum(hi - s, 0)],
                              color=col, marker="o", ms=3, lw=1.2, capsize=2, label=c)
                f = np.array([np.nan if v is None else v for v in d["mean_force"]])
                ax_f.plot(mids, f, color=col, marker="o", ms=3, lw=1.2)
            ax_s.set_ylim(-0.05, 1.05)
            ax_s.set_title(name, fontsize=8)
            ax_f.set_xlabel(plot.axis_label(name, None, e["unit"]))
            if j == 0:
                ax_s.set_ylabel("success rate")
                ax_f.set_ylabel(plot.axis_label("mean force", None, "N"))
        for k in range(len(names), groups * cols):
            g, j = divmod(k, cols)
            axes[2 * g, j].set_visible(False)
            axes[2 * g + 1, j].set_visible(False)
        axes[0, 0].legend(fontsize=7, loc="lower left")
    return fig


def frontier_figure(data: dict[str, Any]):
    """Success rate against mean grip force: the constant-force frontier as a step curve, each
    controller as a point with its 95 % Wilson interval."""
    from .. import plot

    fr = data.get("frontier")
    if not fr:
        return None
    with plot.style():
        fig, axes = plot.new_figure(
            1, 1, col_width=6.0, row_height=3.8, squeeze=False,
            title=f"{data['campaign']} ({data['plant']}, {data.get('set', 'tuning')} set, "
            f"{data['runs']} runs)\nsuccess rate against mean grip force",
        )
        ax = axes[0, 0]
        if fr["curve"]["force"]:
            ax.step(fr["curve"]["force"], fr["curve"]["rate"], where="post", color="0.3", lw=1.4,
                    label="constant force (frontier)")
            if fr.get("max_force") is not None:
                ax.plot([fr["max_force"]], [fr["max_rate"]], marker="v", color="0.3", ms=6)
        for i, (c, pt) in enumerate(fr["controllers"].items()):
            if pt["mean_force"] is None or pt["success_rate"] is None:
                continue
            lo, hi = pt["wilson95"]
            r = pt["success_rate"]
            ax.errorbar([pt["mean_force"]], [r], yerr=[[max(r - lo, 0.0)], [max(hi - r, 0.0)]],
                        color=plot.color(i), marker="o", ms=5, capsize=3, lw=1.2, label=c)
        ax.set_xscale("log")
        ax.set_ylim(-0.03, 1.03)
        ax.set_xlabel(plot.axis_label("mean grip force", None, "N"))
        ax.set_ylabel("success rate")
        ax.legend(fontsize=7, loc="upper left", framealpha=0.85)
    return fig


def markdown(data: dict[str, Any], figure: str | None = None,
             frontier_fig: str | None = None) -> str:
    which = data.get("set", "tuning")
    seeds = f"seed {data['seed']}"
    lines = [
        f"# Campaign {data['campaign']}",
        "",
        f"Plant: {data['plant']}; **{which} set** ({seeds}"
        + (f"; the evaluation set's seed is {data['evaluation_seed']}"
           if which == "tuning" and data.get("evaluation_seed") is not None else "")
        + f"); {data['runs']} runs; success = "
        + ", ".join(f"{k} ({v})" if v is not True else k for k, v in data["criteria"].items()
                    if v is not False),
        "",
        "| controller | runs | success | rate | 95 % interval (Wilson) | mean force [N] | "
        "mean force / min static (held) | crushed | errors |",
        "|---|---:|---:|---:|---|---:|---:|---:|---:|",
    ]
    for c, s in data["summary"].items():
        lo, hi = s["wilson95"]
        lines.append(
            f"| {c} | {s['runs']} | {s['successes']} | {_fmt(s['success_rate'])} | "
            f"[{lo:.3f}, {hi:.3f}] | {_fmt(s['mean_force'])} | "
            f"{_fmt(s.get('mean_force_over_min_static'))} | {s.get('crushed', 0)} | "
            f"{s['errors']} |"
        )
    fr = data.get("frontier")
    if fr:
        lines += ["", "## Constant-force frontier", ""]
        if frontier_fig:
            lines += [f"![frontier]({frontier_fig})", ""]
        lo, hi = fr["max_wilson95"]
        lines += [
            f"Per run, the smallest constant force that passes it (bisection, bracket up to the "
            f"crush force or f_max = {_fmt(fr['f_max'])} N); a constant F holds a run when that "
            f"force <= F <= its crush force. No constant passes {fr['no_constant_passes']} of "
            f"{fr['runs']} runs; {fr['evaluations_mean']:.1f} simulations per run"
            + (f"; {fr['errors']} frontier errors" if fr["errors"] else "")
            + (f"; on {fr['floor_passed']} runs the bracket's bottom passed too (their force is "
               "an upper bound)" if fr["floor_passed"] else "")
            + (f"; on {fr['non_monotone']} runs a force above the smallest passing one failed "
               "(success not monotone in the force there: such a run counts as held only below "
               "that failing force)" if fr.get("non_monotone") else "") + ".",
            "",
            f"- Runs some constant under the crush force passes: **{_fmt(fr['passable_rate'])}** "
            f"({fr['passable']}/{fr['runs']}, Wilson [{fr['passable_wilson95'][0]:.3f}, "
            f"{fr['passable_wilson95'][1]:.3f}]). A command that never exceeds a run's crush force "
            f"grips no harder than the constant at that force, so where holding grows with the "
            f"grip this bounds every controller's success; held where no constant passes: "
            + ", ".join(f"{c} {pt.get('held_where_no_constant_passes', 0)}"
                        for c, pt in fr["controllers"].items()) + ".",
            f"- Frontier maximum: **{_fmt(fr['max_rate'])}** ({fr['max_successes']}/{fr['runs']}"
            f", Wilson [{lo:.3f}, {hi:.3f}], optimistic: the best constant is chosen after the "
            f"fact) at F = {_fmt(fr['max_force'])} N.",
            "",
            "| controller | success | 95 % interval | mean force [N] | constant of the same "
            "mean force | difference | it holds, that constant fails | that constant holds, it "
            "fails | minus frontier max |",
            "|---|---:|---|---:|---:|---:|---:|---:|---:|",
        ]
        chk = fr.get("constant_force_check")
        if chk:
            lines[-3:-3] = [
                f"- Check of the monotonicity the frontier assumes: the simulated constant_force "
                f"controller ({_fmt(chk['force'])} N) and the frontier's verdict for that force "
                f"agree on {chk['agree']} of {chk['runs']} runs"
                + (f" (they differ on runs {', '.join(map(str, chk['disagree_runs'][:10]))})"
                   if chk["disagree_runs"] else "") + ".",
            ]
        for c, pt in fr["controllers"].items():
            w = pt["wilson95"] or [math.nan, math.nan]
            lines.append(
                f"| {c} | {_fmt(pt['success_rate'])} | [{w[0]:.3f}, {w[1]:.3f}] | "
                f"{_fmt(pt['mean_force'])} | {_fmt(pt['constant_same_mean_force'])} | "
                f"{_fmt(pt['minus_constant_same_mean_force'])} | "
                f"{pt.get('holds_constant_fails', '-')} | "
                f"{pt.get('constant_holds_it_fails', '-')} | "
                f"{_fmt(pt['minus_frontier_max'])} |"
            )
    if data["paired_with_lugrip"]:
        lines += ["", "Paired with lugrip (same grasp, same noise):", "",
                  "| controller | runs | lugrip holds, it fails | it holds, lugrip fails |",
                  "|---|---:|---:|---:|"]
        for c, p in data["paired_with_lugrip"].items():
            lines.append(f"| {c} | {p['runs']} | {p['lugrip_holds_other_fails']} | "
                         f"{p['other_holds_lugrip_fails']} |")
    if data.get("belief"):
        lines += ["", "## Friction belief", "",
                  "The controller's mu over each run's true mu: as told (the campaign's mismatch) "
                  "and at the end of the run (what it learned); median [10 %, 90 %].", "",
                  "| controller | runs | told / true | at the end / true | runs it moved | "
                  "told >= 5 % wrong | of those, error at least halved |",
                  "|---|---:|---|---|---:|---:|---:|"]
        for c, b in data["belief"].items():
            t, e = b["told_over_true"], b["end_over_true"]
            lines.append(
                f"| {c} | {b['runs']} | {t[0]:.3f} [{t[1]:.3f}, {t[2]:.3f}] | "
                f"{e[0]:.3f} [{e[1]:.3f}, {e[2]:.3f}] | {b['moved']} | {b['told_wrong']} | "
                f"{b['error_halved']} |")
    lines += ["", "## Failure map", ""]
    if figure:
        lines += [f"![failure map]({figure})", ""]
    for name, e in data["failure_map"].items():
        shows = [c for c, d in e["controllers"].items() if d["effect"]]
        lines.append(
            f"- {name} [{e['unit']}]: "
            + (f"success depends on it for {', '.join(shows)} (95 % intervals of two bins "
               "do not overlap)" if shows else
               "no bin differs beyond the 95 % intervals at this size: its effect is not "
               "resolved by these runs")
        )
    lines += ["", "## Worst runs", ""]
    for c, items in data["worst_runs"].items():
        if not items:
            lines.append(f"- {c}: no failed run")
            continue
        for w in items:
            what = w["error"] or ("dropped" if w["dropped"] else
                                  f"slip {_fmt(w['hold_slip_mm'])} mm, rotation "
                                  f"{_fmt(w['hold_rotation_deg'])} deg")
            params = ", ".join(f"{k}={_fmt(v)}" for k, v in w["parameters"].items())
            lines.append(f"- {c} run {w['run']}: {what} ({params}); replay: `{w['replay']}`")
    return "\n".join(lines) + "\n"


def write_report(directory: str | Path, campaign: Campaign, rows: Sequence[dict] | None = None,
                 *, figures: bool = True) -> dict[str, Path]:
    """Write report.md, report.json, failure_map.png and (with the frontier) frontier.png into
    `directory` (rows: the stored results by default). Returns {name: path}."""
    from .runner import ResultStore

    d = Path(directory)
    if rows is None:
        rows = ResultStore(d, campaign).rows()
    data = summarise(rows, campaign, out_dir=d)
    paths = {}
    fig_name = front_name = None
    if figures:
        from .. import plot

        fig = failure_map_figure(data)
        if fig is not None:
            paths["failure_map"] = plot.save(fig, d / "failure_map.png")
            fig_name = "failure_map.png"
        fig = frontier_figure(data)
        if fig is not None:
            paths["frontier"] = plot.save(fig, d / "frontier.png")
            front_name = "frontier.png"
    from .._atomic import write_text_atomic

    write_text_atomic(d / "report.json", json.dumps(data, indent=1, default=str))
    write_text_atomic(d / "report.md", markdown(data, fig_name, front_name))
    paths["json"] = d / "report.json"
    paths["markdown"] = d / "report.md"
    return paths
