"""Silence is never green, and live = offline for deadlines (issue 62), with
real rclpy nodes on Fast DDS (tests/_ros2.py).

One ROS 2 system runs once for the module: ``echo`` answers each ``/r``
on ``/out`` at once, except the value 3.0, which it answers 301 ms late
(the contract's deadline is 100 ms); ``driver`` sends ten values, each
after the previous answer; ``base`` serves ``/estop`` (std_srvs/SetBool)
and ``driver`` calls it twice (without waiting for ``service_is_ready()``:
rmw_fastrtps calls a server ready only when the request topic has as many
readers as the reply topic has writers, which a monitor reading both breaks).  Four monitors watch the same run, each as
its own process with its own verdict topic:

* ``echo``: ``--node Echo --strict``: the late answer is a ``false``
  deadline, exit 1; its log, checked offline by ``rclverify monitor``,
  gives the same verdicts and exit code;
* ``ghost`` and ``ghost_lax``: ``--node Ghost`` (a contract whose topics
  nobody publishes), with and without ``--strict``: nothing heard, said
  item by item; exit 1 under ``--strict``, else 0 with the node
  ``pending``, never ``discharged``;
* ``base``: ``--node Base --strict``: the service either is judged (its
  calls paired and checked) or is listed as not judged with the reason, and
  then the exit is 1; whichever the middleware's pairing allows, never a
  silent 0.

The offline checks of the echo run's log under ``--strict`` close it: a
trace with no event of a node (Ghost) exits 1 and says so.

The whole module runs twice, the monitors hearing the system through each
source (``--source dds`` and ``--source rclpy``, docs/ros2.md "Two
sources"): the same verdicts and exit codes; each record must name the
source asked.
"""
from __future__ import annotations

import json
import signal
from pathlib import Path
from typing import Any, Iterator

import pytest
from _procs import stop, wait_for, wait_logged
from _ros2 import live_workspace, rclverify, ros2_env, ros2_python, start_node

from rclverify.cli.commands import main

RCL = """\
node Echo {
  inputs( r : REAL )
  outputs( y : REAL )
  topics( std_msgs/Float64 r matches(in.r), std_msgs/Float64 out matches(out.y) )
  assume( in.r >= 0 )
  guarantee( out.y == in.r ) triggered by in.r within 100 ms
}

node Ghost {
  inputs( g : REAL )
  outputs( h : REAL )
  topics( std_msgs/Float64 ghost_in matches(in.g), std_msgs/Float64 ghost_out matches(out.h) )
  assume( TRUE )
  guarantee( out.h >= in.g ) triggered by in.g within 100 ms
}

node Base {
  inputs( req : BOOL )
  outputs( ok : BOOL )
  services( std_srvs/SetBool estop serves(in.req, out.ok) )
  assume( TRUE )
  guarantee( in.req -> out.ok )
}
"""

SYSTEM = """\
import time
import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from std_msgs.msg import Float64
from std_srvs.srv import SetBool

rclpy.init()
echo, driver, base = Node("echo"), Node("driver"), Node("base")
out = echo.create_publisher(Float64, "out", 10)

def answer(msg):
    if msg.data == 3.0:
        time.sleep(0.301)  # the one late answer: the deadline is 100 ms
    out.publish(Float64(data=msg.data))

echo.create_subscription(Float64, "r", answer, 10)
base.create_service(SetBool, "estop", lambda req, resp: (setattr(resp, "success", True), resp)[1])
r = driver.create_publisher(Float64, "r", 10)
answers = []
driver.create_subscription(Float64, "out", lambda m: answers.append(m.data), 10)
client = driver.create_client(SetBool, "estop")
ex = SingleThreadedExecutor()
for n in (echo, driver, base):
    ex.add_node(n)
print("ready", flush=True)
until = time.monotonic() + 20
# the monitors' readers are made when they discover a publisher: wait until they match
while time.monotonic() < until and (r.get_subscription_count() < 2 or out.get_subscription_count() < 2):
    ex.spin_once(timeout_sec=0.05)
print("matched", r.get_subscription_count(), out.get_subscription_count(), flush=True)
# the writer has matched the monitors' readers; their own side of the match can lag under load, and a
# volatile reader misses what was written before it matched (a full suite once heard nothing on /r after
# 0 s, and again after 1 s on a machine running the suite's three workers: the monitor then says so,
# `pending`, never green; a transient-local /r would let the monitor hear the readings late, after their
# answers)
time.sleep(3.0)
for k in range(10):
    r.publish(Float64(data=float(k)))
    until = time.monotonic() + 3
    while len(answers) <= k and time.monotonic() < until:
        ex.spin_once(timeout_sec=0.01)
    time.sleep(0.03)
# while the monitor reads /estop's request and reply topics, rmw_fastrtps may never call the server ready (it
# wants as many request readers as reply writers): wait a little, then call anyway (the server is there)
# the base monitor's reader of the requests, beside the server's (the raw DDS topic), on the DDS source only: the
# rclpy source hears calls through introspection events alone (REQUEST_READERS: 2, or 1 for the server)
until = time.monotonic() + 5
while time.monotonic() < until and len(driver.get_subscriptions_info_by_topic("rq/estopRequest", True)) \
        < REQUEST_READERS:
    ex.spin_once(timeout_sec=0.05)
replies = []
for k in range(2):
    fut = client.call_async(SetBool.Request(data=True))
    ex.spin_until_future_complete(fut, timeout_sec=3)
    replies.append(fut.done())
print("service ready", client.service_is_ready(), "readers", len(driver.get_subscriptions_info_by_topic(
    "rq/estopRequest", True)), "replies", replies, flush=True)
print("done", len(answers), flush=True)
while True:
    ex.spin_once(timeout_sec=0.1)
"""

