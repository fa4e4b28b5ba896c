"""``lugrip identify``: contact parameters from sliding logs with ground-truth velocity (paper
Section 4, docs/model.md §8), or an object's mu and beta_A from a rubbing log (paper Section 6)."""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

from . import CliError, observer_options, positive_float
from ._log_options import add_log_options, read_log_from_args
from ._output import atomic_write_text, check_dir, check_file, is_same_file

__all__ = ["ProgressBar", "register", "run", "write_report"]

_EPILOG = """\
examples:
  lugrip identify logs/*.csv --out fingertip.yaml --report out/
  lugrip identify obj/*.parquet --free mu,beta_a --params0 fingertip.yaml --out object.yaml
  lugrip identify rub.csv --rubbing --params0 fingertip.yaml --out object.yaml

Without --params0 the parameters come from stages, each from what the data carry: the
phase of every sample (still, loading, gross sliding) from the wrench and the motion, the
sensor noise from the still samples, the limit surface (mu, delta, gamma, k) from the
gross-sliding wrench, beta_A from its speed dependence (not significant: "sliding speed not
observable", beta_A set so that the observer reports speed_observable = False), sigma0 and
sigma_z from the loading runs; then the paper's eq. 32 refines them, regularised toward the
stage values (--no-refine: stages only). A parameter at a bound is a failure: the YAML's
status says "failed" and the exit code is 3. User errors exit with 2 and one line.

The cost runs the online observer, and the parameters are identified FOR that observer
(docs/model.md §8): the output YAML records its settings in an 'observer' block (with the
measured torque noise), and 'lugrip observe --params' and 'lugrip identify --params0' use
that block (options override it). Every log needs an 'omega' column (ground truth, rad/s);
maneuvers come from the 'maneuver' column and are never integrated across a gap.
"""


def _exponent(text: str) -> float:
    if text.strip().lower() == "ellipse":
        return 0.0
    try:
        k = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number (inf allowed) or 'ellipse'") from None
    if not (k >= 0.5 or k == 0.0):
        raise argparse.ArgumentTypeError(
            f"{text!r}: the pressure exponent must be >= 0.5 (or 0 / 'ellipse')")
    return k


