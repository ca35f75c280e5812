"""Problems by root cause on the drone workspaces (issue 30, items 2 and 5):
unrelated bugs stay separate problems, findings of one culprit are one, every
finding is named fully, and a culprit is named only when Z3 showed that
strengthening it removes the counterexample (report/problems.py,
diagnosis/blame.py)."""
from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import pytest

from _drone_ws import copy, verify
from rclverify.report.diagnosis_text import status_lines
from rclverify.report.summary import summary_data

FULL_ID = re.compile(r"^(\w+\.(g\d+(\.[\w.-]+)?|sc\d+|derived)|REQ\d+)$")


@pytest.fixture(scope="module")
def drone(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, Any]]:
    """tests/data/drone verified once for the module: its root and its report, read (never changed) by the
    tests below."""
    root = copy(tmp_path_factory.mktemp("drone"), "drone")
    _, report = verify(root)
    return root, report


def _keys(report: dict) -> list[set[str]]:
    return [set(g["key"]) for g in report["problems"]]


def test_three_seeded_unrelated_bugs_are_three_problems(drone: tuple[Path, dict[str, Any]]) -> None:
    _, report = drone
    assert not report["unverified"]  # every guarantee has evidence: only the seeded bugs are problems
    assert _keys(report) == [
        {"assumption:BatteryMonitor:1"},  # guarantee 1's premise excluded by the assumption (vacuity)
        {"assumption:MissionPlanner:1", "guarantee:BatteryMonitor:2"},  # percent vs fraction
        {"guarantee:MissionPlanner:3"},  # the 150 m bound where REQ1 asks for 120 m
    ]
    members = [[m["id"] for m in g["members"]] for g in report["problems"]]
    assert members == [["BatteryMonitor.g1.non-vacuous"],
                       ["MissionPlanner.sc2", "FlightController.derived", "MissionPlanner.derived"],
                       ["REQ1"]]


def test_two_findings_of_one_culprit_are_one_problem(tmp_path: Path) -> None:
    _, report = verify(copy(tmp_path, "drone-one-culprit"))
    (g,) = report["problems"]
    assert g["key"] == ["assumption:BatteryMonitor:1"]
    assert [m["id"] for m in g["members"]] == ["BatteryMonitor.g1.non-vacuous", "REQ1"]
    assert [q["verdict"] for q in report["requirements"]] == ["proved vacuously"]


def test_the_fraction_mismatch_is_its_own_problem_on_the_terminal_and_in_the_report(
        drone: tuple[Path, dict[str, Any]]) -> None:
    """Item 2: the failed side condition was filed under the vacuity of
    BatteryMonitor guarantee 1 (a guarantee its diagnosis named although it
    plays no part), and findings were listed as bare node names."""
    root, report = drone
    d = next(x for x in report["diagnoses"] if x["id"] == "MissionPlanner.sc2")
    assert [c["source"] for c in d["culprits"]] == ["contracts/mission_planner.rcl:10:31",
                                                    "contracts/battery_monitor.rcl:12:3"]
    lines = status_lines(summary_data(report))
    assert lines[1].startswith("3 problems by root cause")
    row = next(i for i, line in enumerate(lines) if "MissionPlanner.sc2" in line)
    assert lines[row].strip().startswith("findings: MissionPlanner.sc2")
    assert "BatteryMonitor.g1.non-vacuous" not in lines[row]
    assert "assumption 1 of MissionPlanner (contracts/mission_planner.rcl:10:3)" in lines[row - 2]
    assert "`in.battery <= 1`" in lines[row - 1]
    for line in lines:
        if line.strip().startswith("findings: "):
            ids = line.strip()[len("findings: "):].split(", ")
            assert all(FULL_ID.match(i) for i in ids), ids
    md = (root / "reports" / "assurance.md").read_text(encoding="utf-8")
    attention = md[md.index("## What needs attention"):md.index("## System model")]
    assert "MissionPlanner assumes \\`in.battery \\<= 1\\`" in attention and "`MissionPlanner.sc2`" in attention
    html = (root / "reports" / "assurance.html").read_text(encoding="utf-8")
    assert html.count('<tr id="problem-') == 3


