"""Deadlines judged in batch (backends/monitors/batch_deadlines.py) against the streaming deadline
monitor and a brute-force enumeration of the rules, its oracle.

On small random runs (triggers and answers at random whole milliseconds, equal stamps, gaps past
every deadline, answers that do not satisfy the guarantee, triggers the assumption refuses, a run
ending before a deadline, chunks of 1 to 9 events), the batch judge must give exactly the streaming
monitor's verdict list (verdicts, order, reasons, time margins) and result, and each trigger's
verdicts must be those found here by enumerating the run (nothing of rclverify's: for each trigger,
the first later output satisfying the guarantee in exact rationals, the first message past the
deadline).  Runs the batch cannot judge (a stamp going back, a header stamp, NaN, a string, a
topic written with ``/``, a value near a boundary) must still equal the streaming monitor's, in
chunks of both kinds.  Controls: a brute force reading ``within`` as strictly before the deadline
differs on a run answered at the deadline itself, and a batch judge whose expiry includes the
deadline's own stamp is caught.  An enumeration output (a value of no other type now and then) is judged
in batch to the streaming monitor's verdicts too.  The bundled warehouse and delivery runs (a recorded log and two live
monitors' logs, their eligible nodes' deadlines) give the streaming monitor's verdicts too.
"""
from __future__ import annotations

import random
from fractions import Fraction
from pathlib import Path
from typing import Any, Callable

import pytest

from rclverify.backends.monitors import batch_deadline_chunk
from rclverify.backends.monitors.config import load_mapping
from rclverify.backends.monitors.deadline_topics import has_deadlines
from rclverify.backends.monitors.batch_deadlines import BatchDeadlines, deadline_monitor
from rclverify.backends.monitors.deadlines import DeadlineMonitor
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check, load
from rclverify.traces import read_trace
from rclverify.semantics.floatsem import Tolerance
from rclverify.traces.events import Event
from rclverify.traces.mapping import load_rules

NODES = """
context { Level : {lo, hi} ; }
node D {
  inputs( a : REAL )
  outputs( b : REAL )
  topics( std_msgs/Float64 trig matches(in.a), std_msgs/Float64 ans matches(out.b) )
  assume( in.a < 9 )
  guarantee( out.b > in.a ) triggered by in.a within 30 ms
  guarantee( out.b >= in.a + 1 ) triggered by in.a within 50 ms
  guarantee( out.b < 100 ) triggered by in.a
}
node E {
  inputs( r : REAL )
  outputs( s : Level )
  topics( std_msgs/Float64 trig matches(in.r), std_msgs/String ans matches(out.s) )
  guarantee( (in.r < 5 -> out.s == hi) and (in.r >= 5 -> out.s == lo) ) triggered by in.r within 20 ms
}
node Two {
  inputs( a : REAL, c : REAL )
  outputs( b : REAL )
  topics( std_msgs/Float64 trig matches(in.a), std_msgs/Float64 other matches(in.c),
          std_msgs/Float64 ans matches(out.b) )
  guarantee( out.b > in.a + in.c ) triggered by in.a within 30 ms
}
"""
CHECKED = check([parse_text(NODES)])
NODE = CHECKED.nodes["D"]
EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
RULES = load_rules({"trig": {"fields": ["data"]}, "ans": {"fields": ["data"]}, "other": {"fields": ["data"]}})
HORIZON = 0.04
#: guarantee -> (its test on (a, b) in exact rationals, its bound in ms); the third's bound is the horizon
RULES_OF: dict[int, tuple[Callable[[Fraction, Fraction], bool], int]] = {
    1: (lambda a, b: b > a, 30), 2: (lambda a, b: b >= a + 1, 50), 3: (lambda a, b: b < 100, 40)}


