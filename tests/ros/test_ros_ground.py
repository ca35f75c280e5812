"""Grounding (``rclverify ros check``): the test rover's contracts against
its catkin workspace; each finding kind from a seeded mistake, located at
the RCL line and at the source/launch/.msg line (docs/ros.md)."""
from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from rclverify.cli.commands import main

WS = Path(__file__).parent.parent / "data" / "ros" / "catkin_ws"


def _ws(tmp_path: Path, rcl_edits: list[tuple[str, str]] = (), plan_edits: list[tuple[str, str]] = ()) -> Path:
    ws = tmp_path / "ws"
    shutil.copytree(WS, ws)
    for rel, edits in (("contracts/rover.rcl", rcl_edits), ("contracts/plan.yaml", plan_edits)):
        p = ws / rel
        text = p.read_text()
        for old, new in edits:
            assert old in text, old
            text = text.replace(old, new)
        p.write_text(text)
    return ws


def _check(ws: Path, *extra: str) -> tuple[int, list[tuple[str, str, str, str]]]:
    out = ws / "findings.json"
    rc = main(["ros", "check", "-w", str(ws), "--json", str(out), *extra])
    data = json.loads(out.read_text())
    loc = lambda d: f"{d['file']}:{d['line']}" if d else "-"  # noqa: E731
    return rc, [(f["code"], loc(f["rcl"]), loc(f["ros"]), f["message"]) for f in data["findings"]]


def test_the_test_rover_is_grounded(tmp_path: Path) -> None:
    rc, fs = _check(_ws(tmp_path), "--strict")
    assert rc == 0
    assert fs == [("ROS-SCAN", "-", "src/rover_sensing/scripts/sensor.py:14",
                   "publisher topic name is 'debug_topic', not a string literal: not resolved statically "
                   "(ROS-UNRESOLVED)")]
    graph = json.loads((tmp_path / "ws" / "artifacts/ros/graph.json").read_text())
    assert [n["name"] for n in graph["nodes"]] == ["/rover/controller", "/rover/sensor"]


