"""The NoDL stage of ``doit verify`` (docs/nodl.md, "In the report"): examples/manipulator's NoDL
documents beside its contracts are checked by the pipeline and their findings reach
reports/assurance.json, the Markdown report and SARIF at every place they involve.

A copy of the example is verified as it is (the control: the stage ran and found nothing), then with
one seeded mismatch (the Battery's publisher of ``battery`` offers best effort, the ChargeMonitor's
subscription requests reliable: they never connect), found at both documents' lines and failing
``--strict``; a document that cannot be read stops the run with its located line; a record made
from other documents is stale and an altered one is not believed.
"""
from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import pytest

from _report_schema import check_report
from rclverify.cli.commands import main
from rclverify.report.bundle.fresh import report_out_of_date
from rclverify.stages.nodl import INDEX, read_nodl
from rclverify.stages.workspace import Workspace

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "manipulator"


def _copy(dst: Path) -> Path:
    shutil.copytree(EXAMPLE, dst, ignore=shutil.ignore_patterns("artifacts", "reports", ".doit*", "__pycache__"))
    return dst


def _read(ws: Path, name: str = "assurance.json") -> Any:
    return json.loads((ws / "reports" / name).read_text(encoding="utf-8"))


def _nodl_results(ws: Path) -> list[dict[str, Any]]:
    return [r for r in _read(ws, "assurance.sarif")["runs"][0]["results"] if r["ruleId"] == "RCL-NODL"]


def _line_of(path: Path, text: str, nth: int = 1) -> int:
    """The 1-based line of the ``nth`` line of ``path`` holding ``text``."""
    hits = [i for i, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1) if text in line]
    return hits[nth - 1]


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    ws = _copy(tmp_path_factory.mktemp("nodl_verify") / "manipulator")
    assert main(["verify", "-w", str(ws)]) == 0
    out: dict[str, Any] = {"ws": ws, "clean": _read(ws), "clean_sarif": _nodl_results(ws),
                           "clean_md": (ws / "reports" / "assurance.md").read_text(encoding="utf-8")}
    battery = ws / "nodl" / "Battery.nodl.yaml"
    battery.write_text(battery.read_text(encoding="utf-8").replace("reliability: RELIABLE", "reliability: BEST_EFFORT"),
                       encoding="utf-8")
    out["strict_exit"] = main(["verify", "-w", str(ws), "--strict"])
    out["seeded"], out["seeded_sarif"] = _read(ws), _nodl_results(ws)
    return out


def test_the_examples_documents_are_checked_clean_by_verify(runs: dict[str, Any]) -> None:
    report = runs["clean"]
    check_report(report, "manipulator")
    nodl = report["nodl"]
    assert sorted(nodl["documents"]) == ["Arm", "Battery", "ChargeMonitor", "Docking", "EStop", "JointLimiter",
                                         "ObstacleGuard", "Planner", "SpeedGovernor"]
    assert nodl["counts"] == {"error": 0, "warning": 0} and nodl["findings"] == [] and "stale" not in nodl
    assert set(nodl["inputs"]) >= {"contracts/plan.yaml", "contracts/manipulator.rcl", "nodl/Battery.nodl.yaml"}
    assert runs["clean_sarif"] == []
    assert "## NoDL node interfaces" in runs["clean_md"] and "No NoDL findings" in runs["clean_md"]


