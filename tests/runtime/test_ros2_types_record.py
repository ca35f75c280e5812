"""Every message type from real ROS 2 publishers, and ``--record`` in both
bag storages (issue 62), with real rclpy nodes on Fast DDS (tests/_ros2.py).

One rclpy node, ``talker``, publishes :data:`N` messages on each of seven
topics whose types hold what a flat type does not: unbounded and bounded
sequences (``std_msgs/Float64MultiArray``, ``test_msgs/UnboundedSequences``,
``test_msgs/BoundedSequences`` with their default values), fixed arrays and
strings (``test_msgs/Arrays``), sequences of strings beside numbers
(``sensor_msgs/JointState``), a nested fixed array (the covariance of
``geometry_msgs/PoseWithCovarianceStamped``) and sequences of nested
sequences (``test_msgs/MultiNested``).  Each topic has a node in the
contracts whose guarantee reads one scalar through a field path
(``data[0]``, ``pose.covariance[35]``,
``unbounded_sequence_of_unbounded_sequences[1].int32_values[-1]`` ...), and
some of the values break it, so the verdicts are known in advance
(:data:`EXPECTED`).

An eighth topic, ``mislaid``, carries ROS 2's ``test_msgs/Nested`` from
the rclpy node while the workspace defines ``test_msgs/Nested`` with other
fields (``float64 x``), and a Cyclone DDS publisher of the project's own
(tests/dds_ros2.py) publishes the workspace's layout on it: the same type
name, two layouts.  Fast DDS's writers are matched on the type name
(``rclverify.ros.live.dds.COMPATIBILITY``), so the rclpy node's samples reach
the monitor's reader; the ROS 2 type hash it announces differs from the
workspace's, so the monitor names it in a warning and drops every one of
its samples (counted), while the Cyclone publisher, whose XTypes type
object has the contract's layout, is heard.

A tenth, ``keyed``, carries ``test_msgs/KeyedLong`` (``@key long key``,
declared in ``.idl`` only), which the workspace describes with a ``.msg``
of the same fields and no key: DDS never matches a keyless reader with a
keyed writer, so the monitor says so and hears nothing of it.

A ninth, ``ws``, carries ``test_msgs/WStrings`` (wide strings, their
defaults, arrays and sequences of them), watched by a third monitor of its
own (``--node W``, no bag: rosbags cannot describe a ``wstring``), whose
guarantee compares the decoded text.

Two live monitors watch the rest of the run, one recording to the default
storage (SQLite 3), one to MCAP.  Checked: every message heard and decoded (the
counts per topic, no decode error), the verdicts, no layout warning and no
Cyclone ``invalid type object`` line on the monitor's output; each bag read
back by rosbags (its ``metadata.yaml``, the message counts, a decoded
value), and ``rclverify monitor BAG`` giving the live verdicts.
"""
from __future__ import annotations

import json
import re
import shutil
import signal
import subprocess
import time
from pathlib import Path
from typing import Any, Iterator

import pytest
from _procs import stop, wait_for, wait_logged
from _ros2 import rclverify, ros2_env, ros2_python, start_node
from dds_ros2 import Ros2Participant, domain_of, matched, wait_until

from rclverify.runtime.dds.types import TypeBook
from rclverify.ros.live.dds import configure_domain

from rclverify.cli.commands import main

N = 20  # messages per topic
#: topic -> (type, field path, RCL type, guarantee over the value v, expected (satisfied, violated))
TOPICS: dict[str, tuple[str, str, str, str, tuple[int, int]]] = {
    "arr": ("std_msgs/Float64MultiArray", "data[0]", "REAL", "v >= 0", (N - 1, 1)),
    "joints": ("sensor_msgs/JointState", "position[1]", "REAL", "v <= 1.05", (11, N - 11)),
    "pose": ("geometry_msgs/PoseWithCovarianceStamped", "pose.covariance[35]", "REAL", "v >= 0", (N, 0)),
    "bounded": ("test_msgs/BoundedSequences", "int32_values[0]", "INTEGER", "v < 15", (15, N - 15)),
    "unbounded": ("test_msgs/UnboundedSequences", "float64_values[-1]", "REAL", "v >= 0", (N, 0)),
    "arrays": ("test_msgs/Arrays", "int32_values[2]", "INTEGER", "v != 13", (N - 1, 1)),
    "nested": ("test_msgs/MultiNested", "unbounded_sequence_of_unbounded_sequences[1].int32_values[-1]",
               "INTEGER", "v <= 16", (17, N - 17)),
}
EXPECTED = {**{name.capitalize(): want for name, (*_, want) in TOPICS.items()}, "Mislaid": (N, 0), "Keyed": (0, 0)}
WIDE = "context {\n  Greeting = {hello, bye} ;\n}\nnode W {\n  inputs( )\n  outputs( v : Greeting )\n" \
    "  topics( test_msgs/WStrings ws matches(out.v) )\n  assume( TRUE )\n  guarantee( out.v == hello )\n}\n"
