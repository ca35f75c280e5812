"""Every call paired right, or not at all: real rclpy services on Fast DDS
(docs/monitors.md, "Services and actions over DDS"; docs/ros2.md).

rmw_fastrtps carries a reply's request identity in RTPS inline QoS, which
the monitor's DDS reader does not see, so calls without introspection are
paired by their order, per server, where the order is certain
(runtime/dds/order.py).  One rclpy process, one monitor started first:

* ``base`` serves ``/estop``; ``teleop`` calls it six times, one call at a
  time; call 3 is answered wrongly, call 5 right but 350 ms late (the
  deadline is 200 ms).  Each call is judged as its own: the violation is
  call 3's, the late answer call 5's, the deadlines false for calls 3 (its
  only answer is wrong) and 5, nothing blamed on another call;
* ``dual_a`` and ``dual_b`` both serve ``/dual`` (two servers of one
  service: each answers every request, the client takes the first reply);
  ``dual_b`` answers wrongly.  Its wrong replies are judged against its own
  calls and named by its node, never dropped;
* ``pile_a`` and ``pile_b`` serve ``/pile``; the slow ``pile_b`` answers
  after the client's next call was written: which request each of its
  replies answers cannot be known: inconclusive with the reason, counted,
  never paired by a guess and never dropped.

The live log, replayed offline, gives the same summary.
"""
from __future__ import annotations

import json
import signal
from typing import Any, Iterator

import pytest
from _procs import calls_judged, stop, wait_for, wait_logged
from _ros2 import live_workspace, rclverify, ros2_env, ros2_python, start_node

from rclverify.backends.monitors.dds_calls import CallBook, replay
from rclverify.lang.typecheck import load

RCL = """\
node Base {
  inputs( req : BOOL )
  outputs( ok : BOOL )
  services( std_srvs/SetBool estop serves(in.req, out.ok) )
  assume( TRUE )
  guarantee( in.req -> out.ok ) triggered by in.req within 200 ms
}

node Dual {
  inputs( req : BOOL )
  outputs( ok : BOOL )
  services( std_srvs/SetBool dual serves(in.req, out.ok) )
  assume( TRUE )
  guarantee( in.req -> out.ok )
}

node Pile {
  inputs( req : BOOL )
  outputs( ok : BOOL )
  services( std_srvs/SetBool pile serves(in.req, out.ok) )
  assume( TRUE )
  guarantee( in.req -> out.ok )
}
"""

