"""The warehouse robot as real ROS 2 nodes (rclpy); run by ``record_live.py``
in a ROS 2 Python (rclpy, std_msgs, sensor_msgs, geometry_msgs and the
colcon-built ``warehouse_msgs``; no rclverify).

``python ros2_nodes.py NODE...`` runs those nodes in one process (the
recorder starts one process per node); ``python ros2_nodes.py scenario`` is
the environment and the operator.  Each node's callback calls the same
function of this folder that the property tests check (``base.py``,
``controller.py``, ...), waits that node's latency (the figures of the
simulator ``record_run.py``, which drives the same scenario on a simulated
clock) and publishes: the Controller asks the Base's ``get_limits`` service
before following a new speed command, the MissionManager sends the order to
the Planner as a goal of the ``navigate`` action, whose feedback and result
the Planner gives as the robot reaches each marker.
"""
import sys
import threading
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(1, str(Path(__file__).resolve().parents[2]))  # examples/: ros2_recording.serve
sys.dont_write_bytecode = True

from geometry_msgs.msg import Twist  # noqa: E402
from rclpy.action import ActionClient, ActionServer  # noqa: E402
from rclpy.callback_groups import MutuallyExclusiveCallbackGroup, ReentrantCallbackGroup  # noqa: E402
from ros2_recording import serve  # noqa: E402
from sensor_msgs.msg import Range  # noqa: E402
from std_msgs.msg import Bool, Float64  # noqa: E402
from warehouse_msgs.action import Navigate  # noqa: E402
from warehouse_msgs.srv import GetLimits  # noqa: E402

from base import base  # noqa: E402
from battery_monitor import battery_monitor  # noqa: E402
from controller import controller  # noqa: E402
from lidar_driver import lidar_driver  # noqa: E402
from localiser import localiser  # noqa: E402
from mission_manager import mission_manager  # noqa: E402
from planner import planner  # noqa: E402

#: s: from receiving a message to publishing the answer (the simulator's figures)
LATENCY = {"LidarDriver": 0.008, "Localiser": 0.010, "BatteryMonitor": 0.005, "MissionManager": 0.004,
           "Planner": 0.020, "Controller": 0.015, "Base": 0.040,
           "Controller/get_limits": 0.002, "Base/get_limits": 0.005}
#: (time s, topic, value): what the environment and the operator send (the simulator's scenario)
SCENARIO = [(0.000, "battery_charge", 80.0), (0.020, "marker", 0.0), (0.100, "scan", 5.0), (0.200, "order", 3.0),
            (0.500, "scan", 1.2), (1.000, "marker", 1.0), (1.500, "battery_charge", 50.0), (2.000, "marker", 2.0),
            (2.300, "scan", 0.3), (2.600, "scan", 2.5), (3.000, "marker", 3.0), (3.500, "battery_charge", 20.0),
            (4.000, "battery_charge", 15.0)]
END = 4.5
#: topic -> subscribers the scenario waits for: the nodes' and the monitor's
READERS = {"battery_charge": 2, "marker": 2, "scan": 2, "order": 2, "obstacle": 2, "pose": 2, "battery_low": 2,
           "dock": 1, "speed_cmd": 2, "cmd_vel": 2, "odom": 1}
QOS = 10


def twist(vx):
    msg = Twist()
    msg.linear.x = float(vx)
    return msg


def lidar_driver_node(node):
    pub = node.create_publisher(Float64, "obstacle", QOS)

    def on_scan(msg):
        out = lidar_driver(msg.range)["obstacle"]
        time.sleep(LATENCY["LidarDriver"])
        pub.publish(Float64(data=float(out)))
    node.create_subscription(Range, "scan", on_scan, QOS)


def localiser_node(node):
    pub = node.create_publisher(Float64, "pose", QOS)

    def on_marker(msg):
        out = localiser(msg.data)["pose_x"]
        time.sleep(LATENCY["Localiser"])
        pub.publish(Float64(data=float(out)))
    node.create_subscription(Float64, "marker", on_marker, QOS)


def battery_monitor_node(node):
    pub = node.create_publisher(Bool, "battery_low", QOS)

    def on_charge(msg):
        out = battery_monitor(msg.data)["battery_low"]
        time.sleep(LATENCY["BatteryMonitor"])
        pub.publish(Bool(data=bool(out)))
    node.create_subscription(Float64, "battery_charge", on_charge, QOS)


def mission_manager_node(node):
    dock = node.create_publisher(Bool, "dock", QOS)
    client = ActionClient(node, Navigate, "navigate", callback_group=ReentrantCallbackGroup())
    state = {"order_x": None, "remaining": 0.0, "reached_x": 0.0, "battery_low": False}

    def on_feedback(fb):
        state["remaining"] = fb.feedback.remaining

    def on_result(fut):
        state["reached_x"] = fut.result().result.reached_x

    def on_accepted(fut):
        fut.result().get_result_async().add_done_callback(on_result)

    def mission(goal):
        if state["order_x"] is None:
            state["order_x"] = 0.0
        out = mission_manager(**state)
        time.sleep(LATENCY["MissionManager"])
        if goal:
            client.send_goal_async(Navigate.Goal(goal_x=float(out["goal_x"])),
                                   feedback_callback=on_feedback).add_done_callback(on_accepted)
        dock.publish(Bool(data=bool(out["dock"])))

    def on_order(msg):
        state["order_x"] = msg.data
        mission(goal=True)

    def on_battery_low(msg):
        state["battery_low"] = msg.data
        mission(goal=False)
    node.create_subscription(Float64, "order", on_order, QOS)
    node.create_subscription(Bool, "battery_low", on_battery_low, QOS)
    return lambda: client.wait_for_server(timeout_sec=20)


