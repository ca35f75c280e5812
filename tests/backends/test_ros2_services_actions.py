"""Services and actions of real rclpy nodes on Fast DDS, judged call by call
(issue 62; docs/monitors.md, "Services and actions over DDS"; docs/ros2.md).

rmw_fastrtps writes a service's requests and replies without the request
header rmw_cyclonedds puts in the payload: a reply names its request only in
RTPS inline QoS, which the monitor's DDS reader does not see.  One ROS 2
system (one rclpy process, tests/_ros2.py) runs once for the module, and one
monitor watches it:

* ``base`` serves ``/estop`` (std_srvs/SetBool), answering the first call
  right, the second wrong, the third right but 400 ms late (the contract's
  deadline is 200 ms); ``teleop`` calls it three times, one call at a time:
  each call is paired by order (one outstanding) and judged;
* ``brake`` serves ``/brake`` and answers every call ``success: false``
  after 200 ms; two clients call it at once (``data: true`` and ``data:
  false``, two outstanding): which answer is whose cannot be known: the
  ``data: true`` call is inconclusive with the reason, never guessed (by
  order, the wrong answer would be blamed on one of them; the ``data:
  false`` call holds whatever its answer);
* ``lamp`` is ``brake`` again with service introspection enabled
  (``configure_introspection(..., CONTENTS)``): the same two concurrent
  calls are paired exactly by ``client_gid`` + ``sequence_number``: the
  ``data: true`` call is violated, the ``data: false`` one satisfied;
* ``fib`` serves the test_msgs/action/Fibonacci action; ``mission`` sends
  three goals one after the other (order 3; order 4, whose result the
  server spoils with a negative last number; order 40, canceled while it
  runs): each goal is judged, the second violated, and the cancel request
  and reply are logged with the goal's id.

The live log, read back by ``rclverify monitor LOG``, gives the same call verdicts, call deadlines, items
not judged and exit code as the live run (issue 62: live = offline).

A second monitor, told the wrong middleware (``RMW_IMPLEMENTATION=rmw_cyclonedds_cpp``),
names each Fast DDS writer of ``/estop`` whose calls it cannot read, and exits 1 under ``--strict``.

A third monitor hears the same system, run again in a domain of its own, through the rclpy source
(docs/ros2.md, "Two sources"), which reads no request or reply topic: ``lamp``'s calls through its introspection events and ``fib``'s goals through the
introspection events of the action's own services (the server enables them) give the DDS monitor's verdicts;
``/estop`` and ``/brake``, without introspection, are said unheard and never green.
"""
from __future__ import annotations

import json
import re
import signal
from pathlib import Path
from typing import Any

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

node Brake {
  inputs( req : BOOL )
  outputs( ok : BOOL )
  services( std_srvs/SetBool brake serves(in.req, out.ok) )
  assume( TRUE )
  guarantee( in.req -> out.ok )
}

node Lamp {
  inputs( req : BOOL )
  outputs( ok : BOOL )
  services( std_srvs/SetBool lamp serves(in.req, out.ok) )
  assume( TRUE )
  guarantee( in.req -> out.ok )
}

node Fib {
  inputs( order : INTEGER )
  outputs( last : INTEGER, final : INTEGER )
  actions( test_msgs/Fibonacci fib serves(in.order, out.last, out.final) )
  assume( in.order >= 1 )
  guarantee( out.final >= 0 )
}
"""
# the feedback's and the result's number: the last of the sequence (docs/monitors.md, "Field paths")
MAPPING = """\
topics:
  fib/feedback: {fields: ["sequence[-1]"]}
  fib/result: {fields: ["sequence[-1]"]}
"""
FIBONACCI = "int32 order\n---\nint32[] sequence\n---\nint32[] sequence\n"

SYSTEM = """\
import time
import rclpy
from rclpy.action import ActionClient, ActionServer, CancelResponse
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node
from rclpy.qos import qos_profile_services_default
from rclpy.service_introspection import ServiceIntrospectionState
from std_srvs.srv import SetBool
from test_msgs.action import Fibonacci

