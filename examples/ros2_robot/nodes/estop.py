"""The e-stop server, an rclpy node: serves ``/estop`` (std_srvs/SetBool),
engaging (``data: true``) or releasing the motors' brake, and answers the
brake's state in ``success``, as ``estop_logic.step`` decides.  Contract:
``EStop`` in ``contracts/robot.rcl``.  Run: ``python estop.py`` in a ROS 2
Python."""
import sys

from rclpy.node import Node
from std_srvs.srv import SetBool

from estop_logic import step
from robot_node import run


class EStop(Node):
    def __init__(self):
        super().__init__("estop")
        self.create_service(SetBool, "estop", self.on_call)

    def on_call(self, request, response):
        response.success = step(request.data)["engaged"]
        response.message = "brake engaged" if response.success else "brake released"
        return response


if __name__ == "__main__":
    sys.exit(run(EStop))
