"""A charge monitor as an rclpy node: it says the battery is low at 20 % or less."""
import struct

from rclpy.node import Node
from sensor_msgs.msg import BatteryState
from std_msgs.msg import Bool

F32 = lambda v: struct.unpack("f", struct.pack("f", v))[0]  # noqa: E731 - a float32 field's value


def build():
    """The charge monitor's node: its subscription to /battery publishes /low."""
    node = Node("charge_monitor")
    low = node.create_publisher(Bool, "low", 100)
    limit = F32(0.2)  # the contract's 0.2 as the float32 field carries it
    node.create_subscription(BatteryState, "battery", lambda m: low.publish(Bool(
        data=m.percentage < limit)), 100)
    return node