def _run(rng: random.Random, n: int, hazards: bool) -> list[Event]:
    """A random run: triggers ``a`` and answers ``b`` at whole milliseconds (equal stamps, gaps past the
    deadlines), values on a quarter grid (exact in doubles); with ``hazards``, messages the batch declines."""
    out: list[Event] = []
    ms = rng.randrange(0, 50)
    a = 1.0
    for i in range(n):
        ms += rng.choice([0, 0, 1, 5, 10, 20, 29, 30, 31, 49, 50, 51, 120])
        t = ms / 1000
        r = rng.random()
        if r < 0.4:
            a = rng.choice([0.0, 0.25, 1.0, 2.5, 8.75, 9.0, 9.5])
            topic, fields = "trig", {"data": a}
        elif r < 0.9:
            topic, fields = "ans", {"data": a + rng.choice([-1.0, 0.0, 0.25, 1.0, 2.0, 200.0])}
        else:
            topic, fields = "tick", {"data": 0.0}
        if hazards and rng.random() < 0.08:
            kind = rng.randrange(6)
            if kind == 0:
                t = max(0.0, t - rng.choice([0.001, 0.03, 0.2]))  # a stamp going back
            elif kind == 1:
                fields = {**fields, "header": {"stamp": {"sec": int(t), "nanosec": int(round(t % 1 * 1e9))}}}
            elif kind == 2:
                fields = {"data": float("nan")}
            elif kind == 3:
                fields = {"data": "high"}
            elif kind == 4:
                topic = "/" + topic
            else:
                fields = {"data": rng.choice([0.1, 1.1, 0.30000000000000004]) + (1.0 if topic == "ans" else 0.0)}
        out.append(Event(i, t, topic, fields, f"run:{i + 1}"))
    return out


def _judge(mon: DeadlineMonitor, run: list[Event], got: list[Any]) -> dict[str, Any]:
    for ev in run:
        mon.feed(ev)
    res = mon.finish()
    return {"verdicts": got, "result": res.to_json()}


def _both(run: list[Event], chunk: int, node: Any = NODE) -> tuple[dict[str, Any], dict[str, Any], BatchDeadlines]:
    """(the streaming monitor's verdicts and result, the batch judge's, the batch judge)."""
    seen: list[Any] = []
    stream = _judge(DeadlineMonitor(CHECKED, node, RULES, seen.append, HORIZON), run, seen)
    got: list[Any] = []
    mon = deadline_monitor(CHECKED, node, RULES, got.append, HORIZON, chunk=chunk)
    assert isinstance(mon, BatchDeadlines)
    return stream, _judge(mon, run, got), mon


def _enumerate(run: list[Event], strict: bool = False) -> list[tuple[Any, ...]]:
    """Each trigger's verdicts found by enumerating the run (module docstring): ``(trigger, guarantee,
    verdict, answer or None, update, margin ms or None)``, sorted; ``strict``: the control's misreading
    of ``within`` as strictly before the deadline."""
    found: list[tuple[Any, ...]] = []
    ms = [round(ev.time * 1000) for ev in run]
    for i, ev in enumerate(run):
        if ev.topic != "trig" or not Fraction(ev.fields["data"]) < 9:
            continue
        a = Fraction(ev.fields["data"])
        for k, (holds, bound) in RULES_OF.items():
            due = ms[i] + bound
            answer = next((j for j in range(i + 1, len(run)) if run[j].topic == "ans"
                           and holds(a, Fraction(run[j].fields["data"]))), None)
            past = next((j for j in range(i + 1, len(run)) if ms[j] > due), None)
            if answer is not None and (past is None or answer <= past):
                ok = ms[answer] < due if strict else ms[answer] <= due
                found.append((i, k, "true" if ok else "false", answer, False, due - ms[answer]))
            elif past is not None:
                found.append((i, k, "false", None, False, None))
                if answer is not None:
                    found.append((i, k, "false", answer, True, due - ms[answer]))
            else:
                found.append((i, k, "currently_false", None, False, None))
    return sorted(found, key=repr)


def _as_found(verdicts: list[Any]) -> list[tuple[Any, ...]]:
    """The monitor's verdicts in :func:`_enumerate`'s form."""
    def at(where: str) -> int:
        return int(where.rsplit(":", 1)[1]) - 1
    return sorted(((at(v.trigger_where), v.guarantee, v.verdict, at(v.answer_where) if v.answer_where else None,
                    v.update, None if v.time_margin is None else round(v.time_margin * 1000))
                   for v in verdicts), key=repr)


def test_batch_deadlines_equal_the_streaming_monitor_and_the_enumeration() -> None:
    rng = random.Random(106)
    batched = 0
    for case in range(70):
        run = _run(rng, rng.randrange(1, 40), hazards=False)
        stream, batch, mon = _both(run, rng.randrange(1, 10))
        assert batch == stream, f"case {case}"
        assert _as_found(stream["verdicts"]) == _enumerate(run), f"case {case}"
        quiet = deadline_monitor(CHECKED, NODE, RULES, None, HORIZON, chunk=rng.randrange(1, 10))
        assert _judge(quiet, run, [])["result"] == stream["result"], f"case {case}: without a verdict callback"
        batched += mon.stats["batched"]
    assert batched > 700  # the runs were judged in batch, not streamed


