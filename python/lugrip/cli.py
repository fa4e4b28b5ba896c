"""The ``lugrip`` command line: ``lugrip <command> [options]``.

Subcommands live in :mod:`lugrip.commands` (one module each, listed in
``lugrip.commands.COMMANDS``). User errors (a bad argument, an unreadable, oversized or
invalid file or field, malformed YAML, a number out of range, exhausted memory) exit with code
2 and one line on stderr; any other exception exits with code 1 and one line naming it as an
internal error. Set ``LUGRIP_DEBUG=1`` to get the traceback instead.
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
    from ._data import docs_dir

    where = docs_dir()
    epilog = _EPILOG + (f" The pages cited as docs/*.md are in {where} (the site: 'make docs' "
                        "in a clone)." if where is not None else "")
    parser = _Parser(prog="lugrip", description=_DESCRIPTION, epilog=epilog)
    parser.add_argument("--version", action="version", version=f"lugrip {__version__}")
    subparsers = parser.add_subparsers(dest="command", metavar="<command>", required=True,
                                       parser_class=_Parser)
    for name in COMMANDS:
        module = importlib.import_module(f"{__package__}.commands.{name}")
        module.register(subparsers)
    return parser


_MAX_MESSAGE = 600  # [characters] longest error line printed (a message may embed a value)


def _one_line(err: BaseException) -> str:
    # errors that carry a command-line wording of their hints (lugrip.io.LogError) use it
    text = getattr(err, "cli_message", None) or str(err) or type(err).__name__
    if isinstance(err, OSError) and err.filename is not None and err.strerror:
        text = f"{err.filename}: {err.strerror}"
    line = "; ".join(part.strip() for part in text[: 4 * _MAX_MESSAGE].splitlines() if part.strip())
    return line if len(line) <= _MAX_MESSAGE else line[: _MAX_MESSAGE - 5] + " [...]"


#: Arguments that name outputs (never reported as the input a message is about).
_OUTPUT_ARGS = ("out", "output", "run", "json", "video", "csv", "plot", "report")


def _input_files(args: argparse.Namespace) -> str:
    """'FILE: ' for the one existing input file among the arguments (outputs excluded), or
    'one of A, B: ' for several; '' when none is known."""
    from pathlib import Path

    files = []
    for name, value in vars(args).items():
        if name in _OUTPUT_ARGS or not isinstance(value, (str, os.PathLike)):
            continue
        try:
            if Path(value).is_file():
                files.append(str(value))
        except (OSError, ValueError):
            continue
    if not files:
        return ""
    return f"{files[0]}: " if len(files) == 1 else f"one of {', '.join(files)}: "


def _input_error(err: BaseException, args: argparse.Namespace) -> str | None:
    """One line for the errors a hostile input provokes in the readers (malformed YAML or CSV
    from a reader without limits, text that is not UTF-8, nesting beyond the recursion limit,
    numbers beyond the float range, memory exhausted); None for other exceptions."""
    import csv

    if isinstance(err, UnicodeDecodeError):
        return f"{_input_files(args)}not UTF-8 text (byte {err.start})"
    if isinstance(err, csv.Error):
        return f"{_input_files(args)}malformed CSV: {_one_line(err)}"
    if type(err).__module__.split(".")[0] == "yaml":  # yaml.YAMLError and subclasses
        mark = getattr(err, "problem_mark", None)
        where = f"line {mark.line + 1}: " if mark is not None else ""
        problem = getattr(err, "problem", None) or type(err).__name__
        return f"not valid YAML: {where}{problem}"
    if isinstance(err, RecursionError):
        return "input nested too deeply"
    if isinstance(err, OverflowError):
        return f"number out of range: {_one_line(err)}"
    if isinstance(err, MemoryError):
        return "out of memory: the input or the requested output is too large"
    return None


class _Terminated(BaseException):
    """SIGTERM, raised in the main thread so that every ``finally`` block runs (the output
    policy's temporary files are removed, commands/_output.py)."""


def _on_sigterm(signum, frame):  # the signal handler signature
    raise _Terminated()


def _sigterm_handler():
    """Installs the SIGTERM handler when SIGTERM has its default action and this is the main
    thread; returns the previous handler to restore, or None."""
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        return None
    try:
        if signal.getsignal(signal.SIGTERM) is not signal.SIG_DFL:
            return None
        return signal.signal(signal.SIGTERM, _on_sigterm)
    except (ValueError, OSError, AttributeError):
        return None


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
    previous = _sigterm_handler()
    try:
        return _run(args, prog)
    finally:
        if previous is not None:
            import signal

            signal.signal(signal.SIGTERM, previous)


def _run(args: argparse.Namespace, prog: str) -> int:
    try:
        return int(args.run(args) or 0)
    except _Terminated:
        print(f"{prog}: terminated", file=sys.stderr)
        return 143
    except BrokenPipeError:  # e.g. `lugrip ls | head`: not an error
        try:  # silence the second failure when Python flushes stdout at exit
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        except (OSError, ValueError):
            pass
        return 0
    except (CliError, ValueError, OSError) as err:
        if os.environ.get("LUGRIP_DEBUG"):
            raise
        message = _input_error(err, args) if isinstance(err, UnicodeDecodeError) else None
        print(f"{prog}: error: {message or _one_line(err)}", file=sys.stderr)
        return 2
    except ImportError as err:
        if getattr(err, "extra", None) is None or os.environ.get("LUGRIP_DEBUG"):
            raise  # a broken installation, not a missing optional package
        print(f"{prog}: error: {_one_line(err)}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"{prog}: interrupted", file=sys.stderr)
        return 130
    except Exception as err:  # noqa: BLE001 (one line instead of a traceback)
        if os.environ.get("LUGRIP_DEBUG"):
            raise
        message = _input_error(err, args)
        if message is not None:
            print(f"{prog}: error: {message}", file=sys.stderr)
            return 2
        # not a recognised user error: a defect of lugrip or an input it does not check yet
        print(f"{prog}: internal error: {type(err).__name__}: {_one_line(err)} "
              "(set LUGRIP_DEBUG=1 for the traceback)", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
