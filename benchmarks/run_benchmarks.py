#!/usr/bin/env python3
"""Run the C++ core benchmarks and the numpy/scipy baselines in one run; write BENCHMARKS.md.

    python benchmarks/run_benchmarks.py --cpp-dir build/cpp/benchmarks --out BENCHMARKS.md [--quick]

Steps (all in this one process run, so the ratios compare like with like on the same machine
state): ``bench_core --json`` (C++ per-call timings), ``scipy_baseline.run`` (nested quad, CubicSpline
+ brentq, vectorized numpy), the Python API's vectorized path (``lugrip.estimate_cor`` and
``LimitSurface.ft_star/tau_star`` on 1e5 samples, binding overhead included), and two sanity checks
that the baseline computes the same thing as lugrip (LS values at the quad points, CoR estimates on
the baseline's samples). Benchmarks are not tests: nothing here fails on a timing.
"""

from __future__ import annotations

import argparse
import datetime as dt
import json
import os
import platform
import re
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import scipy_baseline as base
import sections

TARGET_COR_NS = 200.0
TARGET_COR_RATIO = 100.0
TARGET_CONSTRUCT_MS = 50.0


def log(*a):
    print(*a, file=sys.stderr, flush=True)


def fmt_ns(ns: float) -> str:
    if ns < 1e3:
        return f"{ns:.1f} ns"
    if ns < 1e6:
        return f"{ns / 1e3:.1f} µs"
    if ns < 1e9:
        return f"{ns / 1e6:.1f} ms"
    return f"{ns / 1e9:.2f} s"


def fmt_ratio(x: float) -> str:
    if x >= 100:
        return f"{x:,.0f}×"
    return f"{x:.1f}×"


def cpu_model() -> str:
    try:
        out = subprocess.run(["lscpu"], capture_output=True, text=True, check=True).stdout
        info = dict(line.split(":", 1) for line in out.splitlines() if ":" in line)
        name = info.get("Model name", "?").strip()
        cpus = info.get("CPU(s)", "?").strip()
        hyp = info.get("Hypervisor vendor", "").strip()
        return f"{name}, {cpus} CPUs" + (f" ({hyp} guest)" if hyp else "")
    except (OSError, subprocess.CalledProcessError):
        return platform.processor() or "unknown"


def load_avg() -> str:
    try:
        return " / ".join(f"{x:.2f}" for x in os.getloadavg())
    except OSError:
        return "?"


def ns_stats(s: dict) -> tuple[float, float, float]:
    """(median, p99, worst) in ns from either an ns or a ms stats dict."""
    if "median_ns" in s:
        return s["median_ns"], s["p99_ns"], s["worst_ns"]
    return s["median_ms"] * 1e6, s["p99_ms"] * 1e6, s["worst_ms"] * 1e6


def run_cpp(cpp_dir: Path, quick: bool) -> dict:
    exe = cpp_dir / "bench_core"
    if not exe.exists():
        sys.exit(f"{exe} not found: configure with -DLUGRIP_BUILD_BENCHMARKS=ON and build first")
    cmd = [str(exe), "--json"] + (["--quick"] if quick else [])
    log("running", " ".join(cmd))
    out = subprocess.run(cmd, capture_output=True, text=True, check=True).stdout
    return json.loads(out)


def run_python_api(quick: bool, table: base.LsTable) -> dict:
    """lugrip's vectorized Python path: per-sample ns including binding and wrapper overhead."""
    import lugrip

    n = 100_000
    reps = 3 if quick else 7
    rng = np.random.default_rng(7)
    res = {}
    for obj, p in base.OBJECTS.items():
        params = lugrip.ContactParams(**p)
        f_n, f_t, tau = base.make_samples(p, table, n, rng)
        lugrip.estimate_cor(params, f_n[:10], f_t[:10], tau[:10])  # builds and caches the model
        per = []
        for _ in range(reps):
            t0 = time.perf_counter_ns()
            lugrip.estimate_cor(params, f_n, f_t, tau)
            per.append((time.perf_counter_ns() - t0) / n)
        res[obj] = base.stats(per)
    ls = lugrip.LimitSurface(4.0)
    c = np.exp(rng.uniform(np.log(1e-3), np.log(1e3), n))
    per = []
    for _ in range(reps):
        t0 = time.perf_counter_ns()
        ls.ft_star(c)
        ls.tau_star(c)
        per.append((time.perf_counter_ns() - t0) / n)
    res["ls"] = base.stats(per)
    return res