def _bootstrap_count(text: str) -> int:
    """argparse type for --bootstrap: a whole number of refits in [2, 10000]."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"invalid value {text!r}: expected a whole number") from None
    if not 2 <= value <= 10000:
        raise argparse.ArgumentTypeError(f"invalid value {text!r}: must be in [2, 10000]")
    return value


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "identify",
        help="identify contact parameters from sliding logs (stages from the data, then the "
        "observer's velocity error)",
        description=(
            "Identify the contact parameters (mu, beta_A, sigma0, sigma_z, delta, gamma and the "
            "pressure exponent k) from sliding logs with ground-truth velocity: stages from "
            "the data, then the online observer's velocity error (paper eqs. 32-33) as a "
            "regularised refinement; or with --rubbing an object's mu and beta_A from a "
            "rubbing log at known angular velocity."
        ),
        epilog=_EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "logs",
        nargs="+",
        type=Path,
        metavar="LOG",
        help="sliding logs (CSV, Parquet, MCAP, ROS bags) with an omega column",
    )
    p.add_argument(
        "--out",
        type=Path,
        required=True,
        metavar="YAML",
        help="write the identified parameters (value, unit, std. error, bounds); an existing "
        "file is only replaced with --force",
    )
    p.add_argument(
        "--free",
        default=None,
        metavar="NAMES",
        help="comma-separated parameters to identify (default: all six; the "
        "per-object step is mu,beta_a)",
    )
    p.add_argument(
        "--params0",
        type=Path,
        metavar="YAML",
        help="start point and values of the fixed parameters (default: computed "
        "from the data; required with --free)",
    )
    p.add_argument(
        "--start",
        choices=("data", "params0"),
        help="start from the data-computed guess or from --params0 (default: params0 when given)",
    )
    p.add_argument(
        "--report",
        type=Path,
        metavar="DIR",
        help="write the report: parameter table, Figure-5-style plot of the "
        "validation maneuvers, per-maneuver RMSE, cost trace",
    )
    p.add_argument(
        "--validation",
        type=float,
        default=0.2,
        metavar="FRACTION",
        help="fraction of maneuvers held out for validation (default 0.2)",
    )
    p.add_argument("--seed", type=int, default=0, help="seed of the validation split")
    p.add_argument("--loss", choices=("squared", "huber"), default="squared")
    p.add_argument(
        "--huber-scale",
        type=positive_float,
        default=0.05,
        metavar="RAD_S",
        help="Huber loss: residuals above this count linearly [rad/s]",
    )
    p.add_argument(
        "--weighting",
        choices=("maneuver", "sample"),
        default="maneuver",
        help="each maneuver weighs the same (default) or each sample",
    )
    p.add_argument(
        "--method",
        choices=("gauss-newton", "slsqp", "trust-constr"),
        default="gauss-newton",
        help="optimiser: SQP with the Gauss-Newton Hessian (default), scipy SLSQP or trust-constr",
    )
    p.add_argument("--max-iterations", type=int, default=200, metavar="N")
    p.add_argument(
        "--uncertainty",
        choices=("gauss-newton", "sandwich", "bootstrap"),
        default="sandwich",
        help="standard errors: sandwich (default, clustered by maneuver: robust to the "
        "autocorrelation within a maneuver), gauss-newton (independent residuals: optimistic) "
        "or bootstrap",
    )
    p.add_argument(
        "--no-refine",
        dest="refine",
        action="store_false",
        help="stop after the stages (no eq. 32 refinement)",
    )
    p.add_argument(
        "--k",
        type=_exponent,
        default=None,
        metavar="K",
        help="hold the pressure exponent at K (0.5 .. inf; 2 Hertzian; 0 or 'ellipse' the "
        "elliptic limit surface); default: identified (the pressure family and the ellipse "
        "are both fitted, the lower RMS distance is kept)",
    )
    p.add_argument(
        "--bootstrap", type=_bootstrap_count, default=20, metavar="N",
        help="refits for --uncertainty bootstrap (2 .. 10000)"
    )
    o = p.add_argument_group(
        "observer inside the cost (default: the observer block of --params0 when it has one, "
        "else the library defaults; written to the output YAML, which 'lugrip observe "
        "--params' then uses)"
    )
    gain = o.add_mutually_exclusive_group()
    gain.add_argument(
        "--bandwidth",
        type=positive_float,
        metavar="B",
        help="observer bandwidth l sigma_1 [1/s]",
    )
    gain.add_argument(
        "--gain",
        type=positive_float,
        metavar="L",
        help="fixed observer gain l [1/(kg m^2)]",
    )
    o.add_argument(
        "--integrator",
        choices=("rosenbrock", "implicit", "rk4", "rk4_adaptive"),
        default=None,
        help="observer integrator (default rosenbrock)",
    )
    p.add_argument(
        "--score-saturated",
        action="store_true",
        help="also score sliding samples where the observer clips the CoR at c_max (default: "
        "left out, omega_hat there is the slip about the clipped CoR, not the rotation)",
    )
    p.add_argument("--threads", type=int, default=0, help="C++ worker threads (0: all cores)")
    p.add_argument("--force", action="store_true", help="overwrite an existing --out file")
    p.add_argument(
        "--rubbing",
        action="store_true",
        help="rubbing estimate of mu and beta_A instead: the logs' omega is the "
        "known angular velocity of a rotation about the patch centre "
        "(needs --params0 for delta and gamma)",
    )
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    add_log_options(p)
    p.set_defaults(run=run)


class ProgressBar:
    """The identification's progress (tqdm) over the iteration budget, with the fit's RMSE and
    the cost relative to the first; called as bar(iteration, cost, params)."""

    def __init__(self, total: int, stream=None):
        self.total = max(int(total), 1)
        self.stream = sys.stderr if stream is None else stream
        self.first: float | None = None
        self.bar = None  # drawn at the first iteration: a refusal before it prints no bar

    def __call__(self, it: int, cost: float, params=None) -> None:
        if self.bar is None:
            from tqdm import tqdm

            tty = bool(getattr(self.stream, "isatty", lambda: False)())
            self.bar = tqdm(total=self.total, desc="identify", unit="it", file=self.stream,
                            mininterval=0.2 if tty else 10.0, dynamic_ncols=tty)
        if self.first is None:
            self.first = cost
        rel = cost / self.first if self.first else float("nan")
        self.bar.set_postfix_str(f"RMSE {math.sqrt(max(cost, 0.0)):.4g} rad/s, cost x{rel:.3g} "
                                 "of the first", refresh=False)
        self.bar.update(max(0, min(int(it), self.bar.total) - self.bar.n))

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


#: The files write_report writes in its folder (identify --report refuses them without --force).
REPORT_FILES = ("identification.txt", "maneuver_rmse.csv", "params.yaml", "cost_trace.png",
                "fig07_limit_surface.png", "validation_S_omega.png", "fig05_identification.png")


def write_report(result, out_dir: Path, *, title: str | None = None) -> list[Path]:
    """Parameter table (text), per-maneuver RMSE (CSV), the cost trace and the Figure-5-style
    plot of the validation maneuvers (PNG). Returns the written paths."""
    import numpy as np

    from .. import plot
    from .._atomic import write_text_atomic

    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    written = []
    path = write_text_atomic(out_dir / "identification.txt", result.summary() + "\n")
    written.append(path)
    path = out_dir / "maneuver_rmse.csv"
    val = set(result.validation_keys)
    lines = ["maneuver,set,rmse_rad_s"]
    for key, v in result.maneuver_rmse.items():
        lines.append(f"{key},{'validation' if key in val else 'train'},{v:.6g}")
    write_text_atomic(path, "\n".join(lines) + "\n")
    written.append(path)
    written.append(result.save_yaml(out_dir / "params.yaml"))

    with plot.style():
        fig, ax = plot.new_figure(1, 1, width=6.0, row_height=3.0)
        ax.semilogy(
            np.arange(len(result.cost_trace)),
            np.sqrt(result.cost_trace),
            marker="o",
            color=plot.color(0),
        )
        ax.set_xlabel(plot.axis_label("iteration"))
        ax.set_ylabel(plot.axis_label("training error", r"\sqrt{C}", "rad/s"))
        ax.set_title(f"{result.status}, {result.iterations} iterations, {result.fit_time:.2f} s")
        written.append(plot.save(fig, out_dir / "cost_trace.png"))

    if result.stages is not None:
        written.append(plot.save(limit_surface_figure(result), out_dir / "fig07_limit_surface.png"))
    if result.validation_trace is not None and len(result.validation_trace["omega"]):
        written.append(plot.save(validation_figure(result), out_dir / "validation_S_omega.png"))

    tr = result.validation_trace
    if tr is not None and len(tr["omega"]):
        # a continuous time axis over the validation maneuvers, in log order
        t = np.asarray(tr["t"], dtype=float)
        man = np.asarray(tr["maneuver"])
        t_plot = np.empty_like(t)
        offset = 0.0
        for i in range(man.max() + 1):
            sel = man == i
            ti = t[sel] - t[sel][0]
            t_plot[sel] = ti + offset
            offset += ti[-1] + 0.1
        name = "fig05_identification"
        heading = title or (f"validation maneuvers ({len(tr['keys'])}): identified parameters")
        try:
            from ..plot.observer import figure5
        except ImportError:  # pragma: no cover - the plot module ships with the package
            figure5 = None
        if figure5 is not None:
            fig = figure5(
                t_plot,
                tr["omega_hat"],
                tr["omega"],
                None,
                maneuver=man,
                title=heading,
                rmse=result.rmse_validation,
            )
        else:  # pragma: no cover
            with plot.style():
                fig, ax = plot.new_figure(1, 1, width=10.0)
                ax.plot(t_plot, tr["omega"], color=plot.color(0), lw=0.8, label="omega")
                ax.plot(t_plot, tr["omega_hat"], color=plot.color(1), lw=0.8, label="omega_hat")
                ax.legend()
        written.append(plot.save(fig, out_dir / f"{name}.png"))
    return written


def limit_surface_figure(result):
    """The limit-surface stage like the paper's Figure 7: the gross-sliding points in
    normalised coordinates (f_t / (mu f_n), |tau| / tau_max(f_n)), coloured by |omega|, the
    fitted dry limit surface and the points with their fitted viscous part removed."""
    import numpy as np

    from .. import plot
    from ..identification._stages import _A, _curves, _ellipse_curves

    ls = result.stages.ls
    pts = ls.points
    if ls.elliptic:
        F, T, xi = _ellipse_curves()
    else:
        F, T, xi = _curves(0.0 if np.isinf(ls.k) else 1.0 / ls.k)
    ft = pts.f_t / (ls.mu * pts.f_n)
    tt = pts.tau_abs / (ls.mu * xi * ls.delta * pts.f_n ** (1.0 + ls.gamma))
    lam = ls.kappa * pts.f_n ** (3.0 * ls.gamma - 1.0) * pts.omega_abs / (2.0 * xi)
    with plot.style():
        fig, ax = plot.new_figure(1, 1, width=5.5, row_height=4.5)
        keep = _A <= 30.0
        ax.plot(F[keep], T[keep], color="k", lw=1.2, label="fitted LS (ellipse)" if ls.elliptic else f"fitted LS (k = {ls.k:.3g})")
        sc = ax.scatter(ft, tt, c=pts.omega_abs, s=12, cmap="viridis", label="measured")
        if ls.kappa > 0:
            ax.scatter(ft - 2 * xi * ls.c_abs * lam, tt - lam, s=6, marker="x",
                       color=plot.color(3), label="measured minus fitted viscous part")
        fig.colorbar(sc, ax=ax, label="|omega| [rad/s]")
        ax.set_xlabel(plot.axis_label("tangential", r"f_t/(\mu f_n)"))
        ax.set_ylabel(plot.axis_label("torsional", r"|\tau|/\tau_{max}"))
        ax.set_xlim(0, max(1.1, float(np.percentile(ft, 98)) * 1.05))
        ax.set_ylim(0, max(1.1, float(np.percentile(tt, 98)) * 1.05))
        ax.set_title(f"mu {ls.mu:.3g}, delta {ls.delta:.3g}, gamma {ls.gamma:.3g}, "
                     f"{len(pts)} points", fontsize=9)
        ax.legend(loc="upper right", fontsize=7)
    return fig


def validation_figure(result):
    """The online observer with the identified parameters on the validation maneuvers:
    omega and omega_hat, and the slippage indicator S with the 0.9 line."""
    import numpy as np

    from .. import plot

    tr = result.validation_trace
    obs = result.make_observer()
    man = np.asarray(tr["maneuver"])
    S = np.empty(man.size)
    what = np.empty(man.size)
    obsv = np.zeros(man.size, bool)
    t_plot = np.empty(man.size)
    offset = 0.0
    for i in range(man.max() + 1):
        sel = np.flatnonzero(man == i)
        run = obs.run({"t": tr["t"][sel], "f_n": tr["f_n"][sel], "f_t": tr["f_t"][sel],
                       "tau": tr["tau"][sel]})
        S[sel] = np.asarray(run.S)
        what[sel] = np.asarray(run.omega_hat)
        obsv[sel] = np.asarray(run.speed_observable, bool)
        ti = tr["t"][sel] - tr["t"][sel][0]
        t_plot[sel] = ti + offset
        offset += ti[-1] + 0.1
    with plot.style():
        fig, (a0, a1) = plot.new_figure(2, 1, width=10.0, row_height=2.6, sharex=True)
        a0.plot(t_plot, tr["omega"], color=plot.color(0), lw=0.8, label="omega (truth)")
        a0.plot(t_plot, what, color=plot.color(1), lw=0.8, label="omega_hat")
        a0.set_ylabel(plot.axis_label("angular velocity", r"\omega", "rad/s"))
        a0.legend(loc="upper right", fontsize=7)
        a1.plot(t_plot, S, color=plot.color(2), lw=0.8, label="S")
        a1.axhline(0.9, color="k", lw=0.6, ls="--")
        a1.fill_between(t_plot, 0, 1.05, where=obsv, color=plot.color(4), alpha=0.15,
                        label="speed_observable")
        a1.set_ylim(0, 1.05)
        a1.set_ylabel(plot.axis_label("slippage", "S"))
        a1.set_xlabel(plot.axis_label("time (validation maneuvers back to back)", None, "s"))
        a1.legend(loc="lower right", fontsize=7)
    return fig


def run(args) -> int:
    import warnings

    from ..identification import IdentificationError, estimate_rubbing, identify

    for path in args.logs:
        if not path.exists():
            raise CliError(f"{path}: no such file")
    # the output policy (commands/_output.py), checked before any work
    inputs = [*args.logs, args.params0]
    check_file(args.out, "--out", force=args.force, inputs=inputs, create_parent=True)
    if args.report is not None:
        check_dir(args.report, "--report", force=args.force, results=REPORT_FILES,
                  inputs=inputs)
        for name in ("params.yaml",):
            if is_same_file(args.report / name, args.out):
                raise CliError(f"argument --report: {args.report / name} is also the --out file")
    if args.rubbing:
        if args.params0 is None:
            raise CliError("--rubbing needs --params0 (the fingertip's delta and gamma)")
        from .._observer import read_observer_settings
        from .._params import ContactParams

        try:
            base = ContactParams.from_yaml(args.params0)
            block = read_observer_settings(args.params0)
        except ValueError as err:
            raise CliError(f"argument --params0: {err}") from None
        results = []
        for path in args.logs:
            est = estimate_rubbing(read_log_from_args(path, args, allow_gaps=True), base, mode="rotation")
            results.append(est)
            print(f"{path}: {est}")
        est = results[0] if len(results) == 1 else None
        if est is None:  # several logs: combine by inverse-variance weighting
            import numpy as np

            w_mu = np.array([1 / r.mu_stderr**2 for r in results])
            w_b = np.array([1 / r.beta_a_stderr**2 for r in results])
            mu = float(np.sum(w_mu * [r.mu for r in results]) / w_mu.sum())
            beta = float(np.sum(w_b * [r.beta_a for r in results]) / w_b.sum())
        else:
            mu, beta = est.mu, est.beta_a
        params = base.replace(mu=mu, beta_a=beta)
        text = params.to_yaml(
            comment=f"lugrip identify --rubbing: mu and beta_A from "
            f"{', '.join(str(p) for p in args.logs)}",
            observer=block,  # the fingertip's observer goes with its parameters
        )
        atomic_write_text(args.out, text, "--out", force=args.force, create_parent=True)
        print(f"wrote {args.out}")
        return 0

    block = None
    if args.params0 is not None and args.params0.suffix in (".yaml", ".yml"):
        from .._observer import read_observer_settings

        if not args.params0.exists():
            raise CliError(f"argument --params0: {args.params0}: no such file")
        try:
            block = read_observer_settings(args.params0)
        except ValueError as err:
            raise CliError(f"argument --params0: {err}") from None
    observer = observer_options(block, args)
    if args.free is not None and args.params0 is None:
        raise CliError("--free needs --params0 for the values of the fixed parameters")
    bar = None if args.quiet else ProgressBar(args.max_iterations)
    logs = [read_log_from_args(p, args, allow_gaps=True) for p in args.logs]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            result = identify(
                logs,
                None if args.params0 is None else args.params0,
                free=args.free
                if args.free is not None
                else ("mu", "beta_a", "sigma0", "sigma_z", "delta", "gamma"),
                observer=observer,
                validation=args.validation,
                seed=args.seed,
                loss=args.loss,
                huber_scale=args.huber_scale,
                weighting=args.weighting,
                method=args.method,
                max_iterations=args.max_iterations,
                uncertainty=args.uncertainty,
                n_bootstrap=args.bootstrap,
                start=args.start,
                refine=args.refine,
                k=args.k,
                threads=args.threads,
                score_saturated=args.score_saturated,
                progress=bar,
            )
        except IdentificationError as err:
            raise CliError(str(err)) from None
        finally:
            if bar is not None:
                bar.close()
    seen = set()
    for w in caught:
        text = str(w.message)
        if text not in seen:
            seen.add(text)
            print(f"warning: {text}", file=sys.stderr)
    print(result.summary())
    atomic_write_text(args.out, result.yaml_text(), "--out", force=args.force,
                      create_parent=True)
    print(f"wrote {args.out}")
    if args.report is not None:
        for path in write_report(result, args.report):
            print(f"wrote {path}")
    if result.status == "failed":
        print(f"lugrip identify: fit failed: {result.message} (written with status: failed)",
              file=sys.stderr)
        return 3
    return 0
