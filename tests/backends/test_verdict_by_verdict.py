"""Live = log = bag, verdict by verdict (issue 106): the comparison of the robot generator's runner
(bench/_robot_verdicts.py) and the records it compares (``rclverify monitor --verdicts``,
backends/monitors/verdict_lines.py).

A hand-made live log: a relay copying each reading's header stamp onto an answer published 120 ms
later (a reading every 300 ms), its verdict lines the ones the online engine gives when fed the
messages in the order they reached the monitor, written as the live monitor writes them.  The
recorded path (``rclverify monitor --verdicts FILE LOG``) judges the same log's messages; its records
and the log's verdict lines are the same, message by message, identified by topic and header stamp
(the answers' event time in the log is their copied stamp; a bag's would be its receipt).  The
controls: one verdict line changed is found, named with both sides' verdicts and reasons, and one
verdict line left out is found as a verdict the live run did not give.
"""
from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any

import pytest

from rclverify.backends.monitors.config import load_mapping
from rclverify.backends.monitors.deadlines import DeadlineMonitor
from rclverify.backends.monitors.online import OnlineEngine
from rclverify.backends.monitors.verdict_lines import VERDICT_TOPIC, log_records, verdict_record
from rclverify.cli.commands import main
from rclverify.lang.typecheck import load
from test_judge_event_time import _msg, _workspace
from test_judge_writers import COPY, COPY_MAPPING

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bench"))
from _robot_verdicts import compare, finals, tally, three_way  # noqa: E402

PERIOD, DELAY, N = 0.3, 0.12, 8
#: the answer heard later than the lateness bound (50 ms): 200 ms after its publication
LATE, LATE_S = 5, 0.2


def _sent() -> list[dict[str, Any]]:
    """Readings every 300 ms from 1 s, each copied 120 ms later onto an answer with its stamp; each
    message with the time it reaches the monitor (``heard``): 1 ms after publication, answer
    :data:`LATE` 200 ms."""
    out = []
    for i in range(N):
        t = 1.0 + i * PERIOD
        out.append({**_msg("x", t, t, value=float(i) + 0.5), "heard": t + 0.001})
        out.append({**_msg("r", t + DELAY, t, range=float(i) + 0.5),
                    "heard": t + DELAY + (LATE_S if i == LATE else 0.001)})
    return out


def _live_log(ws: Path) -> list[dict[str, Any]]:
    """The log the live monitor writes of ``_sent()``: each message at its event time (its header stamp),
    one heard later than the bound at its source time with its lateness (runtime/live.py), each verdict as
    the online engine and the deadline monitor gave it."""
    checked = load([ws / "contracts" / "c.rcl"])
    rules = load_mapping(ws, "mapping.yaml").rules
    lines: list[dict[str, Any]] = []
    deadline = lambda v: lines.append({"topic": VERDICT_TOPIC, "time": v.trigger_stamp, "kind": "deadline",  # noqa: E731
                                       "verdict": v.to_json()})
    dm = DeadlineMonitor(checked, checked.nodes["Relay"], rules, deadline, horizon=1.0)

    def released(ev: Any) -> None:
        late = {"late_s": round(ev.late, 6)} if ev.late else {}
        lines.append({"topic": ev.topic, "time": ev.source if late and ev.source is not None else ev.time, **late,
                      **dict(ev.fields)})
        dm.feed(ev)
    eng = OnlineEngine(checked, [checked.nodes["Relay"]], rules, 1.0, reorder_window=0.05,
                       on_verdict=lambda v: lines.append({"topic": VERDICT_TOPIC, "time": v.decided_at,
                                                          "verdict": v.to_json()}), on_event=released)
    now = 1.0
    for m in sorted(_sent(), key=lambda m: m["heard"]):
        while now + 0.01 <= m["heard"]:
            now += 0.01
            eng.tick(now)
            dm.advance(eng.watermark(now))
        eng.push(m["topic"], {x: v for x, v in m.items() if x not in ("topic", "time", "heard")}, m["time"])
    eng.finish()
    dm.finish()
    return lines


