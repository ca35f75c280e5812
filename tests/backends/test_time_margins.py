"""Time margins of `triggered by ... within` deadlines on runs (backends/monitors/deadlines.py,
docs/semantics.md "Margins"): the deadline less the answer's stamp, per answer
(negative when late) and the smallest per guarantee, exact in integer
nanoseconds.  Controls: the figures of a run are fixed by hand (a margin
computed from the trigger's stamp instead of the deadline, or in doubles,
gives other numbers), and the `0.7 + 0.2` case whose double difference is
not zero."""
from __future__ import annotations

from typing import Any

import pytest

from rclverify.backends.monitors.deadlines import DeadlineMonitor, check_deadlines
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check
from rclverify.traces.events import Event
from rclverify.traces.mapping import load_rules

CONTRACT = """
node Stopper {
  inputs( press : BOOL )
  outputs( stop : BOOL )
  topics( std_msgs/Bool press matches(in.press), std_msgs/Bool stop matches(out.stop) )
  guarantee( in.press -> out.stop ) triggered by in.press within 200 ms
}
"""
CHECKED = check([parse_text(CONTRACT)])
NODE = CHECKED.nodes["Stopper"]
RULES = load_rules({"press": {"fields": ["data"]}, "stop": {"fields": ["data"]}})


def _run(script: list[tuple[float, str, bool]], end: float | None = None) -> tuple[Any, list[Any]]:
    seen: list[Any] = []
    events = [Event(i, t, topic, {"data": v}, f"run.jsonl:{i + 1}") for i, (t, topic, v) in enumerate(script)]
    mon = DeadlineMonitor(CHECKED, NODE, RULES, seen.append)
    for ev in events:
        mon.feed(ev)
    if end is not None:
        mon.advance(end)
    return mon.finish(), seen


def test_each_answer_and_the_smallest() -> None:
    # answered after 50 ms (150 ms to spare), after 190 ms (10 ms), after 350 ms (150 ms late), never answered
    res, seen = _run([(1.0, "press", True), (1.05, "stop", True), (2.0, "press", True), (2.19, "stop", True),
                      (3.0, "press", True), (3.35, "stop", True), (4.0, "press", True)], end=4.5)
    got = [(v.verdict, v.update, v.answer_where, v.time_margin) for v in seen]
    assert got == [("true", False, "run.jsonl:2", pytest.approx(0.15)), ("true", False, "run.jsonl:4", pytest.approx(0.01)),
                   ("false", False, "run.jsonl:6", pytest.approx(-0.15)), ("false", False, "", None)]
    (m,) = res.to_json()["time_margins"]
    assert (m["margin_ns"], m["trigger_where"], m["answer_where"], m["answers"], m["unanswered"]) == \
        (-150_000_000, "run.jsonl:5", "run.jsonl:6", 3, 1)
    assert seen[2].to_json()["time_margin"] == pytest.approx(-0.15) and "time_margin" not in seen[3].to_json()


def test_a_late_answer_after_the_expiry_replaces_unanswered() -> None:
    res, seen = _run([(1.0, "press", True), (1.3, "press", False), (1.35, "stop", True)])
    assert [(v.verdict, v.update) for v in seen][:2] == [("false", False), ("false", True)]
    assert seen[1].time_margin == pytest.approx(-0.15)
    m = res.time_margins[1]
    assert (m.margin_ns, m.answers, m.unanswered) == (-150_000_000, 2, 0)  # the release answered in time too


def test_in_time_only_and_exact_at_the_deadline() -> None:
    """0.7 + 0.2 is 0.8999999999999999 in doubles: the answer at 0.9 s is exactly on time, margin 0."""
    res, seen = _run([(0.7, "press", True), (0.9, "stop", True), (1.0, "press", True), (1.1, "stop", True)])
    assert [v.verdict for v in seen] == ["true", "true"]
    assert seen[0].time_margin == 0.0 and (0.7 + 0.2) - 0.9 != 0  # the control: doubles would not give 0
    (m,) = res.to_json()["time_margins"]
    assert (m["margin_ns"], m["answers"], m["unanswered"], m["answer_where"]) == (0, 2, 0, "run.jsonl:2")


def test_still_open_at_the_end_is_unanswered_not_a_number() -> None:
    res, seen = _run([(1.0, "press", True), (1.05, "stop", True), (2.0, "press", True)])
    (m,) = res.to_json()["time_margins"]
    assert (m["margin"], m["answers"], m["unanswered"]) == (pytest.approx(0.15), 1, 1)
    assert [v.verdict for v in seen] == ["true", "currently_false"]


def test_check_deadlines_carries_them() -> None:
    events = [Event(0, 1.0, "press", {"data": True}, "a:1"), Event(1, 1.2, "stop", {"data": True}, "a:2")]
    (res,) = check_deadlines(CHECKED, [NODE], events, RULES)
    assert res.time_margins[1].margin_ns == 0 and res.time_margins[1].answers == 1
