"""docs/model.md against the repository that cites it.

Documentation checks, no plant involved. They fail when

* a file cites a section of docs/model.md that does not exist (including the numbered items of
  §11, the criteria of §10.3, the plants (a)/(b) of §10.1, the methods of §3.3 and quoted
  phrases), or cites the model document under a name the repository does not contain;
* a `file:symbol` or a path quoted in docs/model.md no longer exists (a moved or renamed
  function shows up here, so the mapping can be updated);
* an equation of the article is missing from the equation index (Appendix B) or has no
  implementation listed there.

Run as a script (``python tests/python/test_docs_model.py``) it prints every citation found and
every problem, and exits 1 if there is one.
"""

from __future__ import annotations

import glob
import os
import re
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DOC = ROOT / "docs" / "model.md"

SKIP_DIRS = {
    ".git",
    ".venv",
    "venv",
    "build",
    "dist",
    "out",
    "_skbuild",
    "__pycache__",
    ".pytest_cache",
    ".ruff_cache",
    ".mypy_cache",
    "node_modules",
    ".hypothesis",
}
TEXT_SUFFIXES = {
    ".py",
    ".cpp",
    ".hpp",
    ".h",
    ".c",
    ".md",
    ".yaml",
    ".yml",
    ".txt",
    ".toml",
    ".cfg",
    ".cff",
    ".cmake",
    ".rst",
    ".in",
    ".sh",
}
TEXT_NAMES = {"CMakeLists.txt", "Makefile"}

# The model document as cited today, and the name of the former out-of-repository spec, which
# must not be cited any more (written with escapes so that a text rewrite leaves it alone).
CITE = re.compile(r"(?<![\w/.])(docs/model\.md|MODEL\.md)")
MISSING_NAME = "MODEL" + ".md"

_APPENDIX = re.compile(r"\s*(?:§\s*|sections?\s+)?Appendix\s+([A-Z])\b")
_NUMBER = re.compile(r"\s*(?:§\s*|sections?\s+)?(\d+(?:\.\d+)?)(?!\d|\.\d)")
_SEP = re.compile(r"\s*(?:,|and|/|-|–|&)\s*")
_QUAL = re.compile(
    r"\s*,?\s*(?:item\s+(?P<item>\d+)|criterion\s+(?P<crit>\d+)|\((?P<plant>[ab])\)"
    r"|method\s+(?P<method>[AB])|\"(?P<quote>[^\"]+)\")"
)
_COMMENT_LEAD = re.compile(r"^\s*(?://+!?|#+|\*+|\"|')?\s*")


@dataclass(frozen=True)
class Ref:
    section: str  # "7.4", "11", "A"
    item: str | None = None
    criterion: str | None = None
    plant: str | None = None
    method: str | None = None
    quote: str | None = None


@dataclass(frozen=True)
class Citation:
    path: str
    line: int
    name: str  # the cited file name as written
    refs: tuple[Ref, ...]
    text: str


def _ref_at(text: str, pos: int):
    """One section reference at `pos` (with 'Appendix' handled explicitly), or None."""
    m = _APPENDIX.match(text, pos)
    if m:
        return m.group(1), m.end()
    m = _NUMBER.match(text, pos)
    if m:
        return m.group(1), m.end()
    return None


def parse_refs(text: str) -> tuple[Ref, ...]:
    """Section references at the start of `text` (what follows the cited file name)."""
    refs: list[Ref] = []
    pos = 0
    first = True
    while True:
        if not first:
            sep = _SEP.match(text, pos)
            if not sep:
                break
            nxt = _ref_at(text, sep.end())
            if nxt is None:
                break
        else:
            nxt = _ref_at(text, pos)
            if nxt is None:
                break
        first = False
        section, pos = nxt
        kw = {}
        q = _QUAL.match(text, pos)
        if q:
            kw = {
                "item": q.group("item"),
                "criterion": q.group("crit"),
                "plant": q.group("plant"),
                "method": q.group("method"),
                "quote": q.group("quote"),
            }
            pos = q.end()
        refs.append(Ref(section, **kw))
    return tuple(refs)


