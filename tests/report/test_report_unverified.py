"""Guarantees no obligation covers are `unverified` everywhere the report
speaks (issue 30, item 1; report/unverified.py): the summary, the problems,
the dashboard, the terminal's table and problem list, SARIF, JUnit, and
--strict's message; the overall status is never better than that."""
from __future__ import annotations

import json
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import jsonschema
import pytest

from _drone_ws import DATA, copy, set_nodes, verify
from rclverify.report.diagnosis_text import status_lines
from rclverify.report.summary import print_summary, summary_data
from rclverify.app.tasks import act_verify

HOARE_FC = """  FlightController:
    evidence:
      - backend: hoare
        program: backends/hoare/flight_controller.imp
        binding: {in.target_altitude: target, out.altitude: altitude}
"""
HOARE_MP = """  MissionPlanner:
    evidence:
      - backend: hoare
        program: backends/hoare/mission_planner.imp
        binding: {in.battery: battery, in.inside: inside, out.target_altitude: target}
"""


def _partly_covered(tmp_path: Path) -> Path:
    """The drone with evidence for MissionPlanner and FlightController only:
    BatteryMonitor's two guarantees and Geofence's one have no obligation."""
    root = copy(tmp_path, "drone")
    set_nodes(root, "nodes:\n  BatteryMonitor: {}\n  Geofence: {}\n" + HOARE_MP + HOARE_FC)
    return root


@pytest.fixture(scope="module")
def partly(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, Any]]:
    """The partly covered drone verified once for the module: its root and its report, read (never
    changed) by the tests below."""
    root = _partly_covered(tmp_path_factory.mktemp("partly"))
    _, report = verify(root)
    return root, report


def test_guarantees_without_an_obligation_are_listed_counted_and_problems(
        partly: tuple[Path, dict[str, Any]]) -> None:
    root, report = partly
    assert [u["id"] for u in report["unverified"]] == ["BatteryMonitor.g1", "BatteryMonitor.g2", "Geofence.g1"]
    assert {u["source"] for u in report["unverified"]} == {"contracts/battery_monitor.rcl:10:3",
                                                           "contracts/battery_monitor.rcl:12:3",
                                                           "contracts/geofence.rcl:8:3"}
    geofence = next(n for n in report["nodes"] if n["name"] == "Geofence")
    assert geofence["status"] == "unverified" and geofence["guarantees"][0]["status"] == "unverified"
    # the obligations that exist are all discharged; the headline no longer reads as all done
    assert report["summary"]["counts"] == {"discharged": 4}
    assert "4 obligations: 4 discharged; 3 guarantees unverified (no obligation covers them)" \
        in report["summary"]["headline"]
    assert any(p.startswith("Guarantee Geofence.g1 (contracts/geofence.rcl:8:3) is unverified")
               for p in report["summary"]["problems"])
    rows = [g for g in report["problems"] if g["status"] == "unverified"]
    assert [[m["id"] for m in g["members"]] for g in rows] == [["BatteryMonitor.g1", "BatteryMonitor.g2"],
                                                               ["Geofence.g1"]]
    assert [c["source"] for c in rows[1]["culprits"]] == ["contracts/geofence.rcl:8:3"]
    # the terminal: the problem list and the per-node table
    data = summary_data(report)
    lines = status_lines(data)
    assert any(line.strip() == "findings: Geofence.g1" for line in lines)
    from io import StringIO
    out = StringIO()
    print_summary(data, "reports/assurance.html", file=out, terminal=False, rows=data["rows"])
    table = out.getvalue()
    assert "| unverified" in table and "g1, g2" in table and "3 guarantees" in table
    # the HTML: the dashboard's column and the list under "Pending and why"
    html = (root / "reports" / "assurance.html").read_text(encoding="utf-8")
    assert "<th>no evidence</th>" in html and "Unverified guarantees (3)" in html
    assert "Nothing is pending." not in html
    md = (root / "reports" / "assurance.md").read_text(encoding="utf-8")
    assert "Unverified guarantees (3)" in md


