#!/usr/bin/env python3
"""Publishes a range on 'range'; its debug topic's name is computed from a
parameter, so the code does not name it statically (ros diff finds it on the
master)."""
import rospy
from std_msgs.msg import Float32, String

if __name__ == '__main__':
    rospy.init_node('sensor')
    pub = rospy.Publisher('range', Float32, queue_size=10)
    debug = rospy.Publisher(rospy.get_param('~debug_prefix', 'sensor') + '_debug', String, queue_size=10)
    rate = rospy.Rate(20)
    while not rospy.is_shutdown():
        pub.publish(Float32(data=1.5))
        debug.publish(String(data='ok'))
        rate.sleep()