def sanity_checks(py: dict) -> dict:
    """The baseline and lugrip compute the same quantities (not a test: informative figures)."""
    import lugrip

    ls = lugrip.LimitSurface(4.0)
    err = 0.0
    npts = 0
    for r in py["results"]:
        if "F" in r:
            c = np.asarray(r["c_tilde"])
            err = max(
                err,
                float(np.max(np.abs(np.abs(ls.ft_star(c)) - np.asarray(r["F"])))),
                float(np.max(np.abs(ls.tau_star(c) - np.asarray(r["T"])))),
            )
            npts += c.size
    out = {"ls_max_abs_diff": err, "ls_points": npts, "cor": {}}
    for obj, s in py["samples"].items():
        est = lugrip.estimate_cor(
            lugrip.ContactParams(**base.OBJECTS[obj]),
            np.asarray(s["f_n"]),
            np.asarray(s["f_t"]),
            np.asarray(s["tau"]),
        )
        d = np.abs(np.asarray(est.c_tilde) - np.asarray(s["c_tilde"]))
        out["cor"][obj] = {
            "n": int(d.size),
            "max_abs_diff": float(d.max()),
            "median_abs_diff": float(np.median(d)),
            "inside_agree": float(np.mean(np.asarray(est.inside) == np.asarray(s["inside"]))),
        }
    return out


def reference_ks() -> str:
    """The k values of the test suite's independent LS reference (for the report)."""
    path = HERE.parent / "tests" / "reference" / "ls_reference.csv"
    try:
        ks = sorted(
            {
                float(line.split(",")[0])
                for line in path.read_text().splitlines()
                if line and line[0] not in "#k"
            }
        )
    except (OSError, ValueError):
        return "see the file"
    return ", ".join("∞" if np.isinf(k) else f"{k:g}" for k in ks)


def find(rows, group, name):
    for r in rows:
        if r["group"] == group and r["name"] == name:
            return r
    raise KeyError(f"{group}/{name}")


BEGIN, END = sections.markers("issue2")
LEGACY = "Generated by `benchmarks/run_benchmarks.py`; do not edit by hand."


def write_section(path: Path, section: str) -> None:
    """Replaces this script's section of `path`, keeping the other sections (the other
    benchmark scripts write theirs between their own markers)."""
    text = path.read_text() if path.exists() else ""
    if LEGACY in text and not (BEGIN in text and END in text):
        # a whole-file report of an earlier version: keep only its marked sections
        marked = re.compile(r"<!-- (\w+):begin -->.*?<!-- \1:end -->", flags=re.DOTALL)
        blocks = [m.group(0) for m in marked.finditer(text)]
        path.write_text("# Benchmarks\n\n" + section + "".join("\n" + b + "\n" for b in blocks))
        return
    sections.write_section(path, section, "issue2")


