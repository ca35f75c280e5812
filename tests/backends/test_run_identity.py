"""A run is its content (docs/statistics.md, "A run's identity"): one run written as the live monitor's
log, an sqlite3 bag and an MCAP bag, reformatted, reordered, or with its topics written with or without
their leading ``/``, has one identity (``run_digest``); two different runs never share one.

The oracle: random runs made here as lists of ROS 2 messages (their CDR bytes, as the middleware
carries them, and the times the monitor received them).  Each run's log is written by the live
monitor's own :class:`~rclverify.runtime.live.LiveRun`, fed the fields the live ROS 2 decoder gives
(:func:`~rclverify.runtime.dds.types.to_fields` of the bytes) at the receipt times, as the live run's
engine thread feeds it; its bags hold the same bytes at the same times, written by ``rosbags`` as the
``--record`` bag is."""
from __future__ import annotations

import json
import math
import random
from pathlib import Path
from typing import Any, Callable

import pytest

from rclverify.backends.monitors.runset import run_digest
from rclverify.records.statistics import count_runs

#: A node whose contract names every topic of the runs below, so the live engine logs each of them.
RCL = """
node Watch {
  inputs( level : REAL, flag : BOOL, charge : REAL, x : REAL, blob : INTEGER, ping : BOOL )
  outputs( ok : BOOL )
  topics( std_msgs/Float64 level matches(in.level), std_msgs/Bool flag matches(in.flag),
          sensor_msgs/BatteryState battery matches(in.charge), geometry_msgs/PoseStamped pose matches(in.x),
          std_msgs/UInt8MultiArray blob matches(in.blob), std_msgs/Empty ping matches(in.ping),
          std_msgs/Bool ok matches(out.ok) )
  assume( TRUE )
  guarantee( out.ok -> in.level >= 0 )
}
"""
TYPES = {"level": "std_msgs/msg/Float64", "flag": "std_msgs/msg/Bool", "battery": "sensor_msgs/msg/BatteryState",
         "pose": "geometry_msgs/msg/PoseStamped", "blob": "std_msgs/msg/UInt8MultiArray", "ping": "std_msgs/msg/Empty",
         "ok": "std_msgs/msg/Bool"}
STAMPED = ("battery", "pose")
#: One run: (topic, receipt time in ns, CDR bytes) in receipt order.
Run = list[tuple[str, int, bytes]]
N_RUNS = 5


@pytest.fixture(scope="module")
def store() -> Any:
    pytest.importorskip("rosbags")
    from rclverify.traces.bag import typestore
    return typestore([])


def _message(store: Any, topic: str, rng: random.Random, stamp_ns: int) -> Any:
    """A random message of ``topic``'s type (a stamped one stamped ``stamp_ns``)."""
    import numpy as np
    T = store.types
    stamp = T["builtin_interfaces/msg/Time"](sec=stamp_ns // 10**9, nanosec=stamp_ns % 10**9)
    header = T["std_msgs/msg/Header"](stamp=stamp, frame_id=rng.choice(["base", "map", ""]))
    f32 = lambda: float(np.float32(rng.uniform(-50, 50)))  # noqa: E731 - a float32 value, as the wire holds it
    if topic == "level":  # integral, NaN and infinite values too: the log writes those its own way
        return T["std_msgs/msg/Float64"](data=rng.choice([rng.uniform(-5, 5), 2.0, -0.0, math.nan, math.inf, 1e300]))
    if topic in ("flag", "ok"):
        return T["std_msgs/msg/Bool"](data=rng.random() < 0.5)
    if topic == "battery":
        cells = np.array([f32() for _ in range(rng.randrange(4))], dtype=np.float32)
        return T["sensor_msgs/msg/BatteryState"](
            header=header, voltage=f32(), temperature=math.nan, current=f32(), charge=f32(), capacity=f32(),
            design_capacity=3.0, percentage=rng.random(), power_supply_status=rng.randrange(5),
            power_supply_health=rng.randrange(9), power_supply_technology=2, present=True, cell_voltage=cells,
            cell_temperature=np.array([], dtype=np.float32), location=rng.choice(["left", "right"]),
            serial_number=f"SN{rng.randrange(10**6)}")
    if topic == "pose":
        p = T["geometry_msgs/msg/Point"](x=rng.uniform(-9, 9), y=rng.uniform(-9, 9), z=0.0)
        q = T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=rng.uniform(-1, 1), w=1.0)
        return T["geometry_msgs/msg/PoseStamped"](header=header, pose=T["geometry_msgs/msg/Pose"](position=p, orientation=q))
    if topic == "blob":
        n = rng.randrange(1, 6)
        dim = T["std_msgs/msg/MultiArrayDimension"](label="row", size=n, stride=n)
        return T["std_msgs/msg/UInt8MultiArray"](layout=T["std_msgs/msg/MultiArrayLayout"](dim=[dim], data_offset=0),
                                                 data=np.array([rng.randrange(256) for _ in range(n)], dtype=np.uint8))
    return T["std_msgs/msg/Empty"]()


