"""``rclverify ros diff --nodl DIR`` (docs/nodl.md, "ros diff against the documents"): the graph the NoDL
documents declare, QoS included, as ros diff's expected graph.

The running side is what rclpy's graph reader sends (its ``graph_all`` dump, read by
:class:`~rclverify.runtime.rclpy_source.graph.RclpyDiscovery` and made a graph by
:func:`~rclverify.ros.live.diff_dds.graph_of`, as ``ros diff --ros2 --source rclpy`` does), written
here for examples/manipulator's Battery and ChargeMonitor: as their documents say (the control:
equal), then with the Battery's publisher best effort (a QoS item at the document's line, and the
running ends' own conflict), a subscription missing and an undeclared publisher.
"""
from __future__ import annotations

import copy
import shutil
from pathlib import Path
from typing import Any

import pytest

from rclverify.cli.commands import main
from rclverify.model.nodl.check import document_files, read_all, shown
from rclverify.model.nodl.document import Resolver
from rclverify.ros.live.diff import render_text
from rclverify.ros.live.diff_dds import graph_of, qos_conflicts
from rclverify.ros.ground.diff_nodl import diff_nodl, nodes_of
from rclverify.runtime.rclpy_source.graph import RclpyDiscovery

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "manipulator" / "nodl"
BATTERY = "sensor_msgs/msg/BatteryState"


def _end(gid: int, node: str, typ: str, reliable: bool = True) -> dict[str, Any]:
    return {"gid": f"{gid:032x}", "node": node, "ns": "/", "type": typ, "hash": "", "reliable": reliable,
            "durability": "volatile"}


def _dump() -> dict[str, Any]:
    """The two nodes running as their documents declare them (rclpy's graph_all dump)."""
    return {"what": "graph_all", "rmw": "rmw_fastrtps_cpp",
            "nodes": [{"name": "battery", "ns": "/", "pubs": [["/battery", [BATTERY]]], "subs": [], "servers": [],
                       "clients": []},
                      {"name": "charge_monitor", "ns": "/", "pubs": [["/low", ["std_msgs/msg/Bool"]]],
                       "subs": [["/battery", [BATTERY]]], "servers": [], "clients": []}],
            "endpoints": {"/battery": {"pubs": [_end(1, "battery", BATTERY)], "subs": [_end(2, "charge_monitor", BATTERY)]},
                          "/low": {"pubs": [_end(3, "charge_monitor", "std_msgs/msg/Bool")], "subs": []}}}


@pytest.fixture()
def docs(tmp_path: Path) -> tuple[Path, dict[str, Any]]:
    folder = tmp_path / "nodl"
    folder.mkdir()
    for name in ("Battery", "ChargeMonitor"):
        shutil.copy(EXAMPLE / f"{name}.nodl.yaml", folder)
    return folder, nodes_of(read_all(document_files(folder), Resolver([], shown(tmp_path))))


def _diff(documents: dict[str, Any], dump: dict[str, Any]) -> Any:
    disc = RclpyDiscovery(dump)
    source = f"rclpy on {disc.rmw}"
    return diff_nodl(documents, graph_of(disc, source), source, qos_conflicts(disc), disc)  # type: ignore[arg-type]


def test_running_as_declared_is_equal(docs: tuple[Path, dict[str, Any]]) -> None:
    res = _diff(docs[1], _dump())
    assert res.equal, render_text(res)
    assert any("reliability and durability each document writes" in c for c in res.compared)
    assert render_text(res)[-1].startswith("ros diff: 0 missing, 0 extra (equal)")


def test_a_best_effort_publisher_is_a_qos_item_at_the_documents_line(docs: tuple[Path, dict[str, Any]]) -> None:
    folder, documents = docs
    dump = _dump()
    dump["endpoints"]["/battery"]["pubs"][0]["reliable"] = False
    res = _diff(documents, dump)
    lines = (folder / "Battery.nodl.yaml").read_text(encoding="utf-8").splitlines()
    line = next(i for i, text in enumerate(lines, 1) if "reliability: RELIABLE" in text)
    declared = [i for i in res.missing if i.category == "qos" and i.node == "/battery"]
    assert [(i.src.file.rsplit("/", 1)[-1], i.src.line) for i in declared] == [("Battery.nodl.yaml", line)]
    assert "BEST_EFFORT announced by the running node and RELIABLE in its NoDL document" in declared[0].message
    # the running ends' own conflict (a reliable subscription, a best-effort publisher) is said too
    assert any(i.category == "qos" and i.node is None and "/battery" in i.message for i in res.missing)
    assert not res.equal


def test_a_missing_subscription_and_an_undeclared_publisher(docs: tuple[Path, dict[str, Any]]) -> None:
    folder, documents = docs
    dump = copy.deepcopy(_dump())
    dump["nodes"][1]["subs"] = []
    dump["endpoints"]["/battery"]["subs"] = []
    dump["nodes"][0]["pubs"].append(["/battery_temp", ["std_msgs/msg/Float32"]])
    dump["endpoints"]["/battery_temp"] = {"pubs": [_end(4, "battery", "std_msgs/msg/Float32")], "subs": []}
    res = _diff(documents, dump)
    lines = (folder / "ChargeMonitor.nodl.yaml").read_text(encoding="utf-8").splitlines()
    line = next(i for i, text in enumerate(lines, 1) if "- name: battery" in text)
    [missing] = res.missing
    assert (missing.category, missing.name, missing.node) == ("subscriber", "/battery", "/charge_monitor")
    assert missing.src is not None and missing.src.line == line and "in its NoDL document" in missing.message
    [extra] = res.extra
    assert (extra.category, extra.name, extra.node) == ("publisher", "/battery_temp", "/battery")
    assert "no NoDL document names /battery_temp" in extra.message
    assert render_text(res)[0] == "in the NoDL documents, not in the running system at rclpy on rmw_fastrtps_cpp:"


def test_the_command_needs_the_running_system_and_no_code(docs: tuple[Path, dict[str, Any]],
                                                          capsys: pytest.CaptureFixture[str]) -> None:
    folder, _ = docs
    assert main(["ros", "diff", "--nodl", str(folder), "--bag", str(folder / "run.bag")]) == 2
    assert "give --ros2" in capsys.readouterr().err
    assert main(["ros", "diff", "--nodl", str(folder / "none"), "--ros2"]) == 2
    assert "no NoDL document" in capsys.readouterr().err
    assert main(["ros", "diff", "--nodl", str(folder), "--ros2", str(folder)]) == 2
    assert "give no PATH" in capsys.readouterr().err