t0 = time.monotonic()
rclpy.init()
nodes = {n: Node(n) for n in ("base", "teleop", "brake", "brake_a", "brake_b", "lamp", "lamp_a", "lamp_b",
                              "fib", "mission", "watch")}
calls = [0]

def estop(req, resp):
    calls[0] += 1
    if calls[0] == 3:
        time.sleep(0.4)  # right, but late: the deadline is 200 ms
    resp.success = calls[0] != 2  # the second answer is wrong
    return resp

def stubborn(req, resp):
    time.sleep(0.2)  # both calls are outstanding meanwhile
    resp.success = False
    return resp

nodes["base"].create_service(SetBool, "estop", estop)
nodes["brake"].create_service(SetBool, "brake", stubborn)
lamp = nodes["lamp"].create_service(SetBool, "lamp", stubborn)
lamp.configure_introspection(nodes["lamp"].get_clock(), qos_profile_services_default,
                             ServiceIntrospectionState.CONTENTS)

def execute(goal):
    seq = [0, 1]
    for i in range(1, goal.request.order):
        if goal.is_cancel_requested:
            goal.canceled()
            return Fibonacci.Result(sequence=seq)
        seq.append(seq[i] + seq[i - 1])
        goal.publish_feedback(Fibonacci.Feedback(sequence=seq))
        time.sleep(0.04)  # order 40 runs 1.6 s: its cancel, sent after 0.15 s, is taken first on a loaded machine
    goal.succeed()
    return Fibonacci.Result(sequence=seq if goal.request.order < 4 else seq + [-1])  # the second is spoilt

# reentrant: a cancel request is taken while the goal runs (each other node's callbacks stay one at a time)
fib = ActionServer(nodes["fib"], Fibonacci, "fib", execute, cancel_callback=lambda goal: CancelResponse.ACCEPT,
                   callback_group=ReentrantCallbackGroup())
fib.configure_introspection(nodes["fib"].get_clock(), qos_profile_services_default,
                            ServiceIntrospectionState.CONTENTS)
ex = MultiThreadedExecutor(num_threads=4)
for n in nodes.values():
    ex.add_node(n)

def done(*futs, timeout=5.0):
    until = time.monotonic() + timeout
    while time.monotonic() < until and not all(f.done() for f in futs):
        ex.spin_once(timeout_sec=0.01)
    return [f.result() if f.done() else None for f in futs]

teleop = nodes["teleop"].create_client(SetBool, "estop")
pairs = {s: [nodes[f"{s}_{k}"].create_client(SetBool, s) for k in "ab"] for s in ("brake", "lamp")}
mission = ActionClient(nodes["mission"], Fibonacci, "fib")
print("ready", flush=True)
# the monitor's readers are made once it discovers the endpoints: wait for its verdict topic, then a little
def matched():
    return nodes["watch"].count_publishers("/rclverify/verdict") >= 1 and all(
        c.service_is_ready() for c in [teleop, *pairs["brake"], *pairs["lamp"]]) and mission.server_is_ready()

until = time.monotonic() + 40
while time.monotonic() < until and not matched():
    ex.spin_once(timeout_sec=0.05)
ready = matched()  # False: the services never became ready to their clients (the wait ran out)
until = time.monotonic() + 1.5
while time.monotonic() < until:
    ex.spin_once(timeout_sec=0.05)
print("matched", round(time.monotonic() - t0, 2), ready, flush=True)
answers = [done(teleop.call_async(SetBool.Request(data=True)))[0].success for _ in range(3)]
print("estop", answers, flush=True)
for s in ("brake", "lamp"):
    a, b = pairs[s]
    got = done(a.call_async(SetBool.Request(data=True)), b.call_async(SetBool.Request(data=False)))
    print(s, [r.success for r in got], flush=True)
finals = []
for order in (3, 4):
    (handle,) = done(mission.send_goal_async(Fibonacci.Goal(order=order)))
    (result,) = done(handle.get_result_async())
    finals.append(list(result.result.sequence)[-1])
(handle,) = done(mission.send_goal_async(Fibonacci.Goal(order=40)))  # a long one, canceled as it runs
until = time.monotonic() + 0.15
while time.monotonic() < until:
    ex.spin_once(timeout_sec=0.01)
