"""Figure of one scenario on MuJoCo: rendered frames of the lift (and the pivot) above the force,
slip and slip-rate panels, with the patch plant's run beside it when given."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

__all__ = ["figure_mujoco", "snapshot_times"]


def snapshot_times(scenario) -> list[float]:
    """Times [s] worth a frame: before, during and after the lift, the pivot's start and the
    end of the run."""
    t0, t1 = scenario.lift_start, scenario.lift_end
    times = [max(0.0, t0 - 0.5), 0.5 * (t0 + t1), t1 + 0.5]
    for e in scenario.schedule:
        if str(e.get("action", "")).startswith("pivot"):
            tp = float(e["time"])
            times += [tp + 0.5, tp + 2.5]
    times.append(scenario.duration - 0.1)
    return sorted(t for t in set(times) if 0.0 <= t < scenario.duration)


def figure_mujoco(
    result,
    frames: Sequence[tuple[float, np.ndarray]] = (),
    patch=None,
    note: str | None = None,
):
    """Matplotlib figure: frames (t, RGB) in the top row; grip force and command; slip and
    rotation from the lift start; omega_hat against MuJoCo's true slip rate (finger 0).
    `patch`: the patch plant's ScenarioResult of the same scenario, drawn dashed."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    s, run = result.scenario, result.runs["lugrip"]
    n_frames = len(frames)
    fig = plt.figure(figsize=(12, 9.5 if n_frames else 7.5), constrained_layout=True)
    rows = [1.3, 1, 1, 1] if n_frames else [1, 1, 1]
    gs = fig.add_gridspec(len(rows), max(n_frames, 1), height_ratios=rows)
    if n_frames:
        for k, (t, img) in enumerate(frames):
            ax = fig.add_subplot(gs[0, k])
            ax.imshow(img)
            ax.set_title(f"t = {t:.1f} s", fontsize=9)
            ax.axis("off")
    elif note:
        fig.text(0.5, 0.99, note, ha="center", va="top", fontsize=8, color="0.3")
    first = 1 if n_frames else 0
    axes = [fig.add_subplot(gs[first + k, :]) for k in range(3)]
    for a in axes[1:]:
        a.sharex(axes[0])
    t = run["t"]
    ax = axes[0]
    ax.plot(t, run["f_n"], color="tab:blue", lw=1.2, label="MuJoCo: grip force")
    ax.plot(t, run["command"], color="k", lw=0.7, ls="--", label="MuJoCo: command")
    if "constant_force" in result.metrics and result.metrics["constant_force"].get(
        "constant_force"
    ):
        ax.axhline(
            result.metrics["constant_force"]["constant_force"],
            color="tab:green",
            lw=0.8,
            ls=":",
            label="smallest constant force that holds (MuJoCo)",
        )
    if patch is not None:
        pr = patch.runs["lugrip"]
        ax.plot(
            pr["t"], pr["f_n"], color="tab:orange", lw=1.0, ls="--", label="patch plant: grip force"
        )
    ax.set_ylabel("force [N]")
    tw = ax.twinx()
    tw.plot(t, 1e3 * np.abs(run["tau_meas_0"]), color="tab:pink", lw=0.7)
    tw.plot(t, run["f_t_meas_0"] * 10.0, color="tab:purple", lw=0.7)
    tw.set_ylabel(r"$|\tau_0|$ [N mm] (pink), 10 $f_{t,0}$ [N] (purple)", fontsize=8)
    ax.legend(loc="upper left", fontsize=7)
    ax = axes[1]
    i0 = run.index(s.lift_start)
    ax.plot(
        t,
        1e3 * np.hypot(run["slip_x"] - run["slip_x"][i0], run["slip_y"] - run["slip_y"][i0]),
        color="tab:blue",
        label="MuJoCo: slip [mm]",
    )
    ax.plot(
        t,
        np.degrees(run["rotation"] - run["rotation"][i0]),
        color="tab:red",
        label="MuJoCo: rotation [deg]",
    )
    if patch is not None:
        pr = patch.runs["lugrip"]
        j0 = pr.index(s.lift_start)
        ax.plot(
            pr["t"],
            1e3 * np.hypot(pr["slip_x"] - pr["slip_x"][j0], pr["slip_y"] - pr["slip_y"][j0]),
            color="tab:blue",
            ls="--",
            lw=0.8,
            label="patch: slip [mm]",
        )
        ax.plot(
            pr["t"],
            np.degrees(pr["rotation"] - pr["rotation"][j0]),
            color="tab:red",
            ls="--",
            lw=0.8,
            label="patch: rotation [deg]",
        )
    ax.axhline(1.0, color="k", lw=0.5, ls=":")
    ax.axhline(-1.0, color="k", lw=0.5, ls=":")
    ax.set_ylabel("from the lift start")
    ax.legend(loc="upper left", fontsize=7, ncol=2)
    ax = axes[2]
    ax.plot(
        t,
        run["omega_true_0"],
        color="0.4",
        lw=1.0,
        label=r"MuJoCo: true slip rate $\omega$ (pad 0)",
    )
    ax.plot(
        t, run["omega_hat_0"], color="tab:blue", lw=0.8, label=r"$\hat\omega$ (observer, pad 0)"
    )
    ax.set_ylabel("[rad/s]")
    ax.set_xlabel("time $t$ [s]")
    ax.legend(loc="upper left", fontsize=7)
    for a in axes:
        a.axvspan(s.lift_start, s.lift_end, color="0.92", zorder=0)
        for dist in s.plant_config().disturbances:
            a.axvspan(
                dist.t_start, dist.t_start + dist.duration, color="tab:orange", alpha=0.15, zorder=0
            )
        a.grid(alpha=0.3)
    scene = run.scene if hasattr(run, "scene") else {"status": "ok"}
    verdict = "pass" if result.passed else "FAIL"
    fig.suptitle(f"{s.name} on MuJoCo: {verdict} (scene: {scene['status']})", fontsize=11)
    return fig


def save(fig, path: str | Path) -> Path:
    import matplotlib.pyplot as plt

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path
