"""Trace readers (ROSMonitoring JSON lines, ROS 2 bags) and the message-to-RCL mapping rules."""
from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from rclverify.lang import types as T
from rclverify.traces import TraceError, read_trace
from rclverify.traces.mapping import MappingError, TopicRule, map_value
from rclverify.semantics.values import FiniteFunction, Term

REPO = Path(__file__).resolve().parents[2]
TRACES = REPO / "backends" / "monitors" / "traces"
MSG = [REPO / "backends" / "monitors" / "msg"]


def test_log_and_bag_carry_the_same_events() -> None:
    log = list(read_trace(TRACES / "nominal.jsonl"))
    bag = list(read_trace(TRACES / "nominal_bag", MSG))
    assert len(log) == len(bag) > 50
    for a, b in zip(log, bag):
        assert (a.index, a.topic) == (b.index, b.topic)
        assert a.time == pytest.approx(b.time)
        assert dict(a.fields) == pytest.approx(dict(b.fields))


def test_malformed_log_line_is_located_and_earlier_events_are_kept(tmp_path: Path) -> None:
    lines = (TRACES / "nominal.jsonl").read_text().splitlines()
    bad = tmp_path / "bad.jsonl"
    bad.write_text("\n".join(lines[:5] + ['{"topic": "r", "time": 1.0, "value": ', *lines[5:]]) + "\n")
    seen = []
    with pytest.raises(TraceError) as exc:
        for ev in read_trace(bad):
            seen.append(ev)
    assert str(exc.value).startswith(f"{bad}:6:")
    assert "error: malformed JSON" in str(exc.value)
    assert len(seen) == 5


def test_event_without_time_is_rejected(tmp_path: Path) -> None:
    bad = tmp_path / "bad.jsonl"
    bad.write_text(json.dumps({"topic": "r", "value": 1.0}) + "\n")
    with pytest.raises(TraceError, match=r"bad.jsonl:1:1: error: the event has no numeric 'time'"):
        list(read_trace(bad))


