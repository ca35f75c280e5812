"""Checked repairs of the implementation (issue 111; diagnosis/code_repair.py, docs/diagnosis.md
"Repairs of the implementation"): a failing property test whose culprit is a line of the code offers the
one-token corrections of that line that make every guarantee of the node pass again on a scratch copy,
as a unified diff in the report's problem and a SARIF fix, never applied.

One workspace, verified once: ``Gate`` with a seeded ``<`` for ``<=``, ``Clamp`` with ``max`` for ``min``,
``Fine`` written right (the control: nothing fails, nothing is offered).  A correction that repairs
``Gate``'s failing guarantee and breaks its other one (``x < 10``, a number the contract names) is the
control of the check: tried, shown by the harness to break guarantee 2, not offered."""
from __future__ import annotations

import json
from pathlib import Path
from fractions import Fraction
from typing import Any

import pytest

from rclverify.app.pipeline import Workspace
from rclverify.backends.property_tests.boundary import contract_numbers
from rclverify.backends.property_tests.harness import read_config, run_guarantee
from rclverify.cli.commands import main
from rclverify.diagnosis.code_repair import MAX_REPAIRS, MAX_TRIED, candidate_edits

RCL = """\
// A gate: open up to 3, shut from 4.
node Gate {
  inputs( x : INTEGER )
  outputs( ok : BOOL )
  assume( 0 <= in.x and in.x <= 10 )
  guarantee( in.x <= 3 -> out.ok )
  guarantee( in.x >= 4 -> not out.ok )
}

// A clamp: the request, at most 50.
node Clamp {
  inputs( v : INTEGER )
  outputs( y : INTEGER )
  assume( 0 <= in.v and in.v <= 100 )
  guarantee( out.y <= 50 )
  guarantee( in.v <= 50 -> out.y == in.v )
}

// A band: open from 2 to 8, both ends included.
node Band {
  inputs( x : INTEGER )
  outputs( ok : BOOL )
  assume( 0 <= in.x and in.x <= 10 )
  guarantee( 2 <= in.x and in.x <= 8 -> out.ok )
  guarantee( in.x < 2 or in.x > 8 -> not out.ok )
}

node Fine {
  inputs( x : INTEGER )
  outputs( ok : BOOL )
  assume( 0 <= in.x and in.x <= 10 )
  guarantee( in.x <= 3 -> out.ok )
  guarantee( in.x >= 4 -> not out.ok )
}
"""
CODE = {
    "gate": '"""The gate (a seeded slip: < for <=)."""\n\n\ndef gate(x):\n    return {"ok": x < 3}\n',
    "clamp": '"""The clamp (a seeded slip: max for min)."""\n\n\ndef clamp(v):\n    y = max(v, 50)\n    return {"y": y}\n',
    "band": '"""The band (two slips: both ends left out)."""\n\n\ndef band(x):\n    return {"ok": 2 < x and x < 8}\n',
    "fine": '"""The gate written right."""\n\n\ndef fine(x):\n    return {"ok": x <= 3}\n',
}
PLAN = "contracts: [contracts/robot.rcl]\nnodes:\n" + "".join(
    f"  {name.capitalize()}:\n    evidence:\n      - {{backend: property_tests, implementation: \"nodes/{name}.py:{name}\", "
    "max_examples: 60}\n" for name in CODE)


