"""The CI formats of the report (SARIF 2.1.0, JUnit XML) on a small report dict.

The bundled workspace's files are checked in tests/report/test_pipeline_e2e.py."""
from __future__ import annotations

import copy
import json
from pathlib import Path
from typing import Any

import jsonschema
import junitparser
from sarif import loader

from _typed_rows import complete
from rclverify.records.report_record import AssuranceReport
from rclverify.report.ci import write_ci_reports
from rclverify.report.junit import render_junit
from rclverify.records.sarif import split_location
from rclverify.report.sarif import render_sarif, sarif_log
from rclverify.report.sarif_rules import lint_rule_id

SCHEMA = json.loads((Path(__file__).parent.parent / "data" / "sarif-schema-2.1.0.json").read_text(encoding="utf-8"))
SRC = "contracts/n.rcl"


def _report() -> dict[str, Any]:
    """A report of one node, each kind of item once, completed into a whole report (tests/records/_typed_rows.py)."""
    def ob(i: str, status: str, line: int) -> dict[str, Any]:
        return {"id": i, "node": "N", "guarantee": 1, "backend": "hoare", "kind": "proof", "instance": "c1",
                "statement": "out.x <= 3 & <tag>", "source": f"{SRC}:{line}:3", "artifact": "", "status": status}

    def ev(i: str, status: str, cex: dict[str, Any] | None = None) -> dict[str, Any]:
        return {"obligation": i, "backend": "hoare", "kind": "proof", "status": status, "tool": "z3",
                "tool_version": "4", "started": "t", "duration_s": 0.5, "explanation": f"{status} because <&>",
                "counterexample": cex, "artifacts": [], "log_excerpt": ""}
    return complete(AssuranceReport, {
        "meta": {"tool": "rclverify", "version": "0.1.0", "workspace": "w", "plan": "contracts/plan.yaml",
                 "contracts": [SRC], "z3_version": "4", "strict_ok": False},
        "summary": {"status": "failed", "counts": {}, "headline": "", "problems": []},
        "nodes": [{"name": "N", "source": f"{SRC}:1:1", "status": "failed",
                   "guarantees": [{"index": 1, "source": f"{SRC}:4:3", "text": "g", "status": "failed", "obligations": []}]}],
        "obligations": [ob("N.ok", "discharged", 4), ob("N.bad", "failed", 4), ob("N.err", "error", 4),
                        ob("N.old", "stale", 4), ob("N.open", "pending", 4), ob("N.maybe", "inconclusive", 4)],
        "evidence": [ev("N.ok", "discharged"), ev("N.bad", "failed", {"in.r": 10, "out.x": 4}), ev("N.err", "error"),
                     ev("N.old", "stale"), ev("N.maybe", "inconclusive")],
        "pending": [{"obligation": "N.open", "backend": "hoare", "reason": "no program given"}],
        "side_conditions": [
            {"id": "N.sc1", "node": "N", "rule": "R1", "conjunct": "in.a > 0", "source": f"{SRC}:2:5", "status": "failed",
             "verdict": "failed", "explanation": "refuted", "model": {"in.a": 0}, "duration_s": 0.01, "smt2": "x", "hypotheses": []},
            {"id": "N.sc2", "node": "N", "rule": "R1", "conjunct": "in.b > 0", "source": f"{SRC}:2:9",
             "status": "inconclusive", "verdict": "inconclusive", "explanation": "timeout", "model": None, "duration_s": 1.0, "smt2": "x",
             "hypotheses": []}],
        "findings": [
            {"id": "N.g1.non-vacuous", "node": "N", "check": "non-vacuous", "guarantee": 1, "status": "problem",
             "message": "Guarantee 1 of N is vacuous.", "explanation": "", "core": ["guarantee 1", "fact 1"],
             "model": None, "duration_s": 0.1, "smt2": "", "instances": None},
            {"id": "N.contract-consistent", "node": "N", "check": "contract-consistent", "guarantee": None,
             "status": "ok", "message": "consistent", "explanation": "", "core": None, "model": {}, "duration_s": 0.1,
             "smt2": "", "instances": None}],
        "lint": [{"severity": "warning", "location": f"{SRC}:4:21", "message": "unused x'", "code": "W-unused-bound"}],
    })


def test_split_location() -> None:
    assert split_location("a/b.rcl:12:5") == ("a/b.rcl", 12, 5)
    assert split_location("C:/x.rcl:3:4") == ("C:/x.rcl", 3, 4)
    assert split_location("nowhere") is None
    assert lint_rule_id("W-unused-bound") == "RCL-LINT-UNUSED-BOUND" and lint_rule_id("") == "RCL-LINT"


