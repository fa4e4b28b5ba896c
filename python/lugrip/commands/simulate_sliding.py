"""``lugrip simulate-sliding``: synthetic sliding logs like the paper's Section 4 (Fig. 4):
many maneuvers of a slider pushed past the limit surface at 1-10 N, from rotation- to
translation-dominated CoRs, plant = the slider model with known parameters, sensor noise
(:mod:`lugrip.sliding`)."""

from __future__ import annotations

import argparse
import math
import textwrap
from pathlib import Path

from . import CliError, positive_float
from ._output import check_file

__all__ = ["load_params", "register", "run"]

_EPILOG = """\
examples:
  lugrip simulate-sliding --out data.csv                      # Table 1, 240 maneuvers, seed 0
  lugrip simulate-sliding --out can.parquet --preset aluminium_can --maneuvers 100 --seed 3
  lugrip simulate-sliding --out noisy.mcap --params p.yaml --noise-force 0.1 --noise-torque 2e-3

The log holds t, f_n, f_x, f_y, tau (the wrench the object exerts on the fingertip, SI units),
the ground truth omega and the maneuver id; the format follows the suffix (.csv, .parquet, .mcap).
Replay it with `lugrip observe LOG --preset NAME --out est.csv`.
"""


MAX_SAMPLES = 4_000_000
"""Most samples one simulated log may need in the worst case (measured peak memory: about 240
bytes per sample, and a maneuver's mean length is under half its worst case)."""


def _non_negative(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"invalid value {text!r}: expected a number") from None
    if not (value >= 0.0 and value < float("inf")):
        raise argparse.ArgumentTypeError(f"invalid value {text!r}: must be finite and >= 0")
    return value


def _count(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"invalid value {text!r}: expected an integer") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"invalid value {text!r}: must be >= 1")
    return value


def add_params_arguments(p: argparse.ArgumentParser, *, required: bool = False) -> None:
    """--params FILE | --preset NAME (shared with ``lugrip observe``)."""
    g = p.add_mutually_exclusive_group(required=required)
    g.add_argument(
        "--params",
        type=Path,
        metavar="FILE",
        help="contact parameters as YAML (`lugrip params --preset table1 > p.yaml`)",
    )
    g.add_argument(
        "--preset",
        metavar="NAME",
        help="parameter preset: table1, big_resin_block, small_resin_block, "
        "plastic_bottle, aluminium_can" + ("" if required else " (default: table1)"),
    )


def load_params(args, default: str | None = "table1"):
    """ContactParams from --params / --preset (``default`` when neither is given)."""
    from .. import PRESETS, ContactParams

    if getattr(args, "params", None) is not None:
        path = Path(args.params)
        if not path.exists():
            raise CliError(f"argument --params: {path}: no such file")
        try:
            return ContactParams.from_yaml(path)
        except (ValueError, TypeError, KeyError) as err:
            raise CliError(f"argument --params: {err}") from None
    name = getattr(args, "preset", None) or default
    if name is None:
        raise CliError("give the contact parameters with --params FILE or --preset NAME")
    key = name.lower().replace("-", "_")
    if key == "aluminum_can":
        key = "aluminium_can"
    if key not in PRESETS:
        raise CliError(f"argument --preset: unknown preset {name!r}; known: {', '.join(PRESETS)}")
    return ContactParams.preset(key)


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "simulate-sliding",
        help="write a synthetic sliding log (paper Section 4 maneuvers) with ground truth",
        description=textwrap.fill(
            "Simulate sliding maneuvers like the paper's Section 4: a planar slider (eqs. 1-2, "
            "inertia J) about a fixed CoR, pushed with a torque that ramps up past the limit "
            "surface, holds and ramps down (and some maneuvers that stay inside it), f_n "
            "uniform in 1-10 N, |c~| log-spread from rotation- (0.02) to translation-dominated "
            "(2 c_max). The sensor reads the wrench the object exerts on the fingertip plus "
            "white noise. Peak speeds are tenths of rad/s (see lugrip.sliding for the design)."
        ),
        epilog=_EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "--out",
        type=Path,
        required=True,
        metavar="FILE",
        help="output log (.csv, .parquet or .mcap)",
    )
    add_params_arguments(p)
    p.add_argument(
        "--maneuvers",
        type=_count,
        default=240,
        metavar="N",
        help="number of maneuvers (default 240)",
    )
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    p.add_argument(
        "--noise-force",
        type=_non_negative,
        default=0.005,
        metavar="STD",
        help="white noise std on f_n, f_x, f_y [N] (default 0.005)",
    )
    p.add_argument(
        "--noise-torque",
        type=_non_negative,
        default=1e-5,
        metavar="STD",
        help="white noise std on tau [N m] (default 1e-5)",
    )
    p.add_argument(
        "--f-n-range",
        type=positive_float,
        nargs=2,
        default=(1.0, 10.0),
        metavar=("LO", "HI"),
        help="normal force range [N] (default 1 10)",
    )
    p.add_argument(
        "--stick-fraction",
        type=_non_negative,
        default=0.15,
        metavar="F",
        help="fraction of maneuvers that stay inside the limit surface (default 0.15)",
    )
    p.add_argument(
        "--dt", type=positive_float, default=0.002, help="sample period [s] (default 0.002, 500 Hz)"
    )
    p.add_argument(
        "--inertia",
        type=positive_float,
        default=1e-4,
        metavar="J",
        help="slider inertia about the CoR [kg m^2] (default 1e-4)",
    )
    p.add_argument("--force", action="store_true", help="overwrite an existing --out file")
    p.set_defaults(run=run)


