"""``lugrip observe``: replay a sliding log through the sliding-velocity observer (paper eqs.
21-23) and write the estimates per sample; with ground truth, print the RMSE of omega_hat and
the slip-detection figures; optionally draw the paper's Figure 5 for the replay."""

from __future__ import annotations

import argparse
import io
import math
import sys
import textwrap
import time
import types
from pathlib import Path

from . import CliError, observer_options, positive_float
from ._log_options import add_log_options, read_log_from_args
from ._output import atomic_write, check_file, is_same_file
from .simulate_sliding import add_params_arguments, load_params

__all__ = ["OUTPUT_COLUMNS", "demo_section", "register", "replay", "run", "write_estimates"]

OUTPUT_COLUMNS = (
    "t",
    "omega_hat",
    "z_hat",
    "c_tilde",
    "S",
    "status",
    "speed_observable",
    "maneuver",
    "c_tilde_unclipped",
    "omega_object",
    "v_slip",
)
"""Columns of the estimate file: t [s], omega_hat [rad/s], z_hat [rad], c_tilde [-], S [-],
status (ok, saturated, degenerate, no_contact, invalid_sample, sensor_fault, reinitialized),
speed_observable (1 when the slip speed is resolvable through viscous friction, else 0),
maneuver (the log's id), c_tilde_unclipped [-] (the CoR before the clip at c_max),
omega_object [rad/s] (the slip about that unclipped CoR; omega_hat is about the clipped one and
is what the grasp controller uses), v_slip [m/s] (slip speed of the patch centre)."""

_EPILOG = """\
examples:
  lugrip simulate-sliding --out data.csv
  lugrip observe data.csv --preset table1 --out est.csv --plot out/
  lugrip observe run.parquet --params fingertip.yaml --out est.parquet
  lugrip observe run.parquet --params p.yaml --out est.parquet --integrator rk4 --gain 200
  lugrip observe run.bag --preset aluminium_can --out est.csv --wrench-topic /ft --flip-normal
  lugrip observe run.mcap --preset table1 --out est.csv --maneuvers motion --units tau=N_mm

LOG is a sliding log (.csv, .parquet, .mcap, ROS 1 .bag or a ROS 2 bag directory; see
docs/sliding_log.md): the wrench the object exerts on the fingertip. The observer restarts
where the maneuver id changes (ids from the file, --maneuver-topic, --maneuvers motion or
time windows). With an `omega` column (ground truth) the RMSE of omega_hat
(overall and per CoR regime) and the slip detection (delay from |omega| > --omega-threshold to
S >= --s-threshold, false alarms) are printed. Nothing is overwritten without --force.
A --params file written by 'lugrip identify' carries an 'observer' block (the observer the
parameters were identified with); it is used unless an option below overrides a setting.
"""

_INTEGRATORS = ("rosenbrock", "implicit", "rk4", "rk4_adaptive")


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "observe",
        help="replay a sliding log through the velocity observer; RMSE and Figure 5",
        description=textwrap.fill(
            "Run the sliding-velocity observer (paper eqs. 21-23, CoR estimate, slippage "
            "indicator S) over a sliding log and write per sample: "
            + ", ".join(OUTPUT_COLUMNS)
            + ". The output format follows the --out suffix "
            "(.csv or .parquet)."
        ),
        epilog=_EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("log", type=Path, metavar="LOG", help="sliding log to replay")
    add_params_arguments(p, required=True)
    p.add_argument(
        "--out",
        type=Path,
        required=True,
        metavar="FILE",
        help="estimates per sample (.csv or .parquet)",
    )
    p.add_argument(
        "--plot",
        type=Path,
        metavar="DIR",
        help="write the Figure-5-style plot DIR/fig05_observer.<format>",
    )
    p.add_argument(
        "--format", choices=("png", "pdf", "svg"), default="png", help="figure format (default png)"
    )
    o = p.add_argument_group(
        "observer settings (default: the observer block of the --params file, written by "
        "'lugrip identify', else the library defaults; these options override single settings)"
    )
    o.add_argument(
        "--integrator",
        choices=_INTEGRATORS,
        default=None,
        help="discretisation (default rosenbrock; rk4 = the paper's one step per sample)",
    )
    gain = o.add_mutually_exclusive_group()
    gain.add_argument(
        "--gain", type=positive_float, metavar="L", help="fixed observer gain l [1/(kg m^2)]"
    )
    gain.add_argument(
        "--bandwidth",
        type=positive_float,
        metavar="B",
        help="gain l = B / sigma_1 per sample [1/s] (the default mode)",
    )
    o.add_argument(
        "--torque-noise",
        type=float,
        metavar="STD",
        help="torque noise std of the sensor [N m] (CoR sign hysteresis, speed resolution)",
    )
    o.add_argument(
        "--torque-cutoff",
        type=float,
        metavar="HZ",
        help="low-pass cutoff of the torque used for the CoR [Hz] (0: off)",
    )
    s = p.add_argument_group("scoring (when the log has omega)")
    s.add_argument(
        "--omega-threshold",
        type=positive_float,
        default=0.01,
        metavar="W",
        help="|omega| above which the truth slides [rad/s] (default 0.01)",
    )
    s.add_argument(
        "--s-threshold",
        type=positive_float,
        default=0.9,
        metavar="S",
        help="S at or above which the observer signals slip (default 0.9)",
    )
    add_log_options(p)
    p.add_argument("--force", action="store_true", help="overwrite existing output files")
    p.set_defaults(run=run)


