"""The run's simulated clock heard live (traces/sim_clock.py, docs/ros2.md): both ROS 2 sources read
``/clock`` (``rosgraph_msgs/msg/Clock``) whatever the contracts name, push each message to the engine at its
publisher's source time, and the ``--record`` bag keeps it.

Real rclpy nodes on Fast DDS: ``robot`` asks ``/x`` (Int64) every 50 ms and answers each question on ``/y``
(``Echo``: ``y == x``); ``sim`` publishes ``/clock`` at about 100 Hz, its value 10 ms further each time (a
simulator at real-time factor one).  Through each source the live log holds ``clock`` lines, their values
increasing in the log's time order, between the contract topic's lines by time; the bag holds the same
``/clock`` messages at the same times; the record names the ``/clock`` publisher heard.  The control is the
same run without ``sim`` (one source: the reader of ``/clock`` is made the same way in both): no ``clock`` line, no ``/clock`` in the bag or the record, the contract topics heard
as before.

ROS 1 (a real master, a rospy node): the live monitor hears ``/clock`` (``rosgraph_msgs/Clock``) beside the
contract topics, each message a ``clock`` line (``secs``/``nsecs``) at its receipt time, between the contract
topics' lines; the control without ``/clock`` has none.
"""
from __future__ import annotations

import json
import signal
import subprocess
import sys
from pathlib import Path
from typing import Any, Iterator

import pytest
from _procs import stop, wait_for, wait_logged
from _ros2 import AWAIT_MONITOR, live_workspace, rclverify, ros2_env, ros2_python, start_node

from rclverify.runtime.ros1 import LocalMaster, RosUnavailable, import_rospy
from rclverify.traces.bag import typestore
from rclverify.traces.sim_clock import clock_value_ns

RCL = """\
node Echo {
  inputs( x : INTEGER )
  outputs( y : INTEGER )
  topics( std_msgs/Int64 x matches(in.x), std_msgs/Int64 y matches(out.y) )
  assume( TRUE )
  guarantee( out.y == in.x )
}
"""
ROUNDS = 30

SYSTEM = """\
import time
import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from std_msgs.msg import Int64

rclpy.init()
n = Node("robot")
pubs = {k: n.create_publisher(Int64, k, 100) for k in ("x", "y")}
n.create_subscription(Int64, "x", lambda m: pubs["y"].publish(Int64(data=m.data)), 100)
AWAIT_MONITOR
for k in range(1, ROUNDS + 1):
    pubs["x"].publish(Int64(data=k))
    spin(0.05)
print("done", flush=True)
while True:
    ex.spin_once(timeout_sec=0.1)
""".replace("AWAIT_MONITOR\n", AWAIT_MONITOR).replace("ROUNDS", str(ROUNDS))

SIM = """\
import time
import rclpy
from rclpy.node import Node
from builtin_interfaces.msg import Time
from rosgraph_msgs.msg import Clock

rclpy.init()
n = Node("sim")
pub = n.create_publisher(Clock, "/clock", 10)
print("ready", flush=True)
sim_ns = 100 * 10**9
while True:
    pub.publish(Clock(clock=Time(sec=sim_ns // 10**9, nanosec=sim_ns % 10**9)))
    sim_ns += 10 * 10**6
    time.sleep(0.01)
"""


def _echo_judged_last(lines: list[dict[str, Any]]) -> bool:
    """Whether the log holds Echo's verdict on the last answer."""
    last = {x["time"] for x in lines if x.get("topic") == "y" and x.get("data") == ROUNDS}
    return any(x.get("topic") == "rclverify/verdict" and isinstance(x.get("verdict"), dict)
               and x["verdict"].get("node") == "Echo" and x["verdict"].get("time") in last for x in lines)


@pytest.fixture(scope="module", params=[("rclpy", True), ("dds", True), ("dds", False)],
                ids=["rclpy-clock", "dds-clock", "dds-no-clock"])
def run(request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, Any]]:
    """One live run through a source, with ``sim`` publishing ``/clock`` or (the control) without it."""
    py = ros2_python()  # skips, with the reason, without a ROS 2 Python
    source, clock = request.param
    tmp = tmp_path_factory.mktemp(f"clock-{source}-{clock}")
    ws = live_workspace(tmp, RCL)
    env = ros2_env(tmp)
    procs: list[subprocess.Popen[bytes]] = []
    try:
        if clock:
            procs.append(start_node(tmp, "sim", SIM, env))
        procs.append(start_node(tmp, "system", SYSTEM, env))
        monitor = rclverify(["monitor", "-w", str(ws), "--live", "--ros2", "--horizon", "0.5", "--status", "0",
                             "--duration", "90", "--source", source, "--ros2-python", str(py),
                             "--log", str(tmp / "live.jsonl"), "--record", str(tmp / "bag"),
                             "--evidence", str(tmp / "live.json")], env, tmp, tmp / "monitor.out")
        procs.append(monitor)
        wait_for(tmp / "system.log", "done", 90)
        wait_logged(tmp / "live.jsonl", _echo_judged_last, 60)
        stop(monitor, signal.SIGINT)
        out = (tmp / "monitor.out").read_text(errors="replace")
        assert monitor.returncode is not None and (tmp / "live.json").exists(), out
        yield {"clock": clock, "tmp": tmp, "out": out,
               "log": [json.loads(x) for x in (tmp / "live.jsonl").read_text().splitlines()],
               "record": json.loads((tmp / "live.json").read_text())}
    finally:
        for p in procs:
            stop(p)


