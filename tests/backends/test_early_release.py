"""The live engine's early release: a watermark per writer, past the clock less the lateness bound.

Where the source names each sample's writer and matches each contract topic's writers
(:meth:`OnlineEngine.match`, as both ROS 2 sources do), a message is released once every matched and
every heard writer has been heard past it, or has been silent for longer than the lateness bound on
its own clock (docs/semantics.md, "Event time"), not only once the clock less the bound passed it.

The unit cases feed the engine with an injected clock (``tick(now)``, ``watermark(now)``): the release
when every matched writer has been heard past; the hold while a matched writer is silent for less
than the bound, or not heard yet; a writer whose stamps went back capped at the bound less its lag;
a topic with no writer matched, or no sets told at all, keeping the clock less the bound; a writer
matched late whose first message is older than the watermark: late, and no verdict of a correct node
violated.  Each has its control in the same case.

Live = log: a run released early, with and without a reading publisher matched late whose reading is
late, its log written by the live run itself (``LiveRun``), is judged verdict by verdict as the offline check of
that log judges it (bench/_robot_verdicts.py's comparison), no correct answer red.

The oracle: random runs (several writers on one topic, monotone stamps per writer, a stamp-copying
relay answering in stamp order with a lag that grows, delivery delays below the bound, in order per
writer) fed in arrival order with the timer every 5 ms: every message's last verdict equals that of
the same messages all pushed first and drained at the end, and no message is late.  The control: the
engine with the writers' lag left out of the watermark (a seeded defect) makes the relay's answers late.
"""
from __future__ import annotations

import random
from pathlib import Path
from typing import Any

import pytest

from rclverify.backends.monitors import online
from rclverify.backends.monitors.config import load_mapping
from rclverify.backends.monitors.online import OnlineEngine
from rclverify.lang.typecheck import load
from test_judge_event_time import _stamp, _workspace

L = 0.05  # the lateness bound (s), the CLI's

RCL = """
node Relay {
  inputs( x : REAL )
  outputs( r : REAL )
  topics( pkg/Reading x matches(in.x), pkg/Range r matches(out.r) )
  assume( TRUE )
  guarantee( out.r == in.x )
}
node Watch {
  inputs( y : REAL )
  outputs( z : REAL )
  topics( pkg/Reading y matches(in.y), pkg/Range z matches(out.z) )
  assume( TRUE )
  guarantee( out.z <= in.y )
}
"""
MAPPING = ("topics:\n  x: {fields: [value]}\n  r: {fields: [range]}\n  y: {fields: [value]}\n"
           "  z: {fields: [range]}\n")
ALL = {"x": [b"X"], "r": [b"R"], "y": [b"Y"], "z": [b"Z"]}


@pytest.fixture(scope="module")
def contracts(tmp_path_factory: pytest.TempPathFactory) -> tuple[Any, Any]:
    ws, _ = _workspace(tmp_path_factory.mktemp("early"), RCL, [], MAPPING)
    checked = load([ws / "contracts" / "c.rcl"])
    return checked, load_mapping(ws, "mapping.yaml").rules


def _engine(contracts: tuple[Any, Any], got: list[Any] | None = None, events: list[Any] | None = None) -> OnlineEngine:
    checked, rules = contracts
    return OnlineEngine(checked, [checked.nodes["Relay"], checked.nodes["Watch"]], rules, 1.0, reorder_window=L,
                        on_verdict=None if got is None else got.append,
                        on_event=None if events is None else events.append)


def _put(eng: OnlineEngine, topic: str, value: float, stamp: float, source: float, writer: bytes,
         where: str = "") -> None:
    field = "value" if topic in ("x", "y") else "range"
    eng.push(topic, {field: value, **_stamp(stamp)}, source, where, writer=writer)


def _heard_at(eng: OnlineEngine, t: float) -> None:
    """Every writer of :data:`ALL` heard with a message stamped and published at ``t``."""
    for topic, (w,) in ALL.items():
        _put(eng, topic, 1.0, t, t, w)