def _text_files():
    for dirpath, dirnames, filenames in os.walk(ROOT):
        dirnames[:] = [d for d in dirnames if d not in SKIP_DIRS and not d.endswith(".egg-info")]
        for name in filenames:
            p = Path(dirpath) / name
            if p.suffix in TEXT_SUFFIXES or name in TEXT_NAMES:
                yield p


def find_citations() -> list[Citation]:
    out: list[Citation] = []
    for p in _text_files():
        try:
            lines = p.read_text(encoding="utf-8").splitlines()
        except (UnicodeDecodeError, OSError):
            continue
        rel = p.relative_to(ROOT).as_posix()
        for i, line in enumerate(lines):
            for m in CITE.finditer(line):
                rest = line[m.end() :]
                if i + 1 < len(lines):  # a reference list may continue on the next line
                    rest = rest + " " + _COMMENT_LEAD.sub("", lines[i + 1])
                rest = re.sub(r"\s+", " ", rest)
                out.append(Citation(rel, i + 1, m.group(1), parse_refs(rest), line.strip()))
    return out


# --- the document -------------------------------------------------------------------------


def _normalize(s: str) -> str:
    s = s.lower().replace("σ", "sigma").replace("ω", "omega")
    s = re.sub(r"[\\${}_`*]", "", s)
    return re.sub(r"\s+", " ", s).strip()


@dataclass
class Document:
    sections: dict[str, str]  # id -> text of the section (subsections included for top level)
    items11: set[str]
    criteria103: set[str]
    file_symbols: list[tuple[str, str, int]]
    paths: list[tuple[str, int]]
    equation_rows: dict[str, str]


def load_document() -> Document:
    text = DOC.read_text(encoding="utf-8")
    lines = text.splitlines()
    heads: list[tuple[int, str]] = []
    for i, line in enumerate(lines):
        m = re.match(r"^(#{2,3})\s+(?:(\d+(?:\.\d+)?)\.?\s|Appendix\s+([A-Z])\b)", line)
        if m:
            heads.append((i, m.group(2) or m.group(3)))
    sections: dict[str, str] = {}
    for j, (i, sid) in enumerate(heads):
        if "." in sid:
            end = heads[j + 1][0] if j + 1 < len(heads) else len(lines)
        else:  # a top-level section runs to the next top-level one
            end = next((k for k, s in heads[j + 1 :] if "." not in s), len(lines))
        sections[sid] = "\n".join(lines[i:end])

    def numbered(sid: str) -> set[str]:
        return set(re.findall(r"^(\d+)\.\s", sections.get(sid, ""), flags=re.MULTILINE))

    file_symbols, paths = [], []
    for n, line in enumerate(lines, 1):
        for m in re.finditer(r"`([A-Za-z0-9_./*-]+\.[A-Za-z]+):([A-Za-z_~][\w:.~]*)`", line):
            file_symbols.append((m.group(1), m.group(2), n))
        for m in re.finditer(r"`([A-Za-z0-9_.*-]+(?:/[A-Za-z0-9_.*-]*)+)`", line):
            paths.append((m.group(1), n))
    rows = {}
    for line in sections.get("B", "").splitlines():
        m = re.match(r"^\|\s*(\d+(?:–\d+)?|L\d+)\s*\|", line)
        if m:
            rows[m.group(1)] = line
    return Document(sections, numbered("11"), numbered("10.3"), file_symbols, paths, rows)


def citation_problems(doc: Document, citations: list[Citation]) -> list[str]:
    problems = []
    for c in citations:
        where = f"{c.path}:{c.line}"
        if c.name == MISSING_NAME:
            problems.append(f"{where}: cites {MISSING_NAME}, which the repository does not contain")
        for r in c.refs:
            body = doc.sections.get(r.section)
            if body is None:
                problems.append(f"{where}: §{r.section} does not exist in docs/model.md")
                continue
            if r.item and r.section == "11" and r.item not in doc.items11:
                problems.append(f"{where}: §11 has no item {r.item}")
            if r.criterion and r.criterion not in doc.criteria103:
                problems.append(f"{where}: §10.3 has no criterion {r.criterion}")
            if r.plant and f"({r.plant})" not in body:
                problems.append(f"{where}: §{r.section} has no plant ({r.plant})")
            if r.method and f"method {r.method}".lower() not in body.lower():
                problems.append(f"{where}: §{r.section} has no method {r.method}")
            if r.quote and _normalize(r.quote) not in _normalize(body):
                problems.append(f"{where}: §{r.section} does not contain {r.quote!r}")
    return problems


