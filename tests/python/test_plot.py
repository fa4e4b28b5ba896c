"""The shared figure style (lugrip.plot): figures, saving, labels, zoom insets."""

from __future__ import annotations

import struct
import sys

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
    fig, axes = plot.new_figure(3)
    plot.panel_labels(axes)
    texts = [[t.get_text() for t in ax.texts] for ax in axes]
    assert texts == [["(a)"], ["(b)"], ["(c)"]]


def test_inset_zoom_copies_data_lines_and_fits_y():
    """The inset repeats the data lines (not axhline), y fitted to the data inside xlim, and
    its copies stay out of figure legends."""
    fig, ax = plot.new_figure()
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
    handles, labels = ax.get_legend_handles_labels()
    assert labels == ["sin", "cos"]
    plot.inset_zoom(ax, (1.0, 2.0), (0.0, 1.0))  # explicit ylim
    with pytest.raises(ValueError, match="xlim"):
        plot.inset_zoom(ax, (3.0, 2.0))
