#!/usr/bin/env python3
"""Generation speed and content of the MuJoCo rubbing rig (lugrip.rigs.mujoco_rig); writes the
section between ``<!-- mujoco-rig:begin -->`` and ``<!-- mujoco-rig:end -->`` of
BENCHMARKS.md (the rest of the file is kept).

    python benchmarks/bench_mujoco_rig.py [--out BENCHMARKS.md] [--maneuvers 160] [--quick]

In one run: the rig on ``--maneuvers`` maneuvers of the default design; as baseline the bare
``mj_step`` loop over the same number of steps on the same model (MuJoCo's own cost, without
the rig's per-step Python: pad law, damping, wrench, slip velocity, labels). Then what the data
hold. Benchmarks are not tests: nothing here fails on a timing.
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import mujoco
from lugrip.rigs import RubbingDesign
from lugrip.rigs.mujoco_rig import MujocoRubbingRig
from sections import markers, write_section

SECTION = "mujoco-rig"
TARGET_S = 60.0  # [s] 160 maneuvers on one core


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, default=Path("BENCHMARKS.md"))
    ap.add_argument("--maneuvers", type=int, default=160)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--quick", action="store_true", help="16 maneuvers (smoke run)")
    args = ap.parse_args(argv)
    n = 16 if args.quick else args.maneuvers
    rig = MujocoRubbingRig()
    t0 = time.perf_counter()
    data = rig.simulate(RubbingDesign(), n, args.seed)
    sec = time.perf_counter() - t0
    steps = round((data.log.t[-1] + n * rig.settings.settle) / rig.settings.timestep)
    m, d, _ = rig.build()
    d.ctrl[0] = -5.0  # pressed: one contact, as in the rig
    t0 = time.perf_counter()
    for _ in range(steps):
        mujoco.mj_step(m, d)
    bare = time.perf_counter() - t0
    load = 0.0
    if hasattr(os, "getloadavg"):
        load = os.getloadavg()[0]
    pre = 1e3 * data.presliding_durations()
    share = [100.0 * np.mean(data.phase == k) for k in range(4)]
    g = data.gross_sliding
    tr = data.truth
    begin, end = markers(SECTION)
    lines = [
        begin,
        "",
        "## MuJoCo rubbing rig: generation speed and content",
        "",
        (
            f"`python benchmarks/bench_mujoco_rig.py --maneuvers {n}` on {platform.machine()} "
            f"({os.cpu_count()} cores, one used, load average {load:.1f}), MuJoCo "
            f"{mujoco.__version__}; default `RubbingDesign`, seed {args.seed}. Target: 160 "
            f"maneuvers in <= {TARGET_S:g} s on one core (validation/mujoco/README.md)."
        ),
        "",
        "| run | maneuvers | samples | MuJoCo steps | time [s] | samples/s |",
        "|---|---|---|---|---|---|",
        (
            f"| MujocoRubbingRig.simulate | {n} | {len(data)} | {steps} | {sec:.2f} | "
            f"{len(data) / sec:,.0f} |"
        ),
        f"| baseline: bare mj_step loop, same steps, pad pressed at rest | - | - | {steps} | {bare:.2f} | - |",
        "",
        (
            f"MuJoCo's stepping is {100 * bare / sec:.0f} % of the rig's time; the rest is the "
            "per-step Python (pad law and damping, wrench, slip velocity, labels)."
        ),
        "",
        "What the data hold:",
        "",
        (
            "| approach | presliding | sliding | rest | presliding duration median (5-95 %, max) "
            "[ms] | cone utilisation in sliding (min) | max slip speed [mm/s] | max f_n off the "
            "plan | mu | tau_max(2 N), tau_max(8 N) [N m] |"
        ),
        "|---|---|---|---|---|---|---|---|---|---|",
        (
            f"| {share[0]:.1f} % | {share[1]:.1f} % | {share[2]:.1f} % | {share[3]:.1f} % | "
            f"{np.median(pre):.0f} ({np.percentile(pre, 5):.0f}-{np.percentile(pre, 95):.0f}, "
            f"{pre.max():.0f}) | {data.load_ratio[g].min():.4f} | {1e3 * data.v_true.max():.2f} | "
            f"{100 * data.meta['normal_force_deviation_max']:.1f} % | {tr.mu:g} | "
            f"{tr.tau_max(2.0):.3e}, {tr.tau_max(8.0):.3e} |"
        ),
        "",
        (
            f"{len(pre)} of {n} maneuvers reach gross sliding. Coulomb friction only: the "
            "sliding wrench carries no speed information."
        ),
        "",
        end,
        "",
    ]
    text = "\n".join(lines)
    write_section(args.out, text, SECTION)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