(cancel,) = done(handle.cancel_goal_async())
(result,) = done(handle.get_result_async())
finals.append(result.status)
print("fib", finals, len(cancel.goals_canceling), flush=True)
# the monitors' request readers must not hide the services from their clients (dds_shadow.py)
print("ready", [c.service_is_ready() for c in [teleop, *pairs["brake"], *pairs["lamp"]]], mission.server_is_ready(),
      flush=True)
print("done", round(time.monotonic() - t0, 2), flush=True)
while True:
    ex.spin_once(timeout_sec=0.1)
"""


def _workspace(tmp: Path) -> Path:
    ws = live_workspace(tmp, RCL, MAPPING, setbool=True)
    (ws / "interfaces/test_msgs/action").mkdir(parents=True)
    (ws / "interfaces/test_msgs/action/Fibonacci.action").write_text(FIBONACCI)
    return ws


def _watched(tmp: Path, monitors: dict[str, tuple[list[str], dict[str, str]]]) -> dict[str, int]:
    """Start each monitor (name -> its arguments and environment), wait until each monitors, run the system
    once, stop them; their exit codes by name (their output in ``tmp/<name>.out``)."""
    procs: dict[str, Any] = {}
    system = None
    try:
        for name, (args, env) in monitors.items():
            procs[name] = rclverify(args, env, tmp, tmp / f"{name}.out")
        for name in monitors:
            wait_for(tmp / f"{name}.out", "monitoring", 30)
        system = start_node(tmp, "system", SYSTEM, next(iter(monitors.values()))[1])
        wait_for(tmp / "system.log", "done", 60)
        for name in monitors:  # every call judged, the last goal too, however loaded the machine
            if (tmp / f"{name}.jsonl").exists():
                wait_logged(tmp / f"{name}.jsonl", lambda log, n=name: calls_judged(log, JUDGED[n]), 30)
        for p in procs.values():
            stop(p, signal.SIGINT)
        return {name: p.returncode for name, p in procs.items()}
    finally:
        if system is not None:
            stop(system)
        for p in procs.values():
            stop(p)


#: per monitor with a log, the calls it judges once the system is done: node -> call verdicts (the DDS source
#: hears every service; the rclpy source, the introspected ones only)
JUDGED = {"live": {"Base": 3, "Brake": 2, "Lamp": 2, "Fib": 3}, "via": {"Lamp": 2, "Fib": 3}}


def _args(ws: Path, tmp: Path, name: str, *extra: str) -> list[str]:
    # a 300 ms lateness bound: requests, replies and deadlines at their writers' source times (with none, at
    # their receipt, in the order heard, which a loaded machine's delivery may change)
    return ["monitor", "-w", str(ws), "--live", "--ros2", "--interfaces", "interfaces", "--mapping", "mapping.yaml",
            "--horizon", "1.0", "--reorder-window", "0.3", "--status", "0", "--duration", "60", "--log",
            str(tmp / f"{name}.jsonl"), "--evidence", str(tmp / f"{name}.json"), *extra]


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    """The system watched by the DDS source, and by a monitor told the wrong middleware."""
    ros2_python()  # skips, with the reason, without a ROS 2 Python
    tmp = tmp_path_factory.mktemp("calls")
    ws = _workspace(tmp)
    env = ros2_env(tmp)
    # a second monitor told the wrong middleware: it must say it cannot hear the calls, never stay silent
    wrong = ["monitor", "-w", str(ws), "--live", "--ros2", "--interfaces", "interfaces", "--node", "Base", "--strict",
             "--horizon", "1.0", "--status", "0", "--duration", "60", "--verdict-topic", "/wrong/verdict",
             "--evidence", str(tmp / "wrong.json")]
    codes = _watched(tmp, {"live": (_args(ws, tmp, "live"), env),
                           "wrong": (wrong, dict(env, RMW_IMPLEMENTATION="rmw_cyclonedds_cpp"))})
    return {"tmp": tmp, "ws": ws, "code": codes["live"], "out": (tmp / "live.out").read_text(),
            "system": (tmp / "system.log").read_text(),
            "log": [json.loads(x) for x in (tmp / "live.jsonl").read_text().splitlines()],
            "record": json.loads((tmp / "live.json").read_text()),
            "wrong": {"code": codes["wrong"], "out": (tmp / "wrong.out").read_text(),
                      "record": json.loads((tmp / "wrong.json").read_text())}}


@pytest.fixture(scope="module")
def via(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    """The same system, once more in a domain of its own, watched by the rclpy source alone: a Cyclone DDS
    reader on an introspection event topic kept Fast DDS subscribers made after it from matching that topic's
    writer in 2 of 3 runs measured (docs/ros2.md, "Not covered"), so the two sources do not share a domain."""
    tmp = tmp_path_factory.mktemp("calls-rclpy")
    ws = _workspace(tmp)
    codes = _watched(tmp, {"via": (_args(ws, tmp, "via", "--source", "rclpy", "--ros2-python", str(ros2_python()),
                                         "--record", str(tmp / "via_bag")), ros2_env(tmp))})
    return {"code": codes["via"], "out": (tmp / "via.out").read_text(), "system": (tmp / "system.log").read_text(),
            "ws": ws, "bag": tmp / "via_bag",
            "log": [json.loads(x) for x in (tmp / "via.jsonl").read_text().splitlines()],
            "record": json.loads((tmp / "via.json").read_text())}


def _verdicts(run: dict[str, Any], node: str) -> list[dict[str, Any]]:
    return sorted((x["verdict"] for x in run["log"] if x.get("topic") == "rclverify/verdict" and "kind" not in x
                   and x["verdict"].get("call") and x["verdict"]["node"] == node), key=lambda v: v["time"])


def _calls(run: dict[str, Any]) -> dict[str, dict[str, Any]]:
    return {n["node"]: n for n in run["record"]["calls"]["nodes"]}


def test_the_monitor_hides_no_service_from_its_clients(run: dict[str, Any]) -> None:
    """rmw_fastrtps counts request readers against reply writers: without its shadow reply writers the
    monitor's request readers made service_is_ready() false for good (wait_for_service() never returned)."""
    assert "matched" in run["system"] and run["system"].split("matched ")[1].split()[1] == "True", run["system"]
    assert "ready [True, True, True, True, True] True" in run["system"], run["system"]