def _random_run(store: Any, seed: int, size: int = 30) -> Run:
    """``size`` random messages on random topics; receipt times a few ms apart from today's epoch, a
    stamped message's stamp up to 5 ms before its receipt (its source's clock)."""
    rng = random.Random(seed)
    t = 1_795_737_269_000_000_000 + rng.randrange(10**12)
    run: Run = []
    for _ in range(size):
        t += rng.randrange(1, 20_000_000)
        topic = rng.choice(list(TYPES))
        msg = _message(store, topic, rng, t - rng.randrange(5_000_000))
        run.append((topic, t, bytes(store.serialize_cdr(msg, TYPES[topic]))))
    return run


def _bag(store: Any, path: Path, run: Run, storage: str, slash: str = "/", types: dict[str, str] = TYPES) -> str:
    """``run`` as a ROS 2 bag directory ``path`` (``sqlite3`` or ``mcap``); topics named ``slash + topic``."""
    from rosbags.rosbag2 import StoragePlugin, Writer
    plugin, version = (StoragePlugin.MCAP, 9) if storage == "mcap" else (StoragePlugin.SQLITE3, 8)
    with Writer(path, version=version, storage_plugin=plugin) as w:
        conns: dict[str, Any] = {}
        for topic, ns, raw in run:
            if topic not in conns:
                conns[topic] = w.add_connection(slash + topic, types[topic], typestore=store)
            w.write(conns[topic], ns, raw)
    return path.name


def _live_log(path: Path, run: Run, rcl: str = RCL, types: dict[str, str] = TYPES) -> str:
    """``run`` as the live monitor logs it: each message decoded as the live ROS 2 source decodes it and
    pushed at its receipt time (``ns / 1e9``), the timer ticking before each one, as the engine thread does."""
    from rclverify.backends.monitors.config import load_mapping
    from rclverify.lang.parser import parse_text
    from rclverify.lang.typecheck import check
    from rclverify.runtime.dds.types import TypeBook, to_fields
    from rclverify.runtime.live import LiveRun
    checked = check([parse_text(rcl, "w.rcl")])
    cfg = load_mapping(path.parent, None)
    book = TypeBook([])
    live = LiveRun(checked, list(checked.nodes.values()), cfg.rules, cfg.horizon, path)
    for topic, ns, raw in run:
        live.tick(ns / 1e9)
        live.push(topic, to_fields(book.struct(types[topic]).deserialize(raw)), ns / 1e9)
    live.tick(run[-1][1] / 1e9 + 10.0)
    live.stop()
    return path.name


def _lines(path: Path) -> list[dict[str, Any]]:
    return [json.loads(line) for line in path.read_text().splitlines() if line.strip()]


def _write(path: Path, rows: list[dict[str, Any]], dump: Callable[[Any], str] = json.dumps) -> str:
    path.write_text("".join(dump(r) + "\n" for r in rows))
    return path.name


