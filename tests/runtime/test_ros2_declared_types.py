"""Types from the robot: a publisher's messages decoded in the definition it
declares, with real rclpy nodes on Fast DDS (tests/_ros2.py; docs/ros2.md,
"The publisher's own definition").

ROS 2 Kilted's ``sensor_msgs/Range`` has ``float32 variance``, which the
standard definitions the monitor carries (rosbags' Humble store) lack, so
its type hash differs.  With no ``Range.msg`` in the workspace:

* **live** (``--source rclpy``): a publisher of :data:`N` ranges whose
  ``variance`` cycles through :data:`VARIANCES`; the contract reads
  ``variance`` and guarantees it at most 0.5, so the verdicts are known in
  advance.  Each message is heard, decoded with the publisher's own
  definition (said in a located note) and judged; before, the publisher was
  refused as "another layout" and nothing was heard.
* **recorded**: the run's ``--record`` bag (MCAP) carries the publisher's
  definition and hash, and ``rclverify monitor BAG`` gives the live
  verdicts; the same bag with its definitions taken out (a bag of rosbag2
  before Iron) cannot be read with the monitor's definition, and the error
  says, in one line, how to give the robot's (the control: with that
  ``Range.msg`` in the mapping's ``msg_dirs``, it is read).
* **the hash check**: the description rosidl wrote for the ROS 2 Python,
  and the one the publisher's node serves (``~/get_type_description``,
  asked by the agent as in a run), are accepted; one a node serves in place
  of its own, with ``variance`` as a float64, is refused, since it does not
  hash to the publisher's type hash.
"""
from __future__ import annotations

import copy
import json
import shutil
import signal
import sqlite3
import subprocess
import time
from pathlib import Path
from typing import Any, Iterator

import pytest
from _procs import stop, wait_for, wait_logged
from _ros2 import REPO, rclverify, ros2_env, ros2_python, start_node

from rclverify.cli.commands import main
from rclverify.runtime.dds.type_descriptions import declare
from rclverify.runtime.dds.types import DdsTypeError, Declared, TypeBook, to_fields

N = 40
VARIANCES = (0.25, 0.75, 0.5, 1.0)
VIOLATED = sum(1 for k in range(N) if VARIANCES[k % 4] > 0.5)

RCL = """\
node Ranger {
  inputs( )
  outputs( v : REAL )
  topics( sensor_msgs/Range range matches(out.v) )
  assume( TRUE )
  guarantee( out.v <= 0.5 )
}
"""

PUBLISHER = f"""\
import time
import rclpy
from rclpy.node import Node
from sensor_msgs.msg import Range

rclpy.init()
node = Node("ranger")
pub = node.create_publisher(Range, "range", 50)
print("ready", flush=True)
until = time.monotonic() + 30
while time.monotonic() < until and pub.get_subscription_count() < 1:
    time.sleep(0.05)
time.sleep(1.0)
for k in range({N}):
    m = Range(radiation_type=Range.INFRARED, field_of_view=0.1, min_range=0.05, max_range=4.0, range=1.0 + k,
              variance={VARIANCES}[k % 4])
    m.header.stamp = node.get_clock().now().to_msg()
    pub.publish(m)
    time.sleep(0.02)
print("done", flush=True)
while rclpy.ok():
    time.sleep(0.1)
"""

#: a publisher of Range that spins (rclpy answers its node's type description service in the executor)
SPINNER = """\
import rclpy
from rclpy.node import Node
from sensor_msgs.msg import Range

rclpy.init()
node = Node("ranger")
pub = node.create_publisher(Range, "unheard", 10)
node.create_timer(0.1, lambda: pub.publish(Range(variance=0.5)))
print("ready", flush=True)
try:
    rclpy.spin(node)
except Exception:  # rclpy's own SIGTERM handler shuts the context down
    pass
"""