def test_sequential_calls_are_paired_by_order_and_judged(run: dict[str, Any]) -> None:
    assert "estop [True, False, True]" in run["system"], run["system"]
    base = _verdicts(run, "Base")
    assert [v["verdict"] for v in base] == ["satisfied", "violated", "satisfied"], (base, run["out"])
    assert base[1]["values"] == {"in.req": "TRUE", "out.ok": "FALSE"}
    assert _calls(run)["Base"]["status"] == "failed"
    dl = [x["verdict"] for x in run["log"] if x.get("kind") == "deadline" and x["verdict"]["node"] == "Base"
          and not x["verdict"]["update"]]
    assert [v["verdict"] for v in dl] == ["true", "false", "false"], dl
    late = [x["verdict"] for x in run["log"] if x.get("kind") == "deadline" and x["verdict"]["update"]]
    assert len(late) == 1 and late[0]["answer"] - late[0]["trigger_stamp"] >= 0.4  # the late one, with its stamp
    assert run["record"]["deadlines"]["false"] == 2
    assert run["code"] == 1, run["out"]


def test_concurrent_calls_without_identity_are_inconclusive_not_guessed(run: dict[str, Any]) -> None:
    assert "brake [False, False]" in run["system"], run["system"]
    brake = _verdicts(run, "Brake")
    # the data: false call holds whatever its answer (decided on its request); the data: true one waits for
    # an answer that is one of two: inconclusive, with the reason (by order, the wrong answer is blamed)
    assert sorted(v["verdict"] for v in brake) == ["inconclusive", "satisfied"], brake
    (why,) = [v["reason"] for v in brake if v["verdict"] == "inconclusive"]
    assert "2 requests of /brake were unanswered" in why and "introspection" in why, why
    assert _calls(run)["Brake"]["counts"]["violated"] == 0 and _calls(run)["Brake"]["status"] != "discharged"
    unpaired = [x for x in run["log"] if x.get("kind") == "call" and x.get("unpaired")]
    assert {x["link"] for x in unpaired} == {"brake"} and len(unpaired) == 2


