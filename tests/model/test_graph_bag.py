"""The recorded graph as a ``rosgraph_msgs/msg/Graph`` message in a ROS 2 bag (docs/nodl.md, "The graph message
in a bag"; src/rclverify/ros/graph/graph_msg.py, graph_bag.py), read with no ROS 2 running.

tests/data/nodl/recorded's two recordings of real rclpy nodes (one per live source, made by
tests/model/test_nodl_live.py) are written as bags, MCAP and SQLite 3, by the writer ``--record-graph X.mcap``
uses; ``nodl check --graph BAG`` and ``ros diff --graph BAG`` give the finding lines and items the JSON
recordings give (which are the live readings', tests/model/test_graph_record.py).  The message's definition
is checked against rosbags' own ROS 2 Lyrical store, which carries the released one; a bag another tool wrote
(another topic, several messages, ``Action`` entries, no metadata) is read; ``ros check`` takes the recorded
graph's topics from a bag in the plan; what is not a graph bag is refused in one located line."""
from __future__ import annotations

import copy
import json
import shutil
from pathlib import Path
from typing import Any

import pytest

from rclverify.cli.commands import main
from rclverify.ros.graph.graph_bag import read_graph, write_bag
from rclverify.ros.graph.graph_msg import DEFINITIONS, GRAPH_TYPE, graph_store, graph_type_hash

DATA = Path(__file__).parent.parent / "data" / "nodl"
RECORDED = {"rclpy": DATA / "recorded" / "graph_rclpy.json", "dds": DATA / "recorded" / "graph_dds.json"}


