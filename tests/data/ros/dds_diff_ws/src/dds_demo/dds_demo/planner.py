"""Plans from the range readings; asks the sensor to reset."""
import rclpy
from rclpy.node import Node
from std_msgs.msg import Float32, String
from std_srvs.srv import Trigger


class Planner(Node):
    def __init__(self):
        super().__init__('planner')
        self.create_subscription(Float32, 'range', self.on_range, 10)
        self.plan_pub = self.create_publisher(String, 'plan', 10)
        self.reset = self.create_client(Trigger, 'reset')

    def on_range(self, msg):
        self.plan_pub.publish(String(data='go' if msg.data > 1.0 else 'stop'))


def main():
    rclpy.init()
    rclpy.spin(Planner())
