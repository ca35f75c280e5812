"""The robot's world, an rclpy node with no contract: it waits until the
robot's nodes and the monitor are connected, then publishes laser scans on
``/scan`` and battery readings on ``/battery`` (one of each every PERIOD
seconds, stamped with the node's clock), calls ``/estop`` three times and
sends two ``/dock`` goals, each call and goal after the one before was
answered, and prints ``done``.  Run: ``python simulator.py`` in a ROS 2
Python with ``robot_msgs`` built (README.md)."""
import math
import os
import sys
import time

import rclpy
from rclpy.action import ActionClient
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from robot_msgs.action import Dock
from sensor_msgs.msg import BatteryState, LaserScan
from std_srvs.srv import SetBool

#: s between two scans (and two battery readings); ``SIMULATOR_PERIOD_S`` sets another (the test suite's
#: live run spaces them wider than a loaded machine delays an answer: docs/semantics.md, "Event time")
PERIOD = float(os.environ.get("SIMULATOR_PERIOD_S", "0.1"))
BEAMS = 16


def beams(near=None):
    """A scan's ranges (m): a wall 2 to 3.5 m away, with the beams of ``near`` ({index: m}) replaced."""
    ranges = [2.0 + 0.1 * i for i in range(BEAMS)]
    for i, r in (near or {}).items():
        ranges[i] = r
    return ranges


SCANS = [
    beams(),  # clear
    beams({7: 0.4}),  # an obstacle ahead: stop
    beams({3: 0.5}),  # exactly 0.5 m, not nearer: go on
    beams({15: 0.3}),  # the nearest is the last beam: stop
    beams({0: 0.45, 15: 0.8}),  # the nearest is the first beam: stop
    beams(),
]
#: the charge, falling through the 20 % threshold (0.2 arrives as the float32 0.20000000298...)
BATTERY = [0.55, 0.35, 0.21, 0.2, 0.19, 0.2, 0.25]
#: the e-stop calls: engage, release, engage
ESTOP = [True, False, True]
#: the dock goals (m)
GOALS = [1.0, 0.6]
#: s waited after the last answer: more than the monitor's horizon (contracts/mapping.yaml)
END = 1.5
#: topic -> subscribers expected before the first message: the robot's and the monitor's (the monitor's
#: readers show it is up; its verdict writer is not waited for: a Fast DDS participant that does not know
#: the writer's type looks it up first, and nothing here listens to verdicts)
READERS = {"scan": 2, "battery": 2, "stop": 1, "return_home": 1}
#: s allowed for discovery: an upper bound, reached only when the machine is loaded (services and the
#: action server are matched last, seconds after the topics, under three test workers on two cores)
CONNECT_S = 45.0


class Simulator(Node):
    def __init__(self):
        super().__init__("simulator")
        self.scan = self.create_publisher(LaserScan, "scan", 10)
        self.battery = self.create_publisher(BatteryState, "battery", 10)
        self.estop = self.create_client(SetBool, "estop")
        self.dock = ActionClient(self, Dock, "dock")
        self.executor_ = SingleThreadedExecutor()
        self.executor_.add_node(self)

    def spin_until(self, ready, timeout):
        """Spin until ``ready()``; False after ``timeout`` seconds."""
        until = time.monotonic() + timeout
        while not ready():
            if time.monotonic() > until:
                return False
            self.executor_.spin_once(timeout_sec=0.02)
        return True

    def answer(self, future, timeout=5.0):
        """The result of ``future`` once done (spinning meanwhile); None after ``timeout`` seconds."""
        return future.result() if self.spin_until(future.done, timeout) else None

    def readiness(self):
        """What is matched so far: the subscribers per topic of READERS (the monitor's among them, so the
        monitor is up), whether the e-stop service and the dock action server are ready."""
        return {"subscribers": {t: self.count_subscribers(t) for t in READERS},
                "estop": self.estop.service_is_ready(), "dock": self.dock.server_is_ready()}

    def connected(self):
        r = self.readiness()
        return all(r["subscribers"][t] >= n for t, n in READERS.items()) and r["estop"] and r["dock"]

    def publish_scan(self, ranges):
        msg = LaserScan(angle_min=-math.pi / 4, angle_max=math.pi / 4, angle_increment=math.pi / 2 / (BEAMS - 1),
                        scan_time=PERIOD, range_min=0.05, range_max=10.0, ranges=ranges)
        msg.header.stamp = self.get_clock().now().to_msg()
        msg.header.frame_id = "laser"
        self.scan.publish(msg)

    def publish_battery(self, percentage):
        msg = BatteryState(percentage=percentage, present=True)
        msg.header.stamp = self.get_clock().now().to_msg()
        self.battery.publish(msg)

    def run(self):
        if not self.spin_until(self.connected, CONNECT_S):
            print("not connected:", self.readiness(), flush=True)
            return 1
        self.spin_until(lambda: False, 1.5)  # every reader discovered; let the writers match them
        t0 = time.monotonic()
        for k in range(max(len(SCANS), len(BATTERY))):
            time.sleep(max(0.0, t0 + PERIOD * k - time.monotonic()))
            if k < len(SCANS):
                self.publish_scan(SCANS[k])
            if k < len(BATTERY):
                self.publish_battery(BATTERY[k])
        answers = [self.answer(self.estop.call_async(SetBool.Request(data=d))) for d in ESTOP]
        print("estop", [a.success if a else None for a in answers], flush=True)
        finals = []
        for distance in GOALS:
            handle = self.answer(self.dock.send_goal_async(Dock.Goal(distance=distance)))
            result = self.answer(handle.get_result_async()) if handle and handle.accepted else None
            finals.append(round(result.result.remaining, 3) if result else None)
        print("dock", finals, flush=True)
        self.spin_until(lambda: False, END)  # the monitor's horizon passes after the last answer
        print("done", flush=True)
        return 0


def main():
    rclpy.init()
    node = Simulator()
    try:
        return node.run()
    except KeyboardInterrupt:
        return 1
    finally:
        node.executor_.shutdown()
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    sys.exit(main())
