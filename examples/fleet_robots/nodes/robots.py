"""The two-robot fleet as real ROS 2 nodes (rclpy), all in one process; run in a ROS 2 Python
(rclpy and std_msgs; no rclverify): ``python robots.py [--slip] [--steps N]``.

The fleet's ``speed_limit`` runs at the root and publishes ``/fleet/speed_limit``; each robot
``/r1`` and ``/r2`` runs a ``planner`` (``cmd_raw``), a ``battery`` (``battery/level``) and a
``guard`` that subscribes to both and to the fleet's limit and publishes ``cmd_vel``: every name
relative, so that each resolves in its robot's namespace.  The logic is ``logic.py``'s, the
functions the property tests check; ``/r2``'s battery runs 45 steps ahead of ``/r1``'s, so that
the two are low at different times.  ``--slip`` runs ``/r2``'s guard with the absolute name
``/r1/battery/level`` (a name copied from the other robot): it reads the other robot's battery.

Prints ``ready`` once the nodes exist, publishes one round every 0.1 s (the limit and the
batteries' levels, then, 50 ms later, once the guards have heard them, the planners' commands) (``--steps`` rounds, 0:
until stopped; with ``--readers N``, first until each topic has N readers besides the fleet's own,
as a monitor's), prints ``done`` once the guards have answered the last, and spins until SIGINT or SIGTERM.
"""
import argparse
import signal
import sys
import time
from pathlib import Path

import rclpy
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.node import Node
from std_msgs.msg import Float64

sys.path.insert(0, str(Path(__file__).resolve().parent))
from logic import Battery, Planner, guard, speed_limit  # noqa: E402

PERIOD = 0.1


def robot(ns, battery_topic, ex, charged):
    """One robot's nodes under ``ns``, its battery ``charged`` steps into its cycle; returns its
    round's two halves: publish the battery's level, publish the planner's command."""
    planner_node, battery_node, guard_node = (Node(n, namespace=ns) for n in ("planner", "battery", "guard"))
    raw = planner_node.create_publisher(Float64, "cmd_raw", 10)
    level = battery_node.create_publisher(Float64, "battery/level", 10)
    cmd = guard_node.create_publisher(Float64, "cmd_vel", 10)
    seen = {"cmd_raw": 0.0, "level": 1.0, "limit": 0.0}
    heard = {"level": 0, "answered": 0}

    def on(key):
        def cb(msg):
            seen[key] = msg.data
            heard[key] = heard.get(key, 0) + 1
            if key == "cmd_raw":  # one command per planner message
                cmd.publish(Float64(data=float(guard(**seen)["cmd_vel"])))
                heard["answered"] += 1
        return cb
    guard_node.create_subscription(Float64, "cmd_raw", on("cmd_raw"), 10)
    guard_node.create_subscription(Float64, battery_topic, on("level"), 10)
    guard_node.create_subscription(Float64, "/fleet/speed_limit", on("limit"), 10)
    for n in (planner_node, battery_node, guard_node):
        ex.add_node(n)
    plan, bat = Planner(), Battery()
    for _ in range(charged):
        bat.step()

    def first():
        level.publish(Float64(data=float(bat.step()["level"])))
        return heard["level"]

    def then():
        raw.publish(Float64(data=float(plan.step()["cmd_raw"])))
    return first, then, lambda: heard["level"], lambda: heard["answered"]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--slip", action="store_true", help="/r2's guard reads /r1/battery/level")
    ap.add_argument("--steps", type=int, default=0)
    ap.add_argument("--readers", type=int, default=0, help="wait for this many readers of each topic besides the fleet's")
    args = ap.parse_args()
    rclpy.init()
    ex = SingleThreadedExecutor()
    limit_node = Node("speed_limit")
    limit = limit_node.create_publisher(Float64, "/fleet/speed_limit", 10)
    ex.add_node(limit_node)
    rounds = [robot("/r1", "battery/level", ex, 0),
              robot("/r2", "/r1/battery/level" if args.slip else "battery/level", ex, 45)]
    stop = []
    signal.signal(signal.SIGTERM, lambda *_: stop.append(1))
    print("ready", flush=True)
    if args.readers:  # every endpoint matched: the monitor's readers and the guards'
        own = {"/fleet/speed_limit": 2, "/r1/cmd_raw": 1, "/r2/cmd_raw": 1, "/r1/battery/level": 2 if args.slip else 1,
               "/r2/battery/level": 0 if args.slip else 1}  # the guards' readers of each topic
        pubs = [p for n in ex.get_nodes() for p in n.publishers if p.topic_name in own or p.topic_name.endswith("/cmd_vel")]
        until = time.monotonic() + 60
        while time.monotonic() < until and not stop and not all(
                p.get_subscription_count() >= args.readers + own.get(p.topic_name, 0) for p in pubs):
            ex.spin_once(timeout_sec=0.05)
        time.sleep(0.5)
    t0, k = time.monotonic(), 0
    try:
        while not stop:
            if not args.steps or k < args.steps:
                limit.publish(Float64(data=float(speed_limit()["limit"])))
                before = [first() for first, _, _, _ in rounds]
                # the guards hear the levels (at most 1 s) before the planners' commands they answer
                until = time.monotonic() + 1.0
                while (time.monotonic() < t0 + PERIOD * (k + 0.5) or any(
                        heard() <= b for (_, _, heard, _), b in zip(rounds, before))) \
                        and time.monotonic() < until and not stop:
                    ex.spin_once(timeout_sec=0.01)
                for _, then, _, _ in rounds:
                    then()
                k += 1
                if k == args.steps:  # done once each guard has answered the last command (at most 1 s)
                    until = time.monotonic() + 1.0
                    while any(answered() < k for *_, answered in rounds) and time.monotonic() < until and not stop:
                        ex.spin_once(timeout_sec=0.01)
                    print("done", flush=True)
            while time.monotonic() < t0 + PERIOD * k and not stop:
                ex.spin_once(timeout_sec=0.01)
            if args.steps and k >= args.steps:
                ex.spin_once(timeout_sec=0.1)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        ex.shutdown()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
