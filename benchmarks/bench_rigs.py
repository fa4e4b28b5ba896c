#!/usr/bin/env python3
"""Generation speed and content of the rubbing rigs (lugrip.rigs); writes the section between
``<!-- rigs:begin -->`` and ``<!-- rigs:end -->`` of BENCHMARKS.md (the rest of the file is
kept).

    python benchmarks/bench_rigs.py [--out BENCHMARKS.md] [--maneuvers 160] [--quick]

In one run: the grid plant (both variants) on ``--maneuvers`` maneuvers of the default design,
vectorised over maneuvers and cells; as baseline the same plant integrating one maneuver at a
time (on a subset, per-sample cost); the lumped and patch rigs on the same plans. Then what
the data hold: phase shares, presliding durations, load ratios in gross sliding and the
truth each plant states. Benchmarks are not tests: nothing here fails on a timing.
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
from lugrip.rigs import GridContactRig, RubbingDesign, plan_maneuvers
from lugrip.rigs.model_rigs import LumpedRig, PatchRig
from sections import markers, write_section

SECTION = "rigs"
TARGET_S = 60.0  # [s] 160 maneuvers of the grid plant on one core


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, default=Path("BENCHMARKS.md"))
    ap.add_argument("--maneuvers", type=int, default=160)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--quick", action="store_true", help="16 maneuvers (smoke run)")
    args = ap.parse_args(argv)
    n = 16 if args.quick else args.maneuvers
    design = RubbingDesign()
    rows, sets = [], {}
    for rig in (GridContactRig.stribeck(), GridContactRig.viscous()):
        t0 = time.perf_counter()
        data = rig.simulate(design, n, args.seed)
        sec = time.perf_counter() - t0
        sets[rig.name] = data
        rows.append((rig.name, "vectorised (48 maneuvers x cells per array op)", n, len(data), sec))
    grid = GridContactRig.stribeck()
    plans = plan_maneuvers(design, n, args.seed, radius=lambda f: float(grid.rho(f)))
    sub = plans[: max(1, n // 10)]
    t0 = time.perf_counter()
    grid.run(sub, batch=1)
    sec = time.perf_counter() - t0
    n_sub = sum(len(p) for p in sub)
    rows.append(("grid-stribeck", f"baseline: one maneuver at a time ({len(sub)} maneuvers)",
                 len(sub), n_sub, sec))
    for rig in (LumpedRig(), PatchRig()):
        t0 = time.perf_counter()
        data = rig.simulate(design, n, args.seed)
        sec = time.perf_counter() - t0
        sets[rig.name] = data
        rows.append((rig.name, "per maneuver (Python loop over samples)", n, len(data), sec))

    begin, end = markers(SECTION)
    intro = (f"`python benchmarks/bench_rigs.py --maneuvers {n}` on {platform.machine()} "
             f"({os.cpu_count()} cores, one used), numpy {np.__version__}; default "
             f"`RubbingDesign`, seed {args.seed}. Target: 160 grid maneuvers in <= "
             f"{TARGET_S:g} s on one core (docs/rigs.md).")
    lines = [begin, "", "## Rubbing rigs: generation speed and content", "", intro, "",
             "| plant | integration | maneuvers | samples | time [s] | samples/s |",
             "|---|---|---|---|---|---|"]
    for name, how, m, samples, sec in rows:
        lines.append(f"| {name} | {how} | {m} | {samples} | {sec:.2f} | {samples / sec:,.0f} |")
    vec = rows[0][3] / rows[0][4]
    base = rows[2][3] / rows[2][4]
    gain = (f"Vectorising over maneuvers is {vec / base:.1f}x faster per sample than the "
            "same plant one maneuver at a time.")
    header = ("| plant | approach | presliding | sliding | rest | presliding duration "
              "median (5-95 %) [ms] | load ratio in sliding 5/50/95 % | mu_s / mu_k | "
              "beta_A [N s/m^3] | tau_max(2 N), tau_max(8 N) [N m] |")
    lines += ["", gain, "", "What the data hold (all samples of each set):", "", header,
              "|---|---|---|---|---|---|---|---|---|---|"]
    for name, d in sets.items():
        share = [100.0 * np.mean(d.phase == k) for k in range(4)]
        pre = 1e3 * d.presliding_durations()
        lr = np.percentile(d.load_ratio[d.gross_sliding], [5, 50, 95])
        tr = d.truth
        beta = "none" if tr.beta_a is None else f"{tr.beta_a:.3g}"
        lines.append(
            f"| {name} | {share[0]:.1f} % | {share[1]:.1f} % | {share[2]:.1f} % | "
            f"{share[3]:.1f} % | {np.median(pre):.0f} ({np.percentile(pre, 5):.0f}-"
            f"{np.percentile(pre, 95):.0f}) | {lr[0]:.2f} / {lr[1]:.2f} / {lr[2]:.2f} | "
            f"{tr.mu_static:g} / {tr.mu_kinetic:g} | {beta} | "
            f"{tr.tau_max(2.0):.3e}, {tr.tau_max(8.0):.3e} |")
    note = ("The load ratio is the friction torque about the prescribed CoR over the "
            "plant's full-sliding torque about it at static friction; with the viscous shear "
            "it exceeds 1 where the viscous part is large. The lumped and patch rigs use "
            "the aluminium_can preset.")
    lines += ["", note, "", end, ""]
    text = "\n".join(lines)
    write_section(args.out, text, SECTION)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
