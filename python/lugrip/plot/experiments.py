"""The paper's experiment figures (Figures 11, 13, 15, 17) from closed-loop scenario runs, with
the paper's panels, plus one baseline-comparison figure per scenario (ground truth).

* Figure 11 (exp1): grasp force; slippage indicator S and estimated c~; estimated omega_hat.
* Figure 13 (exp2): grasp force, tangential load, torsional torque; S and c~; omega_hat.
* Figure 15 (exp3): grasp force and torque; c~ (pivoting interval marked).
* Figure 17 (exp4): grasp force, tangential force, torque for the full and the empty can; S.

Plotted per-finger quantities are finger 0's (finger 1 mirrors it); S is max(S_0, S_1) and c~
the mean of |c~_i|, the values the controller uses (docs/model.md §9.8). Forces are per finger.
Shaded: the lift (grey), disturbances (orange), pivoting (green).
"""

from __future__ import annotations

import contextlib
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from .. import plot

__all__ = [
    "FIGURES",
    "figure_11",
    "figure_13",
    "figure_15",
    "figure_17",
    "figure_baselines",
    "figure_scenario",
    "write_figures",
]

# Colours (the paper's where it names them): the project palette, in its order.
BLUE, RED, GREEN, MAGENTA, ORANGE, CYAN, BLACK, GREY = plot.PALETTE

WIDTH = 8.0
"""Width of every experiment figure [in]."""

# Shading per phase: colour, alpha.
_PHASE_STYLE = {"lift": (GREY, 0.12), "disturbance": (ORANGE, 0.25), "pivoting": (GREEN, 0.12)}


@contextlib.contextmanager
def _stacked(rows: int, row_height: float, title: str, duration: float):
    """Yields (fig, axes): a column of `rows` panels sharing the time axis, in the project
    style. On leaving: time label under the last panel, time from 0 to `duration`, panel
    letters (a), (b), ..."""
    with plot.style():
        fig, axes = plot.new_figure(
            rows, 1, sharex=True, width=WIDTH, row_height=row_height, title=title
        )
        yield fig, axes
        axes[-1].set_xlabel(plot.axis_label("time", "t", "s"))
        axes[-1].set_xlim(0.0, duration)
        plot.panel_labels(axes)


def _phases(scenario, run=None) -> list[tuple[str, float, float, bool]]:
    """(kind, start, end, first of its kind) of the lifts, the disturbances and (from the run's
    controller mode) the pivoting interval, in drawing order."""
    cfg = scenario.plant_config()
    spans = [("lift", m.t_start, m.t_start + m.duration, k == 0) for k, m in enumerate(cfg.moves)]
    spans += [
        ("disturbance", d.t_start, d.t_start + d.duration, k == 0)
        for k, d in enumerate(cfg.disturbances)
    ]
    if run is not None and np.any(run["mode"] == 1):
        piv = run["t"][run["mode"] == 1]
        spans.append(("pivoting", piv[0], piv[-1], True))
    return spans


def _mark_phases(ax, scenario, run=None, *, label: bool = False) -> None:
    """Shade the lift, the disturbances and the pivoting interval on an axis (with `label`,
    one legend entry per kind)."""
    for kind, start, end, first in _phases(scenario, run):
        color, alpha = _PHASE_STYLE[kind]
        ax.axvspan(
            start, end, color=color, alpha=alpha, lw=0, label=kind if label and first else None
        )


def _line(ax, run, y, color: str, lw: float, **kwargs):
    """Plot `y` (a column name of the run, or values on its time base) against the run's time."""
    return ax.plot(run["t"], run[y] if isinstance(y, str) else y, color=color, lw=lw, **kwargs)


def _torque_nmm(run) -> np.ndarray:
    return np.abs(run["tau_meas_0"]) * 1e3


def _torque_axis(ax, curves, *, headroom: float, color: str | None = None):
    """Right-hand axis of |tau| [N mm]: one line per (run, colour, width, label), y from 0 to
    headroom times the largest |tau| of the first run (at least 1 N mm)."""
    ax2 = plot.twin_y(ax, plot.axis_label("torque", r"|\tau|", "N mm"), color=color)
    for run, c, lw, label in curves:
        _line(ax2, run, _torque_nmm(run), c, lw, label=label)
    peak = float(np.max(np.abs(curves[0][0]["tau_meas_0"])))
    ax2.set_ylim(bottom=0.0, top=max(1.0, headroom * peak * 1e3))
    return ax2


def _c_tilde(run) -> np.ndarray:
    return 0.5 * (np.abs(run["c_tilde_0"]) + np.abs(run["c_tilde_1"]))


def _s_ref(scenario) -> float:
    return scenario.controller.get("s_ref", 0.8)


