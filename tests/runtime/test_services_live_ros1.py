"""Services, actions and deadlines monitored live on ROS 1 (issue 33).

A ROS 1 master on 127.0.0.1 (a free port), the safety-stop example's nodes
as rospy processes, and ``rclverify monitor --live --forward /estop=/estop_real
--interfaces interfaces`` (the service proxy inside the live monitor): the estop server answers
its second call 400 ms late (its deadline is 200 ms), the move action's
feedback comes 0.5 s after the goal (deadline 2 s).  The monitor's log must
hold a ``false`` verdict with the late call's stamps and a ``true`` one for
the feedback.  The run's own deadline checks are the one judge of the calls'
and the goal's deadlines (``runtime/live_ros1.py``, "One judge of the calls"):
one verdict per call in the log, the record and on the verdict topic, none of
the proxy's.  Every process is stopped in a ``finally``; skipped, with the
reason, only where ROS 1 cannot be imported.
"""
from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
from collections import Counter
from pathlib import Path
from typing import Any

import pytest
from _procs import stop, wait_for

from rclverify.runtime.ros1 import LocalMaster, RosUnavailable, import_rospy

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "examples" / "safety_stop"
NODES = EXAMPLE / "nodes" / "ros1_nodes.py"

try:
    import_rospy()
    REASON = ""
except RosUnavailable as exc:
    REASON = str(exc)
pytestmark = pytest.mark.skipif(bool(REASON), reason=f"ROS 1 unavailable: {REASON}")


#: a subscriber of the verdict topic: each message's JSON text a line, "ready" once connected to its publisher
ECHO = """\
import time
from rclverify.runtime.ros1 import import_rospy
rospy = import_rospy()
from std_msgs.msg import String
rospy.init_node("echo", anonymous=True)
sub = rospy.Subscriber("/rclverify/verdict", String, lambda msg: print(msg.data, flush=True))
end = time.monotonic() + 30
while sub.get_num_connections() < 1 and time.monotonic() < end:
    time.sleep(0.05)
print("ready", flush=True)
rospy.spin()
"""


def _start(args: list[str], env: dict[str, str], out: Path) -> subprocess.Popen[bytes]:
    return subprocess.Popen([sys.executable, *args], env=env, cwd=EXAMPLE, stdout=out.open("wb"),
                            stderr=subprocess.STDOUT, start_new_session=True)


