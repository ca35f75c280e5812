"""The batch path's space margins (backends/monitors/batch.py, targets/column_margins.py) against the
streaming engine's (judging.py, semantics/robustness.py), their oracle.

On random runs of small eligible contracts (a band classifier, a linear bound
with inexact literals and two guarantees, a stop distance in metres, an
output-only bound alone and beside a guarantee on a question, an equality,
held without a distance), values on and next to the
boundaries, answers right, wrong, late, missing and out of order, the batch
path with margins gives exactly the streaming engine's verdicts, each with
the same margin, and the same smallest margin per guarantee (value, atom,
unit, message, count).  The control turns the columns' ``and`` into a
maximum and finds the two apart.  A long run with 20 % of its answers
violated, past the violation records and margins a run keeps (answers
missing, late or heard early among them), gives the
engine's result with and without a verdict callback, with and without a
transport skew (a violated answer is held for it).
"""
from __future__ import annotations

import random
from typing import Any

import pytest
from _classifier import CLASSIFIER

from rclverify.backends.monitors.batch import check_batch
from rclverify.backends.monitors.check import check_trace
from rclverify.backends.monitors.verdicts import KEPT_VIOLATIONS
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check
from rclverify.targets import column_margins
from rclverify.traces.events import Event
from rclverify.traces.mapping import load_rules

CONTRACTS = "\n" + CLASSIFIER + """node Linear {
  inputs( a : REAL, b : REAL )
  outputs( y : REAL )
  topics( std_msgs/Float64 a matches(in.a), std_msgs/Float64 b matches(in.b), std_msgs/Float64 y matches(out.y) )
  guarantee( out.y <= 0.1 * in.a + in.b )
  guarantee( out.y >= in.a - 30 - in.b * 2 or not (out.y != 7) )
}
node Stop {
  inputs( r : REAL [m] )
  outputs( d : REAL [m] )
  topics( std_msgs/Float64 range matches(in.r), std_msgs/Float64 dist matches(out.d) )
  guarantee( in.r - 2 <= out.d <= in.r - 0.5 )
}
node Ceiling {
  inputs( r : REAL [m] )
  outputs( d : REAL [m] )
  topics( std_msgs/Float64 range matches(in.r), std_msgs/Float64 dist matches(out.d) )
  guarantee( out.d <= 4.5 )
}
node Both {
  inputs( r : REAL [m] )
  outputs( d : REAL [m] )
  topics( std_msgs/Float64 range matches(in.r), std_msgs/Float64 dist matches(out.d) )
  guarantee( out.d <= 4.5 and out.d != 3.25 )
  guarantee( in.r - 2 <= out.d )
}
node Echo {
  inputs( r : REAL )
  outputs( d : REAL )
  topics( std_msgs/Float64 range matches(in.r), std_msgs/Float64 dist matches(out.d) )
  guarantee( out.d == in.r )
}
"""
CHECKED = check([parse_text(CONTRACTS)])
RULES = load_rules({t: {"fields": ["data"]} for t in ("reading", "status", "a", "b", "y", "range", "dist")})


def _band(r: float) -> str:
    return "green" if r < 120 else "orange" if r < 250 else "red"


def _run(rnd: random.Random, node: str) -> list[Event]:
    events: list[Event] = []
    t = 0.0

    def add(topic: str, value: Any, time: float) -> None:
        events.append(Event(len(events), time, topic, {"data": value}, f"run.jsonl:{len(events) + 1}"))
    a = b = 1.0
    for _ in range(rnd.randint(20, 400)):
        t += rnd.choice([0.01, 0.01, 0.01, 0.004, 0.05])
        odd = rnd.random()
        if node == "Classifier":
            r = rnd.choice([rnd.uniform(0, 400), 120.0, 119.99999999999999, 250.0])
            add("reading", r, t)
            answer = _band(r) if odd < 0.9 else rnd.choice(["green", "orange", "red"])
            if odd < 0.97:
                add("status", answer, t + rnd.choice([0.0, 0.001]))
        elif node == "Linear":
            if rnd.random() < 0.5:
                a = rnd.choice([rnd.uniform(-60, 60), 10.0, 0.1])
                add("a", a, t)
            else:
                b = rnd.choice([rnd.uniform(-10, 110), 0.0, 1.0])
                add("b", b, t)
            y = rnd.choice([0.1 * a + b - rnd.uniform(0, 5), 0.1 * a + b, 7.0, rnd.uniform(-100, 100)])
            if odd < 0.95:
                add("y", y, t + rnd.choice([0.0, 0.001]))
        else:
            r = rnd.choice([rnd.uniform(0, 5), 0.5, 2.0])
            add("range", r, t)
            d = rnd.choice([r - 0.5, r - 0.5 - rnd.uniform(0, 1), r, r - 0.5 + 1e-15]) if node == "Stop" else \
                rnd.choice([r - 0.5, r - 2.5, r, 4.5, 3.25, 4.5 + 1e-15]) if node in ("Ceiling", "Both") else \
                rnd.choice([r, r, r + 1e-9])
            if odd < 0.95:
                add("dist", d, t + rnd.choice([0.0, 0.001]))
        if odd > 0.98 and len(events) > 2:  # heard out of order
            events[-1], events[-2] = events[-2], events[-1]
    return events


