"""The parameter tables of the documentation, generated from the C++ field tables.

Every settings struct a user sets is described once in the core
(``include/lugrip/settings_fields.hpp``): name, unit, valid range, one doc line, and rules
between fields; the bindings expose that table as ``_core.<Struct>.params`` and ``.rules``, the
defaults are the default-constructed struct's. A Markdown page holds a generated table between

    <!-- field-table: ObserverSettings -->
    ...
    <!-- /field-table -->

(``<!-- field-table: ContactParams values=table1 -->`` prints paper Table 1's values instead of
the defaults; a default the struct's validate() refuses reads "required"). ``python -m lugrip._field_docs`` rewrites every such block of README.md and
docs/*.md; ``--check`` exits 1 naming the blocks that differ (tests/python/test_field_tables.py
runs the check).
"""

from __future__ import annotations

import argparse
import math
import re
import sys
from pathlib import Path

from . import _core

__all__ = ["STRUCTS", "controller_table", "markdown_table", "render_blocks"]

#: The structs whose tables the documentation may print.
STRUCTS = ("ContactParams", "CorSettings", "ObserverSettings", "SliderSettings",
           "IdentificationSettings", "SlipControlSettings")

_VALIDATORS = {"ContactParams": "validate_params", "CorSettings": "validate_cor_settings",
               "ObserverSettings": "validate_observer_settings"}

_BLOCK = re.compile(r"(<!-- field-table: (\w+)((?: \w+=\w+)*) -->\n)(.*?)(<!-- /field-table -->)", re.S)


def number(value: float) -> str:
    """The shortest text of a number that reads back as the same value: 0.03, 1e-4, 4.9e9, 500."""
    if math.isinf(value):
        return "∞" if value > 0 else "−∞"
    if value == int(value) and abs(value) < 1e4:
        return str(int(value))
    positional = repr(float(value)).removesuffix(".0")
    for digits in range(17):
        text = f"{value:.{digits}e}"
        if float(text) == value:
            break
    mantissa, exponent = text.split("e")
    scientific = f"{mantissa}e{int(exponent)}"
    return positional if 1e-3 <= abs(value) < 1e4 and "e" not in positional else scientific


def _limit(limit: dict) -> str:
    return limit["text"] if limit["text"] is not None else number(limit["value"])


def range_text(param: dict, rules: list[str]) -> str:
    """The valid range as the pages print it: "(0, 10]", "≥ 0", "[0.5, ∞] or 0", with the rules
    between fields after a semicolon."""
    lo, hi = param["lo"], param["hi"]
    if lo["value"] is not None and hi["value"] is not None:
        text = f"{'(' if lo['open'] else '['}{_limit(lo)}, {_limit(hi)}{')' if hi['open'] else ']'}"
    elif lo["value"] is not None:
        text = f"{'>' if lo['open'] else '≥'} {_limit(lo)}"
    elif hi["value"] is not None:
        text = f"{'<' if hi['open'] else '≤'} {_limit(hi)}"
    elif param["choices"]:
        text = ", ".join(f"`{c}`" for c in param["choices"])
    else:
        text = ""
    if param["also_text"]:
        text += f" or {param['also_text']}"
    for rule in rules:
        text += f"; {rule}" if text else rule
    return text


def _value(param: dict, value) -> str:
    if param["kind"] == "bool":
        return "on" if value else "off"
    if param["kind"] == "enum":
        return f"`{param['choices'][int(getattr(value, 'value', value))]}`"
    if param["kind"] == "struct":
        return f"`{type(value).__name__}()`"
    return number(value)


def _cell(text: str) -> str:
    return text.replace("|", "\\|")


