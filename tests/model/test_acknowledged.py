"""Warnings a user can answer (issue 64): redundancy that respects deadlines
and triggers, and acknowledgements of lint and health warnings in the plan."""
from __future__ import annotations

from rclverify.calculus.health.shape import shape_findings
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check

TIMED = """
node Stopper {
  inputs( estop : BOOL, button : BOOL )
  outputs( halt : BOOL )
  assume( TRUE )
  guarantee( in.estop -> out.halt )
  guarantee( in.estop -> out.halt ) triggered by in.estop within 20 ms
  guarantee( in.estop -> out.halt ) triggered by in.estop
  guarantee( in.estop -> out.halt ) triggered by in.estop within 10 ms
}
"""


def _redundant(text: str) -> set[str]:
    checked = check([parse_text(text, "s.rcl")])
    return {f.id for f in shape_findings(checked, "Stopper") if f.check == "redundant"}


def test_a_timed_guarantee_is_never_implied_by_an_untimed_one():
    found = _redundant(TIMED)
    # g2 (20 ms) follows only from g4 (10 ms); g3 (triggered, untimed) from g2 and g4;
    # g4 from nothing as tight; g1 (every message) from no guarantee on responses only
    assert found == {"Stopper.g2.c1.redundant", "Stopper.g3.c1.redundant"}


def test_without_the_tighter_deadline_the_timed_guarantee_stands():
    text = TIMED.replace("  guarantee( in.estop -> out.halt ) triggered by in.estop within 10 ms\n", "")
    # the case: g3 (untimed) would have flagged g2 (20 ms); deleting g2 would lose the deadline
    assert _redundant(text) == {"Stopper.g3.c1.redundant"}


def test_a_triggered_guarantee_is_implied_by_one_of_the_same_trigger_only():
    text = TIMED.replace("triggered by in.estop\n", "triggered by in.button\n")
    assert "Stopper.g3.c1.redundant" not in _redundant(text)
    untriggered = TIMED.replace("  guarantee( in.estop -> out.halt )\n", "  guarantee( in.estop -> out.halt and in.button -> out.halt )\n")
    assert "Stopper.g1.c1.redundant" not in _redundant(untriggered)


# ---------------------------------------------------------------------------
# Acknowledgements: one small workspace, verified with and without them
# ---------------------------------------------------------------------------

import json  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

import msgspec  # noqa: E402
import pytest  # noqa: E402

from rclverify.cli.commands import main  # noqa: E402
from rclverify.model.plan.acknowledged import digest  # noqa: E402
from rclverify.records.findings import Acknowledged, FindingRow  # noqa: E402
from rclverify.records.lint_rows import LintRow  # noqa: E402

GAIN = """node Gain {
  inputs( x : INTEGER )
  outputs( y : INTEGER )
  assume( in.x >= 0 )
  guarantee( out.y >= in.x and out.y >= 0 )
  guarantee( forall(k in NATURAL | out.y <= in.x + 10) )
}
"""
IMPL = "def gain(x: int) -> dict[str, int]:\n    return {'y': x + 1}\n"
PLAN = """name: gain
contracts: [contracts/gain.rcl]
nodes:
  Gain:
    evidence:
      - {backend: property_tests, implementation: impl/gain.py:gain, max_examples: 20}
"""
ACKS = """acknowledged:
  - warning: Gain.g1.c2.redundant
    text: "out.y >= 0"
    reason: kept so that a reader sees the output is never negative
  - warning: W-unused-bound
    file: contracts/gain.rcl
    text: "forall(k in NATURAL | out.y <= in.x + 10)"
    reason: the bound variable stays until the per-step table of the next release
"""


def _verify(ws: Path, plan: str, strict: bool = False) -> tuple[int, dict[str, Any]]:
    (ws / "contracts" / "plan.yaml").write_text(plan, encoding="utf-8")
    rc = main(["verify", "-w", str(ws)] + (["--strict"] if strict else []))
    return rc, json.loads((ws / "reports" / "assurance.json").read_text(encoding="utf-8"))


