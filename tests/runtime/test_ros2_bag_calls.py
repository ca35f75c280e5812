"""Service calls and action goals in ``--record`` bags, and bags judged like the live run, with real rclpy
nodes on Fast DDS (tests/_ros2.py; docs/ros2.md, "Every message type from Fast DDS; --record").

One ROS 2 system (one rclpy process) runs once for the module; two monitors watch it, one recording to
SQLite 3, one to MCAP:

* ``base`` serves ``/estop`` (std_srvs/SetBool): the first call answered right, the second wrong, the third
  right but 400 ms late (the deadline is 200 ms); ``teleop`` calls it three times, one at a time: each call is
  paired by order (no identity on the wire) and judged;
* ``brake`` serves ``/brake`` slowly and two clients call it at once: which answer is whose cannot be known,
  the ``data: true`` call is inconclusive with the reason (never guessed);
* ``lamp`` is ``brake`` with service introspection (``CONTENTS``): the same concurrent calls paired exactly;
* ``fib`` serves test_msgs/action/Fibonacci, ``mission`` sends goals one after the other (order 3; order 4,
  whose result is spoilt with a negative last number; order 40, canceled as it runs);
* ``talker`` publishes ``/speed`` (std_msgs/Float64).

Each bag holds the calls as ROS 2 records them (``<service>/_service_event`` of ``<Srv>_Event``, an action's
send-goal, get-result and cancel-goal events, its feedback and status), read by rosbags' AnyReader and, its
events' bytes, by rclpy's own deserializer; ``rclverify monitor BAG`` gives the live run's call verdicts,
deadlines, not-judged items and exit code, with and without ``--strict``.  A bag without the call topics (the
same run with them dropped: what ``--record`` wrote before, or ``ros2 bag record`` without introspection) is
never green; a bag with a truncated event, or an event type that is not the contract's service type, is one
error naming the bag and the topic, exit 2.
"""
from __future__ import annotations

import contextlib
import io
import json
import signal
import subprocess
from pathlib import Path
from typing import Any, Iterator

import pytest
from _procs import calls_judged, stop, wait_for, wait_logged
from _ros2 import SETBOOL, rclverify, ros2_env, ros2_python, start_node
from test_ros2_services_actions import FIBONACCI, MAPPING
from test_ros2_services_actions import RCL as CALLS_RCL

# the services_actions module's system contracts (Base, Brake, Lamp, Fib) and a topic beside them
RCL = CALLS_RCL + """
node Speed {
  inputs( )
  outputs( v : REAL )
  topics( std_msgs/Float64 speed matches(out.v) )
  assume( TRUE )
  guarantee( out.v >= 0 )
}
"""
TRIGGER = "---\nbool success\nstring message\n"
STORAGES = {"sqlite3": "run_sqlite", "mcap": "run_mcap.mcap"}

SYSTEM = """\
import time
import rclpy
from rclpy.action import ActionClient, ActionServer, CancelResponse
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node
from rclpy.qos import qos_profile_services_default
from rclpy.service_introspection import ServiceIntrospectionState
from std_msgs.msg import Float64
from std_srvs.srv import SetBool
from test_msgs.action import Fibonacci

rclpy.init()
nodes = {n: Node(n) for n in ("base", "teleop", "brake", "brake_a", "brake_b", "lamp", "lamp_a", "lamp_b",
                              "fib", "mission", "talker")}
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

ActionServer(nodes["fib"], Fibonacci, "fib", execute, cancel_callback=lambda goal: CancelResponse.ACCEPT,
             callback_group=ReentrantCallbackGroup())
speed = nodes["talker"].create_publisher(Float64, "speed", 10)
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
until = time.monotonic() + 20
while time.monotonic() < until and (any(nodes["talker"].count_publishers(f"/{m}/verdict") < 1 for m in ("sqlite3", "mcap"))
                                   or speed.get_subscription_count() < 2
                                   or not all(c.service_is_ready() for c in [teleop, *pairs["brake"], *pairs["lamp"]])
                                   or not mission.server_is_ready()):
    ex.spin_once(timeout_sec=0.05)
until = time.monotonic() + 1.5
while time.monotonic() < until:
    ex.spin_once(timeout_sec=0.05)
print("matched", flush=True)
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
until = time.monotonic() + 1.1  # the horizon (1 s) of every call passes before the bag's last message
while time.monotonic() < until:
    ex.spin_once(timeout_sec=0.05)
for k in range(5):
    speed.publish(Float64(data=float(k)))
print("done", flush=True)
while True:
    ex.spin_once(timeout_sec=0.1)
"""