# -- the rule, clock injected ---------------------------------------------------------------------------
def test_every_matched_writer_heard_past_a_message_releases_it_before_the_bound(contracts: tuple[Any, Any]) -> None:
    events: list[Any] = []
    eng = _engine(contracts, events=events)
    eng.match({f"/{t}": ws for t, ws in ALL.items()})
    _heard_at(eng, 1.0)
    _heard_at(eng, 1.002)
    assert eng.watermark(1.003) == pytest.approx(1.002)  # every writer heard up to 1.002 s: 47 ms before the bound
    assert eng.due() == -float("inf")  # due already: the worker ticks after the batch
    eng.tick(1.003)
    assert len(events) == 8
    # the control: the same messages, no writer set told: the clock less the bound
    events2: list[Any] = []
    eng2 = _engine(contracts, events=events2)
    _heard_at(eng2, 1.0)
    _heard_at(eng2, 1.002)
    assert eng2.watermark(1.003) == pytest.approx(1.003 - L)
    assert eng2.due() == pytest.approx(1.0 + L)
    eng2.tick(1.003)
    assert events2 == []


def test_a_matched_writer_silent_for_less_than_the_bound_or_never_heard_holds_the_release(
        contracts: tuple[Any, Any]) -> None:
    eng = _engine(contracts)
    eng.match({**ALL, "x": [b"X", b"X2"]})
    _heard_at(eng, 1.0)
    assert eng.watermark(1.01) == pytest.approx(1.01 - L)  # X2 matched, not heard: the clock less the bound
    assert eng.due() == pytest.approx(1.0 + L)
    _put(eng, "x", 1.0, 0.99, 0.99, b"X2")
    assert eng.watermark(1.01) == pytest.approx(0.99)  # heard up to 0.99 s, silent for 20 ms: held there
    assert eng.watermark(1.039) == pytest.approx(0.99)
    assert eng.watermark(1.045) == pytest.approx(0.995)  # silent past the bound: the clock less the bound
    _put(eng, "x", 1.0, 1.0, 1.0, b"X2")
    assert eng.watermark(1.01) == pytest.approx(1.0)  # the control: heard past, released


def test_a_writer_whose_stamps_went_back_is_capped_at_the_bound_less_its_lag(contracts: tuple[Any, Any]) -> None:
    eng = _engine(contracts)
    eng.match(ALL)
    _heard_at(eng, 1.0)
    _put(eng, "r", 1.0, 1.05, 1.07, b"R")  # 20 ms after its stamp
    _heard_at(eng, 1.1)
    assert eng.watermark(1.101) == pytest.approx(1.1)  # the control: in order, heard up to 1.1 s
    _put(eng, "r", 1.0, 1.08, 1.105, b"R")  # stamped before its previous one: it copies two inputs' stamps
    assert eng.watermark(1.106) == pytest.approx(1.106 - L - 0.025)  # its lag is the most it published after
    _heard_at(eng, 1.2)
    assert eng.watermark(1.21) == pytest.approx(1.21 - L - 0.025)  # from then on, heard past or not


@pytest.mark.parametrize("sets", [None, {"x": [b"X"], "r": [b"R"], "y": [b"Y"]}, {**ALL, "z": []}],
                         ids=["no sets told", "a topic not told", "a topic with no writer"])
def test_a_topic_whose_writers_are_not_known_keeps_the_clock_less_the_bound(
        contracts: tuple[Any, Any], sets: dict[str, list[bytes]] | None) -> None:
    eng = _engine(contracts)
    if sets is not None:
        eng.match(sets)
    _heard_at(eng, 1.0)
    assert eng.watermark(1.01) == pytest.approx(1.01 - L)
    eng.match(ALL)  # the control: every topic's writers told
    assert eng.watermark(1.01) == pytest.approx(1.0)


