"""The safety-stop example's nodes as ROS 1 (rospy) processes.

    python3 nodes/ros1_nodes.py base --serve /estop_real [--late-call N --delay S]
    python3 nodes/ros1_nodes.py teleop --call /estop --count N [--every S]
    python3 nodes/ros1_nodes.py mover [--feedback-after S]
    python3 nodes/ros1_nodes.py mission --target M

``base`` serves ``std_srvs/SetBool`` (the estop; its answer is
``logic.base``), answering call number ``--late-call`` only after
``--delay`` seconds (a fault to show a missed deadline).  ``teleop`` calls
the estop service.  ``mover`` is the ``move`` action server on actionlib's
topics (``/move/goal`` in, ``/move/feedback`` and ``/move/result`` out, each
with a header stamp), ``mission`` sends one goal.  The classes come from
``interfaces/`` (rclverify's generators).  Each prints ``ready`` once set up.
"""
from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from logic import base, mover  # noqa: E402

from rclverify.runtime.ros1 import import_rospy  # noqa: E402
from rclverify.runtime.ros1_interfaces import action_classes, service_class  # noqa: E402

INTERFACES = [HERE.parent / "interfaces"]


def _wait_for_subscribers(pub: object, count: int, timeout: float = 10.0) -> None:
    end = time.monotonic() + timeout
    while pub.get_num_connections() < count and time.monotonic() < end:  # type: ignore[attr-defined]
        time.sleep(0.05)


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("role", choices=["base", "teleop", "mover", "mission"])
    ap.add_argument("--serve", default="/estop_real")
    ap.add_argument("--call", default="/estop")
    ap.add_argument("--count", type=int, default=2)
    ap.add_argument("--every", type=float, default=0.5)
    ap.add_argument("--late-call", type=int, default=0, help="1-based call answered late (0: none)")
    ap.add_argument("--delay", type=float, default=0.4)
    ap.add_argument("--feedback-after", type=float, default=0.5)
    ap.add_argument("--target", type=float, default=2.0)
    a = ap.parse_args()
    rospy = import_rospy()
    rospy.init_node(a.role, anonymous=True)
    if a.role == "base":
        srv = service_class("std_srvs/SetBool", INTERFACES)
        calls = [0]

        def handle(req: object) -> object:
            calls[0] += 1
            if calls[0] == a.late_call:
                time.sleep(a.delay)
            resp = srv._response_class()
            resp.success = base(req.data)["stopped"]  # type: ignore[attr-defined]
            return resp
        rospy.Service(a.serve, srv, handle)
        print("ready", flush=True)
        rospy.spin()
    elif a.role == "teleop":
        srv = service_class("std_srvs/SetBool", INTERFACES)
        rospy.wait_for_service(a.call, timeout=30)
        proxy = rospy.ServiceProxy(a.call, srv)
        print("ready", flush=True)
        for _ in range(a.count):
            resp = proxy(True)
            print(f"called: success={resp.success}", flush=True)
            time.sleep(a.every)
    else:
        with tempfile.TemporaryDirectory(prefix="move-") as gen:  # the classes live on without their files
            cls = action_classes("rclverify_examples/Move", INTERFACES, Path(gen))
        if a.role == "mover":
            fb_pub = rospy.Publisher("/move/feedback", cls["feedback"], queue_size=10)
            res_pub = rospy.Publisher("/move/result", cls["result"], queue_size=10)

            def on_goal(msg: object) -> None:
                out = mover(msg.goal.target)  # type: ignore[attr-defined]
                time.sleep(a.feedback_after)
                fb = cls["feedback"]()
                fb.header.stamp = rospy.Time.now()
                fb.status.goal_id = msg.goal_id  # type: ignore[attr-defined]
                fb.status.status = 1  # ACTIVE
                fb.feedback.progress = out["progress"]
                fb_pub.publish(fb)
                res = cls["result"]()
                res.header.stamp = rospy.Time.now()
                res.status.goal_id = msg.goal_id  # type: ignore[attr-defined]
                res.status.status = 3  # SUCCEEDED
                res.result.arrived = True
                res_pub.publish(res)
            rospy.Subscriber("/move/goal", cls["goal"], on_goal)
            print("ready", flush=True)
            rospy.spin()
        else:
            pub = rospy.Publisher("/move/goal", cls["goal"], queue_size=10)
            _wait_for_subscribers(pub, 2)
            time.sleep(0.3)
            goal = cls["goal"]()
            goal.header.stamp = rospy.Time.now()
            goal.goal_id.stamp = goal.header.stamp
            goal.goal_id.id = f"mission-{time.time():.3f}"
            goal.goal.target = a.target
            pub.publish(goal)
            print("ready", flush=True)
            time.sleep(1.0)
    return 0


if __name__ == "__main__":
    sys.exit(main())
