"""Trace readers (ROSMonitoring JSON lines, ROS 2 bags) and the message-to-RCL mapping rules."""
from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from rclverify.rcl import types as T
from rclverify.traces import TraceError, read_trace
from rclverify.traces.mapping import MappingError, TopicRule, map_value
from rclverify.values import FiniteFunction, Term

REPO = Path(__file__).resolve().parents[1]
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