def _both(node: str, events: list[Event]) -> tuple[Any, Any, int]:
    streamed: list[Any] = []
    _, (s_res,) = check_trace(CHECKED, [CHECKED.nodes[node]], iter(events), RULES, 0.1, streamed.append,
                              batch=False, margins=True)
    batched: list[Any] = []
    stats: dict[str, int] = {}
    done = check_batch(CHECKED, CHECKED.nodes[node], iter(events), RULES, 0.1, batched.append, chunk=64,
                       stats=stats, margins=True)
    assert done is not None, f"{node} should be eligible"
    return (streamed, s_res), (batched, done[1]), stats["batched"]


def _margins(res: Any) -> dict[int, Any]:
    return {k: (m.value, m.unit, m.atom, m.event, m.where, m.question, m.answers, m.lowest) for k, m in res.margins.items()}


@pytest.mark.parametrize("node", ["Classifier", "Linear", "Stop", "Ceiling", "Both", "Echo"])
def test_batch_margins_are_the_engines(node: str) -> None:
    rnd = random.Random(f"margins-{node}")
    batched_rows = 0
    for _ in range(12):
        events = _run(rnd, node)
        (seen_s, res_s), (seen_b, res_b), batched = _both(node, events)
        batched_rows += batched
        assert seen_b == seen_s  # verdicts, order, reasons and margins
        assert res_b == res_s and _margins(res_b) == _margins(res_s)
        assert any(v.margin is not None for v in seen_s)
    assert batched_rows > 300  # Echo too: a satisfied equality holds without a distance, not at the boundary


def test_units_and_atoms_from_the_columns() -> None:
    events = [Event(0, 1.0, "range", {"data": 3.0}, "r:1"), Event(1, 1.0, "dist", {"data": 2.25}, "r:2"),
              Event(2, 2.0, "range", {"data": 2.0}, "r:3"), Event(3, 2.0, "dist", {"data": 1.0}, "r:4")]
    (_, res_s), (seen_b, res_b), batched = _both("Stop", events)
    assert batched == 2 and [v.margin for v in seen_b] == [0.25, 0.5]
    assert (res_b.margins[1].value, res_b.margins[1].unit, res_b.margins[1].atom) == (0.25, "m", "out.d <= in.r - 0.5")


def test_output_only_guarantee_in_batches() -> None:
    # out.d <= 4.5 reads no input: judged on each answer as the outputs stand, its margin on no question
    events = [Event(2 * i + j, float(i), topic, {"data": v}, f"r:{2 * i + j + 1}")
              for i, (r, d) in enumerate([(3.0, 2.25), (9.0, 4.0), (1.0, 0.5)])
              for j, (topic, v) in enumerate((("range", r), ("dist", d)))]
    (seen_s, res_s), (seen_b, res_b), batched = _both("Ceiling", events)
    assert batched == 3 and seen_b == seen_s and res_b == res_s and _margins(res_b) == _margins(res_s)
    assert [(v.verdict, v.margin, v.question) for v in seen_b] == [
        ("satisfied", 2.25, "r:1"), ("satisfied", 0.5, "r:3"), ("satisfied", 4.0, "r:5")]
    assert (res_b.margins[1].value, res_b.margins[1].where, res_b.margins[1].question) == (0.5, "r:4", "")