KEYED = "node Keyed {\n  inputs( )\n  outputs( v : INTEGER )\n  topics( test_msgs/KeyedLong keyed matches(out.v) )\n" \
    "  assume( TRUE )\n  guarantee( out.v >= 0 )\n}\n"
MISLAID = "node Mislaid {\n  inputs( )\n  outputs( v : REAL )\n  topics( test_msgs/Nested mislaid matches(out.v) )\n" \
    "  assume( TRUE )\n  guarantee( out.v >= 0 )\n}\n"

SYSTEM = f"""\
import time
import rclpy
from rclpy.node import Node
from std_msgs.msg import Float64MultiArray, MultiArrayDimension
from sensor_msgs.msg import JointState
from geometry_msgs.msg import PoseWithCovarianceStamped
from test_msgs.msg import Arrays, BoundedSequences, KeyedLong, MultiNested, Nested, UnboundedSequences, WStrings

rclpy.init()
node = Node("talker")
types = {{"arr": Float64MultiArray, "joints": JointState, "pose": PoseWithCovarianceStamped,
         "bounded": BoundedSequences, "unbounded": UnboundedSequences, "arrays": Arrays, "nested": MultiNested,
         "mislaid": Nested, "ws": WStrings, "keyed": KeyedLong}}
pubs = {{t: node.create_publisher(c, t, 50) for t, c in types.items()}}
print("ready", flush=True)
until = time.monotonic() + 20
while time.monotonic() < until and (min(p.get_subscription_count() for t, p in pubs.items() if t not in ("ws", "keyed")) < 2
                                    or pubs["ws"].get_subscription_count() < 1):
    time.sleep(0.05)
print("matched", {{t: p.get_subscription_count() for t, p in pubs.items()}}, flush=True)
time.sleep(0.3)
for k in range({N}):
    stamp = node.get_clock().now().to_msg()
    m = Float64MultiArray(data=[-1.0 if k == 7 else float(k), 2.0 * k, 0.5])
    m.layout.dim = [MultiArrayDimension(label="x", size=3, stride=3)]
    pubs["arr"].publish(m)
    j = JointState(name=["a", "b"], position=[0.0, 0.1 * k], effort=[1.0])
    j.header.stamp = stamp
    pubs["joints"].publish(j)
    p = PoseWithCovarianceStamped()
    p.header.stamp, p.header.frame_id = stamp, "map"
    p.pose.pose.position.x = float(k)
    p.pose.covariance[35] = 0.1 * k
    pubs["pose"].publish(p)
    pubs["bounded"].publish(BoundedSequences(int32_values=[k, -k], string_values=["s%d" % k]))
    pubs["unbounded"].publish(UnboundedSequences(float64_values=[0.0] * k + [float(k)], string_values=["u"] * k))
    pubs["arrays"].publish(Arrays(int32_values=[0, 0, k], string_values=["a", "bb", "c" * k]))
    pubs["nested"].publish(MultiNested(unbounded_sequence_of_unbounded_sequences=[
        UnboundedSequences(), UnboundedSequences(int32_values=[5, k], string_values=["n"])]))
    pubs["mislaid"].publish(Nested())
    pubs["keyed"].publish(KeyedLong(key=k % 3, value=k))
    pubs["ws"].publish(WStrings(wstring_value="hello" if k < {N - 1} else "bye",
                                array_of_wstrings=["a", "\u00fc", str(k)], unbounded_sequence_of_wstrings=["x"] * (k % 3)))
    time.sleep(0.02)
print("done", flush=True)
while rclpy.ok():  # rclpy's own SIGTERM handler shuts the context down: then this process ends
    time.sleep(0.1)
"""

