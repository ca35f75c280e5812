"""A ``triggered by`` node's untimed judgement in batch (backends/monitors/batch.py, batch_plan.py)
against the streaming engine and a brute-force enumeration of the question/answer rules, its oracles.

On small random runs of triggered nodes (triggers and answers at random whole milliseconds, answers at
the trigger's stamp, later within the horizon, past it, missing or doubled; answers the guarantee
refuses; triggers the assumption refuses; a second input that raises questions owing the triggered
guarantee only as carried; foreign topics, stamps going back, header stamps, NaN; transport skew on
and off; margins on and off; chunks of 2 events up), the batch path must give exactly the streaming
engine's verdict list (verdicts, order, reasons, margins) and result.  On runs of the bench's shape
(a trigger, its answer at the same stamp, lone answers and lone triggers, horizon half the period)
every answer's verdict and margin must be the enumeration's: the guarantee on the latest trigger at
or before it and the answer's value, in exact rationals (nothing of rclverify's).  Controls: a batch
path that takes every input's pairs as owing the triggered guarantee gives verdicts the engine does
not, and an enumeration judging an answer against the trigger before the latest differs.

The lone slots (batch_lone.py: chunks of lone triggers and lone answers judged in batch) and nodes whose
guarantees several inputs trigger have their own random runs against the engine, each with a control: a
judge closing a lone trigger's question silently, a batch path owing every guarantee to every pair.
"""
from __future__ import annotations

import random
from fractions import Fraction
from typing import Any

import pytest

from rclverify.backends.monitors import batch
from rclverify.backends.monitors.batch import MIN_RUN, batch_plan, check_batch
from rclverify.backends.monitors.check import check_trace
from rclverify.backends.monitors.engine import NodeMonitor
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check
from rclverify.traces.events import Event
from rclverify.traces.mapping import load_rules

NODES = """
context { Level : {lo, hi} ; }
node D {
  inputs( a : REAL )
  outputs( b : REAL )
  topics( std_msgs/Float64 trig matches(in.a), std_msgs/Float64 ans matches(out.b) )
  guarantee( out.b > in.a ) triggered by in.a within 30 ms
}
node A {
  inputs( a : REAL )
  outputs( b : REAL )
  topics( std_msgs/Float64 trig matches(in.a), std_msgs/Float64 ans matches(out.b) )
  assume( in.a < 9 )
  guarantee( out.b > in.a ) triggered by in.a within 30 ms
  guarantee( out.b < 100 ) triggered by in.a
}
node E {
  inputs( a : REAL )
  outputs( s : Level )
  topics( std_msgs/Float64 trig matches(in.a), std_msgs/String ans matches(out.s) )
  guarantee( (in.a < 5 -> out.s == hi) and (in.a >= 5 -> out.s == lo) ) triggered by in.a within 20 ms
}
node Two {
  inputs( a : REAL, c : REAL )
  outputs( b : REAL )
  topics( std_msgs/Float64 trig matches(in.a), std_msgs/Float64 other matches(in.c),
          std_msgs/Float64 ans matches(out.b) )
  guarantee( out.b > in.a + in.c ) triggered by in.a within 30 ms
}
node Mixed {
  inputs( a : REAL, c : REAL )
  outputs( b : REAL )
  topics( std_msgs/Float64 trig matches(in.a), std_msgs/Float64 other matches(in.c),
          std_msgs/Float64 ans matches(out.b) )
  guarantee( out.b > in.a ) triggered by in.a within 30 ms
  guarantee( out.b > in.c - 50 )
}
node Multi {
  inputs( a : REAL, c : REAL )
  outputs( b : REAL )
  topics( std_msgs/Float64 trig matches(in.a), std_msgs/Float64 other matches(in.c),
          std_msgs/Float64 ans matches(out.b) )
  guarantee( out.b > in.a ) triggered by in.a within 30 ms
  guarantee( out.b > in.c ) triggered by in.c within 20 ms
}
node Multi3 {
  inputs( a : REAL, c : REAL )
  outputs( b : REAL )
  topics( std_msgs/Float64 trig matches(in.a), std_msgs/Float64 other matches(in.c),
          std_msgs/Float64 ans matches(out.b) )
  guarantee( out.b > in.a ) triggered by in.a within 30 ms
  guarantee( out.b > in.c + 0.5 ) triggered by in.c
  guarantee( out.b < 100 )
}
"""
CHECKED = check([parse_text(NODES)])
RULES = {"trig": {"fields": ["data"]}, "ans": {"fields": ["data"]}, "other": {"fields": ["data"]}}
TRIGGERED = ["D", "A", "E", "Two", "Mixed"]