def test_sarif_validates_and_maps_each_kind_to_its_rule_and_level() -> None:
    log = sarif_log(_report())
    jsonschema.Draft4Validator(SCHEMA).validate(log)
    [run] = log["runs"]
    got = {(r["properties"].get("obligation") or r["properties"].get("sideCondition") or r["properties"].get("finding")
            or "lint", r["ruleId"], r["level"]) for r in run["results"]}
    assert got == {("N.bad", "RCL-OBL-FAILED", "error"), ("N.err", "RCL-OBL-ERROR", "error"),
                   ("N.old", "RCL-OBL-STALE", "warning"), ("N.maybe", "RCL-OBL-INCONCLUSIVE", "warning"),
                   ("N.open", "RCL-OBL-PENDING", "warning"), ("N.sc1", "RCL-SC-REFUTED", "error"),
                   ("N.sc2", "RCL-SC-INCONCLUSIVE", "warning"), ("N.g1.non-vacuous", "RCL-HEALTH-VACUOUS", "error"),
                   ("lint", "RCL-LINT-UNUSED-BOUND", "warning")}
    rules = run["tool"]["driver"]["rules"]
    assert all(rules[r["ruleIndex"]]["id"] == r["ruleId"] for r in run["results"])
    bad = next(r for r in run["results"] if r["ruleId"] == "RCL-OBL-FAILED")
    assert "Counterexample: in.r = 10, out.x = 4." in bad["message"]["text"]
    region = bad["locations"][0]["physicalLocation"]
    assert region["artifactLocation"]["uri"] == SRC and region["region"] == {"startLine": 4, "startColumn": 3}
    sc = next(r for r in run["results"] if r["ruleId"] == "RCL-SC-REFUTED")
    assert "in.a = 0" in sc["message"]["text"] and sc["locations"][0]["physicalLocation"]["region"]["startColumn"] == 5
    vac = next(r for r in run["results"] if r["ruleId"] == "RCL-HEALTH-VACUOUS")
    assert "Unsat core: guarantee 1; fact 1." in vac["message"]["text"]


def test_junit_outcomes_follow_the_statuses(tmp_path: Path) -> None:
    paths = write_ci_reports(_report(), tmp_path)
    assert [p.name for p in paths] == ["assurance.sarif", "assurance.junit.xml"]
    xml = junitparser.JUnitXml.fromfile(str(paths[1]))
    [suite, lint] = list(xml)
    # the lint warning fails --strict, so it is a failing test case too (report/severity.py)
    assert lint.name == "lint" and [(c.name, type(c.result[0]).__name__, c.result[0].type) for c in lint] == [
        ("W-unused-bound contracts/n.rcl:4:21", "Failure", "warning")]
    assert suite.name == "N" and suite.tests == 10
    cases = {c.name: c for c in suite}
    kinds = {name: type(c.result[0]).__name__ if c.result else "pass" for name, c in cases.items()}
    assert kinds == {"N.ok": "pass", "N.bad": "Failure", "N.err": "Error", "N.old": "Failure", "N.open": "Skipped",
                     "N.maybe": "Skipped", "N.sc1": "Failure", "N.sc2": "Skipped", "N.g1.non-vacuous": "Failure",
                     "N.contract-consistent": "pass"}
    assert "counterexample: in.r = 10, out.x = 4" in cases["N.bad"].result[0].text
    assert "<&>" in cases["N.bad"].result[0].text  # escaped on write, read back verbatim
    assert cases["N.old"].result[0].type == "stale"
    assert "no program given" in cases["N.open"].result[0].message
    assert cases["N.sc1"].classname == "N.side_condition" and cases["N.bad"].classname == "N.obligation"
    assert (suite.failures, suite.errors, suite.skipped) == (4, 1, 3)
    sarif = loader.load_sarif_file(str(paths[0]))
    assert sarif.get_result_count() == 9


def test_outputs_are_deterministic() -> None:
    assert render_sarif(_report()) == render_sarif(_report())
    assert render_junit(_report()) == render_junit(_report())


def test_junit_from_kept_suites_is_the_junit_built_whole() -> None:
    from rclverify.report.fragments import FragmentCache
    report = _report()
    whole = render_junit(report)
    cache = FragmentCache()
    assert render_junit(report, cache) == whole and cache.misses == len(report["nodes"])
    assert render_junit(copy.deepcopy(report), cache) == whole and cache.misses == len(report["nodes"])  # all kept
    hostile = copy.deepcopy(report)
    hostile["meta"]["workspace"] = 'w "<&>"\n\ue000'
    assert render_junit(hostile, FragmentCache()) == render_junit(hostile)
    empty = {**copy.deepcopy(report), "nodes": []}
    assert render_junit(empty, FragmentCache()) == render_junit(empty)
