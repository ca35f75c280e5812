"""A level sensor: subscribes to the topic it is given."""
import rospy
from std_msgs.msg import Float32, String

from py_nodes.names import LEVEL_TOPIC


class LevelSensor(object):
    def __init__(self, topic=LEVEL_TOPIC, scale=1.0):
        self.scale = scale
        self.latest = None
        self.sub = rospy.Subscriber(topic, Float32, self.on_level)

    def on_level(self, msg):
        self.latest = msg.data * self.scale


class Announcer(object):
    def __init__(self, topic):
        self.topic = topic

    def start(self):
        self.pub = rospy.Publisher(self.topic, String, queue_size=1, latch=True)