def test_introspection_pairs_concurrent_calls_exactly(run: dict[str, Any]) -> None:
    assert "lamp [False, False]" in run["system"], run["system"]
    lamp = _verdicts(run, "Lamp")
    # the data: false call holds (on its request, and on its answer), the data: true one is violated
    assert {v["verdict"] for v in lamp} == {"satisfied", "violated"}, lamp
    (bad,) = [v for v in lamp if v["verdict"] == "violated"]
    assert bad["values"] == {"in.req": "TRUE", "out.ok": "FALSE"}  # the data: true call got the wrong answer
    keys = [x["key"] for x in run["log"] if x.get("kind") == "call" and x.get("link") == "lamp" and "index" in x]
    assert len(keys) == 4 and all(k[0] == "ev" for k in keys)  # paired by client gid and sequence number
    assert run["record"]["calls"]["samples"]["introspected"] >= 4  # its request/reply samples left to the events


def test_goals_of_a_fibonacci_action_are_judged(run: dict[str, Any]) -> None:
    assert "fib [2, -1, 5] 1" in run["system"], run["system"]  # the third canceled (status 5), one goal canceling
    fib = [v for v in _verdicts(run, "Fib") if v["topic"] == "fib/result"]
    assert [v["verdict"] for v in fib] == ["satisfied", "violated", "satisfied"], (_verdicts(run, "Fib"), run["out"])
    assert fib[1]["values"]["out.final"] == "-1"
    counts = run["record"]["calls"]["counts"]
    assert counts["goals"] == 3 and counts["calls"] == 3 + 2 + 2 and counts["unpaired"] == 2, counts
    lines = [x for x in run["log"] if x.get("kind") == "call" and x.get("link") == "fib"]
    assert {"goal", "feedback", "result", "status", "cancel", "canceling"} <= {x["part"] for x in lines}
    goals = [x["key"][0] for x in lines if x["part"] == "goal"]
    (asked,) = [x["key"] for x in lines if x["part"] == "cancel"]
    (told,) = [x["key"] for x in lines if x["part"] == "canceling"]
    assert asked == told == [goals[2]]  # the cancel of the third goal, named by its goal id
    assert [goals[2]] == [x["key"][0] for x in lines if x["part"] == "status" and x["status"] == "canceled"]


def test_the_live_calls_replay_to_the_same_summary(run: dict[str, Any]) -> None:
    checked = load([run["ws"] / "contracts" / "sys.rcl"])
    from rclverify.backends.monitors.config import load_mapping
    rules = load_mapping(run["ws"], "mapping.yaml", 1.0).rules
    book = CallBook(checked, [(n, lk) for n in checked.nodes.values() for lk in n.node.links], rules, 1.0)
    summary = replay(book, run["log"])
    assert summary["counts"] == run["record"]["calls"]["counts"]
    assert {r["node"]: r["counts"] for r in summary["nodes"]} == \
        {n["node"]: n["counts"] for n in run["record"]["calls"]["nodes"]}
    assert summary["false"] == run["record"]["deadlines"]["false"]


def test_a_monitor_told_the_wrong_middleware_says_so(run: dict[str, Any]) -> None:
    """RMW_IMPLEMENTATION=rmw_cyclonedds_cpp beside Fast DDS nodes: the framed reader cannot take their
    plain samples; each Fast DDS writer of the service is named, nothing is judged, --strict exits 1."""
    wrong = run["wrong"]
    # named by its node, or by its participant when Fast DDS's node list has not come yet (seconds later)
    assert re.search(r"warning: /estop: (node /teleop|node /base|participant [-0-9a-f]+) is eProsima Fast DDS, "
                     r"whose service samples come without rmw_cyclonedds' request header", wrong["out"]), wrong["out"]
    assert "RMW_IMPLEMENTATION='rmw_cyclonedds_cpp'" in wrong["out"]
    assert not wrong["record"]["calls"]["nodes"] and wrong["record"]["calls"]["counts"]["calls"] == 0
    items = {i["name"]: i["reason"] for i in wrong["record"]["not_judged"] if i["kind"] == "service"}
    assert set(items) == {"/estop"} and wrong["code"] == 1, (items, wrong["out"])


