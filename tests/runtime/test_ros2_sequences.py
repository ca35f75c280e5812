"""A sequence of messages judged live (docs/monitors.md, "Sequences of messages"), with a real
rclpy node on Fast DDS (tests/_ros2.py): ``fence`` publishes four
``geometry_msgs/PoseArray`` areas on ``/area`` and answers each on ``/inside``
(whether every pose lies at x <= 2.5 and y >= 0), the fourth answer wrong.
``rclverify monitor --live --ros2`` reads ``poses[*].position.x`` and
``poses[*].position.y`` into a ``seq((REAL, REAL))``: three answers
satisfied, one violated, its value printed as RCL's sequence of tuples; the
live log judged offline gives the same counts (live = offline).
"""
from __future__ import annotations

import json
import signal
from pathlib import Path
from typing import Any, Iterator

import pytest
from _procs import stop, wait_for, wait_logged
from _ros2 import live_workspace, rclverify, ros2_env, ros2_python, start_node
from test_sequences_of_messages import INSIDE, INSIDE_MAPPING

from rclverify.cli.commands import main

RCL = INSIDE
#: an answer's horizon (s): the node answers 50 ms after each area, and a loaded machine may add a few hundred
HORIZON = "1.0"
MAPPING = "topics:\n" + INSIDE_MAPPING

SYSTEM = """\
import time
import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from geometry_msgs.msg import Pose, PoseArray
from std_msgs.msg import Bool

AREAS = [[(1.0, 0.5), (2.5, 0.0)], [], [(2.6, 1.0)], [(0.0, -0.5), (1.0, 1.0)]]
ANSWERS = [True, True, False, True]  # the last is wrong: y = -0.5 is outside
rclpy.init()
node = Node("fence")
area = node.create_publisher(PoseArray, "area", 10)
inside = node.create_publisher(Bool, "inside", 10)
ex = SingleThreadedExecutor()
ex.add_node(node)
print("ready", flush=True)
until = time.monotonic() + 20
while time.monotonic() < until and min(p.get_subscription_count() for p in (area, inside)) < 1:
    ex.spin_once(timeout_sec=0.05)
time.sleep(0.3)
for pts, answer in zip(AREAS, ANSWERS):
    msg = PoseArray()
    msg.header.frame_id = "map"
    for x, y in pts:
        p = Pose()
        p.position.x, p.position.y = x, y
        msg.poses.append(p)
    area.publish(msg)
    time.sleep(0.05)
    inside.publish(Bool(data=answer))
    time.sleep(0.25)
print("done", flush=True)
while True:
    ex.spin_once(timeout_sec=0.1)
"""


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, Any]]:
    ros2_python()  # skips, with the reason, without a ROS 2 Python
    tmp = tmp_path_factory.mktemp("sequences")
    ws = live_workspace(tmp, RCL, MAPPING)
    env = ros2_env(tmp)
    monitor = system = None
    try:
        # a 300 ms lateness bound: each area and its answer are judged at their source times, in the order
        # published (with none, in the order heard: a loaded machine may deliver an /inside before its /area)
        monitor = rclverify(
            ["monitor", "-w", str(ws), "--live", "--ros2", "--mapping", "mapping.yaml", "--horizon", HORIZON,
             "--reorder-window", "0.3", "--status", "0", "--duration", "40", "--log", str(tmp / "live.jsonl"),
             "--evidence", str(tmp / "live.json")], env, tmp, tmp / "monitor.out")
        wait_for(tmp / "monitor.out", "monitoring", 30)
        system = start_node(tmp, "system", SYSTEM, env)
        wait_for(tmp / "system.log", "done", 30)
        # the four answers judged (the last once its answer passed the watermark), however loaded the machine
        wait_logged(tmp / "live.jsonl", lambda log: sum(x.get("topic") == "rclverify/verdict" and "kind" not in x
                                                        for x in log) >= 4, 30)
        stop(monitor, signal.SIGINT)
        yield {"tmp": tmp, "ws": ws, "code": monitor.returncode, "out": (tmp / "monitor.out").read_text(),
               "record": json.loads((tmp / "live.json").read_text())}
    finally:
        if system is not None:
            stop(system)
        if monitor is not None:
            stop(monitor)


def test_live_pose_arrays_are_judged_as_sequences_of_tuples(run: dict[str, Any],
                                                            capsys: pytest.CaptureFixture[str]) -> None:
    live = next(n for n in run["record"]["nodes"] if n["node"] == "Inside")
    assert run["code"] == 1, run["out"]
    assert live["counts"]["satisfied"] == 3 and live["counts"]["violated"] == 1, live["counts"]
    assert live["first_violation"]["values"]["in.pts"] == "<(0.0, -0.5), (1.0, 1.0)>", live["first_violation"]
    capsys.readouterr()
    code = main(["monitor", "-w", str(run["ws"]), "--mapping", "mapping.yaml", "--horizon", HORIZON, "--json",
                 str(run["tmp"] / "live.jsonl")])
    offline = json.loads(capsys.readouterr().out)
    counts = next(r for r in offline if r["node"] == "Inside")["counts"]
    assert code == 1 and counts["satisfied"] == 3 and counts["violated"] == 1, counts
