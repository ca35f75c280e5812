"""A run's ``/clock`` (rosgraph_msgs/Clock) read by every offline reader as events.

A node under ``use_sim_time`` keeps its time from ``/clock``; the deadline
monitor reads it from the run (traces/sim_clock.py).  Every reader of a
recorded run gives each ``/clock`` message as an event of topic ``clock``
whose ``fields["clock"]`` carries the simulated time, at the time the reader
gives any unstamped message (a log line's ``time``; a bag's recorded time),
in the run's order: a JSON-lines log (the live monitor's nested line and
ROSMonitoring's flattened one), a ROS 2 bag (sqlite3, MCAP) and a ROS 1 bag,
read event by event and in blocks (the batch path's columns keep each row's
topic).  Controls: the same runs without ``/clock`` give the same events less
the clock's, and no clock event.
"""
from __future__ import annotations

import json
import random
import struct
from pathlib import Path
from typing import Any

import pytest

from rclverify.traces import read_trace
from rclverify.traces.bag import typestore
from rclverify.traces.sim_clock import clock_value_ns, is_clock_topic

#: the run: (time in ns, topic, value); the /clock samples interleaved with the contract topics
BASE_NS = 1_700_000_000_000_000_000
RUN: list[tuple[int, str, float]] = []
for _i in range(12):
    _t = BASE_NS + _i * 100_000_000
    RUN.append((_t, "x", float(_i)))
    RUN.append((_t + 10_000_000, "clock", _i * 0.5 + 0.000000007))  # simulated time: five times the run's rate
    RUN.append((_t + 50_000_000, "y", float(_i - 1 if _i % 3 == 0 else _i + 1)))
FORMS = ["log", "flat-log", "sqlite3", "mcap", "ros1"]


def _sim_ns(value: float) -> int:
    return round(value * 1e9)


def write_run(path: Path, form: str, clock: bool = True) -> Path:
    """``RUN`` (its ``/clock`` samples left out unless ``clock``) written as ``form`` at ``path``
    (a log file, a ROS 2 bag folder, a ROS 1 ``.bag``); returns the path written."""
    rows = [r for r in RUN if clock or r[1] != "clock"]
    if form in ("log", "flat-log"):
        lines = []
        for t, topic, v in rows:
            if topic == "clock":
                sec, nsec = divmod(_sim_ns(v), 1_000_000_000)
                value: dict[str, Any] = {"clock": {"sec": sec, "nanosec": nsec}} if form == "log" else \
                    {"clock.sec": sec, "clock.nanosec": nsec}
                lines.append({"topic": "/clock", "time": t / 1e9, **value})
            else:
                lines.append({"topic": topic, "time": t / 1e9, "data": v})
        path = path.with_suffix(".jsonl")
        path.write_text("".join(json.dumps(x) + "\n" for x in lines))
        return path
    store = typestore([])
    Clock, Time, F64 = (store.types[n] for n in ("rosgraph_msgs/msg/Clock", "builtin_interfaces/msg/Time",
                                                 "std_msgs/msg/Float64"))

    def clock_msg(v: float) -> Any:
        sec, nsec = divmod(_sim_ns(v), 1_000_000_000)
        return Clock(clock=Time(sec=sec, nanosec=nsec))
    if form == "ros1":
        from rosbags.rosbag1 import Writer as Writer1
        path = path.with_suffix(".bag")
        with Writer1(path) as w1:
            conns = {t: w1.add_connection("/" + t, typ, typestore=store) for t, typ in
                     (("x", "std_msgs/msg/Float64"), ("y", "std_msgs/msg/Float64"),
                      ("clock", "rosgraph_msgs/msg/Clock")) if clock or t != "clock"}
            for t, topic, v in rows:
                msg, typ = (clock_msg(v), "rosgraph_msgs/msg/Clock") if topic == "clock" else \
                    (F64(data=v), "std_msgs/msg/Float64")
                w1.write(conns[topic], t, store.serialize_ros1(msg, typ))
        return path
    from rosbags.rosbag2 import StoragePlugin, Writer
    plugin = StoragePlugin.MCAP if form == "mcap" else StoragePlugin.SQLITE3
    with Writer(path, version=9, storage_plugin=plugin) as w:
        conns = {t: w.add_connection("/" + t, typ, typestore=store) for t, typ in
                 (("x", "std_msgs/msg/Float64"), ("y", "std_msgs/msg/Float64"),
                  ("clock", "rosgraph_msgs/msg/Clock")) if clock or t != "clock"}
        for t, topic, v in rows:
            if topic == "clock":
                raw = store.serialize_cdr(clock_msg(v), "rosgraph_msgs/msg/Clock")
            else:  # little-endian CDR of a Float64: what the block reader decodes straight from its bytes
                raw = struct.pack("<4sd", b"\x00\x01\x00\x00", v)
            w.write(conns[topic], t, raw)
    return path


