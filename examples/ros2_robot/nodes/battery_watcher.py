"""The battery watcher, an rclpy node: on each ``/battery``
(sensor_msgs/BatteryState) it publishes on ``/return_home`` (std_msgs/Bool)
whether to go home, as ``battery_watcher_logic.step`` decides.  Contract:
``BatteryWatcher`` in ``contracts/robot.rcl``.  Run: ``python
battery_watcher.py`` in a ROS 2 Python."""
import sys

from rclpy.node import Node
from sensor_msgs.msg import BatteryState
from std_msgs.msg import Bool

from battery_watcher_logic import step
from robot_node import run


class BatteryWatcher(Node):
    def __init__(self):
        super().__init__("battery_watcher")
        self.home = self.create_publisher(Bool, "return_home", 10)
        self.create_subscription(BatteryState, "battery", self.on_battery, 10)

    def on_battery(self, msg):
        self.home.publish(Bool(data=step(msg.percentage)["go_home"]))


if __name__ == "__main__":
    sys.exit(run(BatteryWatcher))
