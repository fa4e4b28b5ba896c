"""The ``lugrip`` command line: ``lugrip <command> [options]``.

Subcommands live in :mod:`lugrip.commands` (one module each, listed in
``lugrip.commands.COMMANDS``). User errors exit with code 2 and one line on stderr; set
``LUGRIP_DEBUG=1`` to get the traceback instead.
"""

from __future__ import annotations

import argparse
import importlib
import os
import sys

from .commands import COMMANDS, CliError, HelpFormatter

__all__ = ["build_parser", "main"]

_DESCRIPTION = (
    "lugrip: model-based slip detection, slip avoidance and pivoting for parallel grippers "
    "with force/torque fingertips (limit surface + LuGre friction)."
)
_EPILOG = "Run 'lugrip <command> --help' for the options of a command."


class _UsageError(Exception):
    def __init__(self, prog: str, message: str):
        super().__init__(message)
        self.prog = prog
        self.message = message


class _Parser(argparse.ArgumentParser):
    """ArgumentParser that raises instead of printing the usage and exiting, so main() can
    report a bad argument as one line and return 2 (also when called in-process). Help text
    is wrapped by HelpFormatter unless a command chooses another formatter."""

    def __init__(self, *args, **kwargs):
        if kwargs.get("formatter_class") in (None, argparse.HelpFormatter,
                                             argparse.RawDescriptionHelpFormatter):
            kwargs["formatter_class"] = HelpFormatter
        super().__init__(*args, **kwargs)

    def error(self, message: str):  # type: ignore[override]
        raise _UsageError(self.prog, message)


def build_parser() -> argparse.ArgumentParser:
    """The top-level parser with every subcommand of ``lugrip.commands.COMMANDS``."""
    from . import __version__

    parser = _Parser(prog="lugrip", description=_DESCRIPTION, epilog=_EPILOG)
    parser.add_argument("--version", action="version", version=f"lugrip {__version__}")
    subparsers = parser.add_subparsers(dest="command", metavar="<command>", required=True,
                                       parser_class=_Parser)
    for name in COMMANDS:
        module = importlib.import_module(f"{__package__}.commands.{name}")
        module.register(subparsers)
    return parser


def _one_line(err: BaseException) -> str:
    # errors that carry a command-line wording of their hints (lugrip.io.LogError) use it
    text = getattr(err, "cli_message", None) or str(err) or type(err).__name__
    if isinstance(err, OSError) and err.filename is not None and err.strerror:
        text = f"{err.filename}: {err.strerror}"
    return "; ".join(part.strip() for part in text.splitlines() if part.strip())


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``lugrip`` script; returns the exit code (0 ok, 2 user error)."""
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except _UsageError as err:
        print(f"{err.prog}: error: {_one_line(err)} (see '{err.prog} --help')", file=sys.stderr)
        return 2
    except SystemExit as exit_:  # --help, --version
        return exit_.code if isinstance(exit_.code, int) else 0

    prog = f"lugrip {args.command}"
    try:
        return int(args.run(args) or 0)
    except BrokenPipeError:  # e.g. `lugrip ls | head`: not an error
        try:  # silence the second failure when Python flushes stdout at exit
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        except (OSError, ValueError):
            pass
        return 0
    except (CliError, ValueError, OSError) as err:
        if os.environ.get("LUGRIP_DEBUG"):
            raise
        print(f"{prog}: error: {_one_line(err)}", file=sys.stderr)
        return 2
    except ImportError as err:
        if getattr(err, "extra", None) is None or os.environ.get("LUGRIP_DEBUG"):
            raise  # a broken installation, not a missing optional package
        print(f"{prog}: error: {_one_line(err)}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"{prog}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