#: where the ROS 2 Python's test_msgs definitions are: an ament prefix (apt's setup.bash), else the venv's own
FIND_TEST_MSGS = """\
import os, sys
prefixes = [p for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p] + [sys.prefix]
print(next(os.path.join(p, "share", "test_msgs") for p in prefixes
           if os.path.isdir(os.path.join(p, "share", "test_msgs", "msg"))))
"""


def _workspace(ws: Path) -> None:
    """Contracts, plan, mapping and the test_msgs definitions (the .msg files ROS 2 installs)."""
    rcl = []
    for name, (typ, _path, rcl_type, guarantee, _want) in TOPICS.items():
        rcl.append(f"node {name.capitalize()} {{\n  inputs( )\n  outputs( v : {rcl_type} )\n"
                   f"  topics( {typ} {name} matches(out.v) )\n  assume( TRUE )\n"
                   f"  guarantee( {guarantee.replace('v', 'out.v')} )\n}}\n")
    (ws / "contracts").mkdir(parents=True)
    (ws / "contracts/types.rcl").write_text("\n".join(rcl + [MISLAID, KEYED, WIDE]), encoding="utf-8")
    (ws / "contracts/plan.yaml").write_text("contracts: [contracts/types.rcl]\n")
    fields = "\n".join(f"  {name}: {{fields: ['{path}']}}" for name, (_t, path, *_r) in TOPICS.items())
    (ws / "mapping.yaml").write_text(f"msg_dirs: [interfaces]\ntopics:\n{fields}\n  mislaid: {{fields: [x]}}\n"
                                 "  ws: {fields: [wstring_value]}\n  keyed: {fields: [value]}\n")
    share = Path(subprocess.run([str(ros2_python()), "-c", FIND_TEST_MSGS], capture_output=True, text=True,
                                timeout=60, check=True).stdout.strip()) / "msg"
    (ws / "interfaces/test_msgs/msg").mkdir(parents=True)
    for f in share.glob("*.msg"):
        shutil.copy(f, ws / "interfaces/test_msgs/msg" / f.name)
    (ws / "interfaces/test_msgs/msg/Nested.msg").write_text("float64 x\n")  # not ROS 2's: another layout
    (ws / "interfaces/test_msgs/msg/KeyedLong.msg").write_text("int32 key\nint32 value\n")  # ROS 2's has only .idl


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, Any]]:
    ros2_python()  # skips, with the reason, without a ROS 2 Python
    tmp = tmp_path_factory.mktemp("types")
    ws = tmp / "ws"
    _workspace(ws)
    env = ros2_env(tmp)
    bags = {"sqlite3": tmp / "run_sqlite", "mcap": tmp / "run.mcap"}
    procs = {}
    system = cyclone = None
    mp = pytest.MonkeyPatch()
    for var in ("CYCLONEDDS_URI", "ROS_DOMAIN_ID"):  # this process's Cyclone publisher: the same domain, loopback
        mp.setenv(var, env[var])
    try:
        nodes = [x for n in [*EXPECTED] for x in ("--node", n)]
        # no lateness bound: every node here has outputs only, so the order heard decides no verdict
        for name, extra in [*((n, ["--record", str(b), *nodes]) for n, b in bags.items()), ("wide", ["--node", "W"])]:
            procs[name] = rclverify(
                ["monitor", "-w", str(ws), "--live", "--ros2", "--mapping", "mapping.yaml", "--horizon", "1.0",
                 "--reorder-window", "0", "--status", "0", "--duration", "60", "--verdict-topic", f"/{name}/verdict",
                 "--log", str(tmp / f"{name}.jsonl"), "--evidence", str(tmp / f"{name}.json"), *extra],
                env, tmp, tmp / f"{name}.out")
        for name in procs:
            wait_for(tmp / f"{name}.out", "monitoring", 30)
        configure_domain(domain_of(env))  # as the monitor's: Fast DDS's type information read without complaint
        cyclone = Ros2Participant(TypeBook([ws / "interfaces"]), domain_of(env))
        # a history as deep as the run: on a loaded machine a reader's acknowledgement can lag ten samples
        right = cyclone.publisher(cyclone.node("right"), "/mislaid", "test_msgs/Nested", depth=N)
        cyclone.announce()
        wait_until(lambda: matched(right) >= 2, 20, "the monitors' readers of /mislaid matched")
        Nested = cyclone.types.message("test_msgs/Nested")
        for k in range(N):
            right.write(Nested(x=float(k)))
            time.sleep(0.005)
        system = start_node(tmp, "system", SYSTEM, env)
        wait_for(tmp / "system.log", "done", 40)
        announced = _announced_type_ids(env, {f"rt/{t}" for t in [*TOPICS, "ws"]})
        # every message heard by every monitor before it stops, however loaded the machine (a sleep was not)
        for name, topics in [*((n, [*TOPICS, "mislaid"]) for n in bags), ("wide", ["ws"])]:
            wait_logged(tmp / f"{name}.jsonl", lambda log, ts=topics: all(
                sum(x.get("topic") == t for x in log) >= N for t in ts), 30)
        for p in procs.values():
            stop(p, signal.SIGINT)
        yield {"tmp": tmp, "ws": ws, "bags": {n: Path(str(b).removesuffix(".mcap")) for n, b in bags.items()},
               "out": {n: (tmp / f"{n}.out").read_text() for n in procs},
               "record": {n: json.loads((tmp / f"{n}.json").read_text()) for n in procs},
               "wide_log": [json.loads(x) for x in (tmp / "wide.jsonl").read_text().splitlines()],
               "system": (tmp / "system.log").read_text(), "announced": announced}
    finally:
        if system is not None:
            stop(system)
        for p in procs.values():
            stop(p)
        if cyclone is not None:
            cyclone.close()
        mp.undo()


