"""The checks a live run makes as the offline command reads its log (live = offline).

``rclverify monitor LOG`` feeds every line of a log, in order, to the
deadline monitors of the nodes with timed guarantees
(:class:`~.deadlines.DeadlineMonitor`), for the nodes with periodic
outputs to the period monitors (:class:`~.periods.PeriodMonitor`) and for
the nodes with declarations to their monitors
(:class:`~.declarations.DeclarationMonitor`): each
released message, and each verdict or call line too, whose ``time`` moves
their clocks.  :class:`LogChecks` is fed by the live run
(:class:`~.live.LiveRun`) with the same lines as it writes them, in the same
order, so the live verdicts are the offline check's on the live run's log:

* :meth:`event` a released message (its line is written first);
* :meth:`line` any other line written (a verdict, a call event), except
  the deadline monitors' own verdict lines (:meth:`deadline_line`), which
  only the period monitors read: a deadline verdict line carries the time
  of the clock that decided it, so an offline deadline monitor is at or past
  it already when it reads it;
* :meth:`advance` the timer: the deadline monitors' clock moves to the
  run's clock less the reorder window (a trigger unanswered past its
  deadline is ``false`` at once, and that verdict's line then moves the
  offline check's clock to the same point).

The results are reported as the offline command reports them
(:func:`~.deadline_text.deadline_status`, :func:`~.periods.period_status`).
"""
from __future__ import annotations

import math
from typing import Any, Callable, Iterable, Mapping

from rclverify.lang.types import Checked, CheckedNode
from rclverify.traces.events import Event
from rclverify.traces.mapping import TopicRule
from rclverify.backends.monitors.deadline_records import DeadlineResult, DeadlineVerdict
from rclverify.backends.monitors.deadline_topics import has_deadlines
from rclverify.backends.monitors.deadline_text import deadline_status
from rclverify.backends.monitors.deadlines import DeadlineMonitor
from rclverify.backends.monitors.declarations import DeclarationMonitor, DeclarationResult, add_periods, declaration_status, has_declarations
from rclverify.backends.monitors.periods import PeriodMonitor, PeriodResult, has_periods, period_status
from rclverify.runtime.shapes import LogChecksPart


class LogChecks:
    """The deadline and period monitors of ``nodes`` fed a live run's log
    lines (module docstring).  ``on_deadline(verdict, time)`` receives each
    deadline verdict with the deciding clock (s); ``horizon`` (s) bounds a
    ``triggered by`` without ``within``, as offline."""

    def __init__(self, checked: Checked, nodes: Iterable[CheckedNode], rules: Mapping[str, TopicRule],
                 horizon: float, on_deadline: Callable[[DeadlineVerdict, float], None]) -> None:
        nodes = list(nodes)
        self.on_deadline = on_deadline
        self.deadlines = [DeadlineMonitor(checked, n, rules, self._verdict, horizon=horizon)
                          for n in nodes if has_deadlines(n)]
        self.periods = [PeriodMonitor(n, rules) for n in nodes if has_periods(n)]
        #: initially, progress and periods judged as offline (declarations.py)
        self.declarations = [DeclarationMonitor(checked, n, rules) for n in nodes if has_declarations(n)]
        self.active = bool(self.deadlines or self.periods or self.declarations)
        self.deadline_results: list[DeadlineResult] = []
        self.period_results: list[PeriodResult] = []
        self.declaration_results: list[DeclarationResult] = []
        self._lines = 0

    def _verdict(self, v: DeadlineVerdict) -> None:
        clock = max((d.now for d in self.deadlines if d.node.name == v.node), default=-math.inf)
        t = max(clock, v.answer if v.answer is not None else -math.inf)
        self.on_deadline(v, t if math.isfinite(t) else v.trigger_stamp)

    def event(self, ev: Event) -> None:
        """A released message, after its log line."""
        for d in self.deadlines:
            d.feed(ev)
        for p in self.periods:
            p.feed(ev)
        for m in self.declarations:
            m.feed(ev)

    def line(self, obj: Mapping[str, object], deadline: bool = False) -> None:
        """Any other log line (``topic``, ``time``, its fields) after it was
        written; ``deadline``: a deadline verdict's own line."""
        if not self.active:
            return
        t = obj.get("time")
        if isinstance(t, bool) or not isinstance(t, (int, float)) or not math.isfinite(t):
            return  # the offline reader refuses such a line; none is written
        self._lines += 1
        ev = Event(-self._lines, float(t), str(obj.get("topic", "")).lstrip("/"), obj, "a log line")
        if not deadline:
            for d in self.deadlines:
                d.feed(ev)
            for m in self.declarations:  # a call's request or response line is an event of its node
                m.feed(ev)
        for p in self.periods:
            p.feed(ev)

    def advance(self, now: float) -> None:
        """The timer: the deadline monitors' clock to ``now`` (s)."""
        for d in self.deadlines:
            d.advance(now)

    def finish(self) -> None:
        """End of the run: triggers within their deadline are ``currently_false`` (their lines written)."""
        self.deadline_results = [d.finish() for d in self.deadlines]
        self.period_results = [p.finish() for p in self.periods]
        by_node = {p.node: p for p in self.period_results}
        self.declaration_results = [add_periods(m.finish(), m.node, by_node.get(m.node.name))
                                    for m in self.declarations]

    def status(self) -> list[str]:
        """``Node deadlines: 9 true, 1 false`` per node with a verdict."""
        return [f"{d.node.name} deadlines: " + ", ".join(f"{n} {v}" for v, n in d.result.counts.items() if n)
                for d in self.deadlines if any(d.result.counts.values())]

    def record(self, log: str) -> LogChecksPart:
        """The record's ``topic_deadlines``, ``periods`` and ``declarations``: per node its status,
        explanation and result, as ``rclverify monitor LOG`` reports them."""
        out: LogChecksPart = {"topic_deadlines": [], "periods": [], "declarations": []}
        for res in self.deadline_results:
            status, explanation = deadline_status(res, log)
            out["topic_deadlines"].append({"node": res.node, "status": status, "explanation": explanation,
                                           "deadlines": res.to_json()})
        for pres in self.period_results:
            status, explanation = period_status(pres, log)
            out["periods"].append({"node": pres.node, "status": status, "explanation": explanation,
                                   "periods": pres.to_json()})
        for dres in self.declaration_results:
            status, explanation = declaration_status(dres, log)
            out["declarations"].append({"node": dres.node, "status": status, "explanation": explanation,
                                        "declarations": dres.rows()})
        return out


__all__ = ["LogChecks"]
