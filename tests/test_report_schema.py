"""reports/assurance.json against its published JSON Schema (docs/assurance.schema.json), the one
status vocabulary (rclverify.evidence.statuses) and the report's TypedDicts (report/schema_types.py).

One small workspace written here is verified once and reported twice more: after a contract edit
(stale) and after records were altered outside rclverify (error), so the schema meets every kind of
status a run gives.  The bundled workspace and the examples are checked where their tests already
verify them (tests/_report_schema.py).
"""
from __future__ import annotations

import json
import typing
from pathlib import Path
from typing import Any

import pytest
from jsonschema import Draft202012Validator

from _report_schema import SCHEMA, VALIDATOR, check_report, out_of_vocabulary, schema_errors, words_seen
from rclverify.cli import main
from rclverify.evidence import records, statuses
from rclverify.report import schema_types as st

RCL = """node Gain {
  inputs( x : INTEGER )
  outputs( y : INTEGER )
  assume( in.x >= 0 )
  guarantee( out.y >= in.x and out.y >= 0 )
  guarantee( out.y <= in.x + 10 )
}

node Clamp {
  inputs( y : INTEGER )
  outputs( z : INTEGER )
  assume( in.y >= 0 )
  guarantee( out.z >= 0 and out.z <= 100 )
}
"""
PLAN = """name: schema check
contracts: [contracts/chain.rcl]
requirements:
  - id: R1
    text: The clamped output is never negative.
    formal: "Clamp.out.z >= 0"
    supported_by:
      - {node: Clamp, guarantees: [1]}
  - id: R2
    text: The chain is pleasant to tune.
    supported_by:
      - {node: Gain, guarantees: [1]}
connections:
  - {from: Gain.y, to: Clamp.y}
acknowledged:
  - warning: W-no-such-warning
    sha256: 0123456789abcdef
    reason: a warning this run does not raise
nodes:
  Gain:
    evidence:
      - backend: property_tests
        implementation: impl/gain.py:gain
        max_examples: 20
        expected:
          - {guarantee: 1, verdict: discharged, reason: the gain adds one}
"""
IMPL = "def gain(x: int) -> dict[str, int]:\n    return {'y': x + 1}\n"


def _read(ws: Path) -> dict[str, Any]:
    return json.loads((ws / "reports" / "assurance.json").read_text(encoding="utf-8"))


@pytest.fixture(scope="module")
def reports(tmp_path_factory: pytest.TempPathFactory) -> dict[str, dict[str, Any]]:
    ws = tmp_path_factory.mktemp("schema") / "ws"
    for rel, text in {"contracts/chain.rcl": RCL, "contracts/plan.yaml": PLAN, "impl/gain.py": IMPL}.items():
        (ws / rel).parent.mkdir(parents=True, exist_ok=True)
        (ws / rel).write_text(text, encoding="utf-8")
    assert main(["verify", "-w", str(ws)]) == 0
    out = {"verified": _read(ws)}
    rcl = ws / "contracts" / "chain.rcl"
    rcl.write_text(RCL.replace("in.x + 10", "in.x + 11"), encoding="utf-8")  # every record made from the old text
    assert main(["report", "-w", str(ws)]) == 0
    out["stale"] = _read(ws)
    rcl.write_text(RCL, encoding="utf-8")
    ev = ws / "artifacts" / "evidence" / "Gain.g1.property_tests.e0.json"  # altered outside rclverify: error
    ev.write_text(ev.read_text(encoding="utf-8").replace('"status": "discharged"', '"status": "failed"'),
                  encoding="utf-8")
    calc = ws / "artifacts" / "calculus" / "Clamp.json"
    data = json.loads(calc.read_text(encoding="utf-8"))
    data["side_conditions"][0]["status"] = "failed"
    calc.write_text(json.dumps(data), encoding="utf-8")
    assert main(["report", "-w", str(ws)]) == 0
    out["altered"] = _read(ws)
    return out


def _undescribed(x: Any, where: str = "") -> list[str]:
    """The properties of the schema ``x`` without a description, as paths."""
    out: list[str] = []
    if isinstance(x, dict):
        out += [f"{where}/{k}" for k, v in (x.get("properties") or {}).items() if not v.get("description")]
        for k, v in x.items():
            out += _undescribed(v, f"{where}/{k}")
    elif isinstance(x, list):
        for i, v in enumerate(x):
            out += _undescribed(v, f"{where}/{i}")
    return out


def test_the_schema_is_a_draft_2020_12_schema_with_each_key_described() -> None:
    Draft202012Validator.check_schema(SCHEMA)
    assert SCHEMA["$schema"] == "https://json-schema.org/draft/2020-12/schema"
    assert _undescribed(SCHEMA) == []


def test_the_schema_enums_are_the_vocabulary() -> None:
    for name, words in statuses.VOCABULARY.items():
        assert SCHEMA["$defs"][name]["enum"] == list(words), name
    assert list(statuses.SEVERITY) == list(statuses.EVIDENCE_STATUSES)
    assert records.SEVERITY is statuses.SEVERITY  # the roll-up ranks the vocabulary's order
    assert records.worst(["discharged", "unverified", "pending"]) == "unverified"


