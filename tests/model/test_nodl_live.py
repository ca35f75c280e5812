"""NoDL documents against the running ROS 2 graph (docs/nodl.md, "Against the running graph"): real rclpy nodes on
Fast DDS (tests/_ros2.py), read by ``rclverify nodl check --ros2`` through rclverify's own DDS participant and
through rclpy's graph API (``--source dds``, ``--source rclpy``), and by ``rclverify ros diff --nodl`` (the
documents as the expected graph, through rclpy's graph API).

The documents are tests/data/nodl/ws's.  One process runs two nodes: ``Guard`` exactly as its document says (the
control: reliable, transient-local ``/stop`` offering a 100 ms deadline, best-effort ``/scan``; without the deadline
it would be a ``nodl-live-qos`` finding: the document offers it) and ``Base`` with one seeded mismatch of each
kind: ``/speed`` published as ``std_msgs/Float32`` (the document: ``Float64``), ``/stop`` subscribed volatile (the
document: transient-local), no ``/estop`` server, and a publisher ``/odom`` its document does not declare.
``Dock`` does not run: a document matched to no running node is not compared.

The graph each source gave is also recorded (``--record-graph``; docs/nodl.md, "A recorded graph": Kilted's
``rosgraph_msgs`` has no graph message): rclpy's graph API and rclverify's own DDS participant by ``nodl check``,
the DDS source once more by ``ros diff --nodl``, and rclpy's graph API by ``ros diff --nodl`` as a
``rosgraph_msgs/msg/Graph`` message in an MCAP bag (docs/nodl.md, "The graph message in a bag").  Once the nodes have stopped, each recording is checked again
(``nodl check --graph``, ``ros diff --graph``): the same findings and items, line for line, as the live reading
it was made from; a graph difference seeded into a recording found by both commands (the recording as made, the
control, has none); a recording that is not one refused at its line."""
from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path
from typing import Any, Iterator

import pytest

from _procs import stop
from _ros2 import rclverify, ros2_env, ros2_python, start_node

WS = Path(__file__).parent.parent / "data" / "nodl" / "ws"

NODES = """\
import rclpy
from rclpy.duration import Duration
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from sensor_msgs.msg import LaserScan
from std_msgs.msg import Bool, Float32, Float64

rclpy.init()
guard = Node('Guard')
guard.create_publisher(Bool, '/stop', QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                                                 durability=DurabilityPolicy.TRANSIENT_LOCAL,
                                                 deadline=Duration(nanoseconds=100_000_000)))
guard.create_subscription(LaserScan, 'scan', lambda m: None,
                          QoSProfile(depth=5, reliability=ReliabilityPolicy.BEST_EFFORT))
base = Node('Base')
base.create_subscription(Bool, '/stop', lambda m: None, QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                                                                   durability=DurabilityPolicy.VOLATILE))
base.create_publisher(Float32, '/speed', 10)
base.create_publisher(Float64, '/odom', 10)
ex = MultiThreadedExecutor()
ex.add_node(guard)
ex.add_node(base)
print('ready', flush=True)
ex.spin()
"""


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, Any]]:
    tmp = tmp_path_factory.mktemp("nodl_live")
    ws = tmp / "ws"
    shutil.copytree(WS, ws)
    env = ros2_env(tmp)
    procs: list[subprocess.Popen[bytes]] = []
    try:
        procs.append(start_node(tmp, "robot", NODES, env))
        out: dict[str, Any] = {}
        for source in ("dds", "rclpy"):  # rclverify's own DDS participant, rclpy's graph API (as ros diff reads)
            log = tmp / f"check_{source}.log"
            record = ["--record-graph", str(tmp / ("graph.json" if source == "rclpy" else "graph_dds.json"))]
            p = rclverify(["nodl", "check", "-w", str(ws), "--ros2", "--wait", "2", "--source", source,
                           "--ros2-python", str(ros2_python()), *record], env, ws, log)
            procs.append(p)
            code = p.wait(120)
            out[source] = {"code": code, "log": log.read_text()}
        log = tmp / "diff.log"  # the documents as ros diff's expected graph (rclpy's graph API, as above)
        p = rclverify(["ros", "diff", "--nodl", str(ws / "nodl"), "--ros2", "--wait", "2", "--source", "rclpy",
                       "--ros2-python", str(ros2_python()), "--record-graph", str(tmp / "diff_graph.mcap")], env, ws, log)
        procs.append(p)
        out["diff"] = {"code": p.wait(120), "log": log.read_text()}
        log = tmp / "diff_dds.log"  # and through rclverify's own DDS participant, recorded
        p = rclverify(["ros", "diff", "--nodl", str(ws / "nodl"), "--ros2", "--wait", "2", "--source", "dds",
                       "--record-graph", str(tmp / "diff_graph_dds.json")], env, ws, log)
        procs.append(p)
        out["diff_dds"] = {"code": p.wait(120), "log": log.read_text()}
        stop(procs[0])  # the robot stops: the recording is read with no node running
        log = tmp / "check_recorded.log"
        p = rclverify(["nodl", "check", "-w", str(ws), "--graph", str(tmp / "graph.json")], env, ws, log)
        procs.append(p)
        out["recorded"] = {"code": p.wait(120), "log": log.read_text(), "graph": tmp / "graph.json", "ws": ws,
                           "graph_dds": tmp / "graph_dds.json", "diff_graph_dds": tmp / "diff_graph_dds.json",
                           "bag": tmp / "diff_graph.mcap"}
        yield out
    finally:
        for p in procs:
            stop(p)