#: the ROS 2 Python reads each dumped event with rclpy's own deserializer (rosidl's generated type support)
RCLPY_READ = """\
import json, sys
from rclpy.serialization import deserialize_message
from std_srvs.srv import SetBool
from test_msgs.action import Fibonacci
types = {"SetBool": SetBool.Event, "SendGoal": Fibonacci.Impl.SendGoalService.Event,
         "GetResult": Fibonacci.Impl.GetResultService.Event, "Feedback": Fibonacci.Impl.FeedbackMessage}
out = []
for kind, hexed in json.load(open(sys.argv[1])):
    m = deserialize_message(bytes.fromhex(hexed), types[kind])
    if kind == "Feedback":
        out.append([kind, bytes(m.goal_id.uuid).hex(), list(m.feedback.sequence)])
    else:
        req = [str(r) for r in m.request]
        resp = [str(r) for r in m.response]
        out.append([kind, m.info.event_type, bytes(m.info.client_gid).hex(), m.info.sequence_number, req, resp])
print(json.dumps(out))
"""


def _workspace(ws: Path) -> None:
    (ws / "contracts").mkdir(parents=True)
    (ws / "contracts/sys.rcl").write_text(RCL)
    (ws / "contracts/plan.yaml").write_text("contracts: [contracts/sys.rcl]\n")
    (ws / "mapping.yaml").write_text(MAPPING)
    (ws / "interfaces/std_srvs/srv").mkdir(parents=True)
    (ws / "interfaces/std_srvs/srv/SetBool.srv").write_text(SETBOOL)
    (ws / "interfaces/std_srvs/srv/Trigger.srv").write_text(TRIGGER)
    (ws / "interfaces/test_msgs/action").mkdir(parents=True)
    (ws / "interfaces/test_msgs/action/Fibonacci.action").write_text(FIBONACCI)


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, Any]]:
    ros2_python()  # skips, with the reason, without a ROS 2 Python
    tmp = tmp_path_factory.mktemp("bagcalls")
    ws = tmp / "ws"
    _workspace(ws)
    env = ros2_env(tmp)
    procs: dict[str, subprocess.Popen[bytes]] = {}
    system = None
    try:
        # a 300 ms lateness bound: requests, replies and deadlines at their writers' source times, as the bag
        # holds them (with none, at their receipt, in the order heard, which a loaded machine may change)
        for storage, bag in STORAGES.items():
            procs[storage] = rclverify(
                ["monitor", "-w", str(ws), "--live", "--ros2", "--interfaces", "interfaces", "--mapping",
                 "mapping.yaml", "--horizon", "1.0", "--reorder-window", "0.3", "--status", "0", "--duration", "60",
                 "--verdict-topic", f"/{storage}/verdict", "--record", str(tmp / bag), "--log",
                 str(tmp / f"{storage}.jsonl"), "--evidence", str(tmp / f"{storage}.json")],
                env, tmp, tmp / f"{storage}.out")
        for storage in procs:
            wait_for(tmp / f"{storage}.out", "monitoring", 30)
        system = start_node(tmp, "system", SYSTEM, env)
        wait_for(tmp / "system.log", "done", 60)
        for storage in procs:  # every call judged and the five speeds heard, however loaded the machine
            wait_logged(tmp / f"{storage}.jsonl", _all_heard, 30)
        for p in procs.values():
            stop(p, signal.SIGINT)
        yield {"tmp": tmp, "ws": ws, "system": (tmp / "system.log").read_text(),
               "code": {s: p.returncode for s, p in procs.items()},
               "out": {s: (tmp / f"{s}.out").read_text() for s in procs},
               "record": {s: json.loads((tmp / f"{s}.json").read_text()) for s in procs},
               "bag": {s: tmp / b.removesuffix(".mcap") for s, b in STORAGES.items()}}
    finally:
        if system is not None:
            stop(system)
        for p in procs.values():
            stop(p)


