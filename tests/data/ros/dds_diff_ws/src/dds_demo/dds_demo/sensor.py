"""Publishes range readings (best effort, as sensors do) and serves a reset."""
import rclpy
from rclpy.node import Node
from rclpy.qos import qos_profile_sensor_data
from std_msgs.msg import Float32
from std_srvs.srv import Trigger


class Sensor(Node):
    def __init__(self):
        super().__init__('sensor')
        self.pub = self.create_publisher(Float32, 'range', qos_profile_sensor_data)
        self.create_service(Trigger, 'reset', self.on_reset)

    def on_reset(self, request, response):
        response.success = True
        return response


def main():
    rclpy.init()
    rclpy.spin(Sensor())
