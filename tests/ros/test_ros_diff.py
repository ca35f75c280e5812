"""``rclverify ros diff`` on constructed graphs and recorded runs: the exact
missing and extra lists, their locations, the action rule, the command's
exit codes and JSON (docs/ros.md, "Expected against observed").  The live
master side is tests/ros/test_ros_diff_live.py."""
from __future__ import annotations

import json
from pathlib import Path

import pytest

from rclverify.cli.commands import main
from rclverify.ros.live.diff import diff_bag, diff_master, render_text
from rclverify.ros.live.master import fold_actions
from rclverify.ros.extract.model import Graph, GraphEdge, GraphNode, Src

REPO = Path(__file__).resolve().parents[2]
URI = "http://127.0.0.1:11311"
M = Src(URI)


def _node(name: str, at: Src | None, **edges: list[tuple[str, str | None, Src]]) -> GraphNode:
    n = GraphNode(name, "/", "pkg", "exe", declared_at=at, origin="launch" if at else "master")
    for kind, es in edges.items():
        n.edges_of({"pub": "pub", "sub": "sub"}.get(kind, kind)).extend(GraphEdge(t, ty, s, None, t) for t, ty, s in es)
    return n


def _graph(*nodes: GraphNode) -> Graph:
    return Graph(nodes={n.name: n for n in nodes})


def _static() -> Graph:
    f = "src/demo/scripts/x.py"
    return _graph(
        _node("/sensor", Src("launch/robot.launch", 3, 1),
              pub=[("/range", "std_msgs/msg/Float32", Src(f, 7, 11)), ("/status", "std_msgs/msg/String", Src(f, 8, 11))]),
        _node("/base", Src("launch/robot.launch", 4, 1),
              sub=[("/range", "std_msgs/msg/Int32", Src(f, 20, 5))],
              service_servers=[("/estop", "std_srvs/srv/SetBool", Src(f, 21, 9))],
              service_clients=[("/map", "nav_msgs/srv/GetMap", Src(f, 22, 9))]),
        _node("/logger", Src("launch/robot.launch", 5, 1), sub=[("/status", "std_msgs/msg/String", Src(f, 30, 5))]),
        _node("/mover", Src("launch/robot.launch", 6, 1),
              action_servers=[("/move", "demo/action/Move", Src(f, 40, 9))]))


def _running() -> Graph:
    return _graph(
        _node("/sensor", None, pub=[("/range", "std_msgs/msg/Float32", M), ("/debug", "std_msgs/msg/String", M)]),
        _node("/base", None, sub=[("/range", "std_msgs/msg/Float32", M)]),
        _node("/mover", None, action_servers=[("/move", "demo/action/Go", M)]),
        _node("/rviz", None, sub=[("/range", "std_msgs/msg/Float32", M)]))


def test_master_diff_exact_lists_and_locations() -> None:
    res = diff_master(_static(), _running(), URI)
    assert [(i.category, i.name, i.node, i.where()) for i in res.missing] == [
        ("node", "/logger", None, "launch/robot.launch:5:1"),
        ("type", "/range", "/base", "src/demo/scripts/x.py:20:5"),
        ("service server", "/estop", "/base", "src/demo/scripts/x.py:21:9"),
        ("type", "/move", "/mover", "src/demo/scripts/x.py:40:9"),
        ("publisher", "/status", "/sensor", "src/demo/scripts/x.py:8:11"),
    ]
    assert [(i.category, i.name, i.node, i.where()) for i in res.extra] == [
        ("node", "/rviz", None, URI),
        ("publisher", "/debug", "/sensor", URI),
    ]
    by = {(i.category, i.name): i for i in res.missing + res.extra}
    assert by[("type", "/range")].message == \
        "/base subscribes to /range: the code's type is std_msgs/Int32, the running system's std_msgs/Float32"
    assert (by[("type", "/range")].msg_type, by[("type", "/range")].observed_type) == \
        ("std_msgs/msg/Int32", "std_msgs/msg/Float32")
    assert by[("type", "/move")].message == \
        "/mover serves action /move: the code's type is demo/Move, the running system's demo/Go"
    assert by[("node", "/logger")].message == "node /logger is not running (its code subscribes to /status)"
    assert by[("publisher", "/status")].message.endswith("nothing running has /status")
    assert by[("publisher", "/debug")].message.endswith("the code names /debug nowhere")
    assert by[("node", "/rviz")].message == "node /rviz runs, but the code has no such node (it subscribes to /range)"
    # the client of /map is not compared: ROS 1 registers no service client
    assert not [i for i in res.missing if i.name == "/map"]
    assert any("service clients" in n for n in res.not_compared)
    lines = render_text(res)
    assert lines[0] == f"in the code, not in the running system at {URI}:"
    assert lines[1] == "  launch/robot.launch:5:1: node /logger is not running (its code subscribes to /status)"
    assert lines[-1].startswith("ros diff: 5 missing, 2 extra (they differ)")


