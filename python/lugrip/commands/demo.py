"""``lugrip demo``: the project's main job. Runs a list of steps, each writing its figures into
the output directory and returning a Markdown section, and assembles ``report.md``.

Adding a step is one line in :data:`STEPS`: ``DemoStep(name, title, function)`` where
``function(out_dir: Path) -> str`` returns the Markdown body of its section (figures referenced
relative to out_dir). ``function`` may be given as ``"module:attribute"`` so the step's module
is imported only when the step runs.
"""

from __future__ import annotations

import argparse
import datetime as _dt
import importlib
import platform
import sys
import time
import traceback
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from . import CliError

__all__ = ["REPORT_NAME", "STEPS", "DemoStep", "register", "run", "run_demo"]

REPORT_NAME = "report.md"

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

    def resolve(self) -> StepFunction:
        if callable(self.function):
            return self.function
        module, _, attr = self.function.partition(":")
        return getattr(importlib.import_module(module), attr)


STEPS: list[DemoStep] = [
    DemoStep("ls", "Limit surface (paper Figures 3 and 7)", "lugrip.commands.ls:demo_section"),
    DemoStep("observer", "Observer replay (paper Figure 5)", "lugrip.commands.observe:demo_section"),
    DemoStep("experiments", "Closed-loop experiments (paper Figures 11, 13, 15, 17) and baselines",
             "lugrip.sim.report:demo_section"),
    DemoStep("mujoco", "Closed loop on MuJoCo: the paper's experiments and unseen objects",
             "lugrip.sim.report:mujoco_demo_section"),
]
"""Steps of ``lugrip demo`` in report order."""

_EPILOG = """\
examples:
  lugrip demo --out out             # what `make demo` runs
  lugrip demo --out /tmp/d --only ls
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
             log=None) -> tuple[Path, list[str]]:
    """Run the steps, write out_dir/report.md. Returns (report path, names of failed steps).
    A failing step is recorded in the report (with its traceback) and the others still run."""
    from .. import __version__

    log = sys.stderr if log is None else log  # looked up per call (tests swap sys.stderr)
    out_dir = Path(out_dir)
    if out_dir.exists() and not out_dir.is_dir():
        raise CliError(f"argument --out: {out_dir} exists and is not a directory")
    out_dir.mkdir(parents=True, exist_ok=True)
    steps = list(STEPS) if steps is None else steps
    now = _dt.datetime.now(_dt.timezone.utc).replace(microsecond=0)
    sections, failed, timing = [], [], []
    for step in steps:
        print(f"[demo] {step.name}: {step.title} ...", file=log, flush=True)
        t0 = time.perf_counter()
        try:
            body = step.resolve()(out_dir)
            status = "ok"
        except Exception:  # noqa: BLE001  (a failing step must not hide the others)
            body = ("**This step failed:**\n\n```\n" + traceback.format_exc().rstrip() +
                    "\n```\n")
            status = "FAILED"
            failed.append(step.name)
        dt = time.perf_counter() - t0
        timing.append((step, status, dt))
        print(f"[demo] {step.name}: {status} ({dt:.1f} s)", file=log, flush=True)
        sections.append(f"## {step.title}\n\n{body.rstrip()}\n")

    summary = ["| step | status | time [s] |", "|---|---|---|"]
    summary += [f"| {s.name} | {st} | {dt:.2f} |" for s, st, dt in timing]
    report = "\n".join([
        "# lugrip demo report",
        "",
        f"- date: {now.isoformat()}",
        f"- lugrip version: {__version__}",
        f"- Python {platform.python_version()} on {platform.system()} {platform.machine()}",
        f"- command: `lugrip demo --out {out_dir.as_posix()}`",
        "",
        ("lugrip implements a model-based approach to slip detection, slip avoidance and "
        "controlled pivoting for a parallel gripper whose fingertips measure the normal force, "
        "the tangential force and the torsional moment (limit surface + LuGre friction). Each "
        "section below was produced by one demo step; figures are in the same directory as "
        "this report."),
        "",
        *summary,
        "",
        *sections,
    ])
    from .._atomic import write_text_atomic

    path = write_text_atomic(out_dir / REPORT_NAME, report)
    return path, failed


def run(args: argparse.Namespace) -> int:
    steps = _select(args.only)
    from ._output import check_dir

    check_dir(args.out, "--out", force=args.force, results=(REPORT_NAME,))
    if any(step.name == "mujoco" for step in steps):
        from ..sim import report

        report.choose_gl_backend()  # the frames: before any step imports MuJoCo
    path, failed = run_demo(args.out, steps)
    print(f"wrote {path}", file=sys.stderr)
    if failed:
        print(f"lugrip demo: error: step(s) failed: {', '.join(failed)} (details in {path})",
              file=sys.stderr)
        return 1
    return 0