def _by_value(v: Any) -> Any:
    """``v`` with each integral float written as an integer (``2.0`` -> ``2``): the same number."""
    if isinstance(v, float) and v.is_integer():
        return int(v)
    if isinstance(v, dict):
        return {k: _by_value(x) for k, x in v.items()}
    if isinstance(v, list):
        return [_by_value(x) for x in v]
    return v


def _forms(store: Any, d: Path, run: Run, seed: int) -> list[str]:
    """Every form of ``run`` written under ``d``: the live log, the bags, and the log's rewritings."""
    d.mkdir()
    log = _live_log(d / "live.jsonl", run)
    rows = _lines(d / log)
    assert any(r["topic"] == "rclverify/verdict" for r in rows)  # the live log holds the monitor's verdicts
    rng = random.Random(seed)
    shuffled = rows[:]
    rng.shuffle(shuffled)
    mine = [r for r in rows if not r["topic"].startswith("rclverify/")]
    return [log, _bag(store, d / "sq", run, "sqlite3"), _bag(store, d / "mc", run, "mcap"),
            _bag(store, d / "bare", run, "mcap", slash=""),
            _write(d / "reformatted.jsonl", [_by_value(dict(reversed(list(r.items())))) for r in rows],
                   lambda r: "  " + json.dumps(r, separators=(" ,\t", " : ")) + "\n"),
            _write(d / "reordered.jsonl", shuffled),
            _write(d / "slashed.jsonl", [{**r, "topic": "/" + r["topic"]} for r in rows]),
            _write(d / "messages_only.jsonl", mine)]  # a ROSMonitoring log of the same messages, no verdicts


def test_every_form_of_a_run_is_one_run_and_different_runs_are_different(store: Any, tmp_path: Path) -> None:
    identities = []
    for k in range(N_RUNS):
        d = tmp_path / f"run{k}"
        forms = _forms(store, d, _random_run(store, k), k)
        got = {f: run_digest(d, f) for f in forms}
        assert len(set(got.values())) == 1, got
        assert all(len(v) == 64 for v in got.values())  # read as runs, not by their bytes
        identities.append(got[forms[0]])
    assert len(set(identities)) == N_RUNS


def test_the_bundled_live_recordings_and_their_bags_are_one_run_each(store: Any) -> None:
    """``examples/ros2_robot``: each run ``rclverify monitor --live --ros2 --record`` recorded over
    rclpy nodes on Fast DDS, as its log and its MCAP bag (which also hold the run's calls)."""
    base = Path(__file__).resolve().parents[2] / "examples" / "ros2_robot"
    pairs = [(base / "runs", "robot.jsonl", "robot")] + [
        (d, "run.jsonl", "run") for d in sorted((base / "defects").iterdir()) if (d / "run.jsonl").is_file()]
    assert len(pairs) >= 6
    got = [(run_digest(d, log), run_digest(d, bag)) for d, log, bag in pairs]
    assert all(a == b for a, b in got), [p[0].name for p, (a, b) in zip(pairs, got) if a != b]
    assert len({a for a, _ in got}) == len(pairs)


