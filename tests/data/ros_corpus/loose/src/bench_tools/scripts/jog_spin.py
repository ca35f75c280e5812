#!/usr/bin/env python
# Python 2 bench script: the same rig, turned in place; it takes the same node name.
import rospy
from std_msgs.msg import Float32
from std_srvs.srv import Empty, Trigger

rospy.init_node('rig_jogger')
sub = rospy.Subscriber('/gauge/reading', Float32, lambda m: None)
stop = rospy.ServiceProxy('/rig/stop', Trigger)
try:
    rospy.spin()
except rospy.ROSInterruptException, e:
    print "stopped"