def planner_node(node):
    pub = node.create_publisher(Float64, "speed_cmd", QOS)
    lock = threading.Lock()
    state = {"goal_x": None, "pose_x": None, "goal": None, "done": threading.Event(),
             "reached_x": planner.initial["reached_x"]}

    def plan():  # with the lock held
        if state["goal_x"] is None or state["pose_x"] is None or state["goal"] is None:
            return
        out = planner(goal_x=state["goal_x"], pose_x=state["pose_x"])
        time.sleep(LATENCY["Planner"])
        pub.publish(Float64(data=float(out["speed_cmd"])))
        state["goal"].publish_feedback(Navigate.Feedback(remaining=float(out["remaining"])))
        if out["remaining"] == 0.0:
            state["reached_x"] = out["reached_x"]
            state["done"].set()

    def execute(goal):
        with lock:
            state["goal_x"], state["goal"] = goal.request.goal_x, goal
            state["done"].clear()
            plan()
        state["done"].wait()
        with lock:
            state["goal"] = None
            goal.succeed()
            return Navigate.Result(reached_x=float(state["reached_x"]))

    def on_pose(msg):
        with lock:
            state["pose_x"] = msg.data
            plan()
    node.create_subscription(Float64, "pose", on_pose, QOS)
    ActionServer(node, Navigate, "navigate", execute, callback_group=ReentrantCallbackGroup())


def controller_node(node):
    pub = node.create_publisher(Twist, "cmd_vel", QOS)
    client = node.create_client(GetLimits, "get_limits", callback_group=ReentrantCallbackGroup())
    ctl = {"obstacle": None, "speed_cmd": None, "max_speed": None}
    lock = threading.Lock()

    def control():  # with the lock held
        if None in ctl.values():
            return
        out = controller(**ctl)
        time.sleep(LATENCY["Controller"])
        pub.publish(twist(out["cmd_vel"]))

    def on_limits(fut):
        with lock:
            ctl["max_speed"] = fut.result().max_speed
            control()

    def on_obstacle(msg):
        with lock:
            ctl["obstacle"] = msg.data
            control()

    def on_speed_cmd(msg):
        # a new speed command: ask the base for its limit first, follow the command with the answer
        with lock:
            ctl["speed_cmd"] = msg.data
            query = controller(0.0, 0.0, 1.0)["query"]
        time.sleep(LATENCY["Controller/get_limits"])
        client.call_async(GetLimits.Request(query=bool(query))).add_done_callback(on_limits)
    node.create_subscription(Float64, "obstacle", on_obstacle, QOS)
    node.create_subscription(Float64, "speed_cmd", on_speed_cmd, QOS)
    return lambda: client.wait_for_service(timeout_sec=20)


def base_node(node):
    pub = node.create_publisher(Twist, "odom", QOS)

    def on_cmd_vel(msg):
        out = base(cmd_vel=msg.linear.x, query=False)["wheel_speed"]
        time.sleep(LATENCY["Base"])
        pub.publish(twist(out))

    def on_get_limits(request, response):
        response.max_speed = float(base(cmd_vel=0.0, query=request.query)["max_speed"])
        time.sleep(LATENCY["Base/get_limits"])
        return response
    node.create_subscription(Twist, "cmd_vel", on_cmd_vel, QOS)
    node.create_service(GetLimits, "get_limits", on_get_limits, callback_group=MutuallyExclusiveCallbackGroup())


NODES = {"LidarDriver": lidar_driver_node, "Localiser": localiser_node, "BatteryMonitor": battery_monitor_node,
         "MissionManager": mission_manager_node, "Planner": planner_node, "Controller": controller_node,
         "Base": base_node}


def scenario(node, executor):
    pubs = {t: node.create_publisher(Range if t == "scan" else Float64, t, QOS)
            for t in ("battery_charge", "marker", "scan", "order")}
    until = time.monotonic() + 20
    while any(node.count_subscribers(t) < n for t, n in READERS.items()):
        if time.monotonic() > until:
            print("not connected:", {t: node.count_subscribers(t) for t in READERS}, flush=True)
            return 1
        executor.spin_once(timeout_sec=0.05)
    time.sleep(1.5)  # every reader discovered; let the writers match them (the monitor's call readers too)
    t0 = time.monotonic()
    for t, topic, value in SCENARIO:
        time.sleep(max(0.0, t0 + t - time.monotonic()))
        if topic == "scan":
            msg = Range(radiation_type=Range.INFRARED, field_of_view=0.05, min_range=0.05, max_range=30.0,
                        range=value)
            msg.header.stamp = node.get_clock().now().to_msg()
            msg.header.frame_id = "lidar"
        else:
            msg = Float64(data=value)
        pubs[topic].publish(msg)
    time.sleep(max(0.0, t0 + END - time.monotonic()))
    print("done", len(SCENARIO), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(serve(NODES, scenario))
