"""The hostile cases of docs/reliability.md §8, re-run as a user runs them: each command line in
a child process, with its exit code, wall time, peak resident memory and first line of stderr,
and the SHA-256 of the user's input before and after. The files are built by the helpers of the
tests that check the same cases (tests/python), in a temporary folder removed afterwards.

    python benchmarks/reliability_cases.py            # prints a Markdown table

A refusal must exit 2 with one line naming the file and the field, in <= 5 s and <= 500 MB.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import yaml

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "python"))


def _sha(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()[:12] if path.is_file() else "-"


_RSS = ("import atexit, resource, sys\natexit.register(lambda: sys.stdout.write('\\nRSS %d' % "
        "resource.getrusage(resource.RUSAGE_SELF).ru_maxrss))\n")


def measure(what, inputs=()) -> dict:
    """One child process running ``lugrip *what`` (a list) or the Python code ``what``: exit
    code, wall [s], peak RSS [MB] (the child reports its own), stderr lines and the last one,
    and whether the inputs' SHA-256 is unchanged."""
    code = what if isinstance(what, str) else (
        "from lugrip.cli import main\nsys.exit(main(" + repr([str(a) for a in what]) + "))")
    before = [_sha(Path(p)) for p in inputs]
    t0 = time.monotonic()
    proc = subprocess.run([sys.executable, "-c", _RSS + code], capture_output=True, text=True,
                          check=False)
    wall = time.monotonic() - t0
    rss = next((int(x.split()[1]) / 1024.0 for x in proc.stdout.splitlines()
                if x.startswith("RSS ")), float("nan"))
    err = [x for x in proc.stderr.strip().splitlines() if x.strip()]
    if not err:
        err = [x for x in proc.stdout.strip().splitlines() if x and not x.startswith("RSS ")]
    return {"rc": proc.returncode, "wall": wall, "rss": rss, "lines": len(err),
            "msg": err[-1] if err else "",
            "kept": all(b == _sha(Path(p)) for b, p in zip(before, inputs))}


