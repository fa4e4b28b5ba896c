"""The "reliability" section of BENCHMARKS.md: the long seeded adversarial campaign, a libFuzzer
run (from its log) and the cost of refusing hostile parameter files.

    python benchmarks/reliability_report.py --campaign build/cpp/tests/fuzz/lugrip_fuzz_campaign \
        --samples 10000000 --seed 7 --fuzz-log build/fuzz/fuzz.log --out BENCHMARKS.md

The campaign and the fuzzer are described in docs/reliability.md; the libFuzzer run itself is
started by hand (README, "Reliability") and its stderr saved to the log given here.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from sections import markers, write_section  # noqa: E402

SECTION = "reliability"


def run_campaign(binary: str, samples: int, seed: int) -> dict:
    out = subprocess.run([binary, "--samples", str(samples), "--seed", str(seed), "--json"],
                         capture_output=True, text=True)
    lines = out.stdout.strip().splitlines()
    result = json.loads(lines[0])
    result["exit_code"] = out.returncode
    result["first_failure"] = lines[1] if len(lines) > 1 else ""
    return result


def parse_fuzz_log(path: Path) -> dict:
    """Runs, seconds, coverage and crash markers from a libFuzzer stderr log."""
    text = path.read_text(errors="replace")
    done = re.findall(r"Done (\d+) runs in (\d+) second", text)
    cov = re.findall(r"#(\d+)\s+(?:DONE|pulse|NEW|REDUCE)\s+cov: (\d+) ft: (\d+) corp: (\d+)", text)
    crashed = bool(re.search(r"==\d+==ERROR|deadly signal|lugrip_fuzz: |runtime error:", text))
    r = {"crashed": crashed}
    if done:
        r["runs"], r["seconds"] = int(done[-1][0]), int(done[-1][1])
    if cov:
        r["cov"], r["ft"], r["corpus"] = int(cov[-1][1]), int(cov[-1][2]), int(cov[-1][3])
    return r


def _alias_bomb() -> str:
    lines = ['a0: &a0 [' + ", ".join(['"xxxxxxxx"'] * 9) + "]"]
    for i in range(1, 10):
        lines.append(f"a{i}: &a{i} [" + ", ".join([f"*a{i - 1}"] * 9) + "]")
    return "\n".join(lines) + "\ncontact: *a9\n"


def hostile_files() -> list[tuple[str, int, int, float, float, float, str]]:
    """(case, file bytes, exit code, wall s, CPU s, peak RSS MB, message) of `lugrip params
    --check` on each expensive file, in a child process."""
    good = ("contact: {mu: 0.5, beta_a: 1.0e7, sigma0: 16.0, sigma_z: 2.0, delta: 0.0018, "
            "gamma: 0.25}\n")
    cases = {
        "nested aliases, 9 levels of 9": _alias_bomb(),
        "100 000 levels of nesting": "[" * 100000 + "]" * 100000 + "\n",
        "2 MB file": good + ("# " + "x" * 98 + "\n") * 20000,
        "400-digit integer": good.replace("mu: 0.5", "mu: " + "7" * 400),
        "valid file (reference)": good,
    }
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name, text in cases.items():
            path = Path(tmp) / "p.yaml"
            path.write_text(text)
            t0 = time.monotonic()
            proc = subprocess.Popen([sys.executable, "-m", "lugrip", "params", "--check", str(path)],
                                    stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
            err = proc.stderr.read().decode(errors="replace").strip()
            _, status, usage = os.wait4(proc.pid, 0)
            wall = time.monotonic() - t0
            msg = err.replace(str(path), "p.yaml").replace("|", "/")
            rows.append((name, len(text.encode()), os.waitstatus_to_exitcode(status), wall,
                         usage.ru_utime + usage.ru_stime, usage.ru_maxrss / 1024.0, msg))
    return rows


def render(campaign: dict | None, fuzz: dict | None, fuzz_cmd: str, files, cmd: str) -> str:
    begin, end = markers(SECTION)
    out = [begin, "## Reliability: adversarial campaign and hostile files", "",
           "Command: `" + cmd + "`. Method and checks: docs/reliability.md. One run on the shared "
           "2-core machine (timings are indicative).", ""]
    if campaign:
        c = campaign
        out += ["### Seeded campaign (settings at the edges of validity, hostile samples)", "",
                "| figure | value |", "|---|---|",
                f"| seed | {c['seed']} |",
                f"| samples through step() | {c['samples']:,} |",
                f"| cases (CorEstimator / Observer / GraspController / SlipControl) | "
                f"{c['cases']:,} ({c['cases_cor']} / {c['cases_observer']} / {c['cases_controller']}"
                f" / {c['cases_slip_control']}) |",
                f"| drawn settings rejected by validate() (constructor threw, as it must) | "
                f"{c['settings_rejected']:,} |",
                f"| samples the components rejected (invalid, no contact, fault) | "
                f"{c['samples_rejected']:,} |",
                f"| non-finite outputs | {c['non_finite']} |",
                f"| commands out of [f_min, f_max] (and other range checks) | {c['out_of_range']} |",
                f"| twin mismatches | {c['twin_mismatch']} |",
                f"| commands lowered on invalid input | {c['not_held']} |",
                f"| constructor / validate() disagreements | {c['ctor_mismatch']} |",
                f"| allocations inside step() | {c['allocations']} |",
                f"| out-of-enum finger status reported as Ok by GraspController (command held) | "
                f"{c['unknown_status_ok']:,} (open: see below) |",
                f"| wall time | {c['seconds']:.1f} s |", ""]
        if c.get("first_failure"):
            out += ["First failure: " + c["first_failure"], ""]
    if fuzz:
        runs = f"{fuzz.get('runs', 0):,}" if "runs" in fuzz else "n/a"
        out += ["### libFuzzer (ASan + UBSan, library instrumented)", "",
                f"Command: `{fuzz_cmd}`", "",
                "| figure | value |", "|---|---|",
                f"| duration | {fuzz.get('seconds', 'n/a')} s |",
                f"| executions (each one case of up to 512 samples) | {runs} |",
                f"| coverage (edges / features / corpus) | {fuzz.get('cov', 'n/a')} / "
                f"{fuzz.get('ft', 'n/a')} / {fuzz.get('corpus', 'n/a')} |",
                f"| crashes, sanitizer reports, broken checks | "
                f"{'YES (see the log)' if fuzz['crashed'] else 0} |", ""]
    if files:
        out += ["### Hostile parameter files (`lugrip params --check`, child process)", "",
                "| file | bytes | exit | wall [s] | CPU [s] | peak RSS [MB] | message |",
                "|---|---|---|---|---|---|---|"]
        for name, size, code, wall, cpu, rss, msg in files:
            out.append(f"| {name} | {size:,} | {code} | {wall:.2f} | {cpu:.2f} | {rss:.0f} | "
                       f"{msg[:140]} |")
        out += ["", "Before the limits, the nested-alias file took 62-71 s and 10.7-13.4 GB and "
                "printed a 2.1 GB line; the others ended in tracebacks.", ""]
    out += ["Open: GraspController::step() reports Ok (while holding the command) for a finger "
            "status outside the enum; SlipControl never passes one (its observers produce only "
            "enum values).", end]
    return "\n".join(out) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--campaign", help="path of lugrip_fuzz_campaign (skip the campaign if absent)")
    ap.add_argument("--samples", type=int, default=10_000_000)
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--fuzz-log", type=Path, help="stderr of a libFuzzer run")
    ap.add_argument("--fuzz-command", default="lugrip_fuzz -max_total_time=600 -max_len=4096 corpus")
    ap.add_argument("--no-files", action="store_true", help="skip the hostile-file measurements")
    ap.add_argument("--out", type=Path, default=Path("BENCHMARKS.md"))
    args = ap.parse_args(argv)
    campaign = run_campaign(args.campaign, args.samples, args.seed) if args.campaign else None
    fuzz = parse_fuzz_log(args.fuzz_log) if args.fuzz_log else None
    files = None if args.no_files else hostile_files()
    cmd = "python benchmarks/reliability_report.py " + " ".join(argv or sys.argv[1:])
    write_section(args.out, render(campaign, fuzz, args.fuzz_command, files, cmd), SECTION)
    print(render(campaign, fuzz, args.fuzz_command, files, cmd))
    return 0 if not campaign or campaign["exit_code"] == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