def _bag(path: Path) -> dict[str, list[int]]:
    """The times (ns) of the messages of each topic of the bag at ``path``."""
    from rosbags.highlevel import AnyReader
    out: dict[str, list[int]] = {}
    with AnyReader([path], default_typestore=typestore([])) as reader:
        for c, t, _raw in reader.messages():
            out.setdefault(c.topic, []).append(t)
    return out


def test_clock_lines_are_in_the_log_in_time_order(run: dict[str, Any]) -> None:
    """Each ``/clock`` message heard is a ``clock`` line, its value increasing with the log's time; the
    contract topic's lines and the clock's are one sequence in time order, interleaved; the control has none."""
    log = run["log"]
    clocks = [x for x in log if x.get("topic") == "clock"]
    xs = [x for x in log if x.get("topic") == "x"]
    assert len(xs) >= ROUNDS - 2, (len(xs), run["out"])
    if not run["clock"]:
        assert clocks == [] and "clock" not in run["record"], (clocks[:3], run["record"].get("clock"))
        return
    assert len(clocks) >= 100, (len(clocks), run["out"])
    assert all(clock_value_ns(x) is not None for x in clocks), clocks[:3]
    # a message heard later than the lateness bound is written where it was heard, marked (``late_s``): the
    # order is that of the others, as the contract topic's below
    on_time = [x for x in clocks if "late_s" not in x]
    values = [clock_value_ns(x) for x in on_time]
    assert all(a < b for a, b in zip(values, values[1:])), values  # type: ignore[operator]
    times = [x["time"] for x in on_time]
    assert all(a <= b for a, b in zip(times, times[1:])), times
    # the contract topic's lines and the clock's, in the log's order, are in time order
    both = [x["time"] for x in log if x.get("topic") in ("x", "clock") and "late_s" not in x]
    assert all(a <= b for a, b in zip(both, both[1:]))
    # interleaved: wherever a clock line's time lies between two successive questions' (50 ms apart, /clock
    # every 10 ms when its publisher keeps up), a clock line lies between them in the log's order
    placed = [x for x in log if x.get("topic") in ("x", "clock") and "late_s" not in x]
    at = [k for k, x in enumerate(placed) if x["topic"] == "x"]
    ticks = [x["time"] for x in placed if x["topic"] == "clock"]
    due = [(a, b) for a, b in zip(at, at[1:])
           if any(placed[a]["time"] < t < placed[b]["time"] for t in ticks)]
    between = [(a, b) for a, b in due if any(x["topic"] == "clock" for x in placed[a + 1:b])]
    assert len(due) >= len(at) // 2 and between == due, (len(at), len(due), len(between))
    rec = run["record"]
    assert rec["clock"]["publishers_heard"] == 1 and rec["clock"]["samples"] >= len(clocks), rec["clock"]
    assert "clock" not in rec["qos"], rec["qos"]


def test_the_bag_holds_the_clock_the_log_holds(run: dict[str, Any]) -> None:
    """The ``--record`` bag has ``/clock`` at the times of the log's ``clock`` lines (the control: none)."""
    bag = _bag(run["tmp"] / "bag")
    assert len(bag.get("/x", [])) >= ROUNDS - 2, {k: len(v) for k, v in bag.items()}
    if not run["clock"]:
        assert "/clock" not in bag, {k: len(v) for k, v in bag.items()}
        assert "/clock" not in run["record"]["bag"]["topics"], run["record"]["bag"]
        return
    logged = sorted(round(x["time"] * 1e9) for x in run["log"] if x.get("topic") == "clock")
    recorded = sorted(bag["/clock"])
    assert len(recorded) == len(logged), (len(recorded), len(logged))
    assert all(abs(a - b) <= 1000 for a, b in zip(recorded, logged)), list(zip(recorded, logged))[:5]
    assert "/clock" in run["record"]["bag"]["topics"], run["record"]["bag"]


def test_echo_is_judged_with_or_without_a_clock(run: dict[str, Any]) -> None:
    """The contract's verdicts do not depend on the clock heard beside it."""
    (node,) = [n for n in run["record"]["nodes"] if n["node"] == "Echo"]
    assert node["counts"].get("violated", 0) == 0 and node["counts"].get("satisfied", 0) >= ROUNDS - 2, node


