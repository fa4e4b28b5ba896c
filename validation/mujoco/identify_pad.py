"""Identify the MuJoCo gripper's pad and each scenario object's friction from MuJoCo rubbing data.

The parameters the MuJoCo scenarios give their observers and controller come from here, not
from the presets the scenes are built with:

1. **The pad.** The rubbing rig (:class:`lugrip.rigs.mujoco_rig.MujocoRubbingRig`) is built
   with the gripper scenes' pad (:meth:`MujocoRubbingRig.for_scene`: the same hemisphere,
   springs, implicit damping, contact options and torsional law) rubbing a slider of
   ``--pad-mu``. Prescribed-motion rubbing (:class:`lugrip.rigs.RubbingDesign`, presliding
   first, a loaded rest after, sensor noise and offsets) is fitted by ``lugrip identify`` with
   its defaults (staged identification, observer block included): ``objects/mujoco/pad.yaml``.
2. **Each object** (the paper's Table 2 procedure): rubbing data of the pad on that object's
   friction (the scene's mu), fitted by ``lugrip identify --free mu --params0 pad.yaml``
   from the limit-surface stage on that object's gross-sliding wrench with the pad's delta
   and gamma held (``--start data --no-refine``; beta_A only where the data carry it:
   ``--object-free mu,beta_a``): ``objects/mujoco/<object>.yaml``.

The pad's sigma_z is not significant on the loading runs, which bound it near zero; the
identification then gives the observer the sigma_z that damps its stick mode critically
(docs/identification.md, stage (b)), and the file's note says so.

Every data set is drawn from a fixed seed, so the files are reproducible; the logs are cached
under ``build/mujoco_ident/`` (regenerated with ``--force``). A summary of identified against
true mu and tau_max goes to ``build/mujoco_ident/summary.json`` and is printed as a table.

    python validation/mujoco/identify_pad.py                 # both steps (make identify-mujoco)
    python validation/mujoco/identify_pad.py --only pad --maneuvers 24 --out-dir /tmp/fit
    python validation/mujoco/identify_pad.py --only pad --observer-check 0.0115,0.048,0.095
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
from lugrip import ContactParams
from lugrip.rigs import RubbingData, RubbingDesign
from lugrip.rigs.mujoco_rig import MujocoRubbingRig
from lugrip.sim.scenarios import load_scenario

ROOT = Path(__file__).resolve().parents[2]

#: the object of each MuJoCo scenario: (object file name, scenario that defines its scene and mu)
OBJECTS = {
    "big_resin_block": "exp1_big_resin_block",
    "small_resin_block": "exp2_small_resin_block",
    "plastic_bottle": "exp3_plastic_bottle_pivot",
    "aluminium_can": "exp4_aluminium_can_empty",  # the full can: the same object and contact
    "bar": "bar_offset",
    "box": "box_heavy",
    "cup": "cup_light",
    "plate": "plate_pivot",
}
#: scenario -> object file (the full can shares the empty can's, the tilted bar the bar's)
SCENARIO_OBJECT = {v: k for k, v in OBJECTS.items()} | {
    "exp4_aluminium_can_full": "aluminium_can",
    "bar_tilt": "bar",
}
#: the scene whose pad and contact-radius law the pad fit uses (every scene has the same pad)
PAD_SCENE = "exp2_small_resin_block"
PAD_SEED = 0  #: the pad data set's seed; object k uses PAD_SEED + 101 + k
PAD_MANEUVERS = 160
OBJECT_MANEUVERS = 80  #: per object (58-71 of them reach gross sliding)
#: the pad fit's limit-surface shape: identify's default ('free': the pressure family and the
#: elliptic limit surface both fitted, the lower RMS distance kept; on MuJoCo's elliptic cone
#: that is the ellipse, k = 0)
PAD_K = "free"
#: the object refits free mu only: MuJoCo's friction is Coulomb, the pad fit finds no speed
#: dependence (beta_A "not observable"), and freeing beta_A as well lets the velocity-error
#: cost trade mu for a large beta_A (mu 0.05-0.46 for true 0.6-0.9, validation/mujoco/README.md)
OBJECT_FREE = "mu"
#: identify's options of the object refits: mu from the limit-surface stage on the object's
#: gross-sliding wrench with pad.yaml's delta and gamma held (the other parameters from
#: pad.yaml too), without the eq. 32 refinement,
#: whose velocity-error cost cannot see mu when the speed is unobservable (it drifts to
#: 1.1-1.9 for true 0.85-0.9; validation/mujoco/README.md); --object-refine adds it back
OBJECT_OPTIONS = ("--start", "data", "--no-refine")


def pad_rig(mu: float, scene: str = PAD_SCENE) -> MujocoRubbingRig:
    """The rubbing rig with the pad of MuJoCo scene `scene` on a slider of friction `mu`."""
    s = load_scenario(scene)
    return MujocoRubbingRig.for_scene(s.scene_spec(), s.params.replace(mu=float(mu)))


def rubbing_data(
    rig: MujocoRubbingRig, n: int, seed: int, directory: Path, force: bool
) -> RubbingData:
    """The rig's rubbing data set (n maneuvers of the default design, `seed`), cached in
    `directory` with its parameters in the metadata."""
    key = {"n": int(n), "seed": int(seed), "pad": repr(rig.pad), "settings": repr(rig.settings)}
    stamp = directory / "key.json"
    if not force and stamp.is_file() and json.loads(stamp.read_text()) == key:
        return RubbingData.load(directory)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        data = rig.simulate(RubbingDesign(), n=n, seed=seed)
    for w in caught:
        print(f"  warning: {w.message}", file=sys.stderr)
    data.save(directory, overwrite=True)
    stamp.write_text(json.dumps(key))
    return data


def _log_file(directory: Path) -> Path:
    for name in ("log.parquet", "log.csv"):
        if (directory / name).is_file():
            return directory / name
    raise FileNotFoundError(f"no log in {directory}")


def identify(log: Path, out: Path, extra: list[str], report: Path | None) -> int:
    """Run ``lugrip identify`` (the installed command's module) on `log`; its exit code."""
    cmd = [
        sys.executable,
        "-m",
        "lugrip",
        "identify",
        _from_root(log),
        "--out",
        _from_root(out),
        "--force",
        "--quiet",
        *extra,
    ]
    if report is not None:
        cmd += ["--report", _from_root(report)]
    print("  $", " ".join(["lugrip", *cmd[3:]]))
    # run from the repository root so that the files name their logs by repository-relative
    # paths (build/mujoco_ident/...), not by this machine's absolute ones
    return subprocess.run(cmd, check=False, cwd=ROOT).returncode


def _from_root(path: Path) -> str:
    """`path` relative to the repository root when it lies inside it, else absolute."""
    path = Path(path).resolve()
    try:
        return str(path.relative_to(ROOT))
    except ValueError:
        return str(path)


def tau_max(p: ContactParams, f_n: float) -> float:
    """The model's torsional capacity mu xi(k) delta f_n^(gamma+1) [N m]."""
    from lugrip import LimitSurface

    return float(p.mu * LimitSurface(p.k).xi * p.delta * f_n ** (p.gamma + 1.0))


def fit_status(path: Path) -> dict:
    """Status, message, free parameters at (within 0.1 % of) a bound, and the observer's
    omega_hat RMSE on training and held-out maneuvers beside the RMS of omega (the error of
    predicting zero), from an identification YAML."""
    import yaml

    doc = yaml.safe_load(path.read_text())
    ident = doc.get("identification") or {}
    at_bound = []
    for name, v in (doc.get("contact") or {}).items():
        if isinstance(v, dict) and v.get("free") and v.get("bounds"):
            lo, hi = (float(b) for b in v["bounds"])
            x = float(v["value"])
            if x <= lo + 1e-3 * abs(lo) or x >= hi - 1e-3 * abs(hi):
                at_bound.append(name)
    keys = ("rmse_train", "rmse_validation", "rms_omega_train", "rms_omega_validation")
    return {
        "status": ident.get("status"),
        "message": ident.get("message", ""),
        "at_bound": at_bound,
    } | {k: ident.get(k) for k in keys}


def compare(rig: MujocoRubbingRig, fitted: Path) -> dict:
    """Identified against true mu and tau_max(f_n) at 1, 4 and 10 N."""
    p = ContactParams.from_yaml(fitted)
    row = {
        "mu_true": rig.pad.mu,
        "mu_fit": p.mu,
        "beta_a_fit": p.beta_a,
        "sigma0_fit": p.sigma0,
        "sigma_z_fit": p.sigma_z,
        "delta_fit": p.delta,
        "gamma_fit": p.gamma,
        "k_fit": p.k,
    }
    for f in (1.0, 4.0, 10.0):
        row[f"tau_max_true_{f:g}N"] = float(rig.pad.tau_max(f))
        row[f"tau_max_fit_{f:g}N"] = tau_max(p, f)
    row.update(fit_status(fitted))
    return row


def observer_check(fitted: Path, data: RubbingData, sigma_z: list[float]) -> list[dict]:
    """The online observer of `fitted` (its observer block) on the fit's held-out maneuvers of
    `data`, once per sigma_z value (the other parameters the file's), against the rig's truth:
    the share of gross-sliding samples with S >= 0.9, of stick samples below 0.7 of the
    friction limit with S >= 0.9, and the delay from each maneuver's first gross-sliding
    sample to S >= 0.9 (median and 90 % quantile [s]; 0: S was there first)."""
    import yaml
    from lugrip import Observer
    from lugrip.identification import read_observer_settings

    doc = yaml.safe_load(fitted.read_text())
    held = sorted(int(str(m).rsplit("#", 1)[1])
                  for m in doc["identification"]["validation_maneuvers"])
    d = data.select_maneuvers(held)
    log, p0, kw = d.log, ContactParams.from_yaml(fitted), read_observer_settings(fitted)
    rows = []
    for sz in sigma_z:
        p = p0.replace(sigma_z=float(sz))
        S = np.empty(len(log))
        delays = []
        for m in np.unique(log.maneuver):
            sel = np.flatnonzero(log.maneuver == m)
            run = Observer(p, **kw).run(
                {"t": log.t[sel], "f_n": log.f_n[sel], "f_t": log.f_t[sel], "tau": log.tau[sel]}
            )
            S[sel] = np.asarray(run.S)
            gross = np.flatnonzero(d.phase[sel] == 2)
            if gross.size:
                i0 = int(gross[0])
                hit = np.flatnonzero(S[sel][i0:] >= 0.9)
                delays.append(log.t[sel][i0 + hit[0]] - log.t[sel][i0] if hit.size else np.inf)
        delays = np.asarray(delays)
        stick = d.stick_below(0.7)
        rows.append({
            "sigma_z": float(sz),
            "S_sliding": float(np.mean(S[d.gross_sliding] >= 0.9)),
            "S_stick": float(np.mean(S[stick] >= 0.9)),
            "delay_median": float(np.median(delays)),
            "delay_p90": float(np.quantile(delays, 0.9)),
            "maneuvers": int(delays.size),
        })
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument(
        "--only", choices=("pad", "objects"), help="one step only (objects needs the pad file)"
    )
    ap.add_argument("--objects", default=",".join(OBJECTS), help="comma-separated object names")
    ap.add_argument("--maneuvers", type=int, default=PAD_MANEUVERS, help="pad data set size")
    ap.add_argument("--object-maneuvers", type=int, default=OBJECT_MANEUVERS)
    ap.add_argument("--seed", type=int, default=PAD_SEED)
    ap.add_argument("--pad-mu", type=float, default=0.7, help="the pad fit's slider friction")
    ap.add_argument(
        "--pad-k",
        default=str(PAD_K),
        help="identify's --k for the pad fit (default 'free': identify's default, the shape "
        "identified; a number holds k there)",
    )
    ap.add_argument("--out-dir", type=Path, default=ROOT / "objects" / "mujoco")
    ap.add_argument("--cache", type=Path, default=ROOT / "build" / "mujoco_ident")
    ap.add_argument(
        "--object-free",
        default=OBJECT_FREE,
        help=f"identify's --free for the object refits (default {OBJECT_FREE})",
    )
    ap.add_argument(
        "--object-refine",
        action="store_true",
        help="object refits with identify's "
        "eq. 32 refinement from pad.yaml (default: the limit-surface stage alone)",
    )
    ap.add_argument("--report", action="store_true", help="identify's report per fit")
    ap.add_argument(
        "--observer-check",
        default="",
        metavar="SIGMA_Z,...",
        help="after the pad fit: S of its observer on the held-out maneuvers against the rig's "
        "truth with the file's sigma_z and with each of these values",
    )
    ap.add_argument("--force", action="store_true", help="regenerate cached data sets")
    args = ap.parse_args(argv)
    args.out_dir.mkdir(parents=True, exist_ok=True)
    pad_file = args.out_dir / "pad.yaml"
    summary: dict = {}
    failed = []
    if args.only in (None, "pad"):
        rig = pad_rig(args.pad_mu)
        d = args.cache / f"pad_n{args.maneuvers}_s{args.seed}"
        print(f"pad: {args.maneuvers} maneuvers, seed {args.seed}, slider mu {args.pad_mu}")
        rubbing_data(rig, args.maneuvers, args.seed, d, args.force)
        extra = [] if args.pad_k == "free" else ["--k", args.pad_k]
        rc = identify(_log_file(d), pad_file, extra, d / "report" if args.report else None)
        if rc != 0:
            failed.append(("pad", rc))
        if pad_file.is_file():
            summary["pad"] = compare(rig, pad_file) | {"exit": rc}
            if args.observer_check:
                own = ContactParams.from_yaml(pad_file).sigma_z
                values = [own] + [float(v) for v in args.observer_check.split(",") if v]
                rows = observer_check(pad_file, RubbingData.load(d), values)
                summary["pad"]["observer_check"] = rows
                print("| sigma_z [N m s/rad] | S >= 0.9 sliding | S >= 0.9 stick < 0.7 "
                      "| delay to S >= 0.9 median / 90 % [ms] | maneuvers |")
                print("|---|---|---|---|---|")
                for r in rows:
                    print(f"| {r['sigma_z']:.3g} | {r['S_sliding']:.3f} | {r['S_stick']:.4f} | "
                          f"{1e3 * r['delay_median']:.0f} / {1e3 * r['delay_p90']:.0f} | "
                          f"{r['maneuvers']} |")
    if args.only in (None, "objects"):
        if not pad_file.is_file():
            raise SystemExit(f"{pad_file} is missing: run the pad step first")
        for i, name in enumerate(o for o in args.objects.split(",") if o):
            scene = OBJECTS[name]
            mu = load_scenario(scene).params.mu
            rig = pad_rig(mu, scene)
            seed = args.seed + 101 + list(OBJECTS).index(name)
            d = args.cache / f"{name}_n{args.object_maneuvers}_s{seed}"
            print(f"{name}: {args.object_maneuvers} maneuvers, seed {seed}, mu {mu}")
            rubbing_data(rig, args.object_maneuvers, seed, d, args.force)
            out = args.out_dir / f"{name}.yaml"
            extra = ["--free", args.object_free, "--params0", str(Path(pad_file).resolve())]
            extra += [] if args.object_refine else list(OBJECT_OPTIONS)
            rc = identify(_log_file(d), out, extra, d / "report" if args.report else None)
            if rc != 0:
                failed.append((name, rc))
            if out.is_file():
                summary[name] = compare(rig, out) | {"exit": rc}
    args.cache.mkdir(parents=True, exist_ok=True)
    (args.cache / "summary.json").write_text(json.dumps(summary, indent=1, default=float))
    print("| fit | mu true | mu identified | tau_max(4 N) true [N mm] | identified | status |")
    print("|---|---|---|---|---|---|")
    for name, r in summary.items():
        print(
            f"| {name} | {r['mu_true']:.3f} | {r['mu_fit']:.4f} | "
            f"{1e3 * r['tau_max_true_4N']:.3f} | {1e3 * r['tau_max_fit_4N']:.3f} | "
            f"{r['status']}{' at bound: ' + ','.join(r['at_bound']) if r['at_bound'] else ''}"
            f" |"
        )
    if failed:
        print("failed fits: " + ", ".join(f"{n} (exit {rc})" for n, rc in failed), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    np.seterr(all="ignore")
    raise SystemExit(main())
