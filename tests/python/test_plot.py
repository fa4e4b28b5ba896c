"""The shared figure style (lugrip.plot): figures, saving, labels, zoom insets."""

from __future__ import annotations

import struct
import sys
from pathlib import Path

import matplotlib
import numpy as np
import pytest
from matplotlib.colors import to_rgb

from lugrip import plot


def _png_size(path):
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    return struct.unpack(">II", data[16:24])


def test_palette_colours_are_distinct_and_cycle():
    """color(i) walks the palette and wraps around; all colours differ."""
    rgb = [to_rgb(c) for c in plot.PALETTE]
    assert len(set(rgb)) == len(rgb) >= 6
    assert plot.color(0) == plot.PALETTE[0]
    assert plot.color(len(plot.PALETTE) + 2) == plot.PALETTE[2]


def test_style_applies_and_restores_rcparams():
    """style() sets the project rcParams inside the block and restores them after."""
    before = matplotlib.rcParams["lines.linewidth"]
    matplotlib.rcParams["lines.linewidth"] = before + 0.3
    try:
        with plot.style():
            assert matplotlib.rcParams["lines.linewidth"] == plot.RC["lines.linewidth"]
            assert matplotlib.rcParams["axes.grid"] is True
        assert matplotlib.rcParams["lines.linewidth"] == before + 0.3
    finally:
        matplotlib.rcParams["lines.linewidth"] = before


def test_new_figure_shapes_sizes_and_grid():
    """Grid of axes like Figure.subplots, default size from rows/cols, grid on, title."""
    fig, ax = plot.new_figure()
    assert not isinstance(ax, np.ndarray)
    assert tuple(fig.get_size_inches()) == pytest.approx((4.8, 2.6))

    fig, axes = plot.new_figure(3, sharex=True, title="Experiment")
    assert axes.shape == (3,)
    assert fig.get_size_inches()[1] == pytest.approx(3 * 2.6 + 0.3)
    assert fig.get_suptitle() == "Experiment"
    fig.canvas.draw()
    assert all(g.get_visible() for a in axes for g in a.xaxis.get_gridlines())
    assert axes[0].get_shared_x_axes().joined(axes[0], axes[2])

    fig, axes = plot.new_figure(2, 2, squeeze=False, width=8.0, height=5.0,
                                height_ratios=(3, 1))
    assert axes.shape == (2, 2)
    assert tuple(fig.get_size_inches()) == pytest.approx((8.0, 5.0))
    fig.canvas.draw()
    top, bottom = axes[0, 0].get_position(), axes[1, 0].get_position()
    assert top.height > 2.0 * bottom.height


@pytest.mark.parametrize("rows, cols", [(0, 1), (1, 0)])
def test_new_figure_rejects_empty_grid(rows, cols):
    with pytest.raises(ValueError, match="rows"):
        plot.new_figure(rows, cols)


def test_figures_do_not_touch_pyplot():
    """Figures live on the Agg canvas outside pyplot's figure manager."""
    n_before = len(sys.modules["matplotlib.pyplot"].get_fignums()) \
        if "matplotlib.pyplot" in sys.modules else 0
    fig, _ = plot.new_figure()
    assert type(fig.canvas).__name__ == "FigureCanvasAgg"
    if "matplotlib.pyplot" in sys.modules:
        assert len(sys.modules["matplotlib.pyplot"].get_fignums()) == n_before


def test_save_png_pdf_svg(tmp_path):
    """save() picks the format from the suffix, creates the directory, PNG at DPI."""
    with plot.style():
        fig, ax = plot.new_figure(width=4.0, height=3.0)
        ax.plot([0, 1, 2], [0, 1, 4], label="y")
        ax.legend()
    png = plot.save(fig, tmp_path / "a" / "b" / "fig.png")
    assert _png_size(png) == (4 * plot.DPI, 3 * plot.DPI)
    assert plot.save(fig, tmp_path / "fig.pdf").read_bytes()[:5] == b"%PDF-"
    assert b"<svg" in plot.save(fig, tmp_path / "fig.svg").read_bytes()[:400]
    with pytest.raises(ValueError, match="suffix"):
        plot.save(fig, tmp_path / "fig")


def test_axis_label():
    assert plot.axis_label("grasp force", "f_n", "N") == "grasp force $f_n$ [N]"
    assert plot.axis_label("time", unit="s") == "time [s]"
    assert plot.axis_label("S") == "S"


def test_panel_labels():
    _fig, axes = plot.new_figure(3)
    plot.panel_labels(axes)
    texts = [[t.get_text() for t in ax.texts] for ax in axes]
    assert texts == [["(a)"], ["(b)"], ["(c)"]]


