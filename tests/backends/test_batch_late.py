"""A message heard later than the lateness bound, judged by the offline batch path as the engine judges it
(backends/monitors/batch_late.py, batch.py, batch_lone.py; docs/semantics.md, "Event time").

A live log gives each message heard after the lateness bound its ``late_s``
(a bag, its metadata).  The rule: a question reading such a message decides
no violation (its own, and a later question's asked before the message was
heard); its verdict is ``inconclusive`` with why, never ``violated``.  The
batch path judges answer pairs over columns that hold no lateness, so a
pair whose input or answer carries one is the engine's.  Cases, each read
as events and as a log file (whose later blocks are read as columns,
traces/jsonl_blocks.py), with no verdict callback (surely violated pairs
counted in batch) and with one: a late question answered wrongly, a late
answer, both, a pair right after a late one (one input, then a second input
heard late before a run of pairs).  The random oracle marks random messages
of random runs late (a lateness column among the other hazards: answers
missing, past the horizon, unreadable, doubled, foreign topics, lone
triggers), and the batch path's result and verdict list must be the
engine's.  Control: a batch path that ignores a row's lateness counts the
late question's wrong answer ``violated``, and is caught.
"""
from __future__ import annotations

import json
import math
import random
from pathlib import Path
from typing import Any

import pytest

from rclverify.backends.monitors import batch as batch_module
from rclverify.backends.monitors.batch import MIN_RUN, check_batch
from rclverify.backends.monitors.check import check_trace
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check
from rclverify.traces import read_trace
from rclverify.traces.events import Event
from rclverify.traces.mapping import load_rules

NODES = """
node B {
  inputs( r : REAL )
  outputs( y : REAL )
  topics( std_msgs/Float64 q matches(in.r), std_msgs/Float64 a matches(out.y) )
  guarantee( out.y <= in.r )
}
node T {
  inputs( r : REAL, c : REAL )
  outputs( y : REAL )
  topics( std_msgs/Float64 q matches(in.r), std_msgs/Float64 c matches(in.c), std_msgs/Float64 a matches(out.y) )
  guarantee( out.y <= in.r + in.c )
}
node D {
  inputs( r : REAL )
  outputs( y : REAL )
  topics( std_msgs/Float64 q matches(in.r), std_msgs/Float64 a matches(out.y) )
  guarantee( out.y <= in.r ) triggered by in.r within 5 ms
}
"""
CHECKED = check([parse_text(NODES)])
RULES = {"q": {"fields": ["data"]}, "a": {"fields": ["data"]}, "c": {"fields": ["data"]}}
HORIZON = 0.005
#: how late (s) a late message was heard: past any lateness bound, and past the next questions' stamps
LATE = 0.08


def _log(path: Path, events: list[Event]) -> Path:
    """``events`` as a ROSMonitoring log, a late one with its ``late_s`` as a live log writes it."""
    with path.open("w") as fh:
        for ev in events:
            line: dict[str, Any] = {"topic": ev.topic, "time": ev.time, **ev.fields}
            if ev.late:
                line["late_s"] = ev.late
            fh.write(json.dumps(line) + "\n")
    return path


def _judged(node: str, source: Any, callback: bool, chunk: int, batch: bool, skew: float = 0.0,
            min_run: int = 0) -> tuple[Any, list[Any], dict[str, int]]:
    """(result, verdicts, stats) of ``node`` on ``source`` (events, or a log's or a bag's path, which the batch
    path reads in blocks), by the batch path or the engine; ``callback``: verdicts received (else surely violated pairs are counted in batch)."""
    rules = load_rules(RULES)
    rules.skew = skew
    seen: list[Any] = []
    cb = seen.append if callback else None
    events = read_trace(source) if isinstance(source, Path) else iter(source)  # a log or a bag: in blocks
    if not batch:
        _, (res,) = check_trace(CHECKED, [CHECKED.nodes[node]], events, rules, HORIZON, cb, batch=False)
        return res, seen, {}
    stats: dict[str, int] = {}
    done = check_batch(CHECKED, CHECKED.nodes[node], events, rules, HORIZON, cb, chunk=chunk, stats=stats,
                       min_run=min_run)
    assert done is not None, f"{node} should be eligible"
    return done[1], seen, stats