def _force_panel(ax, scenario, run, *, tangential: bool, torque: bool, legend_loc="upper right"):
    _line(ax, run, "f_n_meas_0", BLUE, 1.6, label="grasp force $f_n$")
    _line(ax, run, "command", BLACK, 0.8, ls="--", alpha=0.7, label="command")
    if tangential:
        _line(ax, run, "f_t_meas_0", RED, 1.3, label="tangential load $f_t$")
    ax.set_ylabel(plot.axis_label("force", None, "N"))
    twins = []
    if torque:
        curves = [(run, MAGENTA, 1.3, r"torque $|\tau|$")]
        twins.append(_torque_axis(ax, curves, headroom=1.15, color=MAGENTA))
    plot.merged_legend(ax, *twins, loc=legend_loc, ncol=2, fontsize=8)
    ax.set_ylim(bottom=0.0)
    _mark_phases(ax, scenario, run)


def _s_panel(ax, scenario, run):
    _line(ax, run, run.S, BLUE, 1.4, label="slippage indicator $S$")
    _line(ax, run, _c_tilde(run), RED, 1.4, label=r"estimated $\tilde c$")
    ax.axhline(_s_ref(scenario), color=BLUE, lw=0.8, ls=":", alpha=0.8)
    ax.set_ylabel(plot.axis_label("S, $\\tilde c$", None, "-"))
    ax.set_ylim(0.0, 1.65)
    ax.legend(loc="lower right", ncol=2, fontsize=8)
    _mark_phases(ax, scenario, run)


def _omega_panel(ax, scenario, run):
    _line(ax, run, "omega_hat_0", BLUE, 1.2)
    ax.set_ylabel(plot.axis_label("slip velocity", r"\hat\omega", "rad/s"))
    _mark_phases(ax, scenario, run)


def _force_s_omega(result, title: str, **force_panel):
    """Figures 11 and 13: force panel (options `force_panel`), S and c~, omega_hat."""
    s, run = result.scenario, result.runs["lugrip"]
    with _stacked(3, 2.3, title, s.duration) as (fig, (ax_f, ax_s, ax_w)):
        _force_panel(ax_f, s, run, **force_panel)
        _s_panel(ax_s, s, run)
        _omega_panel(ax_w, s, run)
    return fig


def figure_11(result):
    """Figure 11: exp1, big resin block (grasp force; S and c~; omega_hat)."""
    return _force_s_omega(
        result,
        "Figure 11 (simulated): big resin block grasped above its CoG",
        tangential=False,
        torque=False,
    )


def figure_13(result):
    """Figure 13: exp2, small resin block (force, tangential load, torque; S and c~; omega_hat)."""
    return _force_s_omega(
        result,
        "Figure 13 (simulated): small resin block grasped off its CoG",
        tangential=True,
        torque=True,
        legend_loc="center right",
    )


def figure_15(result):
    """Figure 15: exp3, bottle lift and pivot (grasp force and torque; c~)."""
    s, run = result.scenario, result.runs["lugrip"]
    title = "Figure 15 (simulated): plastic bottle lifted and pivoted"
    with _stacked(2, 2.6, title, s.duration) as (fig, (ax_f, ax)):
        _force_panel(ax_f, s, run, tangential=False, torque=True)
        _line(ax, run, _c_tilde(run), RED, 1.4, label=r"estimated $\tilde c$")
        thr = 1.0  # the pivot's end: mean |c~| > 1 (a constant of the law)
        ax.axhline(thr, color=BLACK, lw=0.8, ls=":", label="end of pivoting ($\\tilde c$ = 1)")
        ax.set_ylim(0.0, 1.65)
        ax.set_ylabel(plot.axis_label("CoR", r"\tilde c", "-"))
        _mark_phases(ax, s, run, label=True)
        ax.legend(loc="lower right", ncol=2, fontsize=8)
    return fig


def figure_17(full, empty):
    """Figure 17: exp4, full and empty can (force, tangential force, torque; S)."""
    s, rf, re = full.scenario, full.runs["lugrip"], empty.runs["lugrip"]
    title = "Figure 17 (simulated): aluminium can, full and empty"
    with _stacked(2, 2.8, title, s.duration) as (fig, (ax, ax_s)):
        _line(ax, rf, "f_n_meas_0", BLUE, 1.6, label="full: grasp force")
        _line(ax, rf, "f_t_meas_0", RED, 1.2, label="full: tangential force")
        _line(ax, re, "f_n_meas_0", MAGENTA, 1.6, label="empty: grasp force")
        _line(ax, re, "f_t_meas_0", GREEN, 1.2, label="empty: tangential force")
        ax.set_ylabel(plot.axis_label("force", None, "N"))
        ax.set_ylim(bottom=0.0)
        curves = [
            (rf, CYAN, 1.2, r"full: torque $|\tau|$"),
            (re, ORANGE, 1.2, r"empty: torque $|\tau|$"),
        ]
        ax2 = _torque_axis(ax, curves, headroom=2.2)
        plot.merged_legend(
            ax, ax2, loc="lower left", bbox_to_anchor=(0.0, 1.02), ncol=3, fontsize=7.5
        )
        _mark_phases(ax, s, rf)
        # inset: the empty can's force on its own scale
        ins = ax.inset_axes([0.33, 0.40, 0.3, 0.25])
        _line(ins, re, "f_n_meas_0", MAGENTA, 1.2)
        _line(ins, re, "f_t_meas_0", GREEN, 1.0)
        ins.set_xlim(re["t"][0], re["t"][-1])
        ins.set_ylim(0.0, 0.5)
        ins.set_title("empty can [N]", fontsize=7.5)
        ins.tick_params(labelsize=7)
        ins.grid(True, alpha=0.35, linewidth=0.6)
        _line(ax_s, rf, rf.S, BLUE, 1.3, label="full: $S$")
        _line(ax_s, re, re.S, RED, 1.3, label="empty: $S$")
        ax_s.axhline(_s_ref(s), color=BLACK, lw=0.8, ls=":")
        ax_s.set_ylim(0.0, 1.1)
        ax_s.set_ylabel(plot.axis_label("slippage indicator", "S", "-"))
        ax_s.legend(loc="lower right", fontsize=8)
        _mark_phases(ax_s, s, rf)
    return fig


