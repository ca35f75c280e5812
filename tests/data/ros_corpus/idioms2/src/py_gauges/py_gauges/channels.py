"""A reading channel: a publisher on the topic it is given, through the node it is given."""
from sensor_msgs.msg import Temperature

from .topics import READING_TOPIC


class Channel:
    def __init__(self, node, name, suffix=READING_TOPIC):
        self.topic = name + '/' + suffix
        self.pub = node.create_publisher(Temperature, self.topic, 10)


def make_alarm_client(node, service):
    from std_srvs.srv import Trigger
    return node.create_client(Trigger, service)
