#!/usr/bin/env python3
"""Logs every 'cmd' (the node the ros diff live test leaves out)."""
import rospy
from std_msgs.msg import Float32

if __name__ == '__main__':
    rospy.init_node('logger')
    rospy.Subscriber('cmd', Float32, lambda msg: rospy.loginfo('cmd %s', msg.data))
    rospy.spin()
