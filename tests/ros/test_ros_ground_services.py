"""Grounding of contract services and actions (docs/ros.md, "Grounding
services and actions"): the safety-stop example's contracts (Teleop calls and
Base serves ``estop``, Mission calls and Mover serves ``move``) against
constructed graphs; each finding code triggered by one seeded mistake,
located at the link's RCL line and the code's line, and silent when the
graph agrees.  The drawing shows services and actions in their own style."""
from __future__ import annotations

from pathlib import Path
from typing import Any

from rclverify.lang import ast
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check
from rclverify.ros.graph.draw import grounding_dot
from rclverify.ros.graph.scan import ScanResult
from rclverify.ros.ground.ground import RULES, ground
from rclverify.ros.extract.interfaces import TypeTable
from rclverify.ros.extract.model import Graph, GraphEdge, GraphNode, Src

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "examples" / "safety_stop"
RCL = (EXAMPLE / "contracts" / "safety_stop.rcl").read_text()
MOVE = EXAMPLE / "interfaces" / "rclverify_examples" / "action" / "Move.action"
SRV = "std_srvs/srv/SetBool"
ACT = "rclverify_examples/action/Move"
F = "src/robot/scripts/nodes.py"


def _line(text: str, needle: str) -> int:
    return next(i for i, ln in enumerate(text.splitlines(), 1) if needle in ln)


def _graph(**changes: Any) -> Graph:
    """The graph that agrees with the contracts; ``changes[node] = {role: [(name, type, line)]}``
    replaces roles of a node."""
    spec: dict[str, dict[str, list[tuple[str, str | None, int]]]] = {
        "/teleop": {"service_clients": [("estop", SRV, 10)]},
        "/base": {"service_servers": [("estop", SRV, 20)]},
        "/mission": {"action_clients": [("move", ACT, 30)]},
        "/mover": {"action_servers": [("move", ACT, 40)]},
    }
    for node, roles in changes.items():
        spec.setdefault(node, {}).update(roles)
    g = Graph()
    for i, (name, roles) in enumerate(spec.items()):
        n = GraphNode(name, "/", "robot", "nodes.py", declared_at=Src("launch/robot.launch", 3 + i, 3))
        for role, edges in roles.items():
            n.edges_of(role).extend(GraphEdge("/" + t.lstrip("/"), ty, Src(F, line, 9), None, t)
                                    for t, ty, line in edges)
        g.nodes[name] = n
    return g


def _ground(g: Graph, text: str = RCL, ros: dict[str, Any] | None = None) -> list[tuple[str, str, str, str]]:
    table = TypeTable()
    table.add_debian_standard(None)  # as the scan of a ROS 1 workspace does (std_srvs/SetBool)
    table.add_file(MOVE, "rclverify_examples", "interfaces/rclverify_examples/action/Move.action", "workspace", None)
    checked = check([parse_text(text, "s.rcl")])
    fs = ground(ScanResult(g, {}, table), checked, "plan.yaml", ros or {}, {}, ast.Loc("plan.yaml", 1, 1))
    for f in fs:
        assert f.severity == RULES[f.code][0]
    return [(f.code, f"{f.rcl.line}" if f.rcl else "-", str(f.ros) if f.ros else "-", f.message) for f in fs]


TELEOP = _line(RCL, "estop calls")
BASE = _line(RCL, "estop serves")
MISSION = _line(RCL, "move calls")
MOVER = _line(RCL, "move serves")


def test_the_example_is_grounded() -> None:
    assert _ground(_graph()) == []


def test_actions_on_raw_actionlib_topics_are_the_action() -> None:
    g = _graph(**{"/mover": {"action_servers": []}})
    m = g.nodes["/mover"]
    m.subscribes.append(GraphEdge("/move/goal", "rclverify_examples/msg/MoveActionGoal", Src(F, 41, 5), None, "/move/goal"))
    m.publishes += [GraphEdge("/move/feedback", "rclverify_examples/msg/MoveActionFeedback", Src(F, 42, 5), None,
                              "/move/feedback"),
                    GraphEdge("/move/result", "rclverify_examples/msg/MoveActionResult", Src(F, 43, 5), None,
                              "/move/result")]
    assert _ground(g) == []
    assert [e.topic for e in g.nodes["/mover"].subscribes] == ["/move/goal"]  # the scan's graph is left as it is


def test_service_without_server() -> None:
    fs = _ground(_graph(**{"/base": {"service_servers": []}}))
    assert fs == [
        ("ROS-SERVICE-NO-SERVER", str(TELEOP), f"{F}:10:9",
         "no node of the graph serves the service /estop that Teleop calls"),
        ("ROS-SERVICE-NOT-SERVED", str(BASE), "launch/robot.launch:4:3",
         "Base serves service 'estop' in its contract, which /base's code does not serve; it serves: none"),
    ]
    # served outside the scanned software: only the server's own contract is contradicted
    fs = _ground(_graph(**{"/base": {"service_servers": []}}), ros={"external": ["/estop"]})
    assert [f[0] for f in fs] == ["ROS-SERVICE-NOT-SERVED"]


