"""The settings tables of the documentation are the C++ field tables
(include/lugrip/settings_fields.hpp) as the bindings expose them (``_core.<Struct>.params``):
README.md's and docs/*.md's generated blocks equal what ``lugrip._field_docs`` prints from the
compiled tables now (a changed default, unit, range or doc line fails until the pages are
regenerated with ``python -m lugrip._field_docs``); the ranges in the tables are what
``validate`` enforces at their numeric bounds (the bound accepted when closed, refused when
open; a step beyond refused); the printed form (``repr``, C++ ``to_string``) lists every field of
the table with its value. The grasp controller's settings keep their own hand-written table,
checked against the compiled defaults. No plant is involved."""

from __future__ import annotations

import math
import re
from pathlib import Path

import pytest
from lugrip import _core, _field_docs

REPO = Path(__file__).resolve().parents[2]


def _blocks(text: str) -> list[str]:
    return re.findall(r"<!-- field-table: (\w+)", text)


def test_pages_print_the_field_tables_as_compiled():
    """Every generated block of README.md and docs/*.md equals the table generated from the
    compiled field tables; the site prints every struct of ``_field_docs.STRUCTS``."""
    printed = []
    stale = []
    for page in _field_docs.pages(REPO):
        text = page.read_text()
        printed += _blocks(text)
        if _field_docs.render_blocks(text) != text:
            stale.append(page.name)
    assert not stale, f"regenerate with `python -m lugrip._field_docs`: {stale}"
    assert sorted(set(printed)) == sorted((*_field_docs.STRUCTS, "GraspControllerSettings"))
    assert _blocks((REPO / "README.md").read_text()) == ["ContactParams", "GraspControllerSettings"]
    # the fields a file must give read "required" (their defaults are refused by validate())
    readme = _field_docs.markdown_table("ContactParams")
    assert readme.count("| required |") == 6 and "| `k` |" in readme


def test_a_changed_table_is_found():
    """The check is not vacuous: a page whose block disagrees with the compiled table in one
    default (ObserverSettings.dt 0.002 written as 0.004) is rewritten, and the rewritten block
    holds the compiled default."""
    text = (REPO / "docs" / "conventions.md").read_text()
    row = next(ln for ln in text.splitlines() if ln.startswith("| `dt` |"))
    assert row.endswith("| 0.002 |")
    mutated = text.replace(row, row.replace("| 0.002 |", "| 0.004 |"))
    assert _field_docs.render_blocks(mutated) == text
    rows = [ln for ln in _field_docs.markdown_table("ObserverSettings").splitlines() if ln.startswith("| `")]
    assert len(rows) == len(_core.ObserverSettings.params)


def test_number_texts_read_back():
    """The table's number texts read back as the same double."""
    for v in (0.002, 1e-9, 1e15, 4.9e9, 16.66, 0.0018, 1e-4, 500.0, 1e4, 1.0 / 3.0, 2e-5):
        assert float(_field_docs.number(v)) == v, v
    assert _field_docs.number(math.inf) == "∞"


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


def _base(struct: str):
    return _core.table1_params() if struct == "ContactParams" else getattr(_core, struct)()


@pytest.mark.parametrize("struct", _field_docs.STRUCTS)
def test_ranges_of_the_table_are_what_validate_enforces(struct):
    """At each finite numeric bound of the table: the bound itself accepted when closed and
    refused when open, a step beyond refused, by validate() naming the field with its own
    range (not a rule between fields); the defaults lie inside their ranges (ContactParams:
    Table 1's values)."""
    validate = getattr(_core, VALIDATORS[struct])
    cls = getattr(_core, struct)
    assert validate(_base(struct)) == ""
    checked = 0
    for p in cls.params:
        if p["kind"] not in ("float", "int"):
            continue
        integer = p["kind"] == "int"
        for side, limit in ((-1, p["lo"]), (+1, p["hi"])):
            if limit["value"] is None or math.isinf(limit["value"]):
                continue
            at = int(limit["value"]) if integer else limit["value"]
            step = 1 if integer else max(abs(at) * 1e-9, 1e-15)
            make = lambda: _base(struct)  # noqa: E731
            assert _refused(validate, make, p["name"], at) is limit["open"], (p["name"], at)
            assert _refused(validate, make, p["name"], at + side * step), (p["name"], at)
            checked += 1
    assert checked >= {"ContactParams": 12, "CorSettings": 5, "ObserverSettings": 25}.get(struct, 2)


