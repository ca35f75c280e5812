#!/usr/bin/env python3
"""Localisation (AMCL from imu and odometry, paper lines 1102-1117): publishes
the rover's position.  Topic interface only."""
import rospy
from gazebo_radiation_plugin.msg import Snapshot

if __name__ == '__main__':
    rospy.init_node('localisation')
    position = rospy.Publisher('position', Snapshot, queue_size=10)
    rospy.spin()