#: a node that serves its own ``~/get_type_description`` (rcl's is turned off) answering for Range with a
#: description whose ``variance`` is a float64: not the definition it publishes
FORGER = """\
import json, sys, time
import rclpy
from rclpy.node import Node
from rclpy.parameter import Parameter
from sensor_msgs.msg import Range
from type_description_interfaces.msg import Field, FieldType, IndividualTypeDescription, TypeDescription
from type_description_interfaces.srv import GetTypeDescription

rclpy.init()
node = Node("forger", parameter_overrides=[Parameter("start_type_description_service", value=False)])
pub = node.create_publisher(Range, "forged", 10)
doc = json.load(open(sys.argv[1]))["type_description_msg"]

def one(d):
    return IndividualTypeDescription(type_name=d["type_name"], fields=[
        Field(name=f["name"], type=FieldType(**f["type"])) for f in d["fields"]])

def answer(request, response):
    d = json.loads(json.dumps(doc))
    for f in d["type_description"]["fields"]:
        if f["name"] == "variance":
            f["type"]["type_id"] = 11  # float64: another layout than the one published
    response.successful = True
    response.type_description = TypeDescription(type_description=one(d["type_description"]),
        referenced_type_descriptions=[one(r) for r in d["referenced_type_descriptions"]])
    return response

node.create_service(GetTypeDescription, "~/get_type_description", answer)
print("ready", flush=True)
try:
    rclpy.spin(node)
except Exception:  # rclpy's own SIGTERM handler shuts the context down
    pass
"""

#: asks, as the agent does in a run, the type description services of /ranger and /forger (argv: hash)
ASK = """\
import json, sys, time
sys.path.insert(0, sys.argv[1])
import agent

a = agent.Agent()
states = {n: a.ask_service("sensor_msgs/msg/Range", sys.argv[2], n, "/") for n in ("ranger", "forger")}
done = {}
until = time.monotonic() + 30
while len(done) < len(states) and time.monotonic() < until:
    a.ex.spin_once(timeout_sec=0.05)
    for n, s in states.items():
        if n not in done:
            got = a.step_request(s)
            if got is not None:
                done[n] = got
print(json.dumps(done))
a.close()
"""

#: this ROS 2 Python's rosidl description of Range and a Kilted Range serialized by rclpy (variance 0.75)
OWN = """\
import json, sys
sys.path.insert(0, sys.argv[1])
import agent
from rclpy.serialization import serialize_message
from sensor_msgs.msg import Range
found = agent.installed_description("sensor_msgs/msg/Range")
raw = serialize_message(Range(range=2.5, variance=0.75))
print(json.dumps({"hash": found[0], "description": found[1], "from": found[2], "raw": raw.hex()}))
"""


