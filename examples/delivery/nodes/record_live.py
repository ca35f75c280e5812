"""Record the delivery robot's run from real ROS 2 nodes: its nine nodes
and the scenario run as rclpy processes (``nodes/ros2_nodes.py``) on ROS 2's
default middleware (rmw_fastrtps_cpp, Fast DDS) while ``rclverify monitor
--live --ros2 --record`` watches the bus, records the contract topics to an
MCAP bag and writes its log (docs/monitors.md, "ROS 2 over DDS").
Everything stays on this host: the nodes discover on localhost only
(``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST``), the monitor's Cyclone DDS
uses the loopback interface, and the domain is a random one.

Run it with the project's Python (the one rclverify and rosbags are
installed in), from the example's folder::

    python3 nodes/record_live.py [--ros2-python PATH] [--keep DIR]

It writes ``backends/monitors/live/``: ``run/``, the monitor's bag as it
wrote it (the topics' messages, their bytes as they came off the wire, at
the times it received them), and ``monitor.jsonl``, its log (messages,
verdicts, and the calls of the service and the action as
``rclverify/call`` lines: the bag has no calls); and the plan's trace
``backends/monitors/traces/run/`` made from both by :func:`make_trace`:
the bag's messages as they are, and each call's parts as messages of
topics of their own (``get_route/request`` ... ``deliver/result``, as the
simulator writes them and the plan's mapping reads them).

The ROS 2 Python is ``--ros2-python``, else ``$RCLVERIFY_ROS2_PYTHON``, else
the ``.venv-ros2/bin/python`` of the nearest folder above this one (ROS 2's
PyPI wheels, docs/ros2.md).  The interface package ``interfaces/delivery_msgs``
is built with colcon into ``.ros2/`` the first time (half a minute on 2
cores).  Exit 0 with the run's figures; 1 with the reason when a part failed
(the old files are kept then).  ``nodes/record_run.py`` is the simulator
this replaced: it rebuilds the run without ROS 2, on a simulated clock, and
is not the committed run.
"""
from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(HERE.parent))
from ros2_recording import Failed, messages_span, read_log, record as record_run, ros2_python  # noqa: E402

NODES_DIR = "nodes"
NODES = ["GnssDriver", "Localiser", "ObstacleDetector", "LockerController", "RouteServer", "SpeedGovernor",
         "WheelController", "Navigator", "MissionPlanner"]
DRIVER = "scenario"
INTERFACES = ["interfaces/delivery_msgs"]
#: the monitor's bag and log as it wrote them; the plan reads the trace made from them (make_trace)
LIVE = "backends/monitors/live"
MONITOR = ["--mapping", "backends/monitors/mapping.yaml", "--interfaces", "interfaces"]
TIMEOUT = 30.0  # s, the whole recording


def record(py: Path, tmp: Path) -> float:
    """Run the monitor, the nodes and the scenario; the monitor's bag is ``tmp/bag/``, its log
    ``tmp/run.jsonl``.  The run ends with the scenario (its nodes stopped at once: the watchdog
    would go on adding messages).  Returns the seconds it took."""
    return record_run(HERE, py, tmp, interfaces=INTERFACES, nodes=NODES, script=f"{NODES_DIR}/ros2_nodes.py",
                      monitor=[*MONITOR, "--record", str(tmp / "bag"), "--record-storage", "mcap"], driver=DRIVER,
                      timeout=TIMEOUT, until_done=True)


#: an action's goal status as its status lines name it (action_msgs/msg/GoalStatus)
STATUS = {"succeeded": 4, "canceled": 5, "aborted": 6}


def parts_of(log: list[dict[str, Any]]) -> list[tuple[int, str, dict[str, Any]]]:
    """``(time ns, topic, fields)`` of each service or action part the monitor paired with its call
    (a ``rclverify/call`` line with an ``index``), at the part's source stamp, in the form of the
    simulator's topics (record_run.TYPES): a service's parts as they are, an action's goal and
    feedback with their goal's id, its result with the goal's last status."""
    import numpy
    status = {tuple(x["key"]): STATUS.get(x.get("status", ""), 0) for x in log
              if x.get("topic") == "rclverify/call" and x.get("part") == "status"}
    out = []
    for x in log:
        if x.get("topic") != "rclverify/call" or "index" not in x:
            continue
        link, part, fields = x["link"], x["part"], dict(x["fields"])
        if part in ("goal", "feedback"):
            uuid = numpy.frombuffer(bytes.fromhex(x["key"][0]), dtype=numpy.uint8)
            fields = {"goal_id": {"uuid": uuid}, part: fields}
        elif part == "result":
            fields = {"status": status.get(tuple(x["key"]), 0), "result": fields}
        out.append((int(round(float(x["time"]) * 1e9)), f"{link}/{part}", fields))
    return out