def test_inset_zoom_copies_data_lines_and_fits_y():
    """The inset repeats the data lines (not axhline), y fitted to the data inside xlim, and
    its copies stay out of figure legends."""
    _fig, ax = plot.new_figure()
    t = np.linspace(0.0, 10.0, 1001)
    ax.plot(t, np.sin(t), label="sin", color=plot.color(1), linestyle="--")
    ax.plot(t, 0.5 * np.cos(t), label="cos")
    ax.axhline(0.0, color="black")
    inset = plot.inset_zoom(ax, (2.0, 3.0))
    lines = inset.get_lines()
    assert len(lines) == 2
    assert lines[0].get_color() == plot.color(1) and lines[0].get_linestyle() == "--"
    assert all(line.get_label().startswith("_") for line in lines)
    assert inset.get_xlim() == pytest.approx((2.0, 3.0))
    sel = (t >= 2.0) & (t <= 3.0)
    lo = min(np.sin(t[sel]).min(), (0.5 * np.cos(t[sel])).min())
    hi = max(np.sin(t[sel]).max(), (0.5 * np.cos(t[sel])).max())
    y0, y1 = inset.get_ylim()
    assert y0 < lo and y1 > hi and (y1 - y0) < 1.3 * (hi - lo)
    _handles, labels = ax.get_legend_handles_labels()
    assert labels == ["sin", "cos"]
    plot.inset_zoom(ax, (1.0, 2.0), (0.0, 1.0))  # explicit ylim
    with pytest.raises(ValueError, match="xlim"):
        plot.inset_zoom(ax, (3.0, 2.0))


def test_twin_y_right_axis_style():
    """twin_y: shares the x axis, shows the right spine the style hides, no grid of its own,
    label and tick labels in the given colour (default text colour without one)."""
    with plot.style():
        _fig, ax = plot.new_figure()
        twin = plot.twin_y(ax, plot.axis_label("torque", r"|\tau|", "N mm"), color=plot.color(3))
        plain = plot.twin_y(ax)
        _fig.canvas.draw()
    assert twin.get_shared_x_axes().joined(ax, twin)
    assert twin.spines["right"].get_visible() and not ax.spines["right"].get_visible()
    assert not any(g.get_visible() for g in twin.yaxis.get_gridlines())
    assert any(g.get_visible() for g in ax.yaxis.get_gridlines())
    assert twin.get_ylabel() == r"torque $|\tau|$ [N mm]"
    assert to_rgb(twin.yaxis.label.get_color()) == to_rgb(plot.color(3))
    assert all(to_rgb(t.label2.get_color()) == to_rgb(plot.color(3))
               for t in twin.yaxis.get_major_ticks())
    assert plain.get_ylabel() == ""
    assert to_rgb(plain.yaxis.label.get_color()) == to_rgb(matplotlib.rcParams["text.color"])


def test_merged_legend_collects_twin_axes_in_order():
    """merged_legend: one legend on the first axis with its entries, then the others'."""
    with plot.style():
        _fig, ax = plot.new_figure()
        twin = plot.twin_y(ax)
        ax.plot([0, 1], [0, 1], label="force")
        twin.plot([0, 1], [1, 0], label="torque")
        ax.plot([0, 1], [0.5, 0.5])  # unlabelled: not in the legend
        ax.axvspan(0.2, 0.4, label="lift")
        leg = plot.merged_legend(ax, twin, loc="upper left", ncol=2)
    assert [t.get_text() for t in leg.get_texts()] == ["force", "lift", "torque"]
    assert ax.get_legend() is leg and twin.get_legend() is None


# --- the experiment figures (lugrip.plot.experiments) drawn with these helpers ----------------

_SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"


@pytest.fixture(scope="module")
def short_runs():
    """Short lumped-plant runs of the scenarios the paper figures need (exp3 with its
    no-pivoting run, exp1 with the baselines)."""
    from lugrip.sim.scenarios import run_scenario

    names = ("exp1_big_resin_block", "exp2_small_resin_block", "exp3_plastic_bottle_pivot",
             "exp4_aluminium_can_full", "exp4_aluminium_can_empty")
    return {n: run_scenario(_SCENARIOS / f"{n}.yaml", plant_model="lumped", short=True,
                            baselines=n == "exp1_big_resin_block") for n in names}


def _legend_texts(ax):
    leg = ax.get_legend()
    return [] if leg is None else [t.get_text() for t in leg.get_texts()]