def _agree(node: str, events: list[Event], tmp_path: Path, chunk: int, skew: float = 0.0,
           min_run: int = 0) -> list[Any]:
    """Assert the batch path gives the engine's result and verdicts on ``events`` and on their log, with
    and without a callback; returns the engine's results (no callback, then with one)."""
    log = _log(tmp_path / "run.jsonl", events)
    got = []
    for callback in (False, True):
        engine = _judged(node, events, callback, chunk, False, skew)
        for source in (events, log):
            b = _judged(node, source, callback, chunk, True, skew, min_run)
            where = f"{'log' if source is log else 'events'}, callback {callback}, chunk {chunk}, skew {skew}"
            assert b[1] == engine[1], where
            assert b[0] == engine[0], where
        got.append(engine[0])
    return got


def _pairs(n: int, late: dict[int, str], wrong: set[int], c_late: int | None = None) -> list[Event]:
    """``n`` questions 10 ms apart, each answered 1 ms later (``wrong``: the answers above the question);
    ``late``: per pair, which of its messages was heard late (``q``, ``a`` or ``both``); ``c_late``: before
    that pair, a message of the second input ``c`` (0.0, node T) heard late."""
    events: list[Event] = []

    def add(topic: str, value: float, t: float, late: bool = False) -> None:
        events.append(Event(len(events), t, topic, {"data": value}, f"run.jsonl:{len(events) + 1}",
                            late=LATE if late else 0.0))
    for i in range(n):
        t = round(0.01 * i, 6)
        if c_late is not None and i in (0, c_late):
            add("c", 0.0, round(t - 0.004, 6) if i else 0.0, late=i == c_late)
        how = late.get(i, "")
        add("q", 1.0, t, how in ("q", "both"))
        add("a", 2.0 if i in wrong else 0.5, round(t + 0.001, 6), how in ("a", "both"))
    return events


@pytest.mark.parametrize("how", ["q", "a", "both"])
@pytest.mark.parametrize("chunk", [7, 64, 4096])
def test_a_late_pair_is_judged_as_the_engine_judges_it(tmp_path: Path, how: str, chunk: int) -> None:
    """Pair 30 of 60 heard late (its question, its answer or both) and answered wrongly, as is the pair right
    after it: the engine's ``inconclusive`` for a late question (its reason names the lateness), ``violated``
    for the pair after it (a question of its own, heard in time) and for a late answer to a question heard in
    time; the batch path's the same, from events and from a log."""
    events = _pairs(60, {30: how}, {30, 31})
    plain, _ = _agree("B", events, tmp_path, chunk)
    undecided = how != "a"
    assert plain.counts["inconclusive"] == undecided and plain.counts["violated"] == 2 - undecided
    assert plain.counts["satisfied"] == 58


@pytest.mark.parametrize("chunk", [7, 64, 4096])
def test_the_pairs_after_a_late_second_input_are_the_engines(tmp_path: Path, chunk: int) -> None:
    """Node T reads two inputs: a message of ``c`` heard 80 ms late before pair 30 makes the questions asked
    before it was heard (pairs 30 to 37) decide no violation; pairs 30, 33 and 40 answered wrongly: two
    ``inconclusive``, pair 40 (asked after it was heard) ``violated``; the batch path's the same."""
    events = _pairs(60, {}, {30, 33, 40}, c_late=30)
    plain, _ = _agree("T", events, tmp_path, chunk)
    assert plain.counts["inconclusive"] == 2 and plain.counts["violated"] == 1


def test_a_log_read_in_blocks_leaves_its_late_pairs_to_the_engine(tmp_path: Path) -> None:
    """A long log read in blocks: most of them columns (traces/jsonl_blocks.py), each holding a late line
    read as events with their lateness; both late questions' wrong answers are ``inconclusive``, the rest
    of the pairs batched."""
    events = _pairs(400, {10: "q", 300: "q"}, {10, 300})
    log = _log(tmp_path / "run.jsonl", events)
    res, _, stats = _judged("B", log, False, 64, True)
    assert res.counts["inconclusive"] == 2 and res.counts["violated"] == 0
    assert stats["batched"] > 300


