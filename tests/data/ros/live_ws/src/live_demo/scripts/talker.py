#!/usr/bin/env python3
"""Publishes a counter on 'chatter' and listens for 'ack'."""
import rospy
from std_msgs.msg import Int32, String

if __name__ == '__main__':
    rospy.init_node('talker')
    pub = rospy.Publisher('chatter', String, queue_size=10)
    rospy.Subscriber('ack', Int32, lambda msg: None)
    rate = rospy.Rate(20)
    k = 0
    while not rospy.is_shutdown():
        pub.publish(String(data=str(k)))
        k += 1
        rate.sleep()
