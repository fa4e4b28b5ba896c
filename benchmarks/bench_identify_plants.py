"""Identification on plants lugrip did not generate: `lugrip.identify` with defaults on
prescribed-motion rubbing data of every rig (lugrip.rigs: grid Stribeck, grid viscous,
MuJoCo, and the patch and lumped plants), scored on held-out maneuvers with the online
observer and the fitted YAML; writes the 'identification-plants' section of BENCHMARKS.md.

    python benchmarks/bench_identify_plants.py [--maneuvers 160] [--plants grid-stribeck,...]

Per plant: 200 maneuvers (seed 11) are generated (cached under build/rubbing/), every fifth
is held out (40), the other 160 are fitted. Acceptance figures: mu against the plant's
(Stribeck: inside [mu_k, mu_s]), tau_max(f_n) at 2 N and 8 N, parameters at a bound, the
share of gross-sliding samples with S >= 0.9 and of stick samples below 70 % of the friction
limit with S >= 0.9, speed_observable against the plant's truth on gross sliding, and the
|omega| RMSE (|c~| <= 1.5 with omega_hat; all samples with the observer's omega_object, the
rotation consistent with the unclipped CoR, when the observer has it) against predicting
zero. The baseline of the fit time, measured in the same run, is one pass of the online
observer over the same 160 maneuvers.
"""

from __future__ import annotations

import argparse
import json
import math
import platform
import sys
import time
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import lugrip
from lugrip.rigs import RubbingData, make_rig
from sections import write_section

SECTION = "identification-plants"
PLANTS = ("grid-stribeck", "grid-viscous", "mujoco", "patch", "lumped")


def data_for(plant: str, n: int, seed: int, cache: Path) -> RubbingData:
    path = cache / f"{plant}_{n}_{seed}"
    if path.exists():
        return RubbingData.load(path)
    data = make_rig(plant).simulate(n=n, seed=seed)
    data.save(path, overwrite=True)
    return data


def score(result, data: RubbingData) -> dict:
    """Observer with the fitted parameters and observer block on ``data``."""
    run = result.make_observer().run(data.log)
    S = np.asarray(run.S)
    obs = np.asarray(run.speed_observable, bool)
    om = np.asarray(data.log.omega)
    wh = np.asarray(run.omega_hat)
    w_all = np.asarray(getattr(run, "omega_object", wh))
    gs = data.gross_sliding
    st = data.stick_below(0.7)
    small = np.abs(data.c_tilde_true) <= 1.5
    rms = lambda x: float(np.sqrt(np.mean(np.square(x)))) if np.size(x) else math.nan
    return {
        "S_sliding": float(np.mean(S[gs] >= 0.9)) if gs.any() else math.nan,
        "S_stick": float(np.mean(S[st] >= 0.9)) if st.any() else math.nan,
        "observable_sliding": float(np.mean(obs[gs])) if gs.any() else math.nan,
        "rmse_small": rms(np.abs(wh[small]) - np.abs(om[small])),
        "zero_small": rms(om[small]),
        "rmse_all": rms(np.abs(w_all) - np.abs(om)),
        "zero_all": rms(om),
        "omega_all_output": "omega_object" if hasattr(run, "omega_object") else "omega_hat",
    }


def bench_plant(plant: str, n_fit: int, seed: int, cache: Path) -> dict:
    n_total = n_fit + n_fit // 4
    data = data_for(plant, n_total, seed, cache)
    ids = np.unique(data.log.maneuver)
    held = ids[ids % 5 == 4]
    train = data.select_maneuvers(ids[ids % 5 != 4])
    test = data.select_maneuvers(held)
    obs0 = lugrip.Observer(lugrip.ContactParams.table1())
    t0 = time.perf_counter()
    obs0.run(train.log)
    t_base = time.perf_counter() - t0
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        load0 = _load()
        t0, c0 = time.perf_counter(), time.process_time()
        r = lugrip.identify(train.log)
        t_fit, cpu_fit = time.perf_counter() - t0, time.process_time() - c0
        load1 = _load()
    T = data.truth
    p = r.params
    xi = lugrip.LimitSurface(p.k).xi
    tau = {f: p.mu * xi * p.delta * f ** (1.0 + p.gamma) / T.tau_max(f) for f in (2.0, 8.0)}
    if T.mu_static > T.mu_kinetic:
        lo, hi = T.mu_kinetic * 0.95, T.mu_static * 1.05
    else:
        lo, hi = T.mu * 0.95, T.mu * 1.05
    out = {
        "plant": plant,
        "samples_fit": len(train),
        "maneuvers_fit": int(len(ids) - len(held)),
        "maneuvers_held_out": len(held),
        "fit_s": t_fit,
        "fit_cpu_s": cpu_fit,
        "load_average": [load0, load1],
        "observer_pass_s": t_base,
        "status": r.status,
        "at_bound": [e.name for e in r.estimates if e.at_bound]
        + ([f"{n} (stage)" for n in r.stages.ls.at_bound] if r.stages is not None else []),
        "mu": p.mu,
        "mu_truth": [T.mu_kinetic, T.mu_static] if T.mu_static > T.mu_kinetic else T.mu,
        "mu_ok": bool(lo <= p.mu <= hi),
        "mu_stderr": r["mu"].stderr,
        "k": p.k,
        "beta_a": p.beta_a,
        "beta_a_truth": T.beta_a,
        "tau_max_ratio_2N": tau[2.0],
        "tau_max_ratio_8N": tau[8.0],
        "speed_observable": r.speed_observable,
        "viscous_truth": T.viscous,
        "torque_noise": r.observer.get("torque_noise"),
        "held_out": score(r, test),
        "training": score(r, train),
        "warnings": sorted({str(w.message)[:160] for w in caught}),
        "stages": list(r.stages.report) if r.stages is not None else [],
    }
    return out


