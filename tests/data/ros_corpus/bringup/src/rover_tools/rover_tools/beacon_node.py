import rclpy
from rclpy.node import Node

from rover_tools import Beacon


def main():
    rclpy.init()
    node = Node('beacon_node')
    Beacon(node, 'rover_beacon')
    rclpy.spin(node)


if __name__ == '__main__':
    main()