def _symbol_present(source: str, symbol: str, path: str = "") -> bool:
    # A qualified C++ symbol cited in a .cpp file must be defined there as written
    # (`Class::member`), so a member moved to another translation unit is reported.
    if path.endswith(".cpp") and "::" in symbol:
        return re.search(r"(?<![\w])" + re.escape(symbol) + r"(?![\w])", source) is not None
    return all(
        re.search(r"(?<![\w])" + re.escape(part) + r"(?![\w])", source)
        for part in re.split(r"::|\.", symbol)
        if part
    )


def mapping_problems(doc: Document) -> list[str]:
    problems = []
    for path, symbol, n in doc.file_symbols:
        f = ROOT / path
        if not f.is_file():
            problems.append(f"docs/model.md:{n}: `{path}:{symbol}`: no file {path}")
        elif not _symbol_present(f.read_text(encoding="utf-8"), symbol, path):
            problems.append(f"docs/model.md:{n}: `{path}:{symbol}`: {symbol} not found in {path}")
    for path, n in doc.paths:
        if "://" in path or path.startswith("."):
            continue
        if not glob.glob(str(ROOT / path.rstrip("/"))):
            problems.append(f"docs/model.md:{n}: `{path}` does not exist")
    return problems


# Equations the code implements (24-31 are the observability proof).
IMPLEMENTED = [str(n) for n in range(1, 24)] + [str(n) for n in range(32, 38)]
# Relations lugrip adds beyond the article (rows L1, L2, ... of Appendix B): the ellipse, the
# shifted limit surface, the outputs past the CoR clip, the regularised refinement, the slope
# gains, the feed-forward floor and slip reflex.
ADDED = [f"L{n}" for n in range(1, 7)]


def equation_problems(doc: Document) -> list[str]:
    problems = []
    for eq in IMPLEMENTED + ADDED:
        row = doc.equation_rows.get(eq)
        if row is None:
            problems.append(f"Appendix B: equation {eq} is missing")
        elif not re.search(r"`[^`]+\.[a-z]+:[^`]+`", row):
            problems.append(f"Appendix B: equation {eq} lists no file:symbol")
    if "24–31" not in doc.equation_rows:
        problems.append("Appendix B: equations 24–31 (observability proof) are not listed")
    return problems


# --- tests --------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def doc() -> Document:
    return load_document()


@pytest.fixture(scope="module")
def citations() -> list[Citation]:
    return find_citations()


def test_reference_parser():
    """The parser reads the citation forms used in the repository (and stops where they end)."""
    assert parse_refs(" 7.4, 8.1): eq. 32") == (Ref("7.4"), Ref("8.1"))
    assert parse_refs(" section 11, item 9).") == (Ref("11", item="9"),)
    assert parse_refs(" §11 item 6). Table") == (Ref("11", item="6"),)
    assert parse_refs(" Appendix A and 10.2.") == (Ref("A"), Ref("10.2"))
    assert parse_refs(" 10.1 (b))") == (Ref("10.1", plant="b"),)
    assert parse_refs(" 3.3, method A, with") == (Ref("3.3", method="A"),)
    assert parse_refs(" 10.3 criterion 6).") == (Ref("10.3", criterion="6"),)
    assert parse_refs(' 7.4 "scale the gain with sigma_1")') == (
        Ref("7.4", quote="scale the gain with sigma_1"),
    )
    assert parse_refs(" §6-7): the RMSE") == (Ref("6"), Ref("7"))
    assert parse_refs(" 9.7 / 10.1: the plant") == (Ref("9.7"), Ref("10.1"))
    assert parse_refs(" 10.1: 0.005 N, 0.01 N mm") == (Ref("10.1"),)
    assert parse_refs(" 8.1, eqs. 32-33)") == (Ref("8.1"),)
    assert parse_refs(" 10.1 (0.005 N and") == (Ref("10.1"),)
    assert parse_refs(" / params.hpp.") == ()
    assert parse_refs(", cited below by section)") == ()


