#!/usr/bin/env python3
"""Agent (the Gwendolen BDI agent, paper lines 1143-1171 and 1256-1278):
commands moves and inspections from the waypoints, the arrival reports, the
inspected waypoints and the radiation status.  Topic interface only."""
import rospy
from gazebo_radiation_plugin.msg import Snapshot

if __name__ == '__main__':
    rospy.init_node('agent')
    command = rospy.Publisher('command', Snapshot, queue_size=10)
    rospy.Subscriber('at', Snapshot, lambda msg: None)
    rospy.Subscriber('inspected', Snapshot, lambda msg: None)
    rospy.Subscriber('wayPNow', Snapshot, lambda msg: None)
    rospy.Subscriber('radiationStatus', Snapshot, lambda msg: None)
    rospy.spin()