def _all_heard(log: list[dict[str, Any]]) -> bool:
    """The run's end in a monitor's ``log``: the calls of each service and goal judged, the five speeds heard."""
    return calls_judged(log, {"Base": 3, "Brake": 2, "Lamp": 2, "Fib": 3}) \
        and sum(x.get("topic") == "speed" for x in log) >= 5


def _monitor(ws: Path, *args: str) -> tuple[int, Any, str]:
    """``rclverify monitor`` in this process: exit code, the JSON report, stderr."""
    from rclverify.cli.commands import main
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(["monitor", "-w", str(ws), "--mapping", "mapping.yaml", "--horizon", "1.0", "--json", *args])
    return code, json.loads(out.getvalue()) if out.getvalue().strip() else None, err.getvalue()


def _messages(bag: Path, ws: Path) -> dict[str, list[tuple[str, int, bytes, Any]]]:
    """Per topic of the bag: (type, bag time, raw bytes, decoded message), read by rosbags' AnyReader."""
    from rosbags.highlevel import AnyReader

    from rclverify.traces.bag import typestore
    out: dict[str, list[tuple[str, int, bytes, Any]]] = {}
    with AnyReader([bag], default_typestore=typestore([ws / "interfaces"])) as reader:
        for conn, t, raw in reader.messages():
            out.setdefault(conn.topic, []).append((conn.msgtype, t, raw, reader.deserialize(raw, conn.msgtype)))
    return out


def test_the_system_ran_and_the_live_runs_judged_it(run: dict[str, Any]) -> None:
    assert "estop [True, False, True]" in run["system"] and "fib [2, -1, 5] 1" in run["system"], run["system"]
    for storage in STORAGES:
        rec = run["record"][storage]
        calls = {n["node"]: n for n in rec["calls"]["nodes"]}
        assert calls["Base"]["counts"]["violated"] == 1 and calls["Fib"]["counts"]["violated"] == 1, calls
        assert rec["deadlines"]["false"] == 2 and run["code"][storage] == 1, run["out"][storage]
        assert rec["bag"]["call_messages"] > 0 and "calls_failed" not in rec["bag"], rec["bag"]


@pytest.mark.parametrize("storage", list(STORAGES))
def test_the_calls_are_in_the_bag_as_ros2_records_them(run: dict[str, Any], storage: str) -> None:
    msgs = _messages(run["bag"][storage], run["ws"])
    types = {t: m[0][0] for t, m in msgs.items()}
    assert types["/estop/_service_event"] == "std_srvs/srv/SetBool_Event"
    assert types["/lamp/_service_event"] == "std_srvs/srv/SetBool_Event"
    assert types["/fib/_action/send_goal/_service_event"] == "test_msgs/action/Fibonacci_SendGoal_Event"
    assert types["/fib/_action/get_result/_service_event"] == "test_msgs/action/Fibonacci_GetResult_Event"
    assert types["/fib/_action/cancel_goal/_service_event"] == "action_msgs/srv/CancelGoal_Event"
    assert types["/fib/_action/feedback"] == "test_msgs/action/Fibonacci_FeedbackMessage"
    assert types["/fib/_action/status"] == "action_msgs/msg/GoalStatusArray"
    # /estop: paired by order, each call its request writer's GUID (one client) and its count from 1
    estop = [m[3] for m in msgs["/estop/_service_event"]]
    assert [(e.info.event_type, e.info.sequence_number) for e in estop] == \
        [(0, 1), (2, 1), (0, 2), (2, 2), (0, 3), (2, 3)], estop
    assert len({bytes(e.info.client_gid) for e in estop}) == 1 and bytes(estop[0].info.client_gid)[:2] == b"\x01\x0f"
    assert [bool(e.response[0].success) for e in estop if e.response] == [True, False, True]
    # /lamp: the server's own introspection events, written as heard (REQUEST_RECEIVED, RESPONSE_SENT)
    lamp = [m[3] for m in msgs["/lamp/_service_event"]]
    assert sorted(e.info.event_type for e in lamp) == [1, 1, 2, 2], lamp
    # /brake: requests written; its replies could not be paired: no response event, the decision instead
    brake = [m[3] for m in msgs["/brake/_service_event"]]
    assert sorted(e.info.event_type for e in brake) == [0, 0], brake
    decisions = [json.loads(m[3].data) for m in msgs["/rclverify/call_decisions"]]
    unpaired = [d for d in decisions if d.get("unpaired")]
    assert {d["link"] for d in unpaired} == {"brake"} and all("2 requests of /brake" in d["reason"]
                                                               for d in unpaired), unpaired
    results = [m[3] for m in msgs["/fib/_action/get_result/_service_event"] if m[3].response]
    assert [int(r.response[0].result.sequence[-1]) for r in results][:2] == [2, -1], results
    assert len(msgs["/speed"]) == 5


