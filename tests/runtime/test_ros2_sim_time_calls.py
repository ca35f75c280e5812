"""Calls' deadlines kept in simulated time, live (docs/semantics.md, "Deadlines in simulated time"): a
``std_srvs/SetBool`` server under ``use_sim_time`` beside a ``/clock`` at a real-time factor of 0.5 (its
calls heard through the DDS source) or 2 (through the rclpy source, from the introspection events), its
log and its bag judged offline.

Real rclpy nodes on Fast DDS: ``sim`` publishes ``/clock`` every 10 ms of the wall clock, ``10 * FACTOR``
ms further each time; ``base`` (``use_sim_time: true``) serves ``/estop`` and answers each request once its
own clock (``/clock``) has moved ``DELAY`` past the request's arrival; ``teleop`` (the wall clock) calls it
``ROUNDS`` times, one call at a time.  The contract: the answer within 400 ms of the request.

* At 0.5 the server waits 300 ms of simulated time, 600 ms of the wall clock: with the mapping's
  ``use_sim_time: true`` every call's deadline is met, live, on the log and on the bag; the control, the
  same log judged with the node said to keep the wall clock, misses (nearly) every one.
* At 2 the server waits 600 ms of simulated time (a seeded defect), 300 ms of the wall clock: every
  deadline missed, live, on the log and on the bag; the control meets (nearly) every one.
* The mapping saying nothing: every deadline ``undecided`` (the two clocks disagree).
"""
from __future__ import annotations

import json
import signal
import subprocess
import sys
import time
from collections import Counter
from pathlib import Path
from typing import Any, Iterator

import pytest
from _procs import stop, wait_for, wait_logged
from _ros2 import AWAIT_MONITOR, clock_node, live_workspace, rclverify, ros2_env, ros2_python, start_node

RCL = """\
node Base {
  inputs( req : BOOL )
  outputs( ok : BOOL )
  services( std_srvs/SetBool estop serves(in.req, out.ok) )
  assume( TRUE )
  guarantee( in.req -> out.ok ) triggered by in.req within 400 ms
}
"""
ROUNDS = 8
#: real-time factor -> the server's delay in simulated time (s)
DELAY = {0.5: 0.3, 2.0: 0.6}

SERVER = """\
import time
import rclpy
from rclpy.callback_groups import MutuallyExclusiveCallbackGroup
from rclpy.clock import Clock, ClockType
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import qos_profile_system_default
from rclpy.service_introspection import ServiceIntrospectionState
from std_srvs.srv import SetBool

rclpy.init()
n = Node("base", parameter_overrides=[Parameter("use_sim_time", Parameter.Type.BOOL, True)])

def estop(req, resp):
    until = n.get_clock().now().nanoseconds + round(DELAY * 1e9)  # /clock under use_sim_time
    while n.get_clock().now().nanoseconds < until:  # the node's clock moves in the other callback group
        time.sleep(0.001)
    resp.success = bool(req.data)
    return resp

srv = n.create_service(SetBool, "estop", estop, callback_group=MutuallyExclusiveCallbackGroup())
srv.configure_introspection(Clock(clock_type=ClockType.SYSTEM_TIME), qos_profile_system_default,
                            ServiceIntrospectionState.CONTENTS)
ex = MultiThreadedExecutor(num_threads=3)
ex.add_node(n)
while n.get_clock().now().nanoseconds == 0:  # its own clock not yet on /clock (reads 0): its waits would be short
    ex.spin_once(timeout_sec=0.05)
print("ready", flush=True)
ex.spin()
"""

CLIENT = """\
import time
import rclpy
from rclpy.clock import Clock, ClockType
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.qos import qos_profile_system_default
from rclpy.service_introspection import ServiceIntrospectionState
from std_srvs.srv import SetBool

rclpy.init()
n = Node("teleop")
cli = n.create_client(SetBool, "estop")
cli.configure_introspection(Clock(clock_type=ClockType.SYSTEM_TIME), qos_profile_system_default,
                            ServiceIntrospectionState.CONTENTS)
AWAIT_MONITOR
until = time.monotonic() + 20
while time.monotonic() < until and not cli.service_is_ready():
    spin(0.05)
spin(2.0)  # past the monitor's horizon after its readers matched: no reply can answer an unheard request
for k in range(1, ROUNDS + 1):
    fut = cli.call_async(SetBool.Request(data=True))
    until = time.monotonic() + 5
    while time.monotonic() < until and not fut.done():
        ex.spin_once(timeout_sec=0.005)
    print("call", k, fut.done() and fut.result().success, flush=True)
    spin(0.3)
print("done", flush=True)
while True:
    ex.spin_once(timeout_sec=0.1)
""".replace("AWAIT_MONITOR\n", AWAIT_MONITOR).replace("ROUNDS", str(ROUNDS))


