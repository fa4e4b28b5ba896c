"""Figure of a grasp replay (``lugrip replay``): the grasp-force command SlipControl would have
sent beside the one recorded with the log, each finger's slippage indicator S, each
finger's estimated sliding velocity omega_hat, and the controller's friction belief and the
reserve it held.

Drawn with the project style (:mod:`lugrip.plot`): Agg canvas, no pyplot.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .. import plot

__all__ = ["REPLAY_NAME", "figure_replay", "write_figure_replay"]

REPLAY_NAME = "replay_command"
"""File stem of the figure written by :func:`write_figure_replay`."""


def figure_replay(t, command_replay, command_recorded=None, S=None, omega_hat=None, *,
                  held=None, s_threshold: float | None = None, title: str | None = None,
                  mu_belief=None, reserve_force=None):
    """Panels over time t [s] (n,): (a) the replayed command [N] (n,) and, when given,
    the recorded one; samples where the replay held its command (a non-ok status) are marked;
    (b) S per finger, shape (n, fingers), with ``s_threshold`` as a line; (c) omega_hat per
    finger [rad/s], (n, fingers); (d) the controller's friction belief mu_belief [-] (n,) and,
    on a second axis, the reserve of its last command reserve_force [N] (n,). Panels without
    data are left out. Returns the Figure."""
    t = np.asarray(t, dtype=float)
    panels = ["command"] + (["S"] if S is not None else []) + \
        (["omega"] if omega_hat is not None else []) + \
        (["belief"] if mu_belief is not None else [])
    with plot.style():
        fig, axes = plot.new_figure(len(panels), 1, sharex=True, title=title,
                                    col_width=7.5, squeeze=False)
        axes = list(axes[:, 0])
        ax = axes[0]
        if command_recorded is not None:
            ax.plot(t, command_recorded, color=plot.color(0), label="recorded command")
        ax.plot(t, command_replay, color=plot.color(1), label="SlipControl (replay)")
        if held is not None and np.any(held):
            h = np.asarray(held, dtype=bool)
            ax.plot(t[h], np.asarray(command_replay)[h], linestyle="none", marker=".",
                    markersize=2, color=plot.color(3), label="held (status not ok)")
        ax.set_ylabel(plot.axis_label("grasp force command", "f_n", "N"))
        ax.legend(loc="best")
        k = 1
        if S is not None:
            ax_s = axes[k]
            k += 1
            S = np.atleast_2d(np.asarray(S, dtype=float).T).T
            for j in range(S.shape[1]):
                ax_s.plot(t, S[:, j], color=plot.color(2 + 2 * j), label=f"finger {j}")
            if s_threshold is not None:
                ax_s.axhline(s_threshold, color=plot.color(7), linestyle="--", linewidth=0.8)
            ax_s.set_ylabel(plot.axis_label("slippage indicator", "S", "-"))
            ax_s.legend(loc="best")
        if omega_hat is not None:
            ax_w = axes[k]
            w = np.atleast_2d(np.asarray(omega_hat, dtype=float).T).T
            for j in range(w.shape[1]):
                ax_w.plot(t, w[:, j], color=plot.color(2 + 2 * j), label=f"finger {j}")
            ax_w.set_ylabel(plot.axis_label("estimated sliding velocity", r"\hat\omega",
                                            "rad/s"))
            ax_w.legend(loc="best")
            k += 1
        if mu_belief is not None:
            ax_b = axes[k]
            ax_b.plot(t, mu_belief, color=plot.color(0), label="friction belief")
            ax_b.set_ylabel(plot.axis_label("friction belief", r"\hat\mu", "-"))
            if reserve_force is not None:
                ax_r = ax_b.twinx()
                ax_r.plot(t, reserve_force, color=plot.color(3), label="reserve (per finger)")
                ax_r.set_ylabel(plot.axis_label("reserve", "r", "N"))
                ax_r.legend(loc="lower right")
            ax_b.legend(loc="upper left")
        axes[-1].set_xlabel(plot.axis_label("time", "t", "s"))
        if len(axes) > 1:
            plot.panel_labels(axes)
    return fig


def write_figure_replay(out_dir, t, command_replay, command_recorded=None, S=None,
                        omega_hat=None, *, fmt: str = "png", name: str = REPLAY_NAME,
                        **kwargs) -> Path:
    """Draw :func:`figure_replay` and save it as ``out_dir/<name>.<fmt>``. Returns the path."""
    fig = figure_replay(t, command_replay, command_recorded, S, omega_hat, **kwargs)
    return plot.save(fig, Path(out_dir) / f"{name}.{fmt}")
