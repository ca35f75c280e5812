#!/usr/bin/env python3
"""Turns each 'range' into a speed on 'cmd'."""
import rospy
from std_msgs.msg import Float32

if __name__ == '__main__':
    rospy.init_node('planner')
    cmd = rospy.Publisher('cmd', Float32, queue_size=10)
    rospy.Subscriber('range', Float32, lambda msg: cmd.publish(Float32(data=min(msg.data, 1.0))))
    rospy.spin()
