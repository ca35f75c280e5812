"""The delivery robot as real ROS 2 nodes (rclpy); run by ``record_live.py``
in a ROS 2 Python (rclpy, std_msgs, sensor_msgs, geometry_msgs and the
colcon-built ``delivery_msgs``; no rclverify).

``python ros2_nodes.py NODE...`` runs those nodes in one process (the
recorder starts one process per node); ``python ros2_nodes.py scenario`` is
the sensors and the operator.  Each node's callback calls the same function
of this folder that the property tests check (the WheelController its
``WheelControllerNode``, watchdog included) on the message it received, and
publishes the outputs that node's latency after the message was sent (its
DDS source timestamp; the figures of the simulator ``record_run.py``, which
drives the same scenario on a simulated clock where messages travel in no
time), without holding up its next callback, as the simulator does.  The
Navigator serves the ``deliver`` action and asks the RouteServer's
``get_route`` service for the goal's route; the MissionPlanner sends each
order as a goal.  The WheelController's watchdog ticks every 100 ms, 13 ms
past each tenth of a second of the host's clock, and the scenario starts on
a tenth of a second: its first tick 13 ms after the start, as simulated.
"""
import sys
import threading
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(1, str(Path(__file__).resolve().parents[2]))  # examples/: ros2_recording.serve
sys.dont_write_bytecode = True

from delivery_msgs.action import Deliver  # noqa: E402
from delivery_msgs.srv import GetRoute  # noqa: E402
from geometry_msgs.msg import Pose2D, Twist  # noqa: E402
from rclpy.action import ActionClient, ActionServer  # noqa: E402
from rclpy.callback_groups import MutuallyExclusiveCallbackGroup, ReentrantCallbackGroup  # noqa: E402
from ros2_recording import serve  # noqa: E402
from sensor_msgs.msg import Range  # noqa: E402
from std_msgs.msg import Empty, Float64, UInt8, UInt32  # noqa: E402

from gnss_driver import gnss_driver  # noqa: E402
from locker_controller import locker_controller  # noqa: E402
from localiser import localiser  # noqa: E402
from mission_planner import mission_planner  # noqa: E402
from navigator import navigator  # noqa: E402
from obstacle_detector import obstacle_detector  # noqa: E402
from route_server import route_server  # noqa: E402
from speed_governor import speed_governor  # noqa: E402
from wheel_controller import WheelControllerNode  # noqa: E402

#: s: from receiving a message to publishing the answer (the simulator's figures)
LATENCY = {"GnssDriver": 0.005, "Localiser": 0.010, "ObstacleDetector": 0.008, "MissionPlanner": 0.004,
           "Navigator": 0.020, "SpeedGovernor": 0.012, "WheelController": 0.025,
           "Navigator/get_route": 0.002, "RouteServer": 0.015, "LockerController": 0.030}
#: s: the WheelController's watchdog period, and its phase (the simulator's first tick)
WATCHDOG, FIRST_TICK = 0.100, 0.013
#: (time s, topic, value): what the sensors and the operator send (the simulator's scenario); ``arrived``
#: is the world telling the Navigator its last waypoint is reached (no contract reads it)
SCENARIO = [(0.000, "cog", 90.0), (0.050, "scan", 12.0), (0.100, "order", 42), (0.500, "cog", 91.0),
            (1.000, "scan", 3.0), (1.000, "cog", 92.5), (1.450, "scan", 0.25), (2.000, "scan", 1.5),
            (2.500, "scan", 5.0), (2.500, "cog", 90.0), (2.900, "arrived", None)]
END = 3.0
#: topic -> subscribers the scenario waits for: the nodes' and the monitor's
READERS = {"cog": 2, "heading": 2, "pose": 2, "scan": 2, "clearance": 3, "order": 2, "locker_dest": 2,
           "compartment": 1, "cmd_vel": 2, "safe_cmd": 2, "wheel_cmd": 1, "arrived": 1}
QOS = 10


def later(node, fn, info=None):
    """Run ``fn`` (the node's publications, in order) on a thread of its own, that node's latency after
    the message it answers was sent (``info``: the message's rclpy MessageInfo, whose source timestamp
    is its writer's clock, this host's), or from now: the simulator's messages travel in no time."""
    delay = LATENCY[node]
    if info is not None:
        delay -= (time.time_ns() - info["source_timestamp"]) / 1e9
    t = threading.Timer(max(0.0, delay), fn)
    t.daemon = True
    t.start()