VALIDATORS = {
    "ContactParams": "validate_params",
    "CorSettings": "validate_cor_settings",
    "ObserverSettings": "validate_observer_settings",
    "SliderSettings": "validate_slider_settings",
    "IdentificationSettings": "validate_identification_settings",
    "SlipControlSettings": "validate_slip_control_settings",
}


def test_validate_messages_carry_the_tables_unit_and_range():
    """A bad value's line names the field, the value, the range and the unit of the table."""
    s = _core.ObserverSettings()
    s.dt = 0.0
    assert _core.validate_observer_settings(s) == "dt = 0: must be finite, >= 1e-09 and <= 10 [s]\n"
    s.dt = 0.1  # valid on its own, above max_dt_gap: the rule between the two
    assert _core.validate_observer_settings(s) == "max_dt_gap = 0.05: must be >= dt [s]\n"
    p = _core.table1_params()
    p.gamma = 0.5
    assert _core.validate_params(p) == "gamma = 0.5: must be finite, > 0 and < 1/3 [-]\n"
    p = _core.table1_params()
    p.k = 0.2
    assert _core.validate_params(p) == ("k = 0.2: must be >= 0.5 or 0 (the elliptic limit surface, "
                                       "docs/model.md 3.5) [-]\n")


@pytest.mark.parametrize("struct", _field_docs.STRUCTS)
def test_printed_form_lists_every_field_of_the_table(struct):
    """repr (C++ to_string) is "Struct(name=value, ...)" over the table's fields in order, each
    number reading back as the attribute's value."""
    obj = _base(struct)
    text = repr(obj)
    assert text.startswith(struct + "(")
    top = re.sub(r"\w+\((?:[^()]|\([^()]*\))*\)", "(...)", text[len(struct) + 1:-1])
    pairs = [part.split("=", 1) for part in top.split(", ")]
    assert [name for name, _ in pairs] == [p["name"] for p in type(obj).params]
    for name, value in pairs:
        attr = getattr(obj, name)
        if isinstance(attr, bool):
            assert value == str(attr)
        elif isinstance(attr, (int, float)):
            assert eval(value, {"float": float}) == attr, (name, value)  # noqa: S307


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


def test_python_contact_params_follow_the_table():
    """The Python ContactParams dataclass has the fields of the C++ table in its order, and a
    file must give exactly the fields a default-constructed C++ struct leaves out of range."""
    import dataclasses

    import lugrip
    from lugrip import _params

    names = [p["name"] for p in _core.ContactParams.params]
    assert [f.name for f in dataclasses.fields(lugrip.ContactParams)] == names
    assert _params._REQUIRED == ("mu", "beta_a", "sigma0", "sigma_z", "delta", "gamma")
    with pytest.raises(ValueError, match="missing parameter"):
        lugrip.ContactParams.from_dict({"mu": 0.5})


def test_readme_prints_the_controller_settings_one_line_each():
    """README.md's controller table: one row per field of the core's table
    (lugrip/grasp_controller_fields.hpp), in its order, with the compiled default; the paper's
    column reads "same" exactly where paper_settings() keeps lugrip's default."""
    text = (REPO / "README.md").read_text()
    block = text.split("<!-- field-table: GraspControllerSettings -->")[1].split("<!-- /field-table -->")[0]
    rows = [line for line in block.splitlines() if line.startswith("| `")]
    names = [r.split("`")[1] for r in rows]
    assert names == [f[0] for f in _core.GraspControllerSettings.fields]
    assert len(names) <= 20
    default, paper = _core.GraspControllerSettings(), _core.paper_settings()
    for row, (name, kind, _doc) in zip(rows, _core.GraspControllerSettings.fields):
        cells = [c.strip() for c in row.strip("|").split("|")]
        if kind == "bool":
            assert cells[3] == ("on" if getattr(default, name) else "off"), row
        else:
            assert float(cells[3]) == pytest.approx(getattr(default, name), rel=1e-12), row
        assert (cells[4] == "same") == (getattr(paper, name) == getattr(default, name)), row