def make_trace(live_bag: Path, log: list[dict[str, Any]], out: Path) -> dict[str, int]:
    """The plan's trace ``out`` (a ROS 2 bag directory in MCAP storage, replaced): every message
    of the monitor's bag ``live_bag`` as it is (its bytes, time and type), and the calls' parts of
    its log (:func:`parts_of`) as messages of topics of their own, all in time order.  The offline
    check reads a bag's topics only, and the monitor records no calls in its bag (docs/monitors.md),
    so the service and the action reach the plan's monitors only this way."""
    from rosbags.highlevel import AnyReader
    from rosbags.rosbag2 import StoragePlugin, Writer
    sys.path.insert(0, str(HERE / NODES_DIR))
    from record_run import TYPES, _message, _store  # the simulator's part types
    store = _store()
    rows: list[tuple[int, str, Any]] = []
    with AnyReader([live_bag]) as reader:
        conns = {c.topic: c for c in reader.connections}
        for conn, stamp, raw in reader.messages():
            rows.append((stamp, conn.topic, bytes(raw)))
    parts = parts_of(log)
    for stamp, topic, fields in parts:
        rows.append((stamp, "/" + topic, store.serialize_cdr(_message(store, TYPES[topic], fields), TYPES[topic])))
    if out.exists():
        shutil.rmtree(out)
    with Writer(out, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        made: dict[str, Any] = {}
        for stamp, topic, data in sorted(rows, key=lambda r: r[0]):
            if topic not in made:
                if topic in conns:
                    c = conns[topic]
                    made[topic] = writer.add_connection(topic, c.msgtype, msgdef=c.msgdef.data, rihs01=c.digest)
                else:
                    made[topic] = writer.add_connection(topic, TYPES[topic.lstrip("/")], typestore=store)
            writer.write(made[topic], stamp, data)
    return {"messages": len(rows) - len(parts), "call_parts": len(parts)}


def install(tmp: Path, live: Path, out: Path) -> dict[str, object]:
    """Put the monitor's bag and log under ``live`` (replaced) and make the plan's trace ``out``."""
    log = read_log(tmp / "run.jsonl")
    if (live / "run").exists():
        shutil.rmtree(live / "run")
    live.mkdir(parents=True, exist_ok=True)
    shutil.copytree(tmp / "bag", live / "run")
    shutil.copyfile(tmp / "run.jsonl", live / "monitor.jsonl")
    figures: dict[str, object] = dict(make_trace(live / "run", log, out))
    figures.update(log_lines=len(log), span_s=messages_span(log)[1])
    return figures


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--ros2-python", help="the ROS 2 Python (rclpy, rmw_fastrtps_cpp)")
    ap.add_argument("--keep", help="keep the processes' outputs in this folder (else a temporary one)")
    ap.add_argument("--out", default="backends/monitors/traces/run",
                    help="the plan's trace to write, a bag directory (relative to the example's folder)")
    ap.add_argument("--live", default=LIVE, help="where the monitor's bag and log go (relative to the example's folder)")
    args = ap.parse_args(argv)
    try:
        py = ros2_python(args.ros2_python, HERE)
        with tempfile.TemporaryDirectory(prefix="record_live_") as scratch:
            tmp = Path(args.keep).resolve() if args.keep else Path(scratch)
            tmp.mkdir(parents=True, exist_ok=True)
            shutil.rmtree(tmp / "bag", ignore_errors=True)
            seconds = record(py, tmp)
            figures = install(tmp, HERE / args.live, HERE / args.out)
    except (Failed, OSError, subprocess.SubprocessError) as exc:
        print(f"record_live.py: error: {exc}", file=sys.stderr)
        return 1
    figures["seconds"] = round(seconds, 1)
    print(f"{args.out}: {json.dumps(figures)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
