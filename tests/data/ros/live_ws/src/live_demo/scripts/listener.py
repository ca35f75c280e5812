#!/usr/bin/env python3
"""Acknowledges every 'chatter' message on 'ack'."""
import rospy
from std_msgs.msg import Int32, String

if __name__ == '__main__':
    rospy.init_node('listener')
    ack = rospy.Publisher('ack', Int32, queue_size=10)
    rospy.Subscriber('chatter', String, lambda msg: ack.publish(Int32(data=len(msg.data))))
    rospy.spin()