def _answer(node: str, a: float, c: float, rng: random.Random) -> Any:
    """An answer to trigger value ``a`` (and ``c``): right mostly, now and then wrong."""
    wrong = rng.random() < 0.15
    if node == "E":
        right = "hi" if a < 5 else "lo"
        return ({"hi": "lo", "lo": "hi"}[right] if wrong else right) if rng.random() > 0.03 else "purple"
    base = a + c if node == "Two" else max(a, c + 0.5) if node.startswith("Multi") else a
    return base + (rng.choice([-1.0, 0.0, -0.25]) if wrong else rng.choice([0.25, 1.0, 2.5, 150.0 if node == "A"
                                                                             else 3.0]))


def _run(rng: random.Random, node: str, horizon: float) -> list[Event]:
    """A random run of ``node`` (module docstring): mostly trigger/answer pairs, every kind of irregularity."""
    out: list[Event] = []
    ms = rng.randrange(0, 40)
    a, c = 1.0, 0.0
    regular = rng.random() < 0.3
    hms = round(horizon * 1000)

    def add(topic: str, value: Any, t_ms: int, stamp_ms: int | None = None) -> None:
        fields = {"data": value}
        out.append(Event(len(out), t_ms / 1000, topic, fields, f"run.jsonl:{len(out) + 1}",
                         None if stamp_ms is None else stamp_ms / 1000))

    for _ in range(rng.randint(5, 200 if regular else 60)):
        ms += 10 if regular else rng.choice([0, 1, 4, 10, 10, 10, 31, 50])
        kind = "pair" if regular and rng.random() < 0.9 else rng.choices(
            ["pair", "lone", "answer", "late", "dup", "other", "refused", "back", "stamped", "nan", "foreign"],
            [50, 8, 10, 4, 4, 8 if node in ("Two", "Mixed") else 30 if node.startswith("Multi") else 0,
             4 if node == "A" else 0, 3, 3, 2, 3])[0]
        if kind == "other":
            c = rng.choice([0.0, 0.5, 1.0, 2.5, 5.0] if node.startswith("Multi") else [0.0, 0.5, 1.0])
            add("other", c, ms)
            if rng.random() < (0.8 if node.startswith("Multi") else 0.6):  # its answer (Two, Mixed: a question
                # owing the trigger only as carried; Multi: its own trigger's guarantee)
                add("ans", _answer(node, a, c, rng), ms + rng.choice([0, 1]))
            continue
        if kind in ("pair", "lone", "late", "dup", "refused", "stamped", "nan"):
            a = 9.5 if kind == "refused" else rng.choice([0.0, 0.25, 1.0, 2.5, 5.0, 7.75])
            if kind == "nan":
                add("trig", float("nan"), ms)
            else:
                add("trig", a, ms, ms - 2 if kind == "stamped" else None)
        if kind in ("pair", "dup", "refused", "stamped", "answer"):
            add("ans", _answer(node, a, c, rng), ms + rng.choice([0, 0, 0, 1, hms // 2]))
        if kind == "dup":
            add("ans", _answer(node, a, c, rng), ms + 1)
        if kind == "late":
            add("ans", _answer(node, a, c, rng), ms + 2 * hms + 3)
        if kind == "back":
            add("ans", _answer(node, a, c, rng), max(0, ms - rng.choice([2, 30, 500])))
        if kind == "foreign":
            add("tick", 0.0, ms)
        ms = max(ms, max(round(ev.time * 1000) for ev in out) if out else ms)
    return out


def _both(node: str, events: list[Event], rules: Any, horizon: float, chunk: int, margins: bool,
          end: float | None = None, min_run: int = 0) -> tuple[Any, Any, dict[str, int]]:
    """(the streaming engine's (count, result, verdicts), the batch path's, the batch path's stats);
    ``min_run`` 0: every run of pairs batched, however short."""
    n = CHECKED.nodes[node]
    seen_s: list[Any] = []
    count, (res,) = check_trace(CHECKED, [n], iter(events), rules, horizon, seen_s.append, None, end,
                                batch=False, margins=margins)
    seen_b: list[Any] = []
    stats: dict[str, int] = {}
    done = check_batch(CHECKED, n, iter(events), rules, horizon, seen_b.append, None, end, chunk=chunk,
                       stats=stats, margins=margins, min_run=min_run)
    assert done is not None, f"{node} should be eligible"
    return (count, res, seen_s), (done[0], done[1], seen_b), stats


@pytest.mark.parametrize("node", TRIGGERED)
def test_triggered_nodes_are_eligible(node: str) -> None:
    rules = load_rules(RULES)
    plan = batch_plan(NodeMonitor(CHECKED, CHECKED.nodes[node], rules, 0.005), rules)
    assert plan is not None and plan.trigger == "in.a"


@pytest.mark.parametrize("node", TRIGGERED)
def test_batch_equals_streaming_on_random_triggered_runs(node: str) -> None:
    rng = random.Random(f"triggered-{node}")
    batched = streamed = 0
    for case in range(16):
        horizon = rng.choice([0.005, 0.02, 0.04])
        rules = load_rules(RULES)
        rules.skew = rng.choice([0.0, 0.0, 0.003, 0.02])
        events = _run(rng, node, horizon)
        chunk = rng.choice([2, 3, 5, 16, 4096] if len(events) < 80 else [16, 64, 4096])
        end = events[-1].time + rng.choice([0.0, 1.0]) if events and rng.random() < 0.3 else None
        margins = case % 2 == 1
        s, b, stats = _both(node, events, rules, horizon, chunk, margins, end, rng.choice([0, 0, MIN_RUN]))
        where = f"case {case}: horizon {horizon}, skew {rules.skew}, chunk {chunk}, margins {margins}, " \
                f"{len(events)} events"
        assert b[2] == s[2], where  # the verdict list: verdicts, order, reasons, margins
        assert b[1] == s[1], where  # the result: counts, first violations, margins
        assert b[0] == s[0], where
        batched += stats["batched"]
        streamed += stats["streamed"]
    assert batched > 100 and streamed > 100, (batched, streamed)  # both halves ran


def _bench_run(rng: random.Random, n: int) -> list[Event]:
    """The bench's shape: at each 10 ms sample a trigger with probability 1/2, an answer with 0.7 (after
    the trigger, at its stamp), values on a quarter grid (exact in doubles), wrong now and then."""
    out: list[Event] = []
    a = 0.0
    for i in range(n):
        if rng.random() < 0.5:
            a = rng.choice([0.0, 0.25, 1.0, 2.5])
            out.append(Event(len(out), i / 100, "trig", {"data": a}, f"run.jsonl:{len(out) + 1}"))
        if rng.random() < 0.7:
            b = a + (rng.choice([0.25, 1.0]) if rng.random() > 0.05 else rng.choice([0.0, -0.5]))
            out.append(Event(len(out), i / 100, "ans", {"data": b}, f"run.jsonl:{len(out) + 1}"))
    out.append(Event(len(out), n / 100 + 1.0, "tick", {}, f"run.jsonl:{len(out) + 1}"))
    return out


def _enumerate(run: list[Event], stale: bool = False) -> list[tuple[int, str, float]]:
    """Each answer's (index, verdict, margin) by enumeration: ``out.b > in.a`` on the latest trigger at or
    before it (``stale``: the control's misreading, the trigger before that), in exact rationals; the
    margin ``b - a``.  An answer before any trigger has no question: no verdict."""
    found = []
    triggers: list[Fraction] = []
    for ev in run:
        if ev.topic == "trig":
            triggers.append(Fraction(ev.fields["data"]))
        elif ev.topic == "ans" and len(triggers) > (1 if stale else 0):
            a = triggers[-2] if stale else triggers[-1]
            b = Fraction(ev.fields["data"])
            found.append((ev.index, "satisfied" if b > a else "violated", float(b - a)))
    return found


def test_bench_shaped_runs_equal_the_enumeration() -> None:
    rng = random.Random(106)
    rules = load_rules(RULES)
    for case in range(6):
        run = _bench_run(rng, 400)
        s, b, stats = _both("D", run, rules, 0.005, rng.choice([7, 64, 16384]), True)
        assert b == s, f"case {case}"
        assert stats["batched"] > 60
        got = [(v.event, v.verdict, v.margin) for v in b[2] if v.topic == "ans"]
        assert got == _enumerate(run), f"case {case}"
        assert got != _enumerate(run, stale=True)  # control: the trigger before the latest is another verdict
        assert b[1].counts["violated"] == sum(1 for _, v, _ in got if v == "violated") > 0


def _slots_run(rng: random.Random, node: str, n: int, wrong: float, odd: bool) -> list[Event]:
    """The bench's shape for the lone slots (batch_lone.py): a trigger at a sample with probability 1/2, an
    answer with 0.7 (after the trigger, at its stamp), right but with probability ``wrong``; ``odd``: samples
    now and then 0-6 ms apart (within the horizon), an answer before its trigger at one stamp, a NaN trigger,
    a foreign topic."""
    out: list[Event] = []
    a, ms = 0.0, 0

    def add(topic: str, value: Any) -> None:
        out.append(Event(len(out), ms / 1000, topic, {"data": value}, f"run.jsonl:{len(out) + 1}"))

    for _ in range(n):
        ms += rng.choice([10, 10, 10, 10, 20, 5, 6, 4, 0]) if odd else 10
        swap = odd and rng.random() < 0.05
        if rng.random() < 0.5:
            a = rng.choice([0.0, 0.25, 1.0, 2.5, 7.75])
            if not swap:
                add("trig", float("nan") if odd and rng.random() < 0.01 else a)
        if rng.random() < 0.7:
            if node == "E":
                right = "hi" if a < 5 else "lo"
                add("ans", {"hi": "lo", "lo": "hi"}[right] if rng.random() < wrong else right)
            else:
                add("ans", a + (rng.choice([0.0, -0.5]) if rng.random() < wrong else rng.choice([0.25, 1.0])))
        if swap:
            add("trig", a)
        if odd and rng.random() < 0.01:
            add("tick", 0.0)
    if rng.random() < 0.5:
        ms += 1000
        add("tick", 0.0)
    return out


@pytest.mark.parametrize("node", ["D", "E"])
def test_lone_slots_equal_streaming(node: str) -> None:
    """Chunks of lone triggers and answers judged in batch (batch_lone.py), by default (``MIN_RUN``): the
    verdict list (verdicts, order, reasons, margins) and result equal the streaming engine's on runs of the
    bench's shape, the transport skew 0, 3 or 20 ms, margins on and off, chunks of 7 events up, answers all
    right or now and then wrong, samples regular or not (then most chunks are the engine's)."""
    rng = random.Random(f"lone-{node}")
    batched = 0
    for case in range(10):
        rules = load_rules(RULES)
        rules.skew = rng.choice([0.0, 0.003, 0.02, 0.02])
        wrong = 0.0 if case % 3 else rng.choice([0.001, 0.01])
        events = _slots_run(rng, node, rng.choice([60, 300, 600]), wrong, case % 4 == 3)
        chunk = rng.choice([7, 64, 500, 16384])
        margins = case % 2 == 0
        end = events[-1].time + rng.choice([0.0, 1.0]) if rng.random() < 0.3 else None
        s, b, stats = _both(node, events, rules, 0.005, chunk, margins, end, MIN_RUN)
        where = f"case {case}: skew {rules.skew}, chunk {chunk}, margins {margins}, {len(events)} events"
        assert b[2] == s[2], where
        assert b[1] == s[1], where
        assert b[0] == s[0], where
        batched += stats["batched"]
    assert batched > 500, batched  # the lone slots ran


def test_lone_slots_are_batched_and_a_wrong_answer_is_the_engines() -> None:
    """The bench's shape with every answer right is judged in batch (no event fed to the engine past each
    chunk's first few), to the engine's verdicts and the enumeration's; the same run with one answer wrong
    (the control) has that answer's chunk fed to the engine, its violation found."""
    rules = load_rules(RULES)
    run = _slots_run(random.Random(7), "D", 600, 0.0, False)
    s, b, stats = _both("D", run, rules, 0.005, 16384, True, None, MIN_RUN)
    assert b == s and stats["streamed"] <= 16 and stats["batched"] > 300
    got = [(v.event, v.verdict, v.margin) for v in b[2] if v.topic == "ans"]
    assert got == _enumerate(run) and all(v == "satisfied" for _, v, _ in got)
    lone = sum(1 for v in b[2] if v.verdict == "inconclusive")
    assert lone > 50 and lone == b[1].counts["inconclusive"]  # the lone triggers, closed unanswered
    k = next(i for i, ev in enumerate(run) if ev.topic == "ans" and i > 300)
    bad = list(run)
    bad[k] = Event(k, run[k].time, "ans", {"data": -1.0}, run[k].where)
    s, b, stats = _both("D", bad, rules, 0.005, 16384, True, None, MIN_RUN)
    assert b == s and stats["streamed"] > 300 and b[1].counts["violated"] == 1
    assert [v.event for v in b[2] if v.verdict == "violated"] == [k]


def test_control_lone_slots_misreading_the_carried_trigger_is_caught(monkeypatch: pytest.MonkeyPatch) -> None:
    """Control: a lone-slots judge that closes a lone trigger's question silently (as if answered) gives a
    result the engine does not (the ``inconclusive`` count), on the bench's shape."""
    from rclverify.backends.monitors import batch_lone
    rules = load_rules(RULES)
    run = _slots_run(random.Random(8), "D", 400, 0.0, False)
    right = _both("D", run, rules, 0.005, 16384, True, None, MIN_RUN)
    assert right[0] == right[1]
    apply = batch_lone.LoneSlots._apply

    def silent(self: Any, chunk: Any, s: int, k: Any, t: Any, in_rows: Any, out_rows: Any, qidx: Any,
               answered: Any, paired_out: Any, close_q: list[int], close_at: list[int], *rest: Any) -> None:
        apply(self, chunk, s, k, t, in_rows, out_rows, qidx, answered, paired_out, [], [], [], *rest[1:])

    with monkeypatch.context() as patch:
        patch.setattr(batch_lone.LoneSlots, "_apply", silent)
        wrong = _both("D", run, rules, 0.005, 16384, True, None, MIN_RUN)
    assert wrong[0][1].counts["inconclusive"] > wrong[1][1].counts["inconclusive"]


def test_short_runs_of_pairs_are_streamed_whole() -> None:
    """The bench's shape (runs of one or two pairs between lone triggers and answers) with answers now and
    then wrong costs the batch path more than the engine: by default such a chunk is fed to the engine
    whole (the lone slots decline a chunk holding a wrong answer), to the same verdicts; a run of long
    stretches of pairs (the control) is batched."""
    rules = load_rules(RULES)
    run = _bench_run(random.Random(7), 600)
    s, b, stats = _both("D", run, rules, 0.005, 16384, True, None, MIN_RUN)
    assert b == s and stats["batched"] == 0 and stats["streamed"] == len(run)
    steady: list[Event] = []
    for i in range(600):  # every trigger answered at its stamp, a lone trigger every 50 samples
        steady.append(Event(len(steady), i / 100, "trig", {"data": 1.0}, f"r:{len(steady) + 1}"))
        if i % 50:
            steady.append(Event(len(steady), i / 100, "ans", {"data": 2.0}, f"r:{len(steady) + 1}"))
    s, b, stats = _both("D", steady, rules, 0.005, 16384, True, None, MIN_RUN)
    assert b == s and stats["batched"] > 500


def test_control_a_pair_of_another_input_taken_as_owing_is_caught(monkeypatch: pytest.MonkeyPatch) -> None:
    """Control: a batch path taking the pairs another input raises as owing the triggered guarantee (no
    row kept for the engine) gives verdicts or margins the streaming engine does not, on Two's and Mixed's
    runs (Mixed's untriggered guarantee is owed there: the triggered one's margins tell them apart)."""
    init = batch._Run.__init__

    def every_input_owes(self: Any, plan: Any) -> None:
        init(self, plan)
        self.owing = 0

    rules = load_rules(RULES)
    caught = 0
    for node in ("Two", "Mixed"):
        rng = random.Random(f"control-{node}")
        for _ in range(6):
            events: list[Event] = []
            for i in range(60):  # another input's question, its answer wrong for the trigger's reading
                topic, value = ("other", 1.0) if i % 3 == 0 else ("trig", rng.choice([0.0, 1.0]))
                events.append(Event(len(events), i / 100, topic, {"data": value}, f"r:{len(events) + 1}"))
                events.append(Event(len(events), i / 100, "ans", {"data": rng.choice([0.5, 3.0])},
                                    f"r:{len(events) + 1}"))
            right = _both(node, events, rules, 0.005, 64, True)
            assert right[0] == right[1]
            with monkeypatch.context() as patch:
                patch.setattr(batch._Run, "__init__", every_input_owes)
                wrong = _both(node, events, rules, 0.005, 64, True)
            caught += wrong[0] != wrong[1]
    assert caught == 12


MULTI = ["Multi", "Multi3"]


@pytest.mark.parametrize("node", MULTI)
def test_several_trigger_nodes_are_eligible(node: str) -> None:
    rules = load_rules(RULES)
    plan = batch_plan(NodeMonitor(CHECKED, CHECKED.nodes[node], rules, 0.005), rules)
    assert plan is not None and plan.trigger == "" and set(plan.triggers.values()) == {"in.a", "in.c"}


@pytest.mark.parametrize("node", MULTI)
def test_batch_equals_streaming_on_random_several_trigger_runs(node: str) -> None:
    """A node whose guarantees are triggered by different inputs: a pair owes the guarantees its own message
    triggers (and the untriggered ones); a first pair a foreign trigger is carried to is the engine's.  The
    verdict list and result equal the streaming engine's on random runs (module docstring's irregularities,
    pairs of both triggers, skew 0, 3 and 20 ms, margins on and off, chunks of 2 events up)."""
    rng = random.Random(f"several-{node}")
    batched = streamed = 0
    for case in range(16):
        horizon = rng.choice([0.005, 0.02, 0.04])
        rules = load_rules(RULES)
        rules.skew = rng.choice([0.0, 0.0, 0.003, 0.02])
        events = _run(rng, node, horizon)
        chunk = rng.choice([2, 3, 5, 16, 4096] if len(events) < 80 else [16, 64, 4096])
        end = events[-1].time + rng.choice([0.0, 1.0]) if events and rng.random() < 0.3 else None
        margins = case % 2 == 1
        s, b, stats = _both(node, events, rules, horizon, chunk, margins, end, rng.choice([0, 0, MIN_RUN]))
        where = f"case {case}: horizon {horizon}, skew {rules.skew}, chunk {chunk}, margins {margins}, " \
                f"{len(events)} events"
        assert b[2] == s[2], where
        assert b[1] == s[1], where
        assert b[0] == s[0], where
        batched += stats["batched"]
        streamed += stats["streamed"]
    assert batched > 50 and streamed > 100, (batched, streamed)


def test_control_several_triggers_owed_by_every_pair_is_caught(monkeypatch: pytest.MonkeyPatch) -> None:
    """Control: a batch path taking every pair as owing every guarantee (whichever input raised it) gives
    margins the engine does not, on runs of both triggers' pairs (in.c's answer true for in.a's guarantee
    too, which its question does not owe: its margin is not the engine's to count)."""
    init = batch._Run.__init__

    def every_pair_owes_all(self: Any, plan: Any) -> None:
        init(self, plan)
        self.owing = [0] * len(self.owing) if self.owing else []

    rules = load_rules(RULES)
    caught = 0
    for node in MULTI:
        rng = random.Random(f"control-several-{node}")
        for _ in range(4):
            events: list[Event] = []
            c = 0.0
            for i in range(80):
                if i % 2:
                    c = rng.choice([0.0, 1.0])
                    events.append(Event(len(events), i / 100, "other", {"data": c}, f"r:{len(events) + 1}"))
                    b = c + 1.0 if rng.random() < 0.5 else c + 0.75
                else:
                    a = rng.choice([0.0, 0.25])
                    events.append(Event(len(events), i / 100, "trig", {"data": a}, f"r:{len(events) + 1}"))
                    b = max(a, c + 0.5) + 1.0  # true for every guarantee: only the margins counted tell
                events.append(Event(len(events), i / 100, "ans", {"data": b}, f"r:{len(events) + 1}"))
            right = _both(node, events, rules, 0.005, 64, True)
            assert right[0] == right[1] and right[2]["batched"] > 20
            with monkeypatch.context() as patch:
                patch.setattr(batch._Run, "__init__", every_pair_owes_all)
                wrong = _both(node, events, rules, 0.005, 64, True)
            caught += wrong[0] != wrong[1]
    assert caught == 8
