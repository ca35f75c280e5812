"""THE SIMULATOR, to rebuild the run without ROS 2: the committed
``backends/monitors/traces/run/`` is made from a recording of real rclpy
nodes by ``rclverify monitor --live --ros2`` (``nodes/record_live.py``,
README.md), and this script overwrites it.

Record a run of the delivery robot's node logic (the functions of this
folder, one file per node) as a ROS 2 bag in MCAP storage (a rosbag2
directory, format version 9, written by rosbags' writer).

The nodes are driven by a scripted scenario on a simulated clock: each
node's callback runs the same function the property tests check and
publishes its outputs after that node's latency (a few milliseconds, the
figures measured on the robot's computer).  The numbers are what the
Python functions compute, in double arithmetic, as a ROS node would
publish them.  The service and the action are recorded as the monitor's
proxy sees them, one topic per part (``get_route/request`` and
``response``; ``deliver/goal``, ``feedback`` and ``result``), each part of
the ``.srv`` and ``.action`` files registered as a message type
(``delivery_msgs/msg/GetRoute_Request``: a bag's reader takes message
types only; docs/monitors.md).
``python3 nodes/record_run.py`` rewrites ``backends/monitors/traces/run/``;
the run is deterministic.
"""
from __future__ import annotations

import heapq
import shutil
import sys
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).parent))
from gnss_driver import gnss_driver  # noqa: E402
from locker_controller import locker_controller  # noqa: E402
from localiser import localiser  # noqa: E402
from mission_planner import mission_planner  # noqa: E402
from navigator import navigator  # noqa: E402
from obstacle_detector import obstacle_detector  # noqa: E402
from route_server import route_server  # noqa: E402
from speed_governor import speed_governor  # noqa: E402
from wheel_controller import WheelControllerNode  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
#: s: how long each node takes from receiving a message to publishing its answer
LATENCY = {"GnssDriver": 0.005, "Localiser": 0.010, "ObstacleDetector": 0.008, "MissionPlanner": 0.004,
           "Navigator": 0.020, "SpeedGovernor": 0.012, "WheelController": 0.025,
           # the service call: the Navigator's request, the RouteServer's answer
           "Navigator/get_route": 0.002, "RouteServer": 0.015, "LockerController": 0.030}
#: s: the WheelController's watchdog period, and its first tick
WATCHDOG, FIRST_TICK = 0.100, 0.013
#: (time s, topic, message): what the sensors and the operator send
SCENARIO: list[tuple[float, str, dict[str, Any]]] = [
    (0.000, "cog", {"data": 90.0}),
    (0.050, "scan", {"range": 12.0}),
    (0.100, "order", {"data": 42}),
    (0.500, "cog", {"data": 91.0}),
    (1.000, "scan", {"range": 3.0}),
    (1.000, "cog", {"data": 92.5}),
    (1.450, "scan", {"range": 0.25}),
    (2.000, "scan", {"range": 1.5}),
    (2.500, "scan", {"range": 5.0}),
    (2.500, "cog", {"data": 90.0}),
    (2.900, "arrived", {}),       # the Navigator's last waypoint reached (its own timer)
]
END = 3.0
#: topic -> its ROS type
TYPES = {"cog": "std_msgs/msg/Float64", "heading": "std_msgs/msg/Float64", "pose": "geometry_msgs/msg/Pose2D",
         "order": "std_msgs/msg/UInt32", "locker_dest": "std_msgs/msg/UInt32",
         "compartment": "std_msgs/msg/UInt8", "scan": "sensor_msgs/msg/Range", "clearance": "std_msgs/msg/Float64",
         "cmd_vel": "geometry_msgs/msg/Twist", "safe_cmd": "geometry_msgs/msg/Twist",
         "wheel_cmd": "std_msgs/msg/Float64",
         "get_route/request": "delivery_msgs/msg/GetRoute_Request",
         "get_route/response": "delivery_msgs/msg/GetRoute_Response",
         "deliver/goal": "delivery_msgs/msg/Deliver_SendGoal_Request",
         "deliver/result": "delivery_msgs/msg/Deliver_GetResult_Response",
         "deliver/feedback": "delivery_msgs/msg/Deliver_FeedbackMessage"}
#: The messages an action's parts travel in (ROS 2's action protocol): the goal, feedback and result
#: wrapped with the goal's id or the result's status.
ACTION_WRAPPERS = {"SendGoal_Request": "unique_identifier_msgs/UUID goal_id\n{pkg}/{stem}_Goal goal\n",
                   "FeedbackMessage": "unique_identifier_msgs/UUID goal_id\n{pkg}/{stem}_Feedback feedback\n",
                   "GetResult_Response": "int8 status\n{pkg}/{stem}_Result result\n"}


