"""``lugrip replay``: run a recorded two-finger grasp through SlipControl and compare the grasp
force it would have commanded with the command recorded in the log."""

from __future__ import annotations

import argparse
import math
import textwrap
from pathlib import Path

from . import CliError, positive_float
from ._log_options import add_log_options, log_kwargs
from ._output import check_file, is_same_file
from .observe import _atomic_write
from .simulate_sliding import add_params_arguments, load_params

__all__ = ["OUTPUT_COLUMNS", "register", "run"]

OUTPUT_COLUMNS = ("t", "command_recorded", "command_replay", "status", "mode", "held",
                  "S_0", "S_1", "omega_hat_0", "omega_hat_1", "c_tilde_0", "c_tilde_1",
                  "mu_belief", "reserve_force", "reserve_torque")
"""Columns of the replay file: t [s], the recorded command [N] (empty without one), the
replayed command [N], the cycle's status name, the controller mode, held (1 when the command
was held because a finger's status was not ok, else 0), per finger k the
slippage indicator S_k [-], the estimated sliding velocity omega_hat_k [rad/s] and the
estimated CoR c_tilde_k [-], then the controller's friction belief mu_belief [-] and the
reserve of its last command per finger (stated or learned from the pushes seen,
reserve_force [N], reserve_torque [N m])."""

_EPILOG = """\
examples:
  lugrip replay grasp.csv --params fingertip.yaml --out replay.csv --plot out/
  lugrip replay grasp.bag --params fingertip.yaml --out replay.csv \\
      --finger-topics /left/wrench /right/wrench --command-topic /gripper/command
  lugrip replay grasp.mcap --preset big_resin_block --out replay.csv --f-min 0.5 --f-max 15

LOG is a two-finger log (docs/sliding_log.md, "Two-finger logs"): a table with the columns of
each finger suffixed _0 and _1 and a `command` column, or a ROS recording with one
WrenchStamped topic per finger and a std_msgs/Float64 command topic. SlipControl (observers of
both fingers and the grasp-force controller, settings from the --params file's observer block
and the options below) runs over the recorded wrenches at the log's sample rate and writes,
per sample, the command it would have sent beside the recorded one.

This is an open-loop replay: the recorded wrenches are what the recorded commands produced,
the gripper never received the replayed ones. Where the two commands part, the comparison
says what SlipControl would have asked for at that moment, not how the grasp would have gone.
Nothing is overwritten without --force.
"""


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "replay",
        help="run a recorded two-finger grasp through SlipControl; its command beside the "
             "recorded one",
        description=textwrap.fill(
            "Replay a two-finger log through SlipControl and write, per sample: "
            + ", ".join(OUTPUT_COLUMNS) + " (CSV). Prints how far the replayed command is "
            "from the recorded one; --plot draws both."),
        epilog=_EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("log", type=Path, metavar="LOG", help="two-finger log to replay")
    add_params_arguments(p, required=True)
    p.add_argument("--out", type=Path, required=True, metavar="FILE",
                   help="replayed command and observer outputs per sample (.csv)")
    p.add_argument("--plot", type=Path, metavar="DIR",
                   help="write DIR/replay_command.<format>: both commands, S, omega_hat")
    p.add_argument("--format", choices=("png", "pdf", "svg"), default="png",
                   help="figure format (default png)")
    c = p.add_argument_group("controller and observer settings (default: the library's; the "
                             "observer block of the --params file)")
    c.add_argument("--settings", type=Path, metavar="FILE",
                   help="YAML with a 'controller:' block (GraspController settings, "
                        "lugrip.controller_settings() names) and/or an 'observer:' block "
                        "(Observer keywords), e.g. a scenario file; the options below override it")
    c.add_argument("--torque-noise", type=float, metavar="STD",
                   help="torque noise std of the sensors [N m] (observer)")
    c.add_argument("--f-min", type=positive_float, metavar="N",
                   help="lowest grasp-force command [N]")
    c.add_argument("--f-max", type=positive_float, metavar="N",
                   help="highest grasp-force command [N]")
    c.add_argument("--initial-force", type=positive_float, metavar="N",
                   help="command SlipControl starts from [N] (default: the first recorded "
                        "command, else f_min)")
    t = p.add_argument_group("two-finger ROS recordings")
    t.add_argument("--finger-topics", nargs="+", metavar="TOPIC",
                   help="WrenchStamped topic of each finger, finger 0 first (one or two)")
    t.add_argument("--command-topic", metavar="TOPIC",
                   help="std_msgs/Float64 topic of the recorded grasp-force command [N]")
    add_log_options(p, wrench_topic=False, omega_topic=False, maneuvers=False, columns=False)
    p.add_argument("--force", action="store_true", help="overwrite existing output files")
    p.set_defaults(run=run)