def _lines(log: str, node: str) -> list[str]:
    return [ln for ln in log.splitlines() if f"node /{node}" in ln and ln.startswith("nodl/")]


SOURCES = {"dds": "DDS domain", "rclpy": "rclpy on rmw_fastrtps_cpp", "recorded": "rclpy on rmw_fastrtps_cpp"}


@pytest.mark.parametrize("source", SOURCES)
def test_the_documents_are_matched_to_the_running_nodes(run, source: str) -> None:
    log = run[source]["log"]
    assert f"2 document(s) matched to a running node ({SOURCES[source]}" in log
    assert "; Base -> /Base; Guard -> /Guard" in log
    assert run[source]["code"] == 1 and "Traceback" not in log


@pytest.mark.parametrize("source", SOURCES)
def test_the_node_running_as_its_document_says_has_no_finding(run, source: str) -> None:
    assert _lines(run[source]["log"], "Guard") == []


@pytest.mark.parametrize("source", SOURCES)
def test_each_seeded_mismatch_of_the_running_node_is_found(run, source: str) -> None:
    found = {ln.rsplit("[", 1)[1].rstrip("]"): ln for ln in _lines(run[source]["log"], "Base")}
    assert sorted(found) == ["nodl-live-absent", "nodl-live-qos", "nodl-live-type", "nodl-live-undeclared"]
    assert "/speed has type std_msgs/msg/Float32 in the running node and std_msgs/msg/Float64" in found["nodl-live-type"]
    assert "/stop's durability is VOLATILE announced by the running node and TRANSIENT_LOCAL" in found["nodl-live-qos"]
    assert "declares /estop (std_srvs/srv/SetBool) in service_servers, and the running node has no such endpoint" \
        in found["nodl-live-absent"]
    assert "/odom (std_msgs/msg/Float64) in publishers in the running node" in found["nodl-live-undeclared"]
    # each is located in the document too: the document's line of the policy, of the type, of the entry
    assert found["nodl-live-qos"].startswith("nodl/Base.nodl.json:6:")
    assert f"(also at {SOURCES[source]}" in found["nodl-live-qos"]


