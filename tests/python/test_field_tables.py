"""The settings tables written by hand beside the code agree with the code: the field tables of
the headers (``//! | field | meaning | unit | range | default |`` in include/lugrip/contact.hpp
and observer.hpp) and of docs/conventions.md (ContactParams, CorSettings) list exactly the fields
of the bindings' tables (``_core.<Struct>.fields``, bindings/tables.hpp), with the defaults the
compiled structs hold, the units of the bindings' docs, and ranges that ``validate`` enforces at
their numeric bounds (the bound accepted when closed, refused when open; a step beyond refused).
The grasp controller's settings are left to their own tables (they are being reworked). No plant
is involved."""

from __future__ import annotations

import math
import re
from pathlib import Path

import pytest
from lugrip import _core

REPO = Path(__file__).resolve().parents[2]


def _table(text: str, prefix: str, header: str) -> list[list[str]]:
    """Rows (cells stripped) of the Markdown table whose header row starts with ``header``;
    ``prefix`` is what each line starts with (``//! `` in a header, nothing in a page)."""
    lines = [ln[len(prefix):] if ln.startswith(prefix) else None for ln in text.splitlines()]
    start = next(i for i, ln in enumerate(lines) if ln is not None and ln.startswith(header))
    rows = []
    for ln in lines[start + 2:]:
        if ln is None or not ln.startswith("|"):
            break
        # five columns; a pipe inside the meaning (|f_n|, |c~|) belongs to the meaning
        cells = [c.strip() for c in ln.strip()[1:-1].split("|")]
        cells = [cells[0], "|".join(cells[1:-3]).strip(), *cells[-3:]]
        rows.append([c.strip("`") for c in cells])
    return rows


def _header_rows(header: str, after: str) -> dict[str, list[str]]:
    """{field: [meaning, unit, range, default]} of the header table following ``after``."""
    text = (REPO / "include" / "lugrip" / header).read_text()
    text = text[text.index(after):]
    out = {}
    for name, meaning, unit, rng, default in _table(text, "//! ", "| field | meaning"):
        names = [n.strip() for n in name.split(",")]
        defaults = [d.strip() for d in default.split(",")] if len(names) > 1 else [default]
        for n, d in zip(names, defaults):
            out[n] = [meaning, unit, rng, d]
    return out


def _number(text: str) -> float | None:
    text = text.replace("∞", "inf").replace("−", "-")
    try:
        return float(text)
    except ValueError:
        return None


def _default_matches(value, text: str) -> bool:
    if isinstance(value, bool):
        return text.lower() == str(value).lower()
    if isinstance(value, (int, float)):
        number = _number(text)
        return number is not None and math.isclose(float(value), number, rel_tol=1e-12)
    return text == str(value).split(".")[-1]  # an enum: its name


def _unit_of_doc(doc: str) -> str | None:
    m = re.search(r"\[([^\]]+)\]\s*$", doc)
    return None if m is None else m.group(1)


def _bounds(rng: str) -> list[tuple[float, bool, int]]:
    """Numeric bounds of a range cell: (value, closed, side) with side -1 lower, +1 upper.
    Bounds that name another field ("[dt, 10]") are skipped."""
    rng = rng.replace("≥", ">=").replace("≤", "<=").replace("∞", "inf")
    out = []
    m = re.fullmatch(r"([\[(])\s*([^,]+),\s*([^\])]+)([\])])", rng.strip())
    if m:
        lo, hi = _number(m.group(2)), _number(m.group(3))
        if lo is not None:
            out.append((lo, m.group(1) == "[", -1))
        if hi is not None and math.isfinite(hi):
            out.append((hi, m.group(4) == "]", +1))
        return out
    m = re.fullmatch(r"(>=|>)\s*(\S+)", rng.strip())
    if m and _number(m.group(2)) is not None:
        out.append((_number(m.group(2)), m.group(1) == ">=", -1))
    return out


def _refused(validate, make, field: str, value) -> bool:
    """validate() refuses ``field`` = ``value`` for its own range: a line naming the field
    whose reason states the range ("must be finite, ...", "must satisfy ...") or names no
    other field ("static_ratio ... must be >= kinetic_ratio" is another rule)."""
    obj = make()
    setattr(obj, field, value)
    others = [f[0] for f in type(obj).fields if f[0] != field]
    for line in validate(obj).splitlines():
        head, _, reason = line.partition(":")
        if not head.startswith(f"{field} = "):
            continue
        reason = reason.split("[")[0]  # the unit may spell a field's name (m/N^gamma)
        if "finite" in reason or "satisfy" in reason or not any(
                re.search(rf"\b{o}\b", reason) for o in others):
            return True
    return False