def _explain(ws: Path) -> str:
    import subprocess
    import sys
    p = subprocess.run([sys.executable, "-m", "rclverify.cli.commands", "explain", "-w", str(ws), "Gain.g1.c2.redundant"],
                       capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stderr
    return p.stdout


@pytest.fixture(scope="module")
def gain_ws(tmp_path_factory: pytest.TempPathFactory) -> Path:
    ws = tmp_path_factory.mktemp("ack") / "gain"
    (ws / "contracts").mkdir(parents=True)
    (ws / "impl").mkdir()
    (ws / "contracts" / "gain.rcl").write_text(GAIN, encoding="utf-8")
    (ws / "impl" / "gain.py").write_text(IMPL, encoding="utf-8")
    return ws


def test_unacknowledged_warnings_fail_strict_and_offer_the_entry(gain_ws):
    rc, report = _verify(gain_ws, PLAN, strict=True)
    assert rc == 1 and not report["meta"]["strict_ok"]
    [f] = [f for f in report["findings"] if f["id"] == "Gain.g1.c2.redundant"]
    assert f["status"] == "warning" and f["flagged"] == "out.y >= 0" and f["sha256"] == digest("out.y >= 0")
    assert [x["code"] for x in report["lint"]] == ["W-unused-bound"]
    html = (gain_ws / "reports" / "assurance.html").read_text(encoding="utf-8")
    assert f"sha256: {f['sha256'][:16]}" in html  # the entry to paste, for a warning not yet answered
    assert f"{{warning: Gain.g1.c2.redundant, sha256: {f['sha256'][:16]}, reason: ...}}" in _explain(gain_ws)


def test_acknowledged_warnings_pass_strict_with_their_reasons_everywhere(gain_ws):
    rc, report = _verify(gain_ws, PLAN + ACKS, strict=True)
    assert rc == 0 and report["meta"]["strict_ok"]
    # what the terminal's "accepted risks:" line is printed from (report/summary.py)
    summary = json.loads((gain_ws / "artifacts" / "report" / "summary.json").read_text(encoding="utf-8"))
    assert [a.split(" (")[0] for a in summary["acknowledged"]] == ["Gain.g1.c2.redundant",
                                                                   "contracts/gain.rcl:6:21:W-unused-bound"]
    assert "accepted risk, acknowledged in the plan (contracts/plan.yaml:8:5): kept so that" in _explain(gain_ws)
    assert [a["status"] for a in report["acknowledgements"]] == ["ok", "ok"]
    [f] = [f for f in report["findings"] if f["id"] == "Gain.g1.c2.redundant"]
    assert f["status"] == "warning" and f["acknowledged"]["at"] == "contracts/plan.yaml:8:5"
    sarif = json.loads((gain_ws / "reports" / "assurance.sarif").read_text(encoding="utf-8"))
    import jsonschema
    schema = Path(__file__).parent.parent / "data" / "sarif-schema-2.1.0.json"
    jsonschema.validate(sarif, json.loads(schema.read_text(encoding="utf-8")))
    sup = {r["ruleId"]: r.get("suppressions") for r in sarif["runs"][0]["results"]}
    assert sup["RCL-HEALTH-REDUNDANT"][0]["justification"].startswith("kept so that a reader")
    assert sup["RCL-HEALTH-REDUNDANT"][0]["status"] == "accepted"
    assert sup["RCL-LINT-UNUSED-BOUND"][0]["kind"] == "external"
    region = sup["RCL-HEALTH-REDUNDANT"][0]["location"]["physicalLocation"]["region"]
    assert region["startLine"] == 8  # the plan entry that accepted it
    md = (gain_ws / "reports" / "assurance.md").read_text(encoding="utf-8")
    assert "**Accepted risk**" in md and "the per-step table of the next release" in md
    attention = md.split("## What needs attention", 1)[1].split("\n## ", 1)[0]
    assert "Gain.g1.c2.redundant" not in attention  # accepted: listed with its reason, not as outstanding
    argument = json.loads((gain_ws / "reports" / "argument.json").read_text(encoding="utf-8"))
    risks = [e for e in argument["elements"] if str(e["id"]).startswith("A-accepted")]
    assert len(risks) == 2 and all(e["type"] == "assumption" for e in risks)


def test_a_changed_flagged_text_raises_the_warning_again(gain_ws):
    (gain_ws / "contracts" / "gain.rcl").write_text(GAIN.replace("out.y >= 0 )", "out.y >= 0 - 1 )"),
                                                    encoding="utf-8")
    try:
        rc, report = _verify(gain_ws, PLAN + ACKS + """  - warning: W-implication-precedence
    file: contracts/gain.rcl
    text: "a -> b -> c"
    reason: an old slip of the contract since repaired
""", strict=True)
    finally:
        (gain_ws / "contracts" / "gain.rcl").write_text(GAIN, encoding="utf-8")
    assert rc == 1
    status = {a["warning"]: a["status"] for a in report["acknowledgements"]}
    assert status == {"Gain.g1.c2.redundant": "stale", "W-unused-bound": "ok", "W-implication-precedence": "stale"}
    [f] = [f for f in report["findings"] if f["id"] == "Gain.g1.c2.redundant"]
    assert not f.get("acknowledged") and f["flagged"] == "out.y >= 0 - 1"
    md = (gain_ws / "reports" / "assurance.md").read_text(encoding="utf-8")
    attention = md.split("## What needs attention", 1)[1].split("\n## ", 1)[0]
    assert "W-implication-precedence" in attention and "Gain.g1.c2.redundant" in attention
    why = " ".join(report["summary"]["problems"])
    assert "the text it acknowledged changed" in why and "matches no warning of this run" in why


def test_only_a_warning_can_be_acknowledged_and_lint_binds_by_clause_text():
    from rclverify.model.plan.acknowledged import Acknowledgement, apply_acknowledgements
    from rclverify.lang import ast
    checked = check([parse_text(GAIN, "contracts/gain.rcl")])
    problem = FindingRow(id="Gain.g1.tautology", node="Gain", check="tautology", guarantee=1, status="problem",
                         message="always true", explanation="")
    lint = LintRow(location="contracts/gain.rcl:6:21", code="W-unused-bound", severity="warning",
                   message="unused k")
    at = ast.Loc("contracts/plan.yaml", 3, 5)
    acks = [Acknowledgement("Gain.g1.tautology", "it is meant", at, text="out.y >= in.x and out.y >= 0"),
            Acknowledgement("W-unused-bound", "kept as written", at, text="forall(k in NATURAL | out.y <= in.x + 10)",
                            file="contracts/other.rcl"),
            Acknowledgement("W-unused-bound", "kept as written", at, text="forall(k in NATURAL |  out.y <= in.x + 10)",
                            file="./contracts/gain.rcl")]
    (found,), (linted,), got = apply_acknowledgements(acks, [problem], [lint], checked)
    assert [a.status for a in got] == ["error", "stale", "ok"]  # refused; another file; white space is no change
    assert "not a warning" in got[0].message and found.acknowledged is None and found.flagged == ""
    assert linted.flagged == "forall(k in NATURAL | out.y <= in.x + 10)" and isinstance(linted.acknowledged,
                                                                                         Acknowledged)
    assert linted.acknowledged.at == "contracts/plan.yaml:3:5" and lint.acknowledged is msgspec.UNSET  # a new row


@pytest.mark.parametrize("entry, where, said", [
    ("  - {warning: Gain.g1.c2.redundant, reason: kept for the reader of it}\n", "4:5", "give the flagged text"),
    ("  - warning: W-unused-bound\n    text: forall(k in NATURAL | TRUE)\n    reason: '...'\n", "6:14",
     "the reason must say why"),
])
def test_a_malformed_acknowledgement_is_one_located_error(tmp_path, entry, where, said):
    from rclverify.model.plan.errors import PlanError
    from rclverify.model.plan.load import load_plan
    (tmp_path / "contracts").mkdir()
    (tmp_path / "contracts" / "gain.rcl").write_text(GAIN, encoding="utf-8")
    (tmp_path / "contracts" / "plan.yaml").write_text("name: gain\ncontracts: [contracts/gain.rcl]\nacknowledged:\n"
                                                      + entry, encoding="utf-8")
    with pytest.raises(PlanError) as e:
        load_plan(tmp_path)
    [d] = e.value.diagnostics
    assert f"{d.loc.line}:{d.loc.col}" == where and said in d.message


# ---------------------------------------------------------------------------
# An acknowledgement answers one finding: its file, its node and its text
# ---------------------------------------------------------------------------

BOUND = "  guarantee( forall(k in NATURAL | out.y <= in.x + 10) )\n"
NODE = "node {name} {{\n  inputs( x : INTEGER )\n  outputs( y : INTEGER )\n  assume( TRUE )\n" + BOUND + "}}\n"
TWO_PLAN = """name: two
contracts: [contracts/gov.rcl, contracts/other.rcl]
nodes:
  Gov: {{evidence: [{{backend: property_tests, implementation: impl/gain.py:gain, max_examples: 5}}]}}
  Other: {{evidence: [{{backend: property_tests, implementation: impl/gain.py:gain, max_examples: 5}}]}}
acknowledged:
  - warning: W-unused-bound
{where}    text: "forall(k in NATURAL | out.y <= in.x + 10)"
    reason: the bound variable stays until the per-step table of the next release
"""


def _two(tmp_path: Path, other: str) -> Path:
    (tmp_path / "contracts").mkdir(exist_ok=True)
    (tmp_path / "impl").mkdir(exist_ok=True)
    (tmp_path / "impl" / "gain.py").write_text(IMPL, encoding="utf-8")
    (tmp_path / "contracts" / "gov.rcl").write_text(NODE.format(name="Gov"), encoding="utf-8")
    (tmp_path / "contracts" / "other.rcl").write_text(other, encoding="utf-8")
    return tmp_path


def _lint_acks(report: dict[str, Any]) -> dict[str, bool]:
    return {x["location"]: bool(x.get("acknowledged")) for x in report["lint"] if x["code"] == "W-unused-bound"}


def test_a_lint_acknowledgement_for_one_file_leaves_the_same_warning_in_another_file(tmp_path):
    ws = _two(tmp_path, NODE.format(name="Other"))
    rc, report = _verify(ws, TWO_PLAN.format(where="    file: contracts/gov.rcl\n"), strict=True)
    assert _lint_acks(report) == {"contracts/gov.rcl:5:21": True, "contracts/other.rcl:5:21": False}
    assert rc == 1 and not report["meta"]["strict_ok"]  # Other's warning is not answered
    assert [a["matched"] for a in report["acknowledgements"]] == [["contracts/gov.rcl:5:21:W-unused-bound"]]
    # written without file: it answered both nodes' warnings and --strict passed; now refused before any check
    (ws / "contracts" / "plan.yaml").write_text(TWO_PLAN.format(where=""), encoding="utf-8")
    assert main(["verify", "-w", str(ws), "--strict"]) == 1


def test_the_acknowledgement_for_gov_still_accepts_govs_own_warning(tmp_path):
    ws = _two(tmp_path, "node Other {\n  inputs( x : INTEGER )\n  outputs( y : INTEGER )\n  assume( TRUE )\n"
                        "  guarantee( out.y >= in.x )\n}\n")
    rc, report = _verify(ws, TWO_PLAN.format(where="    file: contracts/gov.rcl\n"), strict=True)
    assert _lint_acks(report) == {"contracts/gov.rcl:5:21": True}
    assert rc == 0 and report["meta"]["strict_ok"]


@pytest.mark.parametrize("other, where, at, said", [
    (NODE.format(name="Other"), "", "7:5", "give the contract file"),
    (NODE.format(name="Other") + NODE.format(name="Third"), "    file: contracts/other.rcl\n", "7:5",
     "holds the nodes Other, Third"),
    (NODE.format(name="Other"), "    file: contracts/gov.rcl\n    node: Other\n", "9:11", "has no node Other"),
    (NODE.format(name="Other"), "    file: contracts/none.rcl\n", "8:11", "no contract file"),
])
def test_an_acknowledgement_that_cannot_be_tied_to_one_finding_is_a_located_plan_error(tmp_path, capsys, other,
                                                                                        where, at, said):
    ws = _two(tmp_path, other)
    (ws / "contracts" / "plan.yaml").write_text(TWO_PLAN.format(where=where), encoding="utf-8")
    assert main(["compose", "-w", str(ws)]) == 1
    err = capsys.readouterr().err
    assert err.startswith(f"contracts/plan.yaml:{at}: error: acknowledged[0] (W-unused-bound): ") and said in err
    assert "Traceback" not in err


def test_node_names_the_one_node_of_a_file_that_holds_several(tmp_path):
    ws = _two(tmp_path, NODE.format(name="Other") + NODE.format(name="Third"))
    plan = TWO_PLAN.format(where="    file: contracts/other.rcl\n    node: Third\n")
    rc, report = _verify(ws, plan, strict=True)
    assert _lint_acks(report) == {"contracts/gov.rcl:5:21": False, "contracts/other.rcl:5:21": False,
                                  "contracts/other.rcl:11:21": True}
    assert rc == 1


def test_a_health_acknowledgement_names_its_own_node_file():
    from rclverify.model.plan.acknowledged import Acknowledgement, apply_acknowledgements
    from rclverify.lang import ast
    checked = check([parse_text(GAIN, "contracts/gain.rcl")])
    at = ast.Loc("contracts/plan.yaml", 3, 5)
    rows = [FindingRow(id="Gain.g1.c2.redundant", node="Gain", check="redundant", guarantee=1, status="warning",
                       message="implied", explanation="")]
    acks = [Acknowledgement("Gain.g1.c2.redundant", "kept for the reader", at, text="out.y >= 0",
                            file="contracts/other.rcl")]
    (found,), _, got = apply_acknowledgements(acks, rows, [], checked)
    assert [a.status for a in got] == ["stale"] and found.acknowledged is None and found.flagged == "out.y >= 0"
    acks = [Acknowledgement("W-unused-bound", "kept as written", at, text="forall(k in NATURAL | out.y <= in.x + 10)")]
    lint = [LintRow(location="contracts/gain.rcl:6:21", code="W-unused-bound", severity="warning", message="k")]
    _, (linted,), got = apply_acknowledgements(acks, [], lint, checked)
    assert [a.status for a in got] == ["error"] and linted.acknowledged is msgspec.UNSET  # no file: no finding
