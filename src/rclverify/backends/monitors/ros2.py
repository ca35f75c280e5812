"""ROS 2 (rclpy) layer of the live monitor: as thin as possible over the shared engine.

Everything that decides a verdict, writes the log or the evidence is
:class:`~.live.LiveRun`, fed by the same engine thread as ROS 1
(:class:`~.worker.EngineWorker`: callbacks only queue, one thread decodes,
checks, publishes and runs the timer, whose clock never passes a queued
message; tested with ROS 1 and without middleware).  This module only
subscribes, stamps messages with the node's clock and publishes:

* every verdict as ``std_msgs/msg/String`` JSON on the verdict topic;
* each node's latest verdict on ``<prefix>/<Node>/last_verdict`` with
  transient-local durability (ROS 2's latching: a late subscriber gets it);
* message classes from the installation (``rosidl_runtime_py.utilities.get_message``),
  converted with ``message_to_ordereddict``.  The workspace's own ``.msg``
  files must be built into a ROS 2 interface package first (``rosidl``
  cannot generate at run time, unlike ROS 1's genpy).

rclpy cannot be installed on the machines this project is developed and
tested on (no ROS 2 Debian packages for them), so this module is not
exercised by the test suite: docs/monitors.md says so.
"""
from __future__ import annotations

import json
import threading
import time as _time
from typing import Any, Callable

from ...evidence.store import atomic_write_text
from ...rcl.types import Checked, CheckedNode
from .live import LiveRun, stop_and_record
from .worker import EngineWorker


class Ros2Unavailable(Exception):
    """rclpy (or a message type) cannot be imported here; ``str`` says why."""


def run_ros2(run_factory: Callable[..., LiveRun], checked: Checked, nodes: list[CheckedNode], *,
             verdict_topic: str, last_prefix: str, node_name: str, duration: float | None, tick_s: float,
             status_s: float, stop: threading.Event, out: Callable[[str], None],
             evidence: Any = None) -> dict[str, Any]:
    """Run live monitoring on ROS 2 until ``stop`` or ``duration`` s; returns the evidence record.

    Same contract as :func:`~.live.run_ros1`.  Raises :class:`Ros2Unavailable`."""
    try:
        import rclpy
        from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
        from rosidl_runtime_py.convert import message_to_ordereddict
        from rosidl_runtime_py.utilities import get_message
        from std_msgs.msg import String
    except ImportError as exc:
        raise Ros2Unavailable(f"rclpy is not installed ({exc}); source a ROS 2 installation first") from None
    from .ros1 import contract_topics
    topics = contract_topics(checked, nodes)
    classes = {}
    for topic, typ in topics.items():
        pkg, _, name = typ.replace("/msg/", "/").partition("/")
        try:
            classes[topic] = get_message(f"{pkg}/msg/{name}")
        except (AttributeError, ModuleNotFoundError, ValueError) as exc:
            raise Ros2Unavailable(f"message type {pkg}/msg/{name} is not built in this ROS 2 installation: {exc}") \
                from None
    rclpy.init()
    node = rclpy.create_node(node_name)

    def now() -> float:
        return float(node.get_clock().now().nanoseconds) / 1e9
    latched = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL, reliability=ReliabilityPolicy.RELIABLE)
    pub = node.create_publisher(String, verdict_topic, 1000)
    lasts = {n.name: node.create_publisher(String, f"{last_prefix}/{n.name}/last_verdict", latched) for n in nodes}

    def text(data: str) -> Any:
        s = String()
        s.data = data
        return s
    live = run_factory(publish=lambda m: pub.publish(text(m)),
                              publish_last=lambda n, m: lasts[n].publish(text(m)))
    worker = EngineWorker(live, lambda _t, msg: dict(message_to_ordereddict(msg)), now, tick_s=tick_s).start()
    for topic, cls in classes.items():
        node.create_subscription(cls, topic, lambda msg, t=topic: worker.offer(t, msg, now()), 1000)
    out(f"monitoring {len(topics)} topic(s) for {len(nodes)} node(s); verdicts on {verdict_topic}")
    t0 = _time.monotonic()
    next_status = t0 + status_s
    try:
        while not stop.is_set() and rclpy.ok():
            if duration is not None and _time.monotonic() - t0 >= duration:
                break
            rclpy.spin_once(node, timeout_sec=tick_s)
            if worker.error is not None:
                break  # the engine thread died: stop and say so, never monitor on silently
            if status_s > 0 and _time.monotonic() >= next_status:
                out(live.status_line())
                next_status += status_s
    finally:
        record = stop_and_record(worker, live, evidence, out)
        if evidence is not None:
            atomic_write_text(evidence, json.dumps(record, indent=2, sort_keys=True) + "\n")
        out(live.status_line())
        node.destroy_node()
        rclpy.shutdown()
    return record


__all__ = ["Ros2Unavailable", "run_ros2"]
