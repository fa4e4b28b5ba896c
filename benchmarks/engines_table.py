"""The paper experiments and unseen scenes on the patch plant, MuJoCo and Drake side by side
(BENCHMARKS.md, section "Closed loop on three plants"), from the metrics files of

    lugrip simulate all unseen --plant patch  --short --no-plots --out DIR/patch
    lugrip simulate all unseen --plant mujoco --short --no-plots --out DIR/mujoco
    lugrip simulate all --plant drake --short --no-plots --out DIR/drake_paper
    lugrip simulate unseen --plant drake --short --no-plots --out DIR/drake_unseen

Usage: python benchmarks/engines_table.py PLANT=METRICS.json [PLANT=METRICS.json ...]
(several files of one plant are merged).
Per scenario and plant: pass (and the criteria that failed), the worst slip and rotation over
the hold phases, the mean hold force per finger, the smallest passing constant force
(bisection; "none <= F" when even the gripper's f_max F fails) and lugrip's mean over it.
"""

from __future__ import annotations

import json
import sys
from collections import defaultdict


def load(args: list[str]) -> dict[str, dict[str, dict]]:
    plants: dict[str, dict[str, dict]] = defaultdict(dict)
    for arg in args:
        plant, _, path = arg.partition("=")
        with open(path) as f:
            plants[plant].update(json.load(f)["scenarios"])
    return plants


def _fmt(x, spec: str) -> str:
    return "-" if x is None else format(x, spec)


def table(plants: dict[str, dict[str, dict]]) -> str:
    names = []
    for runs in plants.values():
        names += [n for n in runs if n not in names]
    rows = ["| scenario | plant | pass | failed | hold slip mm | hold rot deg | mean N | "
            "constant N | mean / constant |", "|---|---|---|---|---|---|---|---|---|"]
    for name in names:
        for plant, runs in plants.items():
            s = runs.get(name)
            if s is None:
                continue
            m = s["metrics"]["lugrip"]
            failed = [k for k, c in s["criteria"].items() if c["pass"] is False]
            search = s.get("constant_force_search") or {}
            const = search.get("force")
            mean = m.get("mean_force")
            ratio = None if const is None or mean is None else mean / const
            if search and not search.get("found", True) and search.get("history"):
                top = max(f for f, _ in search["history"])  # even the gripper's f_max failed
                const_txt = f"none ≤ {top:g}"
                ratio_txt = "-" if mean is None else f"< {mean / top:.3f}"
            else:
                const_txt, ratio_txt = _fmt(const, ".3g"), _fmt(ratio, ".3f")
            rows.append(
                f"| {name} | {plant} | {'pass' if s['pass'] else 'FAIL'} | "
                f"{', '.join(failed) or '-'} | {_fmt(m.get('hold_slip_mm'), '.3g')} | "
                f"{_fmt(m.get('hold_rotation_deg'), '.3g')} | {_fmt(mean, '.3g')} | "
                f"{const_txt} | {ratio_txt} |")
    return "\n".join(rows)


def main(argv=None) -> int:
    args = sys.argv[1:] if argv is None else argv
    if not args:
        print(__doc__)
        return 2
    print(table(load(args)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