def test_ros_diff_takes_the_documents_as_its_expected_graph(run) -> None:
    """The same seeded mismatches as ros diff's items, each of the documents' side at the document's line; the
    node running as its document says gives none (the control); Dock, not running, is missing."""
    log, code = run["diff"]["log"], run["diff"]["code"]
    assert code == 1 and "Traceback" not in log
    items = [ln.strip() for ln in log.splitlines() if ln.startswith("  ")]
    assert not [i for i in items if "/Guard" in i], items
    assert any(i.startswith("nodl/Dock.nodl.yaml:1:1: node /Dock is not running") for i in items), items
    assert any(i.startswith("nodl/Base.nodl.json:6:") and "/stop" in i and "durability is VOLATILE announced by the "
               "running node and TRANSIENT_LOCAL in its NoDL document" in i for i in items), items
    assert any(i.startswith("nodl/Base.nodl.json:10:") and "/Base publishes /speed: its NoDL document's type is "
               "std_msgs/Float64, the running system's std_msgs/Float32" in i for i in items), items
    assert any(i.startswith("nodl/Base.nodl.json:") and "/Base serves /estop" in i and "in its NoDL document, not in "
               "the running system" in i for i in items), items
    assert any("/Base publishes /odom" in i and "not in its NoDL document" in i for i in items), items
    assert "in the NoDL documents, not in the running system at rclpy on rmw_fastrtps_cpp:" in log


def _places(log: str) -> list[tuple[str, str]]:
    """Each finding line's first place and code."""
    return sorted((ln.split(": ", 1)[0], ln.rsplit("[", 1)[1]) for ln in log.splitlines() if ln.startswith("nodl/"))


def test_the_recorded_graph_gives_the_findings_of_the_live_sources(run) -> None:
    recorded = run["recorded"]["log"]
    assert "source: recorded (the graph recorded in " in recorded and "Traceback" not in recorded
    assert [ln for ln in recorded.splitlines() if ln.startswith("nodl/")] == \
        [ln for ln in run["rclpy"]["log"].splitlines() if ln.startswith("nodl/")]  # the same lines as live
    assert _places(recorded) == _places(run["dds"]["log"]) == _places(run["rclpy"]["log"])  # and as the DDS source
    assert len(_places(recorded)) == 5  # the four seeded mismatches and Dock, not running, at its document


def test_a_graph_difference_seeded_into_the_recording_is_found_and_a_bad_recording_refused(
        run, tmp_path: Path, capsys, monkeypatch: pytest.MonkeyPatch) -> None:
    """Guard's /stop publisher made best-effort in the recording: a finding at Guard's document that the
    recording as made (the control, above: no Guard line) does not have; a recording that is not one: one line."""
    from rclverify.cli.commands import main
    data = json.loads(run["recorded"]["graph"].read_text(encoding="utf-8"))
    [stop_pub] = [e for e in data["endpoints"]["/stop"]["pubs"] if e["node"] == "Guard"]
    stop_pub["reliable"] = False
    edited = tmp_path / "edited.json"
    edited.write_text(json.dumps(data), encoding="utf-8")
    monkeypatch.chdir(run["recorded"]["ws"])
    assert main(["nodl", "check", "--graph", str(edited)]) == 1
    guard = _lines(capsys.readouterr().err, "Guard")
    assert guard and all("[nodl-live-qos]" in ln and "/stop's reliability is BEST_EFFORT" in ln for ln in guard), guard
    stop_pub["reliable"] = "no"
    edited.write_text(json.dumps(data, indent=1), encoding="utf-8")
    assert main(["nodl", "check", "--graph", str(edited)]) == 1
    err = capsys.readouterr().err
    assert f"{edited}:" in err and "error: endpoints.'/stop'.pubs.0.reliable: is a bool" in err and "Traceback" not in err
    assert main(["nodl", "check", "--graph", str(edited), "--ros2"]) == 2  # one graph at a time