def test_a_changed_value_time_or_message_is_another_run(store: Any, tmp_path: Path) -> None:
    run = _random_run(store, 99, size=40)
    plain = next(i for i, (t, _, _) in enumerate(run) if t not in STAMPED)
    stamped = next(i for i, (t, _, _) in enumerate(run) if t in STAMPED)
    (tmp_path / "base").mkdir()
    base = run_digest(tmp_path / "base", _live_log(tmp_path / "base" / "live.jsonl", run))
    assert base == run_digest(tmp_path / "base", _bag(store, tmp_path / "base" / "sq", run, "sqlite3"))
    rows = _lines(tmp_path / "base" / "live.jsonl")
    messages = [i for i, r in enumerate(rows) if not r["topic"].startswith("rclverify/")]
    at_plain = next(i for i in messages if rows[i]["topic"] == run[plain][0] and
                    rows[i]["time"] == run[plain][1] / 1e9)

    def log(name: str, edit: Callable[[list[dict[str, Any]]], None]) -> str:
        changed = json.loads(json.dumps(rows))
        edit(changed)
        return run_digest(tmp_path, _write(tmp_path / f"{name}.jsonl", changed))

    def bag(name: str, changed: Run) -> str:
        return run_digest(tmp_path, _bag(store, tmp_path / name, changed, "mcap"))

    def later(rs: list[dict[str, Any]]) -> None:
        rs[at_plain]["time"] = math.nextafter(rs[at_plain]["time"], math.inf)

    def new_value(rs: list[dict[str, Any]]) -> None:
        r = next(rs[i] for i in messages if rs[i]["topic"] in ("battery", "pose"))
        if r["topic"] == "battery":
            r["percentage"] += 0.25
        else:
            r["pose"]["position"]["x"] += 0.25

    own = store.deserialize_cdr(run[stamped][2], TYPES[run[stamped][0]]).header.stamp

    def new_stamp(rs: list[dict[str, Any]]) -> None:  # the message _restamped changes in the bag
        stamp = next(rs[i] for i in messages if rs[i]["topic"] == run[stamped][0] and
                     rs[i]["header"]["stamp"] == {"sec": own.sec, "nanosec": own.nanosec})["header"]["stamp"]
        stamp["nanosec"] = stamp["nanosec"] + 1 if stamp["nanosec"] < 999_999_999 else 0

    def dropped(rs: list[dict[str, Any]]) -> None:
        del rs[messages[-1]]

    def twice(rs: list[dict[str, Any]]) -> None:
        rs.append(rs[messages[0]])
    assert log("same", lambda rs: None) == base  # the control: the log rewritten unchanged is the run
    others = {
        "a log's time moved by one float step": log("time", later),
        "a log's value changed": log("value", new_value),
        "a log's field added": log("field", lambda rs: rs[messages[0]].update(extra=1)),
        "a log's header stamp moved by 1 ns": log("stamp", new_stamp),
        "a log's message dropped": log("dropped", dropped),
        "a log's message given twice": log("twice", twice),
        "a bag's time moved by 1 us": bag("later", [(t, ns + 1000 * (i == plain), raw) for i, (t, ns, raw) in enumerate(run)]),
        "a bag's header stamp moved by 1 ns": bag("bytes", [(t, ns, raw if i != stamped else _restamped(store, t, raw))
                                                            for i, (t, ns, raw) in enumerate(run)]),
        "a bag's topic renamed": bag("renamed", [("flag" if t == "ok" else "ok" if t == "flag" else t, ns, raw)
                                                 for t, ns, raw in run]),
    }
    assert base not in others.values(), [k for k, v in others.items() if v == base]
    # one change made in the log and in the bag is one run again; the other changes are each their own
    assert others.pop("a log's header stamp moved by 1 ns") == others["a bag's header stamp moved by 1 ns"]
    assert len(set(others.values())) == len(others)


def _restamped(store: Any, topic: str, raw: bytes) -> bytes:
    """``raw`` (a stamped message of ``topic``) with its header stamp one nanosecond later."""
    msg = store.deserialize_cdr(raw, TYPES[topic])
    stamp = msg.header.stamp
    msg.header.stamp = type(stamp)(sec=stamp.sec, nanosec=stamp.nanosec + 1 if stamp.nanosec < 999_999_999 else 0)
    return bytes(store.serialize_cdr(msg, TYPES[topic]))


def test_the_copies_count_as_duplicates(store: Any, tmp_path: Path) -> None:
    rows = []
    for k in range(N_RUNS):
        d = tmp_path / f"run{k}"
        for f in _forms(store, d, _random_run(store, 100 + k), k):
            rows.append({"trace": f"{d.name}/{f}", "sha256": run_digest(d, f), "status": "discharged",
                         "answers": 3, "violations": 0, "inconclusive": 0, "seconds": 1.0})
    c = count_runs(rows)
    assert (c["runs"], c["duplicates"], c["answers"]) == (N_RUNS, len(rows) - N_RUNS, 3 * N_RUNS)


