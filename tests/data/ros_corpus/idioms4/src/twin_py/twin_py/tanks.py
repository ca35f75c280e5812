import rclpy
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node
from std_msgs.msg import Float32


class Tank(Node):
    """A tank gauge; the process runs two of them."""

    def __init__(self, name, topic='level'):
        super().__init__(name)
        self.level_pub = self.create_publisher(Float32, topic, 10)
        self.refill_sub = self.create_subscription(Float32, 'refill', self.on_refill, 10)

    def on_refill(self, msg):
        self.get_logger().info(f'refill {msg.data}')


def main():
    rclpy.init()
    executor = MultiThreadedExecutor()
    executor.add_node(Tank('fresh_tank'))
    executor.add_node(Tank('grey_tank', topic='~/level'))
    executor.spin()
