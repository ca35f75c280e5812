"""A ROS 2 run judged as the robot carries it: real rclpy nodes on Fast DDS,
a monitor started AFTER the publishers (docs/semantics.md, "Widths" and
"Steps"; docs/ros2.md, "Judged as the robot carries it").

One rclpy process runs for each source; it publishes for about 1.5 s
before the monitors start, goes on publishing until their verdict writers
are in the graph, and publishes 45 more rounds after (at least 150 ms apart,
about 6.8 s, each once the node published the round before's answers: at
their source times no answer lies after the next round's question).  The run
is heard through each source, rclpy and DDS (docs/ros2.md, "Two sources"),
with the same verdicts:

* **float32 at a decimal threshold**: ``BatteryState.percentage`` (float32)
  cycles through 0.5, 0.2, 0.1; ``battery`` answers ``home`` comparing with
  0.2 as the field carries it (``<=``), ``slip`` with ``<`` (the slip).  On
  the wire 0.2 is 0.2000000030: the contract's 0.2 is judged at float32, so
  ``battery`` is green and ``slip`` violated at the 0.2 messages, live, on
  the log offline and on the bag;
* **LaserScan.ranges** (an unbounded float32 sequence) into ``seq(REAL)``:
  ``guard`` stops when any range is below 0.5, ``blind`` forgets the last
  beam: violated where only the last beam is near;
* **start-up**: ``echo`` answers every ``/x``, ``progress( within 0 steps
  )``; its inputs heard before its answers were (the monitor's readers
  match one by one) are not counted against it;
* **one instant, one step**: ``upstream`` publishes ``/fa`` and ``/fb`` at
  once, ``fuse`` answers their sum once: ``progress( within 0 steps )`` holds;
* **transient-local**: ``config`` publishes ``/limit`` once, latched, long
  before the monitor starts; ``clamp`` answers each ``/cmd`` with at most
  the limit.  The monitor's reader is transient-local as the publisher
  offers, so the latched limit is delivered as ROS 2 delivers it to a late
  subscriber, and every answer is judged (none undecided for want of it);
* **nothing decided**: ``probe`` publishes only NaN on ``/nan`` and
  ``sink`` echoes it; a second monitor of that node alone, under
  ``--strict``, exits 1 and says that nothing was decided.
"""
from __future__ import annotations

import json
import signal
from typing import Any, Iterator

import pytest
from _procs import stop, wait_for, wait_logged
from _ros2 import live_workspace, rclverify, ros2_env, ros2_python, start_node

from rclverify.cli.commands import main

RCL = """\
node Battery {
  inputs( p : REAL )
  outputs( home : BOOL )
  topics( sensor_msgs/BatteryState battery matches(in.p), std_msgs/Bool home matches(out.home) )
  assume( 0 <= in.p and in.p <= 1 )
  guarantee( out.home == (in.p <= 0.2) )
}

node Slip {
  inputs( p : REAL )
  outputs( home : BOOL )
  topics( sensor_msgs/BatteryState battery matches(in.p), std_msgs/Bool slip_home matches(out.home) )
  assume( 0 <= in.p and in.p <= 1 )
  guarantee( out.home == (in.p <= 0.2) )
}

node Guard {
  inputs( ranges : seq(REAL) )
  outputs( stop : BOOL )
  topics( sensor_msgs/LaserScan scan matches(in.ranges), std_msgs/Bool stop matches(out.stop) )
  assume( TRUE )
  guarantee( out.stop == exists(r in in.ranges | r < 0.5) )
}

node Blind {
  inputs( ranges : seq(REAL) )
  outputs( stop : BOOL )
  topics( sensor_msgs/LaserScan scan matches(in.ranges), std_msgs/Bool blind_stop matches(out.stop) )
  assume( TRUE )
  guarantee( out.stop == exists(r in in.ranges | r < 0.5) )
}

node Echo {
  inputs( x : INTEGER )
  outputs( y : INTEGER )
  topics( std_msgs/Int64 x matches(in.x), std_msgs/Int64 y matches(out.y) )
  assume( TRUE )
  guarantee( out.y == in.x )
  progress( within 0 steps )
}

node Fuse {
  inputs( a : INTEGER, b : INTEGER )
  outputs( s : INTEGER )
  topics( std_msgs/Int64 fa matches(in.a), std_msgs/Int64 fb matches(in.b), std_msgs/Int64 fs matches(out.s) )
  assume( TRUE )
  guarantee( out.s == in.a + in.b )
  progress( within 0 steps )
}

node Clamp {
  inputs( limit : INTEGER, v : INTEGER )
  outputs( c : INTEGER )
  topics( std_msgs/Int64 limit matches(in.limit), std_msgs/Int64 cmd matches(in.v),
          std_msgs/Int64 clamped matches(out.c) )
  assume( TRUE )
  guarantee( out.c <= in.limit )
}

node Limiter {
  inputs( cap : REAL )
  outputs( speed : REAL )
  topics( std_msgs/Float64 cap matches(in.cap), std_msgs/Float64 speed matches(out.speed) )
  assume( TRUE )
  guarantee( out.speed <= in.cap )
}

node Sink {
  inputs( v : REAL )
  outputs( w : REAL )
  topics( std_msgs/Float64 nan matches(in.v), std_msgs/Float64 nan_out matches(out.w) )
  assume( TRUE )
  guarantee( out.w == in.v )
}
"""
# the stated transport skew: fa and fb, published together, may arrive tens of milliseconds apart on a loaded
# machine (the suite runs three workers on two cores); rounds are 150 ms apart
MAPPING = """\
skew: 0.05
topics:
  battery: {fields: [percentage]}
  scan: {fields: [ranges]}
  limit: {state: true}
"""

