"""THE SIMULATOR, to rebuild the run without ROS 2: the committed
``backends/monitors/traces/run.jsonl`` is made from a recording of real rclpy
nodes by ``rclverify monitor --live --ros2`` (``nodes/record_live.py``,
README.md), and this script overwrites it.

Record a run of the warehouse robot's node logic (the functions of this
folder, one file per node) in the
form of the monitor's logs (ROSMonitoring JSON lines; services as
``<svc>/request`` and ``<svc>/response``, the action as actionlib's
``navigate/goal``, ``feedback`` and ``result``; docs/monitors.md).

The nodes are driven by a scripted scenario on a simulated clock: each
node's callback runs the same function the property tests check and
publishes its outputs after that node's latency (a few milliseconds, the
figures measured on the robot's computer).  The numbers are what the
Python functions compute, in double arithmetic, as a ROS node would
publish them.  ``python3 nodes/record_run.py`` rewrites
``backends/monitors/traces/run.jsonl``; the run is deterministic.
"""
from __future__ import annotations

import heapq
import json
import sys
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).parent))
from base import base  # noqa: E402
from battery_monitor import battery_monitor  # noqa: E402
from controller import controller  # noqa: E402
from lidar_driver import lidar_driver  # noqa: E402
from localiser import localiser  # noqa: E402
from mission_manager import mission_manager  # noqa: E402
from planner import planner  # noqa: E402

#: s: how long each node takes from receiving a message to publishing its answer
LATENCY = {"LidarDriver": 0.008, "Localiser": 0.010, "BatteryMonitor": 0.005, "MissionManager": 0.004,
           "Planner": 0.020, "Controller": 0.015, "Base": 0.040,
           # the service calls: the Controller's request, the Base's answer
           "Controller/get_limits": 0.002, "Base/get_limits": 0.005}
#: (time s, topic, message): what the environment and the operator send
SCENARIO: list[tuple[float, str, dict[str, Any]]] = [
    (0.000, "battery_charge", {"data": 80.0}),
    (0.020, "marker", {"data": 0.0}),
    (0.100, "scan", {"range": 5.0}),
    (0.200, "order", {"data": 3.0}),
    (0.500, "scan", {"range": 1.2}),
    (1.000, "marker", {"data": 1.0}),
    (1.500, "battery_charge", {"data": 50.0}),
    (2.000, "marker", {"data": 2.0}),
    (2.300, "scan", {"range": 0.3}),
    (2.600, "scan", {"range": 2.5}),
    (3.000, "marker", {"data": 3.0}),
    (3.500, "battery_charge", {"data": 20.0}),
    (4.000, "battery_charge", {"data": 15.0}),
]
END = 4.5