def _offline(ws: Path, log: Path, capsys: pytest.CaptureFixture[str]) -> list[dict[str, Any]]:
    out = ws / "offline.verdicts.jsonl"
    main(["monitor", "-w", str(ws), "--mapping", "mapping.yaml", "--horizon", "1.0", "--json", "--verdicts", str(out),
          str(log)])
    capsys.readouterr()
    return [json.loads(x) for x in out.read_text().splitlines()]


@pytest.fixture()
def run(tmp_path: Path) -> tuple[Path, Path]:
    ws, _ = _workspace(tmp_path, COPY, [], COPY_MAPPING)
    log = ws / "live.jsonl"
    log.write_text("".join(json.dumps(x) + "\n" for x in _live_log(ws)))
    return ws, log


def test_the_live_verdicts_of_a_log_are_its_offline_verdicts_one_by_one(
        run: tuple[Path, Path], capsys: pytest.CaptureFixture[str]) -> None:
    ws, log = run
    live, offline = log_records(log), _offline(ws, log, capsys)
    f = finals(live)
    # each answer satisfied, each reading's deadline met, every message identified by its header stamp
    assert tally(f)["Relay"]["satisfied"] == N and tally(f)["Relay"]["deadline true"] == N
    assert sorted(r["time"] for r in f[("Relay", "guarantee", "r", 0)]) == pytest.approx(
        [1.0 + i * PERIOD for i in range(N)])
    assert compare(f, finals(offline)) == []
    assert three_way({"live": live, "log": offline, "bag": offline})[1] == []
    # the answer heard late: placed live at the watermark, not at its stamp, and named by its stamp
    late = next(json.loads(x)["verdict"] for x in log.read_text().splitlines()
                if '"verdict"' in x and json.loads(x)["verdict"].get("topic") == "r"
                and json.loads(x)["verdict"]["time"] > 1.0 + LATE * PERIOD + 0.05)
    assert late["verdict"] == "satisfied"


def test_the_control_one_changed_verdict_is_found_with_both_sides(
        run: tuple[Path, Path], capsys: pytest.CaptureFixture[str]) -> None:
    ws, log = run
    offline = _offline(ws, log, capsys)
    lines = [json.loads(x) for x in log.read_text().splitlines()]
    fourth = [x for x in lines if x["topic"] == VERDICT_TOPIC and "kind" not in x][3]
    fourth["verdict"].update(verdict="violated", reason="out.r == in.x is false")
    log.write_text("".join(json.dumps(x) + "\n" for x in lines))
    found = compare(finals(log_records(log)), finals(offline))
    assert len(found) == 1, found
    d = found[0]
    assert (d.node, d.item, d.topic) == ("Relay", "guarantee", "r") and d.time == pytest.approx(1.0 + 3 * PERIOD)
    assert d.a is not None and d.b is not None and (d.a["verdict"], d.b["verdict"]) == ("violated", "satisfied")
    assert "live: violated (out.r == in.x is false); log: satisfied" in d.text(("live", "log"))


def test_the_control_a_verdict_one_path_did_not_give_is_found(
        run: tuple[Path, Path], capsys: pytest.CaptureFixture[str]) -> None:
    ws, log = run
    offline = _offline(ws, log, capsys)
    lines = [json.loads(x) for x in log.read_text().splitlines()]
    dropped = [x for x in lines if x.get("kind") == "deadline"][2]
    log.write_text("".join(json.dumps(x) + "\n" for x in lines if x is not dropped))
    found = compare(finals(log_records(log)), finals(offline))
    assert [(d.item, d.a, d.b is not None and d.b["verdict"]) for d in found] == [("deadline", None, "true")]
    assert found[0].time == pytest.approx(1.0 + 2 * PERIOD)


def _rec(verdict: str, time: float, **more: Any) -> dict[str, Any]:
    return verdict_record("guarantee", {"node": "N", "topic": "t", "time": time, "verdict": verdict, **more})


