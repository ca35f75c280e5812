"""examples/fleet_robots: two robots from one contract set (issue 110; docs/plan.md "Instances in the
report").  ``rclverify verify`` (doit's verify) is green and its report lists each instance with its
resolved names, its inputs' feeders and its contract's obligations, and each requirement per robot;
a namespace slip in the contracts (the fleet's speed limit named relative, so that each robot reads
its own, which nothing publishes) is found by the fleet's system model, per robot, while the
type-level check still proves it (the control: the example as it is); a slip in the code (``/r2``'s
guard reading ``/r1/battery/level``) is found by the NoDL check against the graph recorded from the
example's real rclpy nodes (nodes/robots.py), at ``/r2``'s guard only (the control: the graph of
the fleet as written).  tests/model/test_fleet_example_live.py monitors the same nodes live."""
from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import pytest

from _report_schema import check_report
from rclverify.app.pipeline import stage_check
from rclverify.cli.commands import main
from rclverify.stages.instances import INDEX, read_instances, stage_instances
from rclverify.stages.requirements import stage_requirements
from rclverify.stages.workspace import Workspace

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "fleet_robots"
RELATIVE_LIMIT = "std_msgs/Float64 speed_limit matches(in.limit)"


def _copy(tmp: Path) -> Path:
    root = tmp / "ws"
    shutil.copytree(EXAMPLE, root, ignore=shutil.ignore_patterns("artifacts", "reports", ".doit*", "__pycache__"))
    return root


def _stages(root: Path) -> tuple[dict[str, str], dict[str, Any]]:
    """The type-level verdicts and the instances stage's record."""
    ws = Workspace(root, "contracts/plan.yaml")
    stage_check(ws)
    types = {rec["id"]: str(rec["verdict"]) for rec, _ in stage_requirements(ws)}
    rec = stage_instances(ws)
    assert rec is not None
    return types, rec