def test_a_copy_with_every_time_shifted_is_the_same_run(tmp_path: Path) -> None:
    """Times are relative to the run's first (a receipt time to the first receipt time, a header stamp
    to the first stamp): a copy re-timed by one offset is no new trial; a changed value or a changed
    interval is."""
    def rows(offset_s: int, offset_ns: int, level: float = 1.5, gap: str = "0.25") -> list[dict[str, Any]]:
        out: list[dict[str, Any]] = []
        for j in range(4):
            out.append({"topic": "level", "time": float(f"{1700000000 + offset_s + j}.{j}25"), "data": level + j})
            ns = 1_700_000_000_000_000_000 + offset_ns + j * 100_000_007
            out.append({"topic": "battery", "time": float(f"{12 + offset_s + j}.{gap[2:]}"), "percentage": 0.5,
                        "header": {"stamp": {"sec": ns // 10**9, "nanosec": ns % 10**9}, "frame_id": "base"}})
        return out
    base = run_digest(tmp_path, _write(tmp_path / "base.jsonl", rows(0, 0)))
    shifted = run_digest(tmp_path, _write(tmp_path / "shifted.jsonl", rows(3600, 3_600_000_000_123)))
    assert shifted == base
    # the controls: a read value changed, or one interval changed, is another run
    assert run_digest(tmp_path, _write(tmp_path / "value.jsonl", rows(3600, 3_600_000_000_123, level=2.5))) != base
    moved = rows(3600, 3_600_000_000_123)
    moved[2]["time"] = float(f"{1700003601}.126")
    assert run_digest(tmp_path, _write(tmp_path / "moved.jsonl", moved)) != base
    stamp = rows(0, 0)
    stamp[3]["header"]["stamp"]["nanosec"] += 1
    assert run_digest(tmp_path, _write(tmp_path / "stamp.jsonl", stamp)) != base


def test_a_file_neither_reader_takes_is_its_bytes(tmp_path: Path) -> None:
    (tmp_path / "a.jsonl").write_text("not json\n")
    (tmp_path / "b.jsonl").write_text("not json \n")
    (tmp_path / "c.jsonl").write_text("not json\n")
    assert run_digest(tmp_path, "a.jsonl") == run_digest(tmp_path, "c.jsonl") != run_digest(tmp_path, "b.jsonl")
    # a log of nothing but rclverify's own lines holds no message: its bytes too
    (tmp_path / "v.jsonl").write_text('{"topic": "rclverify/verdict", "time": 1.0, "verdict": {}}\n')
    (tmp_path / "w.jsonl").write_text('{"topic": "rclverify/verdict", "time": 2.0, "verdict": {}}\n')
    assert run_digest(tmp_path, "v.jsonl") != run_digest(tmp_path, "w.jsonl")


def test_lines_that_are_no_message_are_skipped_and_calls_alone_identify_a_run(tmp_path: Path) -> None:
    msg = '{"topic": "x", "time": 1.5, "data": 2}\n'
    (tmp_path / "a.jsonl").write_text(msg)
    (tmp_path / "b.jsonl").write_text('{"kind": "summary", "results": [], "false": 0}\n' + msg +
                                      '{"topic": "rclverify/run", "time": 1.0, "kind": "run", "source": "dds"}\n')
    assert run_digest(tmp_path, "a.jsonl") == run_digest(tmp_path, "b.jsonl")
    call = '{"topic": "rclverify/call", "time": 2.0, "kind": "call", "link": "estop", "part": "%s"}\n'
    (tmp_path / "c1.jsonl").write_text(call % "request" + call % "response")
    (tmp_path / "c2.jsonl").write_text(call % "response" + "\n" + call % "request")
    (tmp_path / "c3.jsonl").write_text(call % "request" + call % "request")
    assert run_digest(tmp_path, "c1.jsonl") == run_digest(tmp_path, "c2.jsonl") != run_digest(tmp_path, "c3.jsonl")
    # calls beside messages: the messages are the run (a bag holds the calls in another form)
    (tmp_path / "m.jsonl").write_text(msg + call % "request")
    assert run_digest(tmp_path, "m.jsonl") == run_digest(tmp_path, "a.jsonl")


CLAMP = """
node Clamp {
  inputs( a : REAL )
  outputs( x : REAL )
  topics( std_msgs/Float64 a matches(in.a), std_msgs/Float64 x matches(out.x) )
  assume( in.a >= 0 )
  guarantee( out.x <= 30 )
}
"""


def _clamp_run(store: Any, k: int) -> Run:
    """Two questions of Clamp and their clean answers; ``k`` makes the run its own."""
    f64 = store.types["std_msgs/msg/Float64"]
    t0 = 1_795_000_000_000_000_000 + k * 10**10
    run: Run = []
    for j in range(2):
        for topic, dt, v in (("a", 0, float(j + k)), ("x", 10_000_000, 20.0 - k / 7)):
            run.append((topic, t0 + j * 100_000_000 + dt, bytes(store.serialize_cdr(f64(data=v), "std_msgs/msg/Float64"))))
    return run


def _runset(root: Path, traces: list[str], target: str) -> Any:
    """The evidence of the run-set obligation of Clamp's one monitors entry over ``traces``."""
    from rclverify.backends.monitors.backend import MonitorsBackend
    from rclverify.stages.workspace import Workspace
    entry = {"backend": "monitors", "traces": traces, "environment": "lab", "target": target}
    (root / "contracts/plan.yaml").write_text(json.dumps({"contracts": ["contracts/sys.rcl"],
                                                         "nodes": {"Clamp": {"evidence": [entry]}}}))
    ws = Workspace(root)
    target_ = ws.target("Clamp", 0)
    backend = MonitorsBackend()
    (ob,) = [o for o in backend.export(target_) if o.data.get("run_set") is not None]
    return backend.run(ob, target_)


def test_a_live_log_and_its_bag_named_together_count_one_run(store: Any, tmp_path: Path) -> None:
    (tmp_path / "contracts").mkdir()
    (tmp_path / "contracts/sys.rcl").write_text(CLAMP)
    (tmp_path / "runs").mkdir()
    types = {"a": "std_msgs/msg/Float64", "x": "std_msgs/msg/Float64"}
    traces = []
    for k in range(3):
        run = _clamp_run(store, k)
        traces += [f"runs/{_live_log(tmp_path / 'runs' / f'live{k}.jsonl', run, CLAMP, types)}",
                   f"runs/{_bag(store, tmp_path / 'runs' / f'bag{k}', run, 'sqlite3', types=types)}"]
    ev = _runset(tmp_path, traces, "violation probability <= 1e-1 at 95 % per answer")
    st = ev.details["statistics"]
    assert {r["recorded"] for r in st["runs"]} == {"live", "bag"}
    assert all(r["answers"] == 2 for r in st["runs"])  # each form judged on its own: two answers
    assert (st["counts"]["runs"], st["counts"]["duplicates"], st["counts"]["answers"]) == (3, 3, 6)


def test_thirty_runs_and_their_slashed_copies_are_thirty_runs(tmp_path: Path) -> None:
    (tmp_path / "contracts").mkdir()
    (tmp_path / "contracts/sys.rcl").write_text(CLAMP)
    (tmp_path / "runs").mkdir()
    traces = []
    for k in range(30):
        rows = [{"topic": t, "time": 1000.0 + k + 0.1 * j + dt, "data": v}
                for j in range(2) for t, dt, v in (("a", 0.0, float(j + k)), ("x", 0.01, 20.0))]
        traces.append("runs/" + _write(tmp_path / "runs" / f"run{k:02d}.jsonl", rows))
        traces.append("runs/" + _write(tmp_path / "runs" / f"copy{k:02d}.jsonl",
                                       [{**r, "topic": "/" + r["topic"]} for r in rows]))
    # 59 clean runs meet 5 % at 95 %; 30 do not, however often each is named
    ev = _runset(tmp_path, traces, "violation probability <= 5 % at 95 % per run")
    c = ev.details["statistics"]["counts"]
    assert (c["runs"], c["duplicates"]) == (30, 30)
    assert ev.status != "discharged" and "30 run file(s) repeat a run already counted" in ev.explanation
