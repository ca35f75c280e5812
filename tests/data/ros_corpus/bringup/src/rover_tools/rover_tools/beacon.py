from std_msgs.msg import String


class Beacon:
    """Says where the rover is, once a second."""

    def __init__(self, node, topic='beacon'):
        self._pub = node.create_publisher(String, topic, 10)
        self._timer = node.create_timer(1.0, self._say)

    def _say(self):
        self._pub.publish(String(data='here'))
