"""Surely violated answers judged in batch from the first one on (backends/monitors/batch_violations.py):
the violation records the batch path writes against the streaming engine's, their oracle.

With no verdict callback and one guarantee read against a question, the
batch path takes a surely violated answer pair in batch before the run's
200 violation records are full too, writing each record as the engine
writes it (its output, guarantee, formula, the rendered values of the
question and its answer, the reason, the semantics, the question).  On
runs of windowed formulas (``G[0,2]``, until) and of two pointwise bounds
(one with an inexact literal, whose violations are false in exact and
double arithmetic), a third to a half of the answers
violated, now and then an answer missing, late or unreadable, skew 0 and
20 ms, margins on and off, chunks of 5 events up, now and then a message heard
later than the lateness bound (``late_s``), the batch path's result
(counts, every record, the smallest margins) equals the streaming engine's
and the violated pairs are not streamed.  Controls: records worded without
the arithmetics that agreed, and records rendering the values of the
question before, are caught.  A window whose inexact literal sends a false
answer to the double reading, which enumerates no ``<lo upto hi>``, is
``inconclusive`` for the engine: those answers stay the engine's.  With a declared tolerance a surely false
answer may hold within it: such a node's violations stay the engine's,
and the result is the engine's; the control, the batch path counting them
violated as it did, is caught; so is a batch path ignoring a row's lateness.
"""
from __future__ import annotations

import math
import random
from typing import Any

import pytest

from _late import heard_late
from rclverify.backends.monitors import batch as batch_module
from rclverify.backends.monitors import batch_violations
from rclverify.backends.monitors.answered import AnsweredRun
from rclverify.backends.monitors.batch import check_batch
from rclverify.backends.monitors.check import check_trace
from rclverify.backends.monitors.verdicts import KEPT_VIOLATIONS
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check
from rclverify.semantics.floatsem import parse_tolerance
from rclverify.traces.events import Event
from rclverify.traces.mapping import load_rules

NODES = """
node G {
  inputs( r : REAL )
  outputs( x : NATURAL --> REAL )
  topics( std_msgs/Float64 q matches(in.r), std_msgs/Float64MultiArray a matches(out.x) )
  guarantee( forall(k in <0 upto 2> | out.x(k) > in.r) )
}
node F {
  inputs( r : REAL )
  outputs( x : NATURAL --> REAL )
  topics( std_msgs/Float64 q matches(in.r), std_msgs/Float64MultiArray a matches(out.x) )
  guarantee( exists(k in <0 upto 2> | out.x(k) >= in.r + 0.1) )
}
node U {
  inputs( x : NATURAL --> REAL )
  outputs( y : NATURAL --> REAL )
  topics( std_msgs/Float64MultiArray q matches(in.x), std_msgs/Float64MultiArray a matches(out.y) )
  guarantee( exists(j in <0 upto 3> | out.y(j) > 4 and forall(i in <0 upto 3> | i < j -> in.x(i) > 1)) )
}
node P {
  inputs( r : REAL )
  outputs( y : REAL )
  topics( std_msgs/Float64 q matches(in.r), std_msgs/Float64 a matches(out.y) )
  guarantee( out.y <= in.r - 0.1 )
}
node B {
  inputs( r : REAL )
  outputs( y : REAL )
  topics( std_msgs/Float64 q matches(in.r), std_msgs/Float64 a matches(out.y) )
  guarantee( out.y <= in.r )
}
"""
CHECKED = check([parse_text(NODES)])
RULES = {"q": {"fields": ["data"]}, "a": {"fields": ["data"]}}


def _question(rnd: random.Random, node: str) -> Any:
    return [round(rnd.uniform(0.0, 2.0), 3) for _ in range(4)] if node == "U" else round(rnd.uniform(0.5, 2.0), 3)


