"""ROS 1's service proxy in simulated time, live (docs/semantics.md, "Deadlines in simulated time";
``runtime/live_ros1.py``, "The run's clock" and "One judge of the calls").

A ROS 1 master on 127.0.0.1 (a free port), its ``/use_sim_time`` true, and rospy processes: ``sim``
publishes ``/clock`` every 10 ms of the wall clock, 5 ms further each time (a real-time factor of 0.5);
``base`` serves ``/estop_real`` and ``/halt_real`` (``std_srvs/SetBool``) and answers each call once its
ROS clock (``/clock``, read at its start) has moved 300 ms (``rospy.sleep``: 600 ms of the wall clock);
``teleop`` calls ``/estop`` and ``/halt`` through ``rclverify monitor --live --forward`` (the service
proxy), one call at a time; ``echo`` prints each message of the verdict topic.  The contracts: each answer
within 400 ms of its request, ``Base`` for ``estop``, ``Halt`` for ``halt``.  The same process relays each
``x`` (``geometry_msgs/PointStamped``, ``teleop`` publishes one each round) to ``y`` after 300 ms of its
clock, ``Relay``'s contract asking for ``y`` within 400 ms of ``x``: a topic's deadline.  The live run's
own deadline checks, on the wall clock with ``/clock``'s samples in the log, are the one judge of every
deadline; the proxy stamps and forwards.  Two runs of the monitor on one master and one server, four
clock cases for the calls:

* ``sim``: ``/use_sim_time`` true, the mapping's ``use_sim_time: [Base, Relay]``.  ``Base``, on ``/clock``:
  every deadline ``true`` (300 of 400 simulated ms); ``Halt``, said to keep the wall clock: ``false``
  (600 ms of it), with one warning line naming ``Halt``, its clock and ``/use_sim_time``; ``Relay``
  ``true``.
* ``wall``: ``/use_sim_time`` false when the monitor starts (the server still on ``/clock``), the
  mapping's ``use_sim_time: [Halt]``.  ``Base``, a wall-clock node: the same 600 ms answers ``false``;
  ``Halt``, said to keep ``/clock``: ``true``, with the warning line; ``Relay`` ``false``.

Each call has one deadline verdict, the same in the log, the evidence record, on the verdict topic and in
the log's offline replay (``rclverify monitor`` on it, the same mapping); none is the proxy's.  Every
process is stopped in a ``finally``; skipped, with the reason, only where ROS 1 cannot be imported.
"""
from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import xmlrpc.client
from collections import Counter
from pathlib import Path
from typing import Any, Iterator

import pytest
from _procs import stop, wait_for, wait_logged

from rclverify.runtime.ros1 import LocalMaster, RosUnavailable, import_rospy
from rclverify.runtime.service_proxy import PROXY_LOG_TOPIC

REPO = Path(__file__).resolve().parents[2]

try:
    import_rospy()
    REASON = ""
except RosUnavailable as exc:
    REASON = str(exc)
pytestmark = pytest.mark.skipif(bool(REASON), reason=f"ROS 1 unavailable: {REASON}")

RCL = """\
node Base {
  inputs( req : BOOL )
  outputs( ok : BOOL )
  services( std_srvs/SetBool estop serves(in.req, out.ok) )
  assume( TRUE )
  guarantee( in.req -> out.ok ) triggered by in.req within 400 ms
}

node Halt {
  inputs( req : BOOL )
  outputs( ok : BOOL )
  services( std_srvs/SetBool halt serves(in.req, out.ok) )
  assume( TRUE )
  guarantee( in.req -> out.ok ) triggered by in.req within 400 ms
}

node Relay {
  inputs( x : REAL )
  outputs( y : REAL )
  topics( geometry_msgs/PointStamped x matches(in.x), geometry_msgs/PointStamped y matches(out.y) )
  assume( TRUE )
  guarantee( out.y == in.x ) triggered by in.x within 400 ms
}
"""
#: the mapping of the relay's topics, beside each run's use_sim_time
TOPICS = "topics:\n  x: {fields: [point.x]}\n  y: {fields: [point.x]}\n"
SETBOOL = "bool data\n---\nbool success\nstring message\n"
#: calls per service and run
ROUNDS = 3
#: the server's delay on its ROS clock (s): 300 ms of /clock, 600 ms of the wall clock at a factor of 0.5
DELAY = 0.3

