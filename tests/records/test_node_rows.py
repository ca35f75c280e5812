"""The node, derived-property, environment-assumption and unverified rows and the shared strength,
limited-by and culprit objects, each defined once (records/node_rows.py, records/derived_rows.py,
records/strength_rows.py): their ``$defs`` entries generated from the classes, the JSON they write
(a field at UNSET left out, the keys in the order the report has always written them), an undeclared
key refused.  In-process and cheap: no pipeline runs here.
"""
from __future__ import annotations

import copy
from typing import Any

import msgspec
import pytest
from jsonschema import Draft202012Validator

from _report_schema import SCHEMA
from rclverify.records import schema_gen
from rclverify.records.derived_rows import DerivedPropertyRow, EnvironmentAssumptionRow
from rclverify.records.node_rows import CulpritOf, GuaranteeRow, NodeRow, UnverifiedRow
from rclverify.records.strength_rows import LimitedBy, Strength


@pytest.mark.parametrize("cls", schema_gen.DEFINED, ids=lambda c: c.__name__)
def test_a_shared_entry_is_generated_from_its_class(cls: type[msgspec.Struct]) -> None:
    assert SCHEMA["$defs"][schema_gen.SHARED[cls.__name__]] == schema_gen.generated_def(cls)


def test_a_field_added_to_a_shared_class_reaches_its_entry(monkeypatch: pytest.MonkeyPatch) -> None:
    class Strength(msgspec.Struct, frozen=True, forbid_unknown_fields=True):  # the name SHARED knows
        """How strong a piece of evidence is (docs/confidence.md)."""
        kind: str
        doubt: float
        margin_added_here: str = ""

    monkeypatch.setattr(schema_gen, "DEFINED", (Strength, LimitedBy, CulpritOf))
    regenerated = schema_gen.with_generated(copy.deepcopy(SCHEMA))
    assert regenerated["$defs"]["strength"]["properties"]["margin_added_here"]["type"] == "string"
    assert [k for k in regenerated["$defs"] if regenerated["$defs"][k] != SCHEMA["$defs"][k]] == ["strength"]
    assert list(regenerated["$defs"]) == list(SCHEMA["$defs"])  # the entry stays in its place


_GUARANTEE: dict[str, Any] = {"index": 1, "text": "y > 0", "source": "a.rcl:3:4", "status": "discharged",
                              "obligations": ["N.g1.hoare.c1"]}
_NODE: dict[str, Any] = {
    "name": "N", "source": "a.rcl:1:1", "status": "discharged",
    "inputs": [{"name": "x", "type": "real", "producer": None}],
    "outputs": [{"name": "y", "type": "real", "consumers": ["M.x"]}],
    "assumptions": [{"text": "x > 0", "source": "a.rcl:2:4", "environment": True}],
    "guarantees": [_GUARANTEE], "latex": "\\mathit{N}"}


def _valid(key: str, rows: list[dict[str, Any]]) -> list[str]:
    """What the published schema says is wrong with ``rows`` as the report's ``key``."""
    schema = {**SCHEMA, "properties": {key: SCHEMA["properties"][key]}, "required": [key]}
    return [e.message for e in Draft202012Validator(schema).iter_errors({key: rows})]


def test_a_node_row_writes_no_key_a_later_pass_has_not_given() -> None:
    row = NodeRow.of(_NODE).to_json()
    assert row == _NODE and list(row) == list(_NODE)  # the later passes' fields are not written until they run
    assert _valid("nodes", [row]) == []
    # what the confidence and culprit passes add: written in the order declared, the strength's keys as before
    later = NodeRow.of({**_NODE, "guarantees": [{**_GUARANTEE, "strength": {"kind": "proof", "doubt": 1e-3},
                                                 "culprit_of": [{"status": "failed", "sentence": "S."}]}],
                        "confidence": 0.999, "limited_by": None}).to_json()
    assert list(later)[-2:] == ["confidence", "limited_by"] and later["limited_by"] is None
    assert later["guarantees"][0]["strength"] == {"kind": "proof", "doubt": 1e-3}
    assert _valid("nodes", [later]) == []
    with pytest.raises(msgspec.ValidationError, match="margin_added_here"):
        NodeRow.of({**_NODE, "margin_added_here": "0.5 m"})
    with pytest.raises(msgspec.ValidationError, match="status"):
        GuaranteeRow.of({**_GUARANTEE, "status": "fine"})


def test_a_strength_keeps_the_key_order_the_report_wrote() -> None:
    """kind, detail, solvers, doubt (report/argument/strength.py wrote them so); doubt is 0 to 1."""
    assert list(Strength(kind="proof", detail="Z3 and cvc5", solvers=2, doubt=1e-4).to_json()) == [
        "kind", "detail", "solvers", "doubt"]
    assert list(Strength(kind="tested", detail="", doubt=0.05).to_json()) == ["kind", "detail", "doubt"]
    assert LimitedBy(label="N guarantee 1", kind="proof", doubt=1e-3).to_json() == {
        "label": "N guarantee 1", "kind": "proof", "doubt": 1e-3}
    assert list(CulpritOf(status="failed", sentence="S.").to_json()) == ["status", "sentence"]
    assert SCHEMA["$defs"]["strength"]["properties"]["doubt"]["maximum"] == 1


def test_the_other_rows_are_their_schema_parts() -> None:
    derived = DerivedPropertyRow(node="N", rules=["R1"], instances=[{"rule": "R1"}], environment_assumptions=[],
                                 property="y > 0", status="discharged", derivation="derived",
                                 evidence_status="pending", evidence_note="n", loop_assumption=None).to_json()
    assert "confidence" not in derived and _valid("derived_properties", [derived]) == []
    env = EnvironmentAssumptionRow(node="N", text="x > 0", source="a.rcl:2:4").to_json()
    assert _valid("environment_assumptions", [env]) == []
    unverified = UnverifiedRow(id="N.g2", node="N", guarantee=2, text="y < 9", source="a.rcl:4:4",
                               status="unverified", reason="r", message="m").to_json()
    assert _valid("unverified", [unverified]) == []
    assert _valid("unverified", [{**unverified, "status": "pending"}]) != []
