#!/usr/bin/env python3
import rclpy
from std_msgs.msg import String
rclpy.init()
node = rclpy.create_node('beeper_py')
pub = node.create_publisher(String, 'beep_text', 1)
rclpy.spin(node)