def _seen(events: Any) -> list[tuple[str, float, Any]]:
    """(topic, time, the simulated time in ns for a clock event, else its ``data``) of each event."""
    return [(e.topic, e.time, clock_value_ns(e.fields) if is_clock_topic(e.topic) else e.fields["data"])
            for e in events]


def _want(clock: bool = True) -> list[tuple[str, Any, Any]]:
    return [(topic, pytest.approx(t / 1e9, abs=1e-9), _sim_ns(v) if topic == "clock" else v)
            for t, topic, v in RUN if clock or topic != "clock"]


@pytest.mark.parametrize("form", FORMS)
def test_every_reader_gives_the_clock_messages_as_events_in_the_run_s_order(tmp_path: Path, form: str) -> None:
    path = write_run(tmp_path / "run", form)
    got = list(read_trace(path))
    assert _seen(got) == _want()
    clocks = [e for e in got if e.topic == "clock"]
    assert len(clocks) == 12
    assert all(e.stamp is None for e in clocks)  # no header: placed at the reader's time for it
    assert [e.index for e in got] == list(range(len(got)))
    # control: the same run without /clock gives the same events less the clock's, and no clock event
    plain = list(read_trace(write_run(tmp_path / "plain", form, clock=False)))
    assert _seen(plain) == _want(clock=False)
    assert not any(is_clock_topic(e.topic) for e in plain)


def _block_rows(blocks: Any) -> list[tuple[str, float, Any]]:
    """(topic as the block's column names it, time as its column gives it, the row's value) of every row."""
    out: list[tuple[str, float, Any]] = []
    for b in blocks:
        if isinstance(b, list):
            out += _seen(b)
            continue
        for i, (topic, t) in enumerate(zip(b.topics, b.times.tolist())):
            ev = b[i]
            assert (ev.topic, ev.time) == (topic, t)
            out.append((topic, t, clock_value_ns(ev.fields) if is_clock_topic(topic) else ev.fields["data"]))
    return out


@pytest.mark.parametrize("form", ["log", "flat-log", "sqlite3", "mcap"])
@pytest.mark.parametrize("rows", [4, 1000])
def test_the_blocks_keep_each_clock_row_s_topic_and_time(tmp_path: Path, form: str, rows: int) -> None:
    """The batch path's blocks (a log's, a ROS 2 bag's): each row's topic in the block's ``topics``
    column, so a reader of the columns sees a clock row, and its event as the stream gives it."""
    path = write_run(tmp_path / "run", form)
    blocks = read_trace(path).blocks(["data"], rows)  # type: ignore[attr-defined]
    assert blocks is not None
    assert _block_rows(blocks) == _want()
    plain = read_trace(write_run(tmp_path / "plain", form, clock=False)).blocks(["data"], rows)  # type: ignore[attr-defined]
    assert _block_rows(plain) == _want(clock=False)