def test_a_revision_replaces_the_verdict_given_before_and_a_provisional_one_is_told_apart() -> None:
    """The last verdict of a message stands (a live revision); a verdict still provisional at the end is
    marked so when it differs; times a float's rounding apart are one message, 10 ms apart two."""
    live = [_rec("inconclusive", 1.0), _rec("satisfied", 1.0), _rec("satisfied", 1.3, provisional=True)]
    offline = [_rec("satisfied", 1.0 + 4e-9), _rec("violated", 1.3 + 4e-9)]
    found = compare(finals(live), finals(offline))
    assert [(d.time, d.provisional) for d in found] == [(pytest.approx(1.3), True)]
    # the control: the revision left out, the first verdict differs and is found, not provisional
    found = compare(finals(live[:1] + live[2:]), finals(offline))
    assert [(round(d.time, 6), d.provisional) for d in found] == [(1.0, False), (1.3, True)]
    # a message 10 ms off is another message: each side's verdict has no counterpart
    assert [(d.a is None, d.b is None) for d in compare(finals([_rec("satisfied", 1.0)]),
                                                        finals([_rec("satisfied", 1.01)]))] == [(False, True), (True, False)]


def test_a_live_verdict_names_its_message_by_the_log_line_it_is_on(tmp_path: Path) -> None:
    """Seed 516 of the robot generator: a relay's first answer, heard 219 ms late, was placed live at
    the watermark (749.98484), neither its stamp (749.928117) nor its log line's time (its source time,
    750.1597): its verdict names it by the log's message line it is on (``message 1``), its header stamp.
    The control: an unstamped message is named by its line's time, and a verdict whose ``where`` names
    no message line of its topic keeps its own time."""
    stamp = {"header": {"stamp": {"sec": 749, "nanosec": 928117200}}}
    lines = [{"topic": "s0", "time": 749.9281172, **stamp, "range": 2.95},
             {"topic": "rclverify/call", "time": 749.95, "kind": "call", "part": "unjudged", "link": "x"},
             {"topic": "r4", "time": 750.2609477, "late_s": 0.219456, **stamp, "range": 2.95},
             {"topic": "a5", "time": 749.98484, "data": True},
             {"topic": VERDICT_TOPIC, "time": 750.26, "verdict": {"node": "Relay4", "verdict": "satisfied", "event": 1,
                                                                  "time": 749.98484, "where": "message 1", "topic": "r4"}},
             {"topic": VERDICT_TOPIC, "time": 750.27, "verdict": {"node": "Alarm5", "verdict": "satisfied", "event": 2,
                                                                  "time": 749.98484, "where": "message 2", "topic": "a5"}},
             {"topic": VERDICT_TOPIC, "time": 750.28, "verdict": {"node": "Alarm5", "verdict": "satisfied", "event": 2,
                                                                  "time": 749.98484, "where": "message 0", "topic": "a5"}}]
    log = tmp_path / "live.jsonl"
    log.write_text("".join(json.dumps(x) + "\n" for x in lines))
    assert [(r["node"], r["time"]) for r in log_records(log)] == [
        ("Relay4", pytest.approx(749.9281172, abs=1e-9)), ("Alarm5", 749.98484), ("Alarm5", 749.98484)]


def test_one_message_placed_apart_with_one_verdict_is_told_apart_from_a_disagreement() -> None:
    """Seed 530 (a ``/clock`` robot): a relay's answer in another clock, placed live at its source time and
    by the bag's reader 0.2 ms earlier, satisfied on both: one message placed apart, not two verdicts
    without a counterpart.  The controls: placed apart with different verdicts is a disagreement; two
    records 10 ms apart are two messages."""
    live, bag = [_rec("satisfied", 242.8070235)], [_rec("satisfied", 242.8068178)]
    found = compare(finals(live), finals(bag))
    assert [(d.placed_apart, round(d.apart, 7)) for d in found] == [(True, 0.0002057)]
    assert "placed it at 242.807024, log at 242.806818" in found[0].text(("live", "log"))
    assert three_way({"live": live, "log": bag, "bag": live})[1][0].startswith("placed apart: live != log")
    differ = compare(finals(live), finals([_rec("violated", 242.8068178)]))
    assert [(d.placed_apart, d.a and d.a["verdict"], d.b and d.b["verdict"]) for d in differ] == [
        (False, "satisfied", "violated")]
    assert len(compare(finals(live), finals([_rec("satisfied", 242.817)]))) == 2
