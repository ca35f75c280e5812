"""Counts on chatter and reports that it is alive."""
import rclpy
from rclpy.node import Node
from std_msgs.msg import Empty, String


class Talker(Node):

    def __init__(self):
        super().__init__('talker')
        self.pub = self.create_publisher(String, 'chatter', 10)
        self.alive = self.create_publisher(Empty, 'heartbeat', 1)


def main(args=None):
    rclpy.init(args=args)
    rclpy.spin(Talker())
