"""Echoes the topic given on the command line to /echo_out."""
import argparse
import sys

import rclpy
from rclpy.node import Node
from std_msgs.msg import String


class Echo(Node):

    def __init__(self, topic):
        super().__init__('echo')
        self.pub = self.create_publisher(String, 'echo_out', 10)
        self.sub = self.create_subscription(String, topic, self.pub.publish, 10)


def main(args=None):
    parser = argparse.ArgumentParser()
    parser.add_argument('topic')
    parsed = parser.parse_args(sys.argv[1:])
    rclpy.init(args=args)
    rclpy.spin(Echo(parsed.topic))