def test_a_refuted_requirement_blames_the_bound_z3_showed(drone: tuple[Path, dict[str, Any]]) -> None:
    """Item 5: REQ1 blamed FlightController guarantee 1 (shown discharged);
    the gap is MissionPlanner guarantee 3's bound, and only tightening that
    bound lets Z3 prove REQ1."""
    _, report = drone
    d = next(x for x in report["diagnoses"] if x["id"] == "REQ1")
    assert d["kind"] == "requirement"
    assert [c["source"] for c in d["culprits"]] == ["contracts/mission_planner.rcl:16:3"]
    assert "FlightController" not in " ".join(c["what"] for c in d["culprits"])
    (r,) = d["repairs"]
    assert r["kind"] == "tighten-bound" and "-  guarantee( out.target_altitude <= 150 )" in r["diff"] \
        and "+  guarantee( out.target_altitude <= 120 )" in r["diff"]
    # the counterexample shows the nodes involved only: the culprit's and the one the requirement names
    assert {row["node"] for row in d["counterexample"]} == {"MissionPlanner", "FlightController"}
    fc = next(n for n in report["nodes"] if n["name"] == "FlightController")
    assert fc["status"] == "discharged"


def test_a_side_condition_names_only_the_guarantee_whose_strengthening_discharges_it(
        drone: tuple[Path, dict[str, Any]]) -> None:
    """Item 5: BatteryMonitor guarantee 1 (`in.voltage > 30 -> ...`, whose
    premise never fires) was named for the fraction mismatch, and the
    counterexample showed Geofence's input, which plays no part."""
    _, report = drone
    d = next(x for x in report["diagnoses"] if x["id"] == "MissionPlanner.sc2")
    assert not any("guarantee 1 of BatteryMonitor" in c["what"] for c in d["culprits"])
    assert "guarantee 1" not in d["sentence"]
    assert {row["node"] for row in d["counterexample"]} == {"BatteryMonitor"}
    assert "Geofence" not in d["sentence"]
    # the side condition's own model, as the calculus section, SARIF and JUnit show it
    sc = next(s for s in report["side_conditions"] if s["id"] == "MissionPlanner.sc2")
    assert set(sc["model"]) == {"BatteryMonitor.in.voltage", "BatteryMonitor.out.battery"}


def test_a_row_without_a_culprit_shows_where_it_was_found() -> None:
    data = {"summary": {"status": "failed", "headline": "h"},
            "problems": [{"status": "failed", "sentence": "s", "culprits": [], "where": "contracts/a.rcl:3:5",
                          "members": ["A.derived"], "repairs": 0},
                         {"status": "failed", "sentence": "s", "culprits": [], "where": "", "members": ["x"],
                          "repairs": 0}]}
    lines = status_lines(data)
    assert lines[2] == "  1. [failed] at contracts/a.rcl:3:5: 1 finding"
    assert lines[5] == "  2. [failed] (no culprit named): 1 finding"


def test_every_group_of_the_drone_has_a_location(drone: tuple[Path, dict[str, Any]]) -> None:
    _, report = drone
    assert [g["where"] for g in report["problems"]] == ["contracts/battery_monitor.rcl:10:3",
                                                        "contracts/mission_planner.rcl:10:31",
                                                        "contracts/plan.yaml:12:14"]


def test_explain_prints_findings_without_a_record_of_their_own(drone: tuple[Path, dict[str, Any]], capsys) -> None:
    """Every finding `status` lists can be explained: a derived property by its full name."""
    from rclverify.cli.commands import main
    root, _ = drone
    capsys.readouterr()
    assert main(["explain", "-w", str(root), "FlightController.derived"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("FlightController.derived [failed] (derived property)")
    assert "guarantee 2 of BatteryMonitor (contracts/battery_monitor.rcl:12:3)" in out
    assert "the same root cause, found by: MissionPlanner.sc2, MissionPlanner.derived" in out
    capsys.readouterr()
    assert main(["explain", "-w", str(root), "FlightController"]) == 0  # a node: explained as a node, not a finding
    assert capsys.readouterr().out.startswith("FlightController [")


def test_a_stored_report_without_where_or_unverified_still_renders() -> None:
    """A report dict written before `where` and `unverified` existed (the
    case study's stored report with both removed): its row without a culprit
    (the replacement that does not refine) renders."""
    import gzip
    import json

    from _drone_ws import DATA
    from rclverify.report.render import render_markdown
    report = json.loads(gzip.open(DATA / "case-study-report.json.gz").read())
    report.pop("unverified", None)
    for g in report["problems"]:
        g.pop("where", None)
    assert any(not g["culprits"] for g in report["problems"])
    md = render_markdown(report)
    assert "`Agent.replacement-refines`" in md and "Nothing is pending." not in md


def test_the_terminal_writes_a_file_once_for_culprits_on_several_of_its_lines() -> None:
    from rclverify.report.diagnosis_text import same_file_lines
    assert same_file_lines(["a.gwen:72", "a.gwen:74", "b.imp:15", "guarantee 3 of Agent (x.rcl:72:3)", "b.imp:18"]) \
        == ["a.gwen:72, 74", "b.imp:15", "guarantee 3 of Agent (x.rcl:72:3)", "b.imp:18"]