def figure_scenario(result):
    """Any scenario without a paper figure (a user's own, unseen objects, faults): lugrip's run
    as Figure 13 lays it out (grasp force, tangential force and torque; S and c~; omega_hat)."""
    s = result.scenario
    return _force_s_omega(result, f"{s.name}: {s.title}", tangential=True, torque=True,
                          legend_loc="center right")


_KIND_STYLE = {
    "lugrip": (BLUE, "-", "lugrip"),
    "lugrip_no_pivot": (CYAN, "-", "lugrip, no pivoting"),
    "constant_force": (ORANGE, "--", "constant force"),
    "friction_cone": (RED, "-.", "friction cone"),
}


def figure_baselines(result):
    """lugrip against the baselines on one scenario: grasp-force command, and the true
    translational slip [mm] and rotation [deg] of the object relative to the fingers."""
    s = result.scenario
    title = f"{s.name}: lugrip vs baselines (ground truth)"
    with _stacked(3, 2.1, title, s.duration) as (fig, axes):
        for kind, run in result.runs.items():
            color, ls, label = _KIND_STYLE.get(kind, (GREY, "-", kind))
            m = result.metrics[kind]
            if kind == "constant_force" and m.get("constant_force") is not None:
                label = f"constant force {m['constant_force']:.2f} N (minimum that survives)"
            _line(axes[0], run, "command", color, 1.4, ls=ls, label=label)
            _line(axes[1], run, run["slip"] * 1e3, color, 1.4, ls=ls)
            _line(axes[2], run, np.degrees(run["rotation"]), color, 1.4, ls=ls)
        axes[0].set_ylabel(plot.axis_label("command", "f_n", "N"))
        axes[0].set_ylim(bottom=0.0)
        axes[0].legend(loc="lower right", fontsize=7.5, ncol=2)
        axes[1].set_ylabel(plot.axis_label("slip", None, "mm"))
        axes[2].set_ylabel(plot.axis_label("rotation", None, "deg"))
        for ax in axes:
            _mark_phases(ax, s)
            ax.axvline(s.hold_time, color=BLACK, lw=0.8, ls=":")
        axes[1].text(
            s.hold_time,
            0.97,
            " hold starts",
            transform=axes[1].get_xaxis_transform(),
            fontsize=7.5,
            va="top",
        )
    return fig


#: Paper figure per scenario (exp4 full and empty share Figure 17).
FIGURES = {
    "exp1_big_resin_block": ("fig11_exp1_big_resin_block.png", figure_11),
    "exp2_small_resin_block": ("fig13_exp2_small_resin_block.png", figure_13),
    "exp3_plastic_bottle_pivot": ("fig15_exp3_plastic_bottle_pivot.png", figure_15),
}


def write_figures(
    results: Mapping[str, object] | Sequence[object], out_dir: str | Path
) -> dict[str, Path]:
    """Write the paper figures available from `results` (ScenarioResult by name), the time
    series of every other scenario (``<name>.png``, :func:`figure_scenario`) and one
    baseline-comparison figure per result with baselines. Returns {figure name: path}."""
    by_name = results if isinstance(results, Mapping) else {r.name: r for r in results}
    out = Path(out_dir)
    paths: dict[str, Path] = {}
    for name, (fname, fn) in FIGURES.items():
        if name in by_name:
            paths[fname] = plot.save(fn(by_name[name]), out / fname)
    covered = set(FIGURES)
    if "exp4_aluminium_can_full" in by_name and "exp4_aluminium_can_empty" in by_name:
        covered |= {"exp4_aluminium_can_full", "exp4_aluminium_can_empty"}
        fname = "fig17_exp4_aluminium_can.png"
        paths[fname] = plot.save(
            figure_17(by_name["exp4_aluminium_can_full"], by_name["exp4_aluminium_can_empty"]),
            out / fname,
        )
    for name, r in by_name.items():
        if name not in covered and "lugrip" in r.runs:
            fname = f"{name}.png"
            paths[fname] = plot.save(figure_scenario(r), out / fname)
    for name, r in by_name.items():
        if len(r.runs) > 1:
            fname = f"{name}_baselines.png"
            paths[fname] = plot.save(figure_baselines(r), out / fname)
    return paths