def test_runs_the_batch_declines_are_streamed_to_the_same_verdicts() -> None:
    rng = random.Random(112)
    stats = {"batched": 0, "streamed": 0}
    for case in range(70):
        run = _run(rng, rng.randrange(1, 40), hazards=True)
        stream, batch, mon = _both(run, rng.randrange(1, 10))
        assert batch == stream, f"case {case}"
        for key in stats:
            stats[key] += mon.stats[key]
    assert stats["batched"] > 350 and stats["streamed"] > 350  # chunks of both kinds, one after the other


def test_an_enumeration_output_is_judged_in_batch_too() -> None:
    rng = random.Random(113)
    node, batched = CHECKED.nodes["E"], 0
    for case in range(40):
        run, ms = [], 0
        for i in range(rng.randrange(1, 30)):
            ms += rng.choice([0, 1, 10, 20, 21, 60])
            if rng.random() < 0.45:
                run.append(Event(i, ms / 1000, "trig", {"data": rng.choice([0.0, 4.5, 5.0, 7.25])}, f"run:{i + 1}"))
            else:  # a value of another type or no value of Level now and then: that chunk is streamed
                value = rng.choice(["mid", 3.0]) if rng.random() < 0.05 else rng.choice(["lo", "hi"])
                run.append(Event(i, ms / 1000, "ans", {"data": value}, f"run:{i + 1}"))
        stream, batch, mon = _both(run, rng.randrange(1, 8), node)
        assert batch == stream, f"case {case}"
        batched += mon.stats["batched"]
    assert batched > 200


def test_controls_a_misread_deadline_is_caught(monkeypatch: pytest.MonkeyPatch) -> None:
    # answered at the deadline itself: met ("within" includes it); the strict reading differs
    run = [Event(0, 0.0, "trig", {"data": 1.0}, "run:1"), Event(1, 0.03, "ans", {"data": 2.0}, "run:2"),
           Event(2, 0.2, "tick", {}, "run:3")]
    stream, batch, _ = _both(run, 3)
    assert batch == stream and _as_found(stream["verdicts"]) == _enumerate(run)
    assert _as_found(stream["verdicts"]) != _enumerate(run, strict=True)
    # a batch judge whose clock expires a deadline at its own stamp gives another verdict list
    real = batch_deadline_chunk.expiries
    monkeypatch.setattr(batch_deadline_chunk, "expiries", lambda ns, due: real(ns, due - 1))
    run = [Event(0, 0.0, "trig", {"data": 1.0}, "run:1"), Event(1, 0.03, "tick", {}, "run:2"),
           Event(2, 0.03, "ans", {"data": 2.5}, "run:3")]
    stream, batch, mon = _both(run, 3)
    assert mon.stats["batched"] == 3 and batch != stream


def test_only_eligible_nodes_are_judged_in_batch() -> None:
    assert isinstance(deadline_monitor(CHECKED, NODE, RULES), BatchDeadlines)
    two = deadline_monitor(CHECKED, CHECKED.nodes["Two"], RULES)  # two inputs: the question's inputs matter
    assert type(two) is DeadlineMonitor
    tolerant = deadline_monitor(CHECKED, NODE, RULES, tolerance=Tolerance(abs=Fraction(1, 1000)))
    assert type(tolerant) is DeadlineMonitor


@pytest.mark.parametrize("example, trace", [("warehouse", "traces/run.jsonl"), ("warehouse", "live/monitor.jsonl"),
                                            ("delivery", "live/monitor.jsonl")])
def test_bundled_runs_judged_in_batch_equal_the_streaming_monitor(example: str, trace: str) -> None:
    root = EXAMPLES / example
    checked = load(sorted(root.rglob("*.rcl")))
    cfg = load_mapping(root, None)
    run = list(read_trace(root / "backends/monitors" / trace, [root / d for d in cfg.msg_dirs]))
    batched = judged = 0
    for node in (n for n in checked.nodes.values() if has_deadlines(n)):
        mon = deadline_monitor(checked, node, cfg.rules, None, cfg.horizon, cfg.tolerance, chunk=7)
        if not isinstance(mon, BatchDeadlines):
            continue
        seen: list[Any] = []
        stream = _judge(DeadlineMonitor(checked, node, cfg.rules, seen.append, cfg.horizon, cfg.tolerance), run, seen)
        got: list[Any] = []
        mon.on_verdict = got.append
        assert _judge(mon, run, got) == stream, node.name
        judged += len(got)
        batched += mon.stats["batched"]
    assert batched > 0 and judged > 0