SYSTEM = """\
import math, struct, time
import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.qos import QoSProfile, DurabilityPolicy, ReliabilityPolicy
from sensor_msgs.msg import BatteryState, LaserScan
from std_msgs.msg import Bool, Float64, Int64

rclpy.init()
n = Node("robot")
LIMIT = struct.unpack("f", struct.pack("f", 0.2))[0]  # 0.2 as a float32 field carries it
pubs = {k: n.create_publisher(t, k, 10) for k, t in (
    ("battery", BatteryState), ("home", Bool), ("slip_home", Bool), ("scan", LaserScan), ("stop", Bool),
    ("blind_stop", Bool), ("x", Int64), ("y", Int64), ("fa", Int64), ("fb", Int64), ("fs", Int64),
    ("cmd", Int64), ("clamped", Int64), ("nan", Float64), ("nan_out", Float64), ("cap", Float64),
    ("speed_unchecked", Float64))}
latched = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL, reliability=ReliabilityPolicy.RELIABLE)
limit_pub = n.create_publisher(Int64, "limit", latched)
limit_pub.publish(Int64(data=7))  # once, before anyone listens

answered = {}  # input -> the round whose answer was published last (a round's number rides in a field no
                # contract reads: the battery's voltage, the scan's range_max)
n.create_subscription(BatteryState, "battery", lambda m: (
    pubs["home"].publish(Bool(data=m.percentage <= LIMIT)),
    pubs["slip_home"].publish(Bool(data=m.percentage < LIMIT)), answered.__setitem__("battery", m.voltage)), 10)
n.create_subscription(LaserScan, "scan", lambda m: (
    pubs["stop"].publish(Bool(data=any(r < 0.5 for r in m.ranges))),
    pubs["blind_stop"].publish(Bool(data=any(r < 0.5 for r in m.ranges[:-1]))),
    answered.__setitem__("scan", m.range_max)), 10)
n.create_subscription(Int64, "x", lambda m: (pubs["y"].publish(Int64(data=m.data)),
                                             answered.__setitem__("x", m.data)), 10)
got = {}
def fused(k, m):
    got[k] = m.data
    if len(got) == 2:
        pubs["fs"].publish(Int64(data=got["a"] + got["b"]))
        answered["fs"] = got["a"]
        got.clear()
n.create_subscription(Int64, "fa", lambda m: fused("a", m), 10)
n.create_subscription(Int64, "fb", lambda m: fused("b", m), 10)
limit = [None]
n.create_subscription(Int64, "limit", lambda m: limit.__setitem__(0, m.data), latched)
n.create_subscription(Int64, "cmd", lambda m: (pubs["clamped"].publish(Int64(data=min(m.data, limit[0]))),
                                               answered.__setitem__("cmd", m.data)), 10)
n.create_subscription(Float64, "nan", lambda m: pubs["nan_out"].publish(Float64(data=m.data)), 10)
from std_msgs.msg import String
import json as _json
released = []  # what the gate lets through on /speed (--enforce /speed: the node writes /speed_unchecked)
n.create_subscription(Float64, "speed", lambda m: released.append(m.data), 100)
heard = []  # the monitor's verdicts, as a ROS 2 subscriber decodes them
n.create_subscription(String, "/rclverify/verdict", lambda m: heard.append(_json.loads(m.data)), 1000)
ex = SingleThreadedExecutor()
ex.add_node(n)

def spin(seconds):
    until = time.monotonic() + seconds
    while time.monotonic() < until:
        ex.spin_once(timeout_sec=0.005)

spin(0.5)
print("ready", flush=True)
levels = [0.5, 0.2, 0.1]
scans = [[1.0, 2.0, 3.0], [1.0, 0.3, 3.0], [1.0, 2.0, 0.3]]

OWN = {"battery", "scan", "x", "fa", "fb", "cmd", "nan"}  # the topics this node reads itself

def readers_matched():  # every topic read by the monitor, /nan and /nan_out by the second one too
    return all(p.get_subscription_count() >= (t in OWN) + 1 + (t in ("nan", "nan_out")) for t, p in pubs.items())

def wait_monitors():
    print("before", flush=True)  # the monitors start now (the fixture), while this keeps publishing
    until = time.monotonic() + 60
    while time.monotonic() < until and (n.count_publishers("/rclverify/verdict") < 1
                                       or n.count_publishers("/nan/verdict") < 1 or not readers_matched()):
        spin(0.05)
        publish_all(-1)
    print("matched", readers_matched(), flush=True)

def publish_all(k):
    pubs["battery"].publish(BatteryState(percentage=levels[k % 3], voltage=float(k)))
    pubs["scan"].publish(LaserScan(ranges=scans[k % 3], range_max=float(k)))
    pubs["x"].publish(Int64(data=k))
    pubs["fa"].publish(Int64(data=k))
    pubs["fb"].publish(Int64(data=2 * k))  # at the same instant as fa: one question
    pubs["cmd"].publish(Int64(data=k % 12))
    pubs["nan"].publish(Float64(data=math.nan))
    pubs["cap"].publish(Float64(data=5.0))
    pubs["speed_unchecked"].publish(Float64(data=[1.0, 7.0, 4.0][k % 3]))  # 7.0 breaks the cap

for k in range(20):  # about 1.4 s before any monitor
    publish_all(k)
    spin(0.07)
wait_monitors()  # the monitors' readers match their publishers one by one: the rounds once all did
spin(0.3)
def round_answered(k):
    return answered == {"battery": float(k), "scan": float(k), "x": k, "fs": k, "cmd": k % 12}

for k in range(20, 65):
    publish_all(k)
    spin(0.15)
    # the next round's questions only once this round's answers were published: at their source times every
    # answer lies before the next question, however late a loaded machine runs the node's callbacks
    until = time.monotonic() + 5
    while time.monotonic() < until and not round_answered(k):
        ex.spin_once(timeout_sec=0.005)
spin(0.5)
print("released", sorted(set(released)), len(released), flush=True)
print("done", len(heard), len([v for v in heard if v.get("verdict") == "violated"]), flush=True)
while True:
    ex.spin_once(timeout_sec=0.1)
"""