def _check_ranges(validate, make, field: str, rng: str, integer: bool) -> int:
    checked = 0
    for bound, closed, side in _bounds(rng):
        step = 1 if integer else max(abs(bound) * 1e-9, 1e-15)
        at = int(bound) if integer else bound
        assert _refused(validate, make, field, at) is (not closed), (field, rng, at)
        beyond = at + side * step
        assert _refused(validate, make, field, beyond), (field, rng, beyond)
        checked += 1
    return checked


STRUCTS = [
    ("CorSettings", "contact.hpp", "//! Per-sample settings of the CoR estimator",
     _core.validate_cor_settings),
    ("ObserverSettings", "observer.hpp", "//! Observer settings", _core.validate_observer_settings),
]


@pytest.mark.parametrize("name,header,after,validate", STRUCTS, ids=[s[0] for s in STRUCTS])
def test_header_table_matches_the_struct(name, header, after, validate):
    """Names, defaults, units and numeric ranges of the header's table against the bindings'
    field table, the default-constructed struct and validate()."""
    cls = getattr(_core, name)
    rows = _header_rows(header, after)
    fields = {f[0]: f for f in cls.fields}
    assert set(rows) == set(fields), (sorted(set(rows) ^ set(fields)))
    default = cls()
    checked = 0
    for field, (_meaning, unit, rng, text) in rows.items():
        kind = fields[field][1]
        if kind == "struct":
            continue
        assert _default_matches(getattr(default, field), text), (field, text)
        doc_unit = _unit_of_doc(fields[field][2])
        if doc_unit is not None:
            assert doc_unit == unit, (field, doc_unit, unit)
        if kind in ("float", "int"):
            checked += _check_ranges(validate, cls, field, rng, kind == "int")
    assert checked >= 5


def _page_rows(title: str) -> dict[str, list[str]]:
    text = (REPO / "docs" / "conventions.md").read_text()
    text = text[text.index(title):]
    return {r[0]: r[1:] for r in _table(text, "", "| field | meaning")}


def test_docs_contact_params_table_matches_the_struct():
    """docs/conventions.md's ContactParams table: every field of the bindings' table, Table 1's
    values, and the numeric ranges validate() enforces."""
    rows = _page_rows("## Parameters (`ContactParams`)")
    fields = {f[0] for f in _core.ContactParams.fields}
    assert set(rows) == fields, sorted(set(rows) ^ fields)
    table1 = _core.table1_params()
    checked = 0
    for field, (_meaning, _unit, rng, value) in rows.items():
        assert _default_matches(getattr(table1, field), value), (field, value)
        checked += _check_ranges(_core.validate_params, _core.table1_params, field,
                                 rng.split(" or ")[0], False)
    assert checked >= 8


def test_docs_cor_settings_table_matches_the_struct():
    """docs/conventions.md's CorSettings table: the fields and defaults of the struct."""
    rows = _page_rows("### `CorSettings`")
    fields = {f[0] for f in _core.CorSettings.fields}
    assert set(rows) == fields, sorted(set(rows) ^ fields)
    default = _core.CorSettings()
    for field, (_meaning, _unit, rng, value) in rows.items():
        assert _default_matches(getattr(default, field), value), (field, value)
        _check_ranges(_core.validate_cor_settings, _core.CorSettings, field, rng, False)


def test_docs_controller_table_names_real_settings_with_their_defaults():
    """docs/conventions.md's table of the controller's additions to the paper: every row is a
    field of GraspControllerSettings (the core's table, lugrip/grasp_controller_fields.hpp, as
    the bindings expose it) and its default column starts with the compiled default ("on"/"off"
    for a switch, a number with its unit otherwise). A field renamed or a default changed in
    the code without the page fails here."""
    text = (REPO / "docs" / "conventions.md").read_text()
    start = text.index("| setting | default | what it does |")
    rows = {}
    for line in text[start:].splitlines()[2:]:
        if not line.startswith("| `"):
            break
        cells = [c.strip() for c in line.strip("|").split("|")]
        rows[cells[0].strip("`")] = cells[1]
    assert len(rows) >= 7  # the additions to the paper's law (docs/controller.md §0)
    fields = {f[0]: f[1] for f in _core.GraspControllerSettings.fields}
    assert set(rows) <= set(fields), sorted(set(rows) - set(fields))
    default = _core.GraspControllerSettings()
    for name, text_default in rows.items():
        value = getattr(default, name)
        first = text_default.split()[0]
        if fields[name] == "bool":
            assert first == ("on" if value else "off"), (name, text_default)
        else:
            assert float(first) == pytest.approx(value, rel=1e-12), (name, text_default)