@pytest.fixture(scope="module")
def live_log(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    tmp = tmp_path_factory.mktemp("svc")
    procs: list[subprocess.Popen[bytes]] = []
    log = tmp / "monitor.jsonl"
    with LocalMaster(tmp / "ros") as env:
        (tmp / "scratch").mkdir()  # the processes' $TMPDIR: what they leave behind
        env = {**env, "PYTHONPATH": str(REPO / "src") + os.pathsep + os.environ.get("PYTHONPATH", ""),
               "TMPDIR": str(tmp / "scratch")}
        try:
            base = _start([str(NODES), "base", "--serve", "/estop_real", "--late-call", "2", "--delay", "0.4"],
                          env, tmp / "base.out")
            mover = _start([str(NODES), "mover", "--feedback-after", "0.5"], env, tmp / "mover.out")
            procs += [base, mover]
            wait_for(tmp / "base.out", "ready", 60)
            wait_for(tmp / "mover.out", "ready", 60)
            # the proxy inside the live monitor: one process, one log, one verdict topic
            monitor = _start(["-m", "rclverify.cli.commands", "monitor", "-w", str(EXAMPLE), "--live", "--interfaces",
                              "interfaces", "--forward", "/estop=/estop_real", "--log", str(log),
                              "--evidence", str(tmp / "live.json"), "--duration", "60"], env, tmp / "monitor.out")
            procs.append(monitor)
            wait_for(tmp / "monitor.out", "monitoring ", 60)
            # the deadline verdicts on the live monitor's verdict topic, as a subscriber sees them
            echo = _start(["-c", ECHO], env, tmp / "echo.out")
            procs.append(echo)
            wait_for(tmp / "echo.out", "ready", 30)  # connected to the monitor's publisher before the first call
            teleop = _start([str(NODES), "teleop", "--call", "/estop", "--count", "2", "--every", "0.3"],
                            env, tmp / "teleop.out")
            mission = _start([str(NODES), "mission", "--target", "2.0"], env, tmp / "mission.out")
            procs += [teleop, mission]
            assert teleop.wait(60) == 0, (tmp / "teleop.out").read_text()
            assert mission.wait(60) == 0, (tmp / "mission.out").read_text()
            wait_for(log, '"node": "Mover"', 30)
            stop(monitor, signal.SIGINT)
            code = monitor.returncode
        finally:
            for p in reversed(procs):
                stop(p)
    # the proxy's lines ("kind": event) and the run's deadline lines among the live monitor's own
    every = [json.loads(x) for x in log.read_text().splitlines()]
    lines = [x for x in every if "kind" in x]
    return {"lines": lines, "code": code, "tmp": tmp, "out": (tmp / "monitor.out").read_text(),
            "messages": [x for x in every if not x["topic"].startswith("rclverify/")],
            "echo": (tmp / "echo.out").read_text(errors="replace"),
            "record": json.loads((tmp / "live.json").read_text())}


def _deadlines(live_log: dict[str, Any], node: str) -> list[dict[str, Any]]:
    """The run's deadline verdicts of ``node`` (its checks' ``kind: deadline`` lines), in the log's order."""
    return [x["verdict"] for x in live_log["lines"] if x["kind"] == "deadline" and x["verdict"]["node"] == node]


def _calls(live_log: dict[str, Any]) -> list[list[dict[str, Any]]]:
    """The Base deadline's verdicts, one list per call (by its trigger), in the calls' order."""
    calls: dict[str, list[dict[str, Any]]] = {}
    for v in _deadlines(live_log, "Base"):
        calls.setdefault(v["trigger_where"], []).append(v)
    return list(calls.values())


def _missed(live_log: dict[str, Any]) -> int:
    """How many estop calls were answered after the 200 ms deadline (or never), by their final verdict."""
    return sum(1 for vs in _calls(live_log) if vs[-1]["verdict"] == "false")


def _published(live_log: dict[str, Any]) -> list[dict[str, Any]]:
    """The deadline verdicts a subscriber of the verdict topic received (:data:`ECHO`'s lines)."""
    return [data for data in (json.loads(x) for x in live_log["echo"].splitlines() if x.startswith("{"))
            if data.get("kind") == "deadline"]


def _messages(live_log: dict[str, Any], topic: str) -> list[float]:
    """The ``time`` of each message line of ``topic`` in the live log."""
    return [x["time"] for x in live_log["messages"] if x["topic"] == topic]


def test_the_late_service_answer_is_false_with_the_calls_stamps(live_log: dict[str, Any]) -> None:
    first, second = _calls(live_log)
    # the first call is answered at once by the server, but through the proxy's first connection on a loaded
    # machine it can take longer than 200 ms: its verdict is what its stamps say, whichever they say
    took = first[-1]["answer"] - first[-1]["trigger_stamp"]
    assert [(v["verdict"], v["update"]) for v in first] in (
        [[("true", False)]] if took <= 0.2 else [[("false", False)], [("false", False), ("false", True)]])
    assert [(v["verdict"], v["update"]) for v in second] == [("false", False), ("false", True)]
    expired, late = second
    # false as soon as the run's clock passed the deadline (the engine's timer), before the answer came ...
    assert expired["answer"] is None and expired["reason"].startswith("no answer within the deadline of 200 ms")
    # ... and the late answer, when it came, shown with the call's stamps
    assert late["trigger_where"] == expired["trigger_where"] and late["guarantee"] == 1
    assert late["due"] == pytest.approx(late["trigger_stamp"] + 0.2)
    assert late["answer"] - late["trigger_stamp"] >= 0.4  # the server slept 400 ms
    # the stamps are the second call's request and response message lines in the log, the lines a replay reads
    requests, responses = _messages(live_log, "estop/request"), _messages(live_log, "estop/response")
    assert (requests[1], responses[1]) == (late["trigger_stamp"], late["answer"])
    # the proxy's own events stamp the same call on its ROS clock (here the wall clock) as it forwards it
    events = [x for x in live_log["lines"] if x["kind"] == "event" and x["call"].startswith("estop/")]
    assert [x["call"] for x in events] == ["estop/request", "estop/response"] * 2
    assert 0 <= late["trigger_stamp"] - events[2]["stamp"] < 0.1 and 0 <= late["answer"] - events[3]["stamp"] < 0.1
    assert live_log["code"] == 1  # a false verdict: the monitor's exit code says so


def test_the_action_feedback_arrives_in_time(live_log: dict[str, Any]) -> None:
    verdicts = _deadlines(live_log, "Mover")
    assert [v["verdict"] for v in verdicts] == ["true"], verdicts
    v = verdicts[0]
    assert 0.4 <= v["answer"] - v["trigger_stamp"] <= 2.0
    topics = [x["call"] for x in live_log["lines"] if x["kind"] == "event"]
    assert {"move/goal", "move/feedback", "move/result"} <= set(topics)
    missed = _missed(live_log)  # the late second call, and the first where its stamps show it late too
    assert missed in (1, 2)
    # the command's evidence record and output carry the run's deadline verdicts
    dls = {d["node"]: d for d in live_log["record"]["topic_deadlines"]}
    assert dls["Base"]["status"] == "failed" and dls["Base"]["deadlines"]["counts"]["false"] == missed, dls["Base"]
    assert dls["Mover"]["status"] == "discharged" and dls["Mover"]["deadlines"]["counts"]["true"] == 1
    assert "deadlines: Base: failed: " in live_log["out"] and "deadlines: Mover: discharged: " in live_log["out"]


def test_each_calls_deadline_is_judged_once(live_log: dict[str, Any]) -> None:
    """One judge: the run's checks.  Each call's and the goal's deadline verdicts are published on the verdict
    topic exactly as the log holds them, one first verdict per call; the control: the service proxy's own
    verdicts (its ``kind: verdict`` and ``summary`` lines, the record's ``deadlines``, a second message per
    call on the topic) are nowhere."""
    logged = [x["verdict"] for x in live_log["lines"] if x["kind"] == "deadline"]
    published = [{k: v for k, v in p.items() if k != "kind"} for p in _published(live_log)]
    assert published == logged, (published, logged)
    firsts = Counter(p["node"] for p in published if not p["update"])
    assert firsts == Counter(Base=2, Mover=1), published  # two estop calls, one goal: once each
    assert not [x for x in live_log["lines"] if x["kind"] in ("verdict", "summary")]
    assert "deadlines" not in live_log["record"] and " judged call(s) or goal(s) " not in live_log["out"]


def test_the_calls_reach_the_node_monitors_live(live_log: dict[str, Any]) -> None:
    """The proxy hands each call and action message to the live engine too
    (issue 40): the untimed monitors check the server's responses against
    its guarantees as the offline check does."""
    nodes = {n["node"]: n for n in live_log["record"]["nodes"]}
    assert nodes["Base"]["counts"]["satisfied"] == 2, nodes["Base"]  # both estop calls answered as guaranteed
    # the goal's feedback and result, each judged when it answers the goal (one heard before the goal answers none)
    assert 1 <= nodes["Mover"]["counts"]["satisfied"] <= 2 and nodes["Mover"]["counts"]["violated"] == 0, nodes["Mover"]
    assert nodes["Base"]["status"] == nodes["Mover"]["status"] == "discharged"


def test_the_generated_action_messages_do_not_outlive_the_processes(live_log: dict[str, Any]) -> None:
    # the monitor's proxy and the mover each write the action's expanded .msg files to make rospy's
    # classes; the classes live on in memory, the files go with the class generation
    assert not [p.name for p in (live_log["tmp"] / "scratch").iterdir()]


def test_the_log_replayed_offline_gives_the_live_runs_deadline_verdicts(live_log: dict[str, Any]) -> None:
    """The live log is a trace ``rclverify monitor`` reads (the proxy's own lines on ``rclverify/proxy``, no
    message): its replay gives each node's deadline verdicts as the live run's own checks gave them."""
    log = live_log["tmp"] / "monitor.jsonl"
    r = subprocess.run([sys.executable, "-m", "rclverify.cli.commands", "monitor", "-w", str(EXAMPLE), "--json",
                        str(log)], capture_output=True, text=True, timeout=60, cwd=EXAMPLE,
                       env={**os.environ, "PYTHONPATH": str(REPO / "src")})
    assert r.stdout.strip().startswith("["), r.stdout[-2000:] + r.stderr[-2000:]
    offline = {e["node"]: e["deadlines"]["counts"] for e in json.loads(r.stdout) if "deadlines" in e}
    live = {e["node"]: e["deadlines"]["counts"] for e in live_log["record"]["topic_deadlines"]}
    assert offline == live, (offline, live)
    assert offline["Base"]["false"] == _missed(live_log) and offline["Mover"]["true"] == 1, offline  # the late call, the feedback
