#!/usr/bin/env python3
"""Publishes radiation readings at the rover's odometry position."""
import rospy
from nav_msgs.msg import Odometry
from rover_msgs.msg import Reading
from std_msgs.msg import String


class Sensor:
    def __init__(self):
        self.pub = rospy.Publisher('radiation', Reading, queue_size=10)
        rospy.Subscriber('odom', Odometry, self.on_odom)
        debug_topic = rospy.get_param('~debug_prefix', '') + 'debug'
        self.debug = rospy.Publisher(debug_topic, String, queue_size=1)

    def on_odom(self, msg):
        r = Reading()
        r.position = msg.pose.pose.position
        r.value = 0.0
        self.pub.publish(r)


if __name__ == '__main__':
    rospy.init_node('sensor')
    Sensor()
    rospy.spin()
