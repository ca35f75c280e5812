"""The offline batch path: one node's contract judged on a whole recorded trace, column-wise.

Offline, a run is a batch: most of it is a node answering each
input message with one output message, every formula far from its
boundaries.  This module reads the trace in chunks (:data:`CHUNK` events;
:mod:`.rows`: a list of events, or a block of a ROSMonitoring log read as
columns, traces/jsonl_blocks.py, whose events are made only for the rows
the engine or the batch path's state needs), finds those rows (a
**pair**: an input message and the output message that follows it, the
output the answer the stream model gives it, docs/semantics.md),
evaluates the assumptions and guarantees over the chunk's columns in
float64 with a certificate per row (:mod:`.columns`), and gives the rows
surely true in exact arithmetic their ``satisfied`` verdict directly.  A
row surely violated (assumptions surely true, the one guarantee surely
false, its margin negative) is counted directly too once the run's
:data:`~.verdicts.KEPT_VIOLATIONS` violation records are full and no
verdict callback is given: the engine would only count it (closing.py);
before that the engine renders its values and reason.  With a transport
skew, only one the engine would release within the run
(:meth:`.batch_pairs.PairRuns._released`).  Every other event (an input with
no answer, an answer past the horizon or duplicated, a value that does not
map, a formula near a boundary, a message of another topic, a message heard
later than the lateness bound or carrying a source time, :mod:`.batch_late`,
and the pair it is part of) goes through the streaming engine
(:class:`~.engine.NodeMonitor`, its ``feed``) exactly as
:func:`~.check.check_trace` would feed it, so its verdict is the engine's by
construction.

The two share one engine: before a run of batch rows the engine must be
**quiet** (no output held for the transport skew, the watched question
answered in full, nothing a new question would supersede), so the rows'
verdicts are the engine's fast path's (``satisfied``, ``exact``, no
reason); after them the engine's small state is set as feeding them would
have set it (the values, the clock, the counts, the last questions and
recent outputs it keeps, the watched question).  Memory is the chunk's
columns and that small state: flat in the trace's length.  A chunk whose
pairs come in many short runs (fewer than :data:`MIN_RUN` pairs a run on
average) is fed to the engine whole: there a run costs more than the engine.

Eligible (:func:`batch_plan`), else the caller streams: one node; no
service or action link, no state topic; every ``triggered by`` guarantee
triggered by one and the same input (a pair whose input is that one owes
every guarantee: batched; a pair another input raises owes a triggered
guarantee only as carried from the question before it: the engine's;
the first batched question takes the triggers the question before it left
unanswered, as :meth:`~rclverify.traces.questions.QuestionStream.ask`
carries them, and each batched question's trigger is answered by its
pair's output; the deadline part is :mod:`.batch_deadlines`'); every topic
carries one ``REAL``, enumeration or window (``NATURAL --> REAL`` from an
array, :mod:`.batch_window`) variable through a rule naming one
field; one output topic; every guarantee reads the output (one that reads no
input is output-only: judged on each answer on the outputs as they stand,
its margin on no question, as the engine judges it), and Z3 showed only an
answer decides them, or for a windowed node :func:`.batch_window.answer_only`
showed it (the engine evaluates nothing when a question comes; a triggered
node's questions the engine evaluates without asking Z3, and finds nothing
decided when Z3 showed it: the batch path asks);
every formula compiled by :mod:`rclverify.targets.columns` (windows:
:mod:`rclverify.targets.column_windows`).
"""
from __future__ import annotations

import gc
from itertools import repeat
from typing import Callable, Iterable, Mapping

from rclverify.core.numeric import np

from rclverify.semantics.floatsem import Tolerance
from rclverify.semantics.floatsens import float_sensitive
from rclverify.lang.types import Checked, CheckedNode
from rclverify.traces.events import Event
from rclverify.traces.jsonl_blocks import LogBlock
from rclverify.traces.mapping import TopicRule
from rclverify.traces.questions import Question
from rclverify.backends.monitors.answered import AnsweredRun
from rclverify.backends.monitors.batch_late import own_times
from rclverify.backends.monitors.batch_lone import LoneSlots, lone_eligible
from rclverify.backends.monitors.batch_pairs import PairRuns
from rclverify.backends.monitors.batch_plan import BatchPlan, batch_plan
from rclverify.backends.monitors.batch_state import _kept
from rclverify.backends.monitors.batch_violations import violated_semantics
from rclverify.backends.monitors.batch_window import window_column
from rclverify.backends.monitors.engine import NodeMonitor
from rclverify.backends.monitors.rows import BlockRows, EventRows, chunks, rows_of
from rclverify.backends.monitors.verdicts import KEPT_VIOLATIONS, NodeResult, Verdict

