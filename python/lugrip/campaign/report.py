"""Campaign report: success rate per controller with Wilson intervals, paired comparison with
lugrip, failure maps (success and mean force against each drawn parameter), the worst runs with
the command that replays each one.

Writes DIR/report.md, DIR/report.json and DIR/failure_map.png.
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from .definition import PARAMETERS, Campaign

__all__ = ["summarise", "wilson", "write_report"]


def wilson(successes: int, n: int, z: float = 1.959964) -> tuple[float, float]:
    """Wilson score interval of a binomial proportion (default 95 %); (0, 1) for n = 0."""
    if n <= 0:
        return 0.0, 1.0
    p = successes / n
    den = 1.0 + z * z / n
    centre = (p + z * z / (2 * n)) / den
    half = z * math.sqrt(p * (1.0 - p) / n + z * z / (4 * n * n)) / den
    return max(0.0, centre - half), min(1.0, centre + half)


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
        "seed": campaign.seed,
        "runs": len(runs),
        "criteria": campaign.criteria,
        "summary": summary,
        "paired_with_lugrip": paired,
        "failure_map": fmap,
        "worst_runs": worst_runs,
    }


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


def markdown(data: dict[str, Any], figure: str | None = None) -> str:
    lines = [
        f"# Campaign {data['campaign']}",
        "",
        f"Plant: {data['plant']}; master seed {data['seed']}; {data['runs']} runs; success = "
        + ", ".join(f"{k} ({v})" if v is not True else k for k, v in data["criteria"].items()
                    if v is not False),
        "",
        "| controller | runs | success | rate | 95 % interval (Wilson) | mean force [N] | errors |",
        "|---|---:|---:|---:|---|---:|---:|",
    ]
    for c, s in data["summary"].items():
        lo, hi = s["wilson95"]
        lines.append(
            f"| {c} | {s['runs']} | {s['successes']} | {_fmt(s['success_rate'])} | "
            f"[{lo:.3f}, {hi:.3f}] | {_fmt(s['mean_force'])} | {s['errors']} |"
        )
    if data["paired_with_lugrip"]:
        lines += ["", "Paired with lugrip (same grasp, same noise):", "",
                  "| controller | runs | lugrip holds, it fails | it holds, lugrip fails |",
                  "|---|---:|---:|---:|"]
        for c, p in data["paired_with_lugrip"].items():
            lines.append(f"| {c} | {p['runs']} | {p['lugrip_holds_other_fails']} | "
                         f"{p['other_holds_lugrip_fails']} |")
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
    """Write report.md, report.json and failure_map.png into `directory` (rows: the stored
    results by default). Returns {name: path}."""
    from .runner import ResultStore

    d = Path(directory)
    if rows is None:
        rows = ResultStore(d, campaign).rows()
    data = summarise(rows, campaign, out_dir=d)
    paths = {}
    fig_name = None
    if figures:
        fig = failure_map_figure(data)
        if fig is not None:
            from .. import plot

            paths["failure_map"] = plot.save(fig, d / "failure_map.png")
            fig_name = "failure_map.png"
    from .._atomic import write_text_atomic

    write_text_atomic(d / "report.json", json.dumps(data, indent=1, default=str))
    write_text_atomic(d / "report.md", markdown(data, fig_name))
    paths["json"] = d / "report.json"
    paths["markdown"] = d / "report.md"
    return paths