def cases(tmp: Path):
    """(number, case, argv or callable, inputs) for each case."""
    import test_reader_integrity as ri
    from lugrip import ContactParams, write_log
    from lugrip.sliding import simulate_maneuvers

    small = simulate_maneuvers(ContactParams.table1(), 2, seed=1).log
    long_ = simulate_maneuvers(ContactParams.table1(), 40, seed=3).log
    x = write_log(long_, tmp / "x.csv")
    yield 1, "`identify x.csv --out x.csv --force`", ["identify", x, "--out", x, "--force"], [x]
    yield 2, "`identify x.csv --out /dev/null --force`", ["identify", x, "--out", "/dev/null",
                                                          "--force"], [x]
    fifo = tmp / "fifo.csv"
    os.mkfifo(fifo)
    yield 2, "`observe x.csv --out FIFO --force`", ["observe", x, "--preset", "table1", "--out",
                                                    fifo, "--force"], [x]
    sim = tmp / "sim"
    sim.mkdir()
    (sim / "metrics.json").write_text('{"mine": 1}\n')
    yield 3, "`simulate SCENARIO --out DIR` (DIR holds metrics.json)", [
        "simulate", "exp1_big_resin_block", "--out", sim], [sim / "metrics.json"]
    camp = tmp / "camp"
    camp.mkdir()
    (camp / "report.md").write_text("# my notes\n")
    yield 3, "`campaign FILE --out DIR` (DIR holds report.md)", [
        "campaign", ROOT / "campaigns" / "patch_blocks.yaml", "--runs", "2", "--out", camp], [
        camp / "report.md"]
    # 4: two f_n values changed in an uncompressed MCAP chunk; Float64 bytes on a wrench channel
    sys.modules["zstandard"] = None
    try:
        good = write_log(small, tmp / "good.mcap")
    finally:
        del sys.modules["zstandard"]
    raw = bytearray(good.read_bytes())
    ri._flip_value(raw, float(small.f_n[10]))
    ri._flip_value(raw, float(small.f_n[11]))
    bad = tmp / "bad.mcap"
    bad.write_bytes(bytes(raw))
    yield 4, "MCAP with two f_n values x1000 (uncompressed chunk)", [
        "observe", bad, "--preset", "table1", "--out", tmp / "e4.csv"], [bad]
    w = ri._one_channel(tmp / "w.mcap")
    yield 4, "Float64 bytes on a WrenchStamped channel", [
        "observe", w, "--preset", "table1", "--out", tmp / "e4b.csv"], [w]
    # 5
    yield 5, "`copy.copy(SlipControl)`", (
        "import copy, lugrip\nsc = lugrip.SlipControl('big_resin_block')\n"
        "try:\n    copy.copy(sc)\nexcept TypeError as e:\n    sys.exit('TypeError: ' + str(e))\n"
        "sys.exit('copied')"), []
    # 6: header clock 10 s back; identical stamps
    stamps = 5_000_000_000 + np.round(long_.t * 1e9).astype(np.int64)
    stamps[len(long_) // 3:] -= 10_000_000_000
    jump = ri._stamped(tmp / "jump.mcap", long_, stamps)
    yield 6, f"header clock 10 s back at a third of {len(long_)} samples", [
        "observe", jump, "--preset", "table1", "--out", tmp / "e6.csv"], [jump]
    yield 6, "the same with `--time-source log`", [
        "observe", jump, "--preset", "table1", "--out", tmp / "e6l.csv", "--time-source", "log"
    ], [jump]
    same = ri._stamped(tmp / "same.mcap", long_, np.full(len(long_), 7_000_000_000))
    yield 6, "identical header stamps", [
        "observe", same, "--preset", "table1", "--out", tmp / "e6s.csv"], [same]
    # 7: tau in N mm in a 5 % block; campaign definitions
    mixed, _, _ = ri._mixed_csv(tmp / "mixed.csv", long_, "tau", 1000.0, 0.4, 0.05)
    yield 7, "tau in N mm in a 5 % block of rows", [
        "observe", mixed, "--preset", "table1", "--out", tmp / "e7.csv"], [mixed]
    doc = yaml.safe_load((ROOT / "campaigns" / "patch_blocks.yaml").read_text())
    doc["scenario"] = str(ROOT / "scenarios" / "exp2_small_resin_block.yaml")
    for name, over in (("duration -1", {"duration": -1}),
                       ("mass 1e-300 kg", {"parameters": doc["parameters"] | {
                           "mass": {"distribution": "constant", "value": 1e-300}}})):
        p = tmp / f"c_{len(name)}.yaml"
        p.write_text(yaml.safe_dump(doc | over))
        yield 7, f"campaign {name}", ["campaign", p, "--runs", "3", "--workers", "1", "--out",
                                      tmp / f"o_{len(name)}", "--quiet"], [p]
    est = tmp / "est.yaml"
    est.write_text("contact: {mu: {value: -3, unit: '-'}}\n")
    d = yaml.safe_load(yaml.safe_dump(doc))
    d["overrides"]["estimator"] = {"patch": str(est)}
    p = tmp / "c_est.yaml"
    p.write_text(yaml.safe_dump(d))
    yield 7, "campaign with a broken estimator file", [
        "campaign", p, "--runs", "3", "--workers", "1", "--out", tmp / "o_est", "--quiet"], [p]
    # 9: alias bombs, --runs 1e9
    bomb = "".join([f"a0: &a0 [{', '.join(['x'] * 10)}]\n"]
                   + [f"a{i}: &a{i} [{', '.join([f'*a{i - 1}'] * 10)}]\n" for i in range(1, 9)])
    cb = tmp / "bomb_campaign.yaml"
    cb.write_text((ROOT / "campaigns" / "patch_blocks.yaml").read_text() + bomb)
    yield 9, f"campaign file with nested aliases ({cb.stat().st_size} B)", [
        "campaign", cb, "--runs", "1", "--out", tmp / "ob"], [cb]
    sb = tmp / "bomb_settings.yaml"
    sb.write_text("controller:\n  f_min: 0.1\n" + bomb)
    g = tmp / "g.csv"
    g.write_text("t,f_n_0,f_t_0,tau_0,f_n_1,f_t_1,tau_1\n0,1,0.1,0,1,0.1,0\n"
                 "0.002,1,0.1,0,1,0.1,0\n")
    yield 9, f"`replay --settings` with nested aliases ({sb.stat().st_size} B)", [
        "replay", g, "--preset", "table1", "--settings", sb, "--out", tmp / "r.csv"], [sb]
    yield 9, "`campaign --runs 1e9`", ["campaign", ROOT / "campaigns" / "patch_blocks.yaml",
                                       "--runs", "1e9", "--out", tmp / "o9"], []
    # 10: messages
    t0 = ri._stamped(tmp / "t0.mcap", small, 1_000_000_000 + np.round(small.t * 1e9),
                     metadata={"t0_ns": "soon"})
    yield 10, "MCAP metadata t0_ns not an integer", [
        "observe", t0, "--preset", "table1", "--out", tmp / "e10.csv"], [t0]
    p = tmp / "c_seed.yaml"
    p.write_text(yaml.safe_dump(doc | {"seed": 2**80}))
    yield 10, "campaign seed 2**80", ["campaign", p, "--runs", "2", "--out", tmp / "o10"], [p]
    broken = tmp / "broken"
    broken.mkdir()
    (broken / "campaign.json").write_text("{not json")
    yield 10, "`campaign report DIR` with a broken campaign.json", [
        "campaign", "report", broken], [broken / "campaign.json"]


def main() -> int:
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        with contextlib.chdir(tmp):
            for num, name, argv, inputs in cases(tmp):
                r = measure(argv, inputs)
                msg = r["msg"].replace(str(tmp) + "/", "").replace("|", "/")
                rows.append((num, name, r, msg))
                print(f"{num} {name}: exit {r['rc']}, {r['wall']:.2f} s, {r['rss']:.0f} MB, "
                      f"{r['lines']} line(s), input kept {r['kept']}: {msg[:160]}", flush=True)
    print("\n| # | case | exit | wall [s] | peak RSS [MB] | stderr lines | input unchanged | "
          "message |")
    print("|---|---|---|---|---|---|---|---|")
    for num, name, r, msg in rows:
        print(f"| {num} | {name} | {r['rc']} | {r['wall']:.2f} | {r['rss']:.0f} | {r['lines']} "
              f"| {'yes' if r['kept'] else 'NO'} | {msg[:150]} |")
    print(f"\nload average {os.getloadavg()[0]:.2f}, {os.cpu_count()} cores")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
