"""A fleet: one node run twice, under ``/r1`` and ``/r2`` (issue 110).  NoDL documents are matched to
the running nodes by their fully qualified names (model/nodl/match.py), each in the namespaces given
for it, and their names resolved there as rcl resolves them, in ``nodl check --ros2`` (check_code,
side "live") and ``ros diff --nodl`` (diff_nodl).

The running side is what rclpy's graph reader sends (its ``graph_all`` dump, read by
:class:`~rclverify.runtime.rclpy_source.graph.RclpyDiscovery`, made a graph by
:func:`~rclverify.ros.live.diff_dds.graph_of`), as tests/ros/test_ros_diff_nodl.py writes it.  The
fleet runs as documented (equal, no finding), then with ``/r2``'s relay wired to ``/r1/odom`` (the
difference, at ``/r2``'s relay and the document's line, and ``/r1``'s relay still clean); by base
name alone the documents match nothing (the user's '13 missing'), and say why.
"""
from __future__ import annotations

import copy
from pathlib import Path
from typing import Any

import pytest

from rclverify.cli.commands import main
from rclverify.model.nodl.check import document_files, read_all, shown
from rclverify.model.nodl.document import Resolver
from rclverify.model.nodl.match import match_instances, parse_namespaces
from rclverify.ros.ground.diff_nodl import diff_nodl, nodes_of
from rclverify.ros.ground.nodl_code import check_code, live_qos_of
from rclverify.ros.live.diff import render_text
from rclverify.ros.live.diff_dds import graph_of, qos_conflicts
from rclverify.runtime.rclpy_source.graph import RclpyDiscovery

F64 = "std_msgs/msg/Float64"
QOS = "  qos:\n    history: KEEP_LAST\n    depth: 10\n    reliability: RELIABLE\n    durability: VOLATILE\n"
ODOM = f"nodl_version: 2\npublishers:\n- name: odom\n  type: {F64}\n{QOS}"
RELAY = (f"nodl_version: 2\nsubscriptions:\n- name: odom\n  type: {F64}\n{QOS}"
         f"publishers:\n- name: ~/cmd\n  type: {F64}\n{QOS}")
FLEET = {"OdomSource": ["/r1", "/r2"], "Relay": ["/r1", "/r2"]}


def _end(gid: int, node: str, ns: str) -> dict[str, Any]:
    return {"gid": f"{gid:032x}", "node": node, "ns": ns, "type": F64, "hash": "", "reliable": True,
            "durability": "volatile"}


def _dump(r2_odom: str = "/r2/odom") -> dict[str, Any]:
    """The fleet running (rclpy's graph_all dump): per robot an odom_source publishing ``odom`` and
    a relay subscribing to it and publishing ``~/cmd``; ``/r2``'s relay subscribes to ``r2_odom``."""
    nodes, ends = [], {}
    for i, ns in enumerate(("/r1", "/r2")):
        odom, sub, cmd = f"{ns}/odom", (r2_odom if ns == "/r2" else f"{ns}/odom"), f"{ns}/relay/cmd"
        nodes += [{"name": "odom_source", "ns": ns, "pubs": [[odom, [F64]]], "subs": [], "servers": [], "clients": []},
                  {"name": "relay", "ns": ns, "pubs": [[cmd, [F64]]], "subs": [[sub, [F64]]], "servers": [],
                   "clients": []}]
        ends.setdefault(odom, {"pubs": [], "subs": []})["pubs"].append(_end(10 * i + 1, "odom_source", ns))
        ends.setdefault(sub, {"pubs": [], "subs": []})["subs"].append(_end(10 * i + 2, "relay", ns))
        ends.setdefault(cmd, {"pubs": [], "subs": []})["pubs"].append(_end(10 * i + 3, "relay", ns))
    return {"what": "graph_all", "rmw": "rmw_fastrtps_cpp", "nodes": nodes, "endpoints": ends}


@pytest.fixture()
def docs(tmp_path: Path) -> tuple[Path, dict[str, Any]]:
    folder = tmp_path / "nodl"
    folder.mkdir()
    (folder / "OdomSource.nodl.yaml").write_text(ODOM, encoding="utf-8")
    (folder / "Relay.nodl.yaml").write_text(RELAY, encoding="utf-8")
    return folder, nodes_of(read_all(document_files(folder), Resolver([], shown(tmp_path))))


def _running(dump: dict[str, Any]) -> tuple[Any, RclpyDiscovery]:
    disc = RclpyDiscovery(dump)
    return graph_of(disc, f"rclpy on {disc.rmw}"), disc  # type: ignore[arg-type]