def _check_target(path: Path, what: str, force: bool, inputs=()) -> None:
    """The output policy (commands/_output.py) for one output file."""
    check_file(path, what, force=force, inputs=inputs)


def _atomic_write(path: Path, force: bool, body, what: str = "--out") -> None:
    """Write through a temporary file next to ``path``; rename into place when complete."""
    atomic_write(path, body, what, force=force)


#: Samples per piece of a replay: the observer runs and the estimates are written piece by
#: piece, so that only the outputs the scores read are held over the whole log.
CHUNK_ROWS = 1 << 17


def _columns(t, maneuver, run) -> dict:
    """The :data:`OUTPUT_COLUMNS` of one piece of a run."""
    import numpy as np

    from .. import Status

    names = {int(s): s.name.lower() for s in Status}
    return {
        "t": np.asarray(t, dtype=float),
        "omega_hat": run.omega_hat,
        "z_hat": run.z_hat,
        "c_tilde": run.c_tilde,
        "S": run.S,
        "status": [names.get(int(v), str(int(v))) for v in run.status],
        "speed_observable": np.asarray(run.speed_observable, dtype=np.int64),
        "maneuver": np.asarray(maneuver, dtype=np.int64),
        "c_tilde_unclipped": run.c_tilde_unclipped,
        "omega_object": run.omega_object,
        "v_slip": run.v_slip,
    }


def _csv_text(cols: dict) -> bytes:
    """CSV lines of one piece; every float reads back exactly (pyarrow's writer, the shortest
    text that round-trips; without pyarrow Python's repr)."""
    try:
        import pyarrow as pa
        import pyarrow.csv as pacsv
    except ImportError:
        pa = None
    if pa is not None:
        sink = io.BytesIO()
        pacsv.write_csv(pa.table({k: cols[k] for k in OUTPUT_COLUMNS}), sink,
                        write_options=pacsv.WriteOptions(include_header=False,
                                                         quoting_style="none"))
        pa.default_memory_pool().release_unused()
        return sink.getvalue()
    lists = {k: (cols[k].tolist() if k != "status" else cols[k]) for k in OUTPUT_COLUMNS}
    lines = [
        ",".join(repr(v) if isinstance(v, float) else str(v) for v in row)
        for row in zip(*(lists[k] for k in OUTPUT_COLUMNS))
    ]
    return ("\n".join(lines) + "\n").encode() if lines else b""


class _ScoredRun:
    """The observer outputs :func:`lugrip.sliding.score` reads, over the whole log (the other
    outputs are written piece by piece and not kept)."""

    def __init__(self, omega_hat, S, c_tilde, valid, diverged):
        self.omega_hat, self.S, self.c_tilde = omega_hat, S, c_tilde
        self.valid, self.diverged = valid, diverged

    def __len__(self) -> int:
        return len(self.omega_hat)


