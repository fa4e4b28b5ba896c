"""The constant-force baseline on Drake at two levels per scene (BENCHMARKS.md, "Closed loop on
three plants"), where a bisection (`lugrip simulate --plant drake`, 6-8 runs per scene) costs
more than a shared machine gives.

Per scenario (``--short``): lugrip's run (and its run without pivoting), judged by the
scenario's Drake criteria; then the constant-force baseline at lugrip's mean hold force and at
1.5 times it, each judged as the bisection judges a constant force (no drop, hold slip and
rotation within the criteria, no worse than lugrip's run by more than the limits). A constant
force that fails at lugrip's mean means the smallest constant that holds is above lugrip's
mean (``mean_force_below_constant`` holds); one that holds means it is not.

Usage: python benchmarks/drake_constant.py OUT.jsonl SCENARIO [SCENARIO ...]
(one JSON line per scenario appended to OUT.jsonl as it finishes).
"""

from __future__ import annotations

import json
import sys
import time

from lugrip.sim.scenarios import _evaluate, _survives, compute_metrics, load_scenario, simulate

#: the constant forces tried, as multiples of lugrip's mean hold force
LEVELS = (1.0, 1.5)


def bracket(name: str) -> dict:
    t0 = time.perf_counter()
    s = load_scenario(name).shortened().for_plant("drake")
    cfg = s.plant_config("drake")
    m = compute_metrics(s, simulate(s, cfg, "drake", s.schedule), cfg=cfg)
    metrics = {"lugrip": m}
    ref = m
    if s.has_pivot:
        ref = compute_metrics(s, simulate(s, cfg, "drake", None), cfg=cfg, pivot=False)
        metrics["lugrip_no_pivot"] = ref
    crit = _evaluate(s, metrics, None)
    row = {"name": name, "pass": all(c["pass"] is not False for c in crit.values()),
           "failed": [k for k, c in crit.items() if c["pass"] is False],
           "hold_slip_mm": m["hold_slip_mm"], "hold_rotation_deg": m["hold_rotation_deg"],
           "mean_force": m.get("mean_force"), "scene_status": m.get("scene_status"),
           "constant": []}
    mean = ref.get("mean_force") or m.get("mean_force")
    for k in LEVELS:
        f = k * mean
        mc = compute_metrics(s, simulate(s, cfg, "drake", None, kind="constant_force",
                                         constant_force=f), cfg=cfg, pivot=False)
        row["constant"].append({"force": f, "survives": bool(_survives(s, mc, ref)),
                                "hold_slip_mm": mc["hold_slip_mm"],
                                "hold_rotation_deg": mc["hold_rotation_deg"],
                                "dropped": mc["dropped"], "scene_status": mc.get("scene_status")})
    row["elapsed_s"] = time.perf_counter() - t0
    return row


def main(argv=None) -> int:
    args = sys.argv[1:] if argv is None else argv
    if len(args) < 2:
        print(__doc__)
        return 2
    with open(args[0], "a") as out:
        for name in args[1:]:
            print(json.dumps(bracket(name)), file=out, flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