def test_control_a_wrong_column_and_is_caught(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(column_margins, "_min", column_margins._max)
    rnd = random.Random("control")
    differ = 0
    for _ in range(5):
        (seen_s, _), (seen_b, _), _ = _both("Classifier", _run(rnd, "Classifier"))
        differ += sum(a.margin != b.margin for a, b in zip(seen_s, seen_b))
    assert differ > 0


def _long_run(rnd: random.Random, pairs: int, wrong: float, node: str = "Stop", odd: float = 0.0) -> list[Event]:
    """``pairs`` answered readings of Stop (or Ceiling), a fraction ``wrong`` of the answers violated (below
    the lower bound, or above the ceiling); with probability ``odd`` each an answer is missing, late (after
    the horizon), or heard before its reading."""
    events: list[Event] = []

    def add(topic: str, v: float, t: float) -> None:
        events.append(Event(len(events), t, topic, {"data": v}, f"run.jsonl:{len(events) + 1}"))
    for i in range(pairs):
        r = rnd.uniform(2, 5)
        d = rnd.uniform(r - 2, min(r - 0.5, 4.4))
        if rnd.random() < wrong:
            d = r - 2 - rnd.uniform(0.01, 1) if node == "Stop" else 4.5 + rnd.uniform(0.01, 1)
        t = 0.01 * i
        add("range", r, t)
        kind = rnd.random() / odd if odd else 3.0
        if kind >= 1:  # answered
            add("dist", d, t + 0.001)
        elif kind < 0.5:  # heard before its reading (stamped after it)
            add("dist", d, t + 0.001)
            events[-1], events[-2] = events[-2], events[-1]
        if 0.5 <= kind < 0.75:  # late: after the horizon (heard at once)
            add("dist", d, t + 0.15)
    return events


@pytest.mark.parametrize("node,margins,skew,odd", [("Stop", True, 0.0, 0.0), ("Stop", False, 0.0, 0.0),
                                                   ("Ceiling", True, 0.0, 0.0), ("Stop", True, 0.02, 0.0),
                                                   ("Stop", True, 0.02, 0.05), ("Ceiling", False, 0.02, 0.05)])
def test_many_violations_beyond_the_kept_ones(node: str, margins: bool, skew: float, odd: float) -> None:
    # 1,500 answers, 20 % violated: past the 200 violation records and 256 margins kept, with and without a
    # verdict callback, the batch path's result (counts, records, kept margins) is the engine's; without a
    # callback the violations are judged in batches too, the kept records written as the engine writes them
    events = _long_run(random.Random(f"many-{node}-{odd}"), 1500, 0.2, node, odd)
    checked_node = CHECKED.nodes[node]
    rules = load_rules({t: {"fields": ["data"]} for t in ("range", "dist")})
    rules.skew = skew  # a violated answer held for the transport skew (docs/semantics.md), then judged
    seen_s: list[Any] = []
    _, (res_s,) = check_trace(CHECKED, [checked_node], iter(events), rules, 0.1, seen_s.append, batch=False,
                              margins=margins)
    _, (quiet_s,) = check_trace(CHECKED, [checked_node], iter(events), rules, 0.1, batch=False, margins=margins)
    seen_b: list[Any] = []
    stats: dict[str, int] = {}
    loud = check_batch(CHECKED, checked_node, iter(events), rules, 0.1, seen_b.append, margins=margins)
    quiet = check_batch(CHECKED, checked_node, iter(events), rules, 0.1, stats=stats, margins=margins, chunk=512)
    assert loud is not None and quiet is not None
    assert res_s.counts["violated"] > 250 and res_s.violations_dropped > 50
    assert len(res_s.margins[1].lowest) == 256 if margins else not res_s.margins
    assert seen_b == seen_s
    for res in (quiet_s, loud[1], quiet[1]):
        assert res == res_s and _margins(res) == _margins(res_s)
    if odd:  # answers missing, late or heard early: the engine's
        assert stats["batched"] > 600
    elif node == "Ceiling":  # the kept violations of an output-only guarantee: the engine renders them
        assert stats["streamed"] == 2 * KEPT_VIOLATIONS
    elif not skew:  # a guarantee on a question: its kept records are written in batch too (batch_violations.py)
        assert stats["streamed"] == 0
    else:  # and a violated answer held for the skew past the end of its run of pairs, with the pairs it holds up
        assert stats["streamed"] < 2 * KEPT_VIOLATIONS + 0.2 * len(events)