def twist(vx):
    msg = Twist()
    msg.linear.x = float(vx)
    return msg


def gnss_driver_node(node):
    pub = node.create_publisher(Float64, "heading", QOS)

    def on_cog(msg, info):
        out = Float64(data=float(gnss_driver(msg.data)["heading"]))
        later("GnssDriver", lambda: pub.publish(out), info)
    node.create_subscription(Float64, "cog", on_cog, QOS)


def localiser_node(node):
    pub = node.create_publisher(Pose2D, "pose", QOS)

    def on_heading(msg, info):
        out = Pose2D(x=0.0, y=0.0, theta=float(localiser(msg.data)["yaw"]))
        later("Localiser", lambda: pub.publish(out), info)
    node.create_subscription(Float64, "heading", on_heading, QOS)


def obstacle_detector_node(node):
    pub = node.create_publisher(Float64, "clearance", QOS)

    def on_scan(msg, info):
        out = Float64(data=float(obstacle_detector(msg.range)["clearance"]))
        later("ObstacleDetector", lambda: pub.publish(out), info)
    node.create_subscription(Range, "scan", on_scan, QOS)


def locker_controller_node(node):
    pub = node.create_publisher(UInt8, "compartment", QOS)

    def on_dest(msg, info):
        out = UInt8(data=int(locker_controller(msg.data)["compartment"]))
        later("LockerController", lambda: pub.publish(out), info)
    node.create_subscription(UInt32, "locker_dest", on_dest, QOS)


def mission_planner_node(node):
    pub = node.create_publisher(UInt32, "locker_dest", QOS)
    client = ActionClient(node, Deliver, "deliver", callback_group=ReentrantCallbackGroup())
    mission = {"order_id": None, "remaining": 0.0, "delivered_id": 0}

    def on_feedback(fb):
        mission["remaining"] = fb.feedback.remaining

    def on_result(fut):
        mission["delivered_id"] = fut.result().result.delivered_id

    def on_accepted(fut):
        fut.result().get_result_async().add_done_callback(on_result)

    def on_order(msg, info):
        mission["order_id"] = msg.data
        dest = int(mission_planner(**mission)["dest_id"])

        def send():
            client.send_goal_async(Deliver.Goal(dest_id=dest), feedback_callback=on_feedback) \
                .add_done_callback(on_accepted)
            pub.publish(UInt32(data=dest))
        later("MissionPlanner", send, info)
    node.create_subscription(UInt32, "order", on_order, QOS)
    return lambda: client.wait_for_server(timeout_sec=20)


def route_server_node(node):
    def on_get_route(request, response):
        response.n_waypoints = int(route_server(route_dest=request.route_dest)["n_waypoints"])
        time.sleep(LATENCY["RouteServer"])
        return response
    node.create_service(GetRoute, "get_route", on_get_route)


def navigator_node(node):
    pub = node.create_publisher(Twist, "cmd_vel", QOS)
    client = node.create_client(GetRoute, "get_route", callback_group=ReentrantCallbackGroup())
    lock = threading.Lock()
    nav = {"dest_id": None, "yaw": None, "clearance": None, "n_waypoints": None}
    goal = {"handle": None, "arrived": threading.Event()}

    def navigate(feedback=False, info=None):  # with the lock held
        if None in nav.values():
            return
        out = navigator(**nav)
        handle = goal["handle"]

        def send():
            pub.publish(twist(out["cmd_vel"]))
            if feedback and handle is not None:
                handle.publish_feedback(Deliver.Feedback(remaining=float(out["remaining"])))
        later("Navigator", send, info)

    def on_route(fut):
        with lock:
            nav["n_waypoints"] = fut.result().n_waypoints
            navigate(feedback=True)

    def execute(handle):
        # a new goal: ask the route server for its route first, drive with the answer
        with lock:
            nav["dest_id"] = handle.request.dest_id
            goal["handle"] = handle
            goal["arrived"].clear()
            route_dest = int(navigator(**{k: (0 if v is None else v) for k, v in nav.items()})["route_dest"])
        later("Navigator/get_route",
              lambda: client.call_async(GetRoute.Request(route_dest=route_dest)).add_done_callback(on_route))
        goal["arrived"].wait()
        with lock:
            out = navigator(**nav)
        time.sleep(LATENCY["Navigator"])
        handle.succeed()
        return Deliver.Result(delivered_id=int(out["delivered_id"]))

    def on_pose(msg, info):
        with lock:
            nav["yaw"] = msg.theta
            navigate(info=info)

    def on_clearance(msg, info):
        with lock:
            nav["clearance"] = msg.data
            navigate(info=info)
    node.create_subscription(Pose2D, "pose", on_pose, QOS)
    node.create_subscription(Float64, "clearance", on_clearance, QOS)
    node.create_subscription(Empty, "arrived", lambda _msg: goal["arrived"].set(), QOS)
    ActionServer(node, Deliver, "deliver", execute, callback_group=ReentrantCallbackGroup())
    return lambda: client.wait_for_service(timeout_sec=20)


