"""``lugrip simulate``: run the paper's experiments (scenario YAML files) in closed loop with the
baselines, write Figures 11/13/15/17, a Markdown report and metrics.json, print a summary.

Exit code 0 when every scenario passes its criteria, 1 when one fails, 2 on a user error.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from . import CliError

__all__ = ["register", "run"]

_EPILOG = """\
scenarios: names in ./scenarios (or $LUGRIP_SCENARIOS) or YAML paths; 'all' runs every file.
examples:
  lugrip simulate all --out out/                        # the four experiments + baselines
  lugrip simulate exp2_small_resin_block --json m.json  # one scenario
  lugrip simulate all --short --plant lumped --no-baselines
  lugrip simulate --list
"""


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "simulate",
        help="closed-loop simulation of the paper's experiments (Figures 11, 13, 15, 17)",
        description=(
            "Simulate scenarios in closed loop (plant -> fingertip sensors -> observers -> "
            "grasp-force controller, 500 Hz / 50 Hz), with the constant-force and friction-cone "
            "baselines; write the paper's figures, a Markdown report (experiments.md) and "
            "metrics.json with a pass flag per criterion."
        ),
        epilog=_EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "scenarios",
        nargs="*",
        metavar="SCENARIO",
        help="scenario names or YAML files ('all': every scenario)",
    )
    p.add_argument(
        "--out",
        type=Path,
        default=Path("out"),
        metavar="DIR",
        help="directory for figures and experiments.md (default: out)",
    )
    p.add_argument(
        "--json",
        type=Path,
        default=None,
        metavar="FILE",
        help="metrics file (default: DIR/metrics.json)",
    )
    p.add_argument(
        "--short",
        action="store_true",
        help="CI mode: the scenarios' short overrides and a 5 %% constant-force search",
    )
    p.add_argument(
        "--plant",
        choices=("patch", "lumped"),
        default=None,
        help="plant model (default: the scenario's, patch)",
    )
    p.add_argument("--no-baselines", action="store_true", help="only lugrip's controller")
    p.add_argument("--no-plots", action="store_true", help="skip the figures")
    p.add_argument("--list", action="store_true", help="list the available scenarios and exit")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from ..sim import report
    from ..sim.scenarios import find_scenario, list_scenarios, load_scenario

    if args.list:
        names = list_scenarios()
        if not names:
            raise CliError(
                "no scenarios found (run from the repository root or set LUGRIP_SCENARIOS)"
            )
        for name in names:
            s = load_scenario(name)
            print(f"{name:32s} {s.title}")
        return 0
    names = list(args.scenarios)
    if not names:
        raise CliError("no scenario given (names, YAML files or 'all'; see --list)")
    if "all" in names:
        names = list_scenarios()
    try:
        paths = [str(find_scenario(n)) for n in names]
    except ValueError as err:
        raise CliError(str(err)) from None

    results = report.run_all(
        paths,
        plant_model=args.plant,
        short=args.short,
        baselines=not args.no_baselines,
        log=lambda s: print(s, file=sys.stderr, flush=True),
    )
    if args.no_plots:
        out = report.write_json(results, args.json if args.json else args.out / "metrics.json")
        written = {"metrics.json": out}
    else:
        _, written = report.write_outputs(results, args.out, json_path=args.json)
    for r in results:
        m = r.metrics["lugrip"]
        print(
            f"{r.name:32s} {'pass' if r.passed else 'FAIL'}  steady {m.get('steady_force', float('nan')):6.3f} N"
            f"  hold slip {m['hold_slip_mm']:.3f} mm  hold rot {m['hold_rotation_deg']:.3f} deg"
            f"  dropped {'yes' if m['dropped'] else 'no'}",
            flush=True,
        )
        for name, c in r.criteria.items():
            if c["pass"] is False:
                print(f"    failed: {name} (value {c['value']}, limit {c['limit']})")
    for name, path in written.items():
        print(f"wrote {path}", file=sys.stderr)
    return 0 if all(r.passed for r in results) else 1
