"""Nested and array fields in mappings, and service exchanges in recorded
runs (issue 40; docs/monitors.md, "Field paths" and "Services, actions
and deadlines").

* a ``geometry_msgs/Twist`` logged as ``{"linear": {"x": ...}}`` is mapped
  by ``fields: [linear.x]``, from a log and from a ROS 2 bag alike, and a
  ``sensor_msgs/LaserScan``'s last range by ``ranges[-1]``;
* a path that does not exist in the message definition is one located
  error of ``rclverify check`` at the entry in the mapping file;
* a service response is checked against the server's guarantee and the
  client's assumption: a response outside what the client assumes is the
  client's ``assumption violated``, blamed on the server through the
  service, and its deadline gets no verdict (no ``true`` for an input the
  client's contract does not accept)."""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from rclverify.backends.monitors.backend import verdict_status
from rclverify.backends.monitors.check import check_trace
from rclverify.backends.monitors.deadline_text import deadline_status
from rclverify.backends.monitors.deadlines import check_deadlines
from rclverify.app.tasks import act_check
from rclverify.lang.typecheck import load
from rclverify.traces import read_trace
from rclverify.traces.mapping import RuleError, load_rules

DRIVE = """
node Drive {
  inputs( goal : REAL, obstacle : REAL )
  outputs( v : REAL )
  topics( std_msgs/Float64 goal matches(in.goal), sensor_msgs/LaserScan scan matches(in.obstacle),
          geometry_msgs/Twist cmd_vel matches(out.v) )
  assume( in.obstacle >= 0 )
  guarantee( out.v <= 1.0 and (in.obstacle < 0.5 -> out.v == 0) )
}
"""

MAPPING = {"cmd_vel": {"fields": ["linear.x"]}, "scan": {"fields": ["ranges[-1]"]}, "goal": {"fields": ["data"]}}


def _twist(x: float, wz: float = 0.0) -> dict[str, Any]:
    return {"linear": {"x": x, "y": 0.0, "z": 0.0}, "angular": {"x": 0.0, "y": 0.0, "z": wz}}


def _scan(*ranges: float) -> dict[str, Any]:
    return {"angle_min": -1.0, "angle_max": 1.0, "ranges": list(ranges)}


RUN = [
    (0.0, "scan", _scan(3.0, 2.0, 4.0)), (0.5, "goal", {"data": 1.0}), (0.6, "cmd_vel", _twist(0.5, 0.3)),
    (1.0, "scan", _scan(3.0, 0.2)), (1.1, "cmd_vel", _twist(0.0)),   # the last range is close: stopped
    (2.0, "scan", _scan(3.0, 2.0)), (2.1, "cmd_vel", _twist(1.5)),   # too fast
    (9.0, "goal", {"data": 2.0}),
]


@pytest.fixture(scope="module")
def drive(tmp_path_factory: pytest.TempPathFactory) -> Any:
    p = tmp_path_factory.mktemp("drive") / "drive.rcl"
    p.write_text(DRIVE)
    return load([p])


def _verdicts(checked: Any, events: Any) -> list[tuple[str, str]]:
    seen: list[Any] = []
    check_trace(checked, [checked.nodes["Drive"]], events, load_rules(MAPPING), 1.0, seen.append)
    return [(v.verdict, v.where.rsplit(":", 1)[-1].strip()) for v in seen]


def test_a_twist_field_and_the_last_range_are_mapped_from_a_log(drive: Any, tmp_path: Path) -> None:
    log = tmp_path / "run.jsonl"
    log.write_text("".join(json.dumps({"topic": tp, "time": t, **f}) + "\n" for t, tp, f in RUN))
    got = _verdicts(drive, read_trace(log))
    # the scan alone is a complete input (the contract never reads the goal), superseded by the goal before any
    # answer; each command is judged against the question it answers, and the 1.5 m/s one violates
    assert got == [("superseded", "1"), ("satisfied", "3"), ("satisfied", "5"), ("violated", "7"), ("open", "8")]