ROS1_NODE = """\
import sys
import time
from rclverify.runtime.ros1 import import_rospy
rospy = import_rospy()
from rosgraph_msgs.msg import Clock
from std_msgs.msg import Int64

rospy.init_node("robot", disable_signals=True)
px = rospy.Publisher("/x", Int64, queue_size=100)
py = rospy.Publisher("/y", Int64, queue_size=100)
pc = rospy.Publisher("/clock", Clock, queue_size=100) if sys.argv[1:] == ["clock"] else None
print("ready", flush=True)
until = time.monotonic() + 30
while time.monotonic() < until and (px.get_num_connections() < 1 or py.get_num_connections() < 1
                                   or (pc is not None and pc.get_num_connections() < 1)):
    time.sleep(0.05)
time.sleep(0.5)
sim_ns = 100 * 10**9
for k in range(1, ROUNDS + 1):
    for _ in range(5):  # /clock at about 100 Hz, 10 ms further each time
        if pc is not None:
            pc.publish(Clock(clock=rospy.Time(sim_ns // 10**9, sim_ns % 10**9)))
            sim_ns += 10 * 10**6
        time.sleep(0.01)
    px.publish(Int64(data=k))
    time.sleep(0.002)
    py.publish(Int64(data=k))
print("done", flush=True)
while True:
    time.sleep(0.1)
""".replace("ROUNDS", str(ROUNDS))

try:
    import_rospy()
    ROS1 = ""
except RosUnavailable as exc:
    ROS1 = str(exc)


@pytest.fixture(scope="module", params=[True, False], ids=["ros1-clock", "ros1-no-clock"])
def ros1_run(request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, Any]]:
    """One live run on a ROS 1 master, the node publishing ``/clock`` or (the control) not."""
    if ROS1:
        pytest.skip(f"ROS 1 unavailable: {ROS1}")
    clock = request.param
    tmp = tmp_path_factory.mktemp(f"ros1-clock-{clock}")
    ws = live_workspace(tmp, RCL)
    (tmp / "robot.py").write_text(ROS1_NODE)
    src = str(Path(__file__).resolve().parents[2] / "src")
    procs: list[subprocess.Popen[bytes]] = []
    with LocalMaster(tmp / "ros") as env:
        env = {**env, "PYTHONPATH": src, "PYTHONUNBUFFERED": "1"}
        try:
            with open(tmp / "robot.log", "wb") as fh:
                procs.append(subprocess.Popen([sys.executable, str(tmp / "robot.py"), *(["clock"] if clock else [])],
                                              cwd=tmp, env=env, stdout=fh, stderr=subprocess.STDOUT,
                                              start_new_session=True))
            wait_for(tmp / "robot.log", "ready", 30)
            with open(tmp / "monitor.out", "wb") as fh:
                monitor = subprocess.Popen([sys.executable, "-m", "rclverify.cli.commands", "monitor", "--live",
                                            "-w", str(ws), "--horizon", "0.5", "--status", "0", "--duration", "90",
                                            "--log", str(tmp / "live.jsonl"), "--evidence", str(tmp / "live.json")],
                                           cwd=tmp, env=env, stdout=fh, stderr=subprocess.STDOUT,
                                           start_new_session=True)
            procs.append(monitor)
            wait_for(tmp / "robot.log", "done", 60)
            wait_logged(tmp / "live.jsonl", _echo_judged_last, 60)
            stop(monitor, signal.SIGINT)
            out = (tmp / "monitor.out").read_text(errors="replace")
            assert (tmp / "live.json").exists(), out
            yield {"clock": clock, "out": out,
                   "log": [json.loads(x) for x in (tmp / "live.jsonl").read_text().splitlines()]}
        finally:
            for p in procs:
                stop(p)


def test_ros1_clock_lines_are_in_the_log_in_time_order(ros1_run: dict[str, Any]) -> None:
    """ROS 1: each ``/clock`` message heard is a ``clock`` line (``secs``/``nsecs``), its value increasing
    with the log's time, between the contract topic's lines; the control has none."""
    log = ros1_run["log"]
    clocks = [x for x in log if x.get("topic") == "clock"]
    xs = [x for x in log if x.get("topic") == "x"]
    assert len(xs) == ROUNDS, (len(xs), ros1_run["out"])
    if not ros1_run["clock"]:
        assert clocks == [], clocks[:3]
        return
    assert len(clocks) >= 4 * ROUNDS and all(set(x["clock"]) == {"secs", "nsecs"} for x in clocks), clocks[:3]
    values = [clock_value_ns(x) for x in clocks]
    assert all(v is not None for v in values) and all(a < b for a, b in zip(values, values[1:])), values  # type: ignore[operator]
    both = [x["time"] for x in log if x.get("topic") in ("x", "clock")]
    assert all(a <= b for a, b in zip(both, both[1:]))
    order = [x.get("topic") for x in log if x.get("topic") in ("x", "clock")]
    at = [k for k, t in enumerate(order) if t == "x"]
    assert sum("clock" in order[a + 1:b] for a, b in zip(at, at[1:])) >= len(at) - 3, order