def test_rclpy_reads_the_recorded_events(run: dict[str, Any], tmp_path: Path) -> None:
    """The events' bytes are what rosidl's own type support reads (the Kilted wheels' rclpy)."""
    msgs = _messages(run["bag"]["mcap"], run["ws"])
    kinds = {"/estop/_service_event": "SetBool", "/fib/_action/send_goal/_service_event": "SendGoal",
             "/fib/_action/get_result/_service_event": "GetResult", "/fib/_action/feedback": "Feedback"}
    dumped = [(kinds[t], raw.hex()) for t in kinds for _ty, _t, raw, _m in msgs[t]]
    (tmp_path / "events.json").write_text(json.dumps(dumped))
    (tmp_path / "read.py").write_text(RCLPY_READ)
    got = subprocess.run([str(ros2_python()), str(tmp_path / "read.py"), str(tmp_path / "events.json")],
                         capture_output=True, text=True, timeout=60)
    assert got.returncode == 0, got.stderr[-2000:]
    read = json.loads(got.stdout)
    estop = [r for r in read if r[0] == "SetBool"]
    assert [(r[1], r[3]) for r in estop] == [(0, 1), (2, 1), (0, 2), (2, 2), (0, 3), (2, 3)], estop
    assert "data=True" in estop[0][4][0] and "success=False" in estop[3][5][0], estop
    goals = [r for r in read if r[0] == "SendGoal" and r[1] == 0]
    assert len(goals) == 3 and "order=4" in goals[1][4][0], goals
    assert any(r[0] == "GetResult" and "-1" in "".join(r[5]) for r in read), read
    assert any(r[0] == "Feedback" and r[2][-1] == 2 for r in read)


def test_the_definitions_hash_as_rosidl_wrote_them_in_the_wheels(run: dict[str, Any]) -> None:
    """Each call topic's definition in the bag has the ROS 2 type hash rosidl wrote into the Kilted wheels."""
    from rclverify.lang.typecheck import load
    from rclverify.runtime.dds.bag_calls import CallRecorder
    from rclverify.runtime.dds.types import TypeBook
    checked = load([run["ws"] / "contracts" / "sys.rcl"])
    plan = CallRecorder(TypeBook([run["ws"] / "interfaces"]),
                        [(n, lk) for n in checked.nodes.values() for lk in n.node.links]).plan
    share = ros2_python().parent.parent / "share"
    wheels: dict[str, str] = {}
    for f in ("std_srvs/srv/SetBool", "test_msgs/action/Fibonacci", "action_msgs/srv/CancelGoal",
              "action_msgs/msg/GoalStatusArray"):
        if not (share / f"{f}.json").is_file():
            pytest.skip(f"no {f}.json in the ROS 2 Python's share (an apt installation keeps it elsewhere)")
        wheels.update({h["type_name"]: h["hash_string"]
                       for h in json.loads((share / f"{f}.json").read_text())["type_hashes"]})
    got = {ty: digest for ty, _msgdef, digest in plan.values() if digest is not None}
    assert len(got) == 6 and got == {ty: wheels[ty] for ty in got}, got  # SetBool_Event for 3 services