def run(args) -> int:
    from .. import write_log
    from ..sim.sliding import REGIMES, simulate_maneuvers

    out = Path(args.out)
    if out.suffix.lower() not in (".csv", ".parquet", ".pq", ".mcap"):
        raise CliError(
            f"argument --out: {out}: unknown suffix {out.suffix!r}; use .csv, .parquet or .mcap"
        )
    check_file(out, "--out", force=args.force, inputs=[getattr(args, "params", None)])
    if args.stick_fraction > 1.0:
        raise CliError(f"argument --stick-fraction: {args.stick_fraction:g} must be <= 1")
    if args.f_n_range[1] < args.f_n_range[0]:
        raise CliError("argument --f-n-range: HI must be >= LO")
    # worst-case length of one maneuver: two rests, the longest ramp, hold and release
    longest = 2 * 0.2 + 1.0 + 2.0 + 0.4  # [s] simulate_maneuvers' default ranges
    worst = args.maneuvers * math.ceil(longest / args.dt)
    if worst > MAX_SAMPLES:
        raise CliError(
            f"argument --maneuvers: {args.maneuvers} maneuvers at dt = {args.dt:g} s may need "
            f"up to {worst:.3g} samples, more than the {MAX_SAMPLES:.0e} one log may hold "
            f"(about {MAX_SAMPLES * 120 // 2**20} MiB); write several logs with different --seed"
        )
    params = load_params(args)
    data = simulate_maneuvers(
        params,
        args.maneuvers,
        seed=args.seed,
        f_n_range=tuple(args.f_n_range),
        stick_fraction=args.stick_fraction,
        noise=(args.noise_force, args.noise_torque),
        dt=args.dt,
        J=args.inertia,
    )
    write_log(data.log, out, overwrite=bool(args.force))
    log = data.log
    counts = {r: 0 for r in REGIMES}
    n_stick = 0
    for m in data.maneuvers:
        if m.kind == "stick":
            n_stick += 1
        else:
            counts[m.regime] += 1
    import numpy as np

    rms = float(np.sqrt(np.mean(log.omega**2)))
    print(
        f"wrote {out}: {len(log)} samples, {len(data.maneuvers)} maneuvers, "
        f"{log.t[-1] + args.dt:.1f} s at {1 / args.dt:g} Hz"
    )
    print(
        "  sliding maneuvers by |c~|: "
        + ", ".join(f"{r} {c}" for r, c in counts.items())
        + f"; stick maneuvers {n_stick}"
    )
    print(
        f"  f_n {args.f_n_range[0]:g}-{args.f_n_range[1]:g} N, peak |omega| "
        f"{np.max(np.abs(log.omega)):.3g} rad/s, RMS omega {rms:.3g} rad/s, noise "
        f"{args.noise_force:g} N / {args.noise_torque:g} N m"
    )
    return 0