def write_report(path: Path, cpp: dict, py: dict, api: dict, chk: dict, meta: dict) -> dict:
    C, P = cpp["results"], py["results"]
    lines: list[str] = []
    w = lines.append
    targets = {}

    w(BEGIN)
    w("")
    w("## Contact-model core: LS evaluation, CoR estimation, construction")
    w("")
    w("Generated by `benchmarks/run_benchmarks.py`, which writes only this section (between the")
    w(
        "`issue2` markers). Every figure below, C++ and Python, comes from **one run** on one machine,"
    )
    w("so the speed-up ratios compare measurements taken under the same conditions. Benchmarks are")
    w("not tests: nothing fails on a timing.")
    w("")
    w(
        f"- Date: {meta['date']}"
        + (
            " — **quick run** (`--quick`: fewer repetitions; the scipy "
            "construction time is extrapolated)"
            if meta["quick"]
            else ""
        )
    )
    w(f"- CPU: {meta['cpu']}")
    w(
        f"- Load average (1/5/15 min) before / after: {meta['load_before']} → {meta['load_after']}"
        " (the machine is shared: worst cases include preemption by other processes)"
    )
    w(
        f"- C++: {cpp['compiler']}, build type {cpp['build_type']}, flags `{cpp['cxx_flags']}`;"
        f" predefined macros: `{cpp['macros']}`"
    )
    w(
        f"- Python {meta['python']}, numpy {meta['numpy']}, scipy {meta['scipy']}, lugrip {meta['lugrip']}"
    )
    w(f"- Run time of the whole benchmark: {meta['elapsed']:.0f} s")
    w("")
    w(
        "Reproduce: `make bench` — builds `build/cpp` (Release, `-DLUGRIP_BUILD_BENCHMARKS=ON`) and the"
    )
    w("package in `.venv`, then runs `.venv/bin/python benchmarks/run_benchmarks.py --cpp-dir")
    w(
        "build/cpp/benchmarks --out BENCHMARKS.md` (about a minute; `--quick` for a ~15 s smoke run)."
    )
    w(f"This file was written by: `{meta['command']}`. The C++ figures alone:")
    w("`build/cpp/benchmarks/bench_core` (human-readable; `--json` for the raw data).")
    w("")

    # --- targets
    cor_all = {obj: find(C, "cor_step", f"{obj}: all") for obj in base.OBJECTS}
    cor_ratio = {
        obj: find(P, "cor_step", f"{obj}: all")["stats"]["median_ns"]
        / cor_all[obj]["stats"]["median_ns"]
        for obj in base.OBJECTS
    }
    cons = [r for r in C if r["group"] == "construct" and r["name"].startswith("LimitSurface")]
    worst_cons = max(cons, key=lambda r: r["stats"]["median_ms"])
    med_cor = max(r["stats"]["median_ns"] for r in cor_all.values())
    targets["cor_median_ns"] = (med_cor, med_cor <= TARGET_COR_NS)
    targets["cor_ratio"] = (min(cor_ratio.values()), min(cor_ratio.values()) >= TARGET_COR_RATIO)
    targets["construct_ms"] = (
        worst_cons["stats"]["median_ms"],
        worst_cons["stats"]["median_ms"] <= TARGET_CONSTRUCT_MS,
    )

    def ok(b):
        return "**met**" if b else "**not met**"

    w("### Targets of the contact-model core")
    w("")
    w("| target | measured | status |")
    w("|---|---|---|")
    w(
        f"| CoR estimate ≤ {TARGET_COR_NS:.0f} ns median in C++ (`CorEstimator::step`, all samples) | "
        + ", ".join(f"{obj} {fmt_ns(r['stats']['median_ns'])}" for obj, r in cor_all.items())
        + f" | {ok(targets['cor_median_ns'][1])} |"
    )
    w(
        f"| CoR estimate ≥ {TARGET_COR_RATIO:.0f}× the scipy reference (brentq, per-sample median) | "
        + ", ".join(f"{obj} {fmt_ratio(x)}" for obj, x in cor_ratio.items())
        + f" | {ok(targets['cor_ratio'][1])} |"
    )
    w(
        f"| LS construction ≤ {TARGET_CONSTRUCT_MS:.0f} ms (`LimitSurface(k)`, k = 2, 3, 4, 8, ∞; median) | "
        f"slowest {worst_cons['name']}: {worst_cons['stats']['median_ms']:.1f} ms "
        f"(worst single build {worst_cons['stats']['worst_ms']:.1f} ms) | {ok(targets['construct_ms'][1])} |"
    )
    w(
        "| LS max abs error ≤ 1e-6 over c~ in [0, 1e3] | checked by the tests, not here: "
        "`tests/python/test_limit_surface.py::test_reference_every_k` and `tests/cpp/test_limit_surface.cpp` "
        "(`LimitSurfaceReference.IndependentQuadratureEveryK`) against the independent quadrature "
        f"`tests/reference/ls_reference.csv` (k = {meta['ref_ks']}). "
        "Informative figure from this run: max \\|lugrip − quad\\| = "
        f"{chk['ls_max_abs_diff']:.1e} at the {chk['ls_points']} random points timed below (k = 4) | see tests |"
    )
    w("")

    # --- LS evaluation
    w("### Limit-surface evaluation (k = 4), per call")
    w("")
    w("| implementation | c~ | median | p99 | worst | C++ speed-up (median; p99) |")
    w("|---|---|---|---|---|---|")
    pairs = [
        (
            "log-uniform [1e-3, 1e3]",
            "ft_star+tau_star, log-uniform",
            "quad, c~ log-uniform [1e-3,1e3]",
            "CubicSpline table, log-uniform",
        ),
        (
            "uniform [0, 3]",
            "ft_star+tau_star, uniform [-3,3]",
            "quad, c~ uniform [0,3]",
            "CubicSpline table, uniform [0,3]",
        ),
    ]
    for label, cname, qname, sname in pairs:
        c = find(C, "ls_eval", cname)["stats"]
        q = find(P, "ls_eval", qname)["stats"]
        s = find(P, "ls_eval", sname)["stats"]
        w(
            f"| C++ `ft_star(c) + tau_star(c)` (two calls) | {label} | {fmt_ns(c['median_ns'])} | "
            f"{fmt_ns(c['p99_ns'])} | {fmt_ns(c['worst_ns'])} | — |"
        )
        w(
            f"| scipy nested `quad` (docs/model.md 3.3 method A) | {label} | {fmt_ns(q['median_ns'])} | "
            f"{fmt_ns(q['p99_ns'])} | {fmt_ns(q['worst_ns'])} | {fmt_ratio(q['median_ns'] / c['median_ns'])}; {fmt_ratio(q['p99_ns'] / c['p99_ns'])} |"
        )
        w(
            f"| scipy `CubicSpline` table, one scalar call | {label} | {fmt_ns(s['median_ns'])} | "
            f"{fmt_ns(s['p99_ns'])} | {fmt_ns(s['worst_ns'])} | {fmt_ratio(s['median_ns'] / c['median_ns'])}; {fmt_ratio(s['p99_ns'] / c['p99_ns'])} |"
        )
    for name in ("eval, c~ log-uniform [1e-3,1e3]", "eval, c~ uniform [0,3]"):
        c = find(C, "ls_eval", name)["stats"]
        w(
            f"| C++ `eval(a)` (F, T, dF, dT) | {name.split(', ', 1)[1].replace('c~ ', '')} | "
            f"{fmt_ns(c['median_ns'])} | {fmt_ns(c['p99_ns'])} | {fmt_ns(c['worst_ns'])} | — |"
        )
    a = api["ls"]
    w(
        f"| Python API `LimitSurface.ft_star` + `.tau_star` on 1e5 points, per point | log-uniform | "
        f"{fmt_ns(a['median_ns'])} | — | {fmt_ns(a['worst_ns'])} (of {a['calls']} runs) | — |"
    )
    w("")

    # --- CoR
    w("### CoR estimation, per sample")
    w("")
    w(
        "C++: `CorEstimator::step`. scipy: one Python call per sample, `brentq` on the σ equation and on"
    )
    w("the outside equation, LS values from the `CubicSpline` table. Inside/outside is each")
    w("implementation's own verdict on its samples.")
    w("")
    w(
        "| contact, samples | C++ median | C++ p99 | C++ worst | iterations | scipy median | scipy p99 | scipy worst | speed-up (median; p99) |"
    )
    w("|---|---|---|---|---|---|---|---|---|")
    for obj in base.OBJECTS:
        for part in ("inside LS", "outside LS", "all"):
            c = find(C, "cor_step", f"{obj}: {part}")
            q = find(P, "cor_step", f"{obj}: {part}")
            cs, qs = c["stats"], q["stats"]
            w(
                f"| {obj}, {part} | {fmt_ns(cs['median_ns'])} | {fmt_ns(cs['p99_ns'])} | {fmt_ns(cs['worst_ns'])} | "
                f"{c['iterations_per_call']:.2f} | {fmt_ns(qs['median_ns'])} | {fmt_ns(qs['p99_ns'])} | "
                f"{fmt_ns(qs['worst_ns'])} | {fmt_ratio(qs['median_ns'] / cs['median_ns'])}; {fmt_ratio(qs['p99_ns'] / cs['p99_ns'])} |"
            )
        sc = cor_all[obj]["single_call"]
        w(
            f"| {obj}, all, each call timed alone | {fmt_ns(sc['median_ns'])} | {fmt_ns(sc['p99_ns'])} | "
            f"{fmt_ns(sc['worst_ns'])} | | | | | |"
        )
    w("")
    w("Vectorized paths (per sample, whole array of samples, median of repeated runs):")
    w("")
    w(
        "| contact | lugrip Python API `estimate_cor` (1e5 samples, binding overhead included) | numpy vectorized bisection on the CubicSpline table | speed-up |"
    )
    w("|---|---|---|---|")
    for obj in base.OBJECTS:
        a = api[obj]["median_ns"]
        v = next(r for r in P if r["group"] == "cor_vectorized" and r["name"].startswith(obj))[
            "stats"
        ]["median_ns"]
        w(f"| {obj} | {fmt_ns(a)} | {fmt_ns(v)} | {fmt_ratio(v / a)} |")
    w("")
    w(
        "Agreement of the scipy baseline with lugrip on the baseline's samples (so the comparison is of"
    )
    w(
        "the same computation): "
        + "; ".join(
            f"{obj}: max \\|Δc~\\| = {d['max_abs_diff']:.1e} (median {d['median_abs_diff']:.1e}), inside flag "
            f"equal on {100 * d['inside_agree']:.2f} % of {d['n']} samples"
            for obj, d in chk["cor"].items()
        )
        + "."
    )
    w("")

    if not targets["cor_median_ns"][1]:
        ev = find(C, "ls_eval", "eval, c~ log-uniform [1e-3,1e3]")["stats"]["median_ns"]
        parts = []
        for obj in base.OBJECTS:
            i = find(C, "cor_step", f"{obj}: inside LS")
            o = find(C, "cor_step", f"{obj}: outside LS")
            parts.append(
                f"{obj}: inside {fmt_ns(i['stats']['median_ns'])} "
                f"({i['iterations_per_call']:.2f} iterations), outside "
                f"{fmt_ns(o['stats']['median_ns'])} ({o['iterations_per_call']:.2f} iterations)"
            )
        w(
            "**Where the time goes** (the ≤ 200 ns target is missed): " + "; ".join(parts) + ". "
            f"One `LimitSurface::eval` costs {fmt_ns(ev)}; a sample spends two `pow` calls (ρ and "
            "|f~|^γ), the σ inversion (table lookup, `exp`, `log`, then one Newton polish = one "
            "`eval` + two `log`), an `eval` for the inside test, on the outside branch one `eval` at "
            "c~_max plus about two Newton steps, and a final `eval` for g. The instruction profile and "
            "the measured effect of concrete optimisations are in `benchmarks/README.md`."
        )
        w("")

    # --- construction
    w("### Construction")
    w("")
    w("| object | median | p99 | worst | builds | heap allocations per build |")
    w("|---|---|---|---|---|---|")
    for r in C:
        if r["group"] == "construct":
            s = r["stats"]
            w(
                f"| C++ `{r['name']}` | {s['median_ms']:.2f} ms | {s['p99_ms']:.2f} ms "
                f"| {s['worst_ms']:.2f} ms | {s['calls']} | {s['allocations']} |"
            )
    q = find(P, "construct", "LsTable(k=4)")
    qs = q["stats"]
    c4 = find(C, "construct", "LimitSurface(k=4)")["stats"]
    w(f"| scipy LS table, k = 4 ({q['method']}) | {qs['median_ms'] / 1e3:.1f} s | | | 1 | |")
    w("")
    w(
        f"C++ `LimitSurface(4)` vs the scipy table: {fmt_ratio(qs['median_ms'] / c4['median_ms'])} faster "
        f"(the C++ tables have 2 × {cpp['ls_table_nodes']} nodes with exact derivatives and Hermite "
        "interpolation; the scipy "
        "table is the 641-node grid of docs/model.md 3.3 with a cubic spline, quoted there at 2e-6)."
    )
    w("")

    # --- method
    w("### Method")
    w("")
    w(
        f"- **C++** (`benchmarks/bench_core.cpp`): inputs precomputed from a seeded `std::mt19937` (seed {cpp['seed']})."
    )
    w(f"  A per-call figure is the time of a batch of {cpp['batch']} consecutive calls, read with")
    w(
        f"  `std::chrono::steady_clock` around the batch, minus the median cost of an empty timed region"
        f" ({cpp['timer_overhead_ns']:.0f} ns), divided by {cpp['batch']}. Median and p99 are over all batches;"
    )
    w(
        f'  **worst** is the slowest batch of {cpp["batch"]} calls (its per-call mean). The row "each call timed'
    )
    w(
        '  alone" times every `step` individually (same clock, overhead subtracted): its worst is the'
    )
    w(
        "  single-call worst case a 1 kHz loop sees, including any preemption. Constructions are timed one"
    )
    w(
        "  by one after a warm-up build. The binary replaces `operator new` and counts allocations in the"
    )
    w(
        "  timed loops: "
        + ", ".join(
            sorted({str(r["stats"]["allocations"]) for r in C if r["group"] != "construct"})
        )
        + " allocation(s) in the evaluation and `step` loops."
    )
    w("- **Samples** (same recipe in C++ and Python, different generators): f_n log-uniform in")
    w(
        "  [0.2, 16] N; an LS parameter a log-uniform in [1e-2, 1e2] (rotational for a ≪ 1, translational"
    )
    w(
        "  for a ≫ 1); half inside the LS (λ·(F, T), λ ~ U[0.05, 0.98]), a quarter on the LS plus a viscous"
    )
    w(
        "  excess ((F + 2ξaν, T + ν), ν log-uniform in [1e-3, 1]), a quarter radially outside (λ ~ U[1.02, 2]);"
    )
    w("  random signs of f_t and τ. Contacts: paper Table 1 and the big resin block of Table 2.")
    w(
        "- **scipy baseline** (`benchmarks/scipy_baseline.py`, no lugrip import): written as a user would,"
    )
    w(
        "  from docs/model.md. The LS at one c~ by nested `scipy.integrate.quad` (method A of docs/model.md 3.3:"
    )
    w(
        "  CoR-centred chords, the inner integral with QUADPACK's algebraic end-point weight, default"
    )
    w("  tolerances, agreeing with the docs/model.md 3.4 table to 1e-10). The CoR per sample with")
    w(
        "  `scipy.optimize.brentq` on F^(γ+1) − σT = 0 and on h(a) = f − F − 2ξa(t − T), with F, T from a"
    )
    w(
        "  `CubicSpline` table built once (one scalar spline call returns both curves), then c, g, σ₁, y"
    )
    w(
        "  as lugrip does. No quadrature per sample: **this is a fair, fast baseline, not a strawman.**"
    )
    w(
        "  Each Python call is timed alone with `time.perf_counter_ns`, the garbage collector off (as in `timeit`)."
    )
    w(
        "- **Python API**: `lugrip.estimate_cor(params, f_n, f_t, tau)` on 1e5 samples (arrays in, arrays"
    )
    w(
        "  out, the loop in C++), total time / 1e5, median of repeated runs after a warm-up call that"
    )
    w("  builds the cached model.")
    w("")
    w(
        "Object sizes (bytes, `sizeof`; the tables live on the heap): "
        + ", ".join(f"{k} {v}" for k, v in cpp["sizeof"].items())
        + "."
    )
    w("")
    w("")
    w(END)
    write_section(path, "\n".join(lines) + "\n")
    return targets


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cpp-dir", type=Path, default=Path("build/cpp/benchmarks"))
    ap.add_argument("--out", type=Path, default=Path("BENCHMARKS.md"))
    ap.add_argument("--quick", action="store_true", help="fewer repetitions (< 20 s)")
    ap.add_argument("--json", type=Path, help="also write all raw results to this JSON file")
    args = ap.parse_args(argv)

    import lugrip
    import scipy

    t_start = time.time()
    meta = {
        "date": dt.datetime.now().astimezone().strftime("%Y-%m-%d %H:%M %Z"),
        "cpu": cpu_model(),
        "load_before": load_avg(),
        "ref_ks": reference_ks(),
        "quick": args.quick,
        "python": platform.python_version(),
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "lugrip": lugrip.__version__,
        "command": " ".join(
            ["python", "benchmarks/run_benchmarks.py"]
            + list(argv if argv is not None else sys.argv[1:])
        ),
    }
    cpp = run_cpp(args.cpp_dir, args.quick)
    log("running the scipy baseline")
    py = base.run(args.quick, log=log)
    log("running the Python API")
    api = run_python_api(args.quick, py.pop("_table"))
    chk = sanity_checks(py)
    meta["load_after"] = load_avg()
    meta["elapsed"] = time.time() - t_start
    targets = write_report(args.out, cpp, py, api, chk, meta)
    if args.json:
        py.pop("samples", None)
        args.json.write_text(
            json.dumps(
                {"cpp": cpp, "scipy": py, "python_api": api, "checks": chk, "meta": meta}, indent=1
            )
        )
    log(f"wrote {args.out} in {meta['elapsed']:.0f} s")
    for k, (v, met) in targets.items():
        log(f"  {k}: {v:.4g} -> {'met' if met else 'NOT met'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
