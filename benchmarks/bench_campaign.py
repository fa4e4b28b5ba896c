#!/usr/bin/env python3
"""Campaign throughput (lugrip.campaign): runs per second on 1 and 2 workers with the process
pool and Ray, on the patch and the MuJoCo plant, the 2-worker speed-up measured in the same
run, and the projected core-hours for 10^4 runs; writes the section between
``<!-- campaign:begin -->`` and ``<!-- campaign:end -->`` of BENCHMARKS.md (the rest is kept).

    nice python benchmarks/bench_campaign.py [--out BENCHMARKS.md] [--patch-runs 16]
        [--mujoco-runs 4] [--no-ray] [--no-mujoco]

Each configuration runs the shipped campaign (campaigns/patch_blocks.yaml,
campaigns/mujoco_blocks.yaml: four controllers per run) into a fresh directory under
build/bench_campaign/; the pool start-up (spawning workers, starting Ray) is inside the timed
span, as a user sees it. The machine's load average is recorded next to the numbers: on a shared
machine the speed-up says more about the other users than about the runner. Benchmarks are not
tests: nothing here fails on a timing.
"""

from __future__ import annotations

import argparse
import os
import platform
import shutil
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))
from lugrip.campaign import ResultStore, load_campaign, run_campaign
from sections import markers, write_section

SECTION = "campaign"
TARGET_SPEEDUP = 1.7  # 2 workers against 1 on an idle 2-core machine


def _one(campaign, runs: int, workers: int, backend: str, work: Path) -> dict:
    out = work / f"{campaign.name}_{backend}_{workers}"
    shutil.rmtree(out, ignore_errors=True)
    load0 = os.getloadavg()[0]
    cpu0 = time.process_time()
    stamps: list[float] = []
    t0 = time.perf_counter()
    run_campaign(campaign, runs, out, workers=workers, backend=backend, progress=False,
                 on_run=lambda i, rows: stamps.append(time.perf_counter()))
    wall = time.perf_counter() - t0
    # throughput once every worker has delivered its first run (start-up excluded)
    k = min(workers, runs - 1)
    steady = (runs - k) / (stamps[-1] - stamps[k - 1]) if runs > k and stamps[-1] > stamps[k - 1] else float("nan")
    rows = ResultStore(out, campaign).rows()
    busy = sum(r["elapsed_s"] for r in rows)  # worker-side simulation time, all controllers
    cpu = sum(r["cpu_s"] for r in rows)  # worker-side CPU time (what a core-hour buys)
    return {
        "plant": campaign.plant, "backend": backend, "workers": workers, "runs": runs,
        "wall_s": wall, "runs_per_s": runs / wall, "steady_runs_per_s": steady,
        "startup_s": stamps[0] - t0 if stamps else float("nan"), "sim_s_per_run": busy / runs,
        "cpu_s_per_run": cpu / runs,
        "load_before": load0, "load_after": os.getloadavg()[0],
        "driver_cpu_s": time.process_time() - cpu0, "rows": rows,
    }