NODES = """\
import sys, time
from pathlib import Path
from rclverify.runtime.ros1 import import_rospy
from rclverify.runtime.ros1_interfaces import service_class

rospy = import_rospy()
from geometry_msgs.msg import PointStamped
role = sys.argv[1]
srv = service_class("std_srvs/SetBool", [Path("interfaces")])
if role == "sim":  # /clock at a real-time factor of 0.5, from a simulated 1000 s
    from rosgraph_msgs.msg import Clock
    rospy.init_node("sim")
    pub = rospy.Publisher("/clock", Clock, queue_size=10)
    print("ready", flush=True)
    ns, nxt = 1000 * 10**9, time.monotonic()
    while not rospy.is_shutdown():  # SIGTERM: rospy's shutdown
        pub.publish(Clock(clock=rospy.Time(ns // 10**9, ns % 10**9)))
        ns += 5 * 10**6
        nxt += 0.01
        time.sleep(max(0.0, nxt - time.monotonic()))
elif role == "base":  # answers once its ROS clock moved DELAY (under /use_sim_time: /clock)
    rospy.init_node("base")
    end = time.monotonic() + 30
    while rospy.Time.now().is_zero() and time.monotonic() < end:  # its clock on /clock before the first call
        time.sleep(0.01)

    def handle(req):
        rospy.sleep(DELAY)
        resp = srv._response_class()
        resp.success = bool(req.data)
        return resp
    keep = [rospy.Service("/estop_real", srv, handle), rospy.Service("/halt_real", srv, handle)]
    pub = rospy.Publisher("/y", PointStamped, queue_size=10)

    def relay(msg):  # y, stamped on its ROS clock, DELAY after each x
        rospy.sleep(DELAY)
        out = PointStamped()
        out.header.stamp = rospy.Time.now()
        out.point.x = msg.point.x
        pub.publish(out)
    keep.append(rospy.Subscriber("/x", PointStamped, relay))
    print("ready", flush=True)
    rospy.spin()
elif role == "echo":  # each message of the verdict topic, its JSON text a line
    from std_msgs.msg import String
    rospy.init_node("echo", anonymous=True)
    sub = rospy.Subscriber("/rclverify/verdict", String, lambda msg: print(msg.data, flush=True))
    end = time.monotonic() + 30
    while sub.get_num_connections() < 1 and time.monotonic() < end:  # connected to the monitor's publisher
        time.sleep(0.05)
    print("ready", flush=True)
    rospy.spin()
else:  # teleop: ROUNDS rounds of an x and one call of each service, one at a time
    rospy.init_node("teleop", anonymous=True)
    calls = {s: rospy.ServiceProxy(s, srv, persistent=True) for s in ("/estop", "/halt")}
    for s in calls:
        rospy.wait_for_service(s, timeout=30)
    pub = rospy.Publisher("/x", PointStamped, queue_size=10)
    end = time.monotonic() + 30
    while pub.get_num_connections() < 2 and time.monotonic() < end:  # the relay and the monitor
        time.sleep(0.05)
    for k in range(ROUNDS):
        x = PointStamped()
        x.header.stamp = rospy.Time.now()
        x.point.x = float(k)
        pub.publish(x)
        for s, call in calls.items():
            print("call", s, call(True).success, flush=True)
    print("done", flush=True)
""".replace("DELAY", repr(DELAY)).replace("ROUNDS", str(ROUNDS))


def _start(args: list[str], env: dict[str, str], cwd: Path, out: Path) -> subprocess.Popen[bytes]:
    return subprocess.Popen([sys.executable, *args], env=env, cwd=cwd, stdout=out.open("wb"),
                            stderr=subprocess.STDOUT, start_new_session=True)