def _deadlines(lines: list[dict[str, Any]]) -> list[dict[str, Any]]:
    return [x["verdict"] for x in lines if x.get("kind") == "deadline" and x["verdict"].get("node") == "Base"]


def _finals(verdicts: list[dict[str, Any]]) -> Counter[str]:
    """Each call's final deadline verdict (an update replaces what it updates), counted."""
    last: dict[str, str] = {}
    for v in verdicts:
        last[v["trigger_where"]] = v["verdict"]
    return Counter(last.values())


def _offline(ws: Path, mapping: str, trace: Path, tmp: Path) -> dict[str, Any]:
    """``rclverify monitor --json`` of ``trace`` under ``mapping``: the calls' deadline result of Base."""
    r = subprocess.run([sys.executable, "-m", "rclverify.cli.commands", "monitor", "-w", str(ws), "--mapping",
                        mapping, "--horizon", "1", "--json", str(trace)],
                       capture_output=True, text=True, timeout=120, cwd=tmp)
    report = json.loads(r.stdout) if r.stdout.strip() else None
    got = [e["call_deadlines"] for e in report or [] if "call_deadlines" in e and e.get("node") == "Base"]
    assert len(got) == 1, r.stdout[-3000:] + r.stderr[-3000:]
    return dict(got[0])


@pytest.fixture(scope="module", params=[("dds", 0.5), ("rclpy", 2.0)], ids=["dds-half", "rclpy-double"])
def run(request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, Any]]:
    """One live run through a source at a factor; its log and bag judged offline under three mappings."""
    py = ros2_python()  # skips, with the reason, without a ROS 2 Python
    source, factor = request.param
    tmp = tmp_path_factory.mktemp(f"simcalls-{source}-{factor}")
    ws = live_workspace(tmp, RCL, "topics: {}\nuse_sim_time: true\n", setbool=True)
    (ws / "wall.yaml").write_text("topics: {}\nuse_sim_time: false\n")
    (ws / "unsaid.yaml").write_text("topics: {}\n")
    env = ros2_env(tmp)
    procs: list[subprocess.Popen[bytes]] = []
    try:
        procs.append(start_node(tmp, "sim", clock_node(factor), env))
        procs.append(start_node(tmp, "base", SERVER.replace("DELAY", repr(DELAY[factor])), env))
        monitor = rclverify(["monitor", "-w", str(ws), "--live", "--ros2", "--interfaces", "interfaces",
                             "--mapping", "mapping.yaml", "--horizon", "1", "--status", "0", "--duration", "90",
                             "--source", source, "--ros2-python", str(py), "--log", str(tmp / "live.jsonl"),
                             "--record", str(tmp / "bag"), "--evidence", str(tmp / "live.json")],
                            env, tmp, tmp / "monitor.out")
        procs.append(monitor)
        procs.append(start_node(tmp, "teleop", CLIENT, env))
        wait_for(tmp / "teleop.log", "done", 90)
        wait_logged(tmp / "live.jsonl", lambda lines: len(_finals(_deadlines(lines))) > 0 and sum(
            _finals(_deadlines(lines)).values()) >= ROUNDS and not _finals(_deadlines(lines))["currently_false"], 30)
        time.sleep(1.0)  # /clock passes the last deadline
        stop(monitor, signal.SIGINT)
        lines = [json.loads(x) for x in (tmp / "live.jsonl").read_text().splitlines()]
        offline = {name: _offline(ws, mapping, trace, tmp) for name, mapping, trace in (
            ("log", "mapping.yaml", tmp / "live.jsonl"), ("bag", "mapping.yaml", tmp / "bag"),
            ("wall", "wall.yaml", tmp / "live.jsonl"), ("unsaid", "unsaid.yaml", tmp / "live.jsonl"))}
        yield {"factor": factor, "lines": lines, "offline": offline, "record": json.loads(
            (tmp / "live.json").read_text()), "out": (tmp / "monitor.out").read_text(errors="replace"),
            "client": (tmp / "teleop.log").read_text(errors="replace")}
    finally:
        for p in procs:
            stop(p)