def speed_governor_node(node):
    pub = node.create_publisher(Twist, "safe_cmd", QOS)
    gov = {"clearance": None, "cmd_vel": None}

    def govern(info):
        if None in gov.values():
            return
        out = twist(speed_governor(**gov)["safe_cmd"])
        later("SpeedGovernor", lambda: pub.publish(out), info)

    def on_clearance(msg, info):
        gov["clearance"] = msg.data
        govern(info)

    def on_cmd_vel(msg, info):
        gov["cmd_vel"] = msg.linear.x
        govern(info)
    node.create_subscription(Float64, "clearance", on_clearance, QOS)
    node.create_subscription(Twist, "cmd_vel", on_cmd_vel, QOS)


def wheel_controller_node(node):
    pub = node.create_publisher(Float64, "wheel_cmd", QOS)
    wheels = WheelControllerNode()
    lock = threading.Lock()

    def on_safe_cmd(msg, info):
        with lock:
            out = Float64(data=float(wheels.on_safe_cmd(msg.linear.x)))
        later("WheelController", lambda: pub.publish(out), info)

    def on_watchdog():
        with lock:
            cmd = wheels.on_watchdog()
        if cmd is not None:
            pub.publish(Float64(data=float(cmd)))
    node.create_subscription(Twist, "safe_cmd", on_safe_cmd, QOS)
    time.sleep((FIRST_TICK - time.time()) % WATCHDOG)  # the timer's phase: 13 ms past a tenth of a second
    node.create_timer(WATCHDOG, on_watchdog, callback_group=MutuallyExclusiveCallbackGroup())


NODES = {"GnssDriver": gnss_driver_node, "Localiser": localiser_node, "ObstacleDetector": obstacle_detector_node,
         "LockerController": locker_controller_node, "MissionPlanner": mission_planner_node,
         "RouteServer": route_server_node, "Navigator": navigator_node, "SpeedGovernor": speed_governor_node,
         "WheelController": wheel_controller_node}


def scenario(node, executor):
    kinds = {"cog": Float64, "scan": Range, "order": UInt32, "arrived": Empty}
    pubs = {t: node.create_publisher(k, t, QOS) for t, k in kinds.items()}
    until = time.monotonic() + 20
    while any(node.count_subscribers(t) < n for t, n in READERS.items()):
        if time.monotonic() > until:
            print("not connected:", {t: node.count_subscribers(t) for t in READERS}, flush=True)
            return 1
        executor.spin_once(timeout_sec=0.05)
    time.sleep(1.5)  # every reader discovered; let the writers match them (the monitor's call readers too)
    t0 = (int(time.time() * 10) + 1) / 10  # on a tenth of a second (the watchdog's phase)
    for t, topic, value in SCENARIO:
        time.sleep(max(0.0, t0 + t - time.time()))
        if topic == "scan":
            msg = Range(radiation_type=Range.ULTRASOUND, field_of_view=0.5, min_range=0.0, max_range=40.0, range=value)
            msg.header.stamp = node.get_clock().now().to_msg()
            msg.header.frame_id = "lidar"
        elif topic == "arrived":
            msg = Empty()
        else:
            msg = kinds[topic](data=value)
        pubs[topic].publish(msg)
    # the run ends at END as simulated: the recorder stops the nodes once this returns, before the
    # watchdog's next tick (END + 13 ms)
    time.sleep(max(0.0, t0 + END - WATCHDOG / 2 - time.time()))
    print("done", len(SCENARIO), t0, flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(serve(NODES, scenario))
