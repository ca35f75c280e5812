"""Two nodes in one process: a counter server and the client that polls it."""
import rclpy
from rclpy.node import Node
from example_interfaces.srv import AddTwoInts
from std_msgs.msg import Int64


class CounterServer(Node):
    def __init__(self):
        super().__init__('counter_server')
        self.total = self.create_publisher(Int64, 'total', 10)
        self.srv = self.create_service(AddTwoInts, 'add', self.on_add)

    def on_add(self, req, resp):
        resp.sum = req.a + req.b
        return resp


class CounterClient(Node):
    class Pending:
        def __init__(self, node):
            self.watch = node.create_subscription(Int64, 'total', lambda m: None, 10)

    def __init__(self):
        super().__init__('counter_client')
        self.cli = self.create_client(AddTwoInts, 'add')
        self.pending = CounterClient.Pending(self)


def main():
    rclpy.init()
    server, client = CounterServer(), CounterClient()
    rclpy.shutdown()
