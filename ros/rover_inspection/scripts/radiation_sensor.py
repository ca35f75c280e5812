#!/usr/bin/env python3
"""Radiation Sensor (paper lines 1280-1304, appendix A): classifies the
reading r as green, orange or red while inspecting, and reports the
inspected waypoint.  Topic interface only."""
import rospy
from gazebo_radiation_plugin.msg import Snapshot

if __name__ == '__main__':
    rospy.init_node('radiation_sensor')
    status = rospy.Publisher('radiationStatus', Snapshot, queue_size=10)
    inspected = rospy.Publisher('inspected', Snapshot, queue_size=10)
    rospy.Subscriber('r', Snapshot, lambda msg: None)
    rospy.Subscriber('command', Snapshot, lambda msg: None)
    rospy.spin()
