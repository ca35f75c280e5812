"""Plans joint goals from the measured joint states."""
import rclpy
from rclpy.node import Node
from arm_interfaces.msg import JointGoal
from sensor_msgs.msg import JointState


class Planner(Node):
    def __init__(self):
        super().__init__('planner')
        self.goal_pub = self.create_publisher(JointGoal, 'joint_goal', 10)
        self.create_subscription(JointState, 'joint_states', self.on_state, 10)

    def on_state(self, msg):
        goal = JointGoal()
        goal.joint = msg.name[0] if msg.name else ''
        self.goal_pub.publish(goal)


def main():
    rclpy.init()
    rclpy.spin(Planner())
