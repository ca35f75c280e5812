"""Issue 106: the judge's pairing, lateness and clocks, offline and live alike.

Small workspaces written here; each run is a JSON-lines log as the live
monitor writes it (each line's ``time`` the publisher's source time, a
header stamp where the message has one), judged offline (``rclverify
monitor LOG``, the recorded path) and by the live engine
(:class:`OnlineEngine` with its lateness bound, fed the same messages in the
order they reached the monitor, its timer ticking as the live worker's
does, the deadline monitors fed the released messages and the timer's
clock as :mod:`rclverify.runtime.live` feeds them).  Each case has its
control: a correct node and a seeded defect.
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from rclverify.backends.monitors import recorded
from rclverify.backends.monitors.config import load_mapping
from rclverify.backends.monitors.deadlines import DeadlineMonitor, DeadlineVerdict, deadline_status
from rclverify.backends.monitors.online import OnlineEngine
from rclverify.lang.typecheck import load

RELAY = """
node Relay {
  inputs( b : BOOL )
  outputs( stop : BOOL )
  topics( std_msgs/Bool b matches(in.b), std_msgs/Bool stop matches(out.stop) )
  assume( TRUE )
  guarantee( in.b -> out.stop ) triggered by in.b within 100 ms
}
"""

MAPPING = "topics:\n  b: {fields: [data]}\n  stop: {fields: [data]}\n"


def _stamp(t: float) -> dict[str, Any]:
    sec = int(t)
    return {"header": {"stamp": {"sec": sec, "nanosec": round((t - sec) * 1e9)}}}


def _msg(topic: str, source: float, stamp: float | None, **fields: Any) -> dict[str, Any]:
    return {"topic": topic, "time": source, **(_stamp(stamp) if stamp is not None else {}), **fields}


def _workspace(tmp: Path, rcl: str, lines: list[dict[str, Any]], mapping: str = MAPPING) -> tuple[Path, Path]:
    (tmp / "contracts").mkdir(exist_ok=True)
    (tmp / "contracts" / "c.rcl").write_text(rcl)
    (tmp / "contracts" / "plan.yaml").write_text("contracts: [contracts/c.rcl]\n")
    (tmp / "mapping.yaml").write_text(mapping)
    run = tmp / "run.jsonl"
    run.write_text("".join(json.dumps(x) + "\n" for x in lines))
    return tmp, run


def _offline(ws: Path, run: Path, node: str) -> tuple[list[str], list[dict[str, int]]]:
    """The recorded path's statuses (the node's, then its deadlines') and deadline counts."""
    checked = load([ws / "contracts" / "c.rcl"])
    cfg = load_mapping(ws, "mapping.yaml")
    got = recorded.check_recorded(checked, [checked.nodes[node]], cfg, ws, str(run), lambda w: None)
    return ([got.verdict(r, str(run))[0] for r in got.results] +
            [deadline_status(d, str(run))[0] for d in got.deadlines], [dict(d.counts) for d in got.deadlines])


def _live(ws: Path, heard: list[tuple[float, dict[str, Any]]], node: str, window: float = 0.05,
          period: float = 0.01) -> tuple[list[DeadlineVerdict], dict[str, int], OnlineEngine]:
    """The live engine fed ``heard`` (arrival time, log line) in arrival order, its timer
    ticking every ``period`` s; the node's deadline monitor fed what the engine releases."""
    checked = load([ws / "contracts" / "c.rcl"])
    rules = load_mapping(ws, "mapping.yaml").rules
    verdicts: list[DeadlineVerdict] = []
    dm = DeadlineMonitor(checked, checked.nodes[node], rules, verdicts.append, horizon=2.0)
    eng = OnlineEngine(checked, [checked.nodes[node]], rules, 2.0, reorder_window=window, on_event=dm.feed)
    now = min(a for a, _ in heard)
    for arrival, line in sorted(heard, key=lambda x: x[0]):
        while now + period <= arrival:
            now += period
            eng.tick(now)
            dm.advance(now - window)
        fields = {k: v for k, v in line.items() if k not in ("topic", "time")}
        eng.push(line["topic"], fields, line["time"])
    for _ in range(40):
        now += period
        eng.tick(now)
        dm.advance(now - window)
    eng.finish()
    return verdicts, dm.finish().counts, eng


# -- a relay copying its question's stamp, its answer heard after the watermark passed the deadline ----------

def _relay(answer_source: float, answer_stamp: float, value: bool = True) -> list[dict[str, Any]]:
    return [_msg("b", 1.0, 1.0, data=True), _msg("stop", answer_source, answer_stamp, data=value),
            _msg("tick", 1.5, None, data=0)]


def test_a_stamp_copying_answer_heard_late_meets_its_deadline_live_as_offline(tmp_path: Path) -> None:
    """The relay answered at 1.05 s (source time), copying the question's stamp
    1.0 s; the answer reached the monitor at 1.3 s, after the watermark (the
    clock less 50 ms) had passed the deadline 1.1 s.  Before: live ``false``,
    "answered after 0 ms, -100 ms past the deadline"; offline met."""
    lines = _relay(1.05, 1.0)
    ws, run = _workspace(tmp_path, RELAY, lines)
    statuses, counts = _offline(ws, run, "Relay")
    assert counts == [{"true": 1, "currently_false": 0, "false": 0}]
    assert statuses[-1] == "discharged"
    verdicts, live, eng = _live(ws, [(1.0, lines[0]), (1.3, lines[1]), (1.5, lines[2])], "Relay")
    assert eng.late == 1  # it did come after the watermark
    assert live == counts[0]
    assert [v.verdict for v in verdicts][:2] == ["false", "true"]  # the clock's false, withdrawn by the answer
    assert "met on the answer's own stamp" in verdicts[-1].reason and "-100 ms" not in verdicts[-1].reason


@pytest.mark.parametrize("lines, why", [
    (_relay(1.25, 1.25), "its own stamp is past the deadline"),
    (_relay(1.05, 1.0, value=False), "a wrong answer, stamp copied"),
])
def test_the_controls_a_late_stamp_or_a_wrong_answer_stay_false(tmp_path: Path, lines: list[dict[str, Any]],
                                                                 why: str) -> None:
    ws, run = _workspace(tmp_path, RELAY, lines)
    statuses, counts = _offline(ws, run, "Relay")
    assert counts == [{"true": 0, "currently_false": 0, "false": 1}], why
    assert statuses[-1] == "failed", why
    _, live, _ = _live(ws, [(1.0, lines[0]), (1.3, lines[1]), (1.5, lines[2])], "Relay")
    assert live == counts[0], why


def test_a_stamp_copying_answer_heard_in_time_is_met_without_a_false(tmp_path: Path) -> None:
    # the correct relay heard within the lateness bound of its (copied) stamp: met, no false ever given
    lines = _relay(1.02, 1.0)
    ws, _ = _workspace(tmp_path, RELAY, lines)
    verdicts, live, eng = _live(ws, [(1.0, lines[0]), (1.03, lines[1]), (1.5, lines[2])], "Relay")
    assert eng.late == 0 and [v.verdict for v in verdicts][0] == "true" and live["true"] == 1