def _calls(report: list[dict[str, Any]]) -> dict[str, dict[str, Any]]:
    return {e["node"]: e for e in report if "calls" in e}


@pytest.mark.parametrize("storage", list(STORAGES))
def test_the_bag_checked_offline_judges_the_calls_as_the_live_run(run: dict[str, Any], storage: str) -> None:
    record = run["record"][storage]
    code, report, err = _monitor(run["ws"], str(run["bag"][storage]))
    calls = _calls(report)
    assert {n: e["calls"]["counts"] for n, e in calls.items()} == \
        {n["node"]: n["counts"] for n in record["calls"]["nodes"]}, err
    assert {n: e["status"] for n, e in calls.items()} == {n["node"]: n["status"] for n in record["calls"]["nodes"]}
    assert all(e["call_counts"] == record["calls"]["counts"] for e in calls.values())
    dls = {e["node"]: e["call_deadlines"] for e in report if "call_deadlines" in e}
    assert {n: (d["counts"], d["unaccepted"]) for n, d in dls.items()} == \
        {r["node"]: (r["counts"], r["unaccepted"]) for r in record["deadlines"]["results"]}
    assert sum(d["counts"]["false"] for d in dls.values()) == record["deadlines"]["false"] == 2
    live_brake = next(n for n in record["calls"]["nodes"] if n["node"] == "Brake")
    assert calls["Brake"]["status"] == "inconclusive"  # a call the monitor could not pair: never a pass
    assert calls["Brake"]["calls"]["first_inconclusive"]["reason"] == live_brake["first_inconclusive"]["reason"]
    assert calls["Base"]["calls"]["first_violation"]["values"] == {"in.req": "TRUE", "out.ok": "FALSE"}
    items = sorted({(i["kind"], i["name"], i["reason"]) for e in report for i in e.get("not_judged", [])})
    assert items == sorted((i["kind"], i["name"], i["reason"]) for i in record["not_judged"]), items
    speed = next(e for e in report if e["node"] == "Speed" and "counts" in e)
    assert speed["counts"]["satisfied"] == 5
    assert code == run["code"][storage] == 1, err
    assert _monitor(run["ws"], "--strict", str(run["bag"][storage]))[0] == 1


def test_strict_and_a_node_alone_as_on_the_live_log(run: dict[str, Any]) -> None:
    """Brake alone: its unpaired call is inconclusive, nothing violated: 0; ``--strict``: 1 (the live run's
    own log, replayed, says the same)."""
    storage = "sqlite3"
    bag, log = str(run["bag"][storage]), str(run["tmp"] / f"{storage}.jsonl")
    for trace in (bag, log):
        code, report, err = _monitor(run["ws"], "--node", "Brake", trace)
        assert [e["status"] for e in report if "calls" in e] == ["inconclusive"] and code == 0, (trace, err)
        assert _monitor(run["ws"], "--node", "Brake", "--strict", trace)[0] == 1
    code, report, _ = _monitor(run["ws"], "--node", "Lamp", "--node", "Speed", bag)
    assert code == 1 and _calls(report)["Lamp"]["calls"]["counts"]["violated"] == 1  # introspected: exact