def _offline(run: dict[str, Any], *extra: str) -> tuple[int, list[dict[str, Any]]]:
    """``rclverify monitor LOG`` on the live run's log (in this process)."""
    import contextlib
    import io

    from rclverify.cli.commands import main
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        code = main(["monitor", "-w", str(run["ws"]), "--mapping", "mapping.yaml", "--horizon", "1.0", "--json",
                     *extra, str(run["tmp"] / "live.jsonl")])
    return code, json.loads(out.getvalue())


def test_the_offline_command_on_the_live_log_judges_the_calls_as_the_live_run(run: dict[str, Any]) -> None:
    """Issue 62, live = offline, the converse: ``rclverify monitor LOG`` reads the live log's call lines
    through the same call book: the same call verdicts per node, the same call deadlines, the same exit
    code, the same items not judged (``--strict`` too)."""
    record = run["record"]
    code, report = _offline(run)
    calls = {e["node"]: e for e in report if "calls" in e}
    assert {n: e["calls"]["counts"] for n, e in calls.items()} == \
        {n["node"]: n["counts"] for n in record["calls"]["nodes"]}
    assert {n: e["status"] for n, e in calls.items()} == {n["node"]: n["status"] for n in record["calls"]["nodes"]}
    assert all(e["call_counts"] == record["calls"]["counts"] for e in calls.values())
    dls = {e["node"]: e["call_deadlines"] for e in report if "call_deadlines" in e}
    assert {n: (d["counts"], d["unaccepted"]) for n, d in dls.items()} == \
        {r["node"]: (r["counts"], r["unaccepted"]) for r in record["deadlines"]["results"]}
    assert sum(d["counts"]["false"] for d in dls.values()) == record["deadlines"]["false"] == 2
    # Brake's call that could not be paired stays inconclusive with the live reason
    assert calls["Brake"]["calls"]["first_inconclusive"]["reason"] == \
        next(n for n in record["calls"]["nodes"] if n["node"] == "Brake")["first_inconclusive"]["reason"]
    assert code == run["code"] == 1
    items = sorted((i["kind"], i["name"], i["reason"]) for e in report for i in e.get("not_judged", []))
    live_items = sorted((i["kind"], i["name"], i["reason"]) for i in record["not_judged"])
    assert sorted(set(items)) == live_items, (items, live_items)
    # judged by their calls: no item names them; /brake's two concurrent calls are "not paired", as live
    assert [i for i in items if i[1] in ("Base", "Brake", "Lamp", "Fib", "/estop", "/brake", "/lamp", "/fib")] == \
        [("service", "/brake", "not paired")], items
    assert _offline(run, "--strict")[0] == 1
    # Brake alone: nothing violated (its unpaired call is inconclusive), so 0; --strict: 1 for its unpaired link
    code, report = _offline(run, "--node", "Brake")
    assert [e["status"] for e in report if "calls" in e] == ["inconclusive"] and code == 0, report
    assert _offline(run, "--node", "Brake", "--strict")[0] == 1


def test_the_rclpy_source_pairs_introspected_calls_as_the_dds_source(run: dict[str, Any],
                                                                    via: dict[str, Any]) -> None:
    """The rclpy source hears ``/lamp`` through its server's introspection events only: the same two
    verdicts as the DDS source, paired by client gid and sequence number, and it says it was rclpy."""
    assert via["record"]["source"] == "rclpy" and via["record"]["rmw"] == "rmw_fastrtps_cpp", via["out"]
    assert (via["log"][0]["kind"], via["log"][0]["source"], run["log"][0]["source"]) == ("run", "rclpy", "dds")
    assert sorted(v["verdict"] for v in _verdicts(via, "Lamp")) == sorted(v["verdict"] for v in _verdicts(run, "Lamp"))
    (bad,) = [v for v in _verdicts(via, "Lamp") if v["verdict"] == "violated"]
    assert bad["values"] == {"in.req": "TRUE", "out.ok": "FALSE"}
    keys = [x["key"] for x in via["log"] if x.get("kind") == "call" and x.get("link") == "lamp" and "index" in x]
    assert len(keys) == 4 and all(k[0] == "ev" for k in keys), keys