def _ros2(script: str, *args: str) -> Any:
    """Run ``script`` in the ROS 2 Python (agent.py's folder and ``args`` as argv); its JSON output."""
    out = subprocess.run([str(ros2_python()), "-c", script, str(REPO / "src/rclverify/runtime/rclpy_source"),
                          *args], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr[-3000:]
    return json.loads(out.stdout.strip().splitlines()[-1])


@pytest.fixture(scope="module")
def own() -> Any:
    return _ros2(OWN)


def test_the_ros2_python_s_description_is_checked_against_its_hash(own: Any) -> None:
    """rosidl's description of Kilted's Range hashes to the hash rosidl gave it (our REP-2011 hash of the
    fields read from it), and reads ``variance`` from rclpy's bytes; the monitor's own Range (no local
    .msg) has another hash and would silently drop ``variance``."""
    book = TypeBook([])
    mine: Any = book.message("sensor_msgs/Range")
    assert book.type_hash(mine) != own["hash"]  # Humble's definition: the reason a definition is asked for
    decl = declare("sensor_msgs/msg/Range", own["hash"], own["description"], own["from"])
    raw = bytes.fromhex(own["raw"])
    fields = to_fields(mine.deserialize(Declared.of(raw, decl)))
    assert (fields["range"], fields["variance"]) == (2.5, 0.75)
    assert "variance" not in to_fields(mine.deserialize(raw))  # the control: the local layout has none


@pytest.mark.parametrize("change", ["float64", "renamed", "dropped", "other type"])
def test_a_forged_description_is_refused(own: Any, change: str) -> None:
    """A description that does not hash to the publisher's hash is refused, whatever was changed."""
    forged = copy.deepcopy(own["description"])
    fields = forged["type_description"]["fields"]
    if change == "float64":
        fields[-1]["type"]["type_id"] = 11
    elif change == "renamed":
        fields[-1]["name"] = "variances"
    elif change == "dropped":
        forged["referenced_type_descriptions"] = [r for r in forged["referenced_type_descriptions"]
                                                  if r["type_name"] != "std_msgs/msg/Header"]
    else:
        forged["type_description"]["type_name"] = "sensor_msgs/msg/Rangex"
    with pytest.raises(DdsTypeError, match="hashes to|lacks std_msgs/msg/Header|describes sensor_msgs/msg/Rangex"):
        declare("sensor_msgs/msg/Range", own["hash"], forged, "a forger")


def test_the_publisher_s_service_is_asked_and_a_forged_answer_refused(tmp_path: Path, own: Any) -> None:
    """The agent asks a publisher's node for its type description (``~/get_type_description``): the
    real node's answer hashes to its type hash and is accepted; a node serving a description with
    ``variance`` as a float64 is refused by the hash check."""
    env = ros2_env(tmp_path)
    described = Path(own["from"].rsplit("(", 1)[1].rstrip(")"))  # rosidl's Range.json, which the forger alters
    ranger = start_node(tmp_path, "ranger", SPINNER, env)
    forger = start_node(tmp_path, "forger", FORGER.replace("sys.argv[1]", repr(str(described))), env)
    try:
        script = tmp_path / "ask.py"
        script.write_text(ASK)
        out = subprocess.run([str(ros2_python()), str(script), str(REPO / "src/rclverify/runtime/rclpy_source"),
                              own["hash"]], capture_output=True, text=True, timeout=120, env=env)
        assert out.returncode == 0, out.stderr[-3000:]
        got = json.loads(out.stdout.strip().splitlines()[-1])
    finally:
        stop(ranger)
        stop(forger)
    assert [len(got[n]["candidates"]) for n in ("ranger", "forger")] == [1, 1], got
    (honest,), (forged,) = got["ranger"]["candidates"], got["forger"]["candidates"]
    assert honest["from"] == "the type description service /ranger/get_type_description"
    decl = declare("sensor_msgs/msg/Range", own["hash"], honest["description"], honest["from"])
    assert decl.type_hash == own["hash"]
    with pytest.raises(DdsTypeError, match="hashes to RIHS01_.*not to the publisher's " + own["hash"]):
        declare("sensor_msgs/msg/Range", own["hash"], forged["description"], forged["from"])


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, Any]]:
    """The live run through the rclpy source, with no Range.msg in the workspace, recorded to MCAP."""
    py = ros2_python()  # skips, with the reason, without a ROS 2 Python
    tmp = tmp_path_factory.mktemp("declared")
    ws = tmp / "ws"
    (ws / "contracts").mkdir(parents=True)
    (ws / "contracts/r.rcl").write_text(RCL)
    (ws / "contracts/plan.yaml").write_text("contracts: [contracts/r.rcl]\n")
    (ws / "mapping.yaml").write_text("topics:\n  range: {fields: [variance]}\n")
    env = ros2_env(tmp)
    publisher = monitor = None
    try:
        publisher = start_node(tmp, "ranger", PUBLISHER, env)
        monitor = rclverify(["monitor", "-w", str(ws), "--live", "--ros2", "--mapping", "mapping.yaml",
                             "--status", "0", "--duration", "60", "--source", "rclpy", "--ros2-python", str(py),
                             "--record", str(tmp / "run.mcap"), "--log", str(tmp / "live.jsonl"),
                             "--evidence", str(tmp / "live.json")], env, tmp, tmp / "monitor.out")
        wait_for(tmp / "ranger.log", "done", 60)
        # all N messages heard, however loaded the machine (a fixed 1 s before)
        wait_logged(tmp / "live.jsonl", lambda log: sum(x.get("topic") == "range" for x in log) >= N, 30)
        stop(monitor, signal.SIGINT)
        yield {"tmp": tmp, "ws": ws, "out": (tmp / "monitor.out").read_text(),
               "record": json.loads((tmp / "live.json").read_text())}
    finally:
        for p in (monitor, publisher):
            if p is not None:
                stop(p)


def _counts(record: dict[str, Any]) -> tuple[int, int]:
    (node,) = record["nodes"]
    return node["counts"]["satisfied"], node["counts"]["violated"]


def test_live_the_publisher_s_definition_is_heard_and_judged(run: dict[str, Any]) -> None:
    """Every message heard and decoded in Kilted's definition; ``variance`` judged: the verdicts exact."""
    out, rec = run["out"], run["record"]
    assert "another layout" not in out and "not heard" not in out, out
    assert "contracts/r.rcl:4:11: note: range: publishers of sensor_msgs/msg/Range with the type hash " in out, out
    assert "are read in their own definition, from this ROS 2 Python's sensor_msgs" in out, out
    assert rec["qos"]["range"]["samples"] == N and rec["qos"]["range"]["other_layout_samples"] == 0, rec["qos"]
    assert rec["decode_errors"] == {}
    assert _counts(rec) == (N - VIOLATED, VIOLATED)


