"""The speed governor and the planner as real ROS 2 nodes (rclpy), one
process each; run by ``record_live.py`` in a ROS 2 Python (rclpy and
std_msgs; no rclverify).

``python ros2_nodes.py SpeedGovernor`` runs the governor: each request on
``requested`` is answered on ``cmd`` by the node's logic (``governor.py``,
the function the property tests check).  ``python ros2_nodes.py planner
SEED`` is the environment: it waits until the governor and the monitor are
connected, publishes 20 requested speeds (0.1-1.2 m/s, drawn with ``SEED``)
one every 0.1 s, and prints ``done``.
"""
import random
import sys
import time
from pathlib import Path

import rclpy
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.node import Node
from std_msgs.msg import Float64

sys.path.insert(0, str(Path(__file__).resolve().parent))
from governor import governor  # noqa: E402

REQUESTS, PERIOD = 20, 0.1
#: topic -> subscribers expected before the first request: the governor's and the monitor's
READERS = {"requested": 2, "cmd": 1}


def speed_governor(node):
    pub = node.create_publisher(Float64, "cmd", 10)
    node.create_subscription(Float64, "requested",
                             lambda msg: pub.publish(Float64(data=float(governor(msg.data)["cmd"]))), 10)


def planner(node, executor, seed):
    pub = node.create_publisher(Float64, "requested", 10)
    until = time.monotonic() + 20
    while any(node.count_subscribers(t) < n for t, n in READERS.items()):
        if time.monotonic() > until:
            print("not connected:", {t: node.count_subscribers(t) for t in READERS}, flush=True)
            return 1
        executor.spin_once(timeout_sec=0.05)
    time.sleep(1.0)  # every reader discovered; let the writers match them
    rng = random.Random(seed)
    t0 = time.monotonic()
    for k in range(REQUESTS):
        time.sleep(max(0.0, t0 + PERIOD * (k + 1) - time.monotonic()))
        pub.publish(Float64(data=round(rng.uniform(0.1, 1.2), 3)))
    time.sleep(0.5)
    print("done", REQUESTS, flush=True)
    return 0


def main():
    role = sys.argv[1]
    rclpy.init()
    node = Node({"planner": "planner"}.get(role, "speed_governor"))
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    try:
        if role == "planner":
            return planner(node, executor, int(sys.argv[2]))
        speed_governor(node)
        print("ready", role, flush=True)
        while rclpy.ok():
            executor.spin_once(timeout_sec=0.2)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
