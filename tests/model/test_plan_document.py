"""The plan's sections read typed once (model/plan/document.py): the loader's readers read attributes."""
from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from rclverify.lang.ast import Loc
from rclverify.model.plan.document import EnvironmentEntry, PlanDocument, plan_document
from rclverify.model.plan.errors import PlanError
from rclverify.model.plan.load import read_plan_data, read_plan_document

PLAN = """\
name: typed
contracts: [a.rcl]
requirements:
  - id: R1
    text: stops in time
    assuming: in.x > 0
    deadline: {path: [A, B], within: 500 ms}
    supported_by: [{node: A, guarantees: [1, 2]}]
  - id: R2
    text: another
    assuming: [in.x > 0, in.y > 0]
connections:
  - {from: A.out_x, to: B.in_x}
environment:
  A: ["in.x >= 0"]
  B: {facts: ["in.y >= 0"], instances: [0, 3]}
state:
  A: {n: {type: NATURAL, init: state.n = 0, next: next.n = state.n}}
acknowledged:
  - {warning: A.g1.redundant, text: in.x > 0, reason: kept for the reader here}
people:
  - {name: Ada Lovelace, aliases: [ada]}
requirements_from: {fret: fret/x.json, doorstop: reqs}
nodes:
  A:
    evidence: [{backend: hoare, program: a.imp}]
    replacement: b.rcl:B
"""


def _workspace(tmp_path: Path, text: str = PLAN) -> Path:
    (tmp_path / "contracts").mkdir()
    (tmp_path / "contracts" / "plan.yaml").write_text(text, encoding="utf-8")
    return tmp_path


def test_sections_read_typed(tmp_path: Path) -> None:
    doc, locs = read_plan_document(_workspace(tmp_path), "contracts/plan.yaml")
    assert isinstance(doc, PlanDocument) and doc.name == "typed" and doc.contracts == ("a.rcl",)
    r1, r2 = doc.requirements
    assert r1.assuming == "in.x > 0" and r2.assuming == ("in.x > 0", "in.y > 0")  # one formula or a list
    assert r1.deadline is not None and r1.deadline.path == ("A", "B") and r1.deadline.within == "500 ms"
    assert r2.deadline is None and r2.formal is None  # absent: None, never a key to test for
    assert r1.supported_by[0].node == "A" and r1.supported_by[0].guarantees == (1, 2)
    assert doc.connections is not None and (doc.connections[0].source, doc.connections[0].to) == ("A.out_x", "B.in_x")
    assert doc.environment is not None and doc.environment["A"] == ("in.x >= 0",)
    b = doc.environment["B"]
    assert isinstance(b, EnvironmentEntry) and b.facts == ("in.y >= 0",) and b.instances == (0, 3)
    assert doc.state is not None and doc.state["A"]["n"].type == "NATURAL"
    assert doc.acknowledged[0].text == "in.x > 0" and doc.acknowledged[0].sha256 is None
    assert doc.people[0].aliases == ("ada",) and doc.people[0].emails == ()
    assert doc.fret_export == "fret/x.json" and list(doc.requirements_from) == ["fret", "doorstop"]  # as written
    assert doc.nodes is not None and doc.nodes["A"].replacement == "b.rcl:B"
    assert doc.nodes["A"].evidence[0] == {"backend": "hoare", "program": "a.imp"}  # a backend's settings as written
    assert locs[("requirements", 0, "deadline", "within")].line == 7  # the locations stay the loader's
    data, _ = read_plan_data(tmp_path, "contracts/plan.yaml")  # control: the same plan as plain data
    assert plan_document(data) == doc


def test_absent_sections_are_empty(tmp_path: Path) -> None:
    doc, _ = read_plan_document(_workspace(tmp_path, "contracts: [a.rcl]\n"), "contracts/plan.yaml")
    assert (doc.requirements, doc.people, doc.standards, doc.design, doc.fret_export) == ((), (), (), "", None)
    assert doc.nodes is None and doc.environment is None and doc.fret is None


def test_a_value_the_sections_do_not_admit_is_located() -> None:
    data: dict[str, Any] = {"contracts": ["a.rcl"],
                            "requirements": [{"id": "R1", "text": "t", "deadline": {"path": "A", "within": 1}}]}
    locs = {("requirements", 0): Loc("plan.yaml", 4, 5), ("requirements", 0, "deadline"): Loc("plan.yaml", 6, 15)}
    with pytest.raises(PlanError) as exc:
        plan_document(data, locs, "plan.yaml")
    (d,) = exc.value.diagnostics
    # the nearest located value on the path msgspec names
    assert (d.loc.line, d.loc.col, d.code) == (6, 15, "E-plan")
    assert "requirements.0.deadline" in d.message and "Expected `array`" in d.message
    data["requirements"][0]["deadline"] = {"path": ["A"], "within": 1}  # control: the same data, well formed
    assert plan_document(data, locs, "plan.yaml").requirements[0].deadline is not None


def test_an_integer_written_as_a_whole_float_reads_as_the_schema_admits_it(tmp_path: Path) -> None:
    text = PLAN.replace("guarantees: [1, 2]", "guarantees: [1.0, 2]").replace("instances: [0, 3]", "instances: [0, 3.0]")
    doc, _ = read_plan_document(_workspace(tmp_path, text), "contracts/plan.yaml")  # JSON Schema's integer admits 1.0
    assert doc.requirements[0].supported_by[0].guarantees == (1, 2)
    b = (doc.environment or {})["B"]
    assert isinstance(b, EnvironmentEntry) and b.instances == (0, 3)
    with pytest.raises(PlanError):  # control: a number that is no integer is refused (by the schema)
        (tmp_path / "contracts" / "plan.yaml").write_text(text.replace("[1.0, 2]", "[1.5, 2]"), encoding="utf-8")
        read_plan_document(tmp_path, "contracts/plan.yaml")