def test_the_same_paths_read_a_ros2_bag(drive: Any, tmp_path: Path) -> None:
    from rosbags.rosbag2 import Writer
    from rosbags.typesys import Stores, get_typestore
    import numpy as np
    store = get_typestore(Stores.ROS2_HUMBLE)
    T = store.types
    Vec, Twist = T["geometry_msgs/msg/Vector3"], T["geometry_msgs/msg/Twist"]
    Scan, Header, Time = T["sensor_msgs/msg/LaserScan"], T["std_msgs/msg/Header"], T["builtin_interfaces/msg/Time"]
    F64 = T["std_msgs/msg/Float64"]
    kinds = {"cmd_vel": "geometry_msgs/msg/Twist", "scan": "sensor_msgs/msg/LaserScan", "goal": "std_msgs/msg/Float64"}
    bag = tmp_path / "run_bag"
    with Writer(bag, version=9) as w:
        conns = {tp: w.add_connection("/" + tp, kind, typestore=store) for tp, kind in kinds.items()}
        for t, tp, f in RUN:
            if tp == "cmd_vel":
                msg: Any = Twist(Vec(**f["linear"]), Vec(**f["angular"]))
            elif tp == "scan":
                msg = Scan(Header(Time(0, 0), "laser"), -1.0, 1.0, 0.1, 0.0, 0.1, 0.0, 10.0,
                           np.array(f["ranges"], dtype=np.float32), np.array([], dtype=np.float32))
            else:
                msg = F64(f["data"])
            w.write(conns[tp], int(t * 1e9), store.serialize_cdr(msg, kinds[tp]))
    got = _verdicts(drive, read_trace(bag))
    assert [v for v, _ in got] == ["superseded", "satisfied", "satisfied", "violated", "open"]


def test_a_missing_step_is_inconclusive_with_the_fields_there_are(drive: Any, tmp_path: Path) -> None:
    log = tmp_path / "run.jsonl"
    rows = [(0.0, "scan", _scan(3.0)), (0.5, "goal", {"data": 1.0}), (0.6, "cmd_vel", {"linear": {"y": 0.5}}),
            (0.7, "scan", {"ranges": []})]
    log.write_text("".join(json.dumps({"topic": tp, "time": t, **f}) + "\n" for t, tp, f in rows))
    _, (res,) = check_trace(drive, [drive.nodes["Drive"]], read_trace(log), load_rules(MAPPING), 1.0)
    assert res.counts["inconclusive"] == 2
    assert res.first_inconclusive["reason"] == ("out.v: the message has no field linear.x: 'linear' has no "  # type: ignore[index]
                                                "field 'x' (it has: y)")


def test_a_malformed_path_is_refused_at_load() -> None:
    with pytest.raises(RuleError) as e:
        load_rules({"scan": {"fields": ["ranges[x]"]}})
    assert "'ranges[x]' is not a field path" in str(e.value) and e.value.path == ("topics", "scan", "fields", 0)


def _workspace(tmp_path: Path, fields: str) -> Path:
    ws = tmp_path / "ws"
    (ws / "contracts").mkdir(parents=True)
    (ws / "contracts" / "drive.rcl").write_text(DRIVE)
    (ws / "contracts" / "plan.yaml").write_text(
        "name: drive\ncontracts: [contracts/drive.rcl]\nnodes:\n  Drive:\n    evidence:\n"
        "      - backend: monitors\n        mapping: mapping.yaml\n        traces: []\n")
    (ws / "mapping.yaml").write_text(f"topics:\n  goal: {{fields: [data]}}\n{fields}")
    return ws


@pytest.mark.parametrize("fields,where,message", [
    ("  cmd_vel: {fields: [linar.x]}\n", "mapping.yaml:3:22:",
     "topic cmd_vel: field 'linar.x' of geometry_msgs/Twist: geometry_msgs/msg/Twist has no field 'linar' "
     "(it has: linear, angular)"),
    ("  cmd_vel:\n    fields:\n      - linear\n", "mapping.yaml:5:9:",
     "topic cmd_vel: field 'linear' of geometry_msgs/Twist: a message (geometry_msgs/Vector3); name one of its "
     "fields (linear.<field>)"),
    ("  scan: {fields: [ranges]}\n", "mapping.yaml:3:19:",
     "topic scan: field 'ranges' of sensor_msgs/LaserScan: an array (float32[]) cannot fill a single value; index "
     "it (ranges[0], ranges[-1])"),
])
def test_check_locates_a_path_the_message_definition_does_not_have(tmp_path: Path, fields: str, where: str,
                                                                   message: str) -> None:
    ws = _workspace(tmp_path, fields)
    err = str(act_check(str(ws)))  # the check task (`doit check`, the start of `rclverify verify`)
    assert f"{where} error: {message}" in err, err


def test_check_accepts_the_paths_that_exist(tmp_path: Path) -> None:
    ws = _workspace(tmp_path, "  cmd_vel: {fields: [linear.x]}\n  scan: {fields: ['ranges[-1]']}\n")
    assert act_check(str(ws)) is None