def test_verify_is_green_and_the_report_lists_every_instance(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    root = _copy(tmp_path)
    assert main(["verify", "-w", str(root)]) == 0, capsys.readouterr().out[-3000:]
    report = json.loads((root / "reports/assurance.json").read_text(encoding="utf-8"))
    check_report(report, "fleet_robots")  # against docs/assurance.schema.json and the status vocabulary
    part = report["instances"]
    assert report["summary"]["status"] == "discharged" and report["meta"]["strict_ok"] is True
    assert [i["node"] for i in part["instances"]] == [
        "Planner_r1", "Planner_r2", "Battery_r1", "Battery_r2", "Guard_r1", "Guard_r2"]
    g2 = next(i for i in part["instances"] if i["node"] == "Guard_r2")
    assert g2["ros_node"] == "/r2/guard" and g2["source"] == "contracts/plan.yaml:12:16"
    assert {n["name"]: n["resolved"] for n in g2["names"]} == {
        "cmd_raw": "/r2/cmd_raw", "battery/level": "/r2/battery/level", "/fleet/speed_limit": "/fleet/speed_limit",
        "cmd_vel": "/r2/cmd_vel"}
    assert {x["var"]: x["source"] for x in g2["inputs"]} == {
        "cmd_raw": "Planner_r2.out.cmd_raw", "level": "Battery_r2.out.level", "limit": "SpeedLimit.out.limit"}
    assert [(o["id"], o["status"]) for o in g2["obligations"]] == [  # the recorded run judged for /r2's guard
        ("Guard.g0.monitors.fleet_jsonl_Guard_r2", "discharged"),
        ("Guard.g1.property_tests.e0", "discharged"), ("Guard.g2.property_tests.e0", "discharged")]
    assert sorted((q["id"], q["namespace"], q["verdict"]) for q in part["requirements"]) == [
        ("BATTERY-GUARD", "/r1", "proved"), ("BATTERY-GUARD", "/r2", "proved"),
        ("FLEET-LIMIT", "/r1", "proved"), ("FLEET-LIMIT", "/r2", "proved")]
    md = (root / "reports/assurance.md").read_text(encoding="utf-8")
    assert "## Fleet: instances per namespace" in md and "`Battery_r2.out.level < 0.2 -> Guard_r2.out.cmd_vel == 0`" in md
    assert 'id="instances"' in (root / "reports/assurance.html").read_text(encoding="utf-8")


def test_the_recorded_slip_is_red_at_r2s_guard_only(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """``doit verify`` judges the run recorded live from nodes/robots.py --slip (runs/slip.jsonl) once per
    robot: ``/r2``'s guard, reading ``/r1``'s battery, drives on below 0.2, red at Guard_r2 only, with the
    11 violations the live monitor found; the control is the example's own run (runs/fleet.jsonl, above),
    green at both guards."""
    root = _copy(tmp_path)
    plan = root / "contracts/plan.yaml"
    plan.write_text(plan.read_text(encoding="utf-8").replace("runs/fleet.jsonl", "runs/slip.jsonl"), encoding="utf-8")
    assert main(["verify", "-w", str(root), "--strict"]) == 1
    capsys.readouterr()
    report = json.loads((root / "reports/assurance.json").read_text(encoding="utf-8"))
    check_report(report, "fleet_robots")
    by_node = {i["node"]: {o["id"]: o["status"] for o in i["obligations"] if ".monitors." in o["id"]}
               for i in report["instances"]["instances"] if i["contract"] == "Guard"}
    assert by_node == {"Guard_r1": {"Guard.g0.monitors.slip_jsonl_Guard_r1": "discharged"},
                       "Guard_r2": {"Guard.g0.monitors.slip_jsonl_Guard_r2": "failed"}}
    ev = json.loads((root / "artifacts/evidence/Guard.g0.monitors.slip_jsonl_Guard_r2.json").read_text(encoding="utf-8"))
    assert ev["explanation"].startswith("11 message(s) of runs/slip.jsonl violated Guard_r2's contract")
    first = ev["details"]["monitoring"]["first_violation"]
    assert first["guarantee"] == 2 and float(first["values"]["in.level"]) < 0.2 and first["values"]["out.cmd_vel"] == "1.0"


def test_a_fleet_topic_named_relative_is_refuted_per_robot_and_proved_for_the_type(tmp_path: Path) -> None:
    root = _copy(tmp_path)
    rcl = root / "contracts/fleet.rcl"
    rcl.write_text(rcl.read_text(encoding="utf-8").replace(
        "std_msgs/Float64 /fleet/speed_limit matches(in.limit)", RELATIVE_LIMIT), encoding="utf-8")
    types, rec = _stages(root)
    assert types == {"BATTERY-GUARD": "proved", "FLEET-LIMIT": "proved"}  # the types: linked by the name limit
    per = {(q["id"], q["namespace"]): q for q in rec["requirements"]}
    for ns in ("r1", "r2"):
        q = per[("FLEET-LIMIT", f"/{ns}")]
        assert q["verdict"] == "refuted" and q["unfed"] == [f"Guard_{ns}.in.limit"], q
        assert per[("BATTERY-GUARD", f"/{ns}")]["verdict"] == "proved"
        guard = next(i for i in rec["instances"] if i["node"] == f"Guard_{ns}")
        assert {n["name"]: n["resolved"] for n in guard["names"]}["speed_limit"] == f"/{ns}/speed_limit"
    assert {(e["node"], e["var"]) for e in rec["environment_inputs"]} == {("Guard_r1", "limit"), ("Guard_r2", "limit")}
    # control: the example as written, the limit named /fleet/speed_limit, proved for both robots
    _types, fine = _stages(_copy(tmp_path / "control"))
    assert {(q["id"], q["namespace"], q["verdict"]) for q in fine["requirements"]} == {
        ("BATTERY-GUARD", "/r1", "proved"), ("BATTERY-GUARD", "/r2", "proved"),
        ("FLEET-LIMIT", "/r1", "proved"), ("FLEET-LIMIT", "/r2", "proved")}
    assert fine["environment_inputs"] == []


def test_verify_fails_when_a_requirement_is_refuted_for_a_robot(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    root = _copy(tmp_path)
    rcl = root / "contracts/fleet.rcl"
    rcl.write_text(rcl.read_text(encoding="utf-8").replace(
        "std_msgs/Float64 /fleet/speed_limit matches(in.limit)", RELATIVE_LIMIT), encoding="utf-8")
    main(["verify", "-w", str(root)])
    capsys.readouterr()
    report = json.loads((root / "reports/assurance.json").read_text(encoding="utf-8"))
    check_report(report, "fleet_robots, the limit relative")
    assert report["summary"]["status"] == "failed" and report["meta"]["strict_ok"] is False
    assert "requirement FLEET-LIMIT is refuted for the instances in /r2 (Guard as Guard_r2): not prevented by " \
           "SpeedLimit guarantee 1, Guard_r2 guarantee 1; fed by no node: Guard_r2.in.limit" in report["summary"]["problems"]
    # the types' proof stands, but the recorded run cannot be judged for the guards: each reads its own
    # /rN/speed_limit, which the fleet's run does not hold (the recorded run finds the slip too)
    assert [r["status"] for r in report["requirements"] if r["id"] == "FLEET-LIMIT"] == ["pending"]
    ev = json.loads((root / "artifacts/evidence/Guard.g0.monitors.fleet_jsonl_Guard_r1.json").read_text(encoding="utf-8"))
    assert ev["status"] == "pending" and {"kind": "topic", "name": "/r1/speed_limit", "node": "Guard_r1",
                                          "reason": "nothing heard", "detail": "no message on /r1/speed_limit in "
                                          "runs/fleet.jsonl"} in ev["details"]["not_judged"]


def test_a_robot_without_an_instance_the_requirement_names_is_not_decided_there(tmp_path: Path) -> None:
    root = _copy(tmp_path)
    plan = root / "contracts/plan.yaml"
    plan.write_text(plan.read_text(encoding="utf-8").replace("Battery: [/r1, /r2]", "Battery: [/r1]"), encoding="utf-8")
    _types, rec = _stages(root)
    per = {(q["id"], q["namespace"]): q for q in rec["requirements"]}
    r2 = per[("BATTERY-GUARD", "/r2")]
    assert r2["verdict"] == "inconclusive" and r2["missing"] == ["Battery"] and "Battery has no instance in /r2" in r2["reason"]
    assert per[("BATTERY-GUARD", "/r1")]["verdict"] == "proved"  # control: the robot with its battery


def test_the_record_is_sealed_and_stale_after_a_plan_edit(tmp_path: Path) -> None:
    root = _copy(tmp_path)
    _stages(root)
    ws = Workspace(root, "contracts/plan.yaml")
    assert "stale" not in (read_instances(ws) or {})  # control: as made
    plan = root / "contracts/plan.yaml"
    plan.write_text(plan.read_text(encoding="utf-8") + "\n# edited\n", encoding="utf-8")
    assert "another text of the plan" in (read_instances(ws) or {})["stale"]
    path = root / INDEX
    path.write_text(path.read_text(encoding="utf-8").replace('"/r2/guard"', '"/r3/guard"'), encoding="utf-8")
    got = read_instances(ws) or {}
    assert got["altered"] and got["instances"] == []


@pytest.mark.parametrize("graph, errors", [("fleet", 0), ("slip", 2)])
def test_nodl_against_the_recorded_graph_finds_the_slip_at_r2s_guard(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], graph: str, errors: int) -> None:
    root = _copy(tmp_path)
    out = tmp_path / "nodl.json"
    code = main(["nodl", "check", "-w", str(root), "--graph", str(root / f"graphs/{graph}.graph.json"),
                 "--json", str(out)])
    got = capsys.readouterr()
    text = got.out + got.err
    assert code == (1 if errors else 0), text
    assert f"{errors} error(s)" in text and "Guard in /r2 -> /r2/guard" in text and "Guard in /r1 -> /r1/guard" in text
    if errors:
        assert "nodl/Guard.nodl.yaml:13:11: error: node /r2/guard's NoDL document declares /r2/battery/level" in text
        assert "node /r2/guard has /r1/battery/level (std_msgs/msg/Float64) in subscriptions" in text
    assert not [line for line in text.splitlines() if "error:" in line and "/r1/guard" in line]  # its own robot
    assert len(json.loads(out.read_text(encoding="utf-8"))["findings"]) == errors