class Replay:
    """What a replay keeps: counts over the whole log, the clipped-CoR comparison with the
    ground truth, and the run (``keep='all'``), the scored outputs (``'score'``, filled piece
    by piece into arrays over the whole log) or nothing."""

    _SCORED = ("omega_hat", "S", "c_tilde", "valid", "diverged")

    def __init__(self, keep: str, n: int):
        import numpy as np

        self.keep = keep
        self.n = self.valid = self.diverged = 0
        self.seconds = 0.0  # in the observer
        self.clip = [0, 0.0, 0.0, 0.0]  # samples; squared errors of omega_hat, omega_object, 0
        self.parts: list = []
        self.run = None
        self._scored = None
        if keep == "score":
            self._scored = {k: np.empty(n, dtype=bool if k in ("valid", "diverged") else float)
                            for k in self._SCORED}

    def add(self, run, omega) -> None:
        import numpy as np

        valid = run.valid
        a, b = self.n, self.n + len(run)
        self.n = b
        self.valid += int(valid.sum())
        self.diverged += int(np.sum(run.diverged))
        if omega is not None:
            m = valid & run.saturated & np.isfinite(omega)
            if m.any():
                w = omega[m]
                self.clip[0] += int(m.sum())
                self.clip[1] += float(np.sum((run.omega_hat[m] - w) ** 2))
                self.clip[2] += float(np.sum((run.omega_object[m] - w) ** 2))
                self.clip[3] += float(np.sum(w**2))
        if self.keep == "all":
            self.parts.append(run)
        elif self._scored is not None:
            for k in self._SCORED:
                self._scored[k][a:b] = valid if k == "valid" else getattr(run, k)

    def finish(self, t) -> None:
        import numpy as np

        from .._observer import ObserverRun

        if self.keep == "all" and self.parts:
            fields = {k: np.concatenate([getattr(p, k) for p in self.parts])
                      for k in self.parts[0].to_dict() if k != "t"}
            self.run = ObserverRun(t=np.asarray(t, dtype=float), **fields)
        elif self._scored is not None:
            self.run = _ScoredRun(*(self._scored[k] for k in self._SCORED))
        self.parts, self._scored = [], None

    def beyond_clip_line(self) -> str | None:
        """One line comparing omega_hat and omega_object with the ground truth where the CoR
        was clipped (None when no valid sample was)."""
        k, e_hat, e_obj, e_zero = self.clip
        if not k:
            return None
        return (
            f"CoR clipped at c_max on {k} samples: RMSE omega_hat {math.sqrt(e_hat / k):.4g}, "
            f"omega_object {math.sqrt(e_obj / k):.4g}, predicting zero "
            f"{math.sqrt(e_zero / k):.4g} rad/s"
        )


def replay(observer, log, path: Path | None, *, force: bool = False, keep: str = "all",
           chunk: int | None = None) -> Replay:
    """Run ``observer`` over ``log`` piece by piece (``chunk`` samples; the outputs equal one
    run over the whole log: the state carries over, the observer restarts where the maneuver
    changes) and write the :data:`OUTPUT_COLUMNS` of each piece to ``path`` (CSV or Parquet by
    suffix, atomically, an existing file replaced only with ``force``; None: not written).
    ``chunk``: default :data:`CHUNK_ROWS`."""
    import numpy as np

    chunk = CHUNK_ROWS if chunk is None else int(chunk)
    if chunk < 1:
        raise ValueError(f"chunk = {chunk!r}: must be >= 1")
    t = np.asarray(log.t, dtype=float)
    man = np.asarray(log.maneuver)
    omega = None if log.omega is None else np.asarray(log.omega, dtype=float)
    result = Replay(keep, len(t))

    def pieces():
        for a in range(0, len(t), chunk):
            b = min(a + chunk, len(t))
            fresh = a == 0 or man[a] != man[a - 1]
            piece = {"t": t[a:b], "f_n": log.f_n[a:b], "f_t": log.f_t[a:b],
                     "tau": log.tau[a:b], "maneuver": man[a:b]}
            t0 = time.perf_counter()
            run = observer.run(piece, reset=fresh, t_before=None if fresh else t[a - 1])
            result.seconds += time.perf_counter() - t0
            result.add(run, None if omega is None else omega[a:b])
            yield _columns(t[a:b], man[a:b], run)

    if path is None:
        for _ in pieces():
            pass
    else:
        _write_pieces(Path(path), pieces(), force)
    result.finish(t)
    return result