#: Events read per chunk: the columns held at once (a log's read of about 1 MiB is one chunk when it holds fewer
#: lines: each chunk costs the state set after it and the questions and outputs it keeps, whatever its length).
CHUNK = 65536
#: The fewest pairs per run of pairs back to back, on average, for which a chunk of more than one run is judged
#: in batch: a run costs the batch path about 300-450 microseconds whatever its length (its columns sliced, its
#: formulas and margins evaluated, the engine's state set), the engine about 20 a message; measured on runs of L
#: answered triggers between lone triggers, 60,000 events, margins on (CPU s batched / fed whole): L = 1 5.94 /
#: 1.47, 4 2.93 / 1.47, 8 1.60 / 1.14, 16 0.81 / 1.28, 64 0.20 / 1.29.  A chunk of shorter runs is fed to the
#: engine whole, which is its verdicts by construction.
MIN_RUN = 12
_EMPTY: Mapping[str, int] = {}


def check_batch(checked: Checked, node: CheckedNode, events: Iterable[Event], rules: Mapping[str, TopicRule],
                horizon: float, on_verdict: Callable[[Verdict], None] | None = None,
                tolerance: Tolerance | None = None, end: float | None = None, chunk: int = CHUNK,
                stats: dict[str, int] | None = None, margins: bool = False,
                min_run: int = MIN_RUN) -> tuple[int, NodeResult] | None:
    """:func:`~.check.check_trace` for one node, in batches: (events read, the
    node's result), the same verdicts in the same order to ``on_verdict``;
    ``None`` before reading any event when the node is not eligible (module
    docstring).  ``chunk``: events (a log's lines) read at once (>= 2); ``stats``, when given,
    receives ``batched`` (answer pairs judged in batches) and ``streamed``
    (events fed to the streaming engine).  ``margins``: the space margins too
    (:func:`~.check.check_trace`; a batch row's in float64 columns,
    :mod:`rclverify.targets.column_margins`, where every guarantee's is
    positive, as the engine computes it in doubles; every other row is the
    engine's).  ``min_run``: a chunk whose pairs come in shorter runs on average
    is fed to the engine whole (:data:`MIN_RUN`; 0 batches every run).  Raises what the event source raises."""
    m = NodeMonitor(checked, node, rules, horizon, on_verdict, tolerance)
    m.margins = margins
    plan = batch_plan(m, rules)
    if plan is None:
        return None
    run = _Run(plan)
    run.min_run = min_run
    count, last_time = 0, 0.0
    carry: list[Event] = []
    was = gc.isenabled()
    gc.disable()  # the chunk's events hold no cycles: refcounting frees them (the collector's passes cost 2x)
    source = chunks(events, max(chunk, 2), plan.fields)
    try:
        while True:
            try:
                got = next(source)
            except StopIteration:
                break
            except BaseException:  # the events before the source's error are judged as the engine judges them
                for ev in carry:
                    run.feed(ev)
                raise
            rows = rows_of(carry, got)
            count += len(rows) - len(carry)
            last_time = rows.last_time
            carry = run.chunk(rows)
            if isinstance(got, LogBlock):  # its decoded rows, judged: freed now (jsonl_blocks.py, ``release``)
                got.release()
        for ev in carry:
            run.feed(ev)
    finally:
        if was:
            gc.enable()
    m.advance(max(last_time, end) if end is not None else last_time)
    if stats is not None:
        stats.update(batched=run.batched, streamed=run.streamed)
    return count, m.finish()


