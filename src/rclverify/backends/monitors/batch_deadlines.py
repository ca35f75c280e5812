"""Deadlines judged in batch: the deadline monitor over a recorded run, a chunk of columns at a time.

:class:`BatchDeadlines` is the deadline monitor (:class:`~.deadlines.DeadlineMonitor`,
the rules of docs/semantics.md "Deadlines") with the same state and the
same results; it takes the run's events :data:`CHUNK` at a time and judges
a chunk over its columns when the chunk is **clean**, else feeds its
events to the streaming monitor one by one, as today.  Either way the
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

from collections import deque
from typing import Callable, Mapping

from rclverify.core.extras import installed
from rclverify.semantics.floatsem import Tolerance, judge
from rclverify.lang.types import Checked, CheckedNode
from rclverify.traces.events import Event
from rclverify.traces.mapping import TopicRule, map_value, rule_for
from rclverify.backends.monitors.deadline_records import DeadlineResult, DeadlineVerdict, Pending
from rclverify.backends.monitors.deadline_text import ms, ms_ns
from rclverify.backends.monitors.deadlines import DeadlineMonitor

#: Events judged at once: the columns held.
CHUNK = 16384


class BatchDeadlines(DeadlineMonitor):
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

    # -- what the chunk judge gives the monitor ---------------------------------------------
    def mapped(self, ev: Event, key: str) -> object:
        """The value variable ``key`` takes from message ``ev`` as :meth:`feed` maps it."""
        typ = self.node.inputs[key[3:]] if key.startswith("in.") else self.node.outputs[key[4:]]
        fields = {k: v for k, v in ev.fields.items() if k != "header"}
        return map_value(typ, fields, rule_for(self.rules, ev.topic, key), None)

    def rejection(self, k: int, inputs: Mapping[str, object], out_key: str, out: Event) -> str:
        """Why output ``out`` did not answer an obligation of guarantee ``k`` on ``inputs``
        (:meth:`~.deadlines.DeadlineMonitor._try`'s words)."""
        cl = self.node.node.guarantees[k - 1]
        values = {**inputs, out_key: self.mapped(out, out_key)}
        j = judge(cl.formula, self.checked, self.node, values, self.tolerance)
        return f"the output at {out.where} did not satisfy guarantee {k}" + (
            f" (false in {j.semantics} arithmetic)" if j.truth is False and "double" in j.semantics else
            f" ({j.reason})" if j.truth is None and j.reason else "")

    def expired_verdict(self, p: Pending, now_ns: int) -> DeadlineVerdict:
        """Obligation ``p``'s ``false``: the clock passed its deadline at ``now_ns`` unanswered."""
        return DeadlineVerdict(self.node.name, p.k, "false", p.trigger.where, p.stamp, p.due, None, "",
                               f"no answer within the deadline of {ms_ns(p.due_ns - p.stamp_ns)} "
                               f"(clock at {now_ns / 1e9:.3f} s)" + (f"; {p.rejected}" if p.rejected else ""))

    def answered_verdict(self, p: Pending, ns: int, ev: Event, d: float) -> DeadlineVerdict:
        """Open obligation ``p`` answered by output ``ev`` stamped ``ns``: ``true`` within the deadline ``d``
        (s), else ``false`` with the answer."""
        if ns <= p.due_ns:
            return DeadlineVerdict(self.node.name, p.k, "true", p.trigger.where, p.stamp, p.due, ns / 1e9,
                                   ev.where, f"answered after {ms_ns(ns - p.stamp_ns)} (deadline {ms(d)})",
                                   semantics="exact", time_margin=(p.due_ns - ns) / 1e9)
        return DeadlineVerdict(self.node.name, p.k, "false", p.trigger.where, p.stamp, p.due, ns / 1e9,
                               ev.where, f"answered after {ms_ns(ns - p.stamp_ns)}, "
                               f"{ms_ns(ns - p.due_ns)} past the deadline of {ms(d)}",
                               semantics="exact", time_margin=(p.due_ns - ns) / 1e9)

    def late_verdict(self, p: Pending, ns: int, ev: Event) -> DeadlineVerdict:
        """Expired obligation ``p``'s late answer ``ev`` stamped ``ns`` (an update of its ``false``)."""
        return DeadlineVerdict(self.node.name, p.k, "false", p.trigger.where, p.stamp, p.due, ns / 1e9,
                               ev.where, f"answered after {ms_ns(ns - p.stamp_ns)}, "
                               f"{ms_ns(ns - p.due_ns)} past the deadline of "
                               f"{ms_ns(p.due_ns - p.stamp_ns)}", update=True,
                               time_margin=(p.due_ns - ns) / 1e9)

    def take_state(self, pending: list[Pending], expired: list[Pending], values: Mapping[str, object],
                   heard: list[tuple[int, Event, set[str], dict[str, object]]], now_ns: int) -> None:
        """The state a clean chunk leaves: open and expired obligations, the latest values, the last
        outputs heard, the clock."""
        self.pending = pending
        self.expired = deque(expired, maxlen=self.expired.maxlen)
        for key, v in values.items():
            self.values[key] = v
            self.invalid.pop(key, None)
        self.heard.extend(heard)
        if self.now_ns is None or now_ns > self.now_ns:
            self.now_ns = now_ns
            self.now = now_ns / 1e9


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