def _write_pieces(path: Path, pieces, force: bool) -> None:
    suffix = path.suffix.lower()
    if suffix == ".csv":

        def body(fh):
            fh.write((",".join(OUTPUT_COLUMNS) + "\n").encode())
            for cols in pieces:
                fh.write(_csv_text(cols))
    elif suffix in (".parquet", ".pq"):
        from ..io import MissingExtraError, need

        try:
            pa = need("pyarrow", "writing Parquet")
            pq = need("pyarrow.parquet", "writing Parquet")
        except MissingExtraError as exc:
            raise CliError(str(exc)) from None

        def body(fh):
            writer = None
            for cols in pieces:
                table = pa.table({k: cols[k] for k in OUTPUT_COLUMNS})
                if writer is None:
                    writer = pq.ParquetWriter(fh, table.schema)
                writer.write_table(table)
            if writer is not None:
                writer.close()
    else:
        raise CliError(
            f"argument --out: {path}: unknown suffix {path.suffix!r}; use .csv or .parquet"
        )
    _atomic_write(path, force, body)


def write_estimates(path: Path, log, run, *, force: bool = False) -> Path:
    """Write the :data:`OUTPUT_COLUMNS` of an observer run as CSV or Parquet (by suffix),
    atomically, refusing to replace an existing file unless ``force``."""
    import numpy as np

    path = Path(path)
    t = run.t if run.t is not None else np.asarray(log.t)
    _write_pieces(path, iter([_columns(t, log.maneuver, run)]), force)
    return path


def observer_block(args) -> dict | None:
    """The ``observer:`` block of the --params file (settings the parameters were identified
    with), or None (no --params, or a file without the block such as objects/*.yaml)."""
    from .._observer import read_observer_settings

    if getattr(args, "params", None) is None:
        return None
    try:
        return read_observer_settings(args.params)
    except ValueError as err:
        raise CliError(f"argument --params: {err}") from None


def _observer(params, args, dt: float, block: dict | None = None):
    from .. import Observer

    kwargs = observer_options(block, args)
    if args.torque_noise is not None:
        kwargs["torque_noise"] = args.torque_noise
    if args.torque_cutoff is not None:
        kwargs["torque_cutoff"] = args.torque_cutoff
    if not (math.isfinite(dt) and dt > 0.0):
        dt = 0.002
    try:
        return Observer(params, dt=dt, **kwargs)
    except ValueError as err:
        raise CliError(str(err).replace("\n", "; ")) from None