@pytest.fixture(scope="module", params=["dds", "rclpy"])
def run(request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, Any]]:
    """The run heard through each source (docs/ros2.md, "Two sources"): the same verdicts and exit codes."""
    py = ros2_python()  # skips, with the reason, without a ROS 2 Python
    source = request.param
    tmp = tmp_path_factory.mktemp(f"carried-{source}")
    ws = live_workspace(tmp, RCL, MAPPING)
    env = ros2_env(tmp)
    system = monitor = nan = None
    # the lateness bound of a loaded machine (three test workers on two cores: a reader's delivery was seen
    # 97 ms late): a question heard later than the bound leaves its answer undecided (docs/semantics.md,
    # "Event time"), which the verdict sets below do not expect of these nodes
    common = ["--live", "--ros2", "--mapping", "mapping.yaml", "--horizon", "0.5", "--status", "0",
              "--duration", "60", "--source", source, "--ros2-python", str(py), "--reorder-window", "0.3"]
    try:
        system = start_node(tmp, "system", SYSTEM, env)
        wait_for(tmp / "system.log", "before", 30)  # the publishers ran before any monitor
        monitor = rclverify(["monitor", "-w", str(ws), *common, "--strict", "--enforce", "/speed",
                             "--log", str(tmp / "live.jsonl"),
                             "--record", str(tmp / "bag"), "--evidence", str(tmp / "live.json")],
                            env, tmp, tmp / "monitor.out")
        nan = rclverify(["monitor", "-w", str(ws), *common, "--node", "Sink", "--strict", "--verdict-topic",
                         "/nan/verdict", "--evidence", str(tmp / "nan.json")], env, tmp, tmp / "nan.out")
        wait_for(tmp / "system.log", "done", 120)
        # the last round's answers heard and released past the watermark, however loaded the machine
        wait_logged(tmp / "live.jsonl", lambda log: {("y", 64), ("fs", 192)} <= {
            (x.get("topic"), x.get("data")) for x in log}, 30)
        stop(monitor, signal.SIGINT)
        stop(nan, signal.SIGINT)
        yield {"source": source, "tmp": tmp, "ws": ws, "code": monitor.returncode,
               "out": (tmp / "monitor.out").read_text(),
               "system": (tmp / "system.log").read_text(),
               "log": [json.loads(x) for x in (tmp / "live.jsonl").read_text().splitlines()],
               "record": json.loads((tmp / "live.json").read_text()),
               "nan": {"code": nan.returncode, "out": (tmp / "nan.out").read_text(),
                       "record": json.loads((tmp / "nan.json").read_text())}}
    finally:
        for p in (system, monitor, nan):
            if p is not None:
                stop(p)


