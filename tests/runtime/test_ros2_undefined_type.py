"""A contract type the workspace has no definition of, heard live through the
rclpy source (docs/ros2.md, "Types from the robot"): ``test_msgs/BasicTypes``
is in no interface file of the workspace and not among the standard types;
the rclpy source's ROS 2 Python describes it (rosidl's description, checked
against its hash), so the monitor reads its ``float32_value`` at its width
and judges it.  Control: the DDS source has no such Python and refuses the
type in one located line, exit 2."""
from __future__ import annotations

import json
import signal
from pathlib import Path

import pytest
from _procs import stop, wait_for, wait_logged
from _ros2 import rclverify, ros2_env, ros2_python, start_node

RCL = """\
node Basic {
  inputs( )
  outputs( v : REAL )
  topics( test_msgs/BasicTypes basic matches(out.v) )
  assume( TRUE )
  guarantee( out.v <= 0.5 )
}
"""
MAPPING = "topics:\n  basic: {fields: [float32_value]}\n"
SYSTEM = """\
import time
import rclpy
from rclpy.node import Node
from test_msgs.msg import BasicTypes

rclpy.init()
n = Node("basic")
pub = n.create_publisher(BasicTypes, "basic", 50)
print("ready", flush=True)
until = time.monotonic() + 40
while time.monotonic() < until and n.count_subscribers("/basic") < 1:
    rclpy.spin_once(n, timeout_sec=0.05)
time.sleep(1.0)
for k in range(20):
    pub.publish(BasicTypes(float32_value=[0.25, 0.75][k % 2]))
    time.sleep(0.03)
print("done", flush=True)
while True:
    rclpy.spin_once(n, timeout_sec=0.1)
"""


def _workspace(tmp: Path) -> Path:
    ws = tmp / "ws"
    (ws / "contracts").mkdir(parents=True)
    (ws / "contracts/b.rcl").write_text(RCL)
    (ws / "contracts/plan.yaml").write_text("contracts: [contracts/b.rcl]\n")
    (ws / "mapping.yaml").write_text(MAPPING)
    return ws


def test_a_type_the_workspace_lacks_is_read_as_the_ros2_python_describes_it(tmp_path: Path) -> None:
    py = ros2_python()
    ws = _workspace(tmp_path)
    env = ros2_env(tmp_path)
    system = start_node(tmp_path, "system", SYSTEM, env)
    monitor = None
    try:
        monitor = rclverify(["monitor", "-w", str(ws), "--live", "--ros2", "--mapping", "mapping.yaml", "--status",
                             "0", "--duration", "60", "--source", "rclpy", "--ros2-python", str(py),
                             "--log", str(tmp_path / "live.jsonl"), "--evidence", str(tmp_path / "live.json")],
                            env, tmp_path, tmp_path / "monitor.out")
        wait_for(tmp_path / "system.log", "done", 60)
        # the twenty messages heard before the monitor stops, however loaded the machine
        wait_logged(tmp_path / "live.jsonl", lambda log: sum(x.get("topic") == "basic" for x in log) >= 20, 30)
        stop(monitor, signal.SIGINT)
    finally:
        for p in (system, monitor):
            if p is not None:
                stop(p)
    out = (tmp_path / "monitor.out").read_text()
    assert "test_msgs/msg/BasicTypes: no definition in the workspace: read as the ROS 2 Python's rosidl" in out, out
    (node,) = json.loads((tmp_path / "live.json").read_text())["nodes"]
    assert node["counts"]["satisfied"] == 10 and node["counts"]["violated"] == 10, node["counts"]


def test_the_dds_source_says_what_to_give(tmp_path: Path) -> None:
    ros2_python()  # skips without ROS 2's Python, as the rclpy case does
    ws = _workspace(tmp_path)
    env = ros2_env(tmp_path)
    monitor = rclverify(["monitor", "-w", str(ws), "--live", "--ros2", "--mapping", "mapping.yaml", "--status", "0",
                         "--duration", "5", "--source", "dds"], env, tmp_path, tmp_path / "monitor.out")
    try:
        monitor.wait(60)
    finally:
        stop(monitor)
    out = (tmp_path / "monitor.out").read_text()
    assert monitor.returncode == 2, out
    assert "contracts/b.rcl:4:11: error: topic /basic (test_msgs/BasicTypes)" in out
    assert "give its definition as DIR/test_msgs/msg/BasicTypes.msg with --interfaces DIR" in out, out
    assert "Traceback" not in out