def test_seeded_topic_and_type_mistakes(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    ws = _ws(tmp_path, [
        ("rover_msgs/Reading radiation matches(out.reading)", "rover_msgs/Reading radiaton matches(out.reading)"),
        ("inputs( reading : REAL )", "inputs( reading : REAL, temp : REAL )"),
        ("rover_msgs/Status status matches(out.level),\n", "rover_msgs/Readng temperature matches(in.temp),\n"),
        ("geometry_msgs/Twist cmd_vel", "geometry_msgs/Point cmd_vel"),
        ("}\n\nnode Controller", "}\n\nnode Planner {\n  inputs( reading : REAL )\n  outputs( )\n"
                               "  topics( rover_msgs/Reading radiation matches(in.reading) )\n"
                               "  guarantee( TRUE )\n}\n\nnode Controller"),
    ], [("odom: [pose.pose.position.x, pose.pose.position.y]", "odom: [pose.pose.position.x, pose.position.y]"),
        ("args: {robot: rover}", "args: {robot: rover, use_sim: true}")])
    rc, fs = _check(ws, "--strict")
    assert rc == 1
    assert [f[:3] for f in fs if f[0] != "ROS-SCAN"] == [
        ("ROS-FIELD-MISSING", "contracts/rover.rcl:10", fs[0][2]),
        ("ROS-TOPIC-NOT-PUBLISHED", "contracts/rover.rcl:11", "src/rover_sensing/scripts/sensor.py:11"),
        # the typo leaves the real publisher undocumented
        ("ROS-TOPIC-UNDOCUMENTED", "contracts/rover.rcl:7", "src/rover_sensing/scripts/sensor.py:11"),
        ("ROS-NODE-NOT-IN-GRAPH", "contracts/rover.rcl:15", "src/rover_control/launch/rover.launch:7"),
        ("ROS-TOPIC-NOT-SUBSCRIBED", "contracts/rover.rcl:26", "src/rover_control/launch/control.launch:3"),
        ("ROS-TOPIC-UNPUBLISHED", "contracts/rover.rcl:26", "src/rover_control/src/controller.cpp:24"),
        ("ROS-TYPE-UNKNOWN", "contracts/rover.rcl:26", "-"),
        ("ROS-TYPE-DIFFERS", "contracts/rover.rcl:27", "src/rover_control/src/controller.cpp:25"),
        ("ROS-TOPIC-UNDOCUMENTED", "contracts/rover.rcl:22", "src/rover_control/src/controller.cpp:24"),
        ("ROS-NODE-NO-CONTRACT", "contracts/plan.yaml:6", "src/rover_control/launch/rover.launch:12"),
    ]
    # Odometry's definition: Debian's ros-nav-msgs where installed, else rosbags' store (no file)
    assert fs[0][2] in ("nav_msgs/msg/Odometry.msg:1", "nav_msgs/Odometry:1")
    msgs = {f[0]: f[3] for f in fs}
    assert msgs["ROS-FIELD-MISSING"] == ("field path 'pose.position.y' of topic 'odom' (nav_msgs/Odometry): "
                                         "geometry_msgs/msg/PoseWithCovariance has no field 'position' "
                                         "(it has: pose, covariance)")
    assert msgs["ROS-TOPIC-NOT-PUBLISHED"] == ("Sensor's output out.reading is on topic 'radiaton', which "
                                               "/rover/sensor does not publish; closest: 'radiation' (/rover/radiation)")
    assert msgs["ROS-TOPIC-UNPUBLISHED"] == ("no node of the graph publishes /rover/temperature (Controller's input "
                                             "in.temp); closest published topic: /rover/status")
    assert msgs["ROS-TYPE-UNKNOWN"] == "message type rover_msgs/Readng of topic 'temperature' is defined by no scanned or standard package"
    assert msgs["ROS-TYPE-DIFFERS"] == "topic 'cmd_vel' carries geometry_msgs/Twist in the code, the contract says geometry_msgs/Point"
    assert fs[8][3] == ("/rover/controller publishes /rover/status (rover_msgs/Status), which "
                                              "Controller's contract leaves out of topics(...)")
    assert msgs["ROS-NODE-NO-CONTRACT"] == "graph node /sim_sensor (rover_sensing/sensor.py) has no contract"
    assert msgs["ROS-NODE-NOT-IN-GRAPH"].startswith("contract node Planner is not in the ROS graph")
    out = capsys.readouterr().out
    assert ("contracts/rover.rcl:27:11: error: topic 'cmd_vel' carries geometry_msgs/Twist in the code, the contract "
            "says geometry_msgs/Point [src/rover_control/src/controller.cpp:25:13] (ROS-TYPE-DIFFERS)") in out


def test_seeded_field_type_mistakes(tmp_path: Path) -> None:
    ws = _ws(tmp_path, [("Level : {green, orange, red}", "Level : {green, amber, red}"),
                        ("speed : REAL", "speed : NATURAL"),
                        ("out.speed == 0", "out.speed == 0")],
             [("radiation: [value]", "radiation: [header.frame_id]"),
              ("cmd_vel: [linear.x]", "cmd_vel: [linear]")])
    rc, fs = _check(ws)
    assert rc == 1  # a grounding error fails the command, --strict or not (issue 65)
    got = [(f[0], f[1], f[2], f[3]) for f in fs if f[0] != "ROS-SCAN"]
    assert got == [
        ("ROS-FIELD-TYPE", "contracts/rover.rcl:11", "src/rover_msgs/msg/Reading.msg:2",
         "out.reading : REAL reads field 'header.frame_id' (string) of rover_msgs/Reading: string read as REAL"),
        ("ROS-FIELD-TYPE", "contracts/rover.rcl:18", "src/rover_msgs/msg/Reading.msg:2",
         "in.reading : REAL reads field 'header.frame_id' (string) of rover_msgs/Reading: string read as REAL"),
        ("ROS-FIELD-TYPE", "contracts/rover.rcl:19", "src/rover_msgs/msg/Status.msg:5",
         "out.level : Level reads field 'level' (uint8) of rover_msgs/Status: its uint8 constants (GREEN, ORANGE, RED) "
         "do not match Level {green, amber, red}: no constant for amber; constants not in the enumeration: ORANGE"),
        ("ROS-FIELD-TYPE", "contracts/rover.rcl:20", fs[-2][2] if False else got[3][2],
         "out.speed : NATURAL reads field 'linear' (geometry_msgs/msg/Vector3) of geometry_msgs/Twist: "
         "a message field; name one of its fields (a nested path)"),
    ]


def test_float_read_as_natural_and_arrays(tmp_path: Path) -> None:
    ws = _ws(tmp_path, [("speed : REAL", "speed : NATURAL")],
             [("status: [level]", "status: [readings]")])
    _rc, fs = _check(ws)
    got = {f[3] for f in fs if f[0] == "ROS-FIELD-TYPE"}
    assert got == {
        "out.speed : NATURAL reads field 'linear.x' (float64) of geometry_msgs/Twist: float64 read as NATURAL",
        "out.level : Level reads field 'readings' (rover_msgs/msg/Reading[]) of rover_msgs/Status: an array field "
        "cannot fill a single value; index it (name[0]) or name a nested field"}


def test_plan_ros_paths_stay_in_the_workspace(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    ws = _ws(tmp_path, [], [("workspaces: [src]", "workspaces: [../src]")])
    assert main(["ros", "check", "-w", str(ws)]) == 1
    assert "contracts/plan.yaml:6:16: error: ros.workspaces: '../src' leaves the workspace" in capsys.readouterr().err


def test_sarif_results_carry_both_locations(tmp_path: Path) -> None:
    from _typed_rows import typed_report
    from rclverify.report.sarif import _grounding_results
    ws = _ws(tmp_path, [("geometry_msgs/Twist cmd_vel", "geometry_msgs/Point cmd_vel")])
    _check(ws)
    data = json.loads((ws / "findings.json").read_text())
    results, rules = _grounding_results(typed_report({"grounding": data}))
    r = next(x for x in results if x["ruleId"] == "ROS-TYPE-DIFFERS")
    assert r["level"] == "error"
    assert r["locations"][0]["physicalLocation"]["artifactLocation"]["uri"] == "contracts/rover.rcl"
    assert r["locations"][0]["physicalLocation"]["region"] == {"startLine": 20, "startColumn": 11}
    rel = r["relatedLocations"][0]["physicalLocation"]
    assert rel["artifactLocation"]["uri"] == "src/rover_control/src/controller.cpp"
    assert rel["region"] == {"startLine": 25, "startColumn": 13}
    assert "ROS-TYPE-DIFFERS" in {x.id for x in rules}


def test_case_study_is_grounded_in_its_ros_workspace(tmp_path: Path) -> None:
    root = Path(__file__).parents[2]
    # one Snapshot definition: the ROS package's is the monitors' one
    assert (root / "ros/gazebo_radiation_plugin/msg/Snapshot.msg").read_bytes() == \
        (root / "backends/monitors/msg/gazebo_radiation_plugin/msg/Snapshot.msg").read_bytes()
    ws = tmp_path / "case"
    for item in ("contracts", "ros", "backends"):
        shutil.copytree(root / item, ws / item)
    rc, fs = _check(ws, "--strict")
    assert rc == 0
    assert fs == [("ROS-TOPIC-ONLY-RECORDED", "contracts/remote_inspection.rcl:45",
                   "ros/rover_inspection/scripts/navigation.py:12",
                   "/currentLoc (Navigation's input in.position) is published in the recorded run "
                   "backends/monitors/traces/nominal_bag, but by no node of the scanned software")]
    # without the recorded run, nothing publishes it: an error
    plan = ws / "contracts/plan.yaml"
    plan.write_text(plan.read_text().replace("  bags: [backends/monitors/traces/nominal_bag]\n", ""))
    rc, fs = _check(ws, "--strict")
    assert rc == 1
    assert fs == [("ROS-TOPIC-UNPUBLISHED", "contracts/remote_inspection.rcl:45",
                   "ros/rover_inspection/scripts/navigation.py:12",
                   "no node of the graph publishes /currentLoc (Navigation's input in.position)")]