@pytest.fixture(scope="module")
def verified(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    ws = tmp_path_factory.mktemp("code_repairs") / "ws"
    (ws / "contracts").mkdir(parents=True)
    (ws / "nodes").mkdir()
    (ws / "contracts/robot.rcl").write_text(RCL, encoding="utf-8")
    (ws / "contracts/plan.yaml").write_text(PLAN, encoding="utf-8")
    for name, text in CODE.items():
        (ws / f"nodes/{name}.py").write_text(text, encoding="utf-8")
    main(["verify", "-w", str(ws)])
    report = json.loads((ws / "reports/assurance.json").read_text(encoding="utf-8"))
    sarif = json.loads((ws / "reports/assurance.sarif").read_text(encoding="utf-8"))
    return {"ws": ws, "report": report, "sarif": sarif,
            "diagnoses": {d["id"]: d for d in report["diagnoses"]},
            "md": (ws / "reports/assurance.md").read_text(encoding="utf-8")}


def _fixes(sarif: dict[str, Any], item: str) -> list[dict[str, Any]]:
    return [f for r in sarif["runs"][0]["results"] if r["partialFingerprints"]["rclverifyItem/v1"] == item
            for f in r.get("fixes", [])]


def test_the_slip_of_strictness_is_offered_checked_as_a_diff_and_a_sarif_fix(verified: dict[str, Any]) -> None:
    d = verified["diagnoses"]["Gate.g1.property_tests.e0"]
    assert d["status"] == "failed" and "nodes/gate.py:5" in d["sentence"]
    reps = d["repairs"]
    assert 1 <= len(reps) <= MAX_REPAIRS and all(r["kind"] == "code" for r in reps)
    strict = next(r for r in reps if '+    return {"ok": x <= 3}' in r["diff"])
    assert '-    return {"ok": x < 3}' in strict["diff"] and strict["diff"].startswith("--- a/nodes/gate.py")
    assert strict["edit"] == {"file": "nodes/gate.py", "line": 5, "col": 21, "end_line": 5, "end_col": 22,
                              "inserted": "<=", "deleted": "<"}
    # checked: both guarantees of Gate ran again on the scratch copy, both discharged
    assert strict["checks"] == [{"check": "Gate.g1.property_tests.e0", "status": "discharged"},
                                {"check": "Gate.g2.property_tests.e0", "status": "discharged"}]
    assert strict["cost"] == [{"check": "Gate.g1.property_tests.e0", "before": "failed", "after": "discharged"}]
    # in the report's problem (its unified diff) and as a SARIF 2.1.0 fix (artifactChanges/replacements)
    assert '+    return {"ok": x <= 3}' in verified["md"]
    row = next(p for p in verified["report"]["problems"] if p["members"][0]["id"] == "Gate.g1.property_tests.e0")
    assert {"diagnosis": "Gate.g1.property_tests.e0", "index": reps.index(strict)} in row["repairs"]
    [change] = [c for f in _fixes(verified["sarif"], "obligation:Gate.g1.property_tests.e0")
                for c in f["artifactChanges"] if c["replacements"][0]["insertedContent"]["text"] == "<="]
    assert change["artifactLocation"]["uri"] == "nodes/gate.py"
    assert change["replacements"][0]["deletedRegion"] == {"startLine": 5, "startColumn": 21, "endLine": 5,
                                                          "endColumn": 22}
    # never applied unasked
    assert (verified["ws"] / "nodes/gate.py").read_text(encoding="utf-8") == CODE["gate"]


def test_an_edit_that_breaks_another_guarantee_is_tried_and_not_offered(verified: dict[str, Any]) -> None:
    """``x < 10`` meets guarantee 1 and breaks guarantee 2: the harness shows both, the repair is not offered."""
    ws = Workspace(verified["ws"])
    target = ws.target("Gate", 0)
    source = CODE["gate"]
    tried = candidate_edits(source, "nodes/gate.py", 5, contract_numbers(target.node))[:MAX_TRIED]
    [wide] = [e for e in tried if e.text == "10"]
    scratch = verified["ws"].parent / "scratch"
    (scratch / "nodes").mkdir(parents=True)
    (scratch / "nodes/gate.py").write_text(wide.apply(source), encoding="utf-8")
    cfg = read_config(target.config, target.node, target.root)
    got = [run_guarantee(target.checked, target.node, k, cfg, scratch, target.facts).status for k in (1, 2)]
    assert got == ["discharged", "failed"]
    offered = [r["edit"]["inserted"] for r in verified["diagnoses"]["Gate.g1.property_tests.e0"]["repairs"]]
    assert "10" not in offered and "<=" in offered


def test_max_for_min_is_offered_at_the_name(verified: dict[str, Any]) -> None:
    for oid in ("Clamp.g1.property_tests.e0", "Clamp.g2.property_tests.e0"):
        [rep] = verified["diagnoses"][oid]["repairs"]
        assert rep["edit"]["deleted"] == "max" and rep["edit"]["inserted"] == "min"
        assert "+    y = min(v, 50)" in rep["diff"] and len(rep["checks"]) == 2
        [fix] = _fixes(verified["sarif"], f"obligation:{oid}")
        assert fix["description"]["text"].count("The property tests show: every guarantee of Clamp") == 1
    assert (verified["ws"] / "nodes/clamp.py").read_text(encoding="utf-8") == CODE["clamp"]


def test_control_a_correct_node_offers_nothing(verified: dict[str, Any]) -> None:
    assert not [d for d in verified["diagnoses"] if d.startswith("Fine.")]
    statuses = {e["obligation"]: e["status"] for e in verified["report"]["evidence"]}
    assert statuses["Fine.g1.property_tests.e0"] == statuses["Fine.g2.property_tests.e0"] == "discharged"
    assert not _fixes(verified["sarif"], "obligation:Fine.g1.property_tests.e0")


def _apply_sarif(text: str, replacement: dict[str, Any]) -> str:
    """``text`` with one SARIF 2.1.0 replacement made as a viewer makes it (§3.57: ``deletedRegion`` with
    1-based lines and columns, ``endColumn`` one past the last character, then ``insertedContent``)."""
    r = replacement["deletedRegion"]
    lines = text.splitlines(keepends=True)
    start = sum(len(x) for x in lines[:r["startLine"] - 1]) + r["startColumn"] - 1
    end = sum(len(x) for x in lines[:r["endLine"] - 1]) + r["endColumn"] - 1
    return text[:start] + replacement["insertedContent"]["text"] + text[end:]


def test_the_sarif_fixes_are_valid_and_applied_give_the_repaired_code(verified: dict[str, Any]) -> None:
    """The log with its code fixes is valid SARIF 2.1.0; each fix, applied by its region, gives the code of
    its repair's diff; the control: the same replacement one column off gives other code."""
    import jsonschema
    schema = json.loads((Path(__file__).resolve().parents[2] / "tests/data/sarif-schema-2.1.0.json")
                        .read_text(encoding="utf-8"))
    jsonschema.validate(verified["sarif"], schema)
    fixes = _fixes(verified["sarif"], "obligation:Gate.g1.property_tests.e0")
    got = {_apply_sarif(CODE["gate"], f["artifactChanges"][0]["replacements"][0]) for f in fixes}
    assert CODE["gate"].replace("x < 3", "x <= 3") in got
    for f in fixes:
        [change] = f["artifactChanges"]
        assert change["artifactLocation"]["uri"] == "nodes/gate.py"
        new = _apply_sarif(CODE["gate"], change["replacements"][0])
        rep = next(r for r in verified["diagnoses"]["Gate.g1.property_tests.e0"]["repairs"]
                   if r["edit"]["inserted"] == change["replacements"][0]["insertedContent"]["text"])
        assert "+" + new.splitlines()[4] + "\n" in rep["diff"]
        off = dict(change["replacements"][0], deletedRegion={**change["replacements"][0]["deletedRegion"],
                                                             "startColumn": 20, "endColumn": 21})
        assert _apply_sarif(CODE["gate"], off) != new


def test_two_slips_on_one_line_get_a_two_token_repair_when_no_one_token_one_passes(verified: dict[str, Any]) -> None:
    """diagnosis/pair_edits.py: each strictness alone still fails at the other end of the band; both together
    pass every guarantee.  The control: Gate's one slip is repaired with one token (no pair is tried)."""
    from rclverify.diagnosis.pair_edits import joined, pair_edits
    d = verified["diagnoses"]["Band.g1.property_tests.e0"]
    first = d["repairs"][0]
    assert first["edit"]["line"] == 5 and "+    return {\"ok\": 2 <= x and x <= 8}" in first["diff"]
    assert "a two-token correction" in first["summary"] and len(first["checks"]) == 2
    assert all(c["status"] == "discharged" for c in first["checks"])
    assert (verified["ws"] / "nodes/band.py").read_text(encoding="utf-8") == CODE["band"]  # never applied
    assert all("one-token" in r["summary"] for r in verified["diagnoses"]["Gate.g1.property_tests.e0"]["repairs"])
    source = CODE["band"]
    singles = candidate_edits(source, "nodes/band.py", 5, [Fraction(2), Fraction(8)])
    assert not any(e.apply(source).endswith('return {"ok": 2 <= x and x <= 8}\n') for e in singles)
    pairs = pair_edits(source, singles)
    assert pairs and pairs[0].apply(source).endswith('return {"ok": 2 <= x and x <= 8}\n')
    a, b = sorted(singles[:2], key=lambda e: e.col)
    assert joined(source, b, a) is None  # out of order (or overlapping): no one edit


def test_a_verdict_only_run_is_discharged_exactly_where_the_full_run_is(verified: dict[str, Any]) -> None:
    """The repair check asks the harness for the verdict only (``verdict_only``): each guarantee of the four
    nodes is discharged by it exactly where the full run discharges it; a violation is ``failed`` unshrunk,
    found among the same examples, with no more bodies run than the full run's (which shrinks it and moves
    it to the boundary).  Controls: Gate's, Clamp's and Band's slips fail both ways, Fine passes both ways."""
    ws = Workspace(verified["ws"])
    seen: dict[str, list[str]] = {}
    for node in ("Gate", "Clamp", "Band", "Fine"):
        target = ws.target(node, 0)
        cfg = read_config(target.config, target.node, target.root)
        for k in (1, 2):
            full = run_guarantee(target.checked, target.node, k, cfg, target.root, target.facts)
            quick = run_guarantee(target.checked, target.node, k, cfg, target.root, target.facts, verdict_only=True)
            assert (quick.status == "discharged") == (full.status == "discharged"), (node, k, full.message)
            seen.setdefault(node, []).append(quick.status)
            if full.status == "failed":
                assert quick.status == "failed" and "(not shrunk)" in quick.message
                assert "(not shrunk)" not in full.message
                assert quick.counts.valid <= full.counts.valid
            else:
                assert quick.message == full.message
    assert seen["Fine"] == ["discharged", "discharged"]
    assert all("failed" in seen[n] for n in ("Gate", "Clamp", "Band"))