def test_the_recorded_bag_carries_the_publisher_s_definition(run: dict[str, Any], capsys: Any) -> None:
    """The bag holds Kilted's definition and the publisher's hash; read back offline, the live verdicts."""
    from rosbags.highlevel import AnyReader
    bag = run["tmp"] / "run"
    with AnyReader([bag]) as reader:
        (conn,) = [c for c in reader.connections if c.topic != "/rclverify/run_end"]  # the run's end: traces/bag_end.py
        assert "float32 variance" in conn.msgdef.data
        got = [getattr(reader.deserialize(raw, conn.msgtype), "variance")
               for _c, _t, raw in reader.messages(connections=[conn])]
    assert got == [VARIANCES[k % 4] for k in range(N)]
    code = main(["monitor", "-w", str(run["ws"]), str(bag), "--mapping", "mapping.yaml"])
    out = capsys.readouterr().out
    assert code == 1 and f"Ranger: {N - VIOLATED} satisfied, {VIOLATED} violated" in out, out


def test_a_bag_without_definitions_says_what_to_do(run: dict[str, Any], tmp_path: Path, capsys: Any) -> None:
    """A bag that carries no definition (as rosbag2 wrote before Iron): the monitor's Range does not read
    Kilted's bytes, and the one error line says how to give the robot's; given, the bag is read."""
    from rosbags.highlevel import AnyReader
    from rosbags.rosbag2 import StoragePlugin, Writer
    bag = tmp_path / "old"  # the run's messages in sqlite3, whose definitions can be taken out in place
    with AnyReader([run["tmp"] / "run"]) as reader, Writer(bag, version=8, storage_plugin=StoragePlugin.SQLITE3) as w:
        (conn,) = [c for c in reader.connections if c.topic != "/rclverify/run_end"]  # the run's end: traces/bag_end.py
        out_conn = w.add_connection(conn.topic, conn.msgtype, msgdef=conn.msgdef.data, rihs01=conn.digest)
        for _c, stamp, raw in reader.messages(connections=[conn]):
            w.write(out_conn, stamp, raw)
    (db,) = bag.glob("*.db3")
    with sqlite3.connect(db) as c:
        c.execute("DELETE FROM message_definitions")
        c.execute("UPDATE topics SET type_description_hash = ''")
    code = main(["monitor", "-w", str(run["ws"]), str(bag), "--mapping", "mapping.yaml"])
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1, err
    assert "cannot decode sensor_msgs/msg/Range" in err and "the bag carries no definition of sensor_msgs/msg/Range" \
        in err and "give the recording robot's as DIR/sensor_msgs/msg/Range.msg with DIR in the mapping's msg_dirs" \
        in err, err
    own = _ros2(OWN)
    share = Path(own["from"].rsplit("(", 1)[1].rstrip(")")).parent / "Range.msg"
    (run["ws"] / "robot/sensor_msgs/msg").mkdir(parents=True)
    shutil.copy(share, run["ws"] / "robot/sensor_msgs/msg/Range.msg")
    (run["ws"] / "given.yaml").write_text("msg_dirs: [robot]\ntopics:\n  range: {fields: [variance]}\n")
    code = main(["monitor", "-w", str(run["ws"]), str(bag), "--mapping", "given.yaml"])
    out = capsys.readouterr().out
    assert code == 1 and f"Ranger: {N - VIOLATED} satisfied, {VIOLATED} violated" in out, out