def _finding_lines(log: str) -> list[str]:
    return [ln for ln in log.splitlines() if ln.startswith("nodl/")]


def _items(log: str) -> list[str]:
    """ros diff's item lines and the headings of its lists."""
    return [ln for ln in log.splitlines() if ln.startswith("  ") or ln.startswith("in the NoDL")]


def test_the_two_sources_record_the_same_graph(run) -> None:
    """The DDS source's recording (rclverify's own participant, rclverify.ros.live.dds_record) holds exactly what
    rclpy's graph API gave: the same nodes with their topics and services, the same endpoints with their GIDs,
    types, type hashes and QoS; only the source's label differs."""
    rclpy, dds = (json.loads(run["recorded"][k].read_text(encoding="utf-8")) for k in ("graph", "graph_dds"))
    assert rclpy["nodes"] == dds["nodes"] and [n["name"] for n in dds["nodes"]] == ["Base", "Guard"]
    def ends(g: dict[str, Any]) -> dict[str, dict[str, list[str]]]:  # each role's endpoints in GID order
        return {t: {r: sorted(json.dumps(e, sort_keys=True) for e in es) for r, es in roles.items()}
                for t, roles in g["endpoints"].items()}
    assert ends(rclpy) == ends(dds) and "/stop" in dds["endpoints"]
    assert all(e.get("hash", "").startswith("RIHS01_") for roles in dds["endpoints"].values()
               for es in roles.values() for e in es)
    assert rclpy["rmw"] == "rmw_fastrtps_cpp" and "source" not in rclpy and dds["source"].startswith("DDS domain ")


def test_the_dds_sources_recording_gives_its_findings(run, capsys, monkeypatch: pytest.MonkeyPatch) -> None:
    """nodl check --graph on the DDS source's recording: the DDS source's lines exactly (its source named
    ``DDS domain N`` as live)."""
    from rclverify.cli.commands import main
    monkeypatch.chdir(run["recorded"]["ws"])
    assert main(["nodl", "check", "--graph", str(run["recorded"]["graph_dds"])]) == 1
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert _finding_lines(err) == _finding_lines(run["dds"]["log"]) and len(_finding_lines(err)) >= 5


@pytest.mark.parametrize("live,graph", [("diff", "graph"), ("diff_dds", "diff_graph_dds")])
def test_ros_diff_reads_a_recording_as_the_live_reading_it_was_made_from(
        run, live: str, graph: str, capsys, monkeypatch: pytest.MonkeyPatch) -> None:
    """ros diff --nodl --graph FILE: the items of the live ros diff through the same source, line for line
    (the rclpy recording was made by nodl check, the DDS one by ros diff itself)."""
    from rclverify.cli.commands import main
    monkeypatch.chdir(run["recorded"]["ws"])
    assert run[live]["code"] == 1 and "Traceback" not in run[live]["log"]
    assert main(["ros", "diff", "--nodl", "nodl", "--graph", str(run["recorded"][graph])]) == 1
    out = capsys.readouterr()
    assert "Traceback" not in out.err and "source: recorded (the graph recorded in " in out.err
    assert _items(out.out) == _items(run[live]["log"]) and len(_items(out.out)) >= 5


