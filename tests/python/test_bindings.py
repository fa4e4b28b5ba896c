"""The field tables of the binding (bindings/tables.hpp) against the C++ headers: every data
member of every bound struct has exactly one table entry, in declaration order, so a member
added to a header and forgotten in the table fails here (it is how ``cor_side_flipped`` went
missing). Parsing check of the source text, no physics."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from lugrip import _core

INCLUDE = Path(__file__).resolve().parents[2] / "include" / "lugrip"

# struct -> (header, members deliberately not in the table: bound by hand)
STRUCTS = {
    "ContactParams": ("params.hpp", set()),
    "CorSettings": ("contact.hpp", set()),
    "CorOutput": ("contact.hpp", set()),
    "ObserverSettings": ("observer.hpp", set()),
    "ObserverOutput": ("observer.hpp", set()),
    "SliderSettings": ("slider_model.hpp", set()),
    "SliderOutput": ("slider_model.hpp", set()),
    "GraspControllerSettings": ("grasp_controller.hpp", set()),
    "GraspControllerOutput": ("grasp_controller.hpp", set()),
    "SlipControlSettings": ("slip_control.hpp", set()),
    "SlipControlOutput": ("slip_control.hpp", {"fingers"}),  # a property returning a tuple
    "FingerSample": ("grasp_plant.hpp", set()),
    "PlantState": ("grasp_plant.hpp", set()),
    "SensorConfig": ("grasp_plant.hpp", {"bias"}),  # get_bias / set_bias
    "PlantConfig": ("grasp_plant.hpp", {"moves", "disturbances"}),  # add_move / add_disturbance
    "ClosedLoopConfig": ("closed_loop.hpp", {"schedule", "faults"}),  # add_event, add_fault
    "FaultSpec": ("closed_loop.hpp", set()),
    "ClosedLoopSample": ("closed_loop.hpp", set()),
}


def members(header: str, struct: str) -> list[str]:
    text = (INCLUDE / header).read_text()
    m = re.search(r"^struct " + struct + r" \{\n(.*?)^\};", text, re.S | re.M)
    assert m, f"struct {struct} not found in {header}"
    body = "\n".join(line.split("//")[0] for line in m.group(1).splitlines())
    names = []
    for stmt in body.split(";"):
        stmt = " ".join(stmt.split())
        if not stmt or "(" in stmt.split("=")[0] or stmt.startswith(("static", "using")):
            continue
        # "double f_n = 0.0, f_x = 0.0" -> f_n, f_x; "std::array<...> x{}" -> x
        decl = re.sub(r"<[^<>]*(<[^<>]*>[^<>]*)*>", "", stmt)
        for part in decl.split(","):
            ident = re.findall(r"([A-Za-z_]\w*)\s*(?:=|\{|$)", part.strip())
            if ident:
                names.append(ident[0])
    return names


@pytest.mark.parametrize("struct", sorted(STRUCTS))
def test_table_lists_every_member_once_in_order(struct):
    header, by_hand = STRUCTS[struct]
    declared = [n for n in members(header, struct) if n not in by_hand]
    table = [name for name, _kind, _doc in getattr(_core, struct).fields]
    renamed = {"ClosedLoopSample": {"S": "slippage"}}.get(struct, {})  # Python name: S
    assert [renamed.get(name, name) for name in table] == declared


def test_kinds_are_known_and_docs_present():
    for struct in STRUCTS:
        for name, kind, doc in getattr(_core, struct).fields:
            assert kind in {"float", "int", "bool", "enum", "pair", "struct"}, (struct, name)
            assert isinstance(doc, str)
