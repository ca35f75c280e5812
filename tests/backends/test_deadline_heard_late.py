"""Issue 106: a deadline decided live as offline when its answer is heard later than the lateness bound.

A relay answers its trigger (stamped 1.0 s, deadline 100 ms); the answer
reaches the monitor at 1.3 s, after the watermark (the clock less the 50 ms
bound) had passed the deadline, so the live monitor had already judged the
trigger ``false``.  What the answer's own stamp says decides, live as on the
run's log (docs/semantics.md, "Deadlines"): stamped within the transport
skew before its trigger and satisfying the guarantee it may be the trigger's
answer, so the deadline is ``undecided`` (before: ``false`` live, with a
header stamp; ``true`` live, without one, the late message put at the clock);
stamped within the deadline it is met.  Controls: an answer stamped after the
deadline, a wrong answer, and one stamped beyond the skew before its trigger
stay ``false`` live and offline.

Each run goes through the live run (:class:`rclverify.runtime.live.LiveRun`:
the online engine with its lateness bound, its timer ticking every 10 ms,
the deadline monitors fed what it releases and writes to its log), and the
offline check reads both the run as published and the live run's own log: the same deadline
counts and, trigger by trigger, the same final verdict (an undecided trigger's is ``undecided``).
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from rclverify.backends.monitors import recorded
from rclverify.backends.monitors.config import load_mapping
from rclverify.lang.typecheck import load
from rclverify.runtime.live import LiveRun

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
WINDOW = 0.05


def _stamp(t: float) -> dict[str, Any]:
    sec = int(t)
    return {"header": {"stamp": {"sec": sec, "nanosec": round((t - sec) * 1e9)}}}


def _line(topic: str, source: float, stamp: float | None, value: Any) -> dict[str, Any]:
    return {"topic": topic, "time": source, **(_stamp(stamp) if stamp is not None else {}), "data": value}


def _workspace(tmp: Path) -> Path:
    (tmp / "contracts").mkdir()
    (tmp / "contracts" / "c.rcl").write_text(RELAY)
    (tmp / "contracts" / "plan.yaml").write_text("contracts: [contracts/c.rcl]\n")
    (tmp / "mapping.yaml").write_text(MAPPING)
    return tmp


def _final(verdicts: list[dict[str, Any]]) -> dict[float, str]:
    """Each trigger's final deadline verdict (its last record: an update replaces the verdict before it)."""
    return {v["trigger_stamp"]: v["verdict"] for v in verdicts}


def _offline(ws: Path, run: Path) -> tuple[dict[str, int], dict[str, int], dict[float, str]]:
    """The deadline counts, the triggers given no verdict and each trigger's final verdict, as
    ``rclverify monitor RUN`` judges ``run``."""
    checked = load([ws / "contracts" / "c.rcl"])
    seen: list[dict[str, Any]] = []

    def verdict(kind: str, v: Any, _: float | None) -> None:
        if kind == "deadline":
            seen.append(v.to_json())
    got = recorded.check_recorded(checked, [checked.nodes["Relay"]], load_mapping(ws, "mapping.yaml"), ws, str(run),
                                  lambda w: None, on_verdict=verdict)
    (res,) = got.deadlines
    return dict(res.counts), dict(res.unaccepted), _final(seen)


def _live(ws: Path, heard: list[tuple[float, dict[str, Any]]]) -> tuple[dict[str, int], dict[str, int],
                                                                         list[dict[str, Any]], Path]:
    """The live run fed ``heard`` (arrival time, line) in arrival order, its timer every 10 ms:
    the deadline counts, the triggers given no verdict, the deadline verdicts published, its log."""
    checked = load([ws / "contracts" / "c.rcl"])
    cfg = load_mapping(ws, "mapping.yaml")
    log = ws / "live" / "live.jsonl"
    published: list[str] = []
    run = LiveRun(checked, [checked.nodes["Relay"]], cfg.rules, 2.0, log, reorder_window=WINDOW,
                  publish=published.append)
    now = heard[0][0]
    for arrival, line in heard:
        while now + 0.01 <= arrival + 1e-9:
            now += 0.01
            run.tick(now)
        run.push(line["topic"], {k: v for k, v in line.items() if k not in ("topic", "time")}, line["time"])
    for _ in range(30):
        now += 0.01
        run.tick(now)
    record = run.stop()
    (dl,) = record["topic_deadlines"]
    verdicts = [m for m in map(json.loads, published) if m.get("kind") == "deadline"]
    return dl["deadlines"]["counts"], dl["deadlines"]["unaccepted"], verdicts, log


