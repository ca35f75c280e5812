"""Record the warehouse robot's run from real ROS 2 nodes: its seven nodes
and the scenario run as rclpy processes (``nodes/ros2_nodes.py``) on ROS 2's
default middleware (rmw_fastrtps_cpp, Fast DDS) while ``rclverify monitor
--live --ros2`` watches the bus and writes its log (docs/monitors.md, "ROS 2
over DDS").  Everything stays on this host: the nodes discover on localhost
only (``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST``), the monitor's Cyclone
DDS uses the loopback interface, and the domain is a random one.

Run it with the project's Python (the one rclverify is installed in), from
the example's folder::

    python3 nodes/record_live.py [--ros2-python PATH] [--keep DIR]

It writes two files: ``backends/monitors/live/monitor.jsonl``, the
monitor's log as it wrote it (messages, verdicts, the calls of the service
and the action as ``rclverify/call`` lines), and the plan's trace
``backends/monitors/traces/run.jsonl`` made from it by :func:`trace_of`
(the messages, and each call's parts as ``get_limits/request`` ...
``navigate/result`` lines, which the plan's mapping reads).

The ROS 2 Python is ``--ros2-python``, else ``$RCLVERIFY_ROS2_PYTHON``, else
the ``.venv-ros2/bin/python`` of the nearest folder above this one (ROS 2's
PyPI wheels, docs/ros2.md).  The interface package
``interfaces/warehouse_msgs`` is built with colcon into ``.ros2/`` the first
time (half a minute on 2 cores).  Exit 0 with the run's figures; 1 with the
reason when a part failed (the old files are kept then).
``nodes/record_run.py`` is the simulator this replaced: it rebuilds the run
without ROS 2, on a simulated clock, and is not the committed run.
"""
from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(HERE.parent))
from ros2_recording import Failed, messages_span, read_log, record as record_run, ros2_python, write_atomic  # noqa: E402,E501

NODES_DIR = "nodes"
NODES = ["LidarDriver", "Localiser", "BatteryMonitor", "Base", "Planner", "Controller", "MissionManager"]
DRIVER = "scenario"
INTERFACES = ["interfaces/warehouse_msgs"]
ACTIONS = {"navigate"}
#: the monitor's log as it wrote it; the plan reads the trace made from it (trace_of)
LIVE_LOG = "backends/monitors/live/monitor.jsonl"
MONITOR = ["--mapping", "backends/monitors/mapping.yaml", "--interfaces", "interfaces"]
TIMEOUT = 30.0  # s, the whole recording


def record(py: Path, tmp: Path, out: Path, live_out: Path) -> dict[str, object]:
    seconds = record_run(HERE, py, tmp, interfaces=INTERFACES, nodes=NODES, script=f"{NODES_DIR}/ros2_nodes.py",
                         monitor=MONITOR, driver=DRIVER, timeout=TIMEOUT)
    lines = read_log(tmp / "run.jsonl")
    messages, span = messages_span(lines)
    trace = trace_of(lines, ACTIONS)
    write_atomic(live_out, (tmp / "run.jsonl").read_text())
    write_atomic(out, "".join(json.dumps(x) + "\n" for x in trace))
    return {"log_lines": len(lines), "trace_lines": len(trace), "messages": messages,
            "call_parts": len(trace) - messages, "span_s": span, "seconds": round(seconds, 1)}


#: an action's parts as the plan's mapping and the offline engine read them (actionlib's wrapped form)
WRAPPED = {"goal": "goal", "feedback": "feedback", "result": "result"}


def trace_of(log: list[dict[str, object]], actions: set[str]) -> list[dict[str, object]]:
    """The plan's trace from the live monitor's log: its message lines as they are, and for each
    service or action part it paired with its call (a ``rclverify/call`` line with an ``index``) a
    line ``<link>/<part>`` with the part's fields at the part's source stamp (an action's parts
    wrapped: ``{"goal": {...}}``), all in time order; verdicts, status and tick lines left out.
    The offline check skips the log's call lines (docs/monitors.md), so the services and the
    action reach the plan's monitors only this way."""
    out = [x for x in log if not str(x.get("topic", "")).startswith("rclverify/")]
    for x in log:
        if x.get("topic") == "rclverify/call" and "index" in x:
            link, part, fields = str(x["link"]), str(x["part"]), dict(x["fields"])  # type: ignore[call-overload]
            body = {WRAPPED[part]: fields} if link in actions else fields
            out.append({"topic": f"{link}/{part}", "time": x["time"], **body})
    return sorted(out, key=lambda x: float(x["time"]))  # type: ignore[arg-type]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--ros2-python", help="the ROS 2 Python (rclpy, rmw_fastrtps_cpp)")
    ap.add_argument("--keep", help="keep the processes' outputs in this folder (else a temporary one)")
    ap.add_argument("--out", default="backends/monitors/traces/run.jsonl",
                    help="the plan's trace to write (relative to the example's folder)")
    ap.add_argument("--live-log", default=LIVE_LOG, help="the monitor's log to write (relative to the example's folder)")
    args = ap.parse_args(argv)
    try:
        py = ros2_python(args.ros2_python, HERE)
        if args.keep:
            Path(args.keep).mkdir(parents=True, exist_ok=True)
            figures = record(py, Path(args.keep).resolve(), HERE / args.out, HERE / args.live_log)
        else:
            with tempfile.TemporaryDirectory(prefix="record_live_") as tmp:
                figures = record(py, Path(tmp), HERE / args.out, HERE / args.live_log)
    except (Failed, OSError, subprocess.SubprocessError) as exc:
        print(f"record_live.py: error: {exc}", file=sys.stderr)
        return 1
    print(f"{args.out}: {json.dumps(figures)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
