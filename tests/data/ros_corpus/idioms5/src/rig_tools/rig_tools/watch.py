"""Watches every String topic the graph has when it starts."""
import rclpy
from rclpy.node import Node
from std_msgs.msg import String


class Watch(Node):

    def __init__(self):
        super().__init__('watch')
        self.subs = []
        for name, types in self.get_topic_names_and_types():
            if 'std_msgs/msg/String' in types:
                self.subs.append(self.create_subscription(String, name, self.seen, 10))
        self.alarm = self.create_publisher(String, '/watch/alarm', 10)

    def seen(self, msg):
        pass


def main(args=None):
    rclpy.init(args=args)
    rclpy.spin(Watch())
