"""reports/assurance.json of a run against its published JSON Schema (docs/assurance.schema.json), the
one status vocabulary (rclverify.records.statuses) and the report's TypedDicts (records/report_schema.py;
tests/report/test_report_vocabulary.py holds the three in step without a run).

One small workspace written here is verified once and reported twice more: after a contract edit
(stale) and after records were altered outside rclverify (error), so the schema meets every kind of
status a run gives.  The bundled workspace and the examples are checked where their tests already
verify them (tests/_report_schema.py).
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from _report_schema import VALIDATOR, check_report, out_of_vocabulary, schema_errors, words_seen
from rclverify.cli.commands import main
from rclverify.records import report_schema as st

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
    file: contracts/chain.rcl
    node: Gain
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