def _proxys(lines: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The service proxy's lines of the log other than its events (a deadline verdict or summary of its own)."""
    return [x for x in lines if x.get("topic") == PROXY_LOG_TOPIC and x["kind"] != "event"]


def _checks(lines: list[dict[str, Any]], node: str) -> list[dict[str, Any]]:
    """The live run's own deadline verdicts of ``node`` (its ``kind: deadline`` lines)."""
    return [x["verdict"] for x in lines if x.get("kind") == "deadline" and x["verdict"]["node"] == node]


def _finals(verdicts: list[dict[str, Any]]) -> Counter[str]:
    """Each call's final deadline verdict (an update replaces what it updates), counted."""
    last: dict[str, str] = {}
    for v in verdicts:
        last[v["trigger_where"]] = v["verdict"]
    return Counter(last.values())


def _published(text: str, node: str) -> list[dict[str, Any]]:
    """The deadline verdicts of ``node`` the verdict topic's subscriber received (``echo``'s lines), as the
    log's ``kind: deadline`` lines hold them."""
    out = []
    for line in text.splitlines():
        data = json.loads(line) if line.startswith("{") else {}
        if data.get("kind") == "deadline" and data["node"] == node:
            out.append({k: v for k, v in data.items() if k != "kind"})
    return out


def _counts(res: dict[str, Any]) -> Counter[str]:
    """A deadline result's verdicts, counted as :func:`_finals` counts them (none that is zero)."""
    return +Counter({"true": res["counts"]["true"], "false": res["counts"]["false"],
                     "undecided": res["unaccepted"]["undecided"]})


def _offline(ws: Path, mapping: str, log: Path) -> dict[str, Counter[str]]:
    """``rclverify monitor --json`` of the live ``log`` under ``mapping``: each node's deadline verdicts."""
    r = subprocess.run([sys.executable, "-m", "rclverify.cli.commands", "monitor", "-w", str(ws), "--mapping",
                        mapping, "--json", str(log)], capture_output=True, text=True, timeout=60, cwd=ws,
                       env={**os.environ, "PYTHONPATH": str(REPO / "src")})
    report = json.loads(r.stdout) if r.stdout.strip().startswith("[") else []
    got = {e["node"]: _counts(e["deadlines"]) for e in report if "deadlines" in e}
    assert set(got) == {"Base", "Halt", "Relay"}, r.stdout[-3000:] + r.stderr[-3000:]
    return got


def _live(tmp: Path, ws: Path, env: dict[str, str], name: str, mapping: str) -> dict[str, Any]:
    """One live run of ``rclverify monitor --live`` (the proxy) under ``mapping`` while ``teleop`` makes its
    calls: its log's lines, exit code, output, evidence record and the log replayed offline."""
    log, out, echoed = tmp / f"{name}.jsonl", tmp / f"{name}.out", tmp / f"{name}-echo.out"
    echo = None
    monitor = _start(["-m", "rclverify.cli.commands", "monitor", "-w", str(ws), "--live", "--interfaces",
                      "interfaces", "--mapping", mapping, "--forward", "/estop=/estop_real", "--forward",
                      "/halt=/halt_real", "--log", str(log), "--status", "0", "--evidence",
                      str(tmp / f"{name}.json"), "--duration", "60"], env, ws, out)
    try:
        wait_for(out, "monitoring ", 30)
        echo = _start([str(tmp / "nodes.py"), "echo"], env, ws, echoed)
        wait_for(echoed, "ready", 30)  # subscribed to the monitor's verdict topic before the first call
        teleop = _start([str(tmp / "nodes.py"), "teleop"], env, ws, tmp / f"{name}-teleop.out")
        try:
            assert teleop.wait(30) == 0, (tmp / f"{name}-teleop.out").read_text()
        finally:
            stop(teleop)
        # every call and x judged by the run's checks (on /clock, once it passed the deadline)
        wait_logged(log, lambda lines: all(sum(_finals(_checks(lines, n)).values()) >= ROUNDS and
                                           not _finals(_checks(lines, n))["currently_false"]
                                           for n in ("Base", "Halt", "Relay")), 15)
        stop(monitor, signal.SIGINT)
    finally:
        stop(monitor)
        if echo is not None:
            stop(echo)
    lines = [json.loads(x) for x in log.read_text().splitlines()]
    return {"lines": lines, "code": monitor.returncode, "out": out.read_text(errors="replace"),
            "record": json.loads((tmp / f"{name}.json").read_text()), "offline": _offline(ws, mapping, log),
            "teleop": (tmp / f"{name}-teleop.out").read_text(), "echo": echoed.read_text(errors="replace")}


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, dict[str, Any]]]:
    """The two live runs on one master and one server (module docstring): ``sim`` and ``wall``."""
    tmp = tmp_path_factory.mktemp("svc-sim")
    ws = tmp / "ws"
    (ws / "contracts").mkdir(parents=True)
    (ws / "contracts/sys.rcl").write_text(RCL)
    (ws / "contracts/plan.yaml").write_text("contracts: [contracts/sys.rcl]\n")
    (ws / "interfaces/std_srvs/srv").mkdir(parents=True)
    (ws / "interfaces/std_srvs/srv/SetBool.srv").write_text(SETBOOL)
    (ws / "sim.yaml").write_text(TOPICS + "use_sim_time: [Base, Relay]\n")
    (ws / "wall.yaml").write_text(TOPICS + "use_sim_time: [Halt]\n")
    (tmp / "nodes.py").write_text(NODES)
    procs: list[subprocess.Popen[bytes]] = []
    with LocalMaster(tmp / "ros") as env:
        env = {**env, "PYTHONPATH": str(REPO / "src") + os.pathsep + os.environ.get("PYTHONPATH", "")}
        master = xmlrpc.client.ServerProxy(env["ROS_MASTER_URI"])
        master.setParam("/test", "/use_sim_time", True)
        try:
            for role in ("sim", "base"):
                procs.append(_start([str(tmp / "nodes.py"), role], env, ws, tmp / f"{role}.out"))
                wait_for(tmp / f"{role}.out", "ready", 30)
            out = {"sim": _live(tmp, ws, env, "sim", "sim.yaml")}
            master.setParam("/test", "/use_sim_time", False)  # the server keeps /clock: it read it at its start
            out["wall"] = _live(tmp, ws, env, "wall", "wall.yaml")
            yield out
        finally:
            for p in reversed(procs):
                stop(p)


