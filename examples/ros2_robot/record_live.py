"""Record the ros2_robot example's runs from real ROS 2 nodes: the robot's
four nodes and its simulator (``nodes/``, one rclpy program each) run on ROS
2's default middleware (rmw_fastrtps_cpp, Fast DDS) while ``rclverify
monitor --live --ros2`` watches the bus, writes its log (topics, service
calls and action goals) and records the contract topics in a ROS 2 bag
(docs/monitors.md, "ROS 2 over DDS").  Everything stays on this host: the
nodes discover on localhost only (``ROS_AUTOMATIC_DISCOVERY_RANGE=
LOCALHOST``), the monitor's Cyclone DDS uses the loopback interface, and the
domain is a random one.

Run it with the project's Python (the one rclverify is installed in)::

    python3 record_live.py [--ros2-python PATH] [--only NAME]... [--keep DIR]

It records the correct robot (``runs/robot.jsonl``, the bag ``runs/robot/``)
and, for each seeded defect ``defects/NAME/NAME.patch``, the robot with that
patch applied to a copy of ``nodes/`` (``defects/NAME/run.jsonl``, the bag
``defects/NAME/run/``); ``--only robot`` or ``--only NAME`` records those
only.  The ROS 2 Python is found as ``examples/ros2_recording.py`` finds it;
the interface package ``interfaces/robot_msgs`` is built with colcon into
``.ros2/`` the first time (about 10 s).  Exit 0 with each recording's
figures; 1 with the reason when a part failed (the recordings already
written are kept, the one that failed is left as it was).
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

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))
from ros2_recording import Failed, messages_span, read_log, record as record_run, ros2_python  # noqa: E402

#: the robot's node programs, then the simulator (the driver)
NODES = {"ScanGuard": "scan_guard.py", "BatteryWatcher": "battery_watcher.py", "EStop": "estop.py",
         "Dock": "dock.py"}
DRIVER = "simulator.py"
INTERFACES = ["interfaces/robot_msgs"]
MONITOR = ["--interfaces", "interfaces", "--mapping", "contracts/mapping.yaml"]
TIMEOUT = 75.0  # s, one recording at most (the simulator waits up to 45 s for discovery)
GOALS = 2  # the simulator's /dock goals, its last calls


def _heard(log: list[dict[str, Any]]) -> bool:
    """The monitor's log holds the result of each of the simulator's /dock goals (its last answers) and
    that result's verdict."""
    results = [x["where"] for x in log if x.get("kind") == "call" and x.get("part") == "result"]
    judged = {x["verdict"].get("where") for x in log if x.get("topic") == "rclverify/verdict"}
    return len(results) >= GOALS and set(results) <= judged


def defects() -> list[str]:
    """The seeded defects: the folders of ``defects/`` holding ``<name>.patch``."""
    return sorted(d.name for d in (HERE / "defects").iterdir() if (d / f"{d.name}.patch").is_file())


def nodes_of(defect: str | None, tmp: Path) -> Path:
    """The folder of the node programs: ``nodes/`` itself, or a copy of it
    under ``tmp`` with the defect's patch applied (GNU patch, ``-p1`` from the
    example's folder).  Raises :class:`Failed` when the patch does not apply."""
    if defect is None:
        return HERE / "nodes"
    root = tmp / "patched"
    shutil.copytree(HERE / "nodes", root / "nodes", ignore=shutil.ignore_patterns("__pycache__"))
    patch = HERE / "defects" / defect / f"{defect}.patch"
    r = subprocess.run(["patch", "-p1", "--forward", "--no-backup-if-mismatch", "-d", str(root), "-i", str(patch)],
                       capture_output=True, text=True, timeout=60)
    if r.returncode != 0:
        raise Failed(f"{patch.relative_to(HERE)} does not apply: {r.stdout}{r.stderr}")
    return root / "nodes"


def record(py: Path, tmp: Path, defect: str | None, out: Path, env: dict[str, str] | None = None) -> dict[str, object]:
    """Record the robot (with ``defect`` applied, if given) into ``tmp``, in
    the environment ``env`` (``ros2_recording.record``'s when None); the log
    is copied to ``out`` (``.jsonl``) and the bag to ``out`` without the
    suffix.  Returns the recording's figures (``red``: the nodes the live
    monitor found violated or late)."""
    nodes = nodes_of(defect, tmp)
    scripts = {name: nodes / prog for name, prog in NODES.items()} | {"simulator": nodes / DRIVER}
    seconds = record_run(HERE, py, tmp, interfaces=INTERFACES, nodes=list(NODES), script="", driver="simulator",
                         monitor=[*MONITOR, "--record", str(tmp / "bag.mcap")], timeout=TIMEOUT, until_done=True,
                         scripts=scripts, env=env, heard=_heard)
    lines = read_log(tmp / "run.jsonl")
    messages, span = messages_span(lines)
    bag, log_tmp = out.with_suffix(""), out.with_name(out.name + ".tmp")
    bag_tmp = bag.with_name(bag.name + ".bag.tmp")
    out.parent.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(tmp / "run.jsonl", log_tmp)
    shutil.rmtree(bag_tmp, ignore_errors=True)
    shutil.copytree(tmp / "bag", bag_tmp)
    shutil.rmtree(bag, ignore_errors=True)
    bag_tmp.replace(bag)
    log_tmp.replace(out)
    verdicts = [x["verdict"] for x in lines if x.get("topic") == "rclverify/verdict"]
    red = sorted({v["node"] for v in verdicts if v.get("verdict") in ("violated", "false")})
    return {"lines": len(lines), "messages": messages, "calls": sum(x.get("kind") == "call" for x in lines),
            "span_s": span, "red": red, "seconds": round(seconds, 1),
            "answers": [x for x in (tmp / "driver.out").read_text().splitlines() if x.startswith(("estop", "dock"))]}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--ros2-python", help="the ROS 2 Python (rclpy, rmw_fastrtps_cpp)")
    ap.add_argument("--only", action="append", help="record only this: robot, or a defect's name (repeatable)")
    ap.add_argument("--keep", help="keep the processes' outputs in this folder (else a temporary one)")
    args = ap.parse_args(argv)
    try:
        py = ros2_python(args.ros2_python, HERE)
        known = ["robot", *defects()]
        wanted = args.only or known
        unknown = sorted(set(wanted) - set(known))
        if unknown:
            raise Failed(f"no such recording: {', '.join(unknown)} (known: {', '.join(known)})")
        for name in wanted:
            defect = None if name == "robot" else name
            out = HERE / ("runs/robot.jsonl" if defect is None else f"defects/{name}/run.jsonl")
            with tempfile.TemporaryDirectory(prefix="record_live_") as tmp:
                where = Path(args.keep).resolve() / name if args.keep else Path(tmp)
                where.mkdir(parents=True, exist_ok=True)
                figures = record(py, where, defect, out)
            print(f"{out.relative_to(HERE)}: {json.dumps(figures)}", flush=True)
    except (Failed, OSError, subprocess.SubprocessError) as exc:
        print(f"record_live.py: error: {exc}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