@pytest.mark.parametrize("form", ["hex", "prefix", "same"], ids=["hex text", "guid prefix", "control: as sampled"])
def test_matched_ids_in_another_form_than_the_samples_never_release_early(contracts: tuple[Any, Any],
                                                                          form: str) -> None:
    """The matched sets name the writers in another form than the samples do (hex text for bytes, a
    GUID's 12-byte participant prefix for its 16 bytes): no matched writer is ever heard, so the
    release stays at the clock less the bound, never earlier (nothing made late by it)."""
    guid = {t: bytes([k + 1]) * 16 for k, t in enumerate(ALL)}
    told = {t: [g.hex() if form == "hex" else g[:12] if form == "prefix" else g] for t, g in guid.items()}
    events: list[Any] = []
    eng = _engine(contracts, events=events)
    eng.match(told)
    for t in (1.0, 1.002):
        for topic, g in guid.items():
            _put(eng, topic, 1.0, t, t, g)
    if form == "same":
        assert eng.watermark(1.003) == pytest.approx(1.002)
    else:
        assert eng.watermark(1.003) == pytest.approx(1.003 - L)
        eng.tick(1.003)
        assert events == [] and eng.released_early == 0


@pytest.mark.parametrize("gated", [True, False], ids=["a gate's topic", "control: no gate"])
def test_a_run_with_a_gates_topics_keeps_the_clock_less_the_bound(contracts: tuple[Any, Any], gated: bool) -> None:
    """A managed node's transition topic (:attr:`OnlineEngine.gate_topics`) has no matched writer: the
    release is never early, every contract topic's writers matched and heard or not."""
    eng = _engine(contracts)
    if gated:
        eng.gate_topics = frozenset({"node/transition_event"})
    eng.match(ALL)
    _heard_at(eng, 1.0)
    assert eng.watermark(1.01) == pytest.approx(1.01 - L if gated else 1.0)


def test_a_writer_matched_late_whose_first_message_is_older_than_the_watermark_is_late_never_violated(
        contracts: tuple[Any, Any]) -> None:
    def run(matched_from_start: bool) -> tuple[int, list[tuple[str, str]]]:
        got: list[Any] = []
        eng = _engine(contracts, got)
        eng.match({**ALL, "x": [b"X", b"X2"]} if matched_from_start else ALL)
        for i in range(5):
            t = 1.0 + 0.1 * i
            _put(eng, "x", float(i), t, t, b"X", f"x{i}")
            _put(eng, "r", float(i), t, t + 0.01, b"R", f"r{i}")
            _put(eng, "y", 1.0, t, t, b"Y")
            _put(eng, "z", 0.0, t, t + 0.01, b"Z")
            eng.tick(t + 0.012)
        if not matched_from_start:
            eng.match({**ALL, "x": [b"X", b"X2"]})  # a publisher discovered now
        # its first message, published 1.395 s, heard 17 ms later (after the tick at 1.412 s): within the
        # bound, but stamped before the 1.4 s every writer matched had been heard past
        _put(eng, "x", 9.0, 1.39, 1.395, b"X2", "new")
        eng.tick(1.47)
        eng.finish()
        return eng.late, [(v.where, v.verdict) for v in got if v.node == "Relay"]
    late, verdicts = run(False)
    assert late == 1
    assert "violated" not in {v for _, v in verdicts}
    assert ("new", "satisfied") not in verdicts
    # the control: matched before it was heard, it holds the watermark at the clock less the bound
    late, verdicts = run(True)
    assert late == 0


@pytest.mark.parametrize("restarted", [True, False], ids=["node restarted", "control: the same writer"])
def test_a_writer_gone_holds_the_release_at_the_bound_for_the_rest_of_the_run(contracts: tuple[Any, Any],
                                                                            restarted: bool) -> None:
    """A node restarted publishes under a new writer id: the old writer, heard, stays a writer and,
    silent, is past the clock less the bound only (its lag 0 here); the control keeps publishing
    under its first id and the release stays early."""
    eng = _engine(contracts)
    eng.match(ALL)
    _heard_at(eng, 1.0)
    assert eng.watermark(1.001) == pytest.approx(1.0)
    if restarted:
        eng.match({**ALL, "r": [b"R2"]})  # the old writer unmatched, the new one matched
    for i in range(1, 20):
        t = 1.0 + 0.01 * i
        for topic, (w,) in ALL.items():
            _put(eng, topic, 1.0, t, t, b"R2" if restarted and topic == "r" else w)
    assert eng.watermark(1.191) == pytest.approx(1.191 - L if restarted else 1.19)