def _skewed(skew: float) -> Any:
    rules = load_rules({"trig": {"fields": ["data"]}, "ans": {"fields": ["data"]}, "other": {"fields": ["data"]}})
    rules.skew = skew
    return rules


def _bench_shaped(rng: random.Random, n: int) -> list[Event]:
    """The windowed race's deadline log: at each 10 ms sample a trigger with probability 1/2 and an answer
    (after it, at its stamp) with 0.7, every answer right."""
    out: list[Event] = []
    for i in range(n):
        if rng.random() < 0.5:
            out.append(Event(len(out), i / 100, "trig", {"data": 0.0}, f"run:{len(out) + 1}"))
        if rng.random() < 0.7:
            out.append(Event(len(out), i / 100, "ans", {"data": 2.0}, f"run:{len(out) + 1}"))
    return out


def test_the_transport_skew_is_judged_in_batch_to_the_streaming_verdicts() -> None:
    """With the mapping's skew (deadline_skew.py: an obligation left unanswered for which an output stamped
    within the skew before its trigger satisfies the guarantee is undecided, its late answer no verdict), the
    batch judge marks the unmet obligations as the monitor does and judges the chunk in batch: the verdicts
    and result equal the streaming monitor's on random runs (skew 3 and 20 ms, chunks of 2 events up) and on
    the race's shape, where every chunk is judged in batch.  Control: a batch judge that ignores the skew
    (marks nothing) gives ``false`` where the monitor is undecided."""
    rng = random.Random("skew-batch")
    undecided = batched = 0
    for case in range(10):
        rules = _skewed(rng.choice([0.003, 0.02]))
        run = _run(rng, rng.choice([40, 200]), case % 3 == 0)
        node = CHECKED.nodes[rng.choice(["D", "E"])] if case % 2 else NODE
        if node.name == "E":
            run = [Event(e.index, e.time, e.topic, {"data": "hi" if e.fields.get("data", 0) else "lo"}, e.where)
                   if e.topic == "ans" else e for e in run]
        seen: list[Any] = []
        stream = _judge(DeadlineMonitor(CHECKED, node, rules, seen.append, HORIZON), run, seen)
        got: list[Any] = []
        mon = deadline_monitor(CHECKED, node, rules, got.append, HORIZON, chunk=rng.choice([2, 3, 16, 4096]))
        assert isinstance(mon, BatchDeadlines)
        assert _judge(mon, run, got) == stream, f"case {case}"
        undecided += stream["result"]["unaccepted"]["undecided"]
        batched += mon.stats["batched"]
    assert undecided > 5 and batched > 300, (undecided, batched)
    rules = _skewed(0.02)
    run = _bench_shaped(random.Random(5), 800)
    seen = []
    stream = _judge(DeadlineMonitor(CHECKED, NODE, rules, seen.append, HORIZON), run, seen)
    got = []
    mon = deadline_monitor(CHECKED, NODE, rules, got.append, HORIZON, chunk=256)
    assert isinstance(mon, BatchDeadlines)
    assert _judge(mon, run, got) == stream and mon.stats["streamed"] == 0
    assert stream["result"]["unaccepted"]["undecided"] > 2


def test_control_a_batch_judge_ignoring_the_skew_is_caught(monkeypatch: pytest.MonkeyPatch) -> None:
    rules = _skewed(0.02)
    run = _bench_shaped(random.Random(5), 800)
    seen: list[Any] = []
    stream = _judge(DeadlineMonitor(CHECKED, NODE, rules, seen.append, HORIZON), run, seen)
    monkeypatch.setattr(batch_deadline_chunk, "_mark", lambda *a: False)
    got: list[Any] = []
    mon = deadline_monitor(CHECKED, NODE, rules, got.append, HORIZON, chunk=256)
    wrong = _judge(mon, run, got)
    assert wrong["result"]["counts"]["false"] > stream["result"]["counts"]["false"]
    assert wrong["result"]["unaccepted"]["undecided"] < stream["result"]["unaccepted"]["undecided"]
