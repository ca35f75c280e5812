"""An rclpy node: parameter-held topic, a service, a client and both action roles."""
import rclpy
from rclpy.action import ActionClient, ActionServer
from rclpy.node import Node
from std_msgs.msg import String
from std_srvs.srv import Empty
from corpus_interfaces.srv import Calibrate
from corpus_interfaces.action import Sweep


class Watchdog(Node):
    def __init__(self):
        super().__init__('watchdog')
        self.declare_parameter('watch_topic', 'heartbeat')
        watch = self.get_parameter('watch_topic').get_parameter_value().string_value
        self.sub = self.create_subscription(String, watch, self.on_beat, 10)
        self.alarm = self.create_publisher(String, '~/alarm', 10)
        self.silence = self.create_service(Empty, 'silence', self.on_silence)
        self.calibrate = self.create_client(Calibrate, '/calibration/run')
        self.sweep_server = ActionServer(self, Sweep, 'deep_sweep', self.on_sweep)
        self.sweep_client = ActionClient(self, Sweep, 'sweep')

    def on_beat(self, msg):
        pass

    def on_silence(self, req, res):
        return res

    def on_sweep(self, goal):
        return Sweep.Result()


def main():
    rclpy.init()
    rclpy.spin(Watchdog())