class Robot:
    """The nine nodes' callbacks: each keeps the latest value of its inputs
    (as a ROS node keeps the last message of each subscription) and calls its
    logic function."""

    def __init__(self) -> None:
        self.queue: list[tuple[float, int, str, dict[str, Any]]] = []
        self.seq = 0
        self.log: list[tuple[float, str, dict[str, Any]]] = []
        self.nav: dict[str, Any] = {"dest_id": None, "yaw": None, "clearance": None, "n_waypoints": None}
        self.gov: dict[str, Any] = {"clearance": None, "cmd_vel": None}
        self.mission: dict[str, Any] = {"order_id": None, "remaining": 0.0, "delivered_id": 0}
        self.wheels = WheelControllerNode()

    def publish(self, node: str, now: float, topic: str, msg: dict[str, Any]) -> None:
        self.seq += 1
        heapq.heappush(self.queue, (round(now + LATENCY[node], 6), self.seq, topic, msg))

    def deliver(self, t: float, topic: str, msg: dict[str, Any]) -> None:
        if topic not in ("watchdog", "arrived"):
            self.log.append((t, topic, msg))
        handler = getattr(self, "on_" + topic.replace("/", "_"), None)
        if handler is not None:
            handler(t, msg)

    # -- callbacks -------------------------------------------------------------
    def on_cog(self, t: float, msg: dict[str, Any]) -> None:
        self.publish("GnssDriver", t, "heading", {"data": gnss_driver(msg["data"])["heading"]})

    def on_heading(self, t: float, msg: dict[str, Any]) -> None:
        self.publish("Localiser", t, "pose", {"x": 0.0, "y": 0.0, "theta": localiser(msg["data"])["yaw"]})

    def on_scan(self, t: float, msg: dict[str, Any]) -> None:
        self.publish("ObstacleDetector", t, "clearance", {"data": obstacle_detector(msg["range"])["clearance"]})

    def on_order(self, t: float, msg: dict[str, Any]) -> None:
        self.mission["order_id"] = msg["data"]
        out = mission_planner(**self.mission)
        self.publish("MissionPlanner", t, "deliver/goal", {"goal": {"dest_id": out["dest_id"]}})
        self.publish("MissionPlanner", t, "locker_dest", {"data": out["dest_id"]})

    def on_locker_dest(self, t: float, msg: dict[str, Any]) -> None:
        self.publish("LockerController", t, "compartment", {"data": locker_controller(msg["data"])["compartment"]})

    def on_deliver_goal(self, t: float, msg: dict[str, Any]) -> None:
        # a new goal: ask the route server for its route first, drive with the answer
        self.nav["dest_id"] = msg["goal"]["dest_id"]
        self.publish("Navigator/get_route", t, "get_route/request", {"route_dest": out_route(self.nav)})

    def on_get_route_request(self, t: float, msg: dict[str, Any]) -> None:
        out = route_server(route_dest=msg["route_dest"])
        self.publish("RouteServer", t, "get_route/response", {"n_waypoints": out["n_waypoints"]})

    def on_get_route_response(self, t: float, msg: dict[str, Any]) -> None:
        self.nav["n_waypoints"] = msg["n_waypoints"]
        self._navigate(t, feedback=True)

    def on_pose(self, t: float, msg: dict[str, Any]) -> None:
        self.nav["yaw"] = msg["theta"]
        self._navigate(t)

    def on_clearance(self, t: float, msg: dict[str, Any]) -> None:
        self.nav["clearance"] = msg["data"]
        self._navigate(t)
        self.gov["clearance"] = msg["data"]
        self._govern(t)

    def _navigate(self, t: float, feedback: bool = False) -> None:
        if None in self.nav.values():
            return
        out = navigator(**self.nav)
        self.publish("Navigator", t, "cmd_vel", twist(out["cmd_vel"]))
        if feedback:
            self.publish("Navigator", t, "deliver/feedback", {"feedback": {"remaining": out["remaining"]}})

    def on_arrived(self, t: float, msg: dict[str, Any]) -> None:
        out = navigator(**self.nav)
        self.publish("Navigator", t, "deliver/result", {"status": 4, "result": {"delivered_id": out["delivered_id"]}})

    def on_deliver_result(self, t: float, msg: dict[str, Any]) -> None:
        self.mission["delivered_id"] = msg["result"]["delivered_id"]

    def on_deliver_feedback(self, t: float, msg: dict[str, Any]) -> None:
        self.mission["remaining"] = msg["feedback"]["remaining"]

    def on_cmd_vel(self, t: float, msg: dict[str, Any]) -> None:
        self.gov["cmd_vel"] = msg["linear"]["x"]
        self._govern(t)

    def _govern(self, t: float) -> None:
        if None in self.gov.values():
            return
        self.publish("SpeedGovernor", t, "safe_cmd", twist(speed_governor(**self.gov)["safe_cmd"]))

    def on_safe_cmd(self, t: float, msg: dict[str, Any]) -> None:
        self.publish("WheelController", t, "wheel_cmd", {"data": self.wheels.on_safe_cmd(msg["linear"]["x"])})

    def on_watchdog(self, t: float, msg: dict[str, Any]) -> None:
        cmd = self.wheels.on_watchdog()
        if cmd is not None:
            self.log.append((t, "wheel_cmd", {"data": cmd}))
        if t + WATCHDOG <= END:
            heapq.heappush(self.queue, (round(t + WATCHDOG, 6), -1, "watchdog", {}))

    def run(self) -> list[tuple[float, str, dict[str, Any]]]:
        for k, (t, topic, msg) in enumerate(SCENARIO):
            heapq.heappush(self.queue, (t, -1000 + k, topic, msg))
        heapq.heappush(self.queue, (FIRST_TICK, -1, "watchdog", {}))
        while self.queue and self.queue[0][0] <= END:
            t, _, topic, msg = heapq.heappop(self.queue)
            self.deliver(t, topic, msg)
        return self.log


