"""The gauge: two channels, an alarm client, tf, message filters and markers."""
import message_filters
import rclpy
from interactive_markers import InteractiveMarkerServer
from rclpy.node import Node
from rclpy.parameter_event_handler import ParameterEventHandler
from rclpy.wait_for_message import wait_for_message
from sensor_msgs.msg import Image, CameraInfo, Temperature
from tf2_ros import StaticTransformBroadcaster, TransformBroadcaster, TransformListener
from tf2_ros.buffer import Buffer

from py_gauges import topics
from py_gauges.channels import Channel, make_alarm_client


class GaugeNode(Node):
    def __init__(self):
        super().__init__(topics.GAUGE_NODE)
        self.inner = Channel(self, 'inner')
        self.outer = Channel(self, 'outer', suffix='raw')
        self.alarm = make_alarm_client(self, topics.ALARM_SERVICE)
        self.broadcaster = TransformBroadcaster(self)
        self.static = StaticTransformBroadcaster(self)
        self.buffer = Buffer()
        self.listener = TransformListener(self.buffer, self)
        self.params = ParameterEventHandler(self)
        image = message_filters.Subscriber(self, Image, 'camera/image')
        info = message_filters.Subscriber(self, CameraInfo, 'camera/camera_info')
        self.sync = message_filters.TimeSynchronizer([image, info], 5)
        self.markers = InteractiveMarkerServer(self, 'gauge_markers')
        ok, first = wait_for_message(Temperature, self, 'temperature', time_to_wait=2.0)


def main():
    rclpy.init()
    rclpy.spin(GaugeNode())
    rclpy.shutdown()
