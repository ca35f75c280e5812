"""The offline check of a live monitor's log names a writer in another clock as the live record and the bag do.

A driver stamps its readings 2 s after it publishes them (another clock: traces/event_time.py,
``other_clock``); a node answers each reading 50 ms later, unstamped, with its value.  The live engine
places each reading at its source time and names the driver in one line (``OnlineEngine.clock_lines``);
its log holds each reading with the stamp set aside (``header.stamp_aside``, runtime/live.py's lines).
The recorded path reads the log (nested and ROSMonitoring's flattened keys, the latter through the
columnar block reader the deadline monitor takes) and the run as a bag has it (each message at its source
time, its stamp in its header): each names the driver in the very line the live engine gave, and judges
the log as the live run did.  The controls: the log with the stamp set aside removed names nobody and
gives the same verdicts (the stamp set aside is never the message's time); a driver 10 ms behind (one
clock) is named by none of the three.
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from rclverify.backends.monitors import recorded
from rclverify.backends.monitors.config import load_mapping
from rclverify.backends.monitors.online import OnlineEngine
from rclverify.lang.typecheck import load
from rclverify.traces.event_time import ASIDE

ALARM = """
node Alarm {
  inputs( x : REAL )
  outputs( r : REAL )
  topics( pkg/Reading x matches(in.x), pkg/Range r matches(out.r) )
  assume( TRUE )
  guarantee( out.r == in.x ) triggered by in.x within 950 ms
}
"""
MAPPING = "topics:\n  x: {fields: [value]}\n  r: {fields: [range]}\n"
PERIOD, ANSWER = 0.3, 0.05


def _stamp(t: float) -> dict[str, Any]:
    sec = int(t)
    return {"header": {"stamp": {"sec": sec, "nanosec": round((t - sec) * 1e9)}}}


def _run(offset: float, defect: bool = False, n: int = 12) -> list[dict[str, Any]]:
    """Readings 0, 1, 2 ... every 300 ms from 1 s, stamped ``offset`` s from their source times, each
    answered 50 ms later unstamped (``defect``: every fourth answer 0.5 too high); a closing tick."""
    out: list[dict[str, Any]] = []
    for i in range(n):
        t = 1.0 + i * PERIOD
        out.append({"topic": "x", "time": t, **_stamp(t + offset), "value": float(i)})
        out.append({"topic": "r", "time": t + ANSWER, "range": float(i) + (0.5 if defect and i % 4 == 3 else 0.0)})
    out.append({"topic": "tick", "time": 1.0 + n * PERIOD + 3.0, "data": 0})
    return out


def _workspace(tmp: Path) -> Path:
    (tmp / "contracts").mkdir(parents=True, exist_ok=True)
    (tmp / "contracts" / "c.rcl").write_text(ALARM)
    (tmp / "contracts" / "plan.yaml").write_text("contracts: [contracts/c.rcl]\n")
    (tmp / "mapping.yaml").write_text(MAPPING)
    return tmp


def _write(path: Path, lines: list[dict[str, Any]]) -> Path:
    path.write_text("".join(json.dumps(x) + "\n" for x in lines))
    return path


def _live(ws: Path, lines: list[dict[str, Any]], node: str = "Alarm") -> tuple[list[str], list[dict[str, Any]]]:
    """The live engine fed ``lines`` 1 ms after publication: its lines naming writers in another clock,
    and what its log holds (runtime/live.py, ``_event``)."""
    checked = load([ws / "contracts" / "c.rcl"])
    log: list[dict[str, Any]] = []

    def event(ev: Any) -> None:
        late = {"late_s": round(ev.late, 6)} if ev.late else {}
        published = ev.source is not None and (late or ev.stamp == ev.time)
        log.append({"topic": ev.topic, "time": ev.source if published else ev.time, **late, **dict(ev.fields)})
    eng = OnlineEngine(checked, [checked.nodes[node]], load_mapping(ws, "mapping.yaml").rules, 1.0,
                       reorder_window=0.05, on_event=event)
    now = lines[0]["time"]
    for line in lines:
        while now + 0.01 <= line["time"] + 0.001:
            now += 0.01
            eng.tick(now)
        eng.push(line["topic"], {k: v for k, v in line.items() if k not in ("topic", "time")}, line["time"])
    eng.finish()
    return eng.clock_lines(), log


def _offline(ws: Path, run: Path, node: str = "Alarm") -> tuple[str, list[tuple[str, str]], list[dict[str, int]]]:
    """The recorded path on ``run``: its note (how the run's clocks were read), each node and deadline
    status with its explanation, the deadline counts."""
    checked = load([ws / "contracts" / "c.rcl"])
    got = recorded.check_recorded(checked, [checked.nodes[node]], load_mapping(ws, "mapping.yaml"), ws, str(run),
                                  lambda w: None)
    return got.stamp_order, [got.verdict(r, str(run)) for r in got.results], [dict(d.counts) for d in got.deadlines]


def _flattened(line: dict[str, Any]) -> dict[str, Any]:
    """``line`` with its header flattened as ROSMonitoring's logs have it (``header.stamp_aside.sec`` ...)."""
    h = line.get("header")
    if not isinstance(h, dict):
        return line
    out = {k: v for k, v in line.items() if k != "header"}
    for key, stamp in h.items():
        out.update({f"header.{key}.{k}": v for k, v in stamp.items()})
    return out


def _without_aside(line: dict[str, Any]) -> dict[str, Any]:
    h = line.get("header")
    if not isinstance(h, dict) or ASIDE not in h:
        return line
    rest = {k: v for k, v in h.items() if k != ASIDE}
    return {**{k: v for k, v in line.items() if k != "header"}, **({"header": rest} if rest else {})}


@pytest.mark.parametrize("defect", [False, True], ids=["correct", "control: defective"])
def test_the_log_names_the_driver_in_another_clock_in_the_live_records_line(tmp_path: Path, defect: bool) -> None:
    ws = _workspace(tmp_path)
    sent = _run(2.0, defect)
    named, log = _live(ws, sent)
    assert len(named) == 1 and named[0].startswith("/x: header stamps +2.000 s to +2.000 s") and \
        "another clock" in named[0], named
    # the live log holds each reading at its source time, its stamp set aside
    readings = [x for x in log if x["topic"] == "x"]
    assert len(readings) == 12 and all(set(x["header"]) == {ASIDE} for x in readings), readings[:2]
    bag_note, bag, bag_deadlines = _offline(ws, _write(tmp_path / "bag.jsonl", sent))
    results = {}
    for name, lines in (("log", log), ("flattened", [_flattened(x) for x in log])):
        note, statuses, deadlines = _offline(ws, _write(tmp_path / f"{name}.jsonl", lines))
        assert note.split("; ")[0] == named[0], (name, note)
        assert [s for s, _ in statuses] == [s for s, _ in bag], (name, statuses, bag)
        assert named[0] in statuses[0][1], statuses
        results[name] = (statuses, deadlines)
    assert bag_note.split("; ")[0] == named[0], bag_note
    assert [s for s, _ in bag] == (["failed"] if defect else ["discharged"]), bag
    # the log ends at the last answer (the bag's closing tick is no contract's): its last deadline still open
    assert results["log"][1] == results["flattened"][1] and sum(results["log"][1][0].values()) == sum(
        bag_deadlines[0].values()) == 12, (results, bag_deadlines)
    # the control: the stamp set aside removed, nobody is named and the verdicts are the log's
    note, statuses, deadlines = _offline(ws, _write(tmp_path / "bare.jsonl", [_without_aside(x) for x in log]))
    assert "another clock" not in note, note
    assert [s for s, _ in statuses] == [s for s, _ in results["log"][0]] and deadlines == results["log"][1]


def test_the_control_a_driver_in_the_run_clock_is_named_nowhere(tmp_path: Path) -> None:
    """10 ms behind its source times: one clock, its stamps its messages' times in every path."""
    ws = _workspace(tmp_path)
    sent = _run(-0.01)
    named, log = _live(ws, sent)
    assert named == []
    assert not any(isinstance(x.get("header"), dict) and ASIDE in x["header"] for x in log)
    for name, lines in (("log", log), ("bag", sent)):
        note, statuses, _ = _offline(ws, _write(tmp_path / f"{name}.jsonl", lines))
        assert "another clock" not in note and [s for s, _ in statuses] == ["discharged"], (name, note, statuses)


def test_the_block_reader_hands_every_stamp_set_aside_to_the_watch(tmp_path: Path) -> None:
    """A flattened log read in blocks of 4 lines (the batch path's reader): the lines holding a stamp set
    aside are read exactly, as events the watch sees, never as a columnar block of times alone, so the
    watch counts every reading of the driver as the live engine did (12 of 12 in the line)."""
    from rclverify.backends.monitors.judged import Counted
    from rclverify.backends.monitors.stamp_order import StampWatch
    from rclverify.traces import read_trace
    ws = _workspace(tmp_path)
    named, log = _live(ws, _run(2.0))
    assert "(12 of 12 stamped message(s)" in named[0], named
    watch = StampWatch(0.0)
    blocks = Counted(read_trace(_write(tmp_path / "flat.jsonl", [_flattened(x) for x in log])), {}, watch).blocks(
        ["value", "range"], 4)
    assert blocks is not None
    assert sum(len(b) for b in blocks) == len(log)
    assert watch.named() == named, watch.named()


def test_a_relay_copying_stamps_on_simulated_time_is_named_alike_live_in_the_log_and_in_the_bag(
        tmp_path: Path) -> None:
    """Both writers on a /clock at half the wall clock's rate (tests/backends/test_judge_writers.py): the
    reading's stamps set aside in the log, the relay's copies carried to their readings' times with the
    stamp it wrote set aside beside them; each writer named in the live engine's line, offsets included,
    from the log as from the bag."""
    import test_judge_writers as w
    (tmp_path / "ws").mkdir()
    ws = _workspace(tmp_path / "ws")
    (ws / "contracts" / "c.rcl").write_text(w.COPY)
    (ws / "mapping.yaml").write_text(w.COPY_MAPPING)
    sent = w._on_simulated_time(w._copying_relay(0.45))
    named, log = _live(ws, sent, "Relay")
    assert [x.split(":")[0] for x in named] == ["/r", "/x"], named
    assert all(ASIDE in x["header"] for x in log if x["topic"] == "r") and any(
        "stamp" in x["header"] for x in log if x["topic"] == "r"), log[:4]
    for name, lines in (("bag", sent), ("log", log)):
        note, statuses, _ = _offline(ws, _write(tmp_path / f"{name}.jsonl", lines), "Relay")
        assert [x for x in note.split("; ") if "another clock" in x] == named, (name, note)
        assert [s for s, _ in statuses] == ["discharged"], (name, statuses)


def test_a_writer_seen_before_the_first_stamp_set_aside_keeps_its_messages_in_the_line() -> None:
    """A writer in another clock whose messages come with their header stamps before any message with a
    stamp set aside is named with all of them: the stamps set aside add to what the header stamps measured
    (3 of 3 for the first writer, 2 of 2 for the second).  The control: counted from the first stamp set
    aside alone, the first writer's line would be missing."""
    from rclverify.backends.monitors.stamp_order import StampWatch
    from rclverify.traces.events import Event

    def stamp(s: float) -> dict[str, Any]:
        return {"secs": int(s), "nsecs": round((s - int(s)) * 1e9)}

    watch = StampWatch(0.0)
    for i in range(3):  # a driver stamping 2 s ahead, its stamps read as the header's
        watch.see(Event(i, 1.0 + i, "pkg/Reading", {"header": {"stamp": stamp(3.0 + i)}}, f"line {i + 1}"))
    for i in range(2):  # another, its stamps set aside by a live log
        watch.see(Event(3 + i, 4.0 + i, "pkg/Other", {"header": {ASIDE: stamp(7.0 + i)}}, f"line {i + 4}"))
    named = watch.named()
    assert len(named) == 2, named
    assert "pkg/Reading" in named[0] + named[1] and "pkg/Other" in named[0] + named[1], named
    assert any("(3 of 3 stamped" in n for n in named) and any("(2 of 2 stamped" in n for n in named), named