def _answers_out_of_order(contracts: tuple[Any, Any], early: bool) -> tuple[int, dict[str, str]]:
    """Readings every 10 ms from ``X`` and, 5 ms after each, from ``X2``; ``y``/``z`` every 5 ms; a relay
    ``R`` answering each reading right, its stamp copied, 2 ms after it, but twice (at 1.1 s and 1.2 s)
    answering ``X2``'s reading 12 ms after it, after ``X``'s next reading's answer and ``X2``'s next
    reading: its stamps go back, heard 0.5 ms after publication, within the bound.  The timer every
    1 ms; ``early``: every writer matched.  The late count and each message's last verdict."""
    got: list[Any] = []
    eng = _engine(contracts, got)
    if early:
        eng.match({"x": [b"X", b"X2"], "r": [b"R"], "y": [b"Y"], "z": [b"Z"]})
    sent: list[tuple[float, str, float, float, float, bytes, str]] = []
    for i in range(30):
        for k, (writer, t) in enumerate(((b"X", 1.0 + 0.01 * i), (b"X2", 1.005 + 0.01 * i))):
            sent.append((t + 0.0005, "x", 100.0 * k + i, t, t, writer, f"x{k}.{i}"))
            pub = t + (0.012 if k == 1 and i in (9, 19) else 0.002)
            sent.append((pub + 0.0005, "r", 100.0 * k + i, t, pub, b"R", f"r{k}.{i}"))
    for i in range(60):
        t = 1.0 + 0.005 * i
        sent += [(t + 0.0005, "y", 1.0, t, t, b"Y", f"y{i}"), (t + 0.0015, "z", 0.0, t, t + 0.001, b"Z", f"z{i}")]
    now = 1.0
    for at, topic, value, stamp, pub, writer, where in sorted(sent):
        while now + 0.001 <= at:
            now += 0.001
            eng.tick(now)
        _put(eng, topic, value, stamp, pub, writer, where)
    eng.finish()
    return eng.late, {v.where: v.verdict for v in got}


def test_a_writers_first_message_placed_before_its_previous_one_is_late_where_the_bound_orders_it(
        contracts: tuple[Any, Any]) -> None:
    """The price of the early release for a node copying the stamps of two inputs: until one of its
    messages was placed before its own previous one nothing says it may, so that first one (here the
    answer to ``X2``'s reading at 1.095 s, published after the answer stamped 1.1 s) is late, and the
    questions around it undecided, never violated; from then on it is capped (the second, at 1.195 s,
    is not late).  The control: the same run at the clock less the bound, nothing late, all satisfied."""
    late, verdicts = _answers_out_of_order(contracts, early=True)
    assert late == 1
    assert "violated" not in verdicts.values()
    assert {v for v in verdicts.values()} - {"satisfied"}  # undecided around the late answer
    late, verdicts = _answers_out_of_order(contracts, early=False)
    assert late == 0
    assert set(verdicts.values()) == {"satisfied"}


# -- the oracle ---------------------------------------------------------------------------------------
#: one message: (arrival s, topic, value, stamp s, publication s, writer, where)
Sent = tuple[float, str, float, float, float, bytes, str]


