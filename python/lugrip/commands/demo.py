"""``lugrip demo``: the project's main job. Runs a list of steps, each writing its figures into
the output directory and returning a Markdown section, and assembles ``report.md``.

Adding a step is one line in :data:`STEPS`: ``DemoStep(name, title, function, units)`` where
``function(out_dir: Path) -> str`` returns the Markdown body of its section (figures referenced
relative to out_dir). ``function`` may be given as ``"module:attribute"`` so the step's module
is imported only when the step runs. A function that takes the keywords ``progress`` and
``full`` gets a callable ``progress(line)`` to call once per unit of work (``units`` of them:
an int, or ``units(full)``) and ``full`` (``lugrip demo --full``); it may return
``(markdown, known_limits)``, known_limits a list of lines naming results that fail as
documented (a scenario's ``known_limits``), which the summary lists without failing the demo.

The progress bar (tqdm) counts the units of every step and gives the ETA; a step that raises
is an unexpected failure: the report holds its traceback and the exit code is 1.
"""

from __future__ import annotations

import argparse
import datetime as _dt
import importlib
import os
import platform
import sys
import time
import traceback
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Union

from . import CliError

__all__ = ["REPORT_NAME", "STEPS", "DemoStep", "register", "run", "run_demo"]

REPORT_NAME = "report.md"

#: The known limits the last run_demo found (lines "step: scene: reason").
known_limits: list[str] = []

StepFunction = Callable[[Path], str]


@dataclass(frozen=True)
class DemoStep:
    """One section of the demo report.

    Attributes:
        name: short id for ``--only`` (lowercase, no spaces).
        title: section heading in the report.
        function: ``function(out_dir) -> markdown`` or ``"package.module:function"``.
    """

    name: str
    title: str
    function: StepFunction | str
    #: units of progress the step reports (an int, or a function of ``full``)
    units: Union[int, Callable[[bool], int]] = 1
    #: the step renders MuJoCo frames (the offscreen GL back end is chosen before any step)
    renders: bool = False

    def count(self, full: bool) -> int:
        return max(1, int(self.units(full) if callable(self.units) else self.units))

    def resolve(self) -> StepFunction:
        if callable(self.function):
            return self.function
        module, _, attr = self.function.partition(":")
        return getattr(importlib.import_module(module), attr)


STEPS: list[DemoStep] = [
    DemoStep("ls", "Limit surface (paper Figures 3 and 7)", "lugrip.commands.ls:demo_section"),
    DemoStep("observer", "Observer replay (paper Figure 5)", "lugrip.commands.observe:demo_section"),
    DemoStep("experiments", "Closed-loop experiments (paper Figures 11, 13, 15, 17) and baselines",
             "lugrip.sim.report:demo_section", lambda full: _count("paper")),
    DemoStep("mujoco", "Closed loop on MuJoCo: the paper's experiments and unseen objects",
             "lugrip.sim.report:mujoco_demo_section", lambda full: _count("all"), renders=True),
]
"""Steps of ``lugrip demo`` in report order."""



def _count(suite: str) -> int:
    from ..sim.scenarios import list_scenarios

    return len(list_scenarios(suite=suite))


_EPILOG = """\
examples:
  lugrip demo --out out             # what `make demo` runs: one noise seed per MuJoCo scene
  lugrip demo --out out --full      # eight noise seeds per MuJoCo scene
  lugrip demo --out /tmp/d --only ls

exit status: 0 when every step ran and every failing result is a documented known limit
(listed in the summary with its reason); 1 on any other failure.
"""


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "demo",
        help="run the demo steps and write figures and report.md",
        description=(
            "Run the demo steps (currently: " + ", ".join(s.name for s in STEPS) + "), write "
            "their figures into DIR and a Markdown report DIR/report.md."),
        epilog=_EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--out", type=Path, default=Path("out"), metavar="DIR",
                   help="output directory (default: out)")
    p.add_argument("--only", nargs="+", metavar="STEP", default=None,
                   help="run only these steps: " + ", ".join(s.name for s in STEPS))
    p.add_argument("--force", action="store_true",
                   help="overwrite the report of an earlier demo in --out")
    p.add_argument("--full", action="store_true",
                   help="eight noise seeds per MuJoCo scene (default: one)")
    p.set_defaults(run=run)


def _select(only) -> list[DemoStep]:
    if not only:
        return list(STEPS)
    known = {s.name: s for s in STEPS}
    unknown = [n for n in only if n not in known]
    if unknown:
        raise CliError(f"argument --only: unknown step {unknown[0]!r}; "
                       f"known: {', '.join(known)}")
    return [s for s in STEPS if s.name in only]


