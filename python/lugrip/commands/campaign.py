"""``lugrip campaign``: randomized grasp campaigns on a local process pool or Ray, streamed to
Parquet (a rerun with the same --out resumes), with a report; ``lugrip campaign replay DIR
--run ID`` reruns one grasp alone with its figures; ``lugrip campaign report DIR`` rewrites
the report of what DIR holds.

Exit code 0 when the runs are done (failed grasps are results, not errors), 2 on a user error
(bad campaign file: one line naming the field).
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path

from . import CliError

__all__ = ["register", "run"]

_EPILOG = """\
examples:
  lugrip campaign campaigns/patch_blocks.yaml --runs 100 --workers 2 --out out/patch_blocks
  lugrip campaign campaigns/patch_blocks.yaml --runs 1000 --workers 2 --out out/patch_blocks
      (the same --out: the 100 runs above are kept, runs 100..999 are added)
  lugrip campaign campaigns/mujoco_blocks.yaml --runs 200 --backend ray --ray-address auto \\
      --out out/mujoco_blocks
  lugrip campaign replay out/patch_blocks --run 17 --controller lugrip
  lugrip campaign report out/patch_blocks
  lugrip campaign campaigns/everyday_patch.yaml --runs 20 --workers 1 --out out/everyday_tuning
  lugrip campaign campaigns/everyday_patch.yaml --evaluation --runs 500 --out out/everyday_eval
      (the evaluation set: drawn with the file's evaluation_seed; run once, after tuning)
Ray: pip install 'lugrip[cluster]'; without --ray-address a local Ray instance with --workers
CPUs is started. The same campaign and run index give the same results on either backend and
any number of workers. Results: DIR/results.parquet (one row per run and controller: p_* drawn
parameters, m_* metrics, pass_* criteria, success, seeds, set, min_static_force, crush_force,
frontier_*), DIR/campaign.json (with the set: tuning or evaluation), DIR/report.md,
report.json, failure_map.png, frontier.png.
campaign file options beyond scenario, plant, seed, controllers, criteria and parameters
(docs/campaigns.md):
  evaluation_seed: N   the evaluation set's seed (--evaluation draws with it)
  frontier: true       per run, the smallest constant force that passes (bisection up to the
                       crush force or f_max); the report draws the constant-force frontier
                       (success rate of every constant) with each controller as a point
  gripper: {f_max: ..} the gripper's range on top of the base scenario's controller block
  crush_factor         (parameter) crush force = factor x the run's minimum static force
                       (true contact, hanging load at S = 1); criterion no_crush: the command
                       never exceeds it
  push_count, push_phase, push_weight_fraction, push_twist_fraction, push_edge
                       (parameters) 1-N trapezoid pushes per run, each drawn on its own,
                       sized by the object's weight and gravity torque, at random phases
                       of the 50 Hz command period (twist_lever: the torque's smallest lever)
"""


def _positive_int(text: str) -> int:
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"invalid value {text!r}: expected an integer") from None
    if v < 1:
        raise argparse.ArgumentTypeError(f"invalid value {text!r}: must be >= 1")
    return v


MAX_RUNS = 1_000_000
"""Most runs one campaign command accepts (checked before any list of runs is built; a
million runs is days of computing on a cluster)."""


def _run_count(text: str) -> int:
    """--runs: an integer 1..MAX_RUNS (refused before any work: '1e9' and 10**9 alike)."""
    t = text.strip()
    if len(t) > 20:
        raise argparse.ArgumentTypeError(f"invalid value of {len(t)} characters: expected an "
                                         f"integer 1..{MAX_RUNS}")
    try:
        v = int(t)
    except ValueError:
        try:
            f = float(t)
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"invalid value {t!r}: expected an integer") from None
        if not (f.is_integer() and 1 <= f <= MAX_RUNS):
            raise argparse.ArgumentTypeError(
                f"invalid value {t!r}: expected an integer 1..{MAX_RUNS}") from None
        v = int(f)
    if not 1 <= v <= MAX_RUNS:
        raise argparse.ArgumentTypeError(f"invalid value {t!r}: expected an integer "
                                         f"1..{MAX_RUNS}")
    return v


#: The report files of a campaign folder (rewritten when the folder is resumed).
REPORT_FILES = ("report.md", "report.json", "failure_map.png", "frontier.png")
#: Stored runs: only a folder holding this campaign's campaign.json resumes from them.
RESULT_FILES = ("results.parquet", "parts")


def check_campaign_out(out: Path, campaign, force: bool, inputs=()) -> bool:
    """The output policy for a campaign folder, before any run. A folder that holds this
    campaign (its campaign.json, same fingerprint) is resumed: its report is rewritten. Any
    other folder that holds report files is refused without --force, and one holding runs
    without a campaign.json (or a campaign.json that cannot be read) is refused always.
    Returns True when the folder is resumed."""
    import json

    from ._output import OutputError, check_dir

    meta = out / "campaign.json"
    if meta.is_file():
        try:
            doc = json.loads(meta.read_text(encoding="utf-8"))
            fp = doc.get("fingerprint") if isinstance(doc, dict) else None
        except (ValueError, OSError) as err:
            raise OutputError(f"argument --out: {meta}: not a readable campaign.json "
                              f"({type(err).__name__}); use a new --out") from None
        if fp == campaign.fingerprint():
            check_dir(out, "--out", force=True, results=REPORT_FILES, inputs=inputs)
            return True
        name = doc.get("name") if isinstance(doc, dict) else None
        raise OutputError(f"argument --out: {out} holds results of another campaign definition "
                          f"({meta}: name {name!s:.60}, fingerprint {fp!s:.20}); use a new "
                          "--out")
    stray = [n for n in RESULT_FILES if os.path.lexists(out / n)]
    if stray:
        raise OutputError(f"argument --out: {out} holds {', '.join(stray)} but no campaign.json: "
                          "not a campaign folder lugrip can resume; use a new --out")
    check_dir(out, "--out", force=force, results=REPORT_FILES, inputs=inputs)
    return False


def _index(text: str) -> int:
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"invalid value {text!r}: expected an integer") from None
    if v < 0:
        raise argparse.ArgumentTypeError(f"invalid value {text!r}: must be >= 0")
    return v


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "campaign",
        help="randomized grasp campaigns (process pool or Ray), resumable, with a report",
        description=(
            "Run runs 0..N-1 of a campaign file (distributions over object, contact, pushes, "
            "sensors and controller-plant mismatch; controllers to compare; master seed), "
            "stream the results to DIR and write the report. 'replay DIR --run ID' reruns one "
            "grasp with its figures; 'report DIR' rewrites the report."
        ),
        epilog=_EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("target", nargs="+", metavar="CONFIG",
                   help="campaign YAML file, or 'replay DIR', or 'report DIR'")
    p.add_argument("--runs", type=_run_count, metavar="N",
                   help=f"number of runs (0..N-1; at most {MAX_RUNS})")
    p.add_argument("--workers", type=_positive_int, default=None, metavar="W",
                   help="parallel workers (default: the CPUs this process may use)")
    p.add_argument("--backend", choices=("process", "ray"), default="process",
                   help="local process pool (default) or Ray")
    p.add_argument("--ray-address", default=None, metavar="ADDR",
                   help="Ray cluster address ('auto' or host:port); default: a local instance")
    p.add_argument("--out", type=Path, metavar="DIR", help="results directory")
    p.add_argument("--evaluation", action="store_true",
                   help="draw the evaluation set (the campaign's evaluation_seed) instead of "
                   "the tuning set (seed)")
    p.add_argument("--run", dest="run_id", type=_index, metavar="ID", help="replay: the run index")
    p.add_argument("--controller", action="append", default=None, metavar="NAME",
                   help="replay: only this controller (repeatable; default: all)")
    p.add_argument("--no-report", action="store_true", help="do not write the report")
    p.add_argument("--no-figures", action="store_true", help="report/replay without figures")
    p.add_argument("--quiet", action="store_true", help="no progress line")
    p.add_argument("--force", action="store_true",
                   help="overwrite report files (report.md, report.json, failure_map.png, frontier.png) in an "
                        "--out folder that is not this campaign's; replay: earlier replay files")
    p.set_defaults(run=run)


def _run_campaign(args) -> int:
    from ..campaign import load_campaign, run_campaign, write_report

    if len(args.target) != 1:
        raise CliError(f"expected one campaign file, got {' '.join(args.target)}")
    if args.runs is None:
        raise CliError("--runs N is required")
    if args.out is None:
        raise CliError("--out DIR is required")
    if args.run_id is not None or args.controller:
        raise CliError("--run and --controller belong to 'lugrip campaign replay DIR'")
    if args.ray_address and args.backend != "ray":
        raise CliError("--ray-address needs --backend ray")
    campaign = load_campaign(args.target[0])
    if args.evaluation:
        campaign = campaign.for_set("evaluation")
    check_campaign_out(args.out, campaign, args.force, inputs=[args.target[0]])
    affinity = getattr(os, "sched_getaffinity", None)  # Linux; elsewhere every CPU
    workers = args.workers or max(len(affinity(0)) if affinity else (os.cpu_count() or 1), 1)
    info = run_campaign(
        campaign,
        args.runs,
        args.out,
        workers=workers,
        backend=args.backend,
        ray_address=args.ray_address,
        progress=not args.quiet,
    )
    rate = info["runs_per_s"]
    print(
        f"{campaign.name} ({campaign.result_set} set, seed {campaign.draw_seed}): "
        f"{info['ran']} runs done, {info['skipped']} already in {args.out}"
        + (f" ({rate:.2f} runs/s on {workers} {args.backend} worker(s))" if info["ran"] else "")
    )
    if not args.no_report:
        paths = write_report(args.out, campaign, figures=not args.no_figures)
        import json

        data = json.loads(paths["json"].read_text())
        for c, s in data["summary"].items():
            lo, hi = s["wilson95"]
            print(f"  {c}: {s['successes']}/{s['runs']} held ({100 * s['success_rate']:.1f} %, "
                  f"95 % interval {100 * lo:.1f}-{100 * hi:.1f} %), mean force "
                  f"{s['mean_force'] if s['mean_force'] is not None else float('nan'):.2f} N")
        fr = data.get("frontier")
        if fr:
            at = f" at {fr['max_force']:.2f} N" if fr["max_force"] is not None else ""
            print(f"  constant-force frontier: best {fr['max_successes']}/{fr['runs']} "
                  f"({100 * fr['max_rate']:.1f} %){at}")
            for c, pt in fr["controllers"].items():
                if pt["constant_same_mean_force"] is not None:
                    print(f"    constant of {c}'s mean force: "
                          f"{100 * pt['constant_same_mean_force']:.1f} %")
        print(f"report: {paths['markdown']}")
    return 0


def check_replay_out(out: Path, index: int, force: bool) -> None:
    """The output policy for the files a campaign replay writes (replay_<ID>.json and its
    figures): refused without --force when they exist."""
    from ._output import check_dir

    check_dir(Path(out), "--out", force=force,
              results=(f"replay_{index}.json", f"replay_{index}_*.png"))


def run(args) -> int:
    head = args.target[0]
    if head in ("replay", "report") and not Path(head).is_file():
        if len(args.target) != 2:
            raise CliError(f"usage: lugrip campaign {head} DIR" + (" --run ID" if head == "replay" else ""))
        directory = Path(args.target[1])
        from ..campaign import load_results_campaign, write_report
        from ..campaign.replay import replay_command

        if head == "report":
            campaign = load_results_campaign(directory)
            paths = write_report(directory, campaign, figures=not args.no_figures)
            print(f"report: {paths['markdown']}")
            return 0
        if args.run_id is None:
            raise CliError("replay needs --run ID")
        campaign = load_results_campaign(directory)
        unknown = [c for c in args.controller or () if c not in campaign.controllers]
        if unknown:
            raise CliError(f"--controller {', '.join(unknown)}: not in the campaign "
                           f"({', '.join(campaign.controllers)})")
        check_replay_out(directory if args.out is None else args.out, args.run_id, args.force)
        return replay_command(directory, args.run_id, controllers=args.controller, out=args.out,
                              figures=not args.no_figures)
    return _run_campaign(args)

