"""The mobile manipulator as real rclpy nodes, one process: sixteen nodes
(nine with a contract in ``contracts/manipulator.rcl``, the rest the robot's
world), each answering its question within a millisecond on ROS 2's
default middleware (Fast DDS), with seeded defects chosen on the command
line.  Run it in a ROS 2 Python (rclpy, std_srvs, test_msgs)::

    python robot.py [--defects all|NAME,NAME...] [--monitors N] [--rounds N]

It waits until ``N`` verdict publishers (``rclverify monitor --live
--ros2``) are in the graph, publishes ``--rounds`` rounds 150 ms apart
(a scan stamped at acquisition, a battery reading from the lifecycle
node, joint positions, an unstamped speed request, an unstamped docking
range and an unstamped pose), calls the e-stop six times, sends the arm
three goals, and prints ``done``.  The defects (README.md): each changes one
node's answers and no other's.
"""
import argparse
import struct
import sys
import time

import rclpy
from geometry_msgs.msg import PointStamped, Pose2D, Twist
from rclpy.action import ActionClient, ActionServer
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import MultiThreadedExecutor
from rclpy.lifecycle import LifecycleNode, TransitionCallbackReturn
from rclpy.node import Node
from rclpy.qos import qos_profile_services_default
from rclpy.service_introspection import ServiceIntrospectionState
from sensor_msgs.msg import BatteryState, JointState, LaserScan
from std_msgs.msg import Bool, Float32, UInt8
from std_srvs.srv import SetBool
from test_msgs.action import Fibonacci

DEFECTS = {
    "guard_last_beam": "ObstacleGuard ignores the scan's last beam",
    "charge_lt": "ChargeMonitor compares with < where the contract says <= (float32 0.2)",
    "limiter_first_five": "JointLimiter checks the first five joints of six",
    "governor_cap": "SpeedGovernor caps at 1.2 m/s",
    "docking_threshold": "Docking engages below 0.25 m, not 0.3 m",
    "estop_always": "EStop answers 'engaged' to every call",
    "arm_spoilt": "Arm's result ends with a negative step",
}
F32 = lambda v: struct.unpack("f", struct.pack("f", v))[0]  # noqa: E731 - a float32 field's value
SCANS = [[2.0] * 8, [2.0, 0.4] + [2.0] * 6, [2.0] * 7 + [0.3], [0.5] * 8, [1.0, 2.0, 0.45, 2.0, 2.0, 2.0, 2.0, 2.0]]
CHARGES = [0.55, 0.21, 0.2, 0.19, 0.2, 0.35]
JOINTS = [[0.1, 0.5, 1.0, 1.5, 2.0, 2.4], [0.1, 0.5, 1.0, 1.5, 2.0, 2.6], [2.6, 0.5, 1.0, 1.5, 2.0, 2.4]]
SPEEDS = [0.5, 1.0, 1.1, 0.0, 2.0]
RANGES = [0.5, 0.3, 0.29, 0.2, 0.26]


class Battery(LifecycleNode):
    """The lifecycle battery: its publisher exists once configured and publishes only while active."""

    def __init__(self):
        super().__init__("battery")
        self.pub = None

    def on_configure(self, state):
        self.pub = self.create_lifecycle_publisher(BatteryState, "battery", 100)
        return TransitionCallbackReturn.SUCCESS