def _read(args):
    from ..io import read_grasp_log

    if not Path(args.log).exists():
        raise CliError(f"{args.log}: no such file or directory")
    kw = log_kwargs(args)
    for unused in ("wrench_topic", "omega_topic", "maneuver_topic", "maneuvers", "columns"):
        kw.pop(unused)
    return read_grasp_log(args.log, finger_topics=args.finger_topics,
                          command_topic=args.command_topic, **kw)


def _settings_file(path: Path) -> tuple[dict, dict]:
    """(controller, observer) settings of a --settings YAML (read with the limits of
    lugrip._yaml.load_yaml, like every YAML file lugrip reads)."""
    from .._yaml import load_yaml

    if not path.is_file():
        raise CliError(f"argument --settings: {path}: no such file")
    try:
        data = load_yaml(path)
    except ValueError as err:
        raise CliError(f"argument --settings: {err}") from None
    if not isinstance(data, dict) or not ({"controller", "observer"} & set(data)):
        raise CliError(f"argument --settings: {path}: expected a mapping with a 'controller:' "
                       "and/or an 'observer:' block")
    blocks = []
    for key in ("controller", "observer"):
        block = data.get(key) or {}
        if not isinstance(block, dict):
            raise CliError(f"argument --settings: {path}: '{key}:' must be a mapping")
        blocks.append(dict(block))
    return blocks[0], blocks[1]


def _slip_control(args, dt: float, fingers: int):
    """SlipControl from --params (its observer block used, dt replaced by the log's) or
    --preset, with --settings and the options on top, at the log's sample rate."""
    from .. import SlipControl

    if args.params is not None:
        load_params(args, default=None)  # the checks and messages of observe
        params = str(args.params)
    else:
        params = load_params(args, default=None)
    controller, observer = ({}, {}) if args.settings is None else _settings_file(args.settings)
    observer["dt"] = dt
    if args.torque_noise is not None:
        observer["torque_noise"] = args.torque_noise
    controller["sensor_rate"] = 1.0 / dt
    if args.f_min is not None:
        controller["f_min"] = args.f_min
    if args.f_max is not None:
        controller["f_max"] = args.f_max
    try:
        return SlipControl(params, fingers=fingers, observer=observer, **controller)
    except (ValueError, TypeError) as err:
        raise CliError(str(err).replace("\n", "; ")) from None


def replay(glog, control, initial_force: float | None = None):
    """Run ``control`` (a :class:`lugrip.SlipControl`, its observer dt the log's median step)
    over the grasp log's wrenches: steps within 1e-6 of the median are nominal, others are
    passed as they are. It starts from ``initial_force`` (default: the first recorded command;
    without one, the controller's own start). Returns the run's per-sample outputs (a mapping
    of (n,) arrays, :class:`lugrip.SlipControlRun`)."""
    import numpy as np

    if initial_force is None and glog.command is not None:
        finite = np.flatnonzero(np.isfinite(glog.command))
        if finite.size:
            initial_force = float(glog.command[finite[0]])
    if initial_force is not None:
        control.reset(initial_force)
    step = np.diff(glog.t)
    nominal = float(np.median(step)) if step.size else 0.0
    dt = np.zeros(len(glog))  # 0: the nominal period (the observer's dt)
    dt[1:] = np.where(np.abs(step - nominal) <= 1e-6 * nominal, 0.0, step)
    return control.run(np.ascontiguousarray(glog.wrench), dt=dt)


def _write(path: Path, glog, out, names, force: bool) -> None:
    import numpy as np

    n = len(glog)
    fingers = glog.wrench.shape[1]
    rec = glog.command if glog.command is not None else np.full(n, np.nan)
    cols = {"t": glog.t, "command_recorded": rec, "command_replay": out["force"],
            "status": [names["status"].get(int(s), str(int(s))) for s in out["status"]],
            "mode": [names["mode"].get(int(m), str(int(m))) for m in out["mode"]],
            "held": np.asarray(out["held"], dtype=np.int64),
            "mu_belief": out["mu_belief"], "reserve_force": out["reserve_force"],
            "reserve_torque": out["reserve_torque"]}
    for k in range(2):
        for base in ("S", "omega_hat", "c_tilde"):
            key = f"{base}_{k}"
            cols[key] = out[key] if k < fingers else np.full(n, np.nan)

    def cell(v):
        if isinstance(v, float):
            return "" if math.isnan(v) else repr(v)
        return str(v)

    def body(fh):
        lists = {k: (v.tolist() if hasattr(v, "tolist") else list(v)) for k, v in cols.items()}
        lines = [",".join(OUTPUT_COLUMNS)]
        for i in range(n):
            lines.append(",".join(cell(lists[k][i]) for k in OUTPUT_COLUMNS))
        fh.write(("\n".join(lines) + "\n").encode())

    _atomic_write(path, force, body)