def test_each_instance_is_matched_to_its_own_node(docs: tuple[Path, dict[str, Any]]) -> None:
    _, documents = docs
    running, disc = _running(_dump())
    assert {i.label: i.running for i in match_instances(documents, running.nodes, FLEET)} == {
        "OdomSource in /r1": "/r1/odom_source", "OdomSource in /r2": "/r2/odom_source",
        "Relay in /r1": "/r1/relay", "Relay in /r2": "/r2/relay"}
    matched, found = check_code(documents, running.nodes, side="live", qos_of=live_qos_of(disc), namespaces=FLEET)
    assert len(matched) == 4 and found == []
    res = diff_nodl(documents, running, "rclpy", qos_conflicts(disc), disc, FLEET)
    assert res.equal, render_text(res)


def test_by_base_name_alone_a_fleet_matches_nothing_and_says_why(docs: tuple[Path, dict[str, Any]]) -> None:
    _, documents = docs
    running, disc = _running(_dump())
    matched, found = check_code(documents, running.nodes, side="live", qos_of=live_qos_of(disc))
    assert matched == {} and [f.code for f in found] == ["nodl-live-unmatched"] * 2
    assert "its name is that of 2 nodes (/r1/relay, /r2/relay): the base name alone is ambiguous; give each " \
           "instance's namespace (--namespace Relay=NS)" in found[1].message
    # control: one robot alone is unambiguous, matched by its base name without a namespace
    one = _dump()
    one["nodes"] = [n for n in one["nodes"] if n["ns"] == "/r1"]
    one["endpoints"] = {k: v for k, v in one["endpoints"].items() if k.startswith("/r1/")}
    running1, disc1 = _running(one)
    matched, found = check_code(documents, running1.nodes, side="live", qos_of=live_qos_of(disc1))
    assert matched == {"OdomSource": "/r1/odom_source", "Relay": "/r1/relay"} and found == []


def test_a_relay_wired_to_the_other_robots_odom_is_found_at_its_place(docs: tuple[Path, dict[str, Any]]) -> None:
    folder, documents = docs
    running, disc = _running(_dump(r2_odom="/r1/odom"))
    line = next(i for i, t in enumerate((folder / "Relay.nodl.yaml").read_text().splitlines(), 1) if "- name: odom" in t)
    matched, found = check_code(documents, running.nodes, side="live", qos_of=live_qos_of(disc), namespaces=FLEET)
    assert len(matched) == 4
    assert sorted((f.code, f.message.split(" ")[1]) for f in found) == [
        ("nodl-live-absent", "/r2/relay's"), ("nodl-live-undeclared", "/r2/relay")]
    absent = next(f for f in found if f.code == "nodl-live-absent")
    assert "declares /r2/odom" in absent.message and absent.locs[0].line == line
    assert "/r1/odom" in next(f for f in found if f.code == "nodl-live-undeclared").message
    res = diff_nodl(documents, running, "rclpy", qos_conflicts(disc), disc, FLEET)
    [missing] = res.missing
    assert (missing.category, missing.name, missing.node) == ("subscriber", "/r2/odom", "/r2/relay")
    assert missing.src is not None and missing.src.line == line
    [extra] = res.extra
    assert (extra.category, extra.name, extra.node) == ("subscriber", "/r1/odom", "/r2/relay")
    # control: the same wiring on /r1 (its own odom) is no difference there
    assert not [i for i in res.missing + res.extra if i.node == "/r1/relay"]


def test_a_namespace_with_no_such_node_is_an_unmatched_instance(docs: tuple[Path, dict[str, Any]]) -> None:
    _, documents = docs
    running, disc = _running(_dump())
    matched, found = check_code(documents, running.nodes, side="live", qos_of=live_qos_of(disc),
                                namespaces={"Relay": ["/r1", "/r3"]})
    assert matched["Relay in /r1"] == "/r1/relay" and "Relay in /r3" not in matched
    [f] = [f for f in found if "Relay's NoDL document in /r3 matches no node" in f.message]
    assert f.code == "nodl-live-unmatched" and "no node of namespace /r3 has its name (it runs as /r1/relay, " \
                                              "/r2/relay)" in f.message
    res = diff_nodl(documents, running, "rclpy", qos_conflicts(disc), disc, {"Relay": ["/r3"], "OdomSource": ["/r1"]})
    assert any(i.category == "node" and i.name == "/r3/Relay" for i in res.missing)


def test_namespaces_given_on_the_command_line(docs: tuple[Path, dict[str, Any]],
                                              capsys: pytest.CaptureFixture[str]) -> None:
    folder, documents = docs
    assert parse_namespaces(["Relay=/r1/", "Relay=/r2", "Relay=/r1"], documents) == {"Relay": ["/r1", "/r2"]}
    for bad, said in (("Nope=/r1", "no document is named after node 'Nope'"), ("Relay=/1r", "no token"),
                      ("Relay", "write NODE=NAMESPACE")):
        assert main(["ros", "diff", "--nodl", str(folder), "--ros2", "--namespace", bad]) == 2
        err = capsys.readouterr().err
        assert said in err and "Traceback" not in err and err.count("\n") == 1
    assert main(["ros", "diff", "--ros2", "--namespace", "Relay=/r1"]) == 2
    assert "give --nodl DIR" in capsys.readouterr().err
