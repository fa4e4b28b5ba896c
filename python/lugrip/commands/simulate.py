"""``lugrip simulate``: run the paper's experiments and the unseen objects (scenario YAML files)
in closed loop with the baselines on the patch, lumped or MuJoCo plant; write the figures, a
Markdown report and the metrics JSON, print a summary.

Exit code 0 when every scenario passes its criteria, 1 when one fails, 2 on a user error.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

from ..sim.plant import builds_scene, plant_names, plant_renders
from . import CliError

__all__ = ["register", "run"]

_EPILOG = """\
scenarios: YAML paths, or names looked up in the first scenario directory of: $LUGRIP_SCENARIOS,
./scenarios (when it holds YAML files), the scenarios installed with lugrip (lugrip/data/
scenarios; 'lugrip simulate --list' prints the one in use), and in its unseen/ and faults/
folders; 'all' runs the paper's experiments, 'unseen' the objects the controller was not tuned
on, 'faults' the injected sensor/actuator faults. A scenario's plant.contact and estimator may
name a parameter file (fit.yaml from 'lugrip identify'), found next to the scenario file.
Scenarios without a paper figure get a time-series figure <name>.png.
examples:
  lugrip simulate all --out out/                        # the four experiments + baselines
  lugrip simulate exp2_small_resin_block --json m.json  # one scenario
  lugrip simulate all --short --plant lumped --no-baselines
  lugrip simulate box_heavy --plant mujoco --video out/box.mp4
  lugrip simulate all unseen --plant mujoco --seeds 8 --compare patch
  lugrip simulate all unseen --plant drake --no-plots   # Drake (pip install "lugrip[drake]")
  lugrip simulate exp2_small_resin_block --plant drake --compare mujoco --compare patch
  lugrip simulate scenarios/faults/*.yaml --no-plots     # sensor and actuator faults
  lugrip simulate --list
An engine plant (mujoco, drake): writes DIR/<plant>.md, DIR/<plant>_<scenario>.png (MuJoCo:
frames of the lift and the pivot when offscreen rendering works: MUJOCO_GL=egl or osmesa) and
the metrics JSON (default DIR/<plant>_metrics.json). Without OpenGL the frames and the video are
skipped with a message.
"""


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "simulate",
        help=(
            "closed-loop simulation of the paper's experiments (Figures 11, 13, 15, 17) and "
            "unseen objects, on the patch, lumped or MuJoCo plant"
        ),
        description=(
            "Simulate scenarios in closed loop (plant -> fingertip sensors -> observers -> "
            "grasp-force controller, 500 Hz / 50 Hz), with the constant-force and friction-cone "
            "baselines; write the paper's figures, a Markdown report (experiments.md; an "
            "engine plant: <plant>.md) and the metrics JSON with a pass flag per criterion."
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
    from ..sim.plant import plant_names

    p.add_argument(
        "--plant",
        choices=plant_names(),
        default=None,
        help="plant model: " + ", ".join(plant_names()) + " (default: the scenario's, patch)",
    )
    p.add_argument(
        "--video",
        type=Path,
        default=None,
        metavar="FILE.mp4",
        help="MuJoCo plant: MP4 of lugrip's run (several scenarios: FILE_<name>.mp4)",
    )
    p.add_argument(
        "--seeds",
        type=int,
        default=1,
        metavar="N",
        help="an engine plant (mujoco, drake): also run lugrip on N - 1 further noise seeds "
        "(default 1)",
    )
    p.add_argument(
        "--compare",
        action="append",
        choices=plant_names(),
        default=None,
        help="an engine plant: run this plant too and put it beside the engine (repeatable)",
    )
    p.add_argument(
        "--no-frames", action="store_true", help="MuJoCo plant: no rendered frames in the figures"
    )
    p.add_argument("--force", action="store_true",
                   help="overwrite the result files of an earlier run in --out (experiments.md, "
                        "metrics.json, <plant>.md, figures) and an existing --json/--video file")
    p.add_argument("--no-baselines", action="store_true", help="only lugrip's controller")
    p.add_argument("--no-plots", action="store_true", help="skip the figures")
    p.add_argument("--list", action="store_true", help="list the available scenarios and exit")
    p.add_argument("--campaign", type=Path, default=None, metavar="DIR",
                   help="replay one run of the campaign results in DIR (with --run ID; figures "
                   "to --out), as 'lugrip campaign replay DIR --run ID'")
    p.add_argument("--run", dest="campaign_run", type=int, default=None, metavar="ID",
                   help="with --campaign: the run index")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    if args.campaign is not None or args.campaign_run is not None:
        if args.campaign is None or args.campaign_run is None or args.campaign_run < 0:
            raise CliError("--campaign DIR and --run ID (>= 0) go together")
        from ..campaign.replay import replay_command
        from .campaign import check_replay_out

        check_replay_out(args.out, args.campaign_run, args.force)
        return replay_command(args.campaign, args.campaign_run, out=args.out,
                              figures=not args.no_plots)
    from ..sim import report

    engine = builds_scene(args.plant or "patch")
    if engine and plant_renders(args.plant) and (args.video or not args.no_frames):
        report.choose_gl_backend()  # before anything imports MuJoCo
    from ..sim.scenarios import find_scenario, list_scenarios, load_scenario, scenario_dir

    if args.list:
        names = list_scenarios()
        if not names:
            raise CliError(
                "no scenarios found (run from the repository root or set LUGRIP_SCENARIOS)"
            )
        for name in names + list_scenarios(suite="unseen") + list_scenarios(suite="faults"):
            s = load_scenario(name)
            print(f"{name:32s} {s.suite:7s} {s.title}")
        print(f"(from {scenario_dir()})", file=sys.stderr)
        return 0
    names = []
    for n in args.scenarios:
        names += (
            list_scenarios()
            if n == "all"
            else list_scenarios(suite=n)
            if n in ("unseen", "faults")
            else [n]
        )
    if not names:
        raise CliError("no scenario given (names, YAML files, 'all' or 'unseen'; see --list)")
    try:
        paths = [str(find_scenario(n)) for n in names]
        if engine:  # the engine's scene of each file, checked before anything runs
            from ..sim.plant import make_plant

            for p in paths:
                s = load_scenario(p).for_plant(args.plant)
                make_plant(args.plant).reset(s, config=s.plant_config(args.plant))
    except ValueError as err:
        raise CliError(str(err)) from None
    if not engine and (args.video or args.compare or args.seeds != 1 or args.no_frames):
        scenes = ", ".join(p for p in plant_names() if builds_scene(p))
        raise CliError("--video, --seeds, --compare and --no-frames need a plant that builds "
                       f"its own scene (--plant {scenes})")
    if args.compare and args.plant in args.compare:
        raise CliError(f"--compare {args.plant}: the plant itself")
    if args.seeds < 1:
        raise CliError(f"--seeds {args.seeds}: must be >= 1")
    if args.video is not None and args.video.suffix.lower() != ".mp4":
        raise CliError(f"--video {args.video}: expected a .mp4 file")
    check_outputs(args, paths)
    if engine:
        return _run_engine(args, paths)

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
    no_window = []
    for r in results:
        m = r.metrics["lugrip"]
        steady = m.get("steady_force")
        if steady is None or not math.isfinite(steady):
            no_window.append(r.name)
            steady_text = "steady      —  "  # the scenario measures no steady force
        else:
            steady_text = f"steady {steady:6.3f} N"
        print(
            f"{r.name:32s} {'pass' if r.passed else 'FAIL'}  {steady_text}"
            f"  hold slip {m['hold_slip_mm']:.3f} mm  hold rot {m['hold_rotation_deg']:.3f} deg"
            f"  dropped {'yes' if m['dropped'] else 'no'}",
            flush=True,
        )
        if "fault_onset" in m:
            lat, slip_force = m["fault_status_latency"], m["fault_min_force"]
            if lat is not None:
                latency = f"status latency {lat} samples"
            elif m.get("fault_expect_status"):
                latency = f"status latency — (never raised {', '.join(m['fault_expect_status'])})"
            else:
                latency = "status latency — (no status reveals this fault)"
            slip = "—, no load before the onset" if slip_force is None else f"{slip_force:.3f} N"
            print(
                f"    fault {', '.join(m['fault_kinds'])}: {latency}, min command "
                f"{m['fault_min_command']:.3f} N (slip force {slip})",
                flush=True,
            )
        for name, c in r.criteria.items():
            if c["pass"] is False:
                print(f"    failed: {name} (value {c['value']}, limit {c['limit']})")
    if no_window:
        which = ("these scenarios have" if len(no_window) == len(results)
                 else f"{', '.join(no_window)} {'has' if len(no_window) == 1 else 'have'}")
        print(f"steady —: {which} no steady_window, so no steady force is measured (the hold's "
              "slip and rotation are)", flush=True)
    for name, path in written.items():
        print(f"wrote {path}", file=sys.stderr)
    return 0 if all(r.passed for r in results) else 1


#: The result files ``simulate`` writes in --out (names and patterns): a folder holding any
#: of them is refused without --force.
RESULT_FILES = ("experiments.md", "metrics.json", "fig1[1357]_*.png", "*_baselines.png",
                *(f"{p}{x}" for p in plant_names() if builds_scene(p)
                  for x in (".md", "_metrics.json", "_*.png")))


def check_outputs(args: argparse.Namespace, scenario_paths: list[str]) -> None:
    """The output policy (commands/_output.py) for --out DIR, --json and --video, before any
    scenario runs; the scenario files are inputs."""
    from ._output import check_dir, check_file

    if args.no_plots and not builds_scene(args.plant or "patch"):  # only the metrics file is written
        if args.json is None:
            check_dir(args.out, "--out", force=args.force, results=("metrics.json",),
                      inputs=scenario_paths)
    else:  # and the time series of the scenarios without a paper figure, <name>.png
        own = tuple(f"{Path(p).stem}.png" for p in scenario_paths)
        check_dir(args.out, "--out", force=args.force, results=RESULT_FILES + own,
                  inputs=scenario_paths)
    if args.json is not None:
        check_file(args.json, "--json", force=args.force, inputs=scenario_paths,
                   create_parent=True)
    if args.video is not None:
        check_file(args.video, "--video", force=args.force, inputs=scenario_paths,
                   create_parent=True)


def _run_engine(args: argparse.Namespace, paths: list[str]) -> int:
    from ..sim import report
    from ..sim.mujoco.render import RenderUnavailable, video_writer_available

    video = args.video
    if video is not None and not video_writer_available():
        print(
            "lugrip simulate: no video: writing MP4 needs imageio-ffmpeg "
            '(pip install "lugrip[video]")',
            file=sys.stderr,
        )
        video = None
    try:
        data = report.run_mujoco_set(
            paths,
            args.out,
            seeds=args.seeds,
            compare=tuple(args.compare or ()),
            short=args.short,
            frames=not args.no_frames,
            video=video,
            baselines=not args.no_baselines,
            log=lambda s: print(s, file=sys.stderr, flush=True),
            engine=args.plant,
            plots=not args.no_plots,
        )
    except RenderUnavailable as err:  # raised only for the video writer; frames degrade
        raise CliError(str(err)) from None
    if data["render"]:
        print(f"lugrip simulate: no frames or video: {data['render']}", file=sys.stderr)
    written = report.write_mujoco_outputs(data, args.out, json_path=args.json)
    for name, r in data["results"].items():
        m = r.metrics["lugrip"]
        seeds = data["seeds"][name]
        print(
            f"{name:32s} {args.plant} {'pass' if r.passed else 'FAIL'}  scene {m.get('scene_status')}"
            f"  mean force {m.get('mean_force', float('nan')):6.3f} N"
            f"  hold slip {m['hold_slip_mm']:.3f} mm  hold rot {m['hold_rotation_deg']:.3f} deg"
            f"  dropped {'yes' if m['dropped'] else 'no'}  seeds {sum(x['pass'] for x in seeds)}/{len(seeds)}",
            flush=True,
        )
        for cname, c in r.criteria.items():
            if c["pass"] is False:
                print(f"    failed: {cname} (value {c['value']}, limit {c['limit']})")
    for path in [*written.values(), *data["videos"].values()]:
        print(f"wrote {path}", file=sys.stderr)
    ok = all(r.passed for r in data["results"].values()) and all(
        x["pass"] for rows in data["seeds"].values() for x in rows
    )
    return 0 if ok else 1