MONITORS = {"echo": ["--node", "Echo", "--strict"], "ghost": ["--node", "Ghost", "--strict"],
            "ghost_lax": ["--node", "Ghost"], "base": ["--node", "Base", "--strict"]}


@pytest.fixture(scope="module", params=["dds", "rclpy"])
def run(request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, Any]]:
    """The run heard through each source (docs/ros2.md, "Two sources"): the same verdicts and exit codes."""
    py = ros2_python()  # skips, with the reason, without a ROS 2 Python
    tmp = tmp_path_factory.mktemp(f"silence-{request.param}")
    ws = live_workspace(tmp, RCL, setbool=True)
    env = ros2_env(tmp)
    procs = {}
    system = None
    try:
        # a 300 ms lateness bound: the monitors place /r and /out at their writers' source times; with none
        # (window 0) they judge in the order heard, and a full suite's three workers on two cores once
        # delivered an /out after the next /r to the echo monitor (one answer undecided, one question
        # superseded: honest, never red, but not the run's 10 satisfied answers)
        for name, extra in MONITORS.items():
            procs[name] = rclverify(
                ["monitor", "-w", str(ws), "--live", "--ros2", "--interfaces", "interfaces", "--horizon", "1.0",
                 "--reorder-window", "0.3", "--status", "0", "--duration", "60", "--verdict-topic",
                 f"/{name}/verdict", "--log", str(tmp / f"{name}.jsonl"), "--evidence", str(tmp / f"{name}.json"),
                 "--source", request.param, "--ros2-python", str(py), *extra], env, tmp, tmp / f"{name}.out")
        for name in MONITORS:
            wait_for(tmp / f"{name}.out", "monitoring", 30)
        readers = 2 if request.param == "dds" else 1
        system = start_node(tmp, "system", SYSTEM.replace("REQUEST_READERS", str(readers)), env)
        wait_for(tmp / "system.log", "done", 40)
        # the ten readings and their answers heard by the echo monitor and released past its watermark, however
        # loaded the machine (a fixed 0.3 s assumed an idle one)
        wait_logged(tmp / "echo.jsonl", lambda log: all(sum(x.get("topic") == t for x in log) >= 10
                                                        for t in ("r", "out")), 30)
        codes = {}
        for name, p in procs.items():
            stop(p, signal.SIGINT)
            codes[name] = p.returncode
        assert {r["source"] for r in (json.loads((tmp / f"{n}.json").read_text()) for n in MONITORS)} == \
            {request.param}  # never a silent fall-back to the other source
        yield {"source": request.param, "tmp": tmp, "ws": ws, "codes": codes,
               "out": {n: (tmp / f"{n}.out").read_text() for n in MONITORS},
               "record": {n: json.loads((tmp / f"{n}.json").read_text()) for n in MONITORS},
               "system": (tmp / "system.log").read_text()}
    finally:
        if system is not None:
            stop(system)
        for p in procs.values():
            stop(p)


def _offline(run: dict[str, Any], capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, list[Any], str]:
    """``rclverify monitor --json ARGS`` on the echo run's log: exit code, report, stderr."""
    capsys.readouterr()
    rc = main(["monitor", "-w", str(run["ws"]), "--horizon", "1.0", "--json", *args, str(run["tmp"] / "echo.jsonl")])
    got = capsys.readouterr()
    return rc, json.loads(got.out), got.err


