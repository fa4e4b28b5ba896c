"""Data files shipped with lugrip: the experiment scenarios, the object parameter files and
the documentation pages.

The repository's top-level ``scenarios/``, ``objects/`` and ``docs/`` are the sources; the wheel
carries copies under ``lugrip/data/`` (pyproject.toml, ``wheel.packages``), so an installed
lugrip finds them from any working directory.
"""

from __future__ import annotations

from pathlib import Path

__all__ = ["DATA_KINDS", "data_dir", "docs_dir"]

DATA_KINDS = ("scenarios", "objects")
"""Names of the bundled data directories."""


def data_dir(kind: str) -> Path | None:
    """Directory of the bundled ``kind`` files (one of :data:`DATA_KINDS`): the copy inside
    the installed package, else the repository's top-level directory when lugrip runs from a
    source tree; None when neither holds a YAML file."""
    if kind not in DATA_KINDS:
        raise ValueError(f"unknown data kind {kind!r}; known: {', '.join(DATA_KINDS)}")
    here = Path(__file__).resolve().parent
    for candidate in (here / "data" / kind, here.parents[1] / kind):
        if candidate.is_dir() and any(candidate.glob("*.yaml")):
            return candidate
    return None


def docs_dir() -> Path | None:
    """Directory of the documentation pages (``model.md``, ``sliding_log.md``, ...): the copy
    inside the installed package, else the repository's ``docs/``; None when neither exists."""
    here = Path(__file__).resolve().parent
    for candidate in (here / "data" / "docs", here.parents[1] / "docs"):
        if (candidate / "model.md").is_file():
            return candidate
    return None
