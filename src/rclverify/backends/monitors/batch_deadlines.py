"""Deadlines judged in batch: the deadline monitor over a recorded run, a chunk of columns at a time.

:class:`BatchDeadlines` is the deadline monitor (:class:`~.deadlines.DeadlineMonitor`,
the rules of docs/semantics.md "Deadlines") with the same state and the
same results; it takes the run's events :data:`CHUNK` at a time, or a
log's blocks as the batch path reads them (:meth:`BatchDeadlines.feed_block`,
the offline check's reading: :mod:`.recorded`), and judges a chunk over its
columns when the chunk is **clean**, else feeds its events to the
streaming monitor one by one.  Either way the
monitor's state after the chunk is the one streaming it leaves (its open
and expired obligations with their outputs and the last output that did
not satisfy them, the values, the clock, the outputs heard, the counts, the
first ``false``, the time margins), so chunks of both kinds follow each
other in any order.

**Eligible** (:func:`deadline_monitor`; else the streaming monitor): numpy
installed; one input variable and one output variable, each on one topic
(no service or action link), each a ``REAL`` or an enumeration mapped
from one field named at the top level, no ``state`` topic; every
assumption and timed guarantee compiled by :mod:`rclverify.targets.columns`,
the assumptions reading the input alone; no declared tolerance.  With one
input, an obligation is judged on its trigger's own input and the answering
output (the question stream's later inputs are the trigger input, which
the trigger's own value replaces: :meth:`~.deadlines.DeadlineMonitor._visible`).

**Clean** (a chunk): no row carries a header stamp; the rows' times never
go back, from the monitor's clock on; every message on the node's two
topics carries its field as the columns hold it (the topic named as the
contract binds it); every trigger's assumption and every pair the search
judges is surely decided in exact arithmetic (:mod:`rclverify.targets.columns`);
no answer search passes :data:`~rclverify.targets.column_deadlines.PASSES`
outputs; the expired obligations never exceed the 256 the monitor keeps.
With the mapping's transport skew (:mod:`.deadline_skew`), each obligation
the chunk leaves unmet is marked as the monitor marks it when its trigger
comes (the outputs heard before the chunk, then the chunk's before the
trigger, within the skew, the first on which the guarantee holds exactly,
judged by the monitor's own code); a marked one unanswered by its deadline is
counted ``undecided`` (no verdict, no time margin), its late answer gives
none; a chunk where such a window holds more than the 64 outputs the monitor
keeps, or where an assumption's refusal and an undecided trigger would race
to be the first unaccepted, is streamed.
A late or out-of-order stamp, a header, a value near a boundary: the
chunk is streamed.

A clean chunk's verdicts (:mod:`rclverify.targets.column_deadlines` finds
each obligation's expiry row and answering row) are given in the order
the streaming monitor gives them: at each row, the late answers of expired
obligations (oldest expiry first), then the answers of open ones, then the
expiries, each in the order the obligations were opened.  A ``true``
verdict is made as an object only when a verdict callback is given (else it
is counted); every ``false`` and late answer goes through the monitor's own
``_emit``.
"""
from __future__ import annotations

from typing import Any, Callable, Mapping

from rclverify.core.extras import installed
from rclverify.semantics.floatsem import Tolerance
from rclverify.lang.types import Checked, CheckedNode
from rclverify.traces.events import Event
from rclverify.traces.mapping import TopicRule
from rclverify.backends.monitors.batch_deadline_state import ChunkSide
from rclverify.backends.monitors.deadline_records import DeadlineResult, DeadlineVerdict
from rclverify.backends.monitors.deadlines import DeadlineMonitor

#: Events judged at once: the columns held.
CHUNK = 16384


class BatchDeadlines(ChunkSide):
    """A :class:`~.deadlines.DeadlineMonitor` that judges clean chunks over columns
    (module docstring); made by :func:`deadline_monitor` for an eligible node.
    ``stats``: ``batched`` and ``streamed`` events so far."""

    def __init__(self, checked: Checked, node: CheckedNode, rules: Mapping[str, TopicRule],
                 on_verdict: Callable[[DeadlineVerdict], None] | None = None, horizon: float | None = None,
                 tolerance: Tolerance | None = None, chunk: int = CHUNK) -> None:
        super().__init__(checked, node, rules, on_verdict, horizon, tolerance)
        from rclverify.backends.monitors.batch_deadline_plan import DeadlinePlan  # deferred: numpy
        plan = DeadlinePlan.of(self)
        if plan is None:
            raise ValueError(f"node {node.name}: its deadlines are not judged in batch (deadline_monitor)")
        self.plan = plan
        self.size = max(chunk, 1)
        self._buffer: list[Event] = []
        self.stats = {"batched": 0, "streamed": 0}

    def feed(self, ev: Event) -> None:
        """Take one event; a full chunk is judged."""
        buf = self._buffer
        buf.append(ev)
        if len(buf) >= self.size:
            self.flush()

    def flush(self) -> None:
        """Judge the events taken so far: in batch when clean, else streamed."""
        evs, self._buffer = self._buffer, []
        if not evs:
            return
        from rclverify.backends.monitors.batch_deadline_chunk import judge_chunk  # deferred: numpy
        if judge_chunk(self, evs):
            self.stats["batched"] += len(evs)
            return
        self.stats["streamed"] += len(evs)
        stream = super().feed
        for ev in evs:
            stream(ev)

    def feed_block(self, block: Any) -> None:
        """Take a log's block (:class:`~rclverify.traces.jsonl_blocks.LogBlock`, rows in the order read):
        the events taken before it judged, then the block judged over its columns when clean, else its rows'
        events streamed one by one; the same verdicts and state as :meth:`feed` of each row's event."""
        self.flush()
        from rclverify.backends.monitors.batch_deadline_chunk import judge_chunk  # deferred: numpy
        if judge_chunk(self, block):
            self.stats["batched"] += len(block)
            return
        self.stats["streamed"] += len(block)
        stream = super().feed
        for i in range(len(block)):
            stream(block[i])

    def advance(self, now: float) -> None:
        """The events taken judged, then the clock moved to ``now`` (s) as the streaming monitor moves it."""
        self.flush()
        super().advance(now)

    def pending_verdicts(self) -> list[DeadlineVerdict]:
        """The events taken judged, then the open obligations' ``currently_false`` verdicts."""
        self.flush()
        return super().pending_verdicts()

    def finish(self) -> DeadlineResult:
        """The events taken judged, then the run ended (:meth:`~.deadlines.DeadlineMonitor.finish`)."""
        self.flush()
        return super().finish()


def deadline_monitor(checked: Checked, node: CheckedNode, rules: Mapping[str, TopicRule],
                     on_verdict: Callable[[DeadlineVerdict], None] | None = None, horizon: float | None = None,
                     tolerance: Tolerance | None = None, chunk: int = CHUNK) -> DeadlineMonitor:
    """The deadline monitor of ``node`` over a recorded run: a :class:`BatchDeadlines` when the node is
    eligible (module docstring), else the streaming :class:`~.deadlines.DeadlineMonitor`; the same
    arguments, the same verdicts and result."""
    if installed("numpy"):
        from rclverify.backends.monitors.batch_deadline_plan import DeadlinePlan  # deferred: numpy
        if DeadlinePlan.of(DeadlineMonitor(checked, node, rules, None, horizon, tolerance)) is not None:
            return BatchDeadlines(checked, node, rules, on_verdict, horizon, tolerance, chunk)
    return DeadlineMonitor(checked, node, rules, on_verdict, horizon, tolerance)


__all__ = ["CHUNK", "BatchDeadlines", "deadline_monitor"]