#: Prints, as JSON, DDS topic -> the repr of the complete XTypes type identifier announced by the one participant
#: that has a writer on each topic of argv[1] (comma separated), read from DCPSPublication by a Cyclone
#: participant of its own process: its domain takes Fast DDS's type information (the monitor's ignores it,
#: ``rclverify.ros.live.dds.COMPATIBILITY``), only invalid try-construct flags allowed.
ANNOUNCED = """\
import json, os, sys, time
from cyclonedds.builtin import BuiltinDataReader, BuiltinTopicDcpsPublication
from cyclonedds.domain import Domain, DomainParticipant
d = int(os.environ["ROS_DOMAIN_ID"])
domain = Domain(d, os.environ["CYCLONEDDS_URI"] + ",<Compatibility><AllowInvalidTryConstruct>true</AllowInvalidTryConstruct></Compatibility>")
dp = DomainParticipant(d)  # kept: a cyclonedds entity is deleted with its last Python reference
reader = BuiltinDataReader(dp, BuiltinTopicDcpsPublication)
topics, seen = set(sys.argv[1].split(",")), {}
until = time.monotonic() + 20
while time.monotonic() < until:
    for s in reader.take(N=256):
        if s.topic_name in topics and s.type_id is not None:
            seen.setdefault(str(s.participant_key), {})[s.topic_name] = repr(s.type_id)
    whole = [ids for ids in seen.values() if set(ids) == topics]
    if whole:
        print(json.dumps(whole[0]))
        break
    time.sleep(0.1)
"""


def _announced_type_ids(env: dict[str, str], topics: set[str]) -> dict[str, str]:
    """DDS topic -> the repr of the type identifier the rclpy talker's (Fast DDS's) writer announces on it."""
    import sys
    r = subprocess.run([sys.executable, "-c", ANNOUNCED, ",".join(sorted(topics))], env=env, capture_output=True,
                       text=True, timeout=60)
    assert r.stdout.strip(), f"no participant announced a writer on each of {sorted(topics)}: {r.stderr[-2000:]}"
    return dict(json.loads(r.stdout))