def test_truncated_bag_is_located(tmp_path: Path) -> None:
    bag = tmp_path / "cut_bag"
    shutil.copytree(TRACES / "nominal_bag", bag)
    db = bag / "nominal_bag.db3"
    data = db.read_bytes()
    db.write_bytes(data[: len(data) // 3])
    seen = []
    with pytest.raises(TraceError) as exc:
        for ev in read_trace(bag, MSG):
            seen.append(ev)
    assert str(exc.value).startswith(f"{bag}: message {len(seen)}")
    assert "error:" in str(exc.value)


def test_missing_trace_is_an_error(tmp_path: Path) -> None:
    with pytest.raises(TraceError, match="no such trace"):
        read_trace(tmp_path / "nope.jsonl")


# -- mapping rules (paper lines 535-548) --------------------------------------

REAL, NAT, BOOL = T.Scalar("REAL"), T.Scalar("NATURAL"), T.Scalar("BOOL")
RAD = T.EnumT("RadStat", ("red", "orange", "green"))
CMD = T.DataT("CommandSet", (("move", (REAL, REAL)), ("inspect", (NAT,))))
MSGF = {"command": "inspect", "posx": 1.5, "posy": 2.0, "id": 3, "level": "red", "value": 7.5}


def test_scalar_rule_takes_the_first_field_of_the_type() -> None:
    assert map_value(REAL, MSGF, TopicRule(("value",)), None) == 7.5
    assert map_value(NAT, MSGF, TopicRule(), None) == 3
    with pytest.raises(MappingError):
        map_value(BOOL, MSGF, TopicRule(), None)


def test_collection_rule_keeps_unknown_strings_for_the_formulas_to_see() -> None:
    assert map_value(RAD, MSGF, TopicRule(("level",)), None) == "red"
    assert map_value(RAD, {"level": "purple"}, TopicRule(("level",)), None) == "purple"


def test_function_rule_accumulates_or_replaces() -> None:
    at = T.FuncT((REAL, REAL), BOOL)
    f1 = map_value(at, {"posx": 1.0, "posy": 2.0}, TopicRule(), None)
    f2 = map_value(at, {"posx": 3.0, "posy": 4.0}, TopicRule(), f1)
    assert f2(1.0, 2.0) is True and f2(3.0, 4.0) is True and f2(0.0, 0.0) is False
    f3 = map_value(at, {"posx": 3.0, "posy": 4.0}, TopicRule(update="replace"), f1)
    assert f3(1.0, 2.0) is False and f3(3.0, 4.0) is True
    wayp = T.FuncT((REAL, REAL), NAT)
    w = map_value(wayp, {"posx": 1.0, "posy": 2.0, "id": 4}, TopicRule(), None)
    assert isinstance(w, FiniteFunction) and w(1.0, 2.0) == 4


def test_constructor_rule_names_the_constructor_then_takes_arguments_by_type() -> None:
    rule = TopicRule(("command", "posx", "posy", "id"))
    assert map_value(CMD, MSGF, rule, None) == Term("inspect", (3,))
    assert map_value(CMD, {**MSGF, "command": "move"}, rule, None) == Term("move", (1.5, 2.0))
    with pytest.raises(MappingError, match="not a constructor"):
        map_value(CMD, {**MSGF, "command": "fly"}, rule, None)


@pytest.mark.parametrize("form", ["mcap", "ros1"])
def test_mcap_and_ros1_bags_carry_the_same_events(tmp_path: Path, form: str) -> None:
    import importlib.util
    spec = importlib.util.spec_from_file_location("make_traces", REPO / "scripts" / "make_traces.py")
    assert spec is not None and spec.loader is not None
    mt = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mt)
    if form == "mcap":
        path = tmp_path / "run_mcap"
        mt.write_bag(path, "sensor_fault", MSG[0], mcap=True)
        assert list(path.glob("*.mcap"))
    else:
        path = tmp_path / "run.bag"
        mt.write_bag1(path, "sensor_fault", MSG[0])
    log = list(read_trace(TRACES / "sensor_fault.jsonl"))
    bag = list(read_trace(path, MSG))
    assert [(e.topic, dict(e.fields)) for e in bag] == [(e.topic, dict(e.fields)) for e in log]
    assert [e.time - bag[0].time for e in bag] == pytest.approx([e.time for e in log])


def _reference_jsonl(path: Path) -> tuple[list[tuple[object, ...]], str]:
    """The log reader as it was before its fast path (issue 44): every line
    through ``json.loads``; the events read and the error ('' when none)."""
    import math
    out: list[tuple[object, ...]] = []
    index = 0
    with path.open(encoding="utf-8") as fh:
        for lineno, line in enumerate(fh, 1):
            if not line.strip():
                continue
            try:
                obj = json.loads(line)
            except json.JSONDecodeError as exc:
                return out, f"{path}:{lineno}:{exc.colno}: error: malformed JSON: {exc.msg}"
            if not isinstance(obj, dict):
                return out, f"{path}:{lineno}:1: error: expected a JSON object, got {type(obj).__name__}"
            topic, time = obj.get("topic"), obj.get("time")
            if not isinstance(topic, str):
                return out, f"{path}:{lineno}:1: error: the event has no string 'topic'"
            if isinstance(time, bool) or not isinstance(time, (int, float)):
                return out, f"{path}:{lineno}:1: error: the event has no numeric 'time'"
            if not -math.inf < time < math.inf or abs(time) > 1.7976931348623157e308:
                return out, f"{path}:{lineno}:1: error: the event's 'time' is {time!r}, not a finite number"
            fields = {k: v for k, v in obj.items() if k not in ("topic", "time")}
            out.append((index, float(time), topic.lstrip("/"), fields, f"{path.name}:{lineno}", None))
            index += 1
    return out, ""


LINES = ['{"topic": "r", "time": 1.5, "value": 3}', '{"topic": "/s", "time": 2, "a": {"b": [1, 2.5]}, "c": "x"}',
         '{"time": 3.0, "topic": "r", "value": NaN}', '   {"topic": "r", "time": 4}', '{"topic": "r", "time": 5} ',
         '{"topic": "r", "time": 6}\t', '{"topic": "r", "time": 7}\x0b', '{"topic": "r", "time": 8} x',
         '{"topic": "r", "time": 9}, {"topic": "r", "time": 10}', '{"topic": "r", "time": [1',
         '{"topic": "r", "time": true}', '{"topic": 5, "time": 1}', '{"topic": "r", "time": Infinity}',
         '{"topic": "r"}', '[1, 2]', '"text"', '', '   ', '{', '{"topic": "r", "time": 1, "topic": "q"}',
         '{"topic": "r", "time": 1e400}', '{"topic": "r", "time": 12, "v": "\\u00e9\\n"}', '\ufeff{"topic": "r", "time": 1}',
         '{"topic": "r", "time": 13, "v": 123456789012345678901234567890, "w": [-9223372036854775809]}',
         '{"topic": "r", "time": 14, "v": "\\ud800"}', '{"topic": "r", "time": 15, "v": {"w": 1E400}}',
         '{"topic": "r", "time": 16, "v": 0.30000000000000004441, "w": 2.2250738585072011e-308}',
         '{"topic": "r", "time": 1' + '0' * 400 + '}', '{"topic": "r", "time": -17, "v": -0.0, "w": 18446744073709551616}']


def test_the_log_readers_fast_path_reads_and_reports_as_json_loads(tmp_path: Path) -> None:
    """Random logs of good, odd and bad lines (whitespace around an object,
    JSON's whitespace and other whitespace after it, two objects on a line,
    a truncated object, non-objects, NaN and Infinity, a BOM, CRLF and bare
    CR ends):
    the same events and the same located error as reading every line with
    ``json.loads``."""
    from hypothesis import HealthCheck, given, settings
    from hypothesis import strategies as st

    @settings(max_examples=150, deadline=None, database=None, derandomize=True,
              suppress_health_check=list(HealthCheck))
    @given(st.lists(st.sampled_from(LINES), max_size=8), st.sampled_from(["\n", "\r\n", "\r"]), st.booleans())
    def check(lines: list[str], end: str, last_newline: bool) -> None:
        p = tmp_path / "run.jsonl"
        p.write_bytes((end.join(lines) + (end if last_newline else "")).encode("utf-8"))
        want, error = _reference_jsonl(p)
        got: list[tuple[object, ...]] = []
        try:
            for ev in read_trace(p):
                got.append((ev.index, ev.time, ev.topic, dict(ev.fields), ev.where, ev.stamp))
            said = ""
        except TraceError as exc:
            said = str(exc)
        assert (got, said) == (want, error)
    check()


def test_bytes_that_are_not_utf8_are_a_located_error(tmp_path: Path) -> None:
    p = tmp_path / "run.jsonl"
    p.write_bytes(b'{"topic": "r", "time": 1, "v": 2}\n{"topic": "r", "time": 2, "v": "\xc3\xa9\xff"}\n')
    got = []
    with pytest.raises(TraceError, match=r"run.jsonl:2:34: error: the line is not UTF-8 text \(byte 0xff\)"):
        got.extend(read_trace(p))
    assert [e.time for e in got] == [1.0]


def test_the_scalar_mapper_maps_as_map_value() -> None:
    """``value_mapper`` (the monitors' per-topic mapper, issue 44) against
    ``map_value`` on random messages: the same value, or the same error."""
    from fractions import Fraction

    from hypothesis import HealthCheck, given, settings
    from hypothesis import strategies as st

    from rclverify.traces.mapping import value_mapper
    scalar = st.sampled_from([1, 0, -2, 2.5, float("nan"), float("inf"), True, "green", "x", None, Fraction(1, 3),
                              [1.5, 2], {"x": 4.0, "y": "red"}])
    messages = st.dictionaries(st.sampled_from(["data", "a", "b", "a.x", "level"]), scalar, max_size=4)
    rules = st.sampled_from([TopicRule(), TopicRule(fields=("data",)), TopicRule(fields=("a", "data")),
                             TopicRule(fields=("a.x",)), TopicRule(fields=("b[1]",)), TopicRule(fields=("a[0]",))])
    types = st.sampled_from([T.Scalar("REAL"), T.EnumT("Band", ("green", "red")), T.Scalar("NATURAL")])

    def outcome(f: object) -> object:
        try:
            return ("value", f())  # type: ignore[operator]
        except MappingError as exc:
            return ("error", str(exc))

    @settings(max_examples=300, deadline=None, database=None, derandomize=True,
              suppress_health_check=list(HealthCheck))
    @given(types, rules, messages)
    def check(typ: T.Type, rule: TopicRule, fields: dict[str, object]) -> None:
        fast = outcome(lambda: value_mapper(typ, rule)(fields, None))
        slow = outcome(lambda: map_value(typ, fields, rule, None))
        assert repr(fast) == repr(slow)  # repr: NaN is not equal to itself
    check()


#: sensor_msgs/msg/Range as ROS 2 Jazzy and newer define it: ``variance`` was added after Humble, whose
#: definitions rosbags' store holds
NEWER_RANGE = ("std_msgs/Header header\nuint8 ULTRASOUND=0\nuint8 INFRARED=1\nuint8 radiation_type\n"
               "float32 field_of_view\nfloat32 min_range\nfloat32 max_range\nfloat32 range\nfloat32 variance\n")


def test_a_workspace_definition_of_a_standard_type_replaces_the_store_s(tmp_path: Path) -> None:
    """A workspace carrying its distribution's newer sensor_msgs/Range: rosbags refused the second
    definition (TypesysError), so no bag of that workspace could be read or recorded; now the
    workspace's definition wins and the other standard types stay."""
    from rosbags.rosbag2 import StoragePlugin, Writer

    from rclverify.traces.bag import typestore
    msgs = tmp_path / "interfaces" / "sensor_msgs" / "msg"
    msgs.mkdir(parents=True)
    (msgs / "Range.msg").write_text(NEWER_RANGE)
    store = typestore([tmp_path / "interfaces"])
    assert [n for n, _ in store.fielddefs["sensor_msgs/msg/Range"][1]][-1] == "variance"
    assert "geometry_msgs/msg/Twist" in store.fielddefs and "std_msgs/msg/Header" in store.fielddefs
    Range, Header, Time = (store.types[f"{p}/msg/{n}"] for p, n in
                           (("sensor_msgs", "Range"), ("std_msgs", "Header"), ("builtin_interfaces", "Time")))
    msg = Range(header=Header(stamp=Time(sec=3, nanosec=0), frame_id="lidar"), radiation_type=1, field_of_view=0.5,
                min_range=0.0, max_range=40.0, range=1.5, variance=0.25)
    with Writer(tmp_path / "bag", version=9, storage_plugin=StoragePlugin.MCAP) as w:
        conn = w.add_connection("/scan", "sensor_msgs/msg/Range", typestore=store)
        w.write(conn, 3_000_000_000, store.serialize_cdr(msg, "sensor_msgs/msg/Range"))
    (ev,) = read_trace(tmp_path / "bag", [tmp_path / "interfaces"])
    assert (ev.topic, ev.fields["range"], ev.fields["variance"]) == ("scan", 1.5, 0.25)


def test_equal_definitions_are_registered_once_and_each_caller_gets_its_own_store(tmp_path: Path) -> None:
    """traces/bag.py registers a workspace's definitions once per process: the same definitions (in
    another folder too) come from one registration, an edited ``.msg`` is registered again with the
    edit, and going back finds the first; each call returns a store of its own, so a caller that
    removes or registers a type changes no other caller's store; a bad definition stays an error."""
    from rosbags.typesys import get_types_from_msg

    from rclverify.traces import bag
    from rclverify.traces.events import TraceError
    a, b = (tmp_path / x / "sensor_msgs" / "msg" for x in ("a", "b"))
    for d in (a, b):
        d.mkdir(parents=True)
        (d / "Range.msg").write_text(NEWER_RANGE)
    first = bag.typestore([tmp_path / "a"])
    made = len(bag._STORES)
    other = bag.typestore([tmp_path / "b"])
    assert len(bag._STORES) == made and other is not first
    assert other.types["sensor_msgs/msg/Range"] is first.types["sensor_msgs/msg/Range"]  # one registration
    (a / "Range.msg").write_text(NEWER_RANGE + "float32 confidence\n")
    edited = bag.typestore([tmp_path / "a"])
    assert [n for n, _ in edited.fielddefs["sensor_msgs/msg/Range"][1]][-2:] == ["variance", "confidence"]
    assert [n for n, _ in first.fielddefs["sensor_msgs/msg/Range"][1]][-1] == "variance"
    (a / "Range.msg").write_text(NEWER_RANGE)
    again = bag.typestore([tmp_path / "a"])
    assert again.types["sensor_msgs/msg/Range"] is first.types["sensor_msgs/msg/Range"]
    # a caller's own change: a 16-byte Gid in one store; the next store still has the standard 24
    mine = bag.typestore([])
    Gid = mine.types["rmw_dds_common/msg/Gid"]
    assert len(mine.serialize_cdr(Gid(data=np.zeros(24, dtype=np.uint8)), "rmw_dds_common/msg/Gid")) == 28
    mine.fielddefs.pop("rmw_dds_common/msg/Gid")
    mine.types.pop("rmw_dds_common/msg/Gid")
    mine.register(get_types_from_msg("uint8[16] data", "rmw_dds_common/msg/Gid"))
    fresh = bag.typestore([])
    assert fresh.fielddefs["rmw_dds_common/msg/Gid"] != mine.fielddefs["rmw_dds_common/msg/Gid"]
    Gid = fresh.types["rmw_dds_common/msg/Gid"]
    assert len(fresh.serialize_cdr(Gid(data=np.zeros(24, dtype=np.uint8)), "rmw_dds_common/msg/Gid")) == 28
    (a / "Range.msg").write_text("float32 range\n@@@ x\n")
    for _ in range(2):
        with pytest.raises(TraceError, match="Range.msg:1: error: bad message definition"):
            bag.typestore([tmp_path / "a"])
