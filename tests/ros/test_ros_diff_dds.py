"""``rclverify ros diff --ros2`` against a running ROS 2 graph on DDS
(docs/ros.md, "Expected against observed").

The code side is tests/data/ros/dds_diff_ws (an ament_python package whose
launch file starts ``/sensor``, which publishes ``/range`` best-effort and
serves ``/reset``, and ``/planner``, which subscribes to ``/range``,
publishes ``/plan`` and calls ``/reset``).  The running side is one
participant written with cyclonedds to ROS 2's conventions
(tests/dds_ros2.py), on 127.0.0.1 and a random ``ROS_DOMAIN_ID``: ``/sensor``
as the code has it plus a ``/debug`` topic the code never names, no
``/planner``, and a ``/viewer`` the code does not have, subscribing to
``/range`` reliably, which DDS will not connect to the best-effort sensor.
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Iterator

import pytest

pytest.importorskip("cyclonedds", reason="the cyclonedds binding is not installed (pip install cyclonedds)")

from dds_ros2 import Ros2Participant, dds_env, domain_of  # noqa: E402

from rclverify.runtime.dds.types import TypeBook  # noqa: E402
from rclverify.cli.commands import main  # noqa: E402

WS = Path(__file__).parent.parent / "data" / "ros" / "dds_diff_ws"
LAUNCH = WS / "src" / "dds_demo" / "launch" / "demo.launch.py"


@pytest.fixture(scope="module")
def diff(tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, Any]]:
    tmp = tmp_path_factory.mktemp("ddsdiff")
    env = dds_env(tmp)
    mp = pytest.MonkeyPatch()
    for k, v in env.items():
        mp.setenv(k, v)
    ros = Ros2Participant(TypeBook([]), domain_of(env))
    try:
        sensor, viewer = ros.node("sensor"), ros.node("viewer")
        ros.publisher(sensor, "/range", "std_msgs/Float32", reliable=False)
        ros.publisher(sensor, "/debug", "std_msgs/String")
        ros.serve(sensor, "/reset", "std_srvs/Trigger", lambda k, req: ({"success": True}, 0.0))
        ros.subscriber(viewer, "/range", "std_msgs/Float32", reliable=True)
        ros.announce()
        out = tmp / "diff.json"
        code = main(["ros", "diff", str(WS), "--launch", str(LAUNCH), "--ros2", "--wait", "1.5", "--json", str(out)])
        yield {"code": code, "json": json.loads(out.read_text()), "domain": domain_of(env)}
    finally:
        ros.close()
        mp.undo()


def _items(d: dict[str, Any], side: str, category: str) -> list[dict[str, Any]]:
    return [i for i in d["json"][side] if i["category"] == category]


def test_a_node_of_the_code_not_running_is_missing_and_located(diff: dict[str, Any]) -> None:
    missing = _items(diff, "missing", "node")
    assert [i["name"] for i in missing] == ["/planner"]
    at = missing[0]["at"]
    assert at["file"].endswith("demo.launch.py") and at["line"] == 9  # its Node(...) in the launch file
    assert diff["code"] == 1 and diff["json"]["observed"] == {"kind": "dds", "source": f"DDS domain {diff['domain']}"}


def test_a_topic_the_code_never_names_is_extra(diff: dict[str, Any]) -> None:
    extra = _items(diff, "extra", "publisher")
    assert [(i["node"], i["name"], i["observed_type"]) for i in extra] == [("/sensor", "/debug", "std_msgs/msg/String")]
    assert "the code names /debug nowhere" in extra[0]["message"]
    assert [i["name"] for i in _items(diff, "extra", "node")] == ["/viewer"]
    # what runs as the code says is not reported: /sensor's /range and its /reset server
    everything = diff["json"]["missing"] + diff["json"]["extra"]
    assert not [i for i in everything if i["node"] == "/sensor" and i["name"] in ("/range", "/reset")]


def test_a_qos_conflict_is_reported(diff: dict[str, Any]) -> None:
    qos = _items(diff, "missing", "qos")
    assert len(qos) == 1 and qos[0]["name"] == "/range"
    assert "node /viewer subscribes with reliable" in qos[0]["message"]
    assert "node /sensor publishes with best_effort" in qos[0]["message"]


def test_a_node_list_that_never_arrives_is_said_after_the_settling(tmp_path: Path,
                                                                  monkeypatch: pytest.MonkeyPatch) -> None:
    """A ROS 2 participant (it has a ros_discovery_info writer) whose node list
    never comes: the reader listens past the wait for the settling time, then
    says so; its endpoints are in no node, never silently in a wrong one."""
    import time

    from rclverify.ros.live.diff_dds import read_dds_graph
    env = dds_env(tmp_path)
    for k, v in env.items():
        monkeypatch.setenv(k, v)
    ros = Ros2Participant(TypeBook([]), domain_of(env))
    try:
        ros.publisher(ros.node("late"), "/scan", "std_msgs/Float32")  # announce() is never called
        start = time.monotonic()
        g, disc, _source, dp = read_dds_graph(0.5, domain_of(env), settle_s=1.0)
        took = time.monotonic() - start
        disc.close()
        dp.__del__()
    finally:
        ros.close()
    said = [n.message for n in g.notes]
    assert [m for m in said if "its node list (ros_discovery_info) has not arrived" in m
            and "the graph may be incomplete" in m], said
    assert [m for m in said if "rt/scan" in m and "in no ROS 2 node" in m], said
    assert not g.nodes and 1.4 <= took < 5, (g.nodes, took)
    # a diff on such a reading is never "equal": nothing differs, but the running side was not read whole
    from rclverify.ros.live.diff import render_text
    from rclverify.ros.live.diff_dds import diff_dds
    from rclverify.ros.extract.model import Graph
    res = diff_dds(Graph(), g, "DDS domain")
    assert not res.missing and not res.extra and not res.equal and len(res.incomplete) == 1
    assert res.to_json()["equal"] is False and res.to_json()["incomplete"] == res.incomplete
    assert render_text(res)[-1].startswith("ros diff: 0 missing, 0 extra (incomplete, not equal)")