def test_the_monitor_announces_the_type_identifiers_fast_dds_announces(run: dict[str, Any]) -> None:
    """The monitor's DDS types announce the XTypes identifiers Fast DDS announces for the same ROS 2 types
    (ros/live/dds_xtypes.py): on each of the talker's seven topics of TOPICS (sequences, arrays, bounded and
    nested sequences, a nested fixed array), the identifier of the workspace's struct equals the one the real
    rclpy writer announced, so no Fast DDS participant looks the monitor's types up.  Controls: the
    identifiers cyclonedds' own builder gives (a try-construct flag on every collection element) differ on
    each of them; and a type with a ``wstring`` differs (the binding has no wide string: the monitor reads
    one as a sequence of uint32, so its identifier cannot be Fast DDS's; docs/ros2.md, "Type objects")."""
    from cyclonedds.idl._xt_builder import XTBuilder
    book = TypeBook([run["ws"] / "interfaces"])
    announced = run["announced"]
    assert set(announced) == {f"rt/{t}" for t in [*TOPICS, "ws"]}
    stock_differs = []
    for topic, (ros_type, *_rest) in TOPICS.items():
        struct = book.message(ros_type)
        assert repr(struct.__idl__.get_type_id()) == announced[f"rt/{topic}"], ros_type
        stock = XTBuilder.process_type(struct)[0].complete.typeid_with_size.type_id
        stock_differs.append(repr(stock) != announced[f"rt/{topic}"])
    assert all(stock_differs), dict(zip(TOPICS, stock_differs))
    assert repr(book.message("test_msgs/WStrings").__idl__.get_type_id()) != announced["rt/ws"]


def _counts(record: dict[str, Any]) -> dict[str, tuple[int, int]]:
    return {n["node"]: (n["counts"].get("satisfied", 0), n["counts"].get("violated", 0)) for n in record["nodes"]}


@pytest.mark.parametrize("storage", ["sqlite3", "mcap"])
def test_every_message_of_every_type_is_heard_decoded_and_judged(run: dict[str, Any], storage: str) -> None:
    assert "matched" in run["system"] and "done" in run["system"], run["system"]
    rec, out = run["record"][storage], run["out"][storage]
    assert rec["decode_errors"] == {}, rec["decode_errors"]
    assert {t: q["samples"] for t, q in rec["qos"].items()} == {**{t: N for t in TOPICS}, "mislaid": N,
                                                                "keyed": 0}, rec["qos"]
    assert all(q["other_layout_samples"] == 0 and q["publishers_heard"] == 1 for t, q in rec["qos"].items()
               if t not in ("mislaid", "keyed"))
    assert rec["events"] == N * (len(TOPICS) + 1), rec["events"]
    assert _counts(rec) == EXPECTED, (_counts(rec), out)
    # no vendor noise, and no layout refused but the one that differs
    assert "invalid type object" not in out and "Traceback" not in out, out
    assert [w for w in out.splitlines() if ": warning:" in w] == rec["warnings"], out


@pytest.mark.parametrize("storage", ["sqlite3", "mcap"])
def test_a_publisher_of_the_type_name_with_another_layout_is_named_and_never_heard(run: dict[str, Any],
                                                                                    storage: str) -> None:
    rec = run["record"][storage]
    (warning,) = [w for w in rec["warnings"] if ": mislaid:" in w]  # said before the monitor stops, named by its node or, not yet known, its participant
    assert re.match(r"contracts/types\.rcl:\d+:\d+: warning: mislaid: (node /talker|participant [0-9a-f-]+) "
                    r"publishes test_msgs::msg::dds_::Nested_ with another layout than the contract's type: its ROS 2 "
                    r"type hash RIHS01_[0-9a-f]+\.\.\. differs from the contract's type's RIHS01_", warning), warning
    assert warning.endswith("its messages are not heard"), warning
    mislaid = rec["qos"]["mislaid"]  # the Cyclone publisher heard, every sample of the rclpy one dropped
    assert mislaid["samples"] == N and mislaid["publishers_heard"] == 1 and mislaid["other_layout_samples"] == N
    assert rec["bag"]["messages"] == N * (len(TOPICS) + 1) and "failed" not in rec["bag"], rec["bag"]


@pytest.mark.parametrize("storage", ["sqlite3", "mcap"])
def test_the_bag_is_a_ros2_bag_rosbags_reads(run: dict[str, Any], storage: str) -> None:
    from rosbags.highlevel import AnyReader

    from rclverify.traces.bag import typestore
    bag = run["bags"][storage]
    meta = (bag / "metadata.yaml").read_text()
    # the contract's messages and the run's end, written last (traces/bag_end.py)
    assert f"storage_identifier: {storage}" in meta and "message_count: %d" % (N * (len(TOPICS) + 1) + 1) in meta, meta
    store = typestore([run["ws"] / "interfaces"])
    with AnyReader([bag], default_typestore=store) as reader:
        counts: dict[str, int] = {}
        last: dict[str, Any] = {}
        for conn, _t, raw in reader.messages():
            counts[conn.topic] = counts.get(conn.topic, 0) + 1
            last[conn.topic] = reader.deserialize(raw, conn.msgtype)
    assert counts == {**{f"/{t}": N for t in TOPICS}, "/mislaid": N, "/rclverify/run_end": 1}, counts  # the Cyclone publisher's only
    assert list(last["/arr"].data) == [N - 1.0, 2.0 * (N - 1), 0.5] and last["/arr"].layout.dim[0].label == "x"
    assert list(last["/joints"].name) == ["a", "b"]
    assert last["/nested"].unbounded_sequence_of_unbounded_sequences[1].int32_values.tolist() == [5, N - 1]
    assert list(last["/bounded"].bool_values_default) == [False, True, False]  # the defaults, on the wire
    assert last["/mislaid"].x == N - 1.0


