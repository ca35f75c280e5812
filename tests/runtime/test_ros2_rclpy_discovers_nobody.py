"""A run through the rclpy source that discovers nobody says so in one line (docs/ros2.md, "A run that
discovers nobody"; runtime/dds/nobody.py).  The DDS source's case, a loopback Cyclone DDS configuration
in a domain where no one runs, is tests/runtime/test_live_stops.py's.

The monitor listens through the rclpy source (its agent in the ROS 2 Python, Fast DDS) in a domain of
its own for 1.5 s: nothing is heard, each item is ``nothing heard``, the one warning line names the
watched topics, the middleware and what to check (the domain, the discovery range, the middleware's own
configuration: the source cannot count DDS participants, so the line says nothing of them), and the run
exits 0, 1 under ``--strict``, as a run that heard nothing does.  The control: the same monitor beside a
real rclpy publisher of the topic hears it, judges it and says nothing of discovery.
"""
from __future__ import annotations

import json
from pathlib import Path

import pytest
from _procs import stop, wait_logged
from _ros2 import live_workspace, rclverify, ros2_env, ros2_python, start_node

pytestmark = [pytest.mark.live, pytest.mark.slow]

RCL = """\
node Level {
  inputs( x : REAL )
  outputs( )
  topics( std_msgs/Float32 level matches(in.x) )
  assume( TRUE )
  guarantee( in.x <= 0.5 )
}
"""

PUBLISHER = """\
import time
import rclpy
from rclpy.node import Node
from std_msgs.msg import Float32

rclpy.init()
n = Node("level")
pub = n.create_publisher(Float32, "level", 10)
print("ready", flush=True)
while True:
    pub.publish(Float32(data=0.25))
    rclpy.spin_once(n, timeout_sec=0.05)
"""


def _monitor(tmp: Path, strict: bool, duration: str = "1.5") -> tuple[int, str, dict[str, object]]:
    ws = tmp / "ws"
    if not ws.exists():
        live_workspace(tmp, RCL)
    env = ros2_env(tmp)  # a domain of its own
    out = tmp / f"monitor{strict}.out"
    args = ["monitor", "-w", str(ws), "--live", "--ros2", "--status", "0", "--source", "rclpy",
            "--ros2-python", str(ros2_python()), "--log", str(tmp / f"live{strict}.jsonl"),
            "--evidence", str(tmp / f"live{strict}.json"), "--duration", duration] + (["--strict"] if strict else [])
    monitor = rclverify(args, env, tmp, out)
    try:
        code = monitor.wait(120)
    finally:
        stop(monitor)
    return code, out.read_text(), json.loads((tmp / f"live{strict}.json").read_text())


@pytest.mark.parametrize("strict", [False, True], ids=["plain", "strict"])
def test_a_run_through_rclpy_that_discovers_nobody_says_so(tmp_path: Path, strict: bool) -> None:
    code, text, record = _monitor(tmp_path, strict)
    lines = [line for line in text.splitlines() if "no publisher was discovered" in line]
    assert code == (1 if strict else 0) and len(lines) == 1, text
    assert "on any of the 1 watched topic(s)" in lines[0] and "rmw_fastrtps_cpp" in lines[0], lines[0]
    assert "ROS_DOMAIN_ID" in lines[0] and "the middleware's own configuration" in lines[0], lines[0]
    assert "DDS participant" not in lines[0], lines[0]  # the rclpy source cannot count them
    assert "not judged: topic /level (Level): nothing heard" in text, text
    assert lines[0] in record["warnings"], record["warnings"]


def test_control_a_run_that_hears_its_publisher_says_nothing_of_discovery(tmp_path: Path) -> None:
    live_workspace(tmp_path, RCL)
    env = ros2_env(tmp_path)
    publisher = start_node(tmp_path, "publisher", PUBLISHER, env)
    try:
        out = tmp_path / "monitor.out"
        monitor = rclverify(["monitor", "-w", str(tmp_path / "ws"), "--live", "--ros2", "--status", "0", "--source",
                             "rclpy", "--ros2-python", str(ros2_python()), "--log", str(tmp_path / "live.jsonl"),
                             "--evidence", str(tmp_path / "live.json"), "--duration", "60"], env, tmp_path, out)
        try:
            wait_logged(tmp_path / "live.jsonl", lambda log: sum(x.get("topic") == "level" for x in log) >= 5, 60)
        finally:
            stop(monitor)
    finally:
        stop(publisher)
    text = out.read_text()
    assert "no publisher was discovered" not in text, text
    record = json.loads((tmp_path / "live.json").read_text())
    assert record["source"] == "rclpy" and not [w for w in record["warnings"] if "discovered" in w], record
