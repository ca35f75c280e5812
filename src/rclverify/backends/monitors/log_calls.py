"""A live run's service calls and action goals judged again from its log (live = offline).

``rclverify monitor --live --ros2`` judges each call and each goal as a
trace of its own (:mod:`.dds_calls`) and writes every call part, pairing
decision and deciding clock tick as a line of its log (topic
:data:`~.dds_calls.CALL_LOG_TOPIC`, ``kind: "call"``).  No contract names
that topic, so the offline engine never reads those lines as messages;
:class:`LogCalls` takes them as the log is read once (:meth:`LogCalls.tap`)
and gives them to a :class:`~.dds_calls.CallBook` made as the live run made
its own (the same nodes' links, mapping rules and horizon; no tolerance, as
live), through :func:`~.dds_calls.replay_line`: the same calls opened and
answered at the same stamps, the same pairs (the live run's: a call it
could not pair stays ``inconclusive`` with its reason), the same clock
ticks, hence the same call verdicts and call deadlines.

Used by ``rclverify monitor LOG`` (:mod:`.cli`) and by the ``monitors``
backend (``doit verify``, :mod:`.backend`); ``rclverify monitor BAG`` feeds
it the lines a ROS 2 bag's recorded calls give back (:mod:`.bag_calls`).  A
log without call lines (a ROS 1 log whose proxy wrote its call parts as
topics) gives nothing here: :meth:`LogCalls.finish` returns ``None`` and the
offline check is what it was.
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any, Iterable, Iterator, Mapping

from rclverify.lang.types import Checked, CheckedNode
from rclverify.traces.events import Event, TraceError
from rclverify.traces.mapping import TopicRule
from rclverify.backends.monitors.judged import count_call_line
from rclverify.backends.monitors.run_origin import ORIGIN_TOPIC, RunOrigin
from rclverify.backends.monitors.summary import verdict_status
from rclverify.backends.monitors.verdicts import NodeResult

if TYPE_CHECKING:
    from rclverify.backends.monitors.dds_calls import CallBook
    from rclverify.backends.monitors.deadline_records import DeadlineResult


class LogCalls:
    """The call book of ``nodes``' links fed a log's call lines.

    ``trace``: the log as messages name it (``file:line:1`` of a bad call
    line); ``horizon`` in seconds.  :attr:`active` is false when no node has
    a link (nothing to tap: a log keeps its columnar reading).  After the
    read, :meth:`finish` gives the summary; :attr:`messages` and
    :attr:`orphans` count the link parts heard as the live run counted them
    (``"estop/request"`` -> paired parts, answers heard without their call:
    :class:`~.judged.Heard`)."""

    def __init__(self, checked: Checked, nodes: Iterable[CheckedNode], rules: Mapping[str, TopicRule],
                 horizon: float, trace: str) -> None:
        links = [(n, lk) for n in nodes for lk in n.node.links]
        self.book: CallBook | None = None
        if links:
            from rclverify.backends.monitors.dds_calls import CallBook  # deferred: start-up (loaded only by a run of nodes with links)
            self.book = CallBook(checked, links, rules, horizon)
        self.trace = trace
        self.lines = 0
        self.messages: dict[str, int] = {}
        self.orphans: dict[str, int] = {}
        self.summary: dict[str, Any] | None = None
        #: the source the live run says it heard through, and what it could not hear (run_origin.py)
        self.origin = RunOrigin()

    @property
    def active(self) -> bool:
        return self.book is not None

    def tap(self, events: Iterable[Event]) -> Iterator[Event]:
        """``events`` unchanged; each call line is replayed first.  Raises
        :class:`TraceError` (located) for a call line the live monitor could
        not have written."""
        from rclverify.backends.monitors.dds_calls import CALL_LOG_TOPIC  # deferred: start-up (loaded only by a run of nodes with links)
        for ev in events:
            if ev.topic == CALL_LOG_TOPIC:
                self.feed(ev)
            elif ev.topic == ORIGIN_TOPIC:
                self.origin.take(ev.fields)
            yield ev

    def feed(self, ev: Event) -> None:
        """One call line (its event: ``time`` and the line's other keys)."""
        if self.book is None or ev.fields.get("kind") != "call":
            return
        from rclverify.backends.monitors.dds_calls import CALL_LOG_TOPIC, replay_line  # deferred: start-up (loaded only by a run of nodes with links)
        line = {"topic": CALL_LOG_TOPIC, "time": ev.time, **ev.fields}
        try:
            replay_line(self.book, line)
        except (KeyError, TypeError, ValueError, AttributeError) as exc:
            lineno = ev.where.rsplit(":", 1)[-1]
            raise TraceError(f"{self.trace}:{lineno}:1: error: a call line of the live monitor that cannot be "
                             f"replayed ({type(exc).__name__}: {exc})") from None
        self.lines += 1
        count_call_line(line, self.messages, self.orphans)  # what the live run counted as heard

    def finish(self) -> dict[str, Any] | None:
        """The book's summary (:meth:`~.dds_calls.CallBook.finish`), ``None``
        when the log had no call line."""
        if self.book is None or not self.lines:
            return None
        self.summary = self.book.finish()
        return self.summary

    def results(self) -> list[NodeResult]:
        """Per node its calls' result, in the order the live record lists them."""
        return list(self.book.results.values()) if self.book is not None and self.summary is not None else []

    def deadlines(self) -> list[DeadlineResult]:
        """Per node its calls' deadline result (nodes with a timed guarantee triggered by a link)."""
        if self.book is None or self.summary is None:
            return []
        return [self.book.deadline_results[n] for n in sorted(self.book.deadline_results)]

    def entries(self) -> list[dict[str, Any]]:
        """Per node ``{node, status, explanation, calls}`` (``calls``: the
        result as JSON, its ``counts`` the live record's ``calls.nodes``); the
        explanation names the node's undecided answers and endpoints not
        judged whatever its status (:meth:`~.dds_calls.CallBook.with_notes`)."""
        out = []
        for res in self.results():
            status, explanation = verdict_status(res, f"the calls in {self.trace}")
            assert self.book is not None  # results() is empty without it
            explanation = self.book.with_notes(res.node, explanation)  # named whatever else was judged
            out.append({"node": res.node, "status": status, "explanation": explanation, "trace": self.trace,
                        "calls": res.to_json()})
        return out

    def deadline_entries(self) -> list[dict[str, Any]]:
        """Per node ``{node, status, explanation, call_deadlines}``."""
        out = []
        for res in self.deadlines():
            from rclverify.backends.monitors.deadline_text import deadline_status  # deferred: start-up (loaded only by a run with a deadline)
            status, explanation = deadline_status(res, f"the calls in {self.trace}")
            out.append({"node": res.node, "status": status, "explanation": explanation, "trace": self.trace,
                        "call_deadlines": res.to_json()})
        return out

    def missed(self) -> tuple[int, int]:
        """``(false, judged)``: call deadlines missed, and judged (``true`` or ``false``)."""
        rs = self.deadlines()
        return (sum(r.counts["false"] for r in rs),
                sum(r.counts["true"] + r.counts["false"] for r in rs))


def merge_deadlines(a: DeadlineResult | None, b: DeadlineResult | None) -> DeadlineResult | None:
    """One node's deadline result on its topics (``a``) and on its calls
    (``b``) as one: counts and refusals summed, the first ``false`` and the
    first refusal of ``a`` before ``b``'s."""
    if a is None or b is None:
        return a if b is None else b
    from rclverify.backends.monitors.deadline_records import DeadlineResult  # deferred: start-up (loaded only by a run with a deadline)
    out = DeadlineResult(a.node)
    for r in (a, b):
        for v, n in r.counts.items():
            out.counts[v] = out.counts.get(v, 0) + n
        for v, n in r.unaccepted.items():
            out.unaccepted[v] = out.unaccepted.get(v, 0) + n
    out.first_false = a.first_false or b.first_false
    out.first_unaccepted = a.first_unaccepted or b.first_unaccepted
    return out


__all__ = ["LogCalls", "merge_deadlines"]