def markdown_table(struct: str, values: str = "default") -> str:
    """The Markdown table of one struct: field, meaning, unit, valid range, and the default (or,
    with ``values="table1"``, paper Table 1's value)."""
    if struct not in STRUCTS:
        raise ValueError(f"no field table for {struct!r} (known: {', '.join(STRUCTS)})")
    cls = getattr(_core, struct)
    if values == "table1":
        source, header = _core.table1_params(), "Table 1"
    elif values == "default":
        source, header = cls(), "default"
    else:
        raise ValueError(f"values={values!r}: expected default or table1")
    rules: dict[str, list[str]] = {}
    for field, text in cls.rules:
        # "must be >= dt" -> "≥ dt"; a nested field's rule names it ("f_n_min ≥ 1e-06 [N] ...")
        text = text.replace("must be ", "").replace("must equal ", "= ").replace(">=", "≥").replace("<=", "≤")
        rules.setdefault(field, []).append(text if "." not in field else f"{field.split('.', 1)[1]} {text}")
    # a default the struct's own validate() refuses is no default: a file must give the field
    required = set()
    if values == "default" and struct in _VALIDATORS:
        message = getattr(_core, _VALIDATORS[struct])(source)
        required = {line.split(" = ")[0] for line in message.splitlines()}
    lines = [f"| field | meaning | unit | valid range | {header} |", "|---|---|---|---|---|"]
    for p in cls.params:
        unit = {"-": "–", "": ""}.get(p["unit"], p["unit"])
        own = rules.get(p["name"], []) + [r for f, texts in rules.items() if f.split(".")[0] == p["name"]
                                          and f != p["name"] for r in texts]
        lines.append(f"| `{p['name']}` | {_cell(p['doc'])} | {unit} | {_cell(range_text(p, own))} | "
                     f"{'required' if p['name'] in required else _value(p, getattr(source, p['name']))} |")
    return "\n".join(lines) + "\n"


def controller_table() -> str:
    """The grasp controller's settings, one line each, from its own C++ table
    (``lugrip/grasp_controller_fields.hpp``: name and doc with the unit): setting, what it does,
    unit, lugrip's default and the paper's law's value (``paper_settings()``) where it differs."""
    default, paper = _core.GraspControllerSettings(), _core.paper_settings()
    lines = ["| setting | what it does | unit | default | the paper's law |", "|---|---|---|---|---|"]
    for name, kind, doc in _core.GraspControllerSettings.fields:
        m = re.fullmatch(r"(.*?)\s*\[([^\]]+)\]", doc)
        meaning, unit = (m.group(1), m.group(2)) if m else (doc, "–" if kind != "bool" else "")
        unit = "–" if unit == "-" else unit
        value = {"kind": kind}
        mine, theirs = getattr(default, name), getattr(paper, name)
        lines.append(f"| `{name}` | {_cell(meaning)} | {unit} | {_value(value, mine)} | "
                     f"{_value(value, theirs) if theirs != mine else 'same'} |")
    return "\n".join(lines) + "\n"


def render_blocks(text: str) -> str:
    """``text`` with every field-table block regenerated."""
    def block(m: re.Match) -> str:
        options = dict(o.split("=") for o in m.group(3).split())
        if m.group(2) == "GraspControllerSettings":
            return m.group(1) + controller_table() + m.group(5)
        return m.group(1) + markdown_table(m.group(2), **options) + m.group(5)
    return _BLOCK.sub(block, text)


def pages(root: Path) -> list[Path]:
    """README.md and the site's pages."""
    return [root / "README.md", *sorted((root / "docs").glob("*.md"))]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m lugrip._field_docs", description=__doc__.split("\n")[0])
    parser.add_argument("root", nargs="?", default=".", type=Path, help="the source tree (default: .)")
    parser.add_argument("--check", action="store_true", help="write nothing; exit 1 when a table differs")
    args = parser.parse_args(argv)
    stale = []
    for page in pages(args.root):
        text = page.read_text()
        new = render_blocks(text)
        if new != text:
            stale.append(page)
            if not args.check:
                page.write_text(new)
    for page in stale:
        print(f"{page}: {'differs from' if args.check else 'rewritten from'} the field tables")
    return 1 if stale and args.check else 0


if __name__ == "__main__":
    sys.exit(main())