@pytest.mark.parametrize("storage", ["sqlite3", "mcap"])
def test_a_bag_read_in_blocks_carries_the_lateness(tmp_path: Path, storage: str) -> None:
    """A bag the live monitor recorded (its late messages in its metadata, traces/bag_late.py), read in blocks of
    columns (traces/bag_blocks.py): the late question's pair is the engine's, and its event carries the lateness
    as :func:`~rclverify.traces.bag.read_bag`'s does, so the wrong answer to it is ``inconclusive`` as when the
    bag is streamed; the control, the same bag without its metadata's lateness, is ``violated``."""
    from rclverify.runtime.dds.bag import BagRecorder
    from rclverify.traces.bag import read_bag, typestore
    t0 = 1_700_000_000.0
    store = typestore([])
    f64 = store.types["std_msgs/msg/Float64"]

    def record(path: Path, late: bool) -> Path:
        rec = BagRecorder(path, storage, {"q": "std_msgs/Float64", "a": "std_msgs/Float64"}, [])
        for ev in _pairs(200, {30: "q", 150: "both"}, {30, 31, 150}):
            ns = round((t0 + ev.time) * 1e9)
            rec.write(ev.topic, ns, store.serialize_cdr(f64(data=ev.fields["data"]), "std_msgs/msg/Float64"))
            if ev.late and late:
                rec.late(ev.topic, ns / 1e9, ev.late)
        rec.close()
        return path
    for late in (True, False):
        bag = record(tmp_path / f"bag-{late}", late)
        engine = _judged("B", list(read_bag(bag)), False, 64, False)[0]
        assert engine.counts["inconclusive"] == 2 * late and engine.counts["violated"] == 3 - 2 * late
        for chunk in (7, 64, 4096):
            b, _, stats = _judged("B", bag, False, chunk, True)
            assert b == engine, f"chunk {chunk}, late {late}"
            assert stats["batched"] > 150


def _random_run(rng: random.Random, node: str, late: float) -> list[Event]:
    """A random run of ``node``: pairs 10 ms apart (node D: now and then 20 ms, lone triggers and lone
    answers, the lone slots' shape), answers wrong now and then, missing, past the horizon, unreadable or
    doubled, a second input (node T), a foreign topic; each message heard late with probability ``late``."""
    events: list[Event] = []
    ms = 0

    def add(topic: str, value: float, t_ms: int) -> None:
        events.append(Event(len(events), t_ms / 1000, topic, {"data": value}, f"run.jsonl:{len(events) + 1}",
                            late=rng.choice([LATE, 0.02, 0.3]) if rng.random() < late else 0.0))
    r = 1.0
    for _ in range(rng.randint(40, 300)):
        ms += rng.choice([10, 10, 10, 20]) if node == "D" else 10
        kind = rng.choices(["pair", "lone", "answer", "past", "nan", "dup", "other", "tick"],
                           [70, 6 if node == "D" else 2, 6 if node == "D" else 1, 2, 1, 2,
                            8 if node == "T" else 0, 1])[0]
        if kind in ("pair", "lone", "past", "nan", "dup"):
            r = rng.choice([0.5, 1.0, 2.5])
            add("q", r, ms)
        if kind == "other":
            add("c", rng.choice([0.0, 0.5, -0.5]), ms)
        y = r - rng.choice([0.25, 0.5]) if rng.random() > 0.2 else r + 1.0
        if kind in ("pair", "answer", "other"):
            add("a", y, ms + rng.choice([0, 0, 1]))
        if kind == "past":
            add("a", y, ms + 8)
        if kind == "nan":
            add("a", math.nan, ms + 1)
        if kind == "dup":
            add("a", y, ms + 1)
            add("a", r + 1.0, ms + 2)
        if kind == "tick":
            add("tick", 0.0, ms)
    return events


@pytest.mark.parametrize("node", ["B", "T", "D"])
def test_random_runs_with_late_messages_equal_the_engine(tmp_path: Path, node: str) -> None:
    rng = random.Random(f"late-{node}")
    undecided = 0
    for case in range(8):
        events = _random_run(rng, node, rng.choice([0.01, 0.05, 0.2]))
        chunk = rng.choice([5, 16, 64, 4096])
        skew = rng.choice([0.0, 0.0, 0.003])
        plain, _ = _agree(node, events, tmp_path, chunk, skew, rng.choice([0, MIN_RUN]))
        undecided += plain.counts["inconclusive"]
    assert undecided > 0  # late questions were answered wrongly


def test_control_a_batch_path_ignoring_lateness_is_caught(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Control: the batch path with every row's lateness ignored (as its pairs were judged before) counts the
    late question's wrong answer ``violated``, which the engine does not, from events and from the log, and
    differs from the engine on the random runs."""
    events = _pairs(60, {30: "q"}, {30})
    log = _log(tmp_path / "run.jsonl", events)
    engine = _judged("B", events, False, 64, False)[0]
    assert engine.counts["violated"] == 0 and engine.counts["inconclusive"] == 1
    monkeypatch.setattr(batch_module, "own_times", lambda chunk: None)
    for source in (events, log):
        wrong = _judged("B", source, False, 64, True)[0]
        assert wrong.counts["violated"] == 1 and wrong != engine
    caught = 0
    rng = random.Random("late-control")
    for _ in range(6):
        run = _random_run(rng, "B", 0.2)
        s = _judged("B", run, False, 64, False)[0]
        b = _judged("B", run, False, 64, True)[0]
        caught += b != s
    assert caught > 0
