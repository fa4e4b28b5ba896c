"""Figure-5-style plots of an observer replay (paper Figure 5): ground-truth sliding velocity
omega (blue), estimate omega_hat (red), error (magenta) over a whole log, with zooms on single
maneuvers as inner plots, and the slippage indicator S below.

Drawn with the project style (:mod:`lugrip.plot`): Agg canvas, no pyplot.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from .. import plot

__all__ = ["COLORS", "FIG5_NAME", "figure5", "pick_zooms", "write_figure5"]

FIG5_NAME = "fig05_observer"
"""File stem of the figure written by :func:`write_figure5`."""

COLORS = {
    "omega": plot.color(0),  # blue: ground truth (paper: blue)
    "omega_hat": plot.color(1),  # vermilion: estimate (paper: red)
    "error": plot.color(3),  # reddish purple: error (paper: magenta)
    "S": plot.color(2),
    "threshold": plot.color(7),
}


def _blocks(maneuver: np.ndarray) -> list[tuple[int, int]]:
    n = maneuver.size
    if n == 0:
        return []
    cuts = np.flatnonzero(maneuver[1:] != maneuver[:-1]) + 1
    bounds = np.concatenate(([0], cuts, [n])).astype(int)
    return [(int(a), int(b)) for a, b in zip(bounds[:-1], bounds[1:])]


def pick_zooms(
    t, signal, maneuver=None, c_tilde=None, *, count: int = 3, min_peak: float = 0.0
) -> list[tuple[float, float]]:
    """Time windows (t0, t1) of up to ``count`` single maneuvers worth a zoom: the strongest
    maneuver (largest |signal|) of each CoR regime when ``c_tilde`` is given (rotation-
    dominated |c~| < 0.5, mixed, translation-dominated >= 1), else the strongest ones, in
    time order. Without maneuver ids, windows of ~2 s around the largest peaks."""
    t = np.asarray(t, dtype=float)
    sig = np.abs(np.nan_to_num(np.asarray(signal, dtype=float)))
    if t.size < 2 or count < 1:
        return []
    if maneuver is None:
        span = min(2.0, 0.1 * (t[-1] - t[0])) if t[-1] > t[0] else 1.0
        out, used = [], np.zeros(t.size, dtype=bool)
        for i in np.argsort(-sig):
            if len(out) >= count or sig[i] <= min_peak:
                break
            if used[i]:
                continue
            sel = np.abs(t - t[i]) <= span
            used |= np.abs(t - t[i]) <= 2 * span
            out.append((float(t[sel][0]), float(t[sel][-1])))
        return sorted(out)
    blocks = [(a, b) for a, b in _blocks(np.asarray(maneuver)) if b - a >= 2]
    peaks = [float(sig[a:b].max()) for a, b in blocks]
    if c_tilde is not None:
        ct = np.abs(np.asarray(c_tilde, dtype=float))
        groups: dict[int, list[int]] = {}
        for k, (a, b) in enumerate(blocks):
            seg = sig[a:b]
            w = seg > 0.25 * seg.max() if seg.max() > 0 else np.ones(seg.size, bool)
            c = float(np.median(ct[a:b][w]))
            groups.setdefault(0 if c < 0.5 else (1 if c < 1.0 else 2), []).append(k)
        chosen = [max(g, key=lambda k: peaks[k]) for _, g in sorted(groups.items())]
        rest = sorted((k for k in range(len(blocks)) if k not in chosen), key=lambda k: -peaks[k])
        chosen += rest
    else:
        chosen = sorted(range(len(blocks)), key=lambda k: -peaks[k])
    chosen = [k for k in chosen if peaks[k] > min_peak][:count]
    return sorted((float(t[blocks[k][0]]), float(t[blocks[k][1] - 1])) for k in chosen)


def figure5(
    t,
    omega_hat,
    omega=None,
    S=None,
    *,
    maneuver=None,
    c_tilde=None,
    zooms: Sequence[tuple[float, float]] | None = None,
    s_threshold: float | None = 0.9,
    title: str | None = None,
    rmse: float | None = None,
):
    """Figure 5 of the paper for an observer replay.

    Args:
        t: sample times [s]; omega_hat: estimate [rad/s]; omega: ground truth [rad/s] or None
            (then the error is not drawn); S: slippage indicator (second panel) or None.
        maneuver, c_tilde: used to pick the zooms (:func:`pick_zooms`) when ``zooms`` is None.
        zooms: up to three time windows drawn as inner plots (the zoomed areas are outlined).
        s_threshold: horizontal line on the S panel (None: none).
        title: figure title; rmse: added to the legend when given.

    Returns:
        matplotlib Figure.
    """
    t = np.asarray(t, dtype=float)
    w_hat = np.asarray(omega_hat, dtype=float)
    w = None if omega is None else np.asarray(omega, dtype=float)
    if w_hat.shape != t.shape or (w is not None and w.shape != t.shape):
        raise ValueError("figure5: t, omega_hat and omega must have the same length")
    if zooms is None:
        zooms = pick_zooms(t, w if w is not None else w_hat, maneuver, c_tilde)
    zooms = list(zooms)[:3]
    rows = 2 if S is not None else 1
    with plot.style():
        fig, axes = plot.new_figure(
            rows,
            1,
            width=10.0,
            row_height=3.4,
            sharex=True,
            height_ratios=[2.2, 1.0] if rows == 2 else None,
            title=title,
            squeeze=False,
        )
        ax = axes[0, 0]
        lw = 0.8
        if w is not None:
            ax.plot(t, w, color=COLORS["omega"], lw=lw, label=r"ground truth $\omega$")
        label = r"estimate $\hat\omega$"
        ax.plot(t, w_hat, color=COLORS["omega_hat"], lw=lw, label=label)
        if w is not None:
            err_label = r"error $\hat\omega-\omega$"
            if rmse is not None and math.isfinite(rmse):
                err_label += f" (RMSE {rmse:.4f} rad/s)"
            ax.plot(t, w_hat - w, color=COLORS["error"], lw=lw, label=err_label)
        ax.set_ylabel(plot.axis_label("sliding velocity", r"\omega", "rad/s"))
        data = [w_hat] + ([w] if w is not None else [])
        finite = np.concatenate([d[np.isfinite(d)] for d in data]) if t.size else np.zeros(1)
        lo = float(finite.min()) if finite.size else -1.0
        hi = float(finite.max()) if finite.size else 1.0
        if not hi > lo:
            lo, hi = lo - 1.0, hi + 1.0
        span = hi - lo
        if zooms:
            # room above the data for the inner plots, as in the paper's figure
            from matplotlib.ticker import MaxNLocator

            ticks = MaxNLocator(nbins=5).tick_values(lo, hi)
            ax.set_yticks([v for v in ticks if lo - 0.05 * span <= v <= hi + 0.05 * span])
            ax.set_ylim(lo - 0.05 * span, hi + 1.35 * span)
            width = 0.9 / len(zooms)
            for i, (z0, z1) in enumerate(zooms):
                if not z1 > z0:
                    continue
                inset = plot.inset_zoom(
                    ax, (z0, z1), bounds=(0.08 + i * width, 0.56, width - 0.06, 0.41)
                )
                inset.tick_params(labelsize=7)
                inset.xaxis.set_major_locator(MaxNLocator(nbins=4))
        else:
            ax.set_ylim(lo - 0.05 * span, hi + 0.25 * span)
        ax.legend(loc="lower right", ncol=3 if w is not None else 1, fontsize=8)
        if S is not None:
            ax_s = axes[1, 0]
            ax_s.plot(t, np.asarray(S, dtype=float), color=COLORS["S"], lw=lw, label="S")
            if s_threshold is not None:
                ax_s.axhline(
                    s_threshold,
                    color=COLORS["threshold"],
                    lw=0.8,
                    ls="--",
                    label=f"S = {s_threshold:g}",
                )
            ax_s.set_ylim(-0.05, 1.1)
            ax_s.set_ylabel(plot.axis_label("slippage indicator", "S", "-"))
            ax_s.legend(loc="lower right", fontsize=8)
            axes[-1, 0].set_xlabel(plot.axis_label("time", "t", "s"))
            plot.panel_labels([ax, ax_s])
        else:
            ax.set_xlabel(plot.axis_label("time", "t", "s"))
    return fig


def write_figure5(
    out_dir,
    log,
    run,
    *,
    fmt: str = "png",
    title: str | None = None,
    rmse: float | None = None,
    name: str = FIG5_NAME,
) -> Path:
    """Draw :func:`figure5` for ``run = Observer.run(log)`` and save it as
    ``out_dir/<name>.<fmt>``. Returns the path."""
    omega = getattr(log, "omega", None)
    fig = figure5(
        run.t if run.t is not None else np.arange(len(run)) * 0.002,
        run.omega_hat,
        omega,
        run.S,
        maneuver=getattr(log, "maneuver", None),
        c_tilde=run.c_tilde,
        title=title,
        rmse=rmse,
    )
    return plot.save(fig, Path(out_dir) / f"{name}.{fmt}")
