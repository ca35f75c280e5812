"""The dock server, an rclpy node: serves the ``/dock`` action
(robot_msgs/action/Dock, ``interfaces/``): for each goal it drives as
``dock_logic.step`` does, publishing the distance left after each tick of
TICK seconds as feedback, and returns the distance left when it stopped.
Contract: ``Dock`` in ``contracts/robot.rcl``.  Run: ``python dock.py`` in a
ROS 2 Python with ``robot_msgs`` built (README.md)."""
import sys
import time

from rclpy.action import ActionServer
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.node import Node
from robot_msgs.action import Dock as DockAction

from dock_logic import TOLERANCE, step
from robot_node import run

#: s: one control tick
TICK = 0.05


class Dock(Node):
    def __init__(self):
        super().__init__("dock")
        ActionServer(self, DockAction, "dock", self.execute, callback_group=ReentrantCallbackGroup())

    def execute(self, goal):
        def feedback(remaining):
            goal.publish_feedback(DockAction.Feedback(remaining=remaining))
            time.sleep(TICK)
        out = step(goal.request.distance, feedback)
        goal.succeed()
        return DockAction.Result(remaining=out["final"], docked=out["final"] <= TOLERANCE)


if __name__ == "__main__":
    sys.exit(run(Dock))