def _spans(ax):
    """(colour, x0, x1) of the shaded intervals (axvspan rectangles) of an axis."""
    out = []
    for p in ax.patches:
        x = p.get_x() if hasattr(p, "get_x") else p.get_xy()[0][0]
        w = p.get_width() if hasattr(p, "get_width") else p.get_xy()[2][0] - x
        out.append((matplotlib.colors.to_hex(p.get_facecolor()).upper(), float(x), float(x + w)))
    return out


def test_experiment_figures_panels_labels_and_legends(short_runs):
    """Figures 11/13/15/17 and the baseline figure: panels, axis labels, legend entries, panel
    letters, time axis, and the shaded phases where the scenario puts them."""
    from lugrip.plot import experiments as pe

    r1, r2, r3 = (short_runs[n] for n in ("exp1_big_resin_block", "exp2_small_resin_block",
                                          "exp3_plastic_bottle_pivot"))
    full, empty = short_runs["exp4_aluminium_can_full"], short_runs["exp4_aluminium_can_empty"]
    f_const = r1.metrics["constant_force"]["constant_force"]
    force, torque = "force [N]", r"torque $|\tau|$ [N mm]"
    s_c, omega = "S, $\\tilde c$ [-]", r"slip velocity $\hat\omega$ [rad/s]"
    expect = {
        "fig11": (pe.figure_11(r1), r1, [force, s_c, omega], [],
                  [["grasp force $f_n$", "command"],
                   ["slippage indicator $S$", r"estimated $\tilde c$"], []]),
        "fig13": (pe.figure_13(r2), r2, [force, s_c, omega], [torque],
                  [["grasp force $f_n$", "command", "tangential load $f_t$", r"torque $|\tau|$"],
                   ["slippage indicator $S$", r"estimated $\tilde c$"], []]),
        "fig15": (pe.figure_15(r3), r3, [force, r"CoR $\tilde c$ [-]"], [torque],
                  [["grasp force $f_n$", "command", r"torque $|\tau|$"],
                   [r"estimated $\tilde c$", "end of pivoting ($\\tilde c$ = 1)", "lift",
                    "disturbance", "pivoting"]]),
        "fig17": (pe.figure_17(full, empty), full, [force, "slippage indicator $S$ [-]"],
                  [torque],
                  [["full: grasp force", "full: tangential force", "empty: grasp force",
                    "empty: tangential force", r"full: torque $|\tau|$",
                    r"empty: torque $|\tau|$"], ["full: $S$", "empty: $S$"]]),
        "baselines": (pe.figure_baselines(r1), r1,
                      ["command $f_n$ [N]", "slip [mm]", "rotation [deg]"], [],
                      [["lugrip", f"constant force {f_const:.2f} N (minimum that survives)",
                        "friction cone"], [], []]),
    }
    for name, (fig, result, ylabels, twin_labels, legends) in expect.items():
        s = result.scenario
        cfg = s.plant_config()
        panels = [ax for ax in fig.axes if ax.get_ylabel() in ylabels]
        twins = [ax for ax in fig.axes if ax.get_ylabel() in twin_labels]
        assert [ax.get_ylabel() for ax in panels] == ylabels, name
        assert len(twins) == len(twin_labels), name
        for ax in twins:
            assert ax.spines["right"].get_visible() and ax.get_ylim()[0] == 0.0
        assert [_legend_texts(ax) for ax in panels] == legends, name
        assert [[t.get_text() for t in ax.texts if t.get_text().startswith("(")]
                for ax in panels] == [[f"({c})"] for c in "abc"[: len(panels)]], name
        assert panels[-1].get_xlabel() == "time $t$ [s]"
        assert panels[-1].get_xlim() == pytest.approx((0.0, s.duration))
        assert all(not ax.get_xlabel() for ax in panels[:-1])
        # shading: the lift grey, each disturbance orange, on every panel, in the plant's times
        lift = [(m.t_start, m.t_start + m.duration) for m in cfg.moves]
        dist = [(d.t_start, d.t_start + d.duration) for d in cfg.disturbances]
        for ax in panels:
            spans = _spans(ax)
            assert [x for c, *x in spans if c == pe.GREY] == [pytest.approx(v) for v in lift]
            assert [x for c, *x in spans if c == pe.ORANGE] == [pytest.approx(v) for v in dist]
        assert fig.get_suptitle()
    # the pivoting interval (green) on exp3 from the controller mode
    run = r3.runs["lugrip"]
    piv = run["t"][run["mode"] == 1]
    assert piv.size > 0
    fig15 = expect["fig15"][0]
    for ax in [a for a in fig15.axes if a.get_ylabel() in expect["fig15"][2]]:
        assert [x for c, *x in _spans(ax) if c == pe.GREEN] == [pytest.approx((piv[0], piv[-1]))]