def _judged(tmp: Path, lines: list[dict[str, Any]], heard_at: list[float]) -> dict[str, Any]:
    """``lines`` (trigger, answer, a later message) heard at ``heard_at``: live, offline on the run as
    published and offline on the live run's log."""
    ws = _workspace(tmp)
    published = ws / "run.jsonl"
    published.write_text("".join(json.dumps(x) + "\n" for x in sorted(lines, key=lambda x: x["time"])))
    counts, unaccepted, verdicts, log = _live(ws, sorted(zip(heard_at, lines), key=lambda x: x[0]))
    return {"live": (counts, unaccepted, _final(verdicts)), "offline": _offline(ws, published),
            "log": _offline(ws, log), "verdicts": verdicts}


#: (deadline counts, triggers given no verdict, the trigger's final verdict) of each outcome
UNDECIDED = ({"true": 0, "currently_false": 0, "false": 0},
             {"assumption violated": 0, "incomplete input": 0, "undecided": 1}, {1.0: "undecided"})
MET = ({"true": 1, "currently_false": 0, "false": 0},
       {"assumption violated": 0, "incomplete input": 0, "undecided": 0}, {1.0: "true"})
FALSE = ({"true": 0, "currently_false": 0, "false": 1},
         {"assumption violated": 0, "incomplete input": 0, "undecided": 0}, {1.0: "false"})


def _relay(answer_source: float, answer_stamp: float | None, value: bool = True,
           trigger_stamped: bool = True) -> list[dict[str, Any]]:
    return [_line("b", 1.0, 1.0 if trigger_stamped else None, True), _line("stop", answer_source, answer_stamp, value),
            _line("tick", 1.6, None, 0)]


@pytest.mark.parametrize("lines", [
    _relay(1.0005, 0.9997),  # stamped 0.3 ms before its trigger, published just after it
    _relay(0.9997, None),    # no header: its source time 0.3 ms before the trigger's
], ids=["header stamp", "source time"])
def test_an_answer_stamped_within_the_skew_before_its_trigger_heard_late_is_undecided_live_as_offline(
        tmp_path: Path, lines: list[dict[str, Any]]) -> None:
    """Before: live ``false`` (the watermark passed the deadline first; the answer, stamped before the
    trigger, answered nothing) or ``true`` (a late message without a header put at the clock, after the
    trigger); offline undecided."""
    got = _judged(tmp_path, lines, [1.0, 1.3, 1.6])
    assert got["offline"] == UNDECIDED and got["log"] == UNDECIDED
    assert got["live"] == UNDECIDED
    # the clock's false, given before the answer was heard, withdrawn by an update saying why
    given, revised = got["verdicts"]
    assert given["verdict"] == "false" and not given["update"], got["verdicts"]
    assert revised["update"] and revised["verdict"] == "undecided", got["verdicts"]
    assert "within the transport skew" in revised["reason"] and "withdrawn" in revised["reason"]


@pytest.mark.parametrize("lines", [_relay(1.05, None), _relay(1.05, 1.0)], ids=["source time", "copied stamp"])
def test_an_answer_stamped_within_the_deadline_heard_late_meets_it_live_as_offline(
        tmp_path: Path, lines: list[dict[str, Any]]) -> None:
    got = _judged(tmp_path, lines, [1.0, 1.3, 1.6])
    assert got["offline"] == MET and got["log"] == MET and got["live"] == MET


def test_a_trigger_heard_late_after_its_answer_is_met_on_its_source_time_live_as_offline(tmp_path: Path) -> None:
    """The trigger, without a header, heard 300 ms after its source time, its answer 20 ms after it heard in
    time: met on the trigger's own time.  Before: live ``false`` (its deadline run from the clock)."""
    lines = _relay(1.02, None, trigger_stamped=False)
    got = _judged(tmp_path, lines, [1.3, 1.021, 1.6])
    assert got["offline"] == MET and got["log"] == MET and got["live"] == MET


@pytest.mark.parametrize("lines, why", [
    (_relay(1.25, 1.25), "stamped after the deadline"),
    (_relay(1.25, None), "published after the deadline, no header"),
    (_relay(1.0005, 0.9997, value=False), "a wrong answer within the skew"),
    (_relay(1.0005, 0.97), "stamped 30 ms before the trigger, beyond the 20 ms skew"),
])
def test_the_controls_late_wrong_or_beyond_the_skew_stay_false_live_as_offline(
        tmp_path: Path, lines: list[dict[str, Any]], why: str) -> None:
    got = _judged(tmp_path, lines, [1.0, 1.3, 1.6])
    assert got["offline"] == FALSE and got["log"] == FALSE, why
    assert got["live"] == FALSE, why
