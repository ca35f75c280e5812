#!/usr/bin/env python
# Python 2 bench script: moves the test rig along a line while reading the gauge.
import rospy
from std_msgs.msg import Float32, String
from std_srvs.srv import Empty


class LinearJog(object):
    def __init__(self):
        rospy.init_node('rig_jogger')
        rospy.Subscriber('/gauge/reading', Float32, self.on_reading)
        self.marks = rospy.Publisher('marks', String, queue_size=1)
        self.home = rospy.ServiceProxy('/rig/home', Empty)

    def on_reading(self, msg):
        print "reading", msg.data


if __name__ == '__main__':
    LinearJog()
    rospy.spin()
