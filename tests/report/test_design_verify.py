"""The design stage of ``doit verify`` (docs/nodl.md, "The design stage"): a plan naming an Autoware System
Designer design (``design: DIR``) has its monitoring fields decided by the pipeline, incrementally, with the
verdicts and findings in reports/assurance.json and the Markdown report.

tests/model/test_design.py's design of our own is imported into a workspace (its filter answers within 150 ms)
and copied into it; the plan names it.  Verified as it is (the control): every timeout and rate proved but the
goal's, which nothing bounds (undecided, a warning).  Run again with nothing changed, the stage does not run.
With the filter's contract deadline made 250 ms (the seeded defect), the tracker's timeout (300 ms) and error
rate (4 Hz) and the planner's timeout (600 ms) are refuted, each at the design's field and at the contract
clauses of its chain, and ``--strict`` fails on them.
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from _report_schema import check_report
from rclverify.cli.commands import main
from rclverify.stages.design import INDEX
from test_design import _design

pytestmark = pytest.mark.slow  # two runs of the whole pipeline


def _read(ws: Path) -> Any:
    return json.loads((ws / "reports" / "assurance.json").read_text(encoding="utf-8"))


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    root = tmp_path_factory.mktemp("design_verify")
    _design(root / "design")
    assert main(["import", "autoware-design", str(root / "design"), "-o", str(root / "ws")]) == 0
    ws = root / "ws"  # the import copied the design into ws/design and named it in the plan (design: "design")
    out: dict[str, Any] = {"ws": ws, "code": main(["verify", "-w", str(ws)]), "clean": _read(ws),
                           "clean_md": (ws / "reports" / "assurance.md").read_text(encoding="utf-8"),
                           "clean_sarif": _design_results(ws), "clean_junit": _design_suite(ws)}
    made = (ws / INDEX).stat().st_mtime_ns
    out["again"] = main(["verify", "-w", str(ws)])
    out["rerun"] = (ws / INDEX).stat().st_mtime_ns != made
    rcl = ws / "contracts" / "design.rcl"
    rcl.write_text(rcl.read_text(encoding="utf-8").replace("in.points within 150 ms", "in.points within 250 ms"),
                   encoding="utf-8")
    out["strict"] = main(["verify", "-w", str(ws), "--strict"])
    out["seeded"] = _read(ws)
    out["seeded_md"] = (ws / "reports" / "assurance.md").read_text(encoding="utf-8")
    out["seeded_sarif"], out["seeded_junit"] = _design_results(ws), _design_suite(ws)
    return out


def _design_results(ws: Path) -> list[dict[str, Any]]:
    """The RCL-DESIGN results of reports/assurance.sarif."""
    log = json.loads((ws / "reports" / "assurance.sarif").read_text(encoding="utf-8"))
    return [r for r in log["runs"][0]["results"] if r["ruleId"] == "RCL-DESIGN"]


def _design_suite(ws: Path) -> Any:
    """The ``design`` testsuite of reports/assurance.junit.xml."""
    import xml.etree.ElementTree as ET
    root = ET.parse(ws / "reports" / "assurance.junit.xml").getroot()
    return next(s for s in root.iter("testsuite") if s.get("name") == "design")


def test_the_design_that_fits_is_proved_by_verify(runs: dict[str, Any]) -> None:
    report = runs["clean"]
    check_report(report, "design clean")
    d = report["design"]
    assert runs["code"] == 0 and d["design"] == "design" and d["system"] == "Rover"
    assert (d["counts"]["proved"], d["counts"]["refuted"], d["counts"]["undecided"], d["counts"]["error"]) == (5, 0, 1, 0)
    tracker = [f for f in d["decided"] if f["node"] == "perception_tracker" and f["field"] == "timeout"]
    assert tracker and tracker[0]["status"] == "proved" and tracker[0]["bound"] == "250 ms" and tracker[0]["limit"] == "300 ms"
    assert [f["code"] for f in d["findings"]] == ["design-undecided"]
    assert set(d["inputs"]) >= {"contracts/plan.yaml", "contracts/design.rcl", "design/node/Tracker.node.yaml"}
    assert "stale" not in d and not [p for p in report["summary"]["problems"] if p.startswith("design")]
    assert "## Design: monitoring fields against the contracts" in runs["clean_md"]
    assert "| perception\\_tracker | in.objects | timeout | 300 ms | 250 ms | **proved** |" in runs["clean_md"]


def test_the_stage_does_not_run_again_when_nothing_changed(runs: dict[str, Any]) -> None:
    assert runs["again"] == 0 and runs["rerun"] is False


def test_a_deadline_the_design_cannot_meet_is_refuted_in_the_report_and_fails_strict(runs: dict[str, Any]) -> None:
    report, ws = runs["seeded"], runs["ws"]
    check_report(report, "design seeded")
    d = report["design"]
    assert (d["counts"]["refuted"], d["counts"]["error"]) == (3, 3) and "stale" not in d
    timeout = [f for f in d["findings"] if f["code"] == "design-timeout" and f["message"].startswith("perception_tracker ")]
    assert len(timeout) == 1 and "350 ms > 300 ms" in timeout[0]["message"]
    places = [p["file"] for p in timeout[0]["places"]]
    assert places == ["design/node/Tracker.node.yaml", "contracts/design.rcl", "contracts/design.rcl"]
    tracker_yaml = (ws / "design/node/Tracker.node.yaml").read_text(encoding="utf-8").splitlines()
    assert "timeout: 0.3" in tracker_yaml[timeout[0]["places"][0]["line"] - 1]
    assert any(p.startswith("design design-timeout at design/node/Tracker.node.yaml:") for p in report["summary"]["problems"])
    assert runs["strict"] != 0 and report["meta"]["strict_ok"] is False
    assert "| perception\\_tracker | in.objects | timeout | 300 ms | 350 ms | **refuted** |" in runs["seeded_md"]


def _where(r: dict[str, Any]) -> tuple[str, int]:
    loc = r["locations"][0]["physicalLocation"]
    return loc["artifactLocation"]["uri"], loc["region"]["startLine"]


def test_the_design_fields_are_sarif_results_and_junit_cases_at_the_design_files_lines(runs: dict[str, Any]) -> None:
    """Each monitoring field is one SARIF result of RCL-DESIGN and one JUnit case, at its line in the design file:
    in the clean run the tracker's timeout is met (a note, a passing case) and the goal's timeout undecided (a
    warning, a skipped case); in the seeded run the tracker's timeout is refuted (an error with the contract
    clauses as related locations, a failing case) and the suite counts three failures."""
    ws = runs["ws"]
    tracker_yaml = (ws / "design/node/Tracker.node.yaml").read_text(encoding="utf-8").splitlines()

    def tracker_timeout(results: list[dict[str, Any]]) -> dict[str, Any]:
        [r] = [r for r in results if r["properties"]["node"] == "perception_tracker"
               and r["properties"]["field"] == "timeout"]
        return r
    clean, seeded = tracker_timeout(runs["clean_sarif"]), tracker_timeout(runs["seeded_sarif"])
    assert len(runs["clean_sarif"]) == 6 == len(runs["seeded_sarif"])  # one per field, no finding twice
    file, line = _where(clean)
    assert file == "design/node/Tracker.node.yaml" and "timeout: 0.3" in tracker_yaml[line - 1]
    assert clean["level"] == "note" and "holds" in clean["message"]["text"] and "250 ms <= 300 ms" in clean["message"]["text"]
    assert "relatedLocations" in clean  # the chain it holds by
    goal = [r for r in runs["clean_sarif"] if r["properties"]["status"] == "undecided"]
    assert [r["level"] for r in goal] == ["warning"] and "[design-undecided]" in goal[0]["message"]["text"]
    assert _where(seeded) == (file, line) and seeded["level"] == "error"
    assert "350 ms > 300 ms" in seeded["message"]["text"] and "[design-timeout]" in seeded["message"]["text"]
    assert {r["physicalLocation"]["artifactLocation"]["uri"] for r in seeded["relatedLocations"]} == {"contracts/design.rcl"}
    assert sorted(r["level"] for r in runs["seeded_sarif"]) == ["error", "error", "error", "note", "note", "warning"]

    def case(suite: Any) -> Any:
        [c] = [c for c in suite.iter("testcase") if c.get("name") == "perception_tracker in.objects timeout"]
        return c
    clean_case, seeded_case = case(runs["clean_junit"]), case(runs["seeded_junit"])
    assert clean_case.get("file") == file and clean_case.get("line") == str(line) and len(clean_case) == 0  # passes
    failure = seeded_case.find("failure")
    assert failure is not None and "350 ms > 300 ms" in failure.get("message", "")
    assert runs["clean_junit"].get("failures") == "0" and runs["clean_junit"].get("skipped") == "1"
    assert runs["seeded_junit"].get("failures") == "3" and runs["seeded_junit"].get("tests") == "6"