def test_master_diff_equal_and_unknown_types_not_compared() -> None:
    s = _graph(_node("/a", Src("l.launch", 2), pub=[("/x", None, Src("a.py", 3, 1))]))
    r = _graph(_node("/a", None, pub=[("/x", "std_msgs/msg/Bool", M)]))
    res = diff_master(s, r, URI)
    assert res.equal and res.missing == [] and res.extra == []
    assert render_text(res)[-1].startswith("ros diff: 0 missing, 0 extra (equal)")
    assert res.to_json()["equal"] is True


def test_actions_are_folded_from_actionlib_topics() -> None:
    def topics(p: str, t: str) -> dict[str, list[tuple[str, str | None, Src]]]:
        return {"sub": [(f"{p}/goal", f"demo/msg/{t}ActionGoal", M), (f"{p}/cancel", "actionlib_msgs/msg/GoalID", M)],
                "pub": [(f"{p}/status", "actionlib_msgs/msg/GoalStatusArray", M),
                        (f"{p}/feedback", f"demo/msg/{t}ActionFeedback", M), (f"{p}/result", f"demo/msg/{t}ActionResult", M),
                        ("/other", "std_msgs/msg/Bool", M)]}
    g = _graph(_node("/srv", None, **topics("/move", "Move")),
               _node("/cli", None, pub=[("/move/goal", "demo/msg/MoveActionGoal", M)],
                     sub=[("/move/result", "demo/msg/MoveActionResult", M)]),
               _node("/plain", None, sub=[("/goal", "std_msgs/msg/Bool", M)]))
    fold_actions(g)
    srv, cli, plain = g.nodes["/srv"], g.nodes["/cli"], g.nodes["/plain"]
    assert [(e.topic, e.msg_type) for e in srv.action_servers] == [("/move", "demo/action/Move")]
    assert [e.topic for e in srv.publishes + srv.subscribes] == ["/other"]
    assert [(e.topic, e.msg_type) for e in cli.action_clients] == [("/move", "demo/action/Move")]
    assert cli.publishes == [] and cli.subscribes == []
    assert plain.action_servers == [] and [e.topic for e in plain.subscribes] == ["/goal"]
    # the code writing an action on its raw topics compares equal to the master's action
    s = _graph(_node("/srv", Src("l.launch", 2), **{k: [(t, ty, Src("m.py", 5)) for t, ty, _ in v]
                                                   for k, v in topics("/move", "Move").items()}))
    assert diff_master(s, g.__class__(nodes={"/srv": srv}), URI).equal