@pytest.mark.parametrize("given", ["genuine", "forged"])
def test_the_bus_reads_a_checked_declaration_and_says_what_to_do_without_one(
        tmp_path: Path, own: Any, monkeypatch: pytest.MonkeyPatch, given: str) -> None:
    """The rclpy source's bus (its agent started in the ROS 2 Python, not started hearing) given the
    graph of a Kilted Range publisher, one of its samples, then the agent's answer: with the genuine
    description the held sample is handed on and decodes ``variance``; with only a forged one (and the
    service unanswered) the sample is dropped and one located line says what was heard, what the
    monitor knows, why the publisher's definition was not had, and what to do."""
    from rclverify.runtime.rclpy_source.bus import RclpyBus
    from rclverify.runtime.rclpy_source.wire import HEADER, sample_frame
    for k, v in ros2_env(tmp_path).items():
        monkeypatch.setenv(k, v)
    book = TypeBook([])
    mine: Any = book.message("sensor_msgs/Range")
    got: list[Any] = []
    said: list[str] = []
    bus = RclpyBus(ros2_python(), lambda tap, raw, info, rns: got.append(raw), said.append, type_hash=book.type_hash)
    try:
        bus.tap("range", "rt/range", mine, "contracts/r.rcl:4:11")
        gid = bytes(range(16))
        bus._json({"what": "graph", "services": {}, "topics": {"/range": [
            {"gid": gid.hex(), "node": "ranger", "ns": "/", "type": "sensor_msgs/msg/Range", "hash": own["hash"],
             "reliable": True, "durability": "volatile"}]}})
        bus._sample(sample_frame(0, 1, 2, 1, gid, bytes.fromhex(own["raw"]))[HEADER.size:])
        assert got == []  # held: its definition is asked for
        description = copy.deepcopy(own["description"])
        if given == "forged":
            description["type_description"]["fields"][-1]["type"]["type_id"] = 11
        bus._json({"what": "description", "type": "sensor_msgs/msg/Range", "hash": own["hash"],
                   "candidates": [{"from": "a forger", "description": description}],
                   "failures": ["the type description service /ranger/get_type_description did not answer within 5 s"]})
    finally:
        bus.close()
    if given == "genuine":
        (raw,) = got
        assert to_fields(mine.deserialize(raw))["variance"] == 0.75
        assert any(": note: range: publishers of sensor_msgs/msg/Range" in s for s in said), said
        return
    assert got == [] and bus.taps[0].dropped == 1
    forged, line = [s for s in said if s.startswith("contracts/r.rcl:4:11: warning: range:")]
    assert forged.startswith("contracts/r.rcl:4:11: warning: range: the type description of sensor_msgs/msg/Range "
                             "from a forger hashes to RIHS01_") and forged.endswith(": not used"), forged
    assert "\n" not in line
    assert line.startswith(f"contracts/r.rcl:4:11: warning: range: node /ranger (publisher {gid.hex()}) publishes "
                           f"sensor_msgs/msg/Range with the type hash {own['hash']}, the monitor's definition of it "
                           f"hashes to {book.type_hash(mine)}, and the publisher's own definition could not be had ("), line
    assert "did not answer within 5 s" in line and "from a forger hashes to RIHS01_" in line, line
    assert line.endswith("its messages are not heard; give the robot's definition as DIR/sensor_msgs/msg/Range.msg "
                         "with --interfaces DIR (or the mapping's msg_dirs)"), line


def test_the_agent_asks_the_node_when_its_own_description_is_another(tmp_path: Path, own: Any,
                                                                     monkeypatch: pytest.MonkeyPatch) -> None:
    """A publisher's hash that the ROS 2 Python's own description does not have (a robot of another
    distribution): the agent asks the node's type description service, and the bus checks the answer.
    rcl's service of a real node answers that it has no such type; the forger's description, for any
    hash, is refused by the hash check; the line of each gives every reason, source by source."""
    from rclverify.runtime.rclpy_source.bus import RclpyBus
    env = ros2_env(tmp_path)
    for k, v in env.items():
        monkeypatch.setenv(k, v)
    described = Path(own["from"].rsplit("(", 1)[1].rstrip(")"))  # rosidl's Range.json, which the forger alters
    nodes = [start_node(tmp_path, "ranger", SPINNER, env),
             start_node(tmp_path, "forger", FORGER.replace("sys.argv[1]", repr(str(described))), env)]
    other = "RIHS01_" + "ab" * 32  # a Range of another distribution
    said: list[str] = []
    bus = RclpyBus(ros2_python(), lambda *a: None, said.append)
    try:
        bus.start()
        for node in ("ranger", "forger"):
            bus._send({"op": "describe", "type": "sensor_msgs/msg/Range", "hash": other, "node": node, "ns": "/"})
            bus._asking.add(("sensor_msgs/msg/Range", other))
            until = time.monotonic() + 30
            while ("sensor_msgs/msg/Range", other) in bus._asking and time.monotonic() < until:
                time.sleep(0.05)
            assert bus._declared[("sensor_msgs/msg/Range", other)] is None
            why = bus._why[("sensor_msgs/msg/Range", other)]
            assert f"this ROS 2 Python's sensor_msgs ({described}) has the type hash {own['hash']}" in why, why
            if node == "ranger":
                assert "the type description service /ranger/get_type_description answered: Type not currently in use " \
                    "by this node" in why, why
            else:
                assert "from the type description service /forger/get_type_description hashes to RIHS01_" in why, why
                assert f"not to the publisher's {other}: not used" in why, why
            del bus._declared[("sensor_msgs/msg/Range", other)]
    finally:
        bus.stop()
        for p in nodes:
            stop(p)