def test_ros_diff_finds_a_difference_seeded_into_a_recording(run, tmp_path: Path, capsys,
                                                            monkeypatch: pytest.MonkeyPatch) -> None:
    """Guard's /stop publisher made best-effort in the DDS recording: ros diff --graph gives an item at Guard's
    document that the recording as made (the control) does not; a recording that is not one: one located line,
    exit 1; --graph with --ros2: a usage error."""
    from rclverify.cli.commands import main
    monkeypatch.chdir(run["recorded"]["ws"])
    made = run["recorded"]["diff_graph_dds"]
    assert main(["ros", "diff", "--nodl", "nodl", "--graph", str(made)]) == 1
    assert not [i for i in _items(capsys.readouterr().out) if "/Guard" in i]  # the control
    data = json.loads(made.read_text(encoding="utf-8"))
    assert data["source"].startswith("DDS domain ")
    [stop_pub] = [e for e in data["endpoints"]["/stop"]["pubs"] if e["node"] == "Guard"]
    stop_pub["reliable"] = False
    edited = tmp_path / "edited.json"
    edited.write_text(json.dumps(data), encoding="utf-8")
    assert main(["ros", "diff", "--nodl", "nodl", "--graph", str(edited)]) == 1
    guard = [i for i in _items(capsys.readouterr().out) if "/Guard" in i]
    assert guard and any("/stop" in i and "BEST_EFFORT" in i for i in guard), guard
    data["endpoints"]["/stop"]["pubs"][0]["durability"] = "sometimes"
    edited.write_text(json.dumps(data, indent=1), encoding="utf-8")
    assert main(["ros", "diff", "--nodl", "nodl", "--graph", str(edited)]) == 1
    err = capsys.readouterr().err
    assert f"{edited}:" in err and "durability: is volatile or transient_local" in err and "Traceback" not in err
    assert main(["ros", "diff", "--nodl", "nodl", "--graph", str(edited), "--ros2"]) == 2


def test_the_graph_message_recorded_in_a_bag_gives_the_live_findings(run, tmp_path: Path, capsys,
                                                                    monkeypatch: pytest.MonkeyPatch) -> None:
    """The running graph recorded live as a rosgraph_msgs/msg/Graph message in an MCAP bag (ros diff --record-graph
    X.mcap), and nodl check's JSON recording written as one in a SQLite 3 bag: nodl check --graph BAG gives the
    live rclpy reading's finding lines exactly, ros diff --graph BAG the live diff's items; the two bags hold the
    same graph.  Guard's /stop publisher made best-effort in the message: a finding at Guard that the bags as
    made (the control) do not give."""
    from rclverify.cli.commands import main
    from rclverify.model.nodl.graph_record import read_record
    from rclverify.ros.graph.graph_bag import read_graph, write_bag
    monkeypatch.chdir(run["recorded"]["ws"])
    live = run["recorded"]["bag"].with_suffix("")
    assert (live / "metadata.yaml").is_file() and (live / "diff_graph.mcap").is_file()
    sqlite = write_bag(tmp_path / "graph.db3", read_record(run["recorded"]["graph"]))
    for bag in (live, sqlite):
        assert main(["nodl", "check", "--graph", str(bag)]) == 1
        err = capsys.readouterr().err
        assert "Traceback" not in err and _finding_lines(err) == _finding_lines(run["rclpy"]["log"])
        assert not _lines(err, "Guard")  # the control
        assert main(["ros", "diff", "--nodl", "nodl", "--graph", str(bag)]) == 1
        assert _items(capsys.readouterr().out) == _items(run["diff"]["log"]) and len(_items(run["diff"]["log"])) >= 5
    def shape(g: dict[str, Any]) -> Any:
        return g["nodes"], {t: {r: sorted(json.dumps({k: v for k, v in e.items() if k != "gid"}, sort_keys=True)
                                          for e in es) for r, es in roles.items()} for t, roles in g["endpoints"].items()}
    assert shape(read_graph(live)) == shape(read_graph(sqlite)) and read_graph(live)["rmw"] == "rmw_fastrtps_cpp"
    seeded = read_graph(live)
    [stop_pub] = [e for e in seeded["endpoints"]["/stop"]["pubs"] if e["node"] == "Guard"]
    stop_pub["reliable"] = False
    bag = write_bag(tmp_path / "seeded.mcap", seeded)
    assert main(["nodl", "check", "--graph", str(bag)]) == 1
    guard = _lines(capsys.readouterr().err, "Guard")
    assert guard and all("/stop's reliability is BEST_EFFORT" in ln for ln in guard), guard
