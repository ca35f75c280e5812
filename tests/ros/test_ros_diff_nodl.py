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

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "manipulator" / "nodl"
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


def _read(folder: Path) -> dict[str, Any]:
    return nodes_of(read_all(document_files(folder), Resolver([], shown(folder.parent))))


def _edit(path: Path, old: str, new: str, nth: int = 1) -> int:
    """Replace the ``nth`` ``old`` of ``path`` by ``new``; the 1-based line of the replaced text's first line."""
    text = path.read_text(encoding="utf-8")
    at = -1
    for _ in range(nth):
        at = text.index(old, at + 1)
    path.write_text(text[:at] + new + text[at + len(old):], encoding="utf-8")
    return text[:at].count("\n") + 1


def _timing(end: dict[str, Any], deadline_ns: int | None = None, liveliness: str = "automatic",
            lease_ns: int | None = None) -> None:
    """Give a dump endpoint the deadline, liveliness and lease rclpy reports (2**63 - 1 ns: none)."""
    none = 2 ** 63 - 1
    end.update(deadline_ns=deadline_ns or none, liveliness=liveliness, lease_ns=lease_ns or none)


def test_a_publishers_deadline_longer_than_its_document_offers(docs: tuple[Path, dict[str, Any]]) -> None:
    """Battery's document offers a 100 ms deadline: its running publisher offering 300 ms is a QoS item
    at the document's ``deadline_ns`` line; offering 100 ms or a tighter 50 ms keeps the document's
    promise (the controls).  ChargeMonitor's document requests no deadline, so its running subscription
    requesting one is an item at its ``qos`` (a publisher the document admits, without a deadline,
    would not connect)."""
    folder, _ = docs
    line = _edit(folder / "Battery.nodl.yaml", "    durability: VOLATILE\n",
                 "    durability: VOLATILE\n    deadline_ns: 100000000\n") + 1
    documents = _read(folder)
    for offered in (100_000_000, 50_000_000):
        dump = _dump()
        _timing(dump["endpoints"]["/battery"]["pubs"][0], deadline_ns=offered)
        _timing(dump["endpoints"]["/battery"]["subs"][0])
        res = _diff(documents, dump)
        assert res.equal, render_text(res)
    dump = _dump()
    _timing(dump["endpoints"]["/battery"]["pubs"][0], deadline_ns=300_000_000)
    _timing(dump["endpoints"]["/battery"]["subs"][0])
    res = _diff(documents, dump)
    [item] = res.missing
    assert (item.category, item.node) == ("qos", "/battery")
    assert item.src is not None and (item.src.file.rsplit("/", 1)[-1], item.src.line) == ("Battery.nodl.yaml", line)
    assert "offers deadline 300000000 ns announced by the running node" in item.message
    assert "its NoDL document offers 100000000 ns" in item.message
    dump = _dump()
    _timing(dump["endpoints"]["/battery"]["pubs"][0], deadline_ns=100_000_000)
    _timing(dump["endpoints"]["/battery"]["subs"][0], deadline_ns=200_000_000)
    res = _diff(documents, dump)
    [item] = res.missing
    lines = (folder / "ChargeMonitor.nodl.yaml").read_text(encoding="utf-8").splitlines()
    assert (item.category, item.node) == ("qos", "/charge_monitor") and item.src is not None
    assert item.src.line == [i for i, t in enumerate(lines, 1) if t.strip() == "qos:"][1] + 1  # the qos mapping
    assert "requests deadline 200000000 ns announced by the running node and its NoDL document requests none" \
        in item.message


def test_a_subscriptions_liveliness_and_lease_stricter_than_its_document_requests(
        docs: tuple[Path, dict[str, Any]]) -> None:
    """ChargeMonitor's document requests automatic liveliness with a 1 s lease: its running
    subscription requesting manual-by-topic, or a 0.5 s lease, is a QoS item at the document's field
    (the liveliness at its ``qos``, which leaves the kind unsaid, rmw's automatic); requesting a 2 s
    lease asks less than the document and is no item (the control).  The running publisher offers
    automatic with a 0.5 s lease: against the manual-by-topic request the running ends' own conflict
    is said too (rclpy's graph carries liveliness)."""
    folder, _ = docs
    doc = folder / "ChargeMonitor.nodl.yaml"
    qos_line = _edit(doc, "    durability: VOLATILE\n", "    durability: VOLATILE\n"
                     "    liveliness_lease_duration_ns: 1000000000\n", nth=2) + 1
    documents = _read(folder)
    lines = doc.read_text(encoding="utf-8").splitlines()
    qos_at = [i for i, t in enumerate(lines, 1) if t.strip() == "qos:"][1] + 1  # where the qos mapping starts
    assert lines[qos_line - 1].strip().startswith("liveliness_lease_duration_ns")

    def run(liveliness: str, lease_ns: int) -> list[Any]:
        dump = _dump()
        _timing(dump["endpoints"]["/battery"]["pubs"][0], lease_ns=500_000_000)
        _timing(dump["endpoints"]["/battery"]["subs"][0], liveliness=liveliness, lease_ns=lease_ns)
        res = _diff(documents, dump)
        return list(res.missing)
    assert run("automatic", 2_000_000_000) == []
    kind, running = sorted(run("manual_by_topic", 2_000_000_000), key=lambda i: i.node is None)
    assert kind.src is not None and kind.src.line == qos_at and "requests liveliness MANUAL_BY_TOPIC" in kind.message, kind.message
    assert running.category == "qos" and running.node is None and "liveliness" in running.message
    [lease] = run("automatic", 500_000_000)
    assert lease.src is not None and lease.src.line == qos_line
    assert "requests liveliness lease duration 500000000 ns" in lease.message and "requests 1000000000 ns" in lease.message