def test_the_readers_typestore_decodes_a_clock_also_where_the_workspace_redefines_a_standard_type(
        tmp_path: Path) -> None:
    """A ROS 2 bag recorded before Iron carries no definitions: its messages decode with the readers'
    type store, which holds rosgraph_msgs/msg/Clock, also when a workspace ``.msg`` replaces a standard
    type (the store is then remade from the standard definitions less the replaced one)."""
    msgs = tmp_path / "interfaces" / "sensor_msgs" / "msg"
    msgs.mkdir(parents=True)
    (msgs / "Range.msg").write_text("std_msgs/Header header\nfloat32 range\nfloat32 variance\n")
    for store in (typestore([]), typestore([tmp_path / "interfaces"])):
        Clock, Time = store.types["rosgraph_msgs/msg/Clock"], store.types["builtin_interfaces/msg/Time"]
        raw = store.serialize_cdr(Clock(clock=Time(sec=12, nanosec=345)), "rosgraph_msgs/msg/Clock")
        msg = store.deserialize_cdr(raw, "rosgraph_msgs/msg/Clock")
        assert (msg.clock.sec, msg.clock.nanosec) == (12, 345)


def test_a_live_log_s_clock_lines_keep_its_reads_decoded_at_once(tmp_path: Path,
                                                               monkeypatch: pytest.MonkeyPatch) -> None:
    """A clock line's ``clock`` (an object of scalars) keeps a read on the at-once path (traces/jsonl_blocks.py,
    one ``decode_lines`` call), with the exact reader's events and columns (``clock`` read as the exact reader
    reads it, a key given twice the last).  Controls: the same read with an object holding an object or an
    array, and lines made to fool a lax reader (an object over two lines, two on one line, keeping the count
    of objects equal to the count of lines), go to the line-by-line paths, with the exact reader's events and
    error."""
    from rclverify.traces import jsonl_blocks
    from rclverify.traces.jsonl import read_jsonl
    from test_jsonl_blocks import _blockwise, _outcome
    lines = []
    for i in range(60):
        lines.append(f'{{"topic": "x", "time": {1 + i / 100!r}, "data": {i * 0.5!r}}}')
        lines.append(f'{{"topic": "clock", "time": {1.005 + i / 100!r}, "clock": {{"sec": {i}, "nanosec": 7, '
                     f'"sec": {i + 1}}}}}')
    flat = jsonl_blocks._flat
    at_once: list[bool] = []

    def noted(*a: Any) -> Any:
        got = flat(*a)
        at_once.append(got is not None)
        return got
    monkeypatch.setattr(jsonl_blocks, "_flat", noted)
    p = tmp_path / "run.jsonl"
    odd_lines = [
        None,
        '{"topic": "clock", "time": 9.0, "clock": {"sec": {"s": 1}, "nanosec": 2}}',
        '{"topic": "clock", "time": 9.0, "clock": {"sec": [1], "nanosec": 2}}',
        '{"topic": "clock", "time": 9.0, "clock": {"sec": 1}}{"topic": "x", "time": 9.5, "data": 1.0}\n'
        '{"topic": "clock", "time": 9.6, "clock": {"sec": 2}\n{"nanosec": 3}}',
        '{"topic": "clock", "time": 9.0, "clock": {"sec": 1}\n{"topic": "x", "time": 9.5}}',
    ]
    for odd in odd_lines:
        p.write_text("\n".join(lines + ([odd] if odd else [])) + "\n")
        at_once.clear()
        seen = {"fast": 0, "exact": 0}
        want = _outcome(read_jsonl(p))
        assert _outcome(_blockwise(p, ["data", "clock"], 1000, random.Random(1), seen)) == want
        assert at_once == [odd is None], odd
        assert bool(want[1]) is (odd is not None and "\n" in odd), odd  # the lax reader's bait: an error
        if odd is None:
            assert [e[3] for e in want[0][1:3]] == ["[('clock', {'sec': 1, 'nanosec': 7})]", "[('data', 0.5)]"]
