"""Subcommands of the ``lugrip`` command line.

Each subcommand is a module of this package exposing

* ``register(subparsers)``: adds its parser with ``subparsers.add_parser(...)`` and sets
  ``parser.set_defaults(run=run)``;
* ``run(args) -> int``: does the work and returns the exit code.

Adding a subcommand is one line: append its module name to ``COMMANDS`` (the order is the
order of ``lugrip --help``). Modules import heavy dependencies (matplotlib, scipy) inside
``run`` so that ``lugrip --help`` stays fast.

Errors the user can fix (bad argument value, unreadable or invalid file) are raised as
:class:`CliError` (or ``ValueError``/``OSError``); the entry point prints them as one line and
exits with code 2, without a traceback.
"""

from __future__ import annotations

import argparse
import math

__all__ = [
    "COMMANDS",
    "CliError",
    "HelpFormatter",
    "k_label",
    "observer_options",
    "parse_k",
    "positive_float",
]

COMMANDS: list[str] = [
    "ls",
    "params",
    "simulate_sliding",
    "simulate_rubbing",
    "observe",
    "replay",
    "identify",
    "simulate",
    "demo",
    "campaign",
    "ros",
]
"""Module names (in this package) of the subcommands, in --help order."""


class HelpFormatter(argparse.RawDescriptionHelpFormatter):
    """Wraps one-line paragraphs of the description/epilog to the terminal width and keeps
    paragraphs that contain line breaks (example blocks) as written. The ``lugrip`` parser
    uses it for every subcommand that asks for the default or the raw-description formatter."""

    def _fill_text(self, text, width, indent):
        import textwrap

        out = []
        for para in text.split("\n\n"):
            if "\n" in para.strip("\n"):
                out.append("\n".join(indent + line for line in para.splitlines()))
            else:
                out.append(textwrap.fill(" ".join(para.split()), width,
                                         initial_indent=indent, subsequent_indent=indent))
        return "\n\n".join(out)


class CliError(Exception):
    """A user error: printed as ``lugrip <command>: error: <message>``, exit code 2."""


def parse_k(text: str) -> float:
    """argparse type for a pressure exponent k: a positive number, 'inf', or 'ellipse' (the
    elliptic limit surface, ContactParams.k = 0)."""
    t = text.strip().lower()
    if t in ("inf", "infinity", "+inf", "oo"):
        return math.inf
    if t == "ellipse":
        return 0.0
    try:
        value = float(t)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"invalid value {text!r}: expected a positive number, 'inf' or 'ellipse'") from None
    if math.isnan(value) or value <= 0.0:
        raise argparse.ArgumentTypeError(
            f"invalid value {text!r}: the pressure exponent k must be > 0 (or 'inf')")
    return value


def positive_float(text: str) -> float:
    """argparse type for a finite number > 0."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"invalid value {text!r}: expected a number") from None
    if not (math.isfinite(value) and value > 0.0):
        raise argparse.ArgumentTypeError(f"invalid value {text!r}: must be finite and > 0")
    return value


def k_label(k: float) -> str:
    """'2', '4', '3.5', 'inf', 'ellipse' (k = 0) — for file names, CSV cells and legends."""
    if math.isinf(k):
        return "inf"
    if k == 0.0:
        return "ellipse"
    return f"{k:g}"


def observer_options(block, args) -> dict:
    """Observer keywords: a parameter file's ``observer:`` block (without its ``dt``: the
    nominal sample period is the log's) with the command's --integrator and --gain or
    --bandwidth (a mutually exclusive pair: either one sets the gain mode) on top."""
    kwargs = dict(block or {})
    kwargs.pop("dt", None)
    if args.integrator is not None:
        kwargs["integrator"] = args.integrator
    if args.gain is not None:
        kwargs["gain"] = args.gain
        kwargs["gain_mode"] = "fixed"
    if args.bandwidth is not None:
        kwargs["bandwidth"] = args.bandwidth
        kwargs["gain_mode"] = "bandwidth"
    return kwargs