def summary(glog, out) -> list[str]:
    """Lines comparing the replayed command with the recorded one."""
    import numpy as np

    rep = np.asarray(out["force"], dtype=float)
    lines = [(f"replayed command: {rep.min():.4g}-{rep.max():.4g} N "
              f"(mean {rep.mean():.4g} N)")]
    held = np.asarray(out["held"], dtype=bool)
    if held.any():
        lines.append(f"{int(held.sum())} of {len(rep)} cycles held the command (a finger's "
                     "status not ok: no contact, invalid sample, ...)")
    if glog.command is None:
        lines.append("no recorded command in the log: nothing to compare with")
        return lines
    rec = np.asarray(glog.command, dtype=float)
    both = np.isfinite(rec)
    if not both.any():
        lines.append("the recorded command has no value: nothing to compare with")
        return lines
    d = rep[both] - rec[both]
    lines.append(f"recorded command: {rec[both].min():.4g}-{rec[both].max():.4g} N "
                 f"(mean {rec[both].mean():.4g} N)")
    lines.append(f"replay - recorded: mean {d.mean():+.4g} N, RMS {np.sqrt(np.mean(d * d)):.4g} "
                 f"N, max |.| {np.abs(d).max():.4g} N; replay lower by more than 1 uN on "
                 f"{100.0 * np.mean(d < -1e-6):.1f} % of the samples, higher on "
                 f"{100.0 * np.mean(d > 1e-6):.1f} %")
    return lines


def run(args) -> int:
    import numpy as np

    from .. import ControllerMode, Status

    out_path = Path(args.out)
    if out_path.suffix.lower() != ".csv":
        raise CliError(f"argument --out: {out_path}: unknown suffix {out_path.suffix!r}; "
                       "use .csv")
    inputs = [args.log, getattr(args, "params", None), getattr(args, "settings", None)]
    check_file(out_path, "--out", force=args.force, inputs=inputs)
    fig_path = None
    if args.plot is not None:
        from ..plot.replay import REPLAY_NAME

        if args.plot.exists() and not args.plot.is_dir():
            raise CliError(f"argument --plot: {args.plot} exists and is not a directory")
        fig_path = args.plot / f"{REPLAY_NAME}.{args.format}"
        check_file(fig_path, "--plot", force=args.force, inputs=inputs, create_parent=True)
        if is_same_file(fig_path, out_path):
            raise CliError(f"argument --plot: {fig_path} is also the --out file")
    glog = _read(args)
    if len(glog) < 2:
        raise CliError(f"{args.log}: a replay needs at least two samples")
    dt = float(np.median(np.diff(glog.t)))
    fingers = glog.wrench.shape[1]
    if not (math.isfinite(dt) and dt > 0.0):
        raise CliError(f"{args.log}: no usable sample period (median step {dt!r} s)")
    control = _slip_control(args, dt, fingers)
    out = replay(glog, control, args.initial_force)
    names = {"status": {int(s): s.name.lower() for s in Status},
             "mode": {int(m): m.name.lower() for m in ControllerMode}}
    _write(out_path, glog, out, names, args.force)
    print(f"{args.log}: {len(glog)} samples, {fingers} finger(s), "
          f"{glog.t[-1] - glog.t[0]:.4g} s at {1.0 / dt:.4g} Hz; wrote {out_path}")
    for line in summary(glog, out):
        print("  " + line)
    if fig_path is not None:
        from ..plot.replay import write_figure_replay

        S = np.stack([out[f"S_{k}"] for k in range(fingers)], axis=1)
        w = np.stack([out[f"omega_hat_{k}"] for k in range(fingers)], axis=1)
        path = write_figure_replay(
            args.plot, glog.t, out["force"], glog.command, S, w, fmt=args.format,
            held=np.asarray(out["held"], dtype=bool), mu_belief=out["mu_belief"],
            reserve_force=out["reserve_force"],
            title=f"{Path(args.log).name}: SlipControl replay")
        print(f"  wrote {path}")
    return 0