@pytest.fixture()
def ws(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    root = tmp_path / "ws"
    shutil.copytree(DATA / "ws", root)
    monkeypatch.chdir(root)
    return root


def _dump(source: str) -> dict[str, Any]:
    return json.loads(RECORDED[source].read_text(encoding="utf-8"))


def _run(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    rc = main(args)
    out = capsys.readouterr()
    assert "Traceback" not in out.err
    return rc, out.out, out.err


def _findings(err: str) -> list[str]:
    return [ln for ln in err.splitlines() if ln.startswith("nodl/") or ln.startswith("rclpy on") or ln.startswith("DDS")]


def _items(out: str) -> list[str]:
    return [ln for ln in out.splitlines() if ln.startswith("  ") or ln.startswith("in the NoDL")]


def test_the_definition_is_the_released_messages() -> None:
    """Each message's fields and constants equal those of rosbags' ROS 2 Lyrical store (the released
    rosgraph_msgs); the type hash is REP-2011's over them, and changes when a field does (the control)."""
    from rosbags.typesys import Stores, get_typestore, get_types_from_msg
    from rclverify.ros.live.type_hash import rihs01
    released = get_typestore(Stores.ROS2_LYRICAL)
    ours = graph_store()
    assert set(DEFINITIONS) == {k for k in released.fielddefs if k.startswith("rosgraph_msgs/") and not k.endswith("Clock")}
    for name in DEFINITIONS:
        assert ours.fielddefs[name] == released.fielddefs[name], name
    assert graph_type_hash() == rihs01(GRAPH_TYPE, lambda t: released.fielddefs[t][1] if t in released.fielddefs else None)
    swapped = get_typestore(Stores.ROS2_LYRICAL)
    swapped.fielddefs.pop("rosgraph_msgs/msg/TypeHash")
    swapped.register(get_types_from_msg("uint8[32] value\nuint8 version\n", "rosgraph_msgs/msg/TypeHash"))
    assert rihs01(GRAPH_TYPE, lambda t: swapped.fielddefs[t][1] if t in swapped.fielddefs else None) != graph_type_hash()


@pytest.mark.parametrize("source,suffix", [("rclpy", ".mcap"), ("dds", ".db3")])
def test_a_graph_bag_gives_the_findings_of_the_recording_it_holds(
        ws: Path, tmp_path: Path, source: str, suffix: str, capsys: pytest.CaptureFixture[str]) -> None:
    bag = write_bag(tmp_path / f"graph{suffix}", _dump(source))
    assert (bag / "metadata.yaml").is_file() and (bag / f"graph{suffix}").is_file()
    rc, out, err = _run(["nodl", "check", "--graph", str(RECORDED[source])], capsys)
    rc_bag, out_bag, err_bag = _run(["nodl", "check", "--graph", str(tmp_path / f"graph{suffix}")], capsys)
    assert rc == rc_bag == 1 and out_bag == out and _findings(err_bag) == _findings(err) and len(_findings(err)) >= 9
    rc, out, _ = _run(["ros", "diff", "--nodl", "nodl", "--graph", str(RECORDED[source])], capsys)
    rc_bag, out_bag, _ = _run(["ros", "diff", "--nodl", "nodl", "--graph", str(bag)], capsys)
    assert rc == rc_bag == 1 and _items(out_bag) == _items(out) and len(_items(out)) >= 5


def test_a_difference_seeded_into_the_graph_message_is_found(ws: Path, tmp_path: Path,
                                                             capsys: pytest.CaptureFixture[str]) -> None:
    """Guard's /stop publisher best-effort in the message: a finding at Guard's document, which the bag of the
    recording as made (the control) does not give."""
    made = write_bag(tmp_path / "made.mcap", _dump("rclpy"))
    _, _, err = _run(["nodl", "check", "--graph", str(made)], capsys)
    assert not [ln for ln in _findings(err) if "node /Guard" in ln]
    seeded = _dump("rclpy")
    [pub] = [e for e in seeded["endpoints"]["/stop"]["pubs"] if e["node"] == "Guard"]
    pub["reliable"] = False
    bag = write_bag(tmp_path / "seeded.db3", seeded)
    rc, _, err = _run(["nodl", "check", "--graph", str(bag)], capsys)
    guard = [ln for ln in _findings(err) if "node /Guard" in ln]
    assert rc == 1 and guard and all("/stop's reliability is BEST_EFFORT" in ln for ln in guard), guard


def _foreign_bag(path: Path, graphs: list[Any], topic: str = "/graph_monitor/rosgraph", rihs01: str | None = None) -> Path:
    """A bag as another tool writes it: rosbags' writer, no custom metadata, ``graphs`` at seconds 1, 2, ..."""
    from rosbags.rosbag2 import StoragePlugin, Writer
    store = graph_store()
    with Writer(path, version=8, storage_plugin=StoragePlugin.MCAP) as writer:
        msgdef = store.generate_msgdef(GRAPH_TYPE, ros_version=2)[0] if rihs01 else None
        conn = writer.add_connection(topic, GRAPH_TYPE, typestore=store, msgdef=msgdef, rihs01=rihs01)
        for k, g in enumerate(graphs, 1):
            writer.write(conn, k * 1_000_000_000, bytes(store.serialize_cdr(g, GRAPH_TYPE)))
    return path


def _graph(nodes: list[Any]) -> Any:
    return graph_store().types[GRAPH_TYPE](nodes=nodes)


def _qos(reliability: int = 1, durability: int = 2, deadline_s: int = 0) -> Any:
    t = graph_store().types
    d = t["builtin_interfaces/msg/Duration"]
    return t["rosgraph_msgs/msg/QoSProfile"](depth=10, deadline=d(sec=deadline_s, nanosec=0), lifespan=d(sec=0, nanosec=0),
                                             history=1, reliability=reliability, durability=durability, liveliness=1,
                                             liveliness_lease_duration=d(sec=0, nanosec=0))


def _itype(name: str) -> Any:
    import numpy
    t = graph_store().types
    return t["rosgraph_msgs/msg/InterfaceType"](name=name, hash=t["rosgraph_msgs/msg/TypeHash"](
        version=0, value=numpy.zeros(32, dtype=numpy.uint8)))


def test_a_bag_another_tool_wrote_is_read(tmp_path: Path) -> None:
    """Another topic, two messages (the later one is the graph), an action server as one ``Action`` entry (its
    three services and two topics read under their own names), a deadline of 2 s, no rclverify metadata."""
    t = graph_store().types
    topic, service = t["rosgraph_msgs/msg/Topic"], t["rosgraph_msgs/msg/Service"]

    def srv(name: str, ty: str) -> Any:
        return service(name=name, request_type=_itype(ty + "_Request"), request_qos=_qos(),
                       response_type=_itype(ty + "_Response"), response_qos=_qos())
    act = "/nav/navigate"
    action = t["rosgraph_msgs/msg/Action"](
        name=act, send_goal=srv(f"{act}/_action/send_goal", "nav2_msgs/action/Navigate_SendGoal"),
        get_result=srv("", "nav2_msgs/action/Navigate_GetResult"),
        cancel_goal=srv(f"{act}/_action/cancel_goal", "action_msgs/srv/CancelGoal"),
        feedback=topic(name=f"{act}/_action/feedback", type=_itype("nav2_msgs/action/Navigate_FeedbackMessage"), qos=_qos()),
        status=topic(name=f"{act}/_action/status", type=_itype("action_msgs/msg/GoalStatusArray"), qos=_qos(durability=1)))
    node = t["rosgraph_msgs/msg/Node"](
        name="/nav/planner", parameters=[], parameter_values=[],
        publishers=[topic(name="/plan", type=_itype("nav_msgs/msg/Path"), qos=_qos(deadline_s=2))],
        subscriptions=[topic(name="/map", type=_itype("nav_msgs/msg/OccupancyGrid"), qos=_qos(durability=1))],
        service_clients=[], service_servers=[srv("/nav/planner/get_parameters", "rcl_interfaces/srv/GetParameters")],
        action_clients=[], action_servers=[action])
    bag = _foreign_bag(tmp_path / "foreign", [_graph([]), _graph([node])])
    dump = read_graph(bag)
    assert dump["source"] == f"{GRAPH_TYPE} in {bag}" and dump["rmw"] == ""
    [n] = dump["nodes"]
    assert (n["name"], n["ns"]) == ("planner", "/nav")
    assert n["servers"] == [["/nav/planner/get_parameters", ["rcl_interfaces/srv/GetParameters"]],
                            [f"{act}/_action/send_goal", ["nav2_msgs/action/Navigate_SendGoal"]],
                            [f"{act}/_action/get_result", ["nav2_msgs/action/Navigate_GetResult"]],
                            [f"{act}/_action/cancel_goal", ["action_msgs/srv/CancelGoal"]]]
    assert [p[0] for p in n["pubs"]] == ["/plan", f"{act}/_action/feedback", f"{act}/_action/status"]
    assert n["subs"] == [["/map", ["nav_msgs/msg/OccupancyGrid"]]]
    [plan] = dump["endpoints"]["/plan"]["pubs"]
    assert plan["deadline_ns"] == 2_000_000_000 and plan["reliable"] and plan["durability"] == "volatile"
    assert "hash" not in plan and dump["endpoints"]["/map"]["subs"][0]["durability"] == "transient_local"
    assert len(bytes.fromhex(plan["gid"])) == 16
    first = read_graph(_foreign_bag(tmp_path / "one", [_graph([node]), _graph([])]))  # the control: order decides
    assert first["nodes"] == [] and first["endpoints"] == {}


def test_what_is_not_a_graph_bag_is_refused_in_one_line(ws: Path, tmp_path: Path,
                                                         capsys: pytest.CaptureFixture[str]) -> None:
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_typestore
    store = get_typestore(Stores.ROS2_HUMBLE)
    plain = tmp_path / "plain"
    with Writer(plain, version=8, storage_plugin=StoragePlugin.SQLITE3) as w:
        c = w.add_connection("/speed", "std_msgs/msg/Float64", typestore=store)
        w.write(c, 1, bytes(store.serialize_cdr(store.types["std_msgs/msg/Float64"](data=1.0), "std_msgs/msg/Float64")))
    rc, _, err = _run(["nodl", "check", "--graph", str(plain)], capsys)
    assert rc == 1 and f"{plain}:1:1: error: the bag holds no {GRAPH_TYPE} message (its topics: /speed" in err
    other = _foreign_bag(tmp_path / "other", [_graph([])], rihs01="RIHS01_" + "0" * 64)
    rc, _, err = _run(["ros", "diff", "--nodl", "nodl", "--graph", str(other)], capsys)
    assert rc == 1 and "recorded with type hash RIHS01_000" in err and f"{other}:1:1: error:" in err
    made = write_bag(tmp_path / "made.mcap", _dump("dds"))
    with pytest.raises(Exception) as exc:  # a recording never replaces a bag
        write_bag(tmp_path / "made.mcap", _dump("dds"))
    assert "exists; a recording goes to a new bag" in str(exc.value)
    (made / "made.mcap").write_bytes(b"\x89MCAP0\r\nbroken")
    rc, _, err = _run(["nodl", "check", "--graph", str(made)], capsys)
    assert rc == 1 and f"{made}:1:1: error: cannot read the recorded graph" in err and len(err.splitlines()) <= 3


def test_ros_check_takes_the_recorded_graphs_topics_from_a_bag(tmp_path: Path) -> None:
    """The case study with its recorded run replaced by a graph bag: /currentLoc, which no scanned node
    publishes, is published in the recorded graph with the contract's type (a warning, as for the recorded
    run: without any bag it is an error, tests/ros/test_ros_ground.py); /command, which the code publishes as
    Snapshot, published in the graph as std_msgs/String: a type finding the control topic does not get."""
    root = Path(__file__).parents[2]
    case = tmp_path / "case"
    for item in ("contracts", "ros", "backends"):
        shutil.copytree(root / item, case / item)
    snap = "gazebo_radiation_plugin/msg/Snapshot"
    end = {"gid": "00" * 16, "node": "bridge", "ns": "/", "reliable": True, "durability": "volatile",
           "deadline_ns": 0, "liveliness": "automatic", "lease_ns": 0}
    dump = {"rmw": "rmw_zenoh_cpp", "nodes": [{"name": "bridge", "ns": "/", "pubs": [["/currentLoc", [snap]],
                                                                                      ["/command", ["std_msgs/msg/String"]]],
                                               "subs": [], "servers": [], "clients": []}],
            "endpoints": {"/currentLoc": {"pubs": [dict(end, type=snap)], "subs": []},
                          "/command": {"pubs": [dict(end, type="std_msgs/msg/String")], "subs": []}}}
    write_bag(case / "graph.mcap", copy.deepcopy(dump))
    plan = case / "contracts/plan.yaml"
    plan.write_text(plan.read_text().replace("bags: [backends/monitors/traces/nominal_bag]", "bags: [graph]"))
    out = case / "findings.json"
    rc = main(["ros", "check", "-w", str(case), "--json", str(out)])
    fs = {(f["code"], f["topic"]): f["message"] for f in json.loads(out.read_text())["findings"]}
    assert rc == 1
    assert fs[("ROS-TOPIC-ONLY-RECORDED", "currentLoc")].endswith(
        "is published in the recorded run graph, but by no node of the scanned software")
    assert not [k for k in fs if k[1] == "currentLoc" and k[0].startswith("ROS-TYPE")]  # the control
    typed = [m for k, m in fs.items() if k[1] == "command" and k[0].startswith("ROS-TYPE")]
    assert typed and all("String" in m for m in typed), fs
    graph = json.loads((case / "artifacts/ros/graph.json").read_text())
    [bag] = graph["bags"]
    assert {(t["name"], t["count"], tuple(t.get("graph", []))) for t in bag["topics"]} >= {
        ("/currentLoc", 0, ("/bridge",)), ("/rosgraph", 1, ())}