def _random_run(seed: int) -> list[Sent]:
    """Two writers of ``x`` and one of ``y``, each at its own jittered period; a relay ``R``
    answering every ``x`` in stamp order with its stamp copied, published up to 300 ms after it, its
    lag passing the most before by less than 40 % of the bound (the first below it), every third
    answer wrong; a watcher ``Z`` answering
    each ``y`` likewise; each message delivered within 60 % of the bound, in order per writer."""
    rng = random.Random(seed)
    sent: list[tuple[str, float, float, float, bytes]] = []  # topic, value, stamp, publication, writer
    for topic, writer, period in (("x", b"X", 0.007), ("x", b"X2", 0.011), ("y", b"Y", 0.005)):
        t = 1.0 + rng.random() * period
        while t < 2.0:
            sent.append((topic, round(rng.uniform(0, 10), 3), t, t, writer))
            t += period * rng.uniform(0.5, 1.5)
    for question, answer, writer in (("x", "r", b"R"), ("y", "z", b"Z")):
        most = pub = 0.0  # the most it published after a stamp so far; its last publication
        for k, (_, value, stamp, _, _) in enumerate(sorted((s for s in sent if s[0] == question),
                                                           key=lambda s: s[2])):
            pub = max(pub, stamp + rng.uniform(0, min(0.3, most + 0.4 * L)))  # in order: never before the last
            most = max(most, pub - stamp)
            wrong = 0.5 if k % 3 == 2 else 0.0
            sent.append((answer, value + wrong if answer == "r" else value - wrong, stamp, pub, writer))
    out: list[Sent] = []
    arrived: dict[bytes, float] = {}
    order: list[tuple[float, int, Sent]] = []
    for k, (topic, value, stamp, pub, writer) in enumerate(sorted(sent, key=lambda s: (s[3], s[2]))):
        at = max(arrived.get(writer, 0.0), pub + rng.uniform(0, 0.6 * L))
        arrived[writer] = at
        order.append((at, k, (at, topic, value, stamp, pub, writer, f"{topic}{k}")))
    return [m for _, _, m in sorted(order)]  # in arrival order, each writer's in the order it published


def _last_verdicts(got: list[Any]) -> dict[tuple[str, str], str]:
    last = {(v.node, v.where): v.verdict for v in got}
    return {k: v for k, v in last.items() if v != "withdrawn"}


def _online(contracts: tuple[Any, Any], run: list[Sent]) -> tuple[dict[tuple[str, str], str], int, float]:
    """Fed in arrival order, the timer every 5 ms and before each message; the verdicts, the late
    count and how far past the clock less the bound the watermark reached at most (s)."""
    got: list[Any] = []
    eng = _engine(contracts, got)
    eng.match({"x": [b"X", b"X2"], "r": [b"R"], "y": [b"Y"], "z": [b"Z"]})
    now, ahead = run[0][0], -1.0
    for at, topic, value, stamp, pub, writer, where in run:
        while now + 0.005 <= at:
            now += 0.005
            eng.tick(now)
        eng.tick(at)
        ahead = max(ahead, eng.watermark(at) - (at - L))
        _put(eng, topic, value, stamp, pub, writer, where)
    eng.finish()
    return _last_verdicts(got), eng.late, ahead


def _drained(contracts: tuple[Any, Any], run: list[Sent]) -> dict[tuple[str, str], str]:
    """The same messages pushed first, released only at the end (in stamp order): the whole run's judgement."""
    got: list[Any] = []
    eng = _engine(contracts, got)
    for _at, topic, value, stamp, pub, writer, where in run:
        _put(eng, topic, value, stamp, pub, writer, where)
    eng.finish()
    assert eng.late == 0
    return _last_verdicts(got)


SEEDS = list(range(12))


@pytest.mark.parametrize("seed", SEEDS)
def test_early_release_gives_the_whole_runs_verdicts_and_no_late_message(contracts: tuple[Any, Any],
                                                                          seed: int) -> None:
    run = _random_run(seed)
    live, late, ahead = _online(contracts, run)
    assert late == 0
    assert ahead > 0.005  # released before the clock less the bound
    whole = _drained(contracts, run)
    assert live == whole
    assert {"satisfied", "violated"} <= set(whole.values())


