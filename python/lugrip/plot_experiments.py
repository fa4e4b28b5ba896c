"""The paper's experiment figures (Figures 11, 13, 15, 17) from closed-loop scenario runs, with
the paper's panels, plus one baseline-comparison figure per scenario (ground truth).

* Figure 11 (exp1): grasp force; slippage indicator S and estimated c~; estimated omega_hat.
* Figure 13 (exp2): grasp force, tangential load, torsional torque; S and c~; omega_hat.
* Figure 15 (exp3): grasp force and torque; c~ (pivoting interval marked).
* Figure 17 (exp4): grasp force, tangential force, torque for the full and the empty can; S.

Plotted per-finger quantities are finger 0's (finger 1 mirrors it); S is max(S_0, S_1) and c~
the mean of |c~_i|, the values the controller uses (MODEL.md 9.8). Forces are per finger.
Shaded: the lift (grey), disturbances (orange), pivoting (green).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from . import plot

__all__ = [
    "FIGURES",
    "figure_11",
    "figure_13",
    "figure_15",
    "figure_17",
    "figure_baselines",
    "write_figures",
]

# Colours (the paper's where it names them, mapped to the project palette).
BLUE, RED, MAGENTA, GREEN = "#0072B2", "#D55E00", "#CC79A7", "#009E73"
CYAN, ORANGE, BLACK, GREY = "#56B4E9", "#E69F00", "#000000", "#999999"


def _mark_phases(ax, scenario, run=None, *, label: bool = False) -> None:
    """Shade the lift, the disturbances and the pivoting interval on an axis."""
    cfg = scenario.plant_config()
    for k, m in enumerate(cfg.moves):
        ax.axvspan(
            m.t_start,
            m.t_start + m.duration,
            color=GREY,
            alpha=0.12,
            lw=0,
            label="lift" if (label and k == 0) else None,
        )
    for k, d in enumerate(cfg.disturbances):
        ax.axvspan(
            d.t_start,
            d.t_start + d.duration,
            color=ORANGE,
            alpha=0.25,
            lw=0,
            label="disturbance" if (label and k == 0) else None,
        )
    if run is not None and np.any(run["mode"] == 1):
        t = run["t"]
        piv = t[run["mode"] == 1]
        ax.axvspan(
            piv[0], piv[-1], color=GREEN, alpha=0.12, lw=0, label="pivoting" if label else None
        )


def _c_tilde(run) -> np.ndarray:
    return 0.5 * (np.abs(run["c_tilde_0"]) + np.abs(run["c_tilde_1"]))


def _force_panel(ax, scenario, run, *, tangential: bool, torque: bool, legend_loc="upper right"):
    t = run["t"]
    ax.plot(t, run["f_n_meas_0"], color=BLUE, lw=1.6, label="grasp force $f_n$")
    ax.plot(t, run["command"], color=BLACK, lw=0.8, ls="--", alpha=0.7, label="command")
    if tangential:
        ax.plot(t, run["f_t_meas_0"], color=RED, lw=1.3, label="tangential load $f_t$")
    ax.set_ylabel(plot.axis_label("force", None, "N"))
    if torque:
        ax2 = ax.twinx()
        ax2.plot(
            t, np.abs(run["tau_meas_0"]) * 1e3, color=MAGENTA, lw=1.3, label=r"torque $|\tau|$"
        )
        ax2.set_ylabel(plot.axis_label("torque", r"|\tau|", "N mm"), color=MAGENTA)
        ax2.tick_params(axis="y", colors=MAGENTA)
        ax2.spines["right"].set_visible(True)
        ax2.grid(False)
        ax2.set_ylim(
            bottom=0.0, top=max(1.0, 1.15 * float(np.max(np.abs(run["tau_meas_0"]))) * 1e3)
        )
        h2, l2 = ax2.get_legend_handles_labels()
    else:
        h2, l2 = [], []
    h1, l1 = ax.get_legend_handles_labels()
    ax.legend(h1 + h2, l1 + l2, loc=legend_loc, ncol=2, fontsize=8)
    ax.set_ylim(bottom=0.0)
    _mark_phases(ax, scenario, run)


def _s_panel(ax, scenario, run, s_ref: float = 0.8):
    t = run["t"]
    ax.plot(t, run.S, color=BLUE, lw=1.4, label="slippage indicator $S$")
    ax.plot(t, _c_tilde(run), color=RED, lw=1.4, label=r"estimated $\tilde c$")
    ax.axhline(s_ref, color=BLUE, lw=0.8, ls=":", alpha=0.8)
    ax.set_ylabel(plot.axis_label("S, $\\tilde c$", None, "-"))
    ax.set_ylim(0.0, 1.65)
    ax.legend(loc="lower right", ncol=2, fontsize=8)
    _mark_phases(ax, scenario, run)


def _omega_panel(ax, scenario, run):
    t = run["t"]
    ax.plot(t, run["omega_hat_0"], color=BLUE, lw=1.2)
    ax.set_ylabel(plot.axis_label("slip velocity", r"\hat\omega", "rad/s"))
    _mark_phases(ax, scenario, run)


def _finish(fig, axes, duration: float | None = None):
    axes[-1].set_xlabel(plot.axis_label("time", "t", "s"))
    if duration is not None:
        axes[-1].set_xlim(0.0, duration)
    plot.panel_labels(axes)
    return fig


def figure_11(result):
    """Figure 11: exp1, big resin block (grasp force; S and c~; omega_hat)."""
    s, run = result.scenario, result.runs["lugrip"]
    with plot.style():
        fig, axes = plot.new_figure(
            3,
            1,
            sharex=True,
            width=8.0,
            row_height=2.3,
            title="Figure 11 (simulated): big resin block grasped above its CoG",
        )
        _force_panel(axes[0], s, run, tangential=False, torque=False)
        _s_panel(axes[1], s, run, s.controller.get("s_ref", 0.8))
        _omega_panel(axes[2], s, run)
        return _finish(fig, axes, s.duration)


def figure_13(result):
    """Figure 13: exp2, small resin block (force, tangential load, torque; S and c~; omega_hat)."""
    s, run = result.scenario, result.runs["lugrip"]
    with plot.style():
        fig, axes = plot.new_figure(
            3,
            1,
            sharex=True,
            width=8.0,
            row_height=2.3,
            title="Figure 13 (simulated): small resin block grasped off its CoG",
        )
        _force_panel(axes[0], s, run, tangential=True, torque=True, legend_loc="center right")
        _s_panel(axes[1], s, run, s.controller.get("s_ref", 0.8))
        _omega_panel(axes[2], s, run)
        return _finish(fig, axes, s.duration)


def figure_15(result):
    """Figure 15: exp3, bottle lift and pivot (grasp force and torque; c~)."""
    s, run = result.scenario, result.runs["lugrip"]
    with plot.style():
        fig, axes = plot.new_figure(
            2,
            1,
            sharex=True,
            width=8.0,
            row_height=2.6,
            title="Figure 15 (simulated): plastic bottle lifted and pivoted",
        )
        _force_panel(axes[0], s, run, tangential=False, torque=True, legend_loc="upper right")
        t = run["t"]
        ax = axes[1]
        ax.plot(t, _c_tilde(run), color=RED, lw=1.4, label=r"estimated $\tilde c$")
        thr = float(s.controller.get("pivot_end_c_tilde", 1.0))
        ax.axhline(thr, color=BLACK, lw=0.8, ls=":", label="end of pivoting ($\\tilde c$ = 1)")
        ax.set_ylim(0.0, 1.65)
        ax.set_ylabel(plot.axis_label("CoR", r"\tilde c", "-"))
        _mark_phases(ax, s, run, label=True)
        ax.legend(loc="lower right", ncol=2, fontsize=8)
        return _finish(fig, axes, s.duration)


def figure_17(full, empty):
    """Figure 17: exp4, full and empty can (force, tangential force, torque; S)."""
    rf, re = full.runs["lugrip"], empty.runs["lugrip"]
    with plot.style():
        fig, axes = plot.new_figure(
            2,
            1,
            sharex=True,
            width=8.0,
            row_height=2.8,
            title="Figure 17 (simulated): aluminium can, full and empty",
        )
        ax = axes[0]
        t = rf["t"]
        ax.plot(t, rf["f_n_meas_0"], color=BLUE, lw=1.6, label="full: grasp force")
        ax.plot(t, rf["f_t_meas_0"], color=RED, lw=1.2, label="full: tangential force")
        ax.plot(re["t"], re["f_n_meas_0"], color=MAGENTA, lw=1.6, label="empty: grasp force")
        ax.plot(re["t"], re["f_t_meas_0"], color=GREEN, lw=1.2, label="empty: tangential force")
        ax.set_ylabel(plot.axis_label("force", None, "N"))
        ax.set_ylim(bottom=0.0)
        ax2 = ax.twinx()
        ax2.plot(
            t, np.abs(rf["tau_meas_0"]) * 1e3, color=CYAN, lw=1.2, label=r"full: torque $|\tau|$"
        )
        ax2.plot(
            re["t"],
            np.abs(re["tau_meas_0"]) * 1e3,
            color=ORANGE,
            lw=1.2,
            label=r"empty: torque $|\tau|$",
        )
        ax2.set_ylabel(plot.axis_label("torque", r"|\tau|", "N mm"))
        ax2.spines["right"].set_visible(True)
        ax2.grid(False)
        ax2.set_ylim(bottom=0.0, top=max(1.0, 2.2 * float(np.max(np.abs(rf["tau_meas_0"]))) * 1e3))
        h1, l1 = ax.get_legend_handles_labels()
        h2, l2 = ax2.get_legend_handles_labels()
        ax.legend(
            h1 + h2, l1 + l2, loc="lower left", bbox_to_anchor=(0.0, 1.02), ncol=3, fontsize=7.5
        )
        _mark_phases(ax, full.scenario, rf)
        # inset: the empty can's force on its own scale
        ins = ax.inset_axes([0.33, 0.40, 0.3, 0.25])
        ins.plot(re["t"], re["f_n_meas_0"], color=MAGENTA, lw=1.2)
        ins.plot(re["t"], re["f_t_meas_0"], color=GREEN, lw=1.0)
        ins.set_xlim(re["t"][0], re["t"][-1])
        ins.set_ylim(0.0, 0.5)
        ins.set_title("empty can [N]", fontsize=7.5)
        ins.tick_params(labelsize=7)
        ins.grid(True, alpha=0.35, linewidth=0.6)
        ax = axes[1]
        ax.plot(t, rf.S, color=BLUE, lw=1.3, label="full: $S$")
        ax.plot(re["t"], re.S, color=RED, lw=1.3, label="empty: $S$")
        ax.axhline(full.scenario.controller.get("s_ref", 0.8), color=BLACK, lw=0.8, ls=":")
        ax.set_ylim(0.0, 1.1)
        ax.set_ylabel(plot.axis_label("slippage indicator", "S", "-"))
        ax.legend(loc="lower right", fontsize=8)
        _mark_phases(ax, full.scenario, rf)
        return _finish(fig, axes, full.scenario.duration)


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
    with plot.style():
        fig, axes = plot.new_figure(
            3,
            1,
            sharex=True,
            width=8.0,
            row_height=2.1,
            title=f"{s.name}: lugrip vs baselines (ground truth)",
        )
        for kind, run in result.runs.items():
            color, ls, label = _KIND_STYLE.get(kind, (GREY, "-", kind))
            m = result.metrics[kind]
            if kind == "constant_force" and m.get("constant_force") is not None:
                label = f"constant force {m['constant_force']:.2f} N (minimum that survives)"
            t = run["t"]
            axes[0].plot(t, run["command"], color=color, ls=ls, lw=1.4, label=label)
            axes[1].plot(t, run["slip"] * 1e3, color=color, ls=ls, lw=1.4)
            axes[2].plot(t, np.degrees(run["rotation"]), color=color, ls=ls, lw=1.4)
        axes[0].set_ylabel(plot.axis_label("command", "f_n", "N"))
        axes[0].set_ylim(bottom=0.0)
        axes[0].legend(loc="lower right", fontsize=7.5, ncol=2)
        axes[1].set_ylabel(plot.axis_label("slip", None, "mm"))
        axes[2].set_ylabel(plot.axis_label("rotation", None, "deg"))
        hold = s.hold_time
        for ax in axes:
            _mark_phases(ax, s)
            ax.axvline(hold, color=BLACK, lw=0.8, ls=":")
        axes[1].text(
            hold,
            0.97,
            " hold starts",
            transform=axes[1].get_xaxis_transform(),
            fontsize=7.5,
            va="top",
        )
        return _finish(fig, axes, s.duration)


#: Paper figure per scenario (exp4 full and empty share Figure 17).
FIGURES = {
    "exp1_big_resin_block": ("fig11_exp1_big_resin_block.png", figure_11),
    "exp2_small_resin_block": ("fig13_exp2_small_resin_block.png", figure_13),
    "exp3_plastic_bottle_pivot": ("fig15_exp3_plastic_bottle_pivot.png", figure_15),
}


def write_figures(
    results: Mapping[str, object] | Sequence[object], out_dir: str | Path
) -> dict[str, Path]:
    """Write the paper figures available from `results` (ScenarioResult by name) and one
    baseline-comparison figure per result with baselines. Returns {figure name: path}."""
    by_name = results if isinstance(results, Mapping) else {r.name: r for r in results}
    out = Path(out_dir)
    paths: dict[str, Path] = {}
    for name, (fname, fn) in FIGURES.items():
        if name in by_name:
            paths[fname] = plot.save(fn(by_name[name]), out / fname)
    if "exp4_aluminium_can_full" in by_name and "exp4_aluminium_can_empty" in by_name:
        fname = "fig17_exp4_aluminium_can.png"
        paths[fname] = plot.save(
            figure_17(by_name["exp4_aluminium_can_full"], by_name["exp4_aluminium_can_empty"]),
            out / fname,
        )
    for name, r in by_name.items():
        if len(r.runs) > 1:
            fname = f"{name}_baselines.png"
            paths[fname] = plot.save(figure_baselines(r), out / fname)
    return paths
