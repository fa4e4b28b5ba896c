"""SHA-256 digest of every closed-loop column of the demo scenarios, for refactors that must
not change a single bit of the results.

Runs each scenario in scenarios/*.yaml through the simulator (lugrip's controller with and
without its pivoting schedule, and the friction-cone baseline) on both plant models and prints
one line per run: scenario, plant model, run, samples, digest. Run it on two commits and diff
the outputs:

    python benchmarks/closed_loop_digest.py --out build/digest_after.txt
    diff build/digest_before.txt build/digest_after.txt
"""

from __future__ import annotations

import argparse
import hashlib
import sys
from pathlib import Path

import numpy as np

from lugrip.sim import scenarios as sc
from lugrip.sim._closed_loop import run_closed_loop


def digest(run, exclude=()) -> str:
    h = hashlib.sha256()
    for name in sorted(k for k in run.keys() if k not in exclude):
        a = np.ascontiguousarray(run[name])
        h.update(name.encode())
        h.update(str(a.dtype).encode())
        h.update(a.tobytes())
    return h.hexdigest()


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenarios", default="scenarios", help="directory of scenario YAML files")
    ap.add_argument("--short", action="store_true", help="apply each scenario's short overrides")
    ap.add_argument("--out", help="also write the lines to this file")
    ap.add_argument("--exclude", nargs="*", default=[], help="columns left out (e.g. one added since)")
    args = ap.parse_args(argv)
    lines = []
    for path in sorted(Path(args.scenarios).glob("*.yaml")):
        scn = sc.load_scenario(path)
        if args.short:
            scn = scn.shortened()
        for model in ("patch", "lumped"):
            cfg = scn.plant_config(model)
            est = scn.estimator_for(cfg.model)
            runs = {
                "lugrip": dict(mode_schedule=scn.schedule),
                "lugrip_no_pivot": dict(mode_schedule=None),
                "friction_cone": dict(mode_schedule=None, kind="friction_cone"),
            }
            for label, kw in runs.items():
                r = run_closed_loop(cfg, scn.controller, scn.observer, duration=scn.duration,
                                    estimator=est, **kw)
                line = f"{scn.name} {model} {label} {len(r['t'])} {digest(r, args.exclude)}"
                print(line, flush=True)
                lines.append(line)
    if args.out:
        Path(args.out).write_text("\n".join(lines) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
