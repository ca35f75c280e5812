"""A two-robot fleet of real rclpy nodes monitored live from one contract set (issue 110; docs/plan.md
"Instances"): ``odom_source`` and ``relay`` under ``/r1`` and ``/r2``, the plan's ``instances`` making each
its own node.  ``rclverify monitor --live --ros2 --source rclpy`` judges each instance on its own topics:
with ``/r2``'s relay wired to the other robot's ``/r1/odom`` (an absolute name in its code) it is red at
``Relay_r2`` only; wired to its own ``odom`` (the control) every instance is green."""
from __future__ import annotations

import json
import signal
from pathlib import Path
from typing import Any, Iterator

import pytest

from _procs import stop, wait_for, wait_logged
from _ros2 import rclverify, ros2_env, ros2_python, start_node

RCL = """\
node OdomSource {
  inputs( )
  outputs( odom : REAL )
  topics( std_msgs/Float64 odom matches(out.odom) )
  assume( TRUE )
  guarantee( out.odom >= 0 )
}

node Relay {
  inputs( odom : REAL )
  outputs( cmd : REAL )
  topics( std_msgs/Float64 odom matches(in.odom), std_msgs/Float64 relay/cmd matches(out.cmd) )
  assume( in.odom >= 0 )
  guarantee( out.cmd == in.odom )
}
"""
ROUNDS = 20  # each source's odom, once every 0.1 s, each answered by its robot's relay
PLAN = "contracts: [contracts/fleet.rcl]\ninstances:\n  OdomSource: [/r1, /r2]\n  Relay: [/r1, /r2]\n"

NODES = """\
import time
import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from std_msgs.msg import Float64

R2_ODOM = "odom"
rclpy.init()
ex = SingleThreadedExecutor()
pubs = []
for ns, value, odom in (("/r1", 1.0, "odom"), ("/r2", 2.0, R2_ODOM)):
    src = Node("odom_source", namespace=ns)
    pub = src.create_publisher(Float64, "odom", 10)
    relay = Node("relay", namespace=ns)
    cmd = relay.create_publisher(Float64, "~/cmd", 10)
    relay.create_subscription(Float64, odom, lambda m, cmd=cmd: cmd.publish(Float64(data=m.data)), 10)
    pubs.append((pub, value, cmd))
    ex.add_node(src)
    ex.add_node(relay)
print("ready", flush=True)
until = time.monotonic() + 40  # the monitor's readers matched
while time.monotonic() < until and not all(p.get_subscription_count() and c.get_subscription_count()
                                           for p, _v, c in pubs):
    ex.spin_once(timeout_sec=0.05)
t0 = time.monotonic()
for k in range(ROUNDS):
    for pub, value, _c in pubs:
        pub.publish(Float64(data=value))
    while time.monotonic() < t0 + 0.1 * (k + 1):
        ex.spin_once(timeout_sec=0.01)
print("done", flush=True)
while rclpy.ok():
    ex.spin_once(timeout_sec=0.1)
""".replace("ROUNDS", str(ROUNDS))


def _heard(log: list[dict[str, Any]]) -> bool:
    """Every odom and every relay's answer to the last of them is in the monitor's log."""
    return all(sum(x.get("topic") == f"{r}/{t}" for x in log) >= ROUNDS
               for r in ("r1", "r2") for t in ("odom", "relay/cmd"))


def _run(tmp: Path, r2_odom: str) -> dict[str, Any]:
    py = ros2_python()  # skips, with the reason, without a ROS 2 Python
    ws = tmp / "ws"
    (ws / "contracts").mkdir(parents=True)
    (ws / "contracts/fleet.rcl").write_text(RCL)
    (ws / "contracts/plan.yaml").write_text(PLAN)
    env = ros2_env(tmp)
    nodes = monitor = None
    try:
        monitor = rclverify(["monitor", "-w", str(ws), "--live", "--ros2", "--status", "0", "--duration", "90",
                             "--horizon", "1", "--source", "rclpy", "--ros2-python", str(py),
                             "--evidence", str(tmp / "live.json")], env, tmp, tmp / "monitor.out")
        nodes = start_node(tmp, "fleet", NODES.replace('R2_ODOM = "odom"', f"R2_ODOM = {r2_odom!r}"), env)
        wait_for(tmp / "fleet.log", "done", 80)
        wait_logged(tmp / "monitor_live.jsonl", _heard, 30)  # the relays' last answers heard, whatever the load
        stop(monitor, signal.SIGINT)
        out = (tmp / "monitor.out").read_text()
        assert (tmp / "live.json").exists(), out + (tmp / "fleet.log").read_text()
        return {"out": out, "nodes": {n["node"]: n for n in json.loads((tmp / "live.json").read_text())["nodes"]}}
    finally:
        for p in (nodes, monitor):
            if p is not None:
                stop(p)


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, dict[str, Any]]]:
    yield {name: _run(tmp_path_factory.mktemp(name), odom) for name, odom in (("own", "odom"), ("slip", "/r1/odom"))}


def test_each_instance_is_heard_on_its_own_topics_and_green(runs: dict[str, Any]) -> None:
    run = runs["own"]
    assert set(run["nodes"]) == {"OdomSource_r1", "OdomSource_r2", "Relay_r1", "Relay_r2"}, run["out"]
    for name, node in run["nodes"].items():
        assert node["status"] == "discharged" and node["counts"]["satisfied"] >= 10, (name, node["counts"], run["out"])


def test_a_relay_wired_to_the_other_robot_is_red_at_its_instance_only(runs: dict[str, Any]) -> None:
    nodes = runs["slip"]["nodes"]
    assert nodes["Relay_r2"]["status"] == "failed" and nodes["Relay_r2"]["counts"]["violated"] >= 10, nodes["Relay_r2"]
    assert nodes["Relay_r2"]["first_violation"]["values"] == {"in.odom": "2.0", "out.cmd": "1.0"}
    for name in ("OdomSource_r1", "OdomSource_r2", "Relay_r1"):
        assert nodes[name]["status"] == "discharged", (name, nodes[name]["counts"])