def test_a_late_answer_is_a_false_deadline_live_and_offline(run: dict[str, Any],
                                                             capsys: pytest.CaptureFixture[str]) -> None:
    assert "done 10" in run["system"], run["system"]
    rec = run["record"]["echo"]
    (dl,) = rec["topic_deadlines"]
    assert dl["node"] == "Echo" and dl["status"] == "failed", (dl, run["out"]["echo"])
    counts = dl["deadlines"]["counts"]
    # every answer but the late one comes within 100 ms on an idle machine (9 true); a loaded one may be slower
    assert counts["false"] >= 1 and counts["true"] + counts["false"] == 10 and counts["true"] >= 5, dl
    assert "100 ms" in dl["deadlines"]["first_false"]["reason"]
    log = [json.loads(x) for x in (run["tmp"] / "echo.jsonl").read_text().splitlines()]
    messages = [x for x in log if not x["topic"].startswith("rclverify/")]  # "message N": the N-th released
    late = [messages[int(x["verdict"]["trigger_where"].split()[-1])]["data"] for x in log
            if x.get("kind") == "deadline" and x["verdict"]["verdict"] == "false" and not x["verdict"]["update"]]
    assert 3.0 in late and len(late) == counts["false"], late
    assert run["codes"]["echo"] == 1 and "deadlines: Echo: failed" in run["out"]["echo"]
    echo = next(n for n in rec["nodes"] if n["node"] == "Echo")
    assert rec["not_judged"] == [] and echo["counts"]["satisfied"] == 10, (rec["not_judged"], echo["counts"])
    # the log the live run wrote, checked offline: the same verdicts, the same exit code
    rc, report, _ = _offline(run, capsys, "--node", "Echo", "--strict")
    off = next(e for e in report if "deadlines" in e)
    assert rc == 1 and off["status"] == "failed"
    assert off["deadlines"]["counts"] == dl["deadlines"]["counts"]
    assert off["deadlines"]["first_false"]["trigger_stamp"] == dl["deadlines"]["first_false"]["trigger_stamp"]
    untimed = next(e for e in report if "counts" in e)
    assert untimed["counts"] == echo["counts"] and untimed["not_judged"] == []


def test_a_run_that_heard_nothing_is_never_green(run: dict[str, Any]) -> None:
    for name in ("ghost", "ghost_lax"):
        rec = run["record"][name]
        (ghost,) = rec["nodes"]
        assert ghost["status"] == "pending" and rec["topic_deadlines"][0]["status"] == "pending", rec
        assert "(not judged: nothing heard: no message on /ghost_in, /ghost_out during the live run)" in \
            ghost["explanation"], ghost["explanation"]
        items = {(i["kind"], i["name"]): i["reason"] for i in rec["not_judged"]}
        assert items == {("node", "Ghost"): "nothing heard", ("topic", "/ghost_in"): "nothing heard",
                         ("topic", "/ghost_out"): "nothing heard",
                         ("deadline", "Ghost guarantee(s) 1"): "nothing heard"}, rec["not_judged"]
        assert "not judged: topic /ghost_in (Ghost): nothing heard" in run["out"][name], run["out"][name]
    # the whole output with each exit code: this test failed in a full suite on a loaded machine and once in
    # about 40 runs alone or beside other live tests, with no word of why; the next failure says what differed
    assert run["codes"]["ghost"] == 1 and "--strict: 4 item(s) were not judged" in run["out"]["ghost"], \
        (run["codes"], run["out"]["ghost"])
    assert run["codes"]["ghost_lax"] == 0, (run["codes"], run["out"]["ghost_lax"])


def test_a_service_is_judged_or_said_not_judged(run: dict[str, Any]) -> None:
    """Whatever the pairing of Fast DDS's calls gives, the run is never a silent 0."""
    rec = run["record"]["base"]
    items = [i for i in rec["not_judged"] if i["kind"] == "service"]
    calls = {n["node"]: n["status"] for n in rec.get("calls", {}).get("nodes", [])}
    if items:
        assert items[0]["name"] == "/estop" and items[0]["reason"] in (
            "nothing heard", "not paired", "no answer", "not decoded", "endpoint not heard"), items
        assert run["codes"]["base"] == 1 and "--strict" in run["out"]["base"]
    else:
        assert calls.get("Base") == "discharged" and run["codes"]["base"] == 0, (calls, run["out"]["base"])


def test_offline_a_trace_without_a_nodes_event_fails_strict(run: dict[str, Any],
                                                            capsys: pytest.CaptureFixture[str]) -> None:
    rc, report, err = _offline(run, capsys, "--node", "Ghost", "--strict")
    (ghost, _deadlines) = report
    assert rc == 1 and ghost["status"] == "pending" and "--strict: 4 item(s) were not judged" in err
    assert "(not judged: nothing heard: no message on /ghost_in, /ghost_out in " in ghost["explanation"]
    assert {i["reason"] for i in ghost["not_judged"]} == {"nothing heard"} and len(ghost["not_judged"]) == 4
    rc, report, _ = _offline(run, capsys, "--node", "Ghost")
    assert rc == 0 and report[0]["status"] == "pending"