class Robot:
    """The seven nodes' callbacks: each keeps the latest value of its inputs
    (as a ROS node keeps the last message of each subscription) and calls its
    logic function."""

    def __init__(self) -> None:
        self.queue: list[tuple[float, int, str, dict[str, Any]]] = []
        self.seq = 0
        self.log: list[dict[str, Any]] = []
        self.ctl: dict[str, Any] = {"obstacle": None, "speed_cmd": None, "max_speed": None}
        self.plan: dict[str, Any] = {"goal_x": None, "pose_x": None}
        self.mission: dict[str, Any] = {"order_x": None, "remaining": 0.0, "reached_x": 0.0, "battery_low": False}

    def publish(self, node: str, now: float, topic: str, msg: dict[str, Any]) -> None:
        self.seq += 1
        heapq.heappush(self.queue, (round(now + LATENCY[node], 6), self.seq, topic, msg))

    def deliver(self, t: float, topic: str, msg: dict[str, Any]) -> None:
        self.log.append({"topic": topic, "time": t, **msg})
        handler = getattr(self, "on_" + topic.replace("/", "_"), None)
        if handler is not None:
            handler(t, msg)

    # -- callbacks -------------------------------------------------------------
    def on_scan(self, t: float, msg: dict[str, Any]) -> None:
        self.publish("LidarDriver", t, "obstacle", {"data": lidar_driver(msg["range"])["obstacle"]})

    def on_marker(self, t: float, msg: dict[str, Any]) -> None:
        self.publish("Localiser", t, "pose", {"data": localiser(msg["data"])["pose_x"]})

    def on_battery_charge(self, t: float, msg: dict[str, Any]) -> None:
        self.publish("BatteryMonitor", t, "battery_low", {"data": battery_monitor(msg["data"])["battery_low"]})

    def on_battery_low(self, t: float, msg: dict[str, Any]) -> None:
        self.mission["battery_low"] = msg["data"]
        self._mission(t, goal=False)

    def on_order(self, t: float, msg: dict[str, Any]) -> None:
        self.mission["order_x"] = msg["data"]
        self._mission(t, goal=True)

    def _mission(self, t: float, goal: bool) -> None:
        if self.mission["order_x"] is None:
            self.mission["order_x"] = 0.0
        out = mission_manager(**self.mission)
        if goal:
            self.publish("MissionManager", t, "navigate/goal", {"goal": {"goal_x": out["goal_x"]}})
        self.publish("MissionManager", t, "dock", {"data": out["dock"]})

    def on_navigate_goal(self, t: float, msg: dict[str, Any]) -> None:
        self.plan["goal_x"] = msg["goal"]["goal_x"]
        self._plan(t)

    def on_pose(self, t: float, msg: dict[str, Any]) -> None:
        self.plan["pose_x"] = msg["data"]
        self._plan(t)

    def _plan(self, t: float) -> None:
        if self.plan["goal_x"] is None or self.plan["pose_x"] is None:
            return
        out = planner(**self.plan)
        self.publish("Planner", t, "speed_cmd", {"data": out["speed_cmd"]})
        self.publish("Planner", t, "navigate/feedback", {"feedback": {"remaining": out["remaining"]}})
        if out["remaining"] == 0.0:
            self.publish("Planner", t, "navigate/result", {"result": {"reached_x": out["reached_x"]}})

    def on_navigate_feedback(self, t: float, msg: dict[str, Any]) -> None:
        self.mission["remaining"] = msg["feedback"]["remaining"]

    def on_navigate_result(self, t: float, msg: dict[str, Any]) -> None:
        self.mission["reached_x"] = msg["result"]["reached_x"]

    def on_obstacle(self, t: float, msg: dict[str, Any]) -> None:
        self.ctl["obstacle"] = msg["data"]
        self._control(t)

    def on_speed_cmd(self, t: float, msg: dict[str, Any]) -> None:
        # a new speed command: ask the base for its limit first, follow the command with the answer
        self.ctl["speed_cmd"] = msg["data"]
        query = controller(0.0, 0.0, 1.0)["query"]
        self.publish("Controller/get_limits", t, "get_limits/request", {"query": query})

    def on_get_limits_request(self, t: float, msg: dict[str, Any]) -> None:
        out = base(cmd_vel=0.0, query=msg["query"])
        self.publish("Base/get_limits", t, "get_limits/response", {"max_speed": out["max_speed"]})

    def on_get_limits_response(self, t: float, msg: dict[str, Any]) -> None:
        self.ctl["max_speed"] = msg["max_speed"]
        self._control(t)

    def _control(self, t: float) -> None:
        if None in self.ctl.values():
            return
        out = controller(**self.ctl)
        self.publish("Controller", t, "cmd_vel", twist(out["cmd_vel"]))

    def on_cmd_vel(self, t: float, msg: dict[str, Any]) -> None:
        out = base(cmd_vel=msg["linear"]["x"], query=False)
        self.publish("Base", t, "odom", twist(out["wheel_speed"]))

    def run(self) -> list[dict[str, Any]]:
        for k, (t, topic, msg) in enumerate(SCENARIO):
            heapq.heappush(self.queue, (t, -1000 + k, topic, msg))
        while self.queue and self.queue[0][0] <= END:
            t, _, topic, msg = heapq.heappop(self.queue)
            self.deliver(t, topic, msg)
        return self.log


def twist(vx: float) -> dict[str, Any]:
    """A geometry_msgs/Twist as the monitor logs it (nested messages as objects)."""
    return {"linear": {"x": vx, "y": 0.0, "z": 0.0}, "angular": {"x": 0.0, "y": 0.0, "z": 0.0}}


def main() -> None:
    out = Path(__file__).resolve().parent.parent / "backends" / "monitors" / "traces" / "run.jsonl"
    out.write_text("".join(json.dumps(e) + "\n" for e in Robot().run()), encoding="utf-8")
    print(out)


if __name__ == "__main__":
    main()