def test_the_stages_use_the_vocabulary() -> None:
    from rclverify.crosscheck.stage import DOWNGRADES
    from rclverify.plan.expected import VERDICTS as EXPECTED
    from rclverify.rcl.errors import Severity as LintSeverity
    from rclverify.report import severity
    from rclverify.report.build import _DERIVATION, _FINDING_AS
    from rclverify.report.deadlines import STATUS_OF
    from rclverify.requirements import rollup
    assert rollup.VERDICTS == statuses.REQUIREMENT_VERDICTS
    assert {rollup.MET, rollup.OUTSTANDING, rollup.INCONSISTENT, rollup.VACUOUS} <= set(statuses.REQUIREMENT_VERDICTS)
    assert set(_FINDING_AS) == set(statuses.HEALTH_STATUSES)
    assert set(_FINDING_AS.values()) <= set(statuses.EVIDENCE_STATUSES)
    assert set(_DERIVATION.values()) | {"undecided"} == set(statuses.DERIVATIONS)
    assert set(STATUS_OF) == set(statuses.DEADLINE_VERDICTS)
    assert set(STATUS_OF.values()) <= set(statuses.EVIDENCE_STATUSES)
    assert (severity.ERROR, severity.WARNING, severity.NOTE) == statuses.SEVERITIES
    assert typing.get_args(LintSeverity) == statuses.LINT_SEVERITIES
    assert DOWNGRADES <= set(statuses.AGREEMENTS)
    assert set(EXPECTED) <= set(statuses.RECORD_STATUSES)


#: Each row TypedDict and where the schema describes it.
_ROWS: tuple[tuple[Any, tuple[str, ...]], ...] = (
    (st.Meta, ("meta",)), (st.Summary, ("summary",)),
    (st.NodeRow, ("nodes", "items")), (st.GuaranteeRow, ("nodes", "items", "guarantees", "items")),
    (st.RequirementRow, ("requirements", "items")), (st.SupportRow, ("requirements", "items", "support", "items")),
    (st.SideConditionRow, ("side_conditions", "items")), (st.DerivedPropertyRow, ("derived_properties", "items")),
    (st.FindingRow, ("findings", "items")), (st.ObligationRow, ("obligations", "items")),
    (st.EvidenceRow, ("evidence", "items")), (st.PendingRow, ("pending", "items")), (st.LintRow, ("lint", "items")),
    (st.AcknowledgementRow, ("acknowledgements", "items")), (st.UnverifiedRow, ("unverified", "items")),
    (st.ProblemRow, ("problems", "items")),
)


def test_the_typeddicts_are_the_schema() -> None:
    assert list(st.REPORT_KEYS) == list(SCHEMA["properties"]) == SCHEMA["required"]
    for td, path in _ROWS:
        sub: Any = SCHEMA["properties"]
        for step in path:
            sub = sub[step] if step in sub else sub["properties"][step]
        keys = set(typing.get_type_hints(td))
        assert set(sub["required"]) == set(td.__required_keys__), td.__name__
        assert keys == set(sub["properties"]), (td.__name__, set(sub["properties"]) ^ keys)


def test_every_report_of_a_run_matches_the_schema(reports: dict[str, dict[str, Any]]) -> None:
    for label, report in reports.items():
        check_report(report, label)
        assert st.as_report(report) is report
    # the run met the words of each kind of state, so the schema was tried on each
    assert {"discharged", "unverified", "informal", "proved, evidence outstanding"} <= words_seen(reports["verified"])
    assert "stale" in {r["status"] for r in reports["stale"]["obligations"]}
    assert {sc["verdict"] for sc in reports["stale"]["side_conditions"]} == {"stale"}
    assert "error" in {r["status"] for r in reports["altered"]["obligations"]}
    assert {sc["verdict"] for sc in reports["altered"]["side_conditions"]} == {"error"}
    assert [a["status"] for a in reports["verified"]["acknowledgements"]] == ["stale"]
    assert [x["outcome"] for x in reports["verified"]["expected_verdicts"]] == ["as expected"]


def test_a_report_outside_the_schema_is_rejected_where_it_breaks(reports: dict[str, dict[str, Any]]) -> None:
    good = reports["verified"]
    ob = good["obligations"][0]
    cases = {
        "summary/status: 'green' is not one of": {**good, "summary": {**good["summary"], "status": "green"}},
        "(top): Additional properties are not allowed ('surprise'": {**good, "surprise": 1},
        "(top): 'meta' is a required property": {k: v for k, v in good.items() if k != "meta"},
        "obligations/0/status: 'ok' is not one of": {**good, "obligations": [{**ob, "status": "ok"}]},
        "obligations/0: Additional properties are not allowed ('colour'": {
            **good, "obligations": [{**ob, "colour": "green"}]},
        "obligations/0/guarantee: '1' is not of type 'integer'": {**good, "obligations": [{**ob, "guarantee": "1"}]},
        "requirements/0/verdict: 'met, probably' is not one of": {
            **good, "requirements": [{**good["requirements"][0], "verdict": "met, probably"}]},
    }
    for want, bad in cases.items():
        got = schema_errors(bad)
        path, _, message = want.partition(": ")
        assert any(e.startswith(path + ": ") and message in e for e in got), (want, got)
        assert not VALIDATOR.is_valid(bad)
    assert out_of_vocabulary({**good, "obligations": [{**ob, "status": "ok"}]}) == [
        "obligations[0].status: 'ok' is not in evidence_status"]
    with pytest.raises(ValueError, match="report lacks meta"):
        st.as_report({k: v for k, v in good.items() if k != "meta"})