def _answer(rnd: random.Random, node: str, q: Any) -> Any:
    """An answer to ``q``: right or wrong about half the time each."""
    if node in ("B", "P"):
        return q - rnd.choice([0.25, -0.25, 0.5])
    if node == "U":
        return [round(rnd.uniform(0.0, 8.0), 3) for _ in range(4)]
    return [round(q + rnd.uniform(-0.3, 0.6), 3) for _ in range(3)]


def _run(rnd: random.Random, node: str, pairs: int, odd: float) -> list[Event]:
    """``pairs`` questions 10 ms apart, each answered 1 ms later; with probability ``odd`` the answer is
    missing, late (past the horizon) or unreadable (NaN)."""
    events: list[Event] = []

    def add(topic: str, value: Any, t: float) -> None:
        events.append(Event(len(events), t, topic, {"data": value}, f"run.jsonl:{len(events) + 1}"))
    for i in range(pairs):
        t = round(0.01 * i, 6)
        q = _question(rnd, node)
        add("q", q, t)
        a = _answer(rnd, node, q)
        kind = rnd.random()
        if kind < odd / 3:
            continue
        if kind < 2 * odd / 3:
            add("a", a, t + 0.008)
            continue
        if kind < odd:
            a = math.nan if node in ("B", "P") else [math.nan] * len(a)
        add("a", a, round(t + 0.001, 6))
    return events


def _both(node: str, events: list[Event], skew: float, margins: bool, chunk: int, tolerance: Any = None
          ) -> tuple[Any, Any, dict[str, int]]:
    rules = load_rules(RULES)
    rules.skew = skew
    _, (streamed,) = check_trace(CHECKED, [CHECKED.nodes[node]], iter(events), rules, 0.005, None, tolerance,
                                 batch=False, margins=margins)
    stats: dict[str, int] = {}
    done = check_batch(CHECKED, CHECKED.nodes[node], iter(events), rules, 0.005, None, tolerance, chunk=chunk,
                       stats=stats, margins=margins)
    assert done is not None, f"{node} should be eligible"
    return streamed, done[1], stats