def test_document_has_the_numbered_sections(doc):
    """Every section number of the numbering the repository cites exists."""
    expected = {
        "1",
        "1.1",
        "1.2",
        "1.3",
        "1.4",
        "2",
        "2.1",
        "2.2",
        "2.3",
        "3",
        "3.1",
        "3.2",
        "3.3",
        "3.4",
        "4",
        "5",
        "5.1",
        "5.2",
        "5.3",
        "5.4",
        "5.5",
        "5.6",
        "5.7",
        "6",
        "7",
        "7.1",
        "7.2",
        "7.3",
        "7.4",
        "8",
        "8.1",
        "8.2",
        "9",
        "9.1",
        "9.2",
        "9.3",
        "9.4",
        "9.5",
        "9.6",
        "9.7",
        "9.8",
        "9.9",
        "10",
        "10.1",
        "10.2",
        "10.3",
        "11",
        "A",
        "B",
    }
    assert expected <= set(doc.sections), sorted(expected - set(doc.sections))
    assert doc.items11 == {str(i) for i in range(1, 17)}
    assert doc.criteria103 == {str(i) for i in range(1, 7)}


def test_citations_point_to_existing_sections(doc, citations):
    """Every citation of the model document names a file and sections that exist."""
    assert len(citations) > 50  # the scan found the repository's citations
    problems = citation_problems(doc, citations)
    assert not problems, "\n".join(problems)


def test_mapped_symbols_exist(doc):
    """Every `file:symbol` and path of docs/model.md exists (stale mappings fail here)."""
    assert len(doc.file_symbols) > 100
    problems = mapping_problems(doc)
    assert not problems, "\n".join(problems)


def test_every_implemented_equation_is_mapped(doc):
    problems = equation_problems(doc)
    assert not problems, "\n".join(problems)


def test_checker_detects_problems(doc):
    """The checks can fail: a missing section, item, symbol and file name are reported."""
    fake = [
        Citation("x.py", 1, "docs/model.md", (Ref("12.1"),), ""),
        Citation("x.py", 2, "docs/model.md", (Ref("11", item="17"),), ""),
        Citation("x.py", 3, MISSING_NAME, (Ref("7.4"),), ""),
        Citation("x.py", 4, "docs/model.md", (Ref("7.4", quote="no such phrase here"),), ""),
    ]
    assert len(citation_problems(doc, fake)) == 4
    broken = Document(
        doc.sections,
        doc.items11,
        doc.criteria103,
        [
            ("src/observer.cpp", "Observer::no_such_method", 1),
            ("src/no_such_file.cpp", "f", 2),
            # called in grasp_plant.cpp, but defined in grasp_plant_lumped.cpp
            ("src/grasp_plant.cpp", "GraspPlant::substep_lumped", 4),
        ],
        [("src/nowhere/", 3)],
        {},
    )
    assert len(mapping_problems(broken)) == 4
    assert len(equation_problems(broken)) == len(IMPLEMENTED) + len(ADDED) + 1


def main() -> int:
    doc = load_document()
    cites = find_citations()
    for c in cites:
        refs = ", ".join(r.section + (f" item {r.item}" if r.item else "") for r in c.refs)
        print(f"{c.path}:{c.line}: {c.name} [{refs or '-'}]")
    problems = citation_problems(doc, cites) + mapping_problems(doc) + equation_problems(doc)
    print(
        f"\n{len(cites)} citations, {len(doc.file_symbols)} file:symbol mappings, "
        f"{len(problems)} problems"
    )
    for p in problems:
        print(p)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
