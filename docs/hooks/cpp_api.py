"""MkDocs hook: the C++ API reference page (api/cpp.md) from the public headers.

Every ``include/lugrip/*.hpp`` (``detail/`` is private) becomes a section: the header's opening
comment, then each declaration at namespace scope (struct, class, enum, function, constant,
alias) with the ``//!`` comment above it (Markdown, as the headers write it) and its
declaration line; a struct's or enum's members are listed with their ``//!`` / ``//!<``
comments and defaults. The page's marker ``<!-- cpp-api -->`` is replaced at build time, so the
reference cannot drift from the headers; tests/python/test_docs_site.py checks that every
header and every namespace-scope type appears.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

MARKER = "<!-- cpp-api -->"
ROOT = Path(__file__).resolve().parents[2]
INCLUDE = ROOT / "include" / "lugrip"

_TYPE_RE = re.compile(r"^(struct|class|enum class|enum)\s+(\w+)(\s*:\s*[\w:<> ,]+)?\s*(\{|;)?")
_FUNC_RE = re.compile(r"^(?:inline\s+|constexpr\s+|static\s+|\[\[nodiscard\]\]\s+)*"
                      r"[\w:<>,\s\*&]+?[\s\*&](~?\w+)\s*\(")
_CONST_RE = re.compile(r"^(?:inline\s+)?constexpr\s+[\w:<>]+\s+(\w+)\s*=")
_USING_RE = re.compile(r"^using\s+(\w+)\s*=")
_MEMBER_RE = re.compile(r"^([\w:<>,\s\*&\[\]]+?)\s+(\w+)(\s*\[[^\]]*\])?\s*(?:=\s*([^;]+?))?;"
                        r"\s*(?://!<\s*(.*))?$")
_ENUMERATOR_RE = re.compile(r"^(\w+)\s*(?:=\s*([^,]+?))?,?\s*(?://!<\s*(.*))?$")
_SKIP = ("return ", "if ", "for ", "while ", "switch ", "case ", "public:", "private:",
         "protected:", "friend ", "#", "static_assert")


@dataclass
class Entry:
    kind: str  # struct, class, enum, function, constant, alias, macro
    name: str
    signature: str
    doc: list[str]
    members: list[tuple[str, str, str]] = field(default_factory=list)  # (name, default, doc)


@dataclass
class Header:
    path: Path
    summary: list[str]
    entries: list[Entry]
    includes: list[str] = field(default_factory=list)  # the lugrip headers it includes

    @property
    def include(self) -> str:
        return f"lugrip/{self.path.relative_to(INCLUDE).as_posix()}"


def public_headers() -> list[Path]:
    """The public headers: include/lugrip/*.hpp (detail/ excluded)."""
    return sorted(INCLUDE.glob("*.hpp"))


def _strip_comment(line: str) -> str | None:
    s = line.strip()
    for lead in ("//!", "///", "//"):
        if s.startswith(lead) and not s.startswith("//!<"):
            return s[len(lead):].removeprefix(" ")
    return None


def _code(line: str) -> str:
    """The line without a trailing // comment and string literals (for brace counting)."""
    line = re.sub(r'"(\\.|[^"\\])*"', '""', line)
    return line.split("//", 1)[0]


def parse_header(path: Path) -> Header:
    """Declarations at the lugrip namespace's scope, with their doc comments."""
    lines = path.read_text().splitlines()
    summary: list[str] = []
    i = 0
    while i < len(lines) and _strip_comment(lines[i]) is not None:
        summary.append(_strip_comment(lines[i]) or "")
        i += 1
    entries: list[Entry] = []
    includes = re.findall(r'^#include "(lugrip/[\w/]+\.hpp)"', "\n".join(lines), re.MULTILINE)
    for j, line in enumerate(lines):
        m = re.match(r"^#define (LUGRIP_\w+)\s+(.*)$", line)
        if m:
            above = []
            k = j - 1
            while k >= 0 and _strip_comment(lines[k]) is not None:
                above.insert(0, _strip_comment(lines[k]) or "")
                k -= 1
            entries.append(Entry("macro", m.group(1), line.strip(), above if k >= i else []))
    depth = 0  # brace depth; 1 = inside namespace lugrip
    ns_depth = None
    doc: list[str] = []
    current: Entry | None = None
    member_doc: list[str] = []
    for raw in lines[i:]:
        stripped = raw.strip()
        text = _strip_comment(raw)
        code = _code(raw).strip()
        if text is not None and not code:
            if current is not None and depth == ns_depth + 1:
                member_doc.append(text)
            elif depth == ns_depth:
                doc.append(text)
            continue
        if ns_depth is None:
            if re.match(r"^namespace lugrip\s*\{", stripped):
                ns_depth = depth + 1
            depth += code.count("{") - code.count("}")
            continue
        if depth == ns_depth and code:
            entry = _entry(code, raw, doc)
            if entry is not None:
                entries.append(entry)
                if entry.kind in ("struct", "class", "enum") and "{" in code and "}" not in code:
                    current = entry
            doc = []
        elif current is not None and depth == ns_depth + 1 and code:
            _member(current, code, raw, member_doc)
            member_doc = []
        if not code and text is None and depth == ns_depth:
            doc = []
        depth += code.count("{") - code.count("}")
        if current is not None and depth <= ns_depth:
            current = None
            member_doc = []
        if ns_depth is not None and depth < ns_depth:
            break
    return Header(path, summary, entries, includes)


def _entry(code: str, raw: str, doc: list[str]) -> Entry | None:
    if code.startswith(_SKIP) or code.startswith(("}", "namespace", "template")):
        return None
    m = _TYPE_RE.match(code)
    if m:
        if m.group(4) == ";" or (m.group(4) is None and code.endswith(";")):
            return None  # a forward declaration
        kind = "enum" if m.group(1).startswith("enum") else m.group(1)
        return Entry(kind, m.group(2), code.rstrip("{ ").strip(), list(doc))
    m = _USING_RE.match(code)
    if m:
        return Entry("alias", m.group(1), code.rstrip(";"), list(doc))
    m = _CONST_RE.match(code)
    if m:
        return Entry("constant", m.group(1), code.rstrip(";"), list(doc))
    m = _FUNC_RE.match(code)
    if m and not code.startswith("operator"):
        return Entry("function", m.group(1), code.rstrip("{;").strip(), list(doc))
    return None


def _member(entry: Entry, code: str, raw: str, doc: list[str]) -> None:
    trailing = raw.split("//!<", 1)[1].strip() if "//!<" in raw else ""
    text = " ".join(d for d in [*doc, trailing] if d).strip()
    if entry.kind == "enum":
        m = _ENUMERATOR_RE.match(code)
        if m:
            entry.members.append((m.group(1), (m.group(2) or "").strip(), text))
        return
    if code.startswith(_SKIP) or "(" in code or code.startswith(("}", "{", "using", "template")):
        return
    m = _MEMBER_RE.match(code)
    if m:
        entry.members.append((m.group(2), (m.group(4) or "").strip(), text))


def _cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def render(headers: list[Header] | None = None) -> str:
    """Markdown of the C++ reference."""
    headers = [parse_header(p) for p in public_headers()] if headers is None else headers
    out: list[str] = []
    for h in headers:
        out += [f"## `{h.include}`", ""]
        summary = [s for s in h.summary if s.strip()]
        if summary:
            out += [" ".join(s.strip() for s in summary), ""]
        if not h.entries and h.includes:
            out += ["Includes " + ", ".join(f"`{inc}`" for inc in h.includes) + ".", ""]
        for e in h.entries:
            out += [f"### {e.kind} `{e.name}`", ""]
            if e.doc:
                out += [*e.doc, ""]
            out += ["```cpp", e.signature, "```", ""]
            if e.members:
                out += ["| member | default | |", "|---|---|---|"]
                out += [f"| `{n}` | {('`' + _cell(d) + '`') if d else ''} | {_cell(t)} |"
                        for n, d, t in e.members]
                out += [""]
    return "\n".join(out)


def on_page_markdown(markdown: str, page, config, files) -> str:
    """MkDocs event: the reference in place of the marker (other pages unchanged)."""
    if MARKER in markdown:
        return markdown.replace(MARKER, render())
    return markdown
