import rclpy
from rclpy.lifecycle import Node
from rclpy.lifecycle import TransitionCallbackReturn
from std_msgs.msg import Float32


class Pump(Node):
    """A managed pump: its publisher is made when it is configured."""

    def __init__(self):
        super().__init__('pump')
        self.flow_pub = None

    def on_configure(self, state):
        self.flow_pub = self.create_lifecycle_publisher(Float32, 'flow', 10)
        return TransitionCallbackReturn.SUCCESS


def main():
    rclpy.init()
    rclpy.spin(Pump())
