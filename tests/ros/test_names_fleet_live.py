"""A two-robot fleet of real rclpy nodes on Fast DDS (tests/_ros2.py): ``odom_source`` and ``relay`` under
``/r1`` and under ``/r2``, ``/r2``'s relay wired to the other robot's ``/r1/odom`` (an absolute name in its code).
``rclverify ros diff --nodl DIR --ros2 --namespace ...`` (rclpy's graph API) matches each document to each
instance by its fully qualified name and finds the miswiring at ``/r2``'s relay and the document's line; ``/r1``'s
relay, wired to its own odom, is the control (docs/nodl.md, "Matching documents to nodes")."""
from __future__ import annotations

import subprocess
from pathlib import Path
from typing import Any, Iterator

import pytest

from _procs import stop
from _ros2 import rclverify, ros2_env, ros2_python, start_node

from test_names_fleet import ODOM, RELAY

NODES = """\
import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from std_msgs.msg import Float64

rclpy.init()
ex = SingleThreadedExecutor()
for ns, odom in (('/r1', 'odom'), ('/r2', '/r1/odom')):
    src = Node('odom_source', namespace=ns)
    src.create_publisher(Float64, 'odom', 10)
    relay = Node('relay', namespace=ns)
    relay.create_subscription(Float64, odom, lambda m: None, 10)
    relay.create_publisher(Float64, '~/cmd', 10)
    ex.add_node(src)
    ex.add_node(relay)
print('ready', flush=True)
ex.spin()
"""


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, Any]]:
    tmp = tmp_path_factory.mktemp("fleet")
    folder = tmp / "nodl"
    folder.mkdir()
    (folder / "OdomSource.nodl.yaml").write_text(ODOM, encoding="utf-8")
    (folder / "Relay.nodl.yaml").write_text(RELAY, encoding="utf-8")
    env = ros2_env(tmp)
    procs: list[subprocess.Popen[bytes]] = []
    try:
        procs.append(start_node(tmp, "fleet", NODES, env))
        log = tmp / "diff.log"
        spaces = [x for node in ("OdomSource", "Relay") for ns in ("/r1", "/r2") for x in ("--namespace", f"{node}={ns}")]
        p = rclverify(["ros", "diff", "--nodl", str(folder), "--ros2", "--wait", "2", "--source", "rclpy",
                       "--ros2-python", str(ros2_python()), *spaces], env, tmp, log)
        procs.append(p)
        yield {"code": p.wait(120), "log": log.read_text(), "relay": (folder / "Relay.nodl.yaml").read_text()}
    finally:
        for p in procs:
            stop(p)


def test_the_miswired_relay_is_found_at_its_place_and_the_other_robot_is_clean(run: dict[str, Any]) -> None:
    log = run["log"]
    assert run["code"] == 1 and "Traceback" not in log, log
    items = [ln.strip() for ln in log.splitlines() if ln.startswith("  ")]
    line = next(i for i, t in enumerate(run["relay"].splitlines(), 1) if "- name: odom" in t)
    assert any(i.startswith(f"nodl/Relay.nodl.yaml:{line}:") and "/r2/relay subscribes to /r2/odom" in i
               for i in items), items
    assert any("/r2/relay subscribes to /r1/odom" in i for i in items), items
    # the control: every other instance runs as its document says (no item names it), and none is missing
    assert not [i for i in items if "/r1/relay" in i or "odom_source" in i or "is not running" in i], items
    assert len(items) == 2, items
