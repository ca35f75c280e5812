"""Record live runs of the fleet_trials example from real ROS 2 nodes: the
speed governor and a planner run as rclpy processes (``nodes/ros2_nodes.py``)
on ROS 2's default middleware (rmw_fastrtps_cpp, Fast DDS) while ``rclverify
monitor --live --ros2`` watches the bus and writes one log per run
(docs/monitors.md, "ROS 2 over DDS"; docs/statistics.md).  Everything stays
on this host: localhost discovery, the monitor's Cyclone DDS on the loopback
interface, a random domain per run.

Run it with the project's Python (the one rclverify is installed in)::

    python3 record_live.py [--runs 5] [--ros2-python PATH] [--out runs/lab_bench]

Run ``k`` is ``<out>/lab_bench_<k>.jsonl``; its planner draws its requests
with seed ``k``.  The ROS 2 Python is found as ``examples/ros2_recording.py``
finds it.  Exit 0 with each log's figures; 1 with the reason when a part
failed (the logs already written are kept).
"""
from __future__ import annotations

import argparse
import json
import os
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))
from ros2_recording import (CYCLONE, Failed, messages_span, read_log, ros2_python, start, stop,  # noqa: E402
                            wait_for)

TIMEOUT = 40.0  # s, one run


def record_one(py: Path, tmp: Path, seed: int, out: Path) -> dict[str, object]:
    """One run: the monitor, the governor, the planner with ``seed``; the log copied to ``out``."""
    (tmp / "cyclonedds.xml").write_text(CYCLONE)
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONSTARTUP")}
    env.update(CYCLONEDDS_URI=(tmp / "cyclonedds.xml").as_uri(), ROS_DOMAIN_ID=str(random.randint(1, 230)),
               ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST", RMW_IMPLEMENTATION="rmw_fastrtps_cpp",
               PYTHONUNBUFFERED="1", ROS_LOG_DIR=str(tmp / "ros_log"))
    procs: list[subprocess.Popen[bytes]] = []
    t0 = time.monotonic()
    try:
        mon = start([sys.executable, "-m", "rclverify.cli.commands", "monitor", "-w", ".", "--live", "--ros2",
                     "--reorder-window", "0", "--status", "0", "--silence", "0", "--duration", str(TIMEOUT),
                     "--log", str(tmp / "run.jsonl"), "--evidence", str(tmp / "evidence.json")],
                    env, tmp / "monitor.out", HERE)
        procs.append(mon)
        wait_for(tmp / "monitor.out", "monitoring", 20, mon)
        gov = start([str(py), "nodes/ros2_nodes.py", "SpeedGovernor"], env, tmp / "governor.out", HERE)
        procs.append(gov)
        wait_for(tmp / "governor.out", "ready", 20, gov)
        drv = start([str(py), "nodes/ros2_nodes.py", "planner", str(seed)], env, tmp / "planner.out", HERE)
        procs.append(drv)
        drv.wait(max(1.0, TIMEOUT - (time.monotonic() - t0)))
        if drv.returncode != 0:
            raise Failed("the planner failed:\n" + (tmp / "planner.out").read_text(errors="replace")[-2000:])
        time.sleep(0.5)  # the last answers reach the monitor
        stop(mon, signal.SIGINT)
        if mon.returncode not in (0, 1):
            raise Failed("the monitor failed:\n" + (tmp / "monitor.out").read_text(errors="replace")[-2000:])
    except subprocess.TimeoutExpired:
        raise Failed(f"not done within {TIMEOUT} s") from None
    finally:
        for p in reversed(procs):
            stop(p)
    lines = read_log(tmp / "run.jsonl")
    messages, span = messages_span(lines)
    out.parent.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(tmp / "run.jsonl", out.with_suffix(".tmp"))
    out.with_suffix(".tmp").replace(out)
    counted = json.loads((tmp / "evidence.json").read_text())["nodes"][0].get("statistics", {})
    return {"lines": len(lines), "messages": messages, "span_s": span, "answers": counted.get("answers"),
            "violations": counted.get("violations"), "seconds": round(time.monotonic() - t0, 1)}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--ros2-python", help="the ROS 2 Python (rclpy, rmw_fastrtps_cpp)")
    ap.add_argument("--runs", type=int, default=5, help="how many runs to record")
    ap.add_argument("--out", default="runs/lab_bench", help="the folder of the logs (relative to this folder)")
    args = ap.parse_args(argv)
    try:
        py = ros2_python(args.ros2_python, HERE)
        for k in range(args.runs):
            out = HERE / args.out / f"lab_bench_{k:03d}.jsonl"
            with tempfile.TemporaryDirectory(prefix="record_live_") as tmp:
                figures = record_one(py, Path(tmp), k, out)
            print(f"{out}: {json.dumps(figures)}", flush=True)
    except (Failed, OSError, subprocess.SubprocessError, ValueError, KeyError) as exc:
        print(f"record_live.py: error: {exc}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