def test_bag_diff_topics_types_actions() -> None:
    s = _graph(
        _node("/sensor", Src("l.launch", 2), pub=[("/range", "std_msgs/msg/Float32", Src("s.py", 7, 5)),
                                                 ("/status", "std_msgs/msg/String", Src("s.py", 8, 5))]),
        _node("/base", Src("l.launch", 3), sub=[("/cmd", "std_msgs/msg/Float32", Src("b.py", 4, 5))],
              action_clients=[("/dock", "demo/action/Dock", Src("b.py", 9, 5))]),
    )
    bag = {"path": "run.bag", "topics": [
        {"name": "/range", "type": "std_msgs/msg/Float64", "count": 3},
        {"name": "/cmd", "type": "std_msgs/msg/Float32", "count": 3},
        {"name": "/tf", "type": "tf2_msgs/msg/TFMessage", "count": 9},
        {"name": "/rosout", "type": "rosgraph_msgs/msg/Log", "count": 9},
        {"name": "/move/goal", "type": "demo/msg/MoveActionGoal", "count": 1},
        {"name": "/move/result", "type": "demo/msg/MoveActionResult", "count": 1}]}
    res = diff_bag(s, bag)
    assert [(i.category, i.name, i.where(), i.msg_type, i.observed_type) for i in res.missing] == [
        ("topic", "/status", "s.py:8:5", "std_msgs/msg/String", None),
        ("type", "/range", "s.py:7:5", "std_msgs/msg/Float32", "std_msgs/msg/Float64"),
        ("action", "/dock", "b.py:9:5", "demo/action/Dock", None),
    ]
    assert [(i.category, i.name, i.where(), i.observed_type) for i in res.extra] == [
        ("topic", "/tf", "run.bag", "tf2_msgs/msg/TFMessage"),
        ("action", "/move", "run.bag", "demo/action/Move"),
    ]
    assert res.compared == ["topics", "types", "actions"]
    assert "not the nodes" in res.not_compared[0]


def test_command_usage_and_unreachable_master(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    ws = REPO / "tests" / "data" / "ros" / "diff_ws"
    assert main(["ros", "diff", str(ws)]) == 2
    assert "exactly one running side" in capsys.readouterr().err
    assert main(["ros", "diff", str(ws), "--master", URI, "--bag", "x.bag"]) == 2
    capsys.readouterr()
    assert main(["ros", "diff", str(tmp_path / "nope"), "--master", URI]) == 2
    assert "no such file or directory" in capsys.readouterr().err
    assert main(["ros", "diff", str(ws), "--arg", "oops", "--master", URI]) == 2
    capsys.readouterr()
    with __import__("socket").socket() as s:  # a port nobody listens on
        s.bind(("127.0.0.1", 0))
        dead = f"http://127.0.0.1:{s.getsockname()[1]}"
    rc = main(["ros", "diff", str(ws), "--master", dead])
    cap = capsys.readouterr()
    assert rc == 1
    errs = [ln for ln in cap.err.splitlines() if ": error: " in ln]
    assert len(errs) == 1 and errs[0].startswith(f"{dead}: error: cannot read the master at {dead}")
    assert "Traceback" not in cap.err and cap.out == ""


def test_command_against_a_bag(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                               monkeypatch: pytest.MonkeyPatch) -> None:
    bag = str(REPO / "backends" / "monitors" / "traces" / "nominal_bag")
    monkeypatch.chdir(REPO)
    # the case study's code against its own recorded run: equal
    out = tmp_path / "same.json"
    assert main(["ros", "diff", "ros", "--launch", "ros/rover_inspection/launch/inspection.launch",
                 "--bag", bag, "--json", str(out)]) == 0
    data = json.loads(out.read_text())
    assert data["schema"] == "rclverify-ros-diff/1" and data["equal"] is True
    assert data["observed"] == {"kind": "bag", "source": bag} and data["missing"] == data["extra"] == []
    capsys.readouterr()
    # another workspace against that run: its published topics are missing, the run's are extra
    out = tmp_path / "other.json"
    assert main(["ros", "diff", "tests/data/ros/diff_ws", "--bag", bag, "--json", str(out)]) == 1
    data = json.loads(out.read_text())
    assert [(i["name"], i["at"]["file"], i["at"]["line"]) for i in data["missing"]] == [
        ("/cmd", "tests/data/ros/diff_ws/src/diff_demo/scripts/planner.py", 8),
        ("/range", "tests/data/ros/diff_ws/src/diff_demo/scripts/sensor.py", 10)]
    assert [i["name"] for i in data["extra"]] == ["/at", "/command", "/currentLoc", "/inspected", "/position",
                                                  "/r", "/radiationStatus", "/wayPNow"]
    assert all(i["at"] is None and i["observed"] == bag for i in data["extra"])
    text = capsys.readouterr().out
    assert "not compared: nodes, publishers, subscribers and services" in text
    assert f"{bag}: the recorded run has /at (gazebo_radiation_plugin/Snapshot)" in text