class _Run(PairRuns, LoneSlots):
    """The batch path over one trace: the shared engine and the chunk loop."""

    def __init__(self, plan: BatchPlan) -> None:
        self.plan, self.m = plan, plan.m
        self.kinds = {t: j for j, t in enumerate(plan.inputs, 1)}
        self.kinds[plan.output[0]] = -1
        self.batched = self.streamed = 0
        self.min_run = MIN_RUN
        #: runs of batch pairs whose older questions the stream keeps unmade (None), oldest first
        self.ghosts: list[AnsweredRun] = []
        self.fields = {key: field for key, field, _ in plan.inputs.values()}
        self.node_topics = frozenset(self.kinds)
        m = self.m
        #: surely violated answers are judged in batches too once nothing renders them: one guarantee (its first
        #: false one is the only one judged), no verdict callback (closing.py: a violation past the kept records
        #: is only counted); with a transport skew, only those released within their run (batch_pairs.py, _released)
        #: (a declared tolerance that could make a false row hold within it, and a window's quantifier the double
        #: reading cannot enumerate, where the engine's verdict is inconclusive: the engine's)
        g = m.guarantees[0] if len(m.guarantees) == 1 else None
        self.wrong = g is not None and m.on_verdict is None and not (
            m.tolerance and float_sensitive(g, m.checked, m.node, tolerant=True)) and not (
            plan.widths and float_sensitive(g, m.checked, m.node))
        #: surely violated answers of a guarantee read against a question are judged in batch before the records are
        #: full too, each record written as the engine writes it (batch_violations.py); an output-only one's the engine's
        self.records = self.wrong and not m._alone
        #: the semantics of such a violation (batch_violations.py)
        self.violated_as = violated_semantics(m) if self.records else ""
        #: a violated answer of a guarantee on a question is held for the skew (an output-only one is not)
        self.held = bool(m.stream.skew) and not m._alone
        #: ``triggered by``: the column code of the input every triggered guarantee answers (0: no trigger)
        codes = {key: self.kinds[t] for t, (key, _, _) in plan.inputs.items()}
        #: ``triggered by``: per guarantee in order, the column code of the input triggering it (0: untriggered);
        #: empty when none is triggered
        self.owing = [codes[plan.triggers[k]] if k in plan.triggers else 0 for k in range(1, len(m.guarantees) + 1)] \
            if plan.triggers else []
        self.trigger_of = {c: k for k, c in codes.items()}
        #: a chunk of short runs of lone triggers and answers judged in batch where clean (batch_lone.py)
        self.lone = lone_eligible(m, plan)

    def _full(self) -> bool:
        """Whether the run's violation records are full: a further violation is only counted."""
        result = self.m.result
        return result.first_violation is not None and len(result.violations) >= KEPT_VIOLATIONS

    def feed(self, ev: Event) -> None:
        """``ev`` to the engine, the kept questions made first when it may look one up (stamped before the latest)."""
        self.streamed += 1
        if self.ghosts and ev.topic in self.node_topics:
            stamps = self.m.stream._stamps
            if stamps and (ev.time if ev.stamp is None else ev.stamp) < stamps[-1]:
                self._materialise()
        self.m.feed(ev)

    def _materialise(self) -> None:
        """Make every question the stream keeps as ``None`` (the latest ghosts, in order)."""
        qs = _kept(self.m.stream)
        left = qs.count(None)
        made: list[Question] = []
        for g in reversed(self.ghosts):
            if len(made) >= left:
                break
            made[:0] = [g.question(j, self) for j in range(max(0, len(g.at) - 1 - (left - len(made))),
                                                           len(g.at) - 1)]
        made = made[len(made) - left:]
        it = iter(made)
        self.m.stream._questions = [q if q is not None else next(it) for q in qs]
        self.ghosts.clear()

    def chunk(self, chunk: EventRows | BlockRows) -> list[Event]:
        """Judge ``chunk``; returns the events to carry to the next chunk (a last input whose answer may follow)."""
        plan, m = self.plan, self.m
        n = len(chunk)
        block = chunk if isinstance(chunk, BlockRows) else None
        kind = None
        if block is not None and not isinstance(block.block, LogBlock):
            kind = block.kinds(self.kinds)  # a bag block's topic codes are its reader's: no string a row
        if kind is None:
            kind = self._alternating(chunk.topics)  # two counts, where the node's two topics take turns
        if kind is None and block is not None:
            kind = block.kinds(self.kinds)  # a log block's topic codes, made once (the deadline judge reads them)
        if kind is None:
            kind = np.fromiter(map(self.kinds.get, chunk.topics, repeat(0)), np.int8, n)
        times = chunk.times
        if n > 1 and not self._long_runs(kind, times):
            i = self._lone(chunk, kind, times) if self.lone else 0
            for ev in chunk[i:n]:
                self.feed(ev)
            return []
        ok = kind != 0
        unstamped = chunk.unstamped()
        if unstamped is not None:
            ok &= unstamped
        own = own_times(chunk)  # heard later than the lateness bound, or a source time: the engine's (batch_late.py)
        if own is not None:
            ok &= ~own
        cols: dict[str, np.ndarray] = {}
        full: np.ndarray
        for topic, j, (key, field, kind_) in [(plan.output[0], -1, plan.output[1:])] + \
                [(t, self.kinds[t], v) for t, v in plan.inputs.items()]:
            rows = np.flatnonzero(kind == j)
            if kind_ == "window":  # a window: its message's array, (rows, width) (batch_window.py)
                width = plan.widths[key]
                good, col = window_column(chunk.values(rows, field), width)
                full = np.zeros((n, width))
            else:
                good, col = chunk.typed(rows, field, kind_, plan.enums.get(key, _EMPTY))
                full = np.zeros(n, dtype=np.float64 if kind_ == "real" else np.int64)
            ok[rows] &= good
            full[rows] = col
            cols[key] = full
        # a pair: an input at i, its answer at i + 1, both mapped, stamped in order, the answer within the horizon
        h = m.horizon
        start = np.zeros(n, dtype=bool)
        if n > 1:
            t0, t1 = times[:-1], times[1:]
            start[:-1] = (kind[:-1] > 0) & (kind[1:] == -1) & ok[:-1] & ok[1:] & (t0 <= t1) & (t1 <= t0 + h)
        keep: list[Event] = []
        if kind[-1] > 0 and ok[-1]:
            keep = [chunk[-1]]  # its answer may be the next chunk's first event
            n -= 1
        pairs = np.flatnonzero(start[:n])
        # runs of pairs back to back, times in order: split where the next pair does not follow on
        link = (pairs[1:] == pairs[:-1] + 2) & (times[pairs[1:]] >= times[pairs[:-1] + 1])
        ends = np.append(np.flatnonzero(~link), len(pairs) - 1) if len(pairs) else np.zeros(0, dtype=np.int64)
        feed = self.feed
        i, k = 0, 0
        for e in ends.tolist():
            run = pairs[k:e + 1]
            for ev in chunk[i:int(run[0])]:  # not a pair: the engine
                feed(ev)
            i = self._pairs(chunk, run, kind, times, cols)
            k = e + 1
        for ev in chunk[i:n]:
            feed(ev)
        return keep

    def _long_runs(self, kind: np.ndarray, times: np.ndarray) -> bool:
        """Whether the chunk's pairs (an input, then an output stamped within the horizon after it; whether
        both map is not read) are one run back to back, or runs of :attr:`min_run` or more pairs on average."""
        t0, t1 = times[:-1], times[1:]
        start = (kind[:-1] > 0) & (kind[1:] == -1) & (t0 <= t1) & (t1 <= t0 + self.m.horizon)
        pairs = np.flatnonzero(start)
        if not len(pairs):
            return False
        runs = 1 + int(np.count_nonzero(pairs[1:] != pairs[:-1] + 2))
        return len(pairs) >= self.min_run * (runs - 1)  # (one run: its cost is paid once)

    def _alternating(self, topics: list[str]) -> np.ndarray | None:
        """Each event's topic as its column code (an input topic's number, -1 the output's) where the node's one
        input topic and its output topic take turns (the common case, read by two counts), else ``None``."""
        n = len(topics)
        if len(self.kinds) == 2 and n > 1:
            (a, ka), (b, kb) = self.kinds.items()
            even, odd = topics[0::2], topics[1::2]
            for x, kx, y, ky in ((a, ka, b, kb), (b, kb, a, ka)):
                if even.count(x) == len(even) and odd.count(y) == len(odd):
                    kind = np.empty(n, dtype=np.int8)
                    kind[0::2], kind[1::2] = kx, ky
                    return kind
        return None


__all__ = ["CHUNK", "MIN_RUN", "BatchPlan", "batch_plan", "check_batch"]