def out_route(nav: dict[str, Any]) -> int:
    """The stop the Navigator asks the route of: its logic's ``route_dest`` (the
    other inputs do not matter to it; before they have a value, zeros)."""
    return int(navigator(**{k: (0 if v is None else v) for k, v in nav.items()})["route_dest"])


def twist(vx: float) -> dict[str, Any]:
    """A geometry_msgs/Twist (nested messages)."""
    return {"linear": {"x": vx, "y": 0.0, "z": 0.0}, "angular": {"x": 0.0, "y": 0.0, "z": 0.0}}


def _store() -> Any:
    """rosbags' store of ROS 2's standard types, the workspace's ``.msg`` files
    (``interfaces/sensor_msgs/msg/Range.msg``: Kilted's, with ``variance``, as
    the real nodes publish it), plus the parts of the
    workspace's ``.srv`` and ``.action`` files as message types
    ``<pkg>/msg/<T>_Request``, ``<pkg>/msg/<T>_Goal``, ..."""
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore
    own: dict[str, Any] = {}
    for f in sorted((ROOT / "interfaces").glob("*/msg/*.msg")):  # sensor_msgs/Range as Kilted defines it
        own.update(get_types_from_msg(f.read_text(encoding="utf-8"), f"{f.parent.parent.name}/msg/{f.stem}"))
    standard = get_typestore(Stores.ROS2_HUMBLE).fielddefs
    store = get_typestore(Stores.EMPTY)  # the workspace's definitions replace Humble's
    store.register({**{k: v for k, v in standard.items() if k not in own}, **own})
    for f in sorted((ROOT / "interfaces").rglob("*")):
        parts = {".srv": ("Request", "Response"), ".action": ("Goal", "Result", "Feedback")}.get(f.suffix)
        if parts is None:
            continue
        sections = f.read_text(encoding="utf-8").split("---")
        for part, text in zip(parts, sections):
            store.register(get_types_from_msg(text, f"{f.parent.parent.name}/msg/{f.stem}_{part}"))
        if f.suffix == ".action":
            for part, text in ACTION_WRAPPERS.items():
                pkg = f.parent.parent.name
                store.register(get_types_from_msg(text.format(pkg=pkg, stem=f.stem), f"{pkg}/msg/{f.stem}_{part}"))
    return store


def _message(store: Any, typename: str, fields: dict[str, Any]) -> Any:
    """The message object of ``typename`` with ``fields`` (nested dicts as
    nested messages, a header's stamp the message's time)."""
    cls = store.types[typename]
    args: dict[str, Any] = {}
    for name, ftype in store.fielddefs[typename][1]:
        if name in fields and not isinstance(fields[name], dict):
            args[name] = fields[name]
        elif ftype[0] == 2:  # a nested message
            args[name] = _message(store, ftype[1], fields.get(name, {}))
        elif ftype[0] == 3:  # a fixed array (a goal id's 16 bytes): zeros
            import numpy
            args[name] = numpy.zeros(ftype[1][1], dtype=numpy.uint8)
        else:  # a field the scenario leaves out: its zero
            base = ftype[1][0] if isinstance(ftype[1], tuple) else ftype[1]
            args[name] = "" if base == "string" else 0.0 if base.startswith("float") else 0
    return cls(**args)


def write_bag(path: Path, log: list[tuple[float, str, dict[str, Any]]]) -> None:
    """The run as a ROS 2 bag directory ``path`` in MCAP storage (replaced)."""
    from rosbags.rosbag2 import StoragePlugin, Writer
    store = _store()
    if path.exists():
        shutil.rmtree(path)
    with Writer(path, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        conns: dict[str, Any] = {}
        for t, topic, fields in log:
            if topic not in conns:
                conns[topic] = writer.add_connection("/" + topic, TYPES[topic], typestore=store)
            if topic == "scan":
                fields = {**fields, "max_range": 40.0, "field_of_view": 0.5}
            data = store.serialize_cdr(_message(store, TYPES[topic], fields), TYPES[topic])
            writer.write(conns[topic], int(round(t * 1e6)) * 1000, data)


def main() -> None:
    out = ROOT / "backends" / "monitors" / "traces" / "run"
    write_bag(out, Robot().run())
    print(out)


if __name__ == "__main__":
    main()
