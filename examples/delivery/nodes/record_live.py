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
import os
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent.parent
NODES_DIR = "nodes"
NODES = ["GnssDriver", "Localiser", "ObstacleDetector", "LockerController", "RouteServer", "SpeedGovernor",
         "WheelController", "Navigator", "MissionPlanner"]
DRIVER = "scenario"
INTERFACES = ["interfaces/delivery_msgs"]
#: the monitor's bag and log as it wrote them; the plan reads the trace made from them (make_trace)
LIVE = "backends/monitors/live"
MONITOR = ["--mapping", "backends/monitors/mapping.yaml", "--interfaces", "interfaces"]
CYCLONE = """<CycloneDDS xmlns="https://cdds.io/config"><Domain Id="any">
  <General><Interfaces><NetworkInterface name="lo" multicast="false"/></Interfaces>
    <AllowMulticast>false</AllowMulticast></General>
  <Discovery><ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>40</MaxAutoParticipantIndex>
    <Peers><Peer address="127.0.0.1"/></Peers></Discovery>
</Domain></CycloneDDS>
"""
TIMEOUT = 30.0  # s, the whole recording


class Failed(Exception):
    """A part of the recording failed; the message says which."""


def ros2_python(named: str | None) -> Path:
    if named or os.environ.get("RCLVERIFY_ROS2_PYTHON"):
        exe = Path(named or os.environ["RCLVERIFY_ROS2_PYTHON"])
        if not exe.is_file():
            raise Failed(f"no ROS 2 Python at {exe}")
        return exe
    for d in HERE.parents:
        if (d / ".venv-ros2" / "bin" / "python").exists():
            return d / ".venv-ros2" / "bin" / "python"
    raise Failed("no ROS 2 Python: give --ros2-python (a Python with rclpy and rmw_fastrtps_cpp)")


def build(py: Path, env: dict[str, str]) -> dict[str, str]:
    """colcon-build the interface packages into .ros2/ (once) and return ``env`` with its setup sourced."""
    ws = HERE / ".ros2"
    if not all((ws / "install" / Path(p).name).is_dir() for p in INTERFACES):
        shutil.rmtree(ws, ignore_errors=True)
        ws.mkdir()
        venv = py.parent.parent
        benv = dict(env, PATH=f"{py.parent}:{env['PATH']}", CMAKE_PREFIX_PATH=str(venv), AMENT_PREFIX_PATH=str(venv))
        r = subprocess.run([str(py), "-m", "colcon", "build", "--base-paths", *[str(HERE / p) for p in INTERFACES]],
                           cwd=ws, env=benv, capture_output=True, timeout=300)
        if r.returncode != 0:
            shutil.rmtree(ws / "install", ignore_errors=True)
            raise Failed("colcon build failed:\n" + r.stdout.decode(errors="replace")[-3000:])
    dump = subprocess.run(["bash", "-c", ". install/setup.sh && env -0"], cwd=ws, env=env, capture_output=True,
                          timeout=60, check=True).stdout
    return dict(kv.split("=", 1) for kv in dump.decode().split("\0") if "=" in kv)


def wait_for(path: Path, text: str, timeout: float, proc: subprocess.Popen[bytes]) -> None:
    until = time.monotonic() + timeout
    while not (path.exists() and text in path.read_text(errors="replace")):
        if proc.poll() is not None or time.monotonic() > until:
            raise Failed(f"{path.name} never said {text!r}:\n{path.read_text(errors='replace')[-2000:]}")
        time.sleep(0.05)


def start(cmd: list[str], env: dict[str, str], log: Path) -> subprocess.Popen[bytes]:
    with open(log, "wb") as fh:
        return subprocess.Popen(cmd, cwd=HERE, env=env, stdout=fh, stderr=subprocess.STDOUT, start_new_session=True)


def stop(p: subprocess.Popen[bytes], sig: int = signal.SIGTERM) -> None:
    if p.poll() is None:
        os.killpg(p.pid, sig)
        try:
            p.wait(10)
        except subprocess.TimeoutExpired:
            os.killpg(p.pid, signal.SIGKILL)
            p.wait(5)


def record(py: Path, tmp: Path) -> float:
    """Run the monitor, the nodes and the scenario; the monitor's bag is ``tmp/bag/``, its log
    ``tmp/run.jsonl``.  Returns the seconds it took."""
    t0 = time.monotonic()
    (tmp / "cyclonedds.xml").write_text(CYCLONE)
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONSTARTUP")}
    env.update(CYCLONEDDS_URI=(tmp / "cyclonedds.xml").as_uri(), ROS_DOMAIN_ID=str(random.randint(1, 230)),
               ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST", RMW_IMPLEMENTATION="rmw_fastrtps_cpp",
               PYTHONUNBUFFERED="1", ROS_LOG_DIR=str(tmp / "ros_log"))
    nenv = build(py, env)
    procs: list[subprocess.Popen[bytes]] = []
    try:
        monitor = start([sys.executable, "-m", "rclverify.cli", "monitor", "-w", ".", "--live", "--ros2", *MONITOR,
                         "--reorder-window", "0", "--status", "0", "--silence", "0", "--duration", str(TIMEOUT),
                         "--record", str(tmp / "bag"), "--record-storage", "mcap",
                         "--log", str(tmp / "run.jsonl"), "--evidence", str(tmp / "evidence.json")],
                        env, tmp / "monitor.out")
        procs.append(monitor)
        wait_for(tmp / "monitor.out", "monitoring", 15, monitor)
        for name in NODES:
            procs.append(start([str(py), f"{NODES_DIR}/ros2_nodes.py", name], nenv, tmp / f"{name}.out"))
        for name, p in zip(NODES, procs[1:]):
            wait_for(tmp / f"{name}.out", "ready", 15, p)
        driver = start([str(py), f"{NODES_DIR}/ros2_nodes.py", DRIVER], nenv, tmp / "driver.out")
        procs.append(driver)
        try:
            wait_for(tmp / "driver.out", "done", max(1.0, TIMEOUT - (time.monotonic() - t0)), driver)
        except Failed:
            raise Failed("the scenario failed:\n" + (tmp / "driver.out").read_text(errors="replace")[-2000:]) from None
        for p in procs[1:-1]:  # the nodes, all at once: the run ends with the scenario (the watchdog stops)
            if p.poll() is None:
                os.killpg(p.pid, signal.SIGTERM)
        time.sleep(0.5)  # the last messages reach the monitor
        stop(monitor, signal.SIGINT)
        if monitor.returncode not in (0, 1):  # 1: a contract failed, as the seeded defects make it
            raise Failed("the monitor failed:\n" + (tmp / "monitor.out").read_text(errors="replace")[-2000:])
    except subprocess.TimeoutExpired:
        raise Failed(f"not done within {TIMEOUT} s") from None
    finally:
        for p in reversed(procs):
            stop(p)
    return time.monotonic() - t0


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
    log = [json.loads(x) for x in (tmp / "run.jsonl").read_text().splitlines() if x.strip()]
    if (live / "run").exists():
        shutil.rmtree(live / "run")
    live.mkdir(parents=True, exist_ok=True)
    shutil.copytree(tmp / "bag", live / "run")
    shutil.copyfile(tmp / "run.jsonl", live / "monitor.jsonl")
    figures: dict[str, object] = dict(make_trace(live / "run", log, out))
    times = [x["time"] for x in log if not str(x.get("topic", "")).startswith("rclverify/")]
    figures.update(log_lines=len(log), span_s=round(max(times) - min(times), 3) if times else 0.0)
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
        py = ros2_python(args.ros2_python)
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
