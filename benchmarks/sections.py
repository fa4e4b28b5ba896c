"""One marked section of BENCHMARKS.md: the text between ``<!-- issueN:begin -->`` and
``<!-- issueN:end -->``. Each benchmark script writes only its own section and keeps the rest of
the file; a section not yet in the file is appended.

Command line (for the C++ benchmarks' Markdown output)::

    python benchmarks/sections.py BENCHMARKS.md issue5 build/issue5.md
"""

from __future__ import annotations

import os
import sys
from pathlib import Path


def markers(issue: str) -> tuple[str, str]:
    """The begin and end markers of `issue` (e.g. "issue5")."""
    return f"<!-- {issue}:begin -->", f"<!-- {issue}:end -->"


def write_section(path: Path, section: str, issue: str) -> None:
    """Replace `issue`'s section of `path` with `section` (which carries its own markers), or
    append it; the file is replaced atomically."""
    begin, end = markers(issue)
    text = path.read_text() if path.exists() else "# Benchmarks\n"
    if begin in text and end in text:
        head, rest = text.split(begin, 1)
        _, tail = rest.split(end, 1)
        text = head + section.rstrip("\n") + tail
    else:
        text = text.rstrip("\n") + "\n\n" + section
    tmp = path.with_name(f".{path.name}.part")
    tmp.write_text(text)
    os.replace(tmp, path)


def main(argv: list[str]) -> int:
    if len(argv) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    out, issue, section = Path(argv[0]), argv[1], Path(argv[2]).read_text()
    begin, end = markers(issue)
    if begin not in section or end not in section:
        print(f"{argv[2]}: no {begin} ... {end} section", file=sys.stderr)
        return 2
    write_section(out, section, issue)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
