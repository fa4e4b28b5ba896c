"""The paper experiments and unseen scenes on the patch plant, MuJoCo and Drake side by side
(BENCHMARKS.md, section "Closed loop on three plants"), from the metrics files of

    lugrip simulate all unseen --plant patch  --short --no-plots --out DIR/patch
    lugrip simulate all unseen --plant mujoco --short --no-plots --out DIR/mujoco
    lugrip simulate all --plant drake --short --no-plots [--no-baselines] --out DIR/drake_paper
    lugrip simulate unseen --plant drake --short --no-plots [--no-baselines] --out DIR/drake_unseen

    python benchmarks/drake_constant.py DIR/drake_constant.jsonl SCENARIO ...

Usage: python benchmarks/engines_table.py PLANT=METRICS.json [PLANT=METRICS.json ...]
(several files of one plant are merged; a ``.jsonl`` file is read as drake_constant.py's rows).
Per scenario and plant: pass (and the criteria that failed), the worst slip and rotation over
the hold phases, the mean hold force per finger, the smallest passing constant force
(bisection) and lugrip's mean over it; for drake_constant.py's rows, the constant forces tried
and whether each held ("5.4 no, 8.1 yes": the smallest that holds lies between).
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
            if path.endswith(".jsonl"):
                plants[plant].update({r["name"]: _bracket_row(r) for r in map(json.loads, f)})
            else:
                plants[plant].update(json.load(f)["scenarios"])
    return plants


def _bracket_row(r: dict) -> dict:
    """A drake_constant.py row in the shape of a metrics file's scenario."""
    m = {k: r[k] for k in ("hold_slip_mm", "hold_rotation_deg", "mean_force")}
    return {"metrics": {"lugrip": m}, "pass": r["pass"],
            "criteria": {k: {"pass": False} for k in r["failed"]}, "bracket": r["constant"]}


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
            if s.get("bracket"):
                const_txt = ", ".join(f"{c['force']:.3g} {'yes' if c['survives'] else 'no'}"
                                      for c in s["bracket"])
                # the smallest constant that holds lies in (largest failed, smallest held]
                held = [c["force"] for c in s["bracket"] if c["survives"]]
                failed_f = [c["force"] for c in s["bracket"] if not c["survives"]]
                if mean is None:
                    ratio_txt = "-"
                elif not held:
                    ratio_txt = f"< {mean / max(failed_f):.3f}"
                elif not failed_f:
                    ratio_txt = f"≥ {mean / min(held):.3f}"
                else:
                    ratio_txt = f"{mean / min(held):.3f} to {mean / max(failed_f):.3f}"
            elif search and not search.get("found", True) and search.get("history"):
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