def _rewrite(src: Path, dst: Path, ws: Path, keep: Any, change: Any = None) -> None:
    """Write bag ``dst`` (MCAP) with the messages of ``src`` whose topic ``keep(topic)`` keeps, each one's
    bytes through ``change(topic, index, raw)`` when given."""
    from rosbags.highlevel import AnyReader
    from rosbags.rosbag2 import StoragePlugin, Writer

    from rclverify.traces.bag import typestore
    with AnyReader([src], default_typestore=typestore([ws / "interfaces"])) as reader, \
            Writer(dst, version=8, storage_plugin=StoragePlugin.MCAP) as writer:
        conns = {}
        for c in reader.connections:
            if keep(c.topic):
                conns[c.id] = writer.add_connection(c.topic, c.msgtype, msgdef=c.msgdef.data, rihs01=c.digest)
        seen: dict[str, int] = {}
        for c, t, raw in reader.messages():
            if c.id in conns:
                n = seen[c.topic] = seen.get(c.topic, -1) + 1
                writer.write(conns[c.id], t, change(c.topic, n, raw) if change else raw)


def test_a_bag_without_the_call_topics_is_never_green(run: dict[str, Any]) -> None:
    old = run["tmp"] / "old"
    _rewrite(run["bag"]["mcap"], old, run["ws"], lambda t: t == "/speed")
    code, report, err = _monitor(run["ws"], str(old))
    assert code == 0 and "Traceback" not in err, err  # nothing violated in what it holds: pending, not green
    assert not _calls(report)
    base = next(e for e in report if e["node"] == "Base")
    assert base["status"] == "pending", base
    items = {i["name"]: i for e in report for i in e.get("not_judged", [])}
    for name, topic in (("/estop", "/estop/_service_event"), ("/fib", "/fib/_action/send_goal/_service_event")):
        assert items[name]["reason"] == "nothing heard" and topic in items[name]["detail"], items[name]
    code, _report, err = _monitor(run["ws"], "--strict", str(old))
    assert code == 1 and "--strict" in err and "_service_event" in err, err


def test_a_bag_with_the_events_alone_is_judged_on_their_stamps(run: dict[str, Any]) -> None:
    """Without the monitor's decisions (a bag ``ros2 bag record`` made of the events): calls paired by
    ``client_gid`` + ``sequence_number``, the book's clock the events' stamps: the same verdicts here,
    where every call was paired; /brake, whose replies could not be paired, is left out."""
    events = run["tmp"] / "events_only"
    _rewrite(run["bag"]["mcap"], events, run["ws"], lambda t: t not in ("/rclverify/call_decisions",
                                                                        "/brake/_service_event"))
    record = run["record"]["mcap"]
    code, report, err = _monitor(run["ws"], "--node", "Base", "--node", "Lamp", "--node", "Fib", str(events))
    live = {n["node"]: n["counts"] for n in record["calls"]["nodes"] if n["node"] != "Brake"}
    assert {n: e["calls"]["counts"] for n, e in _calls(report).items()} == live, err
    dls = {e["node"]: e["call_deadlines"]["counts"] for e in report if "call_deadlines" in e}
    assert dls == {r["node"]: r["counts"] for r in record["deadlines"]["results"]}
    assert code == 1


def test_a_truncated_event_is_one_error_naming_the_bag_and_topic(run: dict[str, Any]) -> None:
    bad = run["tmp"] / "truncated"
    _rewrite(run["bag"]["mcap"], bad, run["ws"], lambda t: True,
             lambda topic, n, raw: raw[:9] if topic == "/estop/_service_event" and n == 1 else raw)
    code, _report, err = _monitor(run["ws"], str(bad))
    assert code == 2 and "Traceback" not in err, err
    assert str(bad) in err and "/estop/_service_event" in err and "error" in err, err


def test_an_event_type_not_the_contracts_service_type_is_refused(run: dict[str, Any]) -> None:
    ws = run["tmp"] / "ws_trigger"
    _workspace(ws)
    rcl = (ws / "contracts/sys.rcl").read_text().replace("std_srvs/SetBool estop", "std_srvs/Trigger estop")
    (ws / "contracts/sys.rcl").write_text(rcl)
    bag = run["bag"]["sqlite3"]
    code, _report, err = _monitor(ws, "--node", "Base", str(bag))
    assert code == 2 and "Traceback" not in err, err
    assert f"{bag}: topic /estop/_service_event: error: its type is std_srvs/srv/SetBool_Event" in err, err
    assert "std_srvs/srv/Trigger_Event" in err