def _results(dirs: list[Path]) -> list[str]:
    """Summary lines of finished campaigns (their report.json)."""
    import json

    out: list[str] = []
    for d in dirs:
        data = json.loads((d / "report.json").read_text())
        meta = json.loads((d / "campaign.json").read_text())
        out += [
            "",
            f"### Campaign `{data['campaign']}` ({data['plant']} plant, {data['runs']} runs)",
            "",
            (
                f"`lugrip campaign campaigns/{data['campaign']}.yaml --runs {data['runs']} "
                f"--workers 2 --out {d}` (fingerprint {meta['fingerprint']}); success = every "
                "criterion of the campaign file; 95 % Wilson intervals."
            ),
            "",
            (
                "| controller | held | rate | 95 % interval | mean force [N] | lugrip holds, it "
                "fails | it holds, lugrip fails |"
            ),
            "|---|---:|---:|---|---:|---:|---:|",
        ]
        for c, s in data["summary"].items():
            p = data["paired_with_lugrip"].get(c, {})
            lo, hi = s["wilson95"]
            out.append(
                f"| {c} | {s['successes']}/{s['runs']} | {s['success_rate']:.2f} | "
                f"[{lo:.2f}, {hi:.2f}] | {s['mean_force']:.2f} | "
                f"{p.get('lugrip_holds_other_fails', '-')} | {p.get('other_holds_lugrip_fails', '-')} |"
            )
        deciding = {n: [c for c, v in e["controllers"].items() if v["effect"]]
                    for n, e in data["failure_map"].items()}
        shown = [f"{n} ({', '.join(cs)})" for n, cs in deciding.items() if cs]
        out += ["", "Parameters whose bins differ beyond the 95 % intervals: "
                + (", ".join(shown) if shown else "none at this size") + "; the others are not "
                "resolved at this number of runs."]
        worst = data["worst_runs"].get("lugrip") or []
        if worst:
            w = worst[0]
            out.append(f"lugrip's worst run: {w['run']} (`{w['replay']}`).")
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, default=ROOT / "BENCHMARKS.md")
    ap.add_argument("--patch-runs", type=int, default=48)
    ap.add_argument("--mujoco-runs", type=int, default=6)
    ap.add_argument("--repeat", type=int, default=2,
                    help="passes over 1 and 2 workers, interleaved; the fastest pass is kept")
    ap.add_argument("--results", type=Path, action="append", default=[], metavar="DIR",
                    help="campaign results directories whose report.json is summarised too")
    ap.add_argument("--no-ray", action="store_true")
    ap.add_argument("--no-mujoco", action="store_true")
    ap.add_argument("--results-only", action="store_true",
                    help="keep the section's throughput table and replace only the campaign "
                         "summaries with those of --results")
    args = ap.parse_args(argv)
    if args.results_only:
        begin, end = markers(SECTION)
        text = args.out.read_text()
        if begin not in text or end not in text:
            ap.error(f"{args.out} has no {SECTION} section to keep")
        body = text.split(begin, 1)[1].split(end, 1)[0]
        body = body.split("\n### Campaign ", 1)[0].rstrip("\n")
        section = "\n".join([begin + body, *_results(args.results), end, ""])
        write_section(args.out, section, SECTION)
        return 0
    work = ROOT / "build" / "bench_campaign"
    work.mkdir(parents=True, exist_ok=True)
    backends = ["process"]
    if not args.no_ray:
        try:
            import ray  # noqa: F401

            backends.append("ray")
        except ImportError:
            print("ray not installed: process pool only", file=sys.stderr)
    plants = [("patch_blocks.yaml", args.patch_runs)]
    if not args.no_mujoco:
        plants.append(("mujoco_blocks.yaml", args.mujoco_runs))
    results = []
    for fname, runs in plants:
        c = load_campaign(ROOT / "campaigns" / fname)
        for backend in backends:
            best: dict[int, dict] = {}
            for _ in range(max(args.repeat, 1)):
                for workers in (1, 2):
                    r = _one(c, runs, workers, backend, work)
                    r["passes"] = max(args.repeat, 1)
                    print(f"{c.plant:6s} {backend:7s} {workers} worker(s): "
                          f"{r['runs_per_s']:.3f} runs/s ({r['wall_s']:.1f} s, load "
                          f"{r['load_before']:.1f})", flush=True)
                    if workers not in best or r["wall_s"] < best[workers]["wall_s"]:
                        best[workers] = r
            results += [best[1], best[2]]
    # identical rows on every backend and worker count (per plant)
    same = {}
    for plant in {r["plant"] for r in results}:
        tabs = [[{k: v for k, v in row.items() if k not in ("elapsed_s", "cpu_s")}
                 for row in r["rows"]]
                for r in results if r["plant"] == plant]
        same[plant] = all(t == tabs[0] for t in tabs)
    lines = [
        markers(SECTION)[0],
        "## Randomized grasp campaigns: throughput of the runner",
        "",
        (
            f"`{'nice ' if os.nice(0) > 0 else ''}python benchmarks/bench_campaign.py` (`--patch-runs "
            f"{args.patch_runs} --mujoco-runs {args.mujoco_runs}`): the shipped campaigns, four "
            "controllers per run (lugrip, the paper's law, constant force, friction cone), each "
            "configuration into a fresh results directory; wall time includes starting the pool "
            f"or Ray; {max(args.repeat, 1)} interleaved passes over 1 and 2 workers, the fastest "
            f"of each kept. Machine: {platform.machine()}, {os.cpu_count()} CPUs, Python "
            f"{platform.python_version()}; load average (1 min) before each configuration in "
            "the table."
        ),
        "",
        (
            "| plant | backend | workers | runs | wall [s] | runs/s | speed-up | start-up [s] | "
            "runs/s after start-up | speed-up after start-up | simulation / CPU per run [s] | "
            "cores obtained | load before |"
        ),
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    verdict = []  # the 2-worker speed-ups against the target
    for r in results:
        base = next(x for x in results if x["plant"] == r["plant"]
                    and x["backend"] == r["backend"] and x["workers"] == 1)
        sp = r["runs_per_s"] / base["runs_per_s"]
        sp2 = r["steady_runs_per_s"] / base["steady_runs_per_s"]
        if r["workers"] == 2:
            verdict.append(f"{r['plant']} {r['backend']} {sp:.2f}x "
                           f"({'meets' if sp >= TARGET_SPEEDUP else 'below'} the target)")
        lines.append(
            f"| {r['plant']} | {r['backend']} | {r['workers']} | {r['runs']} | {r['wall_s']:.1f} | "
            f"{r['runs_per_s']:.3f} | {sp:.2f} | {r['startup_s']:.1f} | "
            f"{r['steady_runs_per_s']:.3f} | {sp2:.2f} | {r['sim_s_per_run']:.2f} / "
            f"{r['cpu_s_per_run']:.2f} | {r['cpu_s_per_run'] * r['runs'] / r['wall_s']:.2f} | "
            f"{r['load_before']:.1f} |"
        )
    lines += ["", ("Projected cost of 10^4 runs (four controllers each), from the CPU time per "
                   "run in the workers (all configurations; CPU time, unlike wall time, does not "
                   "grow with the other users' load):"), ""]
    for plant in dict.fromkeys(r["plant"] for r in results):
        mine = [x for x in results if x["plant"] == plant]
        cpu = sum(x["cpu_s_per_run"] * x["runs"] for x in mine) / sum(x["runs"] for x in mine)
        lines.append(f"- {plant}: {cpu * 1e4 / 3600:.1f} core-hours ({cpu:.2f} CPU s per run), "
                     f"{cpu * 1e4 / 3600 / 2:.1f} h on two idle cores")
    lines += [
        "",
        (
            "Per-run results identical across backends and worker counts: "
            + ", ".join(f"{p} {'yes' if ok else 'NO'}" for p, ok in same.items()) + "."
        ),
        (
            f"Target: >= {TARGET_SPEEDUP}x for 2 workers on an idle 2-core machine. With a load "
            "average above the core count both workers compete with other users' processes for "
            "the two cores, so the measured speed-up depends on their demand as much as on the "
            "runner, and the simulation time per run is inflated the same way. 'cores obtained' "
            "= runs x CPU per run / wall: what the workers got of the machine (2.0 at best)."
        ),
    ]
    lines += ["", "2-worker speed-up, wall time with start-up: " + "; ".join(verdict) + "."]
    lines += _results(args.results)
    lines += [markers(SECTION)[1], ""]
    text = "\n".join(lines)
    write_section(args.out, text, SECTION)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