def test_the_dds_source_says_what_to_do(tmp_path: Path) -> None:
    """The DDS source does not ask for the publisher's definition: the publisher is refused, and the one
    warning gives both hashes and what to do (the robot's .msg with --interfaces, or the rclpy source)."""
    ros2_python()  # skips, with the reason, without a ROS 2 Python
    ws = tmp_path / "ws"
    (ws / "contracts").mkdir(parents=True)
    (ws / "contracts/r.rcl").write_text(RCL)
    (ws / "contracts/plan.yaml").write_text("contracts: [contracts/r.rcl]\n")
    (ws / "mapping.yaml").write_text("topics:\n  range: {fields: [variance]}\n")
    env = ros2_env(tmp_path)
    publisher = start_node(tmp_path, "ranger", SPINNER.replace('"unheard"', '"range"'), env)
    monitor = None
    try:
        monitor = rclverify(["monitor", "-w", str(ws), "--live", "--ros2", "--mapping", "mapping.yaml", "--status",
                             "0", "--duration", "60", "--source", "dds", "--evidence", str(tmp_path / "live.json")],
                            env, tmp_path, tmp_path / "monitor.out")
        # stopped once it named the publisher (its whole line), not when a fixed duration ran out
        wait_for(tmp_path / "monitor.out", "its messages are not heard", 60)
        stop(monitor, signal.SIGINT)
    finally:
        stop(publisher)
        if monitor is not None:
            stop(monitor)
    warnings = json.loads((tmp_path / "live.json").read_text())["warnings"]
    (line,) = [w for w in warnings if ": warning: range:" in w]
    assert "publishes sensor_msgs::msg::dds_::Range_ with another layout than the contract's type: its ROS 2 type " \
        "hash RIHS01_b42b" in line, line
    assert "give the robot's definition as DIR/sensor_msgs/msg/Range.msg with --interfaces DIR, or hear it with " \
        "--source rclpy, which reads the publisher's own definition; its messages are not heard" in line, line


#: a type_description_interfaces/FieldType serialized by rclpy (a type rosbags' Humble store lacks)
FIELD_TYPE = """\
from rclpy.serialization import serialize_message
from type_description_interfaces.msg import FieldType
print(serialize_message(FieldType(type_id=FieldType.FIELD_TYPE_FLOAT_ARRAY, capacity=7, nested_type_name="a/b")).hex())
"""


def test_a_type_with_no_local_definition_is_defined_from_the_ros2_python(tmp_path: Path) -> None:
    """A contract type the monitor has no definition of: without one, the error names the file to give
    and the option; the ROS 2 Python's own description (the agent's --describe, checked against rosidl's
    hash) defines it, nested types included, and rclpy's bytes decode with it."""
    from rclverify.runtime.rclpy_source.describe import installed_declarations
    name = "type_description_interfaces/msg/FieldType"
    book = TypeBook([])
    with pytest.raises(DdsTypeError, match=f"message type {name} is neither in the workspace's interface files nor "
                       "a standard type: give its definition as DIR/type_description_interfaces/msg/FieldType.msg "
                       r"with --interfaces DIR \(or the mapping's msg_dirs\)"):
        book.message(name)
    found = installed_declarations(ros2_python(), [name, "no_such_msgs/msg/Nothing"])
    assert list(found) == [name]
    assert book.add_declaration(found[name]) == [name]
    struct: Any = book.message(name)
    assert book.type_hash(struct) == found[name].type_hash
    out = subprocess.run([str(ros2_python()), "-c", FIELD_TYPE], capture_output=True, text=True, timeout=60, check=True)
    fields = to_fields(struct.deserialize(bytes.fromhex(out.stdout.strip())))
    assert fields == {"type_id": 58, "capacity": 7, "string_capacity": 0, "nested_type_name": "a/b"}