def test_service_type_differs_and_unknown() -> None:
    fs = _ground(_graph(**{"/base": {"service_servers": [("estop", "std_srvs/srv/Trigger", 20)]}}))
    assert fs == [
        ("ROS-SERVICE-TYPE", str(TELEOP), f"{F}:20:9",
         "service 'estop' (/estop) has type std_srvs/Trigger in the code, the contract says std_srvs/SetBool"),
        ("ROS-SERVICE-TYPE", str(BASE), f"{F}:20:9",
         "service 'estop' (/estop) has type std_srvs/Trigger in the code, the contract says std_srvs/SetBool"),
    ]
    text = RCL.replace("std_srvs/SetBool estop calls", "std_srvs/SetBoool estop calls")
    fs = [f for f in _ground(_graph(), text)]
    assert fs == [("ROS-SERVICE-TYPE-UNKNOWN", str(TELEOP), f"{F}:10:9",
                   "service type std_srvs/SetBoool of 'estop' is defined by no scanned or standard package; "
                   "the code gives std_srvs/SetBool")]


def test_node_role_as_the_contract_says() -> None:
    # Teleop's code serves estop instead of calling it
    fs = _ground(_graph(**{"/teleop": {"service_clients": [], "service_servers": [("estop", SRV, 11)]}}))
    assert fs == [("ROS-SERVICE-NOT-CALLED", str(TELEOP), f"{F}:11:9",
                   "Teleop calls service 'estop' in its contract, which /teleop's code does not call; "
                   "its code serves it instead")]
    # Mission's code does not call move; Mover's serves it under another name
    fs = _ground(_graph(**{"/mission": {"action_clients": []},
                           "/mover": {"action_servers": [("mvoe", ACT, 40)]}}))
    assert fs == [
        ("ROS-ACTION-NOT-CALLED", str(MISSION), "launch/robot.launch:5:3",
         "Mission calls action 'move' in its contract, which /mission's code does not call"),
        ("ROS-ACTION-NO-SERVER", str(MISSION), f"{F}:40:9",
         "no node of the graph serves the action /move that Mission calls; closest served action: /mvoe"),
        ("ROS-ACTION-NOT-SERVED", str(MOVER), f"{F}:40:9",
         "Mover serves action 'move' in its contract, which /mover's code does not serve; closest: 'mvoe' (/mvoe)"),
        ("ROS-ACTION-UNDOCUMENTED", str(_line(RCL, "node Mover")), f"{F}:40:9",
         "/mover serves action /mvoe (rclverify_examples/Move), which Mover's contract leaves out of actions(...)"),
    ]


def test_action_type_and_undocumented() -> None:
    fs = _ground(_graph(**{"/mover": {"action_servers": [("move", "rclverify_examples/action/Go", 40)]},
                           "/base": {"service_servers": [("estop", SRV, 20), ("reset", "std_srvs/srv/Trigger", 21)]}}))
    assert fs == [
        ("ROS-SERVICE-UNDOCUMENTED", str(_line(RCL, "node Base")), f"{F}:21:9",
         "/base serves service /reset (std_srvs/Trigger), which Base's contract leaves out of services(...)"),
        ("ROS-ACTION-TYPE", str(MISSION), f"{F}:40:9",
         "action 'move' (/move) has type rclverify_examples/Go in the code, the contract says rclverify_examples/Move"),
        ("ROS-ACTION-TYPE", str(MOVER), f"{F}:40:9",
         "action 'move' (/move) has type rclverify_examples/Go in the code, the contract says rclverify_examples/Move"),
    ]
    text = RCL.replace("rclverify_examples/Move move calls", "rclverify_examples/Mov move calls")
    fs = _ground(_graph(), text)
    assert [(c, r) for c, r, _s, _m in fs] == [("ROS-ACTION-TYPE-UNKNOWN", str(MISSION))]


def test_every_code_is_documented() -> None:
    doc = (REPO / "docs" / "ros.md").read_text()
    codes = sorted(c for c in RULES if c.startswith(("ROS-SERVICE", "ROS-ACTION")))
    assert len(codes) == 12 and [c for c in codes if f"| `{c}` | {RULES[c][0]} |" not in doc] == []


def test_drawing_shows_services_and_actions() -> None:
    g = _graph(**{"/base": {"service_servers": []}})
    checked = check([parse_text(RCL, "s.rcl")])
    findings = [{"code": c, "severity": RULES[c][0], "node": n, "topic": t}
                for c, n, t in (("ROS-SERVICE-NOT-SERVED", "Base", "estop"), ("ROS-SERVICE-NO-SERVER", "Teleop", "estop"))]
    dot = grounding_dot(checked, g.to_json(), findings, {"Base": "/base", "Teleop": "/teleop"})
    assert '"cs:estop" [label="estop", shape=hexagon' in dot
    assert '"ca:move" [label="move", shape=doubleoctagon' in dot
    assert '"c:Teleop" -> "cs:estop" [color="red3", style="dashed"' in dot
    assert '"cs:estop" -> "c:Base" [color="red3", style="dashed"' in dot
    assert '"c:Mission" -> "ca:move" [color="black", style="bold"' in dot
    assert '"r:/teleop" -> "rs:/estop" [color="red3", style="dashed"' in dot
    assert '"ra:/move" -> "r:/mover" [color="black", style="bold"' in dot
