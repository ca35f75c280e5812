"""Declarations judged live (issue 64), with real rclpy nodes on Fast DDS
(tests/_ros2.py).

One ROS 2 system runs once for the module: ``base`` publishes its initial
pose 0 when it starts, then answers every ``/target`` with the same value
on ``/pose``; ``lazy`` answers only every third ``/lazy_target`` on
``/lazy_pose``; ``driver`` sends six targets to each. One live monitor
(``rclverify monitor --live --ros2``) watches both nodes. Its evidence
record's ``declarations`` say Base's initial value, progress and period
held and Lazy's progress ``within 1 steps`` is false (naming the inputs),
and its exit code is 1; its log, checked offline by ``rclverify monitor``,
gives the same rows (live = offline).
"""
from __future__ import annotations

import json
import signal
from pathlib import Path
from typing import Any, Iterator

import pytest
from _procs import stop, wait_for, wait_logged
from _ros2 import live_workspace, rclverify, ros2_env, ros2_python, start_node

from rclverify.cli.commands import main

RCL = """\
node Base {
  inputs( target : INTEGER )
  outputs( pose : INTEGER )
  topics( std_msgs/Int64 target matches(in.target), std_msgs/Int64 pose matches(out.pose) )
  assume( 0 <= in.target and in.target <= 10 )
  guarantee( out.pose == in.target )
  initially( out.pose == 0 )
  progress( within 1 steps )
  periodic( out.pose, 2 s )
}

node Lazy {
  inputs( target : INTEGER )
  outputs( pose : INTEGER )
  topics( std_msgs/Int64 lazy_target matches(in.target), std_msgs/Int64 lazy_pose matches(out.pose) )
  assume( 0 <= in.target and in.target <= 10 )
  guarantee( out.pose == in.target )
  progress( within 1 steps )
}
"""
MAPPING = "topics:\n  pose: {fields: [data], state: true}\n  lazy_pose: {fields: [data], state: true}\n"

SYSTEM = """\
import time
import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from std_msgs.msg import Int64

rclpy.init()
base, lazy, driver = Node("base"), Node("lazy"), Node("driver")
pose = base.create_publisher(Int64, "pose", 10)
lazy_pose = lazy.create_publisher(Int64, "lazy_pose", 10)
answered = []
base.create_subscription(Int64, "target", lambda m: (pose.publish(Int64(data=m.data)), answered.append(m.data)), 10)
seen = []

def lazy_answer(m):
    seen.append(m.data)
    if len(seen) % 3 == 0:  # two targets in a row left unanswered
        lazy_pose.publish(Int64(data=m.data))

lazy.create_subscription(Int64, "lazy_target", lazy_answer, 10)
target = driver.create_publisher(Int64, "target", 10)
lazy_target = driver.create_publisher(Int64, "lazy_target", 10)
ex = SingleThreadedExecutor()
for n in (base, lazy, driver):
    ex.add_node(n)
print("ready", flush=True)
until = time.monotonic() + 20
# the monitor reads every topic; base and lazy read the targets as well
while time.monotonic() < until and any(p.get_subscription_count() < n for p, n in ((pose, 1), (target, 2), (lazy_target, 2))):
    ex.spin_once(timeout_sec=0.05)
time.sleep(0.3)
pose.publish(Int64(data=0))  # the initial pose, before any target
for k in range(1, 7):
    end = time.monotonic() + 0.15
    while time.monotonic() < end:
        ex.spin_once(timeout_sec=0.01)
    target.publish(Int64(data=k))
    lazy_target.publish(Int64(data=k))
    # the next target only once base answered this one and lazy received it: published in that order,
    # judged in that order at their source times, however late a loaded machine delivers them
    end = time.monotonic() + 10
    while time.monotonic() < end and (len(answered) < k or len(seen) < k):
        ex.spin_once(timeout_sec=0.01)
end = time.monotonic() + 0.3
while time.monotonic() < end:
    ex.spin_once(timeout_sec=0.01)
print("done", flush=True)
while True:
    ex.spin_once(timeout_sec=0.1)
"""


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, Any]]:
    ros2_python()  # skips, with the reason, without a ROS 2 Python
    tmp = tmp_path_factory.mktemp("declarations")
    ws = live_workspace(tmp, RCL, MAPPING)
    env = ros2_env(tmp)
    monitor = system = None
    try:
        # a 300 ms lateness bound: targets and answers are judged at their source times (with none, in the
        # order heard, and a loaded machine may deliver an answer after the next target)
        monitor = rclverify(
            ["monitor", "-w", str(ws), "--live", "--ros2", "--mapping", "mapping.yaml", "--horizon", "1.0",
             "--reorder-window", "0.3", "--status", "0", "--duration", "60", "--log", str(tmp / "live.jsonl"),
             "--evidence", str(tmp / "live.json")], env, tmp, tmp / "monitor.out")
        wait_for(tmp / "monitor.out", "monitoring", 30)
        system = start_node(tmp, "system", SYSTEM, env)
        wait_for(tmp / "system.log", "done", 40)
        # every message heard and released past the watermark: the initial pose and six answers of base, two
        # of lazy, the twelve targets
        want = {"pose": 7, "lazy_pose": 2, "target": 6, "lazy_target": 6}
        wait_logged(tmp / "live.jsonl", lambda log: all(sum(x.get("topic") == t for x in log) >= n
                                                        for t, n in want.items()), 30)
        stop(monitor, signal.SIGINT)
        yield {"tmp": tmp, "ws": ws, "code": monitor.returncode, "out": (tmp / "monitor.out").read_text(),
               "record": json.loads((tmp / "live.json").read_text())}
    finally:
        if system is not None:
            stop(system)
        if monitor is not None:
            stop(monitor)


def _rows(entries: list[dict[str, Any]], node: str) -> dict[str, str]:
    return {r["declaration"]: r["verdict"] for r in next(e for e in entries if e["node"] == node)["declarations"]}


def test_the_live_run_judges_the_declarations_as_the_offline_check(run: dict[str, Any],
                                                                  capsys: pytest.CaptureFixture[str]) -> None:
    rec = run["record"]
    assert _rows(rec["declarations"], "Base") == {"initially 1": "true", "progress": "true",
                                                  "periodic out.pose": "true"}, (rec["declarations"], run["out"])
    lazy = next(e for e in rec["declarations"] if e["node"] == "Lazy")
    assert lazy["status"] == "failed" and "2 accepted steps in a row unanswered" in lazy["explanation"], lazy
    assert run["code"] == 1 and "declarations: Lazy: failed" in run["out"]
    capsys.readouterr()
    rc = main(["monitor", "-w", str(run["ws"]), "--mapping", "mapping.yaml", "--horizon", "1.0", "--json",
               str(run["tmp"] / "live.jsonl")])
    report = json.loads(capsys.readouterr().out)
    offline = [e for e in report if "declarations" in e]
    assert rc == 1
    for node in ("Base", "Lazy"):
        assert _rows(offline, node) == _rows(rec["declarations"], node)