def run(args) -> int:
    import numpy as np

    from ..sim.sliding import score

    out = Path(args.out)
    if out.suffix.lower() not in (".csv", ".parquet", ".pq"):
        raise CliError(
            f"argument --out: {out}: unknown suffix {out.suffix!r}; use .csv or .parquet"
        )
    inputs = [args.log, getattr(args, "params", None)]
    _check_target(out, "--out", args.force, inputs)
    fig_path = None
    if args.plot is not None:
        from ..plot.observer import FIG5_NAME

        if args.plot.exists() and not args.plot.is_dir():
            raise CliError(f"argument --plot: {args.plot} exists and is not a directory")
        fig_path = args.plot / f"{FIG5_NAME}.{args.format}"
        check_file(fig_path, "--plot", force=args.force, inputs=inputs, create_parent=True)
        if is_same_file(fig_path, out):
            raise CliError(f"argument --plot: {fig_path} is also the --out file")
    params = load_params(args, default=None)
    block = observer_block(args)
    log = read_log_from_args(args.log, args)
    if len(log) == 0:
        raise CliError(f"{args.log}: the log holds no samples")
    log = log._without_force_vector()  # the replay reads f_t: two columns fewer in memory
    dt = log.sample_period if len(log) > 1 else 0.002
    observer = _observer(params, args, dt, block)
    n_man = len(np.unique(log.maneuver))  # before the replay keeps its outputs (memory)
    keep = "all" if fig_path is not None else ("score" if log.omega is not None else "none")
    rep = replay(observer, log, out, force=args.force, keep=keep)
    elapsed = rep.seconds
    est = rep.run
    st = observer.settings
    gain = (
        f"l = {st['bandwidth']:g}/sigma_1"
        if st["gain_mode"] == "bandwidth"
        else f"fixed l = {st['gain']:g}"
    )
    origin = f", settings from {args.params}" if block is not None else ""
    print(
        f"{args.log}: {len(log)} samples, {n_man} maneuver(s), observer "
        f"({st['integrator']}, {gain}{origin}) "
        f"{1e9 * elapsed / max(len(log), 1):.0f} ns/sample; wrote {out}"
    )
    if rep.valid < len(log):
        print(f"  {len(log) - rep.valid} samples without an estimate (no contact, invalid)")
    if rep.diverged:
        print(
            f"  the divergence guard re-initialised the observer on {rep.diverged} "
            "samples (try the default --integrator rosenbrock)"
        )
    sc = None
    if log.omega is not None:
        if fig_path is None:  # the scores read t, omega and the maneuvers: the forces can go
            log = types.SimpleNamespace(t=log.t, omega=log.omega, maneuver=log.maneuver,
                                        meta=log.meta)
        sc = score(log, est, omega_threshold=args.omega_threshold, s_threshold=args.s_threshold)
        for line in sc.lines():
            print("  " + line)
        line = rep.beyond_clip_line()
        if line:
            print("  " + line)
    else:
        candidates = log.meta.get("omega_candidates")
        where = ("name its topic with --omega-topic (a twist, or a pose to differentiate"
                 + (f"; this recording has: {', '.join(candidates)})" if candidates else ")")
                 if "wrench_topic" in log.meta else "add an 'omega' column (--columns "
                 "omega=NAME for another name)")
        print(f"  no ground-truth omega in the log: RMSE not computed; {where}")
    if fig_path is not None:
        from ..plot.observer import write_figure5

        args.plot.mkdir(parents=True, exist_ok=True)
        path = write_figure5(
            args.plot,
            log,
            est,
            fmt=args.format,
            title=f"{Path(args.log).name}: observer replay",
            rmse=None if sc is None else sc.rmse,
        )
        print(f"  wrote {path}")
    sys.stdout.flush()
    return 0


def demo_section(out_dir: Path) -> str:
    """Demo step "observer replay": 40 synthetic Table 1 maneuvers through the observer with
    the default settings, Figure 5 and the scores (Markdown)."""
    from .. import ContactParams, Observer
    from ..plot.observer import write_figure5
    from ..sim.sliding import score, simulate_maneuvers

    params = ContactParams.table1()
    data = simulate_maneuvers(params, 40, seed=5)
    est = Observer(params).run(data.log)
    sc = score(data, est)
    path = write_figure5(
        out_dir, data.log, est, title="Observer replay, Table 1, 40 maneuvers", rmse=sc.rmse
    )
    rel = path.relative_to(out_dir) if path.is_relative_to(out_dir) else path
    body = [
        (
            "Synthetic sliding maneuvers like the paper's Section 4 (`lugrip simulate-sliding`): a "
            "slider about a fixed CoR (|c~| 0.02-3, f_n 1-10 N) pushed past the limit surface with "
            "a torque ramp, plus maneuvers that stay inside it; the sensor reads the wrench the "
            "object exerts on the fingertip with white noise (0.005 N, 0.01 N mm). The observer "
            "(`lugrip observe`, default settings, true Table 1 parameters) estimates the sliding "
            "velocity from that wrench alone."
        ),
        "",
        f"![Figure 5: observer replay]({rel.as_posix()})",
        "",
        (
            "Figure 5 (after the paper's): ground truth omega (blue), estimate (vermilion), error "
            "(purple), zooms on single maneuvers; below, the slippage indicator S."
        ),
        "",
        "```",
        *sc.lines(),
        "```",
        "",
        "The paper reports an RMSE of 0.0222 rad/s on its 1342 real maneuvers.",
    ]
    return "\n".join(body) + "\n"