SYSTEM = """\
import time
import rclpy
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node
from std_srvs.srv import SetBool

t0 = time.monotonic()
rclpy.init()
nodes = {n: Node(n) for n in ("base", "teleop", "dual_a", "dual_b", "user", "pile_a", "pile_b", "stacker", "watch")}
calls = [0]

def estop(req, resp):
    calls[0] += 1
    if calls[0] == 5:
        time.sleep(0.35)  # right, but late: the deadline is 200 ms
    resp.success = calls[0] != 3  # the third answer is wrong
    return resp

def right(req, resp):
    resp.success = True
    return resp

def wrong(req, resp):
    time.sleep(0.3)  # dual_a's right answer first, the client's: 300 ms, more than a loaded machine adds
    resp.success = False
    return resp

slow_answers = [0]

def slow(req, resp):
    time.sleep(0.5)  # the client's next call is written before this reply, however loaded the machine
    resp.success = True
    slow_answers[0] += 1
    return resp

nodes["base"].create_service(SetBool, "estop", estop)
nodes["dual_a"].create_service(SetBool, "dual", right)
nodes["dual_b"].create_service(SetBool, "dual", wrong)
nodes["pile_a"].create_service(SetBool, "pile", right)
nodes["pile_b"].create_service(SetBool, "pile", slow)
ex = MultiThreadedExecutor(num_threads=6)
for n in nodes.values():
    ex.add_node(n)

def spin(seconds):
    until = time.monotonic() + seconds
    while time.monotonic() < until:
        ex.spin_once(timeout_sec=0.01)

def call(client, data=True, timeout=5.0):
    fut = client.call_async(SetBool.Request(data=data))
    until = time.monotonic() + timeout
    while time.monotonic() < until and not fut.done():
        ex.spin_once(timeout_sec=0.01)
    return fut.result().success if fut.done() else None

teleop = nodes["teleop"].create_client(SetBool, "estop")
user = nodes["user"].create_client(SetBool, "dual")
stacker = nodes["stacker"].create_client(SetBool, "pile")
print("ready", flush=True)
until = time.monotonic() + 20
while time.monotonic() < until and (nodes["watch"].count_publishers("/rclverify/verdict") < 1
                                   or not all(c.service_is_ready() for c in (teleop, user, stacker))):
    ex.spin_once(timeout_sec=0.05)
# the monitor hears a client's requests once its reader matched the client's writer; a reply within the
# monitor's horizon (1 s) after that could answer a request written before: wait past it
spin(2.5)
print("matched", round(time.monotonic() - t0, 2), flush=True)
print("estop", [call(teleop) for _ in range(6)], flush=True)
dual = []
for _ in range(3):
    dual.append(call(user))
    spin(0.6)  # both servers' replies come before the next call
print("dual", dual, flush=True)
print("pile", [call(stacker) for _ in range(3)], flush=True)
until = time.monotonic() + 10
while time.monotonic() < until and slow_answers[0] < 3:  # pile_b's three late replies written
    ex.spin_once(timeout_sec=0.05)
spin(0.2)
print("done", round(time.monotonic() - t0, 2), flush=True)
while True:
    ex.spin_once(timeout_sec=0.1)
"""


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, Any]]:
    ros2_python()  # skips, with the reason, without a ROS 2 Python
    tmp = tmp_path_factory.mktemp("paired")
    ws = live_workspace(tmp, RCL, setbool=True)
    env = ros2_env(tmp)
    monitor = system = deaf = None
    try:
        # the rclpy source hears a call only through introspection events, which these servers do not publish:
        # it must say so and never be green (docs/ros2.md, "Two sources")
        deaf = rclverify(["monitor", "-w", str(ws), "--live", "--ros2", "--interfaces", "interfaces", "--strict",
                          "--node", "Base", "--source", "rclpy", "--ros2-python", str(ros2_python()),
                          "--verdict-topic", "/deaf/verdict", "--status", "0", "--duration", "60", "--evidence",
                          str(tmp / "deaf.json")], env, tmp, tmp / "deaf.out")
        # a 300 ms lateness bound: requests, replies and deadlines at their writers' source times (with none,
        # at their receipt, in the order heard, which a loaded machine's delivery may change)
        monitor = rclverify(["monitor", "-w", str(ws), "--live", "--ros2", "--interfaces", "interfaces", "--strict",
                             "--horizon", "1.0", "--reorder-window", "0.3", "--status", "0", "--duration", "60",
                             "--log", str(tmp / "live.jsonl"), "--evidence", str(tmp / "live.json")],
                            env, tmp, tmp / "monitor.out")
        wait_for(tmp / "monitor.out", "monitoring", 30)
        wait_for(tmp / "deaf.out", "monitoring", 30)
        system = start_node(tmp, "system", SYSTEM, env)
        wait_for(tmp / "system.log", "done", 40)
        wait_logged(tmp / "live.jsonl", _all_judged, 30)  # whatever the load, not a sleep
        stop(monitor, signal.SIGINT)
        stop(deaf, signal.SIGINT)
        yield {"ws": ws, "code": monitor.returncode, "out": (tmp / "monitor.out").read_text(),
               "deaf": {"code": deaf.returncode, "out": (tmp / "deaf.out").read_text(),
                        "record": json.loads((tmp / "deaf.json").read_text())},
               "system": (tmp / "system.log").read_text(),
               "log": [json.loads(x) for x in (tmp / "live.jsonl").read_text().splitlines()],
               "record": json.loads((tmp / "live.json").read_text())}
    finally:
        for p in (system, monitor, deaf):
            if p is not None:
                stop(p)


def _all_judged(log: list[dict[str, Any]]) -> bool:
    """Every call of the run judged in ``log``: six of /estop and their deadlines (and call 5's late answer),
    three of each /dual server, three of pile_a, pile_b's three replies logged unpaired."""
    deadlines = [x for x in log if x.get("kind") == "deadline" and x["verdict"]["node"] == "Base"]
    return calls_judged(log, {"Base": 6, "Dual": 6, "Pile": 3}) \
        and len(deadlines) >= 7 and sum(x.get("link") == "pile" and bool(x.get("unpaired")) for x in log) >= 3


def _verdicts(run: dict[str, Any], node: str) -> list[dict[str, Any]]:
    return sorted((x["verdict"] for x in run["log"] if x.get("topic") == "rclverify/verdict" and "kind" not in x
                   and x["verdict"].get("call") and x["verdict"]["node"] == node), key=lambda v: v["time"])


