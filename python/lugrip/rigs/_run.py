"""Per-maneuver plant output shared by the rigs and the step that turns it into a sensor log
with labels (:func:`assemble`)."""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np

from ..io import SlidingLog
from ._data import RigTruth, RubbingData
from .motion import ManeuverPlan, RubbingDesign, stack_times

__all__ = ["RigRun", "assemble"]


@dataclasses.dataclass(frozen=True)
class RigRun:
    """True outputs of a plant along one plan (no sensor noise), one value per plan sample.

    Attributes:
        f_n: true normal force [N].
        f_x, f_y: in-plane force the slider exerts on the fingertip, sensor frame [N].
        tau: moment the slider exerts on the fingertip about the patch centre (sensor z) [N m].
        load_ratio: friction torque about the prescribed CoR over the plant's full-sliding
            torque about that CoR at static friction [-].
        sliding: True where the plant is in gross sliding (from its own state).
        rho: true contact radius [m].
        sliding_load: fraction of f_n carried by sliding parts of the contact [-] (NaN when
            the plant cannot tell).
    """

    f_n: np.ndarray
    f_x: np.ndarray
    f_y: np.ndarray
    tau: np.ndarray
    load_ratio: np.ndarray
    sliding: np.ndarray
    rho: np.ndarray
    sliding_load: np.ndarray | None = None


def assemble(plans: Sequence[ManeuverPlan], runs: Sequence[RigRun], design: RubbingDesign,
             truth: RigTruth, *, source: str) -> RubbingData:
    """Join per-maneuver plant outputs into one sensor log with labels: maneuvers back to
    back in time, each read through its plan's sensor (offsets and white noise); phase 2
    where the plant says it slides while the motion is under way."""
    plans = list(plans)
    if len(plans) != len(runs):
        raise ValueError("assemble: one run per plan needed")
    dt = 1.0 / design.sample_rate
    starts = stack_times(plans, dt)
    cols: dict[str, list] = {k: [] for k in ("t", "f_n", "f_x", "f_y", "tau", "omega",
                                             "maneuver", "phase", "load", "c", "v")}
    for p, r, t0 in zip(plans, runs, starts):
        if len(r.f_n) != len(p):
            raise ValueError(f"assemble: maneuver {p.index}: run has {len(r.f_n)} samples, "
                             f"plan {len(p)}")
        f_n, f_x, f_y, tau = p.sensor(r.f_n, r.f_x, r.f_y, r.tau)
        phase = p.commanded_phase()
        phase[(phase == 1) & np.asarray(r.sliding, dtype=bool)] = 2
        omega = p.omega
        cols["t"].append(t0 + p.t)
        cols["f_n"].append(f_n)
        cols["f_x"].append(f_x)
        cols["f_y"].append(f_y)
        cols["tau"].append(tau)
        cols["omega"].append(omega)
        cols["maneuver"].append(np.full(len(p), p.index, dtype=np.int64))
        cols["phase"].append(phase)
        cols["load"].append(np.asarray(r.load_ratio, dtype=float))
        cols["c"].append(p.c_tilde_signed(r.rho))
        cols["v"].append(np.abs(omega) * float(np.hypot(*p.cor)))
    cat = {k: np.concatenate(v) for k, v in cols.items()}
    log = SlidingLog.from_arrays(
        cat["t"], cat["f_n"], cat["tau"], f_x=cat["f_x"], f_y=cat["f_y"], omega=cat["omega"],
        maneuver=cat["maneuver"], source=source, meta={"plant": source})
    maneuvers = [{"index": p.index, "c_tilde": p.c_tilde, "f_n": p.f_n_nominal,
                  "reversals": p.reversals, "cor": p.cor.tolist(),
                  "omega_peak": float(np.max(np.abs(p.knots_omega))),
                  "n_samples": len(p)} for p in plans]
    return RubbingData(log=log, phase=cat["phase"], load_ratio=cat["load"],
                       c_tilde_true=cat["c"], v_true=cat["v"], truth=truth,
                       meta={"design": design.to_dict(), "maneuvers": maneuvers})
