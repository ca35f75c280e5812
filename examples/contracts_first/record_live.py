"""Record ``runs/run.jsonl`` from real ROS 2 nodes: the thermostat's two
nodes and its probe run as rclpy processes (``ros2_nodes.py``) on ROS 2's
default middleware (rmw_fastrtps_cpp, Fast DDS) while ``rclverify monitor
--live --ros2`` watches the bus and writes its log (docs/monitors.md, "ROS 2
over DDS").  Everything stays on this host: the nodes discover on localhost
only (``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST``), the monitor's Cyclone
DDS uses the loopback interface, and the domain is a random one.

Run it with the project's Python (the one rclverify is installed in)::

    python3 record_live.py [--ros2-python PATH] [--out runs/run.jsonl]

The ROS 2 Python is ``--ros2-python``, else ``$RCLVERIFY_ROS2_PYTHON``, else
the ``.venv-ros2/bin/python`` of the nearest folder above this one (ROS 2's
PyPI wheels, docs/ros2.md).  The interface package ``gen/thermo_msgs`` is
built with colcon into ``.ros2/`` the first time (a few seconds).  Exit 0
with the log's figures; 1 with the reason when a part failed (the old log is
kept then).  ``record_run.py`` is the simulator this replaced: it rebuilds
the run without ROS 2, on a simulated clock, and is not the committed run.
"""
from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))
from ros2_recording import Failed, messages_span, read_log, record as record_run, ros2_python  # noqa: E402

NODES = ["TempSensor", "HeaterControl"]
DRIVER = "probe"
INTERFACES = ["gen/thermo_msgs"]
MONITOR = ["--mapping", "gen/rclverify_mapping.yaml", "--interfaces", "gen"]
TIMEOUT = 30.0  # s, the whole recording


def record(py: Path, tmp: Path, out: Path) -> dict[str, object]:
    seconds = record_run(HERE, py, tmp, interfaces=INTERFACES, nodes=NODES, script="ros2_nodes.py", monitor=MONITOR,
                         driver=DRIVER, timeout=TIMEOUT)
    lines = read_log(tmp / "run.jsonl")
    messages, span = messages_span(lines)
    out.parent.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(tmp / "run.jsonl", out.with_suffix(".tmp"))
    out.with_suffix(".tmp").replace(out)
    return {"lines": len(lines), "messages": messages, "calls": sum(x.get("kind") == "call" for x in lines),
            "span_s": span, "seconds": round(seconds, 1)}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--ros2-python", help="the ROS 2 Python (rclpy, rmw_fastrtps_cpp)")
    ap.add_argument("--keep", help="keep the processes' outputs in this folder (else a temporary one)")
    ap.add_argument("--out", default="runs/run.jsonl", help="the log to write (relative to this folder)")
    args = ap.parse_args(argv)
    try:
        py = ros2_python(args.ros2_python, HERE)
        if args.keep:
            Path(args.keep).mkdir(parents=True, exist_ok=True)
            figures = record(py, Path(args.keep).resolve(), HERE / args.out)
        else:
            with tempfile.TemporaryDirectory(prefix="record_live_") as tmp:
                figures = record(py, Path(tmp), HERE / args.out)
    except (Failed, OSError, subprocess.SubprocessError) as exc:
        print(f"record_live.py: error: {exc}", file=sys.stderr)
        return 1
    print(f"{args.out}: {json.dumps(figures)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
