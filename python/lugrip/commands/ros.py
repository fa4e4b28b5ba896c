"""``lugrip ros``: lugrip on ROS 2 (the ``[ros]`` extra): ``run`` starts the controller node,
``sim`` runs a scenario on the MuJoCo gripper node against it, ``record`` writes topics to an
MCAP file the log readers take (docs/ros.md)."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from . import CliError

__all__ = ["register", "run"]

_EPILOG = """\
examples:
  lugrip ros run fit.yaml                      # identified YAML: contact model and observer
  lugrip ros run ros_params.yaml               # a ROS parameter file (node name: lugrip)
  lugrip ros run fit.yaml --ros-args -p controller.f_max:=15.0 -r fingertip_0/wrench:=/left/ft
  lugrip ros sim exp3_plastic_bottle_pivot     # in a second shell: the MuJoCo gripper
  lugrip ros record run1 --topics /fingertip_0/wrench /truth/pose   # -> run1/run1.mcap
The node is configured and activated at start (--no-autostart: left unconfigured for a
lifecycle manager). `lugrip ros sim` exits 0 when the scenario's MuJoCo criteria pass, 1 when
one fails.
"""


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "ros",
        help="ROS 2 nodes: the slip controller (run), a MuJoCo gripper to test it (sim), a "
             "recorder to MCAP (record)",
        description="lugrip on ROS 2 (needs the [ros] extra: pip install \"lugrip[ros]\").",
        epilog=_EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    sub = p.add_subparsers(dest="ros_command", metavar="<ros command>", required=True)
    r = sub.add_parser("run", help="start the lugrip lifecycle node")
    r.add_argument("params", nargs="?", type=Path, default=None, metavar="PARAMS.yaml",
                   help="a `lugrip identify` YAML (contact model and observer) or a ROS "
                        "parameter file (with ros__parameters)")
    r.add_argument("--name", default="lugrip", help="node name (default: lugrip)")
    r.add_argument("--no-autostart", action="store_true",
                   help="do not configure and activate at start")
    r.add_argument("--ros-args", dest="ros_args", nargs=argparse.REMAINDER, default=None,
                   metavar="ARG", help="the rest of the line goes to rclpy (remappings -r a:=b, "
                   "parameters -p name:=value, --params-file F)")
    s = sub.add_parser("sim", help="a scenario on the MuJoCo gripper node, closed over ROS 2")
    s.add_argument("scenario", help="scenario name or YAML (e.g. exp1_big_resin_block)")
    s.add_argument("--controller", default="lugrip", help="the controller node's name")
    s.add_argument("--full", action="store_true", help="the full scenario, not its short form")
    s.add_argument("--real-time", action="store_true",
                   help="pace the samples at the wall clock instead of lock-step")
    s.add_argument("--timeout", type=float, default=30.0,
                   help="seconds to wait for the controller node (default 30)")
    s.add_argument("--json", type=Path, default=None, metavar="FILE",
                   help="write the metrics and criteria here")
    s.add_argument("--csv", type=Path, default=None, metavar="FILE",
                   help="write the run's columns here")
    s.add_argument("--force", action="store_true", help="overwrite --json / --csv")
    c = sub.add_parser("record", help="topics to an MCAP file lugrip identify/replay read")
    c.add_argument("out", type=Path, metavar="OUT",
                   help="new rosbag2 directory; the file to read is OUT/OUT.mcap")
    c.add_argument("--topics", nargs="+", metavar="TOPIC",
                   default=["/fingertip_0/wrench", "/fingertip_1/wrench", "/lugrip/command",
                            "/lugrip/joint_command"],
                   help="topics to record (default: the node's wrench inputs and commands)")
    c.add_argument("--duration", type=float, default=None, metavar="S",
                   help="stop after S seconds (default: at Ctrl-C or SIGTERM)")
    c.add_argument("--ros-args", dest="ros_args", nargs=argparse.REMAINDER, default=None,
                   metavar="ARG", help="the rest of the line goes to rclpy")
    s.add_argument("--ros-args", dest="ros_args", nargs=argparse.REMAINDER, default=None,
                   metavar="ARG", help="the rest of the line goes to rclpy")
    p.set_defaults(run=run)


def _ros_parameter_file(path: Path) -> bool:
    """A ROS parameter file (node -> ros__parameters) rather than a lugrip YAML."""
    from .._yaml import load_yaml

    data = load_yaml(path)
    return isinstance(data, dict) and any(
        isinstance(v, dict) and "ros__parameters" in v for v in data.values())


def _init_args(args) -> list[str]:
    if args.ros_args is None:
        return ["lugrip"]
    return ["lugrip", "--ros-args", *args.ros_args]


def run(args) -> int:
    from ..ros import available, missing_message

    if not available():
        raise CliError(missing_message())
    if args.ros_command == "run":
        return _run_node(args)
    if args.ros_command == "record":
        return _run_record(args)
    return _run_sim(args)


def _run_record(args) -> int:
    import rclpy

    from ..ros.record import mcap_file, record

    if args.out.exists():
        raise CliError(f"{args.out}: exists (a new directory is written)")
    rclpy.init(args=_init_args(args))
    import signal

    # SIGTERM is how a recording is normally ended: stop spinning, close the file, report
    signal.signal(signal.SIGTERM, lambda signum, frame: rclpy.try_shutdown())
    try:
        counts = record(args.out, args.topics, args.duration)
    finally:
        rclpy.try_shutdown()
    for topic in args.topics:
        print(f"{topic}: {counts.get(topic if topic.startswith('/') else '/' + topic, 0)} messages")
    print(f"wrote {mcap_file(args.out)}")
    return 0


def _run_node(args) -> int:
    from ..ros.node import main

    init = _init_args(args)
    params_file = None
    if args.params is not None:
        if not args.params.is_file():
            raise CliError(f"{args.params}: no such file")
        if _ros_parameter_file(args.params):
            if "--ros-args" not in init:
                init.append("--ros-args")
            init += ["--params-file", str(args.params)]
        else:
            from .._params import ContactParams

            ContactParams.from_yaml(args.params)  # a readable parameter file, or exit 2
            params_file = str(args.params)
    return main(init, params_file=params_file, node_name=args.name,
                autostart=not args.no_autostart)


def _run_sim(args) -> int:
    import rclpy

    from ..ros.sim import RosTimeout, run_ros_scenario
    from ._output import atomic_write, atomic_write_text, check_file

    for what, path in (("--json", args.json), ("--csv", args.csv)):
        if path is not None:  # the output policy, before the run
            check_file(path, what, force=args.force)
    rclpy.init(args=_init_args(args))
    try:
        result = run_ros_scenario(args.scenario, controller=args.controller,
                                  short=not args.full, lockstep=not args.real_time,
                                  timeout=args.timeout)
    except RosTimeout as err:
        raise CliError(str(err)) from None
    finally:
        rclpy.try_shutdown()
    crit = result["criteria"]
    failed = [k for k, c in crit.items() if c["pass"] is False]
    for k, c in crit.items():
        flag = {True: "pass", False: "FAIL", None: "n/a (needs the baselines)"}[c["pass"]]
        print(f"{k}: {c['value']} ({flag})")
    lat = sorted(result["latencies"])
    if lat:
        print(f"lock-step round trip to a command: median {1e3 * lat[len(lat) // 2]:.2f} ms, "
              f"max {1e3 * lat[-1]:.2f} ms over {len(lat)} commands")
    if result["timeouts"]:
        print(f"{result['timeouts']} sample(s) without an answer from the controller")
    if args.json is not None:
        from ..sim.report import _jsonable

        doc = {"scenario": result["scenario"].name, "criteria": crit,
               "metrics": result["metrics"], "timeouts": result["timeouts"]}
        atomic_write_text(args.json, json.dumps(_jsonable(doc), indent=1), "--json",
                          force=args.force)
    if args.csv is not None:
        import numpy as np

        run = result["run"]
        names = list(run)
        table = np.column_stack([np.asarray(run[n], dtype=float) for n in names])
        atomic_write(args.csv, lambda fh: np.savetxt(fh, table, delimiter=",",
                                                     header=",".join(names), comments=""),
                     "--csv", force=args.force)
    print(f"{result['scenario'].name} over ROS 2: {'FAIL' if failed else 'pass'}",
          file=sys.stderr if failed else sys.stdout)
    return 1 if failed or result["timeouts"] else 0