def _call_no(where: str) -> int:
    return int(where.split("#")[1].split()[0])


def test_six_sequential_calls_each_judged_as_its_own(run: dict[str, Any]) -> None:
    assert "estop [True, True, False, True, True, True]" in run["system"], run["system"]
    base = _verdicts(run, "Base")
    assert [(v["verdict"], _call_no(v["where"])) for v in base] == \
        [("satisfied", 1), ("satisfied", 2), ("violated", 3), ("satisfied", 4), ("satisfied", 5),
         ("satisfied", 6)], (base, run["out"])
    dl = [x["verdict"] for x in run["log"] if x.get("kind") == "deadline" and x["verdict"]["node"] == "Base"
          and not x["verdict"]["update"]]
    assert sorted((_call_no(v["trigger_where"]), v["verdict"]) for v in dl) == \
        [(1, "true"), (2, "true"), (3, "false"), (4, "true"), (5, "false"), (6, "true")], dl
    (late,) = [x["verdict"] for x in run["log"] if x.get("kind") == "deadline" and x["verdict"]["update"]]
    assert _call_no(late["trigger_where"]) == 5 and late["answer"] - late["trigger_stamp"] >= 0.35
    assert not [x for x in run["log"] if x.get("link") == "estop" and (x.get("orphan") or x.get("unpaired"))]


def test_a_second_server_is_judged_on_its_own_answers(run: dict[str, Any]) -> None:
    assert "dual [True, True, True]" in run["system"], run["system"]  # the client took dual_a's answers
    dual = _verdicts(run, "Dual")
    by = {}
    for v in dual:
        by.setdefault(v["where"].split("answered by ")[1].split(" (")[0], []).append(v["verdict"])
    assert by == {"node /dual_a": ["satisfied"] * 3, "node /dual_b": ["violated"] * 3}, dual
    calls = {n["node"]: n for n in run["record"]["calls"]["nodes"]}
    assert calls["Dual"]["status"] == "failed"
    assert run["record"]["calls"]["counts"]["calls"] >= 6 + 3 + 3  # a request is counted once, whatever its servers


def test_replies_of_a_slow_second_server_are_undecided_never_dropped(run: dict[str, Any]) -> None:
    assert "pile [True, True, True]" in run["system"], run["system"]
    pile = _verdicts(run, "Pile")
    fast = [v["verdict"] for v in pile if "node /pile_a" in v["where"]]
    slow = [v for v in pile if "node /pile_b" in v["where"]]
    assert fast == ["satisfied"] * 3, pile
    assert slow and all(v["verdict"] == "inconclusive" for v in slow), pile
    assert "requests of /pile were unanswered" in slow[0]["reason"]
    unpaired = [x for x in run["log"] if x.get("link") == "pile" and x.get("unpaired")]
    slow_writer = slow[0]["where"].split("(writer ")[1].split(")")[0]
    # the three calls of pile_b, each logged with its reason; none of pile_a's
    assert len(unpaired) == 3 and {x["key"][-1] for x in unpaired} == {slow_writer}


def test_strict_exit_and_the_replay(run: dict[str, Any]) -> None:
    assert run["code"] == 1, run["out"]
    checked = load([run["ws"] / "contracts" / "sys.rcl"])
    book = CallBook(checked, [(n, lk) for n in checked.nodes.values() for lk in n.node.links], {}, 1.0)
    summary = replay(book, run["log"])
    assert summary["counts"] == run["record"]["calls"]["counts"]
    assert {r["node"]: r["counts"] for r in summary["nodes"]} == \
        {n["node"]: n["counts"] for n in run["record"]["calls"]["nodes"]}


def test_the_rclpy_source_says_it_cannot_hear_calls_without_introspection(run: dict[str, Any]) -> None:
    deaf = run["deaf"]
    assert deaf["record"]["source"] == "rclpy" and deaf["record"]["unseen"], deaf["record"].get("unseen")
    assert "warning: /estop: the rclpy source hears calls through introspection events only, and no " \
           "introspection event of its server or of every client was heard" in deaf["out"], deaf["out"]
    assert any(i.get("item", "").endswith("/estop") or "/estop" in json.dumps(i) for i in deaf["record"]["not_judged"])
    assert deaf["code"] == 1, deaf["out"]  # nothing judged of Base: never green under --strict