def _one_judge(run: dict[str, Any], node: str, want: str) -> list[dict[str, Any]]:
    """``node``'s calls each judged once, ``want``, by the run's checks: the same verdicts in the log, the
    record (``topic_deadlines``), on the verdict topic and in the offline replay; one first verdict per
    call.  The control: no deadline verdict or summary of the proxy's own, no ``deadlines`` of its in the
    record.  Returns the checks' verdicts of ``node``."""
    checks = _checks(run["lines"], node)
    (res,) = [d["deadlines"] for d in run["record"]["topic_deadlines"] if d["node"] == node]
    assert _finals(checks) == _counts(res) == run["offline"][node] == Counter({want: ROUNDS}), (node, checks)
    assert _published(run["echo"], node) == checks, (node, run["echo"][-3000:])
    assert sum(1 for v in checks if not v["update"]) == ROUNDS  # once per call
    assert _proxys(run["lines"]) == [] and "deadlines" not in run["record"]
    return checks


def _warned(run: dict[str, Any]) -> list[str]:
    """The run's warning lines about a node's clock."""
    return [x for x in run["out"].splitlines() if "warning: node " in x]


def test_calls_in_time_in_simulated_time_are_true_under_use_sim_time(runs: dict[str, dict[str, Any]]) -> None:
    """``/use_sim_time`` true, ``Base`` said on ``/clock``: 300 simulated ms of 400, every deadline ``true``,
    judged once, on ``/clock``'s time (from 1000 s on) though 600 ms of the run's clock passed."""
    sim = runs["sim"]
    assert sim["teleop"].count("True") == 2 * ROUNDS, sim["teleop"]
    for v in _one_judge(sim, "Base", "true"):  # /clock's 100 ms to spare (its samples 5 ms apart)
        assert "in simulated time (use_sim_time): due at 1" in v["reason"] and 0.08 <= v["time_margin"] <= 0.11, v
        assert v["trigger_stamp"] > 1.6e9 and v["answer"] - v["trigger_stamp"] >= 0.5, v  # the run's clock
    assert sim["record"]["decode_errors"] == {}  # /clock heard beside rospy's own subscription to it
    assert sum(1 for x in sim["lines"] if x["topic"] == "clock") > 100