def run_demo(out_dir: str | Path, steps: list[DemoStep] | None = None,
             log=None, full: bool = False) -> tuple[Path, list[str]]:
    """Run the steps, write out_dir/report.md. Returns (report path, names of failed steps).
    A failing step is recorded in the report (with its traceback) and the others still run.
    Known limits the steps report are listed in the report's summary (:data:`known_limits`
    of the last run)."""
    import inspect

    from tqdm import tqdm

    from .. import __version__

    log = sys.stderr if log is None else log  # looked up per call (tests swap sys.stderr)
    out_dir = Path(out_dir)
    if out_dir.exists() and not out_dir.is_dir():
        raise CliError(f"argument --out: {out_dir} exists and is not a directory")
    out_dir.mkdir(parents=True, exist_ok=True)
    steps = list(STEPS) if steps is None else steps
    now = _dt.datetime.now(_dt.timezone.utc).replace(microsecond=0)
    sections, failed, timing, limits = [], [], [], []
    units = [step.count(full) for step in steps]
    tty = bool(getattr(log, "isatty", lambda: False)())
    # on a terminal the bar redraws in place; elsewhere each line carries the count and ETA
    sink = log if tty else open(os.devnull, "w")  # noqa: SIM115 (closed below)
    bar = tqdm(total=sum(units), unit="task", desc="demo", file=sink, dynamic_ncols=tty,
               mininterval=0.5,
               bar_format="{desc}: {percentage:3.0f}%|{bar}| {n}/{total} [{elapsed}<{remaining}]")

    def say(line: str) -> None:
        if tty:
            bar.write(line, file=log)
            return
        d = bar.format_dict
        rate = d["n"] / d["elapsed"] if d["elapsed"] > 0 and d["n"] else None
        eta = (tqdm.format_interval((d["total"] - d["n"]) / rate) if rate else "?")
        print(f"{line}  [{d['n']}/{d['total']}, {tqdm.format_interval(d['elapsed'])} "
              f"elapsed, ETA {eta}]", file=log, flush=True)

    for step, n_units in zip(steps, units):
        start = bar.n
        say(f"[demo] {step.name}: {step.title} ...")
        t0 = time.perf_counter()

        def progress(line: str, _cap=start + n_units) -> None:
            if bar.n < _cap:
                bar.update(1)
            say(f"[demo]   {line}")

        try:
            fn = step.resolve()
            params = inspect.signature(fn).parameters
            kwargs = {k: v for k, v in (("progress", progress), ("full", full)) if k in params}
            body = fn(out_dir, **kwargs)
            if isinstance(body, tuple):
                body, found = body
                limits += [f"{step.name}: {line}" for line in found]
            status = "ok"
        except Exception:  # noqa: BLE001  (a failing step must not hide the others)
            body = ("**This step failed:**\n\n```\n" + traceback.format_exc().rstrip() +
                    "\n```\n")
            status = "FAILED"
            failed.append(step.name)
        dt = time.perf_counter() - t0
        bar.update(start + n_units - bar.n)
        timing.append((step, status, dt))
        say(f"[demo] {step.name}: {status} ({dt:.1f} s)")
        sections.append(f"## {step.title}\n\n{body.rstrip()}\n")
    bar.close()
    if sink is not log:
        sink.close()
    known_limits[:] = limits

    summary = ["| step | status | time [s] |", "|---|---|---|"]
    summary += [f"| {s.name} | {st} | {dt:.2f} |" for s, st, dt in timing]
    report = "\n".join([
        "# lugrip demo report",
        "",
        f"- date: {now.isoformat()}",
        f"- lugrip version: {__version__}",
        f"- Python {platform.python_version()} on {platform.system()} {platform.machine()}",
        f"- command: `lugrip demo --out {out_dir.as_posix()}{' --full' if full else ''}`",
        "",
        ("lugrip implements a model-based approach to slip detection, slip avoidance and "
        "controlled pivoting for a parallel gripper whose fingertips measure the normal force, "
        "the tangential force and the torsional moment (limit surface + LuGre friction). Each "
        "section below was produced by one demo step; figures are in the same directory as "
        "this report."),
        "",
        *summary,
        "",
        *(["Known limits (documented failures, see each scenario's `known_limits`):", "",
           *[f"- {line}" for line in limits], ""] if limits else []),
        *sections,
    ])
    from .._atomic import write_text_atomic

    path = write_text_atomic(out_dir / REPORT_NAME, report)
    return path, failed


def run(args: argparse.Namespace) -> int:
    steps = _select(args.only)
    from ._output import check_dir

    check_dir(args.out, "--out", force=args.force, results=(REPORT_NAME,))
    if any(step.renders for step in steps):
        from ..sim import report

        report.choose_gl_backend()  # the frames: before any step imports MuJoCo
    path, failed = run_demo(args.out, steps, full=args.full)
    print(f"wrote {path}", file=sys.stderr)
    for line in known_limits:
        print(f"lugrip demo: known limit: {line}", file=sys.stderr)
    if failed:
        print(f"lugrip demo: error: step(s) failed: {', '.join(failed)} (details in {path})",
              file=sys.stderr)
        return 1
    return 0