def build(defects):
    """The nodes, their callbacks and the drivers' publishers and clients."""
    def bad(name):
        return name in defects
    nodes = {n: Node(n) for n in ("lidar", "obstacle_guard", "charge_monitor", "joint_driver", "joint_limiter",
                                  "teleop", "speed_governor", "ranger", "docking", "pose_source", "planner",
                                  "estop", "operator", "arm", "mission")}
    battery = Battery()
    out = {}

    def pub(node, typ, topic):
        out[topic] = nodes[node].create_publisher(typ, topic, 100)
        return out[topic]
    pub("lidar", LaserScan, "scan")
    obstacle = pub("obstacle_guard", Bool, "obstacle")
    nodes["obstacle_guard"].create_subscription(LaserScan, "scan", lambda m: obstacle.publish(Bool(data=any(
        r < 0.5 for r in (m.ranges[:-1] if bad("guard_last_beam") else m.ranges)))), 100)
    low = pub("charge_monitor", Bool, "low")
    limit = F32(0.2)  # the contract's 0.2 as the float32 field carries it
    nodes["charge_monitor"].create_subscription(BatteryState, "battery", lambda m: low.publish(Bool(
        data=(m.percentage < limit) if bad("charge_lt") else (m.percentage <= limit))), 100)
    pub("joint_driver", JointState, "joint_states")
    ok = pub("joint_limiter", Bool, "joints_ok")
    nodes["joint_limiter"].create_subscription(JointState, "joint_states", lambda m: ok.publish(Bool(data=all(
        q <= 2.5 for q in (m.position[:5] if bad("limiter_first_five") else m.position)))), 100)
    pub("teleop", Twist, "cmd_in")
    cmd = pub("speed_governor", Twist, "cmd_vel")
    cap = 1.2 if bad("governor_cap") else 1.0

    def govern(m):
        t = Twist()
        t.linear.x = min(m.linear.x, cap)
        cmd.publish(t)
    nodes["speed_governor"].create_subscription(Twist, "cmd_in", govern, 100)
    pub("ranger", Float32, "dock_range")
    dock = pub("docking", UInt8, "dock_cmd")
    near = F32(0.25) if bad("docking_threshold") else F32(0.3)
    nodes["docking"].create_subscription(Float32, "dock_range", lambda m: dock.publish(UInt8(
        data=1 if m.data < near else 0)), 100)
    pub("pose_source", Pose2D, "pose")
    traj = pub("planner", PointStamped, "traj")

    def plan(m):
        p = PointStamped()
        p.header.stamp = nodes["planner"].get_clock().now().to_msg()  # stamped when published
        p.point.x = m.x
        traj.publish(p)
    nodes["planner"].create_subscription(Pose2D, "pose", plan, 100)

    def estop(req, resp):
        resp.success = True if bad("estop_always") else req.data
        return resp
    server = nodes["estop"].create_service(SetBool, "estop", estop)
    client = nodes["operator"].create_client(SetBool, "estop")

    def execute(goal):
        seq = [0, 1]
        for i in range(1, goal.request.order):
            seq.append(seq[i] + seq[i - 1])
            goal.publish_feedback(Fibonacci.Feedback(sequence=seq))
            time.sleep(0.01)
        goal.succeed()
        return Fibonacci.Result(sequence=seq + [-1] if bad("arm_spoilt") else seq)
    arm = ActionServer(nodes["arm"], Fibonacci, "arm", execute, callback_group=ReentrantCallbackGroup())
    mission = ActionClient(nodes["mission"], Fibonacci, "arm")
    for who, end in (("estop", server), ("operator", client), ("arm", arm), ("mission", mission)):
        end.configure_introspection(nodes[who].get_clock(), qos_profile_services_default,
                                    ServiceIntrospectionState.CONTENTS)
    return nodes, battery, out, client, mission


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--defects", default="", help="'all' or a comma-separated list of: " + ", ".join(DEFECTS))
    ap.add_argument("--monitors", type=int, default=1, help="verdict publishers to wait for")
    ap.add_argument("--rounds", type=int, default=40)
    a = ap.parse_args(argv)
    defects = set(DEFECTS) if a.defects == "all" else {d for d in a.defects.split(",") if d}
    unknown = defects - set(DEFECTS)
    if unknown:
        ap.error(f"unknown defect(s): {', '.join(sorted(unknown))}")
    rclpy.init()
    nodes, battery, out, client, mission = build(defects)
    ex = MultiThreadedExecutor(num_threads=4)
    for n in [*nodes.values(), battery]:
        ex.add_node(n)

    def spin(seconds):
        until = time.monotonic() + seconds
        while (left := until - time.monotonic()) > 0:
            ex.spin_once(timeout_sec=min(left, 0.05))  # returns as soon as a callback is ready

    def done(fut, timeout=5.0):
        until = time.monotonic() + timeout
        while (left := until - time.monotonic()) > 0 and not fut.done():
            ex.spin_once(timeout_sec=min(left, 0.05))
        return fut.result() if fut.done() else None
    battery.trigger_configure()
    battery.trigger_activate()
    print("ready", flush=True)
    watch = nodes["operator"]
    until = time.monotonic() + 40
    while time.monotonic() < until and (watch.count_publishers("/rclverify/verdict") < a.monitors
                                       or not client.service_is_ready() or not mission.server_is_ready()):
        spin(0.05)
    spin(1.5)  # the monitors' readers match the publishers one by one
    print("rounds", flush=True)
    clock = nodes["lidar"].get_clock()
    for k in range(a.rounds):
        scan = LaserScan(ranges=SCANS[k % len(SCANS)], range_max=30.0)
        scan.header.stamp = clock.now().to_msg()  # stamped at acquisition
        out["scan"].publish(scan)
        battery.pub.publish(BatteryState(percentage=CHARGES[k % len(CHARGES)]))
        js = JointState(name=[f"j{i}" for i in range(6)], position=JOINTS[k % len(JOINTS)])
        js.header.stamp = clock.now().to_msg()
        out["joint_states"].publish(js)
        t = Twist()
        t.linear.x = SPEEDS[k % len(SPEEDS)]
        out["cmd_in"].publish(t)
        out["dock_range"].publish(Float32(data=RANGES[k % len(RANGES)]))
        out["pose"].publish(Pose2D(x=float(k) / 4))
        spin(0.15)  # rounds further apart than a loaded machine delays an answer (docs/semantics.md, "Event time")
    answers = []
    for engage in (True, False, True, False, False, True):
        r = done(client.call_async(SetBool.Request(data=engage)))
        answers.append(None if r is None else r.success)
    finals = []
    for order in (3, 5, 6):
        handle = done(mission.send_goal_async(Fibonacci.Goal(order=order)))
        res = done(handle.get_result_async()) if handle is not None and handle.accepted else None
        finals.append(None if res is None else list(res.result.sequence)[-1])
    spin(1.5)  # the last answers reach the monitors, and their horizon (1 s) passes
    print("estop", answers, "arm", finals, flush=True)
    print("done", flush=True)
    while rclpy.ok():
        ex.spin_once(timeout_sec=0.1)


if __name__ == "__main__":
    try:
        sys.exit(main())
    except KeyboardInterrupt:
        sys.exit(0)