def test_a_node_said_on_the_wall_clock_under_use_sim_time_is_judged_on_it_with_a_warning(
        runs: dict[str, dict[str, Any]]) -> None:
    """``Halt`` said to keep the wall clock while ``/use_sim_time`` is true: judged on the wall clock, where
    the 600 ms answers are late, once per call; the run says so in one warning line naming the node and both
    settings, the only one (``Base`` and ``Relay``, on ``/clock`` as ROS is, the controls), and exits 1."""
    sim = runs["sim"]
    for v in _one_judge(sim, "Halt", "false"):
        assert v["trigger_stamp"] > 1.6e9 and "simulated time" not in v["reason"], v
    (line,) = _warned(sim)
    assert "node Halt keeps the wall clock by the mapping's use_sim_time but /use_sim_time is true" in line, line
    assert sim["record"]["warnings"] == [line] and sim["code"] == 1


def test_the_wall_clock_judges_the_same_answers_false_without_use_sim_time(
        runs: dict[str, dict[str, Any]]) -> None:
    """``/use_sim_time`` false: the same server's 600 ms answers are ``false`` for ``Base`` (a wall-clock
    node), false once the deadline passed on the run's clock, then again with the late answer; ``Halt``,
    said on ``/clock``, ``true`` by the ``/clock`` samples, with its warning line; the run exits 1."""
    wall = runs["wall"]
    verdicts = _one_judge(wall, "Base", "false")
    assert [(v["answer"] is None, v["update"]) for v in verdicts] == [(True, False), (False, True)] * ROUNDS
    for v in verdicts[1::2]:
        assert v["trigger_stamp"] > 1.6e9 and v["answer"] - v["trigger_stamp"] >= 0.55, v
    _one_judge(wall, "Halt", "true")
    (line,) = _warned(wall)
    assert ("node Halt keeps simulated time (/clock) by the mapping's use_sim_time but /use_sim_time is false"
            in line), line
    assert wall["record"]["warnings"] == [line] and wall["code"] == 1


def test_a_topics_deadline_is_judged_in_the_clock_the_mapping_gives_its_node(runs: dict[str, dict[str, Any]]) -> None:
    """The relay answers each ``x`` after 300 ms of ``/clock``, 600 ms of the wall clock, both stamped on
    ``/clock``: said on ``/clock`` (the ``sim`` run) every deadline is ``true``, said on the wall clock (the
    ``wall`` run, the control) every one ``false``, live and offline; its answers hold in both runs.  The
    stamps on ``/clock`` are named as another clock than the run's, the wall clock: ``y``'s in both runs,
    ``x``'s where ``teleop`` started under ``/use_sim_time`` (``sim``) and not where it did not (``wall``)."""
    for name, want, other in (("sim", "true", {"/x", "/y"}), ("wall", "false", {"/y"})):
        run = runs[name]
        assert _finals(_checks(run["lines"], "Relay")) == run["offline"]["Relay"] == Counter({want: ROUNDS}), name
        (relay,) = [n for n in run["record"]["nodes"] if n["node"] == "Relay"]
        assert relay["counts"]["satisfied"] == ROUNDS and relay["counts"]["violated"] == 0, relay
        assert {line.split(":")[0] for line in run["record"]["other_clocks"]} == other, run["record"]["other_clocks"]
