"""The scan guard, an rclpy node: on each ``/scan`` (sensor_msgs/LaserScan)
it publishes whether to stop on ``/stop`` (std_msgs/Bool), as
``scan_guard_logic.step`` decides.
Contract: ``ScanGuard`` in ``contracts/robot.rcl``.  Run: ``python
scan_guard.py`` in a ROS 2 Python."""
import sys

from rclpy.node import Node
from sensor_msgs.msg import LaserScan
from std_msgs.msg import Bool

from robot_node import run
from scan_guard_logic import step


class ScanGuard(Node):
    def __init__(self):
        super().__init__("scan_guard")
        self.stop = self.create_publisher(Bool, "stop", 10)
        self.create_subscription(LaserScan, "scan", self.on_scan, 10)

    def on_scan(self, msg):
        self.stop.publish(Bool(data=step(list(msg.ranges))["stop"]))


if __name__ == "__main__":
    sys.exit(run(ScanGuard))