def test_the_control_the_writers_lag_left_out_makes_the_relays_answers_late(
        contracts: tuple[Any, Any], monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(online, "_heard_upto", lambda last, lag, now, window: max(last, now - window))
    lates = [_online(contracts, _random_run(seed))[1] for seed in SEEDS[:4]]
    assert all(n > 0 for n in lates), lates


# -- the engine thread ----------------------------------------------------------------------------------
class _Sink:
    """A sink whose next release is due at once (``-inf``: every writer heard past it) while a message
    pushed since its last tick waits, or never; what it was asked, in order."""

    def __init__(self, due: float) -> None:
        self.calls: list[str] = []
        self.pushed: list[tuple[str, object]] = []
        self._due = due

    def push(self, topic: str, fields: Any, received: float, writer: bytes | str | None = None) -> None:
        self.pushed.append((topic, writer))
        self.calls.append("push")

    def due(self) -> float:
        return self._due if self.calls and self.calls[-1] == "push" else float("inf")

    def tick(self, now: float) -> None:
        self.calls.append("tick")


@pytest.mark.parametrize("due, calls", [(-float("inf"), ["push", "tick", "push", "tick"]),
                                        (float("inf"), ["push", "push"])], ids=["due at once", "control"])
def test_the_engine_thread_ticks_right_after_a_batch_lets_the_watermark_pass_the_head(
        due: float, calls: list[str]) -> None:
    """Two messages queued, a batch of one: the tick comes between them, right after the batch whose
    message made the release due, not after the next batch (the timer's 100 s never comes).  Without
    the tick after a batch the loop's next wait (``due()`` read before it) would tick only after the
    second message was pushed: push, push, tick."""
    import time
    from rclverify.runtime.worker import EngineWorker
    sink = _Sink(due)
    worker = EngineWorker(sink, lambda topic, payload: payload, time.monotonic, tick_s=100.0, batch=1)
    worker.offer("x", {"value": 1.0}, time.monotonic(), b"X")
    worker.offer("x", {"value": 2.0}, time.monotonic(), b"X2")
    worker.start()
    try:
        end = time.monotonic() + 2.0
        while time.monotonic() < end and len(sink.calls) < len(calls):
            time.sleep(0.01)
        time.sleep(0.2)
        assert sink.calls == calls
        assert sink.pushed == [("x", b"X"), ("x", b"X2")]  # the writers' ids handed on
    finally:
        worker.stop()


# -- live = log, verdict by verdict -------------------------------------------------------------------
def _released_log(ws: Path, x2_matched_from_start: bool) -> tuple[Path, OnlineEngine]:
    """The live log of a relay copying each reading's stamp onto an answer 8 ms later (readings every
    20 ms), both heard 1 ms after publication, released early; a second reading publisher ``X2``
    (matched late, or from the start) sends one reading stamped between two, heard 30 ms after it.
    Written by the live run itself (runtime/live.py ``LiveRun``: each message at its time, a late one
    at its source time with ``late_s``, each verdict and each deadline verdict), the timer every 2 ms."""
    from rclverify.runtime.live import LiveRun
    checked = load([ws / "contracts" / "c.rcl"])
    rules = load_mapping(ws, "mapping.yaml").rules
    live = LiveRun(checked, [checked.nodes["Relay"]], rules, 1.0, ws / "live.jsonl", reorder_window=L)
    live.match({"x": [b"X"] + ([b"X2"] if x2_matched_from_start else []), "r": [b"R"]})
    heard: list[tuple[float, str, dict[str, Any], float, bytes]] = []  # heard, topic, fields, published, writer
    for i in range(30):
        t = 1.0 + 0.02 * i
        heard.append((t + 0.001, "x", {"value": float(i), **_stamp(t)}, t, b"X"))
        heard.append((t + 0.009, "r", {"range": float(i), **_stamp(t)}, t + 0.008, b"R"))
    t2 = 1.0 + 0.02 * 15 + 0.005
    heard.append((t2 + 0.03, "x", {"value": 15.0, **_stamp(t2)}, t2, b"X2"))
    now = 1.0
    for at, topic, fields, pub, writer in sorted(heard, key=lambda h: h[0]):
        while now + 0.002 <= at:
            now += 0.002
            live.tick(now)
        if topic == "x" and writer == b"X2" and not x2_matched_from_start:
            live.match({"x": [b"X", b"X2"], "r": [b"R"]})  # discovered now
        live.push(topic, fields, pub, writer)
    live.stop()
    return ws / "live.jsonl", live.engine


@pytest.mark.parametrize("from_start", [False, True], ids=["matched late: late", "matched from the start"])
def test_an_early_released_run_and_its_log_give_the_same_verdicts_one_by_one(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], from_start: bool) -> None:
    import json
    import sys
    from rclverify.backends.monitors.verdict_lines import log_records
    from test_judge_writers import COPY, COPY_MAPPING
    from test_verdict_by_verdict import _offline
    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bench"))
    from _robot_verdicts import compare, finals, tally
    ws, _ = _workspace(tmp_path, COPY, [], COPY_MAPPING)
    log, eng = _released_log(ws, from_start)
    lines = [json.loads(x) for x in log.read_text().splitlines()]
    assert eng.released_early > 0
    assert eng.late == (0 if from_start else 1)
    assert sum("late_s" in x for x in lines) == eng.late
    live, offline = finals(log_records(log)), finals(_offline(ws, log, capsys))
    assert compare(live, offline) == []
    counts = tally(live)["Relay"]
    assert counts.get("violated", 0) == 0 and counts.get("deadline false", 0) == 0, counts
    assert counts["satisfied"] == 30 and counts["deadline true"] == 30, counts  # X's readings, all answered