def test_the_rclpy_source_judges_goals_through_the_actions_introspection(via: dict[str, Any]) -> None:
    """``fib``'s goals, results and cancel come from the introspection events of the action's own services
    (its feedback and status from their topics): the verdicts of the DDS source, the cancel named by its goal."""
    fib = [v for v in _verdicts(via, "Fib") if v["topic"] == "fib/result"]
    assert [v["verdict"] for v in fib] == ["satisfied", "violated", "satisfied"], (_verdicts(via, "Fib"), via["out"])
    assert fib[1]["values"]["out.final"] == "-1"
    assert via["record"]["calls"]["counts"]["goals"] == 3, via["record"]["calls"]["counts"]
    lines = [x for x in via["log"] if x.get("kind") == "call" and x.get("link") == "fib"]
    goals = [x["key"][0] for x in lines if x["part"] == "goal"]
    (asked,) = [x["key"] for x in lines if x["part"] == "cancel"]
    (told,) = [x["key"] for x in lines if x["part"] == "canceling"]
    assert asked == told == [goals[2]]


def test_the_rclpy_source_says_which_calls_it_cannot_hear(run: dict[str, Any], via: dict[str, Any]) -> None:
    """``/estop`` and ``/brake`` publish no introspection events: the rclpy source hears none of their calls,
    says so for each, and never calls their nodes green; the run's exit code is the DDS source's."""
    assert "the rclpy source hears the calls of /brake, /estop, /fib, /lamp through their introspection events " \
           "only" in via["out"]
    for name in ("estop", "brake"):
        assert f"warning: /{name}: the rclpy source hears calls through introspection events only, and no " \
               "introspection event of its server or of every client was heard" in via["out"], via["out"]
    assert [u.split(":")[0] for u in via["record"]["unseen"]] == ["/brake", "/estop"], via["record"]["unseen"]
    (said,) = [x for x in via["log"] if x.get("kind") == "unseen"]  # the log carries it to the evidence
    assert said["unseen"] == via["record"]["unseen"]
    calls = {n["node"]: n for n in via["record"]["calls"]["nodes"]}
    assert all(calls.get(n, {}).get("status") != "discharged" for n in ("Base", "Brake")), calls
    items = {i["name"]: i["detail"] for i in via["record"]["not_judged"] if i["kind"] == "service"}
    assert set(items) == {"/estop", "/brake"} and all("the rclpy source: no introspection event" in d
                                                      for d in items.values()), items
    assert via["code"] == run["code"] == 1, via["out"]


def test_the_rclpy_sources_bag_judges_the_calls_as_its_live_run(via: dict[str, Any]) -> None:
    """``--record`` through the rclpy source: ``rclverify monitor BAG`` gives the live run's call verdicts per
    node, its items not judged (the unheard links among them) and its exit code."""
    import contextlib
    import io

    from rclverify.cli.commands import main
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(["monitor", "-w", str(via["ws"]), "--mapping", "mapping.yaml", "--horizon", "1.0", "--json",
                     str(via["bag"])])
    report = json.loads(out.getvalue())
    record = via["record"]
    assert not record["bag"].get("calls_failed"), record["bag"]
    calls = {e["node"]: e for e in report if "calls" in e}
    assert {n: e["calls"]["counts"] for n, e in calls.items()} == \
        {n["node"]: n["counts"] for n in record["calls"]["nodes"]}, err.getvalue()
    assert {n: e["status"] for n, e in calls.items()} == {n["node"]: n["status"] for n in record["calls"]["nodes"]}
    items = {(i["kind"], i["name"]) for e in report for i in e.get("not_judged", [])}
    assert {("service", "/estop"), ("service", "/brake")} <= items, items
    assert code == via["code"] == 1, err.getvalue()