def _f(v, fmt=".3f"):
    return "n/a" if v is None or (isinstance(v, float) and not math.isfinite(v)) else format(v, fmt)


def markdown(rows: list[dict], argv: list[str]) -> str:
    b, e = f"<!-- {SECTION}:begin -->", f"<!-- {SECTION}:end -->"
    lines = [
        b,
        "",
        "## Identification on independent plants (prescribed-motion rubbing)",
        "",
        f"`python benchmarks/bench_identify_plants.py {' '.join(argv)}`".rstrip() + f" on "
        f"{platform.machine()} ({_cores()} cores), {time.strftime('%Y-%m-%d')}. "
        "`lugrip.identify` with defaults (stages, then the regularised eq. 32 refinement) on "
        "160 maneuvers per plant; the observer with the fitted YAML scored on 40 held-out "
        "maneuvers (training maneuvers in brackets).",
        "",
        "| plant | mu (truth) | tau_max 2 N / 8 N | at bound | S >= 0.9 sliding | S >= 0.9 stick < 0.7 "
        "| speed_observable on sliding (truth) | abs-omega RMSE c~ <= 1.5 / zero | all samples / zero "
        "| status | fit wall / CPU [s] (observer pass [s], load average) |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        h, t = r["held_out"], r["training"]
        mu_t = r["mu_truth"]
        mu_t = f"[{mu_t[0]:.2f}, {mu_t[1]:.2f}]" if isinstance(mu_t, list) else f"{mu_t:.2f}"
        lines.append(
            f"| {r['plant']} | {r['mu']:.3f} ({mu_t}) {'ok' if r['mu_ok'] else 'OFF'} "
            f"| {r['tau_max_ratio_2N']:.3f} / {r['tau_max_ratio_8N']:.3f} "
            f"| {', '.join(r['at_bound']) or 'none'} "
            f"| {_f(h['S_sliding'])} ({_f(t['S_sliding'])}) | {_f(h['S_stick'])} ({_f(t['S_stick'])}) "
            f"| {_f(h['observable_sliding'])} ({r['viscous_truth']}) "
            f"| {_f(h['rmse_small'])} / {_f(h['zero_small'])} "
            f"| {_f(h['rmse_all'])} / {_f(h['zero_all'])} "
            f"| {r['status']} "
            f"| {r['fit_s']:.1f} / {r['fit_cpu_s']:.1f} ({r['observer_pass_s']:.2f}, "
            f"{r['load_average'][0]:.1f}) |"
        )
    lines += [
        "",
        "The machine is shared: the wall time of the fit depends on the load average (column); "
        "the CPU time is the work of the whole process (all threads), the observer pass the "
        "cost of one run of the online observer over the same 160 maneuvers, both measured in "
        "the same run. "
        "tau_max is the fitted capacity over the plant's own (kinetic friction); 'all samples' "
        "uses the observer's rotation consistent with the unclipped CoR where it has one "
        f"({rows[0]['held_out']['omega_all_output'] if rows else ''}). Stage reports:",
        "",
    ]
    for r in rows:
        lines.append(f"* **{r['plant']}** ({r['status']}, k {r['k']:.3g}, beta_A "
                     f"{r['beta_a']:.3g}, torque noise {_f(r['torque_noise'], '.2e')} N m): "
                     + "; ".join(s for s in r["stages"] if s.startswith(("(a)", "(c)"))))
    lines += ["", e, ""]
    return "\n".join(lines)


def _load() -> float:
    import os

    try:
        return float(os.getloadavg()[0])
    except OSError:
        return math.nan


def _cores() -> int:
    import os

    return os.cpu_count() or 1


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--maneuvers", type=int, default=160)
    ap.add_argument("--plants", default=",".join(PLANTS))
    ap.add_argument("--seed", type=int, default=11)
    ap.add_argument("--cache", type=Path, default=Path("build/rubbing"))
    ap.add_argument("--out", type=Path, default=Path("BENCHMARKS.md"))
    ap.add_argument("--json", type=Path, default=Path("build/bench_identify_plants.json"))
    a = ap.parse_args(argv)
    rows = []
    for plant in [p for p in a.plants.split(",") if p]:
        try:
            row = bench_plant(plant, a.maneuvers, a.seed, a.cache)
        except ImportError as err:
            print(f"{plant}: skipped ({err})", file=sys.stderr)
            continue
        rows.append(row)
        print(json.dumps(row, default=str)[:2000])
    a.json.parent.mkdir(parents=True, exist_ok=True)
    a.json.write_text(json.dumps(rows, indent=1, default=str))
    write_section(a.out, markdown(rows, argv), SECTION)
    return 0


if __name__ == "__main__":
    sys.exit(main())