def _verdicts(run: dict[str, Any], node: str) -> list[dict[str, Any]]:
    """The node's live verdicts, the latest of each message (a revision replaces the one given before:
    backends/monitors/late.py)."""
    last = {x["verdict"]["event"]: x["verdict"] for x in run["log"] if x.get("topic") == "rclverify/verdict"
            and "kind" not in x and x["verdict"].get("node") == node}
    return list(last.values())


def _inputs(run: dict[str, Any], topic: str, field: str) -> dict[int, Any]:
    return {i: x[field] for i, x in enumerate(run["log"]) if x.get("topic") == topic}


def test_float32_at_a_decimal_threshold_live(run: dict[str, Any]) -> None:
    battery, slip = _verdicts(run, "Battery"), _verdicts(run, "Slip")
    # an input heard before the monitor heard any answer is superseded (docs/semantics.md, "Steps")
    quiet = {"satisfied", "superseded", "before first answer"}  # what a correct node may get at start-up
    assert "satisfied" in {v["verdict"] for v in battery} <= quiet, battery
    bad = [v for v in slip if v["verdict"] == "violated"]
    assert bad and {v["verdict"] for v in slip} <= quiet | {"violated"}, slip
    # every violation answers a battery message at 0.2 (float32 on the wire: 0.2000000030)
    assert all(v["values"]["in.p"].startswith("0.2000000") for v in bad), bad


def test_laserscan_ranges_judged_live(run: dict[str, Any]) -> None:
    guard, blind = _verdicts(run, "Guard"), _verdicts(run, "Blind")
    assert "satisfied" in {v["verdict"] for v in guard} <= {"satisfied", "superseded", "before first answer"}, guard
    bad = [v for v in blind if v["verdict"] == "violated"]
    assert bad and all(v["values"]["out.stop"] == "FALSE" for v in bad), blind
    # only the last beam near, as the float32 field carries 0.3
    assert all(v["values"]["in.ranges"] == "<1.0, 2.0, 0.30000001192092896>" for v in bad), bad


def test_a_monitor_started_after_the_publishers_blames_no_one(run: dict[str, Any]) -> None:
    decl = {d["node"]: d for d in run["record"]["declarations"]}
    for node in ("Echo", "Fuse"):
        assert decl[node]["status"] == "discharged", decl[node]
    # what was heard before the readers all matched is at worst undecided (an input alone, an input
    # superseded before any answer was heard), never violated
    for node in ("Echo", "Fuse"):
        verdicts = {v["verdict"] for v in _verdicts(run, node)}
        assert "satisfied" in verdicts and not verdicts & {"violated", "inconclusive"}, (node, verdicts)


def test_a_latched_input_is_delivered_as_ros2_delivers_it(run: dict[str, Any]) -> None:
    limits = [x for x in run["log"] if x.get("topic") == "limit"]
    assert len(limits) == 1 and limits[0]["data"] == 7  # published once, before the monitor joined
    clamp = _verdicts(run, "Clamp")
    # the latched limit is the state every later command is judged with: a command is "incomplete input" only
    # if it was heard before the limit (the monitor's readers match one by one); the limit came before any
    # answer, so it asks nothing itself (superseded, docs/semantics.md "Steps")
    # (an answer heard within the stated skew of the next command is inconclusive, never guessed: the load)
    skewed = [v for v in clamp if v["verdict"] == "inconclusive" and "before the question" in v.get("reason", "")]
    assert clamp and {v["verdict"] for v in clamp if v not in skewed} <= {
        "satisfied", "superseded", "incomplete input", "before first answer"}, clamp
    assert all(v["time"] <= limits[0]["time"] for v in clamp if v["verdict"] == "incomplete input"), clamp
    assert sum(v["verdict"] == "satisfied" for v in clamp) >= 30


