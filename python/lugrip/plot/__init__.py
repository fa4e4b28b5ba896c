"""Shared figure style for lugrip's plots, and the figures themselves in submodules:
:mod:`lugrip.plot.observer` (observer replay, paper Figure 5) and
:mod:`lugrip.plot.experiments` (the experiment figures 11, 13, 15, 17).

Every figure of the project (limit surface, observer replay, experiments) is drawn with the
helpers below so they look alike: one colour cycle, labelled axes with units, a light grid,
constrained layout, PNG at 150 dpi. Figures are plain :class:`matplotlib.figure.Figure`
objects on the Agg canvas: no pyplot, no global backend switch, safe in scripts, tests and
threads.

Typical use::

    from lugrip import plot

    with plot.style():
        fig, (ax_f, ax_s) = plot.new_figure(2, sharex=True, title="Experiment 1")
        ax_f.plot(t, f_n, color=plot.color(0), label="grasp force")
        ax_f.set_ylabel(plot.axis_label("grasp force", "f_n", "N"))
        plot.panel_labels([ax_f, ax_s])
        plot.save(fig, "out/fig11_experiment1.png")
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator, Sequence
from pathlib import Path

import matplotlib
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

__all__ = [
    "DPI",
    "PALETTE",
    "RC",
    "axis_label",
    "color",
    "inset_zoom",
    "merged_legend",
    "new_figure",
    "panel_labels",
    "save",
    "style",
    "twin_y",
]

PALETTE: tuple[str, ...] = (
    "#0072B2",  # blue
    "#D55E00",  # vermilion
    "#009E73",  # bluish green
    "#CC79A7",  # reddish purple
    "#E69F00",  # orange
    "#56B4E9",  # sky blue
    "#000000",  # black
    "#999999",  # grey
)
"""Colour cycle (Okabe-Ito, without yellow): distinguishable with colour-vision deficiencies
and in greyscale print. Use ``color(i)`` so series keep their colour across figures."""

DPI = 150
"""Resolution of raster output [dots per inch]; figures are sized in inches for 100 % zoom."""

RC: dict[str, object] = {
    "font.size": 10.0,
    "axes.titlesize": 11.0,
    "axes.labelsize": 10.0,
    "legend.fontsize": 9.0,
    "xtick.labelsize": 9.0,
    "ytick.labelsize": 9.0,
    "lines.linewidth": 1.8,
    "lines.markersize": 5.0,
    "axes.grid": True,
    "grid.alpha": 0.35,
    "grid.linewidth": 0.6,
    "axes.spines.top": False,
    "axes.spines.right": False,
    "axes.axisbelow": True,
    "axes.prop_cycle": matplotlib.cycler(color=list(PALETTE)),
    "legend.frameon": True,
    "legend.framealpha": 0.9,
    "legend.edgecolor": "#cccccc",
    "mathtext.fontset": "dejavusans",
    "savefig.dpi": DPI,
    "savefig.facecolor": "white",
}
"""matplotlib rcParams of the project style (applied by :func:`style`)."""


def color(i: int) -> str:
    """The i-th colour of the cycle (wraps around)."""
    return PALETTE[int(i) % len(PALETTE)]


@contextlib.contextmanager
def style() -> Iterator[None]:
    """Context in which figures are created and drawn with the project style (fonts, line
    widths, grid, colour cycle). rcParams are restored on exit."""
    with matplotlib.rc_context(RC):
        yield


def new_figure(
    rows: int = 1,
    cols: int = 1,
    *,
    width: float | None = None,
    height: float | None = None,
    row_height: float = 2.6,
    col_width: float = 4.8,
    sharex: bool | str = False,
    sharey: bool | str = False,
    height_ratios: Sequence[float] | None = None,
    width_ratios: Sequence[float] | None = None,
    title: str | None = None,
    squeeze: bool = True,
):
    """A figure with a grid of axes, constrained layout, on the Agg canvas.

    Args:
        rows, cols: grid of axes.
        width, height: figure size [in]; by default cols * col_width and rows * row_height
            (scaled by height_ratios), which reads well at 100 % zoom at :data:`DPI`.
        sharex, sharey: as in ``Figure.subplots``.
        height_ratios, width_ratios: relative sizes of rows / columns.
        title: figure title (suptitle).
        squeeze: return a single Axes for 1x1 and a 1-D array for one row or column.

    Returns:
        (fig, axes): axes as ``Figure.subplots`` returns them.
    """
    if rows < 1 or cols < 1:
        raise ValueError(f"new_figure: rows = {rows}, cols = {cols}: both must be >= 1")
    if width is None:
        width = cols * col_width
    if height is None:
        if height_ratios is not None:
            height = row_height * rows * sum(height_ratios) / (max(height_ratios) * rows)
            height = max(height, row_height)
        else:
            height = rows * row_height
        if title:
            height += 0.3
    fig = Figure(figsize=(width, height), layout="constrained")
    FigureCanvasAgg(fig)
    gridspec_kw = {}
    if height_ratios is not None:
        gridspec_kw["height_ratios"] = list(height_ratios)
    if width_ratios is not None:
        gridspec_kw["width_ratios"] = list(width_ratios)
    axes = fig.subplots(rows, cols, sharex=sharex, sharey=sharey, squeeze=squeeze,
                        gridspec_kw=gridspec_kw or None)
    for ax in fig.axes:
        ax.grid(True, alpha=0.35, linewidth=0.6)
        ax.set_axisbelow(True)
    if title:
        fig.suptitle(title, fontsize=RC["axes.titlesize"])
    return fig, axes


def save(fig: Figure, path: str | Path, *, dpi: int = DPI) -> Path:
    """Write the figure; the format follows the suffix (.png, .pdf, .svg). Creates the parent
    directory. The file is replaced atomically (a temporary renamed over it). Returns the
    path."""
    from .._atomic import write_atomic

    path = Path(path)
    if not path.suffix:
        raise ValueError(f"{path}: no file suffix; use .png, .pdf or .svg")
    path.parent.mkdir(parents=True, exist_ok=True)
    return write_atomic(path, lambda tmp: fig.savefig(tmp, dpi=dpi, facecolor="white"))


def axis_label(name: str, symbol: str | None = None, unit: str | None = None) -> str:
    """'name $symbol$ [unit]' for axis labels; symbol is mathtext without the dollars
    (e.g. r"\\hat\\omega"), unit in plain text (e.g. "rad/s"); '-' for dimensionless."""
    text = name
    if symbol:
        text += f" ${symbol}$"
    if unit:
        text += f" [{unit}]"
    return text


def twin_y(ax: Axes, label: str | None = None, *, color: str | None = None) -> Axes:
    """A right-hand y axis sharing the x axis of `ax`: its spine shown (the style hides right
    spines), no grid of its own (the grid of `ax` stands), label and tick labels in `color`
    when given."""
    twin = ax.twinx()
    if label:
        if color is None:
            twin.set_ylabel(label)
        else:
            twin.set_ylabel(label, color=color)
    if color is not None:
        twin.tick_params(axis="y", colors=color)
    twin.spines["right"].set_visible(True)
    twin.grid(False)
    return twin


def merged_legend(ax: Axes, *others: Axes, **kwargs):
    """One legend on `ax` with the labelled artists of `ax` and then of `others` (e.g. a
    :func:`twin_y` axis); kwargs as for ``Axes.legend``. Returns the Legend."""
    handles, labels = ax.get_legend_handles_labels()
    for other in others:
        h, lab = other.get_legend_handles_labels()
        handles, labels = handles + h, labels + lab
    return ax.legend(handles, labels, **kwargs)


def panel_labels(axes: Sequence[Axes], *, start: str = "a") -> None:
    """Label panels (a), (b), ... in their top-left corner."""
    for i, ax in enumerate(axes):
        ax.text(0.01, 0.98, f"({chr(ord(start) + i)})", transform=ax.transAxes, ha="left",
                va="top", fontweight="bold", fontsize=RC["axes.labelsize"])


def inset_zoom(ax: Axes, xlim: tuple[float, float], ylim: tuple[float, float] | None = None,
               *, bounds: tuple[float, float, float, float] = (0.58, 0.55, 0.4, 0.4)) -> Axes:
    """Inset axes repeating the lines of `ax` over `xlim` (and `ylim`, default: fitted to the
    data in xlim), with the zoomed area outlined on `ax` (as the paper's Figure 5 zooms).

    Args:
        bounds: inset position (x0, y0, width, height) in axes fraction.

    Returns:
        The inset Axes.
    """
    import numpy as np

    x0, x1 = float(xlim[0]), float(xlim[1])
    if not x1 > x0:
        raise ValueError(f"inset_zoom: xlim = {xlim}: need x0 < x1")
    inset = ax.inset_axes(list(bounds))
    lo, hi = np.inf, -np.inf
    for line in ax.get_lines():
        if line.get_transform() is not ax.transData:
            continue  # axhline/axvline and other lines in axes coordinates
        x = np.asarray(line.get_xdata(), dtype=float)
        y = np.asarray(line.get_ydata(), dtype=float)
        copy = Line2D(x, y)
        copy.update_from(line)  # colour, width, dashes, markers, zorder
        copy.set_transform(inset.transData)
        copy.set_label("_" + line.get_label().lstrip("_"))  # keep it out of figure legends
        inset.add_line(copy)
        sel = (x >= x0) & (x <= x1) & np.isfinite(y)
        if sel.any():
            lo, hi = min(lo, float(y[sel].min())), max(hi, float(y[sel].max()))
    if ylim is None:
        if not np.isfinite(lo):
            lo, hi = ax.get_ylim()
        pad = 0.08 * (hi - lo) if hi > lo else max(abs(hi), 1.0) * 0.05
        ylim = (lo - pad, hi + pad)
    inset.set_xlim(x0, x1)
    inset.set_ylim(*ylim)
    inset.grid(True, alpha=0.35, linewidth=0.6)
    inset.tick_params(labelsize=RC["xtick.labelsize"] - 1)
    ax.indicate_inset_zoom(inset, edgecolor="black", alpha=0.6)
    return inset
