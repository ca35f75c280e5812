"""A live run's recorded bag ends where the live clock did, for every run (traces/bag_end.py, docs/ros2.md
"The run's end in the bag"): the offline check of the bag gives the live run's verdicts, verdict by
verdict, on a run with no timed guarantee, through each source.

Real rclpy nodes on Fast DDS: ``Echo`` answers every question ``/x`` on ``/y`` (``y == x``), its last
answer just before the monitor stops; ``Skip`` answers every question on ``/w`` but the last.  The monitor
(``--horizon 0.5``, ``--record``) is stopped once its log holds ``Skip``'s verdict on that last question:
the live clock passed its horizon unanswered, so live it is ``inconclusive`` ("unanswered"), not ``open``.
The bag carries the run's end on ``/rclverify/run_end``, so its offline check closes that question too:
live = bag.  The control is the same bag's messages recorded again without the end: it ends at its last
message, within that question's horizon, and calls the question ``open``, the one disagreement.
"""
from __future__ import annotations

import signal
import sys
from pathlib import Path
from typing import Any, Iterator

import pytest
from _procs import stop, wait_for, wait_logged
from _ros2 import AWAIT_MONITOR, live_workspace, rclverify, ros2_env, ros2_python, start_node

from rclverify.cli.commands import main
from rclverify.runtime.dds.bag import BagRecorder
from rclverify.traces import bag_end, read_trace
from rclverify.traces.bag import typestore

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bench"))
from _robot_verdicts import compare, finals, read_records  # noqa: E402

RCL = """\
node Echo {
  inputs( x : INTEGER )
  outputs( y : INTEGER )
  topics( std_msgs/Int64 x matches(in.x), std_msgs/Int64 y matches(out.y) )
  assume( TRUE )
  guarantee( out.y == in.x )
}

node Skip {
  inputs( x : INTEGER )
  outputs( w : INTEGER )
  topics( std_msgs/Int64 x matches(in.x), std_msgs/Int64 w matches(out.w) )
  assume( TRUE )
  guarantee( out.w == in.x )
}
"""
ROUNDS = 8

SYSTEM = """\
import time
import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from std_msgs.msg import Int64

rclpy.init()
n = Node("robot")
pubs = {k: n.create_publisher(Int64, k, 100) for k in ("x", "y", "w")}

def answer(m):
    pubs["y"].publish(Int64(data=m.data))
    if m.data != ROUNDS:  # Skip leaves the last question unanswered
        pubs["w"].publish(Int64(data=m.data))

n.create_subscription(Int64, "x", answer, 100)
AWAIT_MONITOR
for k in range(1, ROUNDS + 1):
    pubs["x"].publish(Int64(data=k))
    spin(0.1)
print("done", flush=True)
while True:
    ex.spin_once(timeout_sec=0.1)
""".replace("AWAIT_MONITOR\n", AWAIT_MONITOR).replace("ROUNDS", str(ROUNDS))


def _skip_closed_last(lines: list[dict[str, Any]]) -> bool:
    """Whether the log holds Skip's verdict on the last question, closed (not open) by the live clock."""
    return any(line.get("topic") == "rclverify/verdict" and isinstance(line.get("verdict"), dict)
               and line["verdict"].get("node") == "Skip" and line["verdict"].get("topic") == "x"
               and line["verdict"].get("verdict") == "inconclusive" for line in lines)


@pytest.fixture(scope="module", params=["rclpy", "dds"])
def run(request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, Any]]:
    """One live run through each source, stopped once the live clock closed Skip's last question."""
    py = ros2_python()  # skips, with the reason, without a ROS 2 Python
    source = request.param
    tmp = tmp_path_factory.mktemp(f"run-end-{source}")
    ws = live_workspace(tmp, RCL)
    env = ros2_env(tmp)
    procs = []
    try:
        procs.append(start_node(tmp, "system", SYSTEM, env))
        monitor = rclverify(["monitor", "-w", str(ws), "--live", "--ros2", "--horizon", "0.5", "--status", "0",
                             "--duration", "90", "--source", source, "--ros2-python", str(py),
                             "--log", str(tmp / "live.jsonl"), "--record", str(tmp / "bag"),
                             "--verdicts", str(tmp / "live.verdicts.jsonl")], env, tmp, tmp / "monitor.out")
        procs.append(monitor)
        wait_for(tmp / "system.log", "done", 90)
        wait_logged(tmp / "live.jsonl", _skip_closed_last, 60)
        stop(monitor, signal.SIGINT)
        assert monitor.returncode is not None
        yield {"tmp": tmp, "ws": ws, "out": (tmp / "monitor.out").read_text(errors="replace")}
    finally:
        for p in procs:
            stop(p)


def _offline(ws: Path, bag: Path) -> dict[Any, Any]:
    """The final verdicts of the offline check of ``bag``, as ``--verdicts`` writes them."""
    out = bag.parent / f"{bag.name}.verdicts.jsonl"
    main(["monitor", "-w", str(ws), str(bag), "--horizon", "0.5", "--verdicts", str(out)])
    return finals(read_records(out))


def _without_end(bag: Path) -> Path:
    """``bag``'s messages recorded again through the live monitor's recorder, its end left out."""
    from rosbags.highlevel import AnyReader
    with AnyReader([bag], default_typestore=typestore([])) as reader:
        items = [(c.topic.strip("/"), c.msgtype, t, raw) for c, t, raw in reader.messages()]
    topics = {topic: msgtype for topic, msgtype, _, _ in items if topic != bag_end.TOPIC}
    again = bag.parent / "again"
    rec = BagRecorder(again, "sqlite3", topics, [])
    for topic, _, t, raw in items:
        rec.write(topic, t, raw)
    assert "failed" not in rec.close()
    return again


def test_the_bag_of_a_run_without_timed_guarantees_ends_where_the_live_clock_did(run: dict[str, Any]) -> None:
    tmp, ws = run["tmp"], run["ws"]
    events = list(read_trace(tmp / "bag", []))
    ends = [ev for ev in events if ev.topic == bag_end.TOPIC]
    assert len(ends) == 1 and ends[0].time == max(ev.time for ev in events), run["out"]
    last_question = max(ev.time for ev in events if ev.topic == "x")
    assert ends[0].time > last_question + 0.5  # the live clock passed the last question's horizon
    live = finals(read_records(tmp / "live.verdicts.jsonl"))
    skip = live[("Skip", "guarantee", "x", 0)]  # its questions' own verdicts: the last one's only
    assert skip[-1]["verdict"] == "inconclusive" and abs(float(skip[-1]["time"]) - last_question) < 1e-5, skip
    echo = live[("Echo", "guarantee", "y", 0)]  # the last question answered just before the stop
    assert {r["verdict"] for r in echo} == {"satisfied"} and float(echo[-1]["time"]) >= last_question, echo
    assert [d.text(("live", "bag")) for d in compare(live, _offline(ws, tmp / "bag"))] == []


def test_control_the_same_bag_without_its_end_leaves_the_last_question_open(run: dict[str, Any]) -> None:
    tmp, ws = run["tmp"], run["ws"]
    again = _without_end(tmp / "bag")
    assert bag_end.TOPIC not in {ev.topic for ev in read_trace(again, [])}
    live = finals(read_records(tmp / "live.verdicts.jsonl"))
    found = compare(live, _offline(ws, again))
    assert [(d.node, d.topic, d.a and d.a["verdict"], d.b and d.b["verdict"]) for d in found] == [
        ("Skip", "x", "inconclusive", "open")], [d.text(("live", "bag")) for d in found]