def test_a_seeded_qos_mismatch_is_found_at_both_documents_lines(runs: dict[str, Any]) -> None:
    ws, report = runs["ws"], runs["seeded"]
    check_report(report, "manipulator seeded")
    [f] = report["nodl"]["findings"]
    at = [(p["file"], p["line"]) for p in f["places"]]
    assert f["code"] == "nodl-qos" and f["severity"] == "error" and "BEST_EFFORT" in f["message"]
    # the subscriber's request first (the reader), then the publisher's offer
    assert at == [("nodl/ChargeMonitor.nodl.yaml", _line_of(ws / "nodl" / "ChargeMonitor.nodl.yaml", "reliability:", 2)),
                  ("nodl/Battery.nodl.yaml", _line_of(ws / "nodl" / "Battery.nodl.yaml", "reliability: BEST_EFFORT"))]
    assert runs["strict_exit"] == 1 and not report["meta"]["strict_ok"]
    assert any(p.startswith("NoDL nodl-qos at nodl/ChargeMonitor.nodl.yaml:") for p in report["summary"]["problems"])
    [res] = runs["seeded_sarif"]
    region = res["locations"][0]["physicalLocation"]
    related = res["relatedLocations"][0]["physicalLocation"]
    assert (region["artifactLocation"]["uri"], region["region"]["startLine"]) == at[0]
    assert (related["artifactLocation"]["uri"], related["region"]["startLine"]) == at[1]
    assert res["level"] == "error"


def test_a_record_of_other_documents_is_stale_and_an_altered_one_an_error(runs: dict[str, Any]) -> None:
    ws: Path = runs["ws"]
    doc = ws / "nodl" / "EStop.nodl.yaml"
    kept = doc.read_text(encoding="utf-8")
    try:
        doc.write_text(kept + "# edited after the run\n", encoding="utf-8")
        row = read_nodl(Workspace(ws, "contracts/plan.yaml"))
        assert row is not None and "other NoDL documents" in str(row.get("stale"))
        # nor does a bundle pack the report written before the edit (meta.inputs_sha256)
        assert "built from other inputs" in " ".join(report_out_of_date(Workspace(ws, "contracts/plan.yaml")))
    finally:
        doc.write_text(kept, encoding="utf-8")
    assert "stale" not in (read_nodl(Workspace(ws, "contracts/plan.yaml")) or {"stale": "none read"})
    assert report_out_of_date(Workspace(ws, "contracts/plan.yaml")) == []
    record = ws / INDEX
    text = record.read_text(encoding="utf-8")
    record.write_text(text.replace('"error": 1', '"error": 0'), encoding="utf-8")
    row = read_nodl(Workspace(ws, "contracts/plan.yaml"))
    findings: Any = (row or {}).get("findings")
    assert [f["code"] for f in findings] == ["nodl-record"]
    record.write_text(text, encoding="utf-8")


def test_an_unreadable_document_stops_verify_at_its_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    ws = _copy(tmp_path / "manipulator")
    doc = ws / "nodl" / "Planner.nodl.yaml"
    doc.write_text(doc.read_text(encoding="utf-8").replace("type: geometry_msgs", "tipe: geometry_msgs", 1), encoding="utf-8")
    line = _line_of(doc, "tipe:")
    assert main(["verify", "-w", str(ws)]) != 0
    err = capsys.readouterr()
    text = err.out + err.err
    assert f"nodl/Planner.nodl.yaml:{line}:" in text and "Traceback" not in text


def test_a_workspace_without_documents_has_no_nodl_part(tmp_path: Path) -> None:
    ws = _copy(tmp_path / "manipulator")
    shutil.rmtree(ws / "nodl")
    assert read_nodl(Workspace(ws, "contracts/plan.yaml")) is None


