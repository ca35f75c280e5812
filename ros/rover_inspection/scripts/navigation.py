#!/usr/bin/env python3
"""Navigation (move_base and the velocity controller, paper lines 1207-1227):
moves to the commanded waypoint from the current location, reports arrival.
Topic interface only."""
import rospy
from gazebo_radiation_plugin.msg import Snapshot

if __name__ == '__main__':
    rospy.init_node('navigation')
    at = rospy.Publisher('at', Snapshot, queue_size=10)
    rospy.Subscriber('command', Snapshot, lambda msg: None)
    rospy.Subscriber('currentLoc', Snapshot, lambda msg: None)
    rospy.spin()