@pytest.mark.parametrize("storage", ["sqlite3", "mcap"])
def test_the_bag_checked_offline_gives_the_live_verdicts(run: dict[str, Any], storage: str,
                                                         capsys: pytest.CaptureFixture[str]) -> None:
    capsys.readouterr()
    rc = main(["monitor", "-w", str(run["ws"]), "--mapping", "mapping.yaml", "--horizon", "1.0", "--json",
               str(run["bags"][storage])])
    got = capsys.readouterr()
    report = json.loads(got.out)
    offline = {e["node"]: (e["counts"].get("satisfied", 0), e["counts"].get("violated", 0))
               for e in report if "counts" in e and e["node"] != "W"}
    assert offline == _counts(run["record"][storage]) == EXPECTED, (offline, got.err)
    assert rc == 1, got.err  # violated guarantees: a failing exit, live and offline


@pytest.mark.parametrize("storage", ["sqlite3", "mcap"])
def test_a_keyed_topic_beside_a_keyless_contract_type_is_named_and_never_green(run: dict[str, Any],
                                                                              storage: str) -> None:
    rec = run["record"][storage]
    (warning,) = [w for w in rec["warnings"] if ": keyed:" in w]
    assert re.match(r"contracts/types\.rcl:\d+:\d+: warning: keyed: (node /talker|participant [0-9a-f-]+) "
                    r"publishes test_msgs::msg::dds_::KeyedLong_ as a keyed topic", warning), warning
    assert rec["qos"]["keyed"]["samples"] == 0 and rec["qos"]["keyed"]["publishers_heard"] == 0
    (node,) = [n for n in rec["nodes"] if n["node"] == "Keyed"]
    assert node["status"] == "pending", node


def test_wide_strings_are_heard_and_decoded_to_their_text(run: dict[str, Any]) -> None:
    rec, out = run["record"]["wide"], run["out"]["wide"]
    assert rec["decode_errors"] == {} and rec["warnings"] == [] and rec["qos"]["ws"]["samples"] == N, (rec, out)
    assert _counts(rec) == {"W": (N - 1, 1)}, (_counts(rec), out)  # the last one is another text
    lines = [e for e in run["wide_log"] if e["topic"] == "ws"]
    assert len(lines) == N and lines[0]["wstring_value"] == "hello", lines[:1]
    last = lines[-1]
    assert last["wstring_value"] == "bye" and last["array_of_wstrings"] == ["a", "\u00fc", str(N - 1)]
    assert last["wstring_value_default3"] == "\u30cf\u30ed\u30fc\u30ef\u30fc\u30eb\u30c9"  # rosidl's default
    assert last["unbounded_sequence_of_wstrings"] == ["x"] * ((N - 1) % 3)


def test_recording_a_wstring_topic_is_refused_before_the_run(run: dict[str, Any],
                                                              capsys: pytest.CaptureFixture[str]) -> None:
    """rosbags cannot describe a wstring, so a bag could not hold the topic: one error, exit 2, no traceback,
    before the monitor joins the domain, and nothing of a bag left behind."""
    capsys.readouterr()
    rc = main(["monitor", "-w", str(run["ws"]), "--live", "--ros2", "--mapping", "mapping.yaml", "--node", "W",
               "--duration", "1", "--record", str(run["tmp"] / "wide.mcap")])
    err = capsys.readouterr().err
    assert rc == 2 and "wide: error: cannot record: topic /ws (test_msgs/WStrings): " in err, err
    assert "a wstring cannot be stored" in err and "Traceback" not in err, err
    assert not (run["tmp"] / "wide").exists()