def test_a_parameters_declared_constraints_ensure_an_environment_assumption(tmp_path: Path) -> None:
    """tests/data/nodl/ws: Base assumes ``0 < in.limit and in.limit <= MaxSpeed`` of the input its parameter
    ``limit`` sets, declared ``gt 0`` and ``lt_eq 1.2``: both conjuncts are ensured (Z3: proved), which the
    report's environment assumptions say; declared ``lt_eq 1.8`` the second is refuted, an error at the
    conjunct and at the parameter, and no longer said to be ensured."""
    ws = tmp_path / "ws"
    shutil.copytree(Path(__file__).parent.parent / "data" / "nodl" / "ws", ws)
    assert main(["verify", "-w", str(ws)]) == 0
    report = _read(ws)
    check_report(report, "nodl ws")
    assert [(s["conjunct"], s["status"]) for s in report["nodl"]["side_conditions"]] == [
        ("0 < in.limit", "proved"), ("in.limit <= MaxSpeed", "proved")]
    md = (ws / "reports" / "assurance.md").read_text(encoding="utf-8")
    assert md.count("ensured by NoDL parameter `limit`") == 2
    doc = ws / "nodl" / "Base.nodl.json"
    doc.write_text(doc.read_text(encoding="utf-8").replace('"lt_eq<>": [1.2]', '"lt_eq<>": [1.8]'), encoding="utf-8")
    assert main(["verify", "-w", str(ws)]) == 0
    report = _read(ws)
    [f] = [f for f in report["nodl"]["findings"] if f["code"] == "nodl-parameter-assume"]
    rcl = (ws / "contracts" / "robot.rcl").read_text(encoding="utf-8").splitlines()
    assert [(p["file"], p["line"]) for p in f["places"]] == [
        ("contracts/robot.rcl", next(i for i, t in enumerate(rcl, 1) if "assume( 0 < in.limit" in t)),
        ("nodl/Base.nodl.json", _line_of(doc, '"limit"'))]
    assert "limit = 9/5" in f["message"] or "limit = 1.8" in f["message"], f["message"]
    md = (ws / "reports" / "assurance.md").read_text(encoding="utf-8")
    assert md.count("ensured by NoDL parameter `limit`") == 1 and not report["meta"]["strict_ok"]


def test_the_terminal_summary_lists_each_nodl_error_at_its_lines(runs: dict[str, Any],
                                                                 capsys: pytest.CaptureFixture[str]) -> None:
    """What ``verify`` ends with (read back from the last run's summary, as ``rclverify explain`` prints
    it) counts the seeded NoDL error on the overall line and lists it at both documents' lines; the
    clean run's summary has no NoDL line (the control)."""
    from rclverify.report.summary import print_last_run, status_text, summary_data
    ws = runs["ws"]
    print_last_run(ws)
    out = capsys.readouterr().out
    sub = _line_of(ws / "nodl" / "ChargeMonitor.nodl.yaml", "reliability:", 2)
    pub = _line_of(ws / "nodl" / "Battery.nodl.yaml", "reliability: BEST_EFFORT")
    assert out.splitlines()[0].endswith("; 1 NoDL error."), out
    [line] = [t for t in out.splitlines() if "[nodl-qos]" in t]
    assert line.lstrip().startswith(f"nodl/ChargeMonitor.nodl.yaml:{sub}:") and f"nodl/Battery.nodl.yaml:{pub}:" in line
    assert "1 NoDL error: " in out
    clean = "\n".join(status_text(summary_data(runs["clean"])))
    assert "NoDL" not in clean and "nodl-" not in clean


def test_junit_has_a_nodl_suite_with_a_failing_case_per_error(runs: dict[str, Any]) -> None:
    """reports/assurance.junit.xml of the seeded run: a ``nodl`` suite, its one failing case at the
    reader's document line; the clean report's suite is one passing case (the control)."""
    import xml.etree.ElementTree as ET
    from rclverify.report.junit import junit_tree
    ws = runs["ws"]
    root = ET.parse(ws / "reports" / "assurance.junit.xml").getroot()
    [suite] = [s for s in root.iter("testsuite") if s.get("name") == "nodl"]
    [case] = list(suite.iter("testcase"))
    failure = case.find("failure")
    assert failure is not None and "[nodl-qos]" in str(failure.get("message"))
    assert (case.get("file"), case.get("line")) == (
        "nodl/ChargeMonitor.nodl.yaml", str(_line_of(ws / "nodl" / "ChargeMonitor.nodl.yaml", "reliability:", 2)))
    assert "nodl/Battery.nodl.yaml:" in str(failure.text)
    assert (suite.get("tests"), suite.get("failures")) == ("1", "1")
    [clean] = [s for s in junit_tree(runs["clean"]).iter("testsuite") if s.get("name") == "nodl"]
    assert (clean.get("tests"), clean.get("failures"), clean.get("errors")) == ("1", "0", "0")
    assert [c.find("failure") for c in clean.iter("testcase")] == [None]