def test_sarif_and_junit_carry_each_unverified_guarantee(partly: tuple[Path, dict[str, Any]]) -> None:
    root, _ = partly
    log = json.loads((root / "reports" / "assurance.sarif").read_text(encoding="utf-8"))
    jsonschema.validate(log, json.loads((DATA / "sarif-schema-2.1.0.json").read_text(encoding="utf-8")))
    results = [r for r in log["runs"][0]["results"] if r["ruleId"] == "RCL-GUARANTEE-UNVERIFIED"]
    where = [(r["locations"][0]["physicalLocation"]["artifactLocation"]["uri"],
              r["locations"][0]["physicalLocation"]["region"]["startLine"],
              r["locations"][0]["physicalLocation"]["region"]["startColumn"]) for r in results]
    assert where == [("contracts/battery_monitor.rcl", 10, 3), ("contracts/battery_monitor.rcl", 12, 3),
                     ("contracts/geofence.rcl", 8, 3)]
    assert all(r["level"] == "warning" for r in results)
    tree = ET.parse(root / "reports" / "assurance.junit.xml")
    cases = {c.get("name"): c for c in tree.iter("testcase") if c.get("classname", "").endswith(".guarantee")}
    assert sorted(cases) == ["BatteryMonitor.g1", "BatteryMonitor.g2", "Geofence.g1"]
    failure = cases["Geofence.g1"].find("failure")
    assert failure is not None and failure.get("type") == "unverified"
    assert cases["Geofence.g1"].get("file") == "contracts/geofence.rcl" and cases["Geofence.g1"].get("line") == "8"


def test_strict_names_the_unverified_guarantees(partly: tuple[Path, dict[str, Any]], capsys) -> None:
    root, report = partly
    assert report["meta"]["strict_ok"] is False
    failed = act_verify(str(root), True)
    capsys.readouterr()
    assert failed is not None
    assert "3 guarantees are unverified (no obligation covers them): BatteryMonitor.g1, BatteryMonitor.g2, " \
           "Geofence.g1" in str(failed)


def test_the_overall_status_is_never_better_than_unverified(tmp_path: Path) -> None:
    """A system with nothing wrong but a guarantee without evidence is
    `unverified`, not `discharged`; with the evidence entry it is discharged."""
    root = tmp_path / "one"
    (root / "contracts").mkdir(parents=True)
    (root / "backends" / "hoare").mkdir(parents=True)
    (root / "contracts" / "flight_controller.rcl").write_text(
        (DATA / "drone" / "contracts" / "flight_controller.rcl").read_text(encoding="utf-8"), encoding="utf-8")
    (root / "backends" / "hoare" / "flight_controller.imp").write_text(
        (DATA / "drone" / "backends" / "hoare" / "flight_controller.imp").read_text(encoding="utf-8"), encoding="utf-8")
    (root / "contracts" / "plan.yaml").write_text(
        "name: one\ncontracts: [contracts/flight_controller.rcl]\nrequirements: []\nconnections: []\n"
        "environment: {}\nnodes:\n  FlightController: {}\n", encoding="utf-8")
    _, report = verify(root)
    assert report["summary"]["status"] == "unverified"
    assert [u["id"] for u in report["unverified"]] == ["FlightController.g1"]
    assert report["summary"]["headline"].startswith("no obligations; 1 guarantee unverified (no obligation covers it)")
    set_nodes(root, "nodes:\n" + HOARE_FC)
    _, report = verify(root)
    assert report["summary"]["status"] == "discharged" and report["unverified"] == []
    assert report["meta"]["strict_ok"] is True


def test_explain_prints_an_unverified_guarantee(partly: tuple[Path, dict[str, Any]], capsys) -> None:
    from rclverify.cli.commands import main
    root, _ = partly
    capsys.readouterr()
    assert main(["explain", "-w", str(root), "Geofence.g1"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("Geofence.g1 [unverified] (guarantee 1 of Geofence, contracts/geofence.rcl:8:3)")
    assert "no evidence entry of the plan covers it (`unverified`" in out
