"""Relays a topic named on the command line to one named by an option."""
import argparse
import sys

import rclpy
from std_msgs.msg import String


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument('--out-topic', default='relayed')
    args, rest = parser.parse_known_args()
    rclpy.init(args=rest)
    node = rclpy.create_node('relay')
    pub = node.create_publisher(String, args.out_topic, 10)
    node.create_subscription(String, sys.argv[1], pub.publish, 10)
    rclpy.spin(node)