@pytest.mark.parametrize("node", ["G", "U", "B", "P"])
def test_records_written_in_batch_are_the_engines(node: str) -> None:
    rnd = random.Random(f"violations-{node}")
    for case in range(5):
        skew, margins = (0.0, 0.02)[case % 2], case < 2
        odd = (0.0, 0.04)[case // 2 % 2]
        chunk = (rnd.choice([64, 700, 65536]), 5)[case // 4]  # (5: runs of two pairs, fed to the engine whole)
        events = _run(rnd, node, 900, odd)
        if odd:  # now and then a message heard later than the lateness bound: its pair is the engine's
            events = heard_late(events, random.Random(f"late-{node}-{case}"), 0.02)
        s, b, stats = _both(node, events, skew, margins, chunk)
        where = f"case {case}: skew {skew}, margins {margins}, odd {odd}, chunk {chunk}"
        assert s.counts["violated"] > KEPT_VIOLATIONS + 50, where  # past the kept records
        assert len(s.violations) == KEPT_VIOLATIONS
        assert b == s, where  # counts, every record (values, reason, semantics, question), margins
        if chunk == 5 or odd:  # (odd answers: their pairs streamed, and runs short enough to stream whole)
            continue
        if not skew:  # every violated pair in batch, its record written there
            assert stats["streamed"] <= 2, where
        else:  # a violated answer held past the end of its run of pairs streamed, with the pairs within the skew
            # after it (often here: a third or more of the answers violated)
            assert stats["streamed"] < len(events) / 2, where
        if node == "P":  # the arithmetics that agreed, in the reason and the semantics
            assert s.violations[0]["semantics"] == "exact, double"
            assert s.violations[0]["reason"].endswith("(false in exact and double arithmetic)")


def test_a_window_the_double_reading_cannot_enumerate_stays_the_engines() -> None:
    """F's inexact literal makes the engine read a false window in doubles too, which does not enumerate a
    quantifier over ``<lo upto hi>``: its verdict is ``inconclusive``, never ``violated``, and so the batch
    path's (those answers are streamed)."""
    events = _run(random.Random("violations-F"), "F", 700, 0.0)
    s, b, stats = _both("F", events, 0.0, True, 65536)
    assert s.counts["violated"] == 0 and s.counts["inconclusive"] > 100
    assert b == s and 200 < stats["streamed"] < len(events) / 2


def test_control_a_batch_path_ignoring_lateness_is_caught(monkeypatch: pytest.MonkeyPatch) -> None:
    """Control: with each row's lateness ignored (batch_late.py), a surely violated answer to a question heard
    late is counted ``violated`` in batch, where the engine says ``inconclusive``."""
    events = heard_late(_run(random.Random("violations-late"), "B", 700, 0.0), random.Random("late-B"), 0.02)
    s, b, _ = _both("B", events, 0.0, False, 65536)
    assert b == s and s.counts["inconclusive"] > 0
    monkeypatch.setattr(batch_module, "own_times", lambda chunk: None)
    _, wrong, _ = _both("B", events, 0.0, False, 65536)
    assert wrong.counts["violated"] > s.counts["violated"] and wrong != s


def test_control_records_worded_without_the_arithmetics_are_caught(monkeypatch: pytest.MonkeyPatch) -> None:
    events = _run(random.Random("violations-control"), "P", 700, 0.0)
    s, b, _ = _both("P", events, 0.0, True, 65536)
    assert b == s
    monkeypatch.setattr(batch_violations, "in_all", lambda semantics: "")
    _, wrong, _ = _both("P", events, 0.0, True, 65536)
    assert wrong.counts == s.counts and wrong.violations != s.violations


def test_control_records_of_the_question_before_are_caught(monkeypatch: pytest.MonkeyPatch) -> None:
    events = _run(random.Random("violations-control"), "G", 700, 0.0)
    s, b, _ = _both("G", events, 0.02, False, 65536)
    assert b == s
    real = AnsweredRun.question

    def before(self: Any, j: int, run: Any) -> Any:
        return real(self, max(j - 1, 0), run)
    monkeypatch.setattr(AnsweredRun, "question", before)
    _, wrong, _ = _both("G", events, 0.02, False, 65536)
    assert wrong.counts == s.counts and [v["values"] for v in wrong.violations] != [v["values"] for v in s.violations]


def _near(rnd: random.Random, pairs: int) -> list[Event]:
    """B's answers: a third right, a third wrong, a third above the bound by less than 1e-10 (true within a
    tolerance of 1e-9, surely false in exact arithmetic)."""
    events: list[Event] = []
    for i in range(pairs):
        r = rnd.uniform(1.0, 2.0)
        y = r + (rnd.uniform(1e-12, 1e-10), rnd.uniform(0.1, 1.0), -0.5)[i % 3]
        events.append(Event(len(events), 0.01 * i, "q", {"data": r}, f"run.jsonl:{len(events) + 1}"))
        events.append(Event(len(events), 0.01 * i + 0.001, "a", {"data": y}, f"run.jsonl:{len(events) + 1}"))
    return events


def test_a_tolerance_keeps_near_violations_with_the_engine(monkeypatch: pytest.MonkeyPatch) -> None:
    events = _near(random.Random("tolerance"), 1500)
    tolerance = parse_tolerance({"abs": 1e-9})
    s, b, _ = _both("B", events, 0.0, True, 65536, tolerance)
    assert s.semantics["tolerance"] == 500 and s.counts["violated"] == 500
    assert b == s
    # the control: a batch path blind to the tolerance counts the answers that hold within it violated
    monkeypatch.setattr(batch_module, "float_sensitive", lambda *args, **kwargs: False)
    _, wrong, _ = _both("B", events, 0.0, True, 65536, tolerance)
    assert wrong.counts["violated"] > s.counts["violated"]
