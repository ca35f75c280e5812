"""Issue 106: a bag the live monitor recorded is judged as its log and the
live run were, late messages included (traces/bag_late.py).

The live pieces run in-process: a :class:`LiveRun` (the live engine with its
lateness bound, writing the log) fed messages in the order they reached the
monitor, its timer ticking as the live worker's does, and the
:class:`BagRecorder` that ``--record`` opens, fed each message's bytes at
its time as the DDS path feeds it, told of each late message by the engine
as the DDS path wires it.  The question heard late (after the watermark had
passed it) makes the wrong answer to it undecidable live; the log says so
with ``late_s``; the bag says so in its metadata.  The control reads the same
bag with the lateness removed from its metadata: the wrong answer is then
``violated``, which is what a bag without it was judged before.
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
import yaml

from rclverify.backends.monitors.config import load_mapping
from rclverify.cli.commands import main
from rclverify.lang.typecheck import load
from rclverify.runtime.dds.bag import BagRecorder
from rclverify.runtime.live import LiveRun
from rclverify.traces import bag_late
from rclverify.traces.bag import read_bag, typestore

RCL = """
node Gate {
  inputs( b : BOOL )
  outputs( o : BOOL )
  topics( std_msgs/Bool b matches(in.b), std_msgs/Bool o matches(out.o) )
  assume( TRUE )
  guarantee( out.o == in.b )
}
"""
MAPPING = "topics:\n  b: {fields: [data]}\n  o: {fields: [data]}\n"
T0 = 1_700_000_000.0  # a date's seconds since the epoch: the float precision the engine really has

#: (arrival at the monitor, topic, source time, value), all s after T0: the question of 1.0 s is heard at
#: 1.4 s, after the watermark (the clock less 50 ms, every writer silent past it) had passed it; the node's
#: answer to it (published 1.01 s) is wrong, and heard after it (the monitor's reader of ``b`` stalled)
HEARD = [(0.50, "b", 0.50, True), (0.51, "o", 0.51, True),
         (1.40, "b", 1.00, True), (1.41, "o", 1.01, False),
         (2.00, "b", 2.00, False), (2.01, "o", 2.01, False)]


def _workspace(tmp: Path) -> Path:
    (tmp / "contracts").mkdir()
    (tmp / "contracts" / "c.rcl").write_text(RCL)
    (tmp / "contracts" / "plan.yaml").write_text("contracts: [contracts/c.rcl]\n")
    (tmp / "mapping.yaml").write_text(MAPPING)
    return tmp


def _record(ws: Path, wire: bool = True, heard: list[tuple[float, str, float, bool]] | None = None) -> tuple[dict[str, Any], Path, Path]:
    """The live run: its evidence record, its log and its bag (``wire``: the engine tells the
    recorder of late messages, as runtime/dds/live.py wires it)."""
    checked = load([ws / "contracts" / "c.rcl"])
    rules = load_mapping(ws, "mapping.yaml").rules
    live = LiveRun(checked, [checked.nodes["Gate"]], rules, 0.5, ws / "live.jsonl", reorder_window=0.05)
    rec = BagRecorder(ws / "bag", "sqlite3", {"b": "std_msgs/Bool", "o": "std_msgs/Bool"}, [])
    if wire:
        live.engine.on_late = rec.late
    store = typestore([])
    Bool = store.types["std_msgs/msg/Bool"]
    now, period = T0, 0.01
    for arrival, topic, source, value in HEARD if heard is None else heard:
        while now + period <= T0 + arrival:
            now += period
            live.tick(now)
        ns = round((T0 + source) * 1e9)
        rec.write(topic, ns, store.serialize_cdr(Bool(data=value), "std_msgs/msg/Bool"))
        live.push(topic, {"data": value}, ns / 1e9)
    for _ in range(100):
        now += period
        live.tick(now)
    record = live.stop(ws / "live.json")
    rec.close()
    return record, ws / "live.jsonl", ws / "bag"


def _offline(ws: Path, trace: Path, capsys: pytest.CaptureFixture[str]) -> dict[str, int]:
    main(["monitor", "-w", str(ws), "--mapping", "mapping.yaml", "--horizon", "0.5", "--json", str(trace)])
    (got,) = json.loads(capsys.readouterr().out)
    return {k: v for k, v in got["counts"].items() if v}


def _live_counts(log: Path) -> dict[str, int]:
    counts: dict[str, int] = {}
    for line in log.read_text().splitlines():
        x = json.loads(line)
        if x["topic"] == "rclverify/verdict" and "kind" not in x:
            counts[x["verdict"]["verdict"]] = counts.get(x["verdict"]["verdict"], 0) + 1
    return counts


def test_a_recorded_bag_is_judged_as_the_live_run_and_its_log(tmp_path: Path,
                                                              capsys: pytest.CaptureFixture[str]) -> None:
    ws = _workspace(tmp_path)
    record, log, bag = _record(ws)
    assert record["late_events"] == 2  # the question of 1.0 s and its answer were heard late
    live = _live_counts(log)
    assert live.get("inconclusive") == 1 and "violated" not in live, live
    assert _offline(ws, log, capsys) == live
    assert _offline(ws, bag, capsys) == live  # the bag: the same verdicts, the late question undecided
    # the bag says which message was late, at its time, as the log does
    late_lines = [json.loads(x) for x in log.read_text().splitlines() if "late_s" in x]
    assert [(x["topic"], x["late_s"]) for x in late_lines] == [
        (e.topic, e.late) for e in read_bag(bag) if e.late]


#: the same run, the wrong answer heard before the question it answers (the question's reader stalled longer):
#: live judged it against the question before (false, answered false: satisfied), then, the question heard,
#: against it (undecided: the node may not have had it)
ANSWER_FIRST = [(0.50, "b", 0.50, True), (0.51, "o", 0.51, True), (0.60, "b", 0.60, False), (0.61, "o", 0.61, False),
                (1.02, "o", 1.01, False), (1.40, "b", 1.00, True),
                (2.00, "b", 2.00, False), (2.01, "o", 2.01, False)]


def _last_per_message(log: Path) -> dict[str, int]:
    """The live verdicts, the latest of each message (a later one replaces an earlier: late.py)."""
    last: dict[int, str] = {}
    for line in log.read_text().splitlines():
        x = json.loads(line)
        if x["topic"] == "rclverify/verdict" and "kind" not in x:
            last[x["verdict"]["event"]] = x["verdict"]["verdict"]
    counts: dict[str, int] = {}
    for v in last.values():
        counts[v] = counts.get(v, 0) + 1
    return counts


def test_a_verdict_given_before_its_question_was_heard_is_replaced(tmp_path: Path,
                                                                   capsys: pytest.CaptureFixture[str]) -> None:
    ws = _workspace(tmp_path)
    record, log, bag = _record(ws, heard=ANSWER_FIRST)
    lines = [json.loads(x)["verdict"] for x in log.read_text().splitlines() if '"rclverify/verdict"' in x]
    wrong = [v for v in lines if v["where"] == "message 4"]
    # live said satisfied at once (against the question of 0.6 s), then, the question of 1.0 s heard, replaced it
    assert [v["verdict"] for v in wrong] == ["satisfied", "inconclusive"], wrong
    assert "replaces the satisfied one" in wrong[1]["reason"]
    (node,) = record["nodes"]
    final = {k: v for k, v in node["counts"].items() if v}
    assert final == _last_per_message(log), (final, _last_per_message(log))
    assert final.get("inconclusive") == 1 and final.get("satisfied", 0) < sum(
        v["verdict"] == "satisfied" for v in lines)  # one satisfied fewer than given: withdrawn
    assert _offline(ws, log, capsys) == final  # the log, in stamp order, judges as live finally did
    assert _offline(ws, bag, capsys) == final


def test_the_control_a_bag_without_its_lateness_is_judged_at_its_times(tmp_path: Path,
                                                                       capsys: pytest.CaptureFixture[str]) -> None:
    ws = _workspace(tmp_path)
    _, log, bag = _record(ws)
    meta = bag / "metadata.yaml"
    doc = yaml.safe_load(meta.read_text())
    custom = doc["rosbag2_bagfile_information"]["custom_data"]
    assert set(custom) == {bag_late.KEY}
    del doc["rosbag2_bagfile_information"]["custom_data"]
    meta.write_text(yaml.safe_dump(doc))
    assert not [e for e in read_bag(bag) if e.late]
    got = _offline(ws, bag, capsys)
    assert got.get("violated") == 1 and "inconclusive" not in got, got  # the late question read as in time


def test_a_run_with_nothing_late_writes_no_lateness(tmp_path: Path) -> None:
    ws = _workspace(tmp_path)
    record, _, bag = _record(ws, heard=[(s, t, s, v) for _, t, s, v in HEARD])  # each heard at its time
    assert record["late_events"] == 0
    doc = yaml.safe_load((bag / "metadata.yaml").read_text())
    assert not doc["rosbag2_bagfile_information"].get("custom_data")


@pytest.mark.parametrize("text", [None, "", "not json", "[1, 2]", '{"/b": [[1, "x"], [true, 1.0], [2]]}'])
def test_a_value_that_is_not_the_lateness_is_no_lateness(text: str | None) -> None:
    assert not bag_late.decode(text)


def test_the_lateness_is_matched_to_its_message_by_topic_and_time() -> None:
    got = bag_late.decode(bag_late.encode({"b": [(T0 + 1.0, 0.4)], "o": [(T0 + 2.0, 0.1)]}))
    ns = round((T0 + 1.0) * 1e9)
    assert got.at("/b", ns) == 0.4 and got.at("/b", ns + 900) == 0.4  # the float's rounding, within 1 µs
    assert got.at("/b", ns + 5_000) == 0.0 and got.at("/o", ns) == 0.0 and got.at("/x", ns) == 0.0