# -- services -------------------------------------------------------------------------------------------

SERVICE = """
node Planner {
  inputs( dist : REAL )
  outputs( req : REAL, speed : REAL )
  topics( std_msgs/Float64 speed matches(out.speed) )
  services( demo_srvs/GetRange range calls(out.req, in.dist) )
  assume( in.dist <= 10 )
  guarantee( out.speed <= in.dist ) triggered by in.dist within 100 ms
}
node Ranger {
  inputs( req : REAL )
  outputs( dist : REAL )
  services( demo_srvs/GetRange range serves(in.req, out.dist) )
  assume( TRUE )
  guarantee( out.dist <= 100 ) triggered by in.req within 50 ms
}
"""

CALLS = [
    {"topic": "range/request", "time": 1.00, "max": 100.0}, {"topic": "range/response", "time": 1.02, "dist": 50.0},
    {"topic": "speed", "time": 1.05, "data": 2.0},
    {"topic": "range/request", "time": 2.00, "max": 100.0}, {"topic": "range/response", "time": 2.02, "dist": 5.0},
    {"topic": "speed", "time": 2.05, "data": 4.0},
    {"topic": "clock", "time": 9.0},
]


@pytest.fixture(scope="module")
def service(tmp_path_factory: pytest.TempPathFactory) -> Any:
    p = tmp_path_factory.mktemp("svc") / "svc.rcl"
    p.write_text(SERVICE)
    return load([p])


def test_a_service_response_outside_the_clients_assumption_is_violated(service: Any, tmp_path: Path) -> None:
    log = tmp_path / "calls.jsonl"
    log.write_text("".join(json.dumps(x) + "\n" for x in CALLS))
    seen: list[Any] = []
    nodes = [service.nodes["Planner"], service.nodes["Ranger"]]
    _, (planner, ranger) = check_trace(service, nodes, read_trace(log), {}, 1.0, seen.append)
    # the server kept its guarantee: both responses are within 100
    assert ranger.counts["satisfied"] == 2 and ranger.counts["violated"] == 0
    # the client's assumption monitor: the first response (50) is outside what it assumes
    first = [v for v in seen if v.node == "Planner"][0]
    assert (first.verdict, first.topic, first.where) == ("assumption violated", "range/response",
                                                         "calls.jsonl:2")
    assert first.reason == ("assumption in.dist <= 10 is false; blamed on the upstream node(s) Ranger "
                            "(through service range)")
    assert planner.assumption["verdict"] == "violated" and planner.assumption["violations"] == 1
    assert planner.counts["satisfied"] == 1  # the second response (5) is accepted and answered
    status, text = verdict_status(planner, "calls.jsonl")
    assert "the assumption monitor's verdict is violated: 1 question(s) violated the assumption (first at " \
           "calls.jsonl:2, blamed on the upstream node(s) Ranger (through service range))" in text
    # the deadlines: no `true` for the response the client's contract does not accept
    dplanner, dranger = check_deadlines(service, nodes, read_trace(log), {})
    assert dplanner.counts == {"true": 1, "currently_false": 0, "false": 0}
    assert dplanner.unaccepted == {"assumption violated": 1, "incomplete input": 0, "undecided": 0}
    assert dplanner.first_unaccepted is not None and dplanner.first_unaccepted["where"] == "calls.jsonl:2"
    assert dranger.counts == {"true": 2, "currently_false": 0, "false": 0}
    dstatus, dtext = deadline_status(dplanner, "calls.jsonl")
    assert dstatus == "discharged" and "no deadline verdict for 1 trigger event(s) whose inputs violated the " \
                                      "assumption (first at calls.jsonl:2" in dtext


def test_a_server_answering_outside_its_guarantee_fails_the_server(service: Any, tmp_path: Path) -> None:
    log = tmp_path / "calls.jsonl"
    bad = [dict(x) for x in CALLS]
    bad[1]["dist"] = 500.0
    log.write_text("".join(json.dumps(x) + "\n" for x in bad))
    _, (planner, ranger) = check_trace(service, [service.nodes["Planner"], service.nodes["Ranger"]],
                                       read_trace(log), {}, 1.0)
    assert ranger.counts["violated"] == 1 and ranger.first_violation["where"] == "calls.jsonl:2"  # type: ignore[index]
    assert planner.counts["assumption violated"] == 1
