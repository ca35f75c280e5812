"""What the robot's node programs share: run one rclpy node until SIGINT or
SIGTERM (rclpy's own handlers shut its context down), with no traceback."""
import rclpy
from rclpy.executors import ExternalShutdownException, MultiThreadedExecutor


def run(make):
    """Start rclpy, make the node (``make()``), print ``ready <name>`` and spin
    it until SIGINT/SIGTERM.  Returns the exit code, 0."""
    rclpy.init()
    node = make()
    executor = MultiThreadedExecutor(num_threads=2)
    executor.add_node(node)
    print("ready", node.get_name(), flush=True)
    try:
        while rclpy.ok():
            executor.spin_once(timeout_sec=0.5)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown()
    return 0
