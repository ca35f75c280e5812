"""The case study's Radiation Sensor as a rospy node, and a replay of a bundled
run as a rospy publisher: what the live monitor's test and benchmark watch.

    python3 scripts/ros1_case_study.py sensor [--misclassify] [--heard-by N]
    python3 scripts/ros1_case_study.py replay RUN.jsonl [--rate K] [--skip TOPIC ...]
    python3 scripts/ros1_case_study.py listen TOPIC --out FILE [--count N]

``sensor`` runs the bundled Python Radiation Sensor
(``backends/property_tests/radiation_sensor.py``, the function the
property tests check) on ``/command`` and ``/r`` and publishes
``/inspected`` and ``/radiationStatus``; ``--misclassify`` injects the
fault of the ``sensor_fault`` run (a reading of 250 or more reported
``orange`` instead of ``red``); with ``--heard-by N`` it prints ``outputs heard
by N`` once both its publishers have N subscribers connected (TCPROS links
are made after a subscriber registers, so a run waits for this line before
it sends readings whose answers a monitor must hear).  ``replay`` publishes the messages of a
ROSMonitoring log at their recorded times divided by ``--rate``, leaving out
the ``--skip`` topics (those a live node produces), after waiting for
``--wait-for`` subscribers on every topic.  All topics carry
``gazebo_radiation_plugin/Snapshot`` from the workspace's ``.msg`` file
(generated with genpy at run time, docs/monitors.md).  ``listen`` writes
each ``std_msgs/String`` message of TOPIC (the live monitor's verdicts) as a
JSON line ``{"received": ROS time, "data": ...}``, flushed at once, until
SIGINT/SIGTERM or ``--count`` messages.  ROS_MASTER_URI says which master;
each stops at SIGINT/SIGTERM or when done.
"""
from __future__ import annotations

import argparse
import importlib.util
import json
import sys
import threading
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
MSG_DIRS = [ROOT / "backends" / "monitors" / "msg"]
SNAPSHOT = "gazebo_radiation_plugin/Snapshot"


def _sensor_function() -> Any:
    spec = importlib.util.spec_from_file_location("radiation_sensor", ROOT / "backends/property_tests/radiation_sensor.py")
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod.radiation_sensor


def sensor(misclassify: bool, heard_by: int = 0) -> int:
    from rclverify.runtime.ros1 import import_rospy, message_class
    from rclverify.semantics.values import Term
    rospy = import_rospy()
    Snapshot = message_class(SNAPSHOT, MSG_DIRS)
    step = _sensor_function()
    rospy.init_node("radiation_sensor", anonymous=True)
    status = rospy.Publisher("/radiationStatus", Snapshot, queue_size=100)
    inspected = rospy.Publisher("/inspected", Snapshot, queue_size=100)
    command: list[Any] = [Term("move", (0.0, 0.0))]

    def on_command(msg: Any) -> None:
        command[0] = Term("inspect", (int(msg.id),)) if msg.command == "inspect" else Term("move", (msg.posx, msg.posy))

    def on_reading(msg: Any) -> None:
        out = step(r=msg.value, command=command[0])
        level = out["radiationStatus"]
        if misclassify and msg.value >= 250:
            level = "orange"  # the injected fault
        for (i,), v in sorted(out["inspected"].table.items()):
            if v:
                inspected.publish(Snapshot(id=i))
        status.publish(Snapshot(level=level))

    rospy.Subscriber("/command", Snapshot, on_command, queue_size=100)
    rospy.Subscriber("/r", Snapshot, on_reading, queue_size=100)
    print("radiation sensor ready", flush=True)
    if heard_by:
        def say_heard() -> None:
            while min(status.get_num_connections(), inspected.get_num_connections()) < heard_by:
                if rospy.is_shutdown():
                    return
                time.sleep(0.05)
            print(f"outputs heard by {heard_by}", flush=True)
        threading.Thread(target=say_heard, daemon=True).start()
    rospy.spin()
    return 0


def listen(topic: str, out: Path, count: int) -> int:
    from rclverify.runtime.ros1 import import_rospy
    rospy = import_rospy()
    from std_msgs.msg import String
    rospy.init_node("verdict_listener", anonymous=True)
    got = [0]
    with out.open("w", encoding="utf-8") as fh:
        def on_msg(msg: Any) -> None:
            fh.write(json.dumps({"received": rospy.get_time(), "data": json.loads(msg.data)}) + "\n")
            fh.flush()
            got[0] += 1
            if count and got[0] >= count:
                rospy.signal_shutdown("enough")
        rospy.Subscriber(topic, String, on_msg, queue_size=10000)
        print(f"listening on {topic}", flush=True)
        rospy.spin()
    return 0


def replay(run: Path, rate: float, skip: set[str], wait_for: int, timeout: float,
           need: dict[str, int] | None = None) -> int:
    from rclverify.runtime.ros1 import build_message, import_rospy, message_class
    rospy = import_rospy()
    Snapshot = message_class(SNAPSHOT, MSG_DIRS)
    events = [json.loads(line) for line in run.read_text().splitlines() if line.strip()]
    events = [e for e in events if e["topic"].lstrip("/") not in skip]
    rospy.init_node("replay", anonymous=True)
    pubs = {t: rospy.Publisher("/" + t, Snapshot, queue_size=1000) for t in sorted({e["topic"].lstrip("/") for e in events})}
    deadline = time.monotonic() + timeout
    need = need or {}
    while any(p.get_num_connections() < need.get(t, wait_for) for t, p in pubs.items()):
        if time.monotonic() > deadline or rospy.is_shutdown():
            print("replay: error: subscribers did not connect in time", file=sys.stderr)
            return 2
        time.sleep(0.05)
    time.sleep(0.3)  # let the subscribers' side of each connection settle
    start, t0 = time.monotonic(), events[0]["time"] if events else 0.0
    for e in events:
        wait = start + (e["time"] - t0) / rate - time.monotonic()
        if wait > 0:
            time.sleep(wait)
        pubs[e["topic"].lstrip("/")].publish(build_message(Snapshot, e))
    print(f"replayed {len(events)} message(s)", flush=True)
    time.sleep(0.3)
    return 0


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="what", required=True)
    s = sub.add_parser("sensor")
    s.add_argument("--misclassify", action="store_true")
    s.add_argument("--heard-by", type=int, default=0, help="say when both outputs have this many subscribers")
    r = sub.add_parser("replay")
    r.add_argument("run", type=Path)
    r.add_argument("--rate", type=float, default=1.0)
    r.add_argument("--skip", nargs="*", default=[])
    r.add_argument("--wait-for", type=int, default=1, help="subscribers each topic needs before the replay starts")
    r.add_argument("--need", nargs="*", default=[], metavar="TOPIC=N", help="subscribers a topic needs (overrides --wait-for)")
    r.add_argument("--timeout", type=float, default=20.0)
    li = sub.add_parser("listen")
    li.add_argument("topic")
    li.add_argument("--out", type=Path, required=True)
    li.add_argument("--count", type=int, default=0)
    a = p.parse_args()
    if a.what == "sensor":
        return sensor(a.misclassify, a.heard_by)
    if a.what == "listen":
        return listen(a.topic, a.out, a.count)
    need = {t: int(n) for t, _, n in (x.partition("=") for x in a.need)}
    return replay(a.run, a.rate, set(a.skip), a.wait_for, a.timeout, need)


if __name__ == "__main__":
    sys.exit(main())