def test_the_verdicts_are_the_same_offline_and_in_the_bag(run: dict[str, Any],
                                                          capsys: pytest.CaptureFixture[str]) -> None:
    for source in ("live.jsonl", "bag"):
        code = main(["monitor", "-w", str(run["ws"]), "--mapping", "mapping.yaml", "--horizon", "0.5",
                     "--node", "Slip", "--node", "Battery", "--node", "Guard", "--node", "Blind",
                     str(run["tmp"] / source)])
        out = capsys.readouterr().out
        assert code == 1, out
        for node in ("Slip", "Blind"):
            n = sum(v["verdict"] == "violated" for v in _verdicts(run, node))
            (line,) = [x for x in out.splitlines() if f": {node}: " in x and "deadlines" not in x]
            assert f"{n} violated" in line, (node, line)  # the same count as live, for this node
    assert run["code"] == 1, run["out"]


def test_a_live_run_that_decided_nothing_fails_strict(run: dict[str, Any]) -> None:
    nan = run["nan"]
    assert nan["code"] == 1, nan["out"]
    assert "nothing" in nan["out"] and "Sink" in nan["out"], nan["out"]
    assert nan["record"]["not_judged"], nan["record"]


def test_the_source_is_the_one_asked_and_said(run: dict[str, Any]) -> None:
    """Never a silent fall-back: the record and the first line say which source heard the run."""
    rec = run["record"]
    assert rec["source"] == run["source"], rec.get("middleware")
    if run["source"] == "rclpy":
        assert rec["rmw"] == "rmw_fastrtps_cpp" and "through rclpy on rmw_fastrtps_cpp" in run["out"]
        # the writer's sequence numbers tell what was published before the monitor heard it
        assert rec["qos"]["x"]["published_before_heard"] > 0, rec["qos"]["x"]
    else:
        assert "on DDS domain" in run["out"] and rec["unseen"] == []
    # the log says it too, in its first line, for the evidence and the report (run_origin.py)
    first = json.loads((run["tmp"] / "live.jsonl").read_text().splitlines()[0])
    assert first["topic"] == "rclverify/run" and (first["source"], first["rmw"]) == (rec["source"], rec["rmw"])
    # the verdicts reach a ROS 2 subscriber on /rclverify/verdict, decoded (std_msgs/String JSON), either way
    heard, violated = (int(x) for x in run["system"].split("done ")[1].split()[:2])
    assert "matched True" in run["system"], run["system"]  # the rounds began once every reader had matched
    assert heard > 50 and violated > 0, run["system"]


def test_every_correct_node_is_green_and_every_slip_red(run: dict[str, Any]) -> None:
    """What was heard before the monitor's readers matched counts against no one (docs/semantics.md, "Steps"):
    the correct nodes are discharged, the two slips failed, the NaN-only node not judged."""
    status = {n["node"]: n["status"] for n in run["record"]["nodes"]}
    assert {k: status[k] for k in ("Battery", "Guard", "Echo", "Fuse", "Clamp")} == dict.fromkeys(
        ("Battery", "Guard", "Echo", "Fuse", "Clamp"), "discharged"), run["out"]
    assert status["Slip"] == status["Blind"] == "failed"
    assert [i["node"] for i in run["record"]["not_judged"]] == ["Sink"], run["record"]["not_judged"]


def test_the_gate_releases_only_what_holds(run: dict[str, Any]) -> None:
    """--enforce /speed through either source: Limiter writes /speed_unchecked; the gate republishes on /speed
    exactly the messages within the cap, byte for byte, and a ROS 2 subscriber of /speed hears only those."""
    line = run["system"].split("released ")[1].splitlines()[0]
    values, count = line.rsplit(" ", 1)
    assert values == "[1.0, 4.0]" and int(count) >= 20, line  # 7.0 never released
    gate = run["record"]["enforce"]["speed"]
    assert gate["blocked"] >= 10 and gate["released"] >= int(count), gate