# -- the deadline checks' clock: the watermark the engine released up to ---------------------------------
FAST = """
node Relay {
  inputs( x : REAL )
  outputs( r : REAL )
  topics( pkg/Reading x matches(in.x), pkg/Range r matches(out.r) )
  assume( TRUE )
  guarantee( out.r == in.x ) triggered by in.x within 20 ms
}
"""


@pytest.mark.parametrize("handed_over", [True, False], ids=["sets handed over mid-tick", "control: before"])
def test_the_deadline_checks_never_pass_what_the_engine_released(tmp_path: Path, handed_over: bool) -> None:
    """The discovery thread hands the last topic's matched writers over (``LiveRun.match``, no lock)
    between the engine's release and the deadline checks' advance of one tick: the checks still stop
    at the watermark the engine released up to, so a deadline whose answer is buffered, stamped within
    it, gets no ``false`` (the log, read again, finds none: nothing was late)."""
    import json
    from rclverify.runtime.live import LiveRun
    ws, _ = _workspace(tmp_path, FAST, [], "topics:\n  x: {fields: [value]}\n  r: {fields: [range]}\n")
    checked = load([ws / "contracts" / "c.rcl"])
    published: list[dict[str, Any]] = []
    live = LiveRun(checked, [checked.nodes["Relay"]], load_mapping(ws, "mapping.yaml").rules, 1.0,
                   tmp_path / "live.jsonl", reorder_window=L, publish=lambda text: published.append(json.loads(text)))
    writers = {"x": [b"X"], "r": [b"R"]}
    live.match({"x": [b"X"]} if handed_over else writers)  # r's writer not matched yet: held at the bound
    tick = live.engine.tick

    def tick_then_handover(now: float) -> Any:
        upto = tick(now)
        live.match(writers)  # the discovery thread, between the release and the checks' advance
        return upto
    if handed_over:
        live.engine.tick = tick_then_handover  # type: ignore[method-assign]
    for stamp, topic, value, writer in ((1.045, "x", 1.0, b"X"), (1.06, "r", 1.0, b"R"),
                                        (1.1, "x", 2.0, b"X"), (1.1, "r", 2.0, b"R")):
        live.push(topic, {"value" if topic == "x" else "range": value, **_stamp(stamp)}, stamp, writer)
    live.tick(1.101)  # the bound (1.051) releases the reading at 1.045, not its answer at 1.06
    live.tick(1.12)
    live.stop()
    deadlines = [(p["trigger_stamp"], p["verdict"]) for p in published if p.get("kind") == "deadline"]
    assert (1.045, "false") not in deadlines, deadlines
    assert (1.045, "true") in deadlines
