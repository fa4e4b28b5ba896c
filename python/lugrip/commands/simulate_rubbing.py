"""``lugrip simulate-rubbing``: prescribed-motion rubbing data from a plant written from its own
physics (or from lugrip's own models for comparison), with ground truth and labels
(:mod:`lugrip.rigs`, docs/rigs.md)."""

from __future__ import annotations

import argparse
import textwrap
import time
from pathlib import Path

from . import CliError
from ._output import check_dir

__all__ = ["MAX_MANEUVERS", "register", "run"]

MAX_MANEUVERS = 2000
"""Largest --maneuvers accepted (about 1.3 million samples, about a minute for the grid plant)."""

_EPILOG = """\
examples:
  lugrip simulate-rubbing --plant grid-stribeck --maneuvers 160 --seed 0 --out rub_i
  lugrip simulate-rubbing --plant grid-viscous --maneuvers 12 --out ci_set --force
  lugrip simulate-rubbing --plant patch --preset plastic_bottle --out patch_set
  lugrip simulate-rubbing --plant drake --maneuvers 60 --out drake_set   # pip install "lugrip[drake]"

The directory receives log.parquet (or log.csv with --format csv: the sensor wrench, the true
omega and the maneuver ids, docs/sliding_log.md), labels.npz (phase 0 approach / 1 presliding
/ 2 gross sliding / 3 loaded rest, load_ratio, c_tilde_true, v_true per sample) and
truth.json (what is true in the plant: mu, beta_A, delta, gamma, tau_max points, design).
Read it back with lugrip.rigs.RubbingData.load(DIR).
"""


def _count(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"invalid value {text!r}: expected an integer") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"invalid value {text!r}: must be >= 1")
    if value > MAX_MANEUVERS:
        raise argparse.ArgumentTypeError(
            f"invalid value {text!r}: at most {MAX_MANEUVERS} maneuvers per run "
            "(run several seeds instead)")
    return value


def register(subparsers) -> None:
    from ..rigs.registry import PLANTS

    plants = "\n".join(textwrap.fill(v, 78, initial_indent=f"  {k:15s}",
                                      subsequent_indent=" " * 17)
                        for k, v in PLANTS.items())
    p = subparsers.add_parser(
        "simulate-rubbing",
        help="rubbing data with ground truth from a prescribed-motion plant (grid, patch, "
             "lumped, MuJoCo, Drake)",
        description=textwrap.fill(
            "Rub a fingertip against a fixed slider with prescribed motion, as a robot would: "
            "press, turn about a CoR fixed in the finger frame (c~ from 0.05 to 20 contact "
            "radii, |omega| up to 2 rad/s, some maneuvers reversing once or twice), stop and "
            "rest while still pressed. The sensor reads the wrench the slider exerts on the "
            "fingertip with noise and per-maneuver offsets.") + "\n\nplants:\n" + plants,
        epilog=_EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--plant", required=True, choices=tuple(PLANTS), metavar="NAME",
                   help="plant: " + ", ".join(PLANTS))
    p.add_argument("--out", type=Path, required=True, metavar="DIR",
                   help="output directory (created; must not hold a previous run unless --force)")
    p.add_argument("--maneuvers", type=_count, default=160, metavar="N",
                   help=f"number of maneuvers, 1-{MAX_MANEUVERS} (default 160)")
    p.add_argument("--seed", type=int, default=0, help="random seed of the design (default 0)")
    p.add_argument("--preset", metavar="NAME", default=None,
                   help="contact preset of the lumped and patch plants (default aluminium_can)")
    p.add_argument("--format", choices=("parquet", "csv"), default=None,
                   help="log format (default parquet when pyarrow is installed, else csv)")
    p.add_argument("--force", action="store_true", help="overwrite a previous run in --out")
    p.set_defaults(run=run)


def run(args) -> int:
    from ..rigs import RubbingDesign
    from ..rigs.registry import make_rig

    out = Path(args.out)
    if not out.parent.exists():
        raise CliError(f"argument --out: directory {out.parent} does not exist")
    check_dir(out, "--out", force=args.force,
              results=("log.parquet", "log.csv", "labels.npz", "truth.json"))
    params = None
    if args.preset is not None:
        if args.plant not in ("lumped", "patch"):
            raise CliError(f"argument --preset: applies only to --plant lumped or patch, "
                           f"not {args.plant}")
        from .simulate_sliding import load_params

        params = load_params(args)
    try:
        rig = make_rig(args.plant, params=params)
    except ImportError as err:
        raise CliError(f"--plant {args.plant}: {err}") from None
    t0 = time.perf_counter()
    data = rig.simulate(RubbingDesign(), args.maneuvers, args.seed)
    seconds = time.perf_counter() - t0
    data.save(out, overwrite=bool(args.force), format=args.format)
    ph = data.phase
    n = len(data)
    tr = data.truth
    print(f"wrote {out}: {args.plant}, {args.maneuvers} maneuvers, {n} samples "
          f"({data.log.t[-1]:.1f} s at {RubbingDesign().sample_rate:g} Hz) in "
          f"{seconds:.1f} s")
    print("phases: " + ", ".join(f"{name} {100.0 * (ph == k).mean():.1f} %"
                                 for k, name in enumerate(("approach", "presliding",
                                                           "sliding", "rest"))))
    beta = "none" if tr.beta_a is None else f"{tr.beta_a:.3g} N s/m^3"
    print(f"truth: mu_s {tr.mu_static:g}, mu_k {tr.mu_kinetic:g}, beta_A {beta}, "
          f"rho = {tr.delta:.4g} f_n^{tr.gamma:.4g} m, tau_max(2 N) {tr.tau_max(2.0):.4g} N m, "
          f"tau_max(8 N) {tr.tau_max(8.0):.4g} N m, speed observable: "
          f"{'yes' if tr.viscous else 'no'}")
    return 0