def _readings(run: dict[str, Any]) -> list[tuple[bool | None, bool]]:
    """Each call of the live log read by the rule, from the book's own lines: ``(late in simulated time,
    late on the wall clock)``; simulated lateness ``None`` for a request before the book's first ``/clock``
    sample (no known simulated time).  Late in simulated time: a ``/clock`` sample past the request's
    ``/clock`` plus 400 ms placed at or before the reply (the mapping gives no transport skew)."""
    calls = [x for x in run["lines"] if x.get("kind") == "call"]
    clock: list[tuple[float, int]] = []
    asked: dict[str, tuple[float, int | None]] = {}
    out = []
    for x in calls:
        if x.get("part") == "clock":
            clock.append((x["time"], x["clock"]["sec"] * 1_000_000_000 + x["clock"]["nanosec"]))
        elif x.get("part") == "request" and not x.get("also"):
            asked[json.dumps(x["key"])] = (x["time"], clock[-1][1] if clock else None)
        elif x.get("part") == "response" and json.dumps(x.get("key")) in asked:
            t, sq = asked.pop(json.dumps(x["key"]))
            sim = None if sq is None else any(v > sq + 400_000_000 for tc, v in clock if tc <= x["time"])
            out.append((sim, x["time"] - t > 0.4))
    assert not asked, asked  # every call answered
    return out


def _want(run: dict[str, Any], mode: bool | None) -> tuple[int, int, int]:
    """(true, false, undecided) by :func:`_readings` for the node said to keep simulated time (``True``),
    the wall clock (``False``), or not said (``None``: decided where both clocks agree)."""
    got: Counter[str] = Counter()
    for sim, wall in _readings(run):
        if mode is False:
            got["false" if wall else "true"] += 1
        elif sim is None:
            got["undecided" if mode or wall else "true"] += 1  # not said: the run's clock, never false after
        elif mode is True:
            got["false" if sim else "true"] += 1
        else:
            got["false" if sim and wall else "true" if not (sim or wall) else "undecided"] += 1
    return got["true"], got["false"], got["undecided"]


def _apart(run: dict[str, Any]) -> int:
    """How many calls the two clocks judge apart (a decided simulated-time verdict the wall clock's
    opposite): the calls on which the factor decides.  Under load the server itself can answer late in
    both clocks, so the test asks for some, not for all."""
    return sum(1 for sim, wall in _readings(run) if sim is not None and sim != wall)


def _counts(res: dict[str, Any]) -> tuple[int, int, int]:
    return res["counts"]["true"], res["counts"]["false"], res["unaccepted"]["undecided"]


def test_call_deadlines_are_judged_in_simulated_time_live_on_the_log_and_on_the_bag(run: dict[str, Any]) -> None:
    """Met at 0.5 (600 ms of the wall clock, 300 ms simulated), missed at 2 (300 ms of the wall clock, 600 ms
    simulated), live and on every offline path alike, each call as the rule reads the log's own ``/clock``
    (a server delayed under load past its deadline in simulated time is late); a request before the book
    heard ``/clock`` has no known simulated time: undecided, never judged on the wall clock."""
    assert run["client"].count("True") == ROUNDS, run["client"]
    assert [x for x in run["lines"] if x.get("part") == "clock"], "the book wrote no clock line"
    want = _want(run, True)
    live = _finals(_deadlines(run["lines"]))
    assert (live["true"], live["false"], live["undecided"]) == want, (live, run["out"][-2000:])
    for path in ("log", "bag"):
        assert _counts(run["offline"][path]) == want, (path, run["offline"][path])
    assert _apart(run) >= 1 and want[0 if run["factor"] == 0.5 else 1] >= 1, want  # the factor decides some


def test_the_control_judges_the_same_log_on_the_wall_clock(run: dict[str, Any]) -> None:
    """The node said to keep the wall clock: each deadline as the log's own request and reply times give it,
    the opposite of simulated time on every call the two clocks judge apart."""
    want = _want(run, False)
    assert _counts(run["offline"]["wall"]) == want, run["offline"]["wall"]
    assert want[1 if run["factor"] == 0.5 else 0] >= 1, want


def test_a_node_whose_clock_is_not_said_is_undecided(run: dict[str, Any]) -> None:
    """The mapping says nothing: decided only where the two clocks agree, so every deadline they judge
    apart is undecided."""
    want = _want(run, None)
    assert _counts(run["offline"]["unsaid"]) == want, run["offline"]["unsaid"]
    assert want[2] >= _apart(run) >= 1, want  # where the clocks disagree it is undecided
