"""Service calls and action goals checked one by one with the offline engine.

A ROS 2 service call is a request and a reply that carry the same identity
(rmw_cyclonedds' request header: the client's request-writer handle and a
sequence number, :mod:`.dds_types`; or the call's ``client_gid`` and
sequence number in the service's introspection events,
:mod:`.dds_introspection`); an action goal is its ``goal_id`` (a UUID) on
the send-goal request, the feedback messages and the get-result reply.  A
third party on the bus sees every call of every client, so calls are paired
by identity, and by their order only where the order leaves no doubt
(:mod:`.dds_order`: a call it cannot pair is :meth:`CallBook.unpaired`), and
each call (each goal) is checked as a trace of its own (docs/monitors.md,
"Services and actions over DDS"):

* **the server's guarantee**: the node that ``serves(...)`` the link, seen
  through the link (:func:`link_view`: its topics are the link's parts,
  ``<name>/request`` and ``<name>/response``, or ``<name>/goal``,
  ``/feedback`` and ``/result``, bound to the link's variables), is run by
  :class:`~.check.NodeMonitor`, the engine of every recorded and live
  check: the request (the goal) is its input event, the reply (each
  feedback, the result) its output events.  A wrong answer is ``violated``
  once the horizon has passed without a right one; a right one is
  ``satisfied`` at once;
* **the client's assumption**: the node that ``calls(...)`` it, its
  guarantees left out (a client promises nothing about the server's
  answer), the reply (feedback, result) its input events: ``assumption
  violated`` or ``satisfied`` (the answer met the client's assumption);
* **deadlines**: each node with a timed guarantee triggered by a variable
  of the link gets a :class:`~.deadlines.DeadlineMonitor` per call, whose
  stamps are the DDS source timestamps of the request and the reply (the
  writers' clocks: one host, or hosts whose clocks are synchronised), its
  clock advanced by :meth:`CallBook.tick`, so an unanswered call is
  ``false`` as soon as its deadline has passed, and a late answer is shown
  with its stamp (an ``update``).  A node that keeps simulated time (the
  mapping's ``use_sim_time``, :func:`~rclverify.traces.mapping.sim_time_of`)
  has its calls' deadlines kept in simulated time by the rule of its topics'
  (docs/semantics.md, "Deadlines in simulated time";
  :mod:`.deadline_clock`), over the run's ``/clock`` as the book takes it
  (:meth:`CallBook.clock`, in the order of the call events); a node not said
  is judged on both clocks once ``/clock`` is heard, one said to keep the
  run's clock on that clock alone.

What no call's trace can decide is still said: an answer whose request was
not heard (:meth:`CallBook.orphan`: made before the monitor started) and an
endpoint of a link not heard with contents (:meth:`CallBook.unjudged`) each
keep the link's nodes from ``discharged`` (one more ``inconclusive``) and
are named in their explanation (:meth:`CallBook.with_notes`), in the
summary (``undecided``, ``unjudged``) and in the log's lines, so the replay
says the same (docs/monitors.md, "Every endpoint of a call accounted for").

A call is dropped from memory once it is answered and nothing about it is
pending, or :data:`LINGER_S` seconds after its horizon and deadlines passed
unanswered; at most ``max_calls`` are kept (the oldest is closed first,
counted in ``evicted``; a call with an obligation whose simulated deadline
``/clock`` has not passed is kept until it does or the run ends; an answered
call of a node said to keep simulated time whose request came before any
``/clock`` sample, its obligation held for the first one
(:func:`.deadline_first_clock.hold`), is kept as an unanswered one is, until
:data:`LINGER_S` after its horizon and deadlines, so that a first sample
taken later than the answer places it).
:func:`replay` runs the same book over the ``call`` lines of a live log, its
``clock`` lines included: the offline check of a live run's calls.
"""
from __future__ import annotations

import dataclasses
from collections import OrderedDict, deque
from typing import Any, Callable, Iterable, Mapping

from rclverify.lang import ast
from rclverify.lang.timing import seconds
from rclverify.lang.types import Checked, CheckedNode
from rclverify.traces.events import Event, to_ns
from rclverify.traces.mapping import TopicRule, sim_time_of
from rclverify.traces.sim_clock import CLOCK_TOPIC, clock_value_ns
from rclverify.backends.monitors.check import NodeMonitor, NodeResult, Verdict
from rclverify.backends.monitors.deadline_records import DeadlineResult, DeadlineVerdict
from rclverify.backends.monitors.deadlines import DeadlineMonitor
from rclverify.backends.monitors.verdicts import LINK_TOPICS
from rclverify.backends.monitors.call_notes import NAMED, CallNotes, key_json

#: the ``topic`` of a call's log lines: no contract names it; ``rclverify monitor LOG`` replays them (:func:`replay`)
CALL_LOG_TOPIC = "rclverify/call"
#: seconds an unanswered call is kept after its horizon and deadlines passed (a late answer still shown)
LINGER_S = 10.0
#: seconds of the run's clock a ``/clock`` sample is kept beyond the longest call deadline and :data:`LINGER_S`
#: (a call whose request is stamped that much before the last sample is placed on the samples kept)
CLOCK_KEPT_S = 60.0
#: the most ``/clock`` samples kept (each a change of the simulated time)
CLOCK_MAX = 100_000


def link_view(node: CheckedNode, link: ast.Link) -> CheckedNode:
    """``node`` as the one link shows it: its topics are the link's parts
    bound to the link's variables; a client (``calls``) keeps only its
    assumption (module docstring)."""
    topics = tuple(ast.Topic(link.ros_type, f"{link.name.strip('/')}/{part}", var, link.loc)
                   for part, var in zip(LINK_TOPICS[link.kind], link.parts))
    guarantees = node.node.guarantees if link.role == "serves" else ()
    # links=(): the view's topics already bind the link's parts to its variables, and a DDS call's parts
    # arrive unwrapped (the goal's fields, not an actionlib ActionGoal holding them), so the engine's own
    # reading of the node's links (actionlib's wrapped parts) must not apply a second time
    return CheckedNode(dataclasses.replace(node.node, topics=topics, guarantees=guarantees, links=()), node.inputs,
                       node.outputs)


def _timed_by(node: CheckedNode, link: ast.Link) -> bool:
    names = {v.name for v in link.parts}
    return any(c.trigger is not None and c.deadline is not None and c.trigger.name in names
               for c in node.node.guarantees)


@dataclasses.dataclass
class _Call:
    key: tuple[Any, ...]
    name: str
    label: str
    opened: float
    bound: float
    monitors: list[NodeMonitor]
    deadlines: list[DeadlineMonitor]
    answered: bool = False
    first: int = -1  # the index of the request's (the goal's) event


def _longest(node: CheckedNode) -> float:
    """The longest ``within`` (s) of ``node``'s guarantees, 0 without one."""
    return max((float(seconds(c.deadline) or 0) for c in node.node.guarantees if c.deadline is not None), default=0.0)


class CallBook(CallNotes):
    """The calls and goals in flight and what was concluded of those closed.

    ``links`` are the monitored links: ``(node, link)`` pairs (a link name
    appears once per node that serves or calls it); ``on_verdict(Verdict)``
    and ``on_deadline(DeadlineVerdict)`` receive every verdict as decided,
    ``on_event(dict)`` every call event as a log line (``topic``
    :data:`CALL_LOG_TOPIC`, ``kind: "call"``, the link, the part, the
    identity ``key``, the source stamp as ``time``, the part's fields).
    Times are seconds (DDS source timestamps, the timer's wall clock).
    ``/clock`` samples are given by :meth:`clock`, in the order of the call
    events (each a log line, ``part: "clock"``)."""

    def __init__(self, checked: Checked, links: Iterable[tuple[CheckedNode, ast.Link]],
                 rules: Mapping[str, TopicRule], horizon: float,
                 on_verdict: Callable[[Verdict], None] | None = None,
                 on_deadline: Callable[[DeadlineVerdict], None] | None = None,
                 on_event: Callable[[dict[str, Any]], None] | None = None, max_calls: int = 10_000) -> None:
        self.checked, self.rules, self.horizon = checked, rules, horizon
        self.on_verdict, self.on_deadline, self.on_event = on_verdict, on_deadline, on_event
        self.max_calls = max_calls
        self.links: dict[str, list[tuple[CheckedNode, CheckedNode, bool]]] = {}
        for node, lk in links:
            self.links.setdefault(lk.name.strip("/"), []).append((node, link_view(node, lk), _timed_by(node, lk)))
        self.calls: OrderedDict[tuple[Any, ...], _Call] = OrderedDict()
        self.results: dict[str, NodeResult] = {}
        self.deadline_results: dict[str, DeadlineResult] = {}
        self.index = 0
        self.emitted = 0  # verdicts given so far (a tick that gives one is logged, for the replay)
        self.now = float("-inf")
        self.counts = {"calls": 0, "goals": 0, "answered": 0, "unanswered": 0, "orphan_answers": 0, "evicted": 0,
                       "rejected": 0, "unpaired": 0}
        #: link -> answers heard whose request was not: ``{"count", "first"}`` (the first :data:`NAMED` keys)
        self.undecided: dict[str, dict[str, Any]] = {}
        #: link -> endpoint (``"server /ns/n"``) -> why its calls were not all heard with contents
        self.unjudged_ends: dict[str, dict[str, str]] = {}
        timed = [node for views in self.links.values() for node, _, t in views if t]
        #: whether some node with a call deadline may keep simulated time (said, or not said): ``/clock`` is read
        self.reads_clock = any(sim_time_of(rules, n.name) is not False for n in timed)
        #: the ``/clock`` samples taken that changed the simulated time (or broke it), in order, the oldest
        #: forgotten past :attr:`clock_kept_ns` (integer ns of the run's clock) behind the last
        self.clock_samples: deque[Event] = deque()
        self.clock_kept_ns = to_ns(max((_longest(n) for n in timed), default=0.0) + LINGER_S + CLOCK_KEPT_S)
        #: the sample before the one that broke the relation of the two clocks, and that one (``/clock`` went
        #: back, or a sample came out of order): every call opened later is given both (its clock is broken too)
        self.clock_break: tuple[Event, Event] | None = None
        self.clock_taken = 0  # samples taken (names each in its ``where``)

    # -- input -------------------------------------------------------------------------------
    def open(self, name: str, key: tuple[Any, ...], label: str, fields: Mapping[str, object], stamp: float,
             part: str = "request", count: bool = True) -> None:
        """A request (``part`` ``request``) or a goal (``goal``) of link ``name``
        with identity ``key``, stamped ``stamp`` (s).  ``count`` false: the
        same request's call with another of the service's servers (counted
        once, as the first; its log line says ``"also": true``)."""
        name = name.strip("/")
        views = self.links.get(name)
        if not views or key in self.calls:
            return
        monitors = [NodeMonitor(self.checked, view, self.rules, self.horizon, self._verdict) for _, view, _ in views]
        for m in monitors:  # a call's request was heard: its reply is awaited (the pairing's own rules say
            m.heard_answer = True  # when the monitor cannot know: runtime/dds/order.py), never "before first answer"
        deadlines = [DeadlineMonitor(self.checked, node, self.rules, self._deadline) for node, _, timed in views
                     if timed]
        bound = max([self.horizon] + [t[4] for d in deadlines for t in d.timed])
        call = _Call(key, name, label, stamp, bound, monitors, deadlines)
        self.calls[key] = call
        if count:
            self.counts["goals" if part == "goal" else "calls"] += 1
        call.first = self.index
        sims = [d for d in deadlines if d.sim_mode is not False]
        later = self._clock_before(sims, to_ns(stamp)) if sims else []
        self._feed(call, part, fields, stamp, {} if count else {"also": True})
        for ev in later:  # /clock taken already and stamped after the request: in the run's order, after it
            for d in sims:
                d.feed(ev)
        while len(self.calls) > self.max_calls:
            self._close(next(iter(self.calls)), evicted=True)

    def answer(self, key: tuple[Any, ...], part: str, fields: Mapping[str, object], stamp: float,
               final: bool = True, name: str = "") -> bool:
        """A reply (``response``), feedback or result of the call ``key``;
        ``final`` for the reply or the result (the call is then answered).
        Returns False when no open call has that identity (counted)."""
        call = self.calls.get(key)
        if call is None:
            if final:
                self._log({"link": name.strip("/"), "part": part, "time": stamp, "key": key_json(key), "orphan": True,
                           "fields": dict(fields)})
                self.orphan(name, key, stamp)
            return False
        self._feed(call, part, fields, stamp)
        if final and not call.answered:
            call.answered = True
            self.counts["answered"] += 1
        return True

    def reject(self, key: tuple[Any, ...], stamp: float) -> None:
        """The server refused goal ``key``: nothing more will answer it; its
        obligations are closed as they stand (``open``), not judged."""
        if key in self.calls:
            self.counts["rejected"] += 1
            self._log({"link": self.calls[key].name, "part": "rejected", "time": stamp, "key": key_json(key)})
            self._close(key)

    def unpaired(self, key: tuple[Any, ...], stamp: float, reason: str, part: str = "response") -> None:
        """Call ``key`` may have been answered at ``stamp`` (s), but which answer
        is its cannot be known (:mod:`.dds_order`): what was judged of it stays
        (its request's assumption, a guarantee its request alone decides,
        deadlines already expired: each was decided before any answer could
        have come), what waits for its answer is ``inconclusive`` with
        ``reason`` (each node that serves or calls it),
        its deadlines not yet due are left undecided (``unaccepted``).  Its log
        line (``unpaired``, ``orphan``: an answer heard and not paired) names
        the answer's ``part`` (``response``, ``result``)."""
        call = self.calls.pop(key, None)
        if call is None:
            return
        self.counts["unpaired"] += 1
        self._log({"link": call.name, "part": part, "unpaired": True, "orphan": True, "time": stamp,
                   "key": key_json(key), "reason": reason})
        for m in call.monitors:
            res = m.result
            if not m.pending:  # decided on the request alone (an answer could not change it)
                _add(self.results.setdefault(m.node.name, NodeResult(m.node.name)), res)
                continue
            res.counts["inconclusive"] += 1
            if res.first_inconclusive is None:
                res.first_inconclusive = {"event": call.first, "time": call.opened, "where": f"{call.label} request",
                                          "reason": reason}
            self._verdict(Verdict(m.node.name, "inconclusive", call.first, call.opened, f"{call.label} request",
                                  f"{call.name}/request", max(stamp, self.now), reason=reason))
            _add(self.results.setdefault(m.node.name, NodeResult(m.node.name)), res)
        for d in call.deadlines:
            total = self.deadline_results.setdefault(d.result.node, DeadlineResult(d.result.node))
            for v, n in d.result.counts.items():
                total.counts[v] += n
            total.first_false = _earlier(total.first_false, d.result.first_false)
            total.unaccepted["undecided"] += len(d.pending)
            if d.pending and total.first_unaccepted is None:
                total.first_unaccepted = {"where": f"{call.label} request", "stamp": call.opened,
                                          "guarantee": d.pending[0].k, "why": "undecided", "reason": reason}
            d.pending = []

    def note(self, obj: dict[str, Any]) -> None:
        """A line for the log about a call (a status change) that no monitor reads."""
        self._log(obj)

    def _feed(self, call: _Call, part: str, fields: Mapping[str, object], stamp: float,
              extra: Mapping[str, object] | None = None) -> None:
        topic = f"{call.name}/{part}"
        ev = Event(self.index, stamp, topic, dict(fields), f"{call.label} {part}")
        self.index += 1
        self._log({"index": ev.index, "link": call.name, "part": part, "time": stamp, "key": key_json(call.key),
                   "where": ev.where, "fields": dict(fields), **(extra or {})})
        for m in call.monitors:
            m.advance(stamp)
            m.feed(ev)
        # a deadline monitor's trigger is the link's variable: the whole part message maps to it
        dev = Event(ev.index, stamp, topic, {**ev.fields, part: dict(fields)}, ev.where)
        for d in call.deadlines:
            d.feed(dev)

    # -- the simulated clock --------------------------------------------------------------------
    def clock(self, stamp: float, fields: Mapping[str, object]) -> None:
        """A ``/clock`` message (``fields``: ``clock`` with ``sec``/``nanosec``
        or ``secs``/``nsecs``) stamped ``stamp`` (s, the clock of the call
        events), in the order of the call events: given to every open call's
        deadline monitor that reads ``/clock`` (:func:`.deadline_clock.tick`)
        and kept for the calls opened later (:meth:`open`); a log line
        (``part: "clock"``), which the replay takes again.  Not taken: a
        sample without a time, one that repeats the simulated time (the first
        sample of a value says when the clock got there), any after the two
        clocks' relation broke, and every one when no node with a call
        deadline may keep simulated time."""
        if not self.reads_clock or self.clock_break is not None:
            return
        value = clock_value_ns(fields)
        if value is None:
            return
        ns = to_ns(stamp)
        last = self.clock_samples[-1] if self.clock_samples else None
        if last is not None:
            last_ns, last_value = to_ns(last.time), clock_value_ns(last.fields)
            broken = ns < last_ns or (last_value is not None and value < last_value)
            if not broken and value == last_value:
                return
        else:
            broken = False
        self.clock_taken += 1
        sec, nsec = divmod(value, 1_000_000_000)
        ev = Event(self.index, stamp, CLOCK_TOPIC, {"clock": {"sec": sec, "nanosec": nsec}},
                   f"/clock sample {self.clock_taken}")
        self._log({"part": "clock", "time": stamp, "clock": {"sec": sec, "nanosec": nsec}})
        if broken and last is not None:
            self.clock_break = (last, ev)
        self.clock_samples.append(ev)
        while len(self.clock_samples) > CLOCK_MAX or (
                len(self.clock_samples) > 1 and to_ns(self.clock_samples[1].time) <= ns - self.clock_kept_ns):
            self.clock_samples.popleft()
        for call in self.calls.values():
            for d in call.deadlines:
                if d.sim_mode is not False:
                    d.feed(ev)

    def _clock_before(self, monitors: list[DeadlineMonitor], ns: int) -> list[Event]:
        """Give the deadline monitors of a call whose request is stamped ``ns`` (integer ns) the ``/clock``
        they read at its stamp: the two samples that broke the clocks' relation, or the last sample placed
        at or before it.  Returns the samples placed after it, in order (to be given after the request)."""
        if self.clock_break is not None:
            first = list(self.clock_break)
            later: list[Event] = []
        else:
            before = [ev for ev in self.clock_samples if to_ns(ev.time) <= ns]
            first = before[-1:]
            later = list(self.clock_samples)[len(before):]
        for ev in first:
            for d in monitors:
                d.feed(ev)
        return later

    # -- time ----------------------------------------------------------------------------------
    def tick(self, now: float) -> None:
        """Move every open call's clock to ``now`` (s): horizons and deadlines
        that passed are judged; calls done with are closed."""
        self.now = max(self.now, now)
        before = self.emitted
        done = []
        for key, call in self.calls.items():
            for m in call.monitors:
                m.advance(now)
            for d in call.deadlines:
                d.advance(now)
            quiet = not any(m.pending for m in call.monitors) and not any(d.pending for d in call.deadlines)
            sim_open = any(d.awaiting for d in call.deadlines)  # /clock has not passed a simulated deadline yet
            held = any(d.unclocked for d in call.deadlines)  # no /clock sample yet to place its request
            if (call.answered and quiet and not held) or (now > call.opened + call.bound + LINGER_S and not sim_open):
                done.append(key)
        for key in done:
            self._close(key)
        if self.emitted != before:  # this tick decided something: the replay must tick here too
            self._log({"part": "tick", "time": now})

    def _close(self, key: tuple[Any, ...], evicted: bool = False) -> None:
        call = self.calls.pop(key)
        if evicted:
            self.counts["evicted"] += 1
        if not call.answered:
            self.counts["unanswered"] += 1
        for m in call.monitors:
            _add(self.results.setdefault(m.node.name, NodeResult(m.node.name)), m.finish())
        for d in call.deadlines:
            res = d.finish()
            total = self.deadline_results.setdefault(res.node, DeadlineResult(res.node))
            for v, n in res.counts.items():
                total.counts[v] += n
            for v, n in res.unaccepted.items():  # triggers refused, and obligations undecided by their clock
                total.unaccepted[v] = total.unaccepted.get(v, 0) + n
            total.first_false = _earlier(total.first_false, res.first_false)
            if res.first_unaccepted is not None and (total.first_unaccepted is None or _at(res.first_unaccepted)
                                                     < _at(total.first_unaccepted)):
                total.first_unaccepted = res.first_unaccepted

    def finish(self) -> dict[str, Any]:
        """Close every call (what is within its horizon is ``open``, within its
        deadline ``currently_false``); returns the summary (``counts``,
        ``nodes``: per node its :class:`~.check.NodeResult` as JSON,
        ``deadlines``: per node its deadline result)."""
        for key in list(self.calls):
            self._close(key)
        return {"counts": dict(self.counts), "undecided": {k: dict(v) for k, v in self.undecided.items()},
                "unjudged": {k: dict(v) for k, v in self.unjudged_ends.items()},
                "nodes": [self.results[n].to_json() for n in sorted(self.results)],
                "deadlines": [self.deadline_results[n].to_json() for n in sorted(self.deadline_results)],
                "false": sum(r.counts["false"] for r in self.deadline_results.values())}

    # -- sinks ---------------------------------------------------------------------------------
    def _verdict(self, v: Verdict) -> None:
        self.emitted += 1
        if self.on_verdict is not None:
            self.on_verdict(v)

    def _deadline(self, v: DeadlineVerdict) -> None:
        self.emitted += 1
        if self.on_deadline is not None:
            self.on_deadline(v)

    def _log(self, obj: dict[str, Any]) -> None:
        if self.on_event is not None:
            self.on_event({"topic": CALL_LOG_TOPIC, "kind": "call", **obj})


def _earlier(a: DeadlineVerdict | None, b: DeadlineVerdict | None) -> DeadlineVerdict | None:
    """The ``false`` of the earlier trigger (stamp, then where) of ``a`` and ``b``: a node's first over its
    calls whatever order they were closed in (a live tick closes an answered call that the replay of its
    log closes at the end)."""
    if a is None or b is None:
        return a if b is None else b
    return b if (b.trigger_stamp, b.trigger_where) < (a.trigger_stamp, a.trigger_where) else a


def _at(first: Mapping[str, Any]) -> tuple[float, str]:
    """Where a first refusal (``{"stamp", "where", ...}``) stands among a node's calls' triggers."""
    return float(first.get("stamp") or 0.0), str(first.get("where", ""))


def _add(total: NodeResult, one: NodeResult) -> None:
    """Add one call's result to the node's total (the first of each kind kept)."""
    total.events += one.events
    for v, n in one.counts.items():
        total.counts[v] += n
    total.first_violation = total.first_violation or one.first_violation
    total.first_assumption_violation = total.first_assumption_violation or one.first_assumption_violation
    total.first_inconclusive = total.first_inconclusive or one.first_inconclusive


def replay_line(book: CallBook, x: Mapping[str, Any]) -> None:
    """Give ``book`` one line of a live log (a JSON object: ``topic``,
    ``time`` in s, the line's keys), as the live call book wrote it: a line
    that is not a call line (``kind`` ``"call"``) is ignored.  A line with an
    ``index`` opens its call (a request or a goal) or answers it; a ``tick``
    line (written where a live tick decided something) moves the clock as the
    live timer did; a ``clock`` line gives the book the ``/clock`` sample the
    live book took there (:meth:`CallBook.clock`); an ``unpaired`` line leaves its call inconclusive with the
    live reason; a ``rejected`` line closes its goal as the live book did; an
    ``orphan`` answer (no call of its identity was open) is counted and named
    undecided (:meth:`CallBook.orphan`); an ``unjudged`` line says an
    endpoint not heard with contents (:meth:`CallBook.unjudged`).  Raises
    ``KeyError``, ``TypeError`` or ``ValueError`` for a call line missing its
    keys (a log not written by the monitor)."""
    if x.get("kind") != "call":
        return
    part = str(x.get("part"))
    if part == "tick":
        book.tick(float(x["time"]))
    elif part == "clock":
        book.clock(float(x["time"]), {"clock": dict(x["clock"])})
    elif x.get("unpaired"):
        book.unpaired(tuple(x["key"]), float(x["time"]), str(x["reason"]), part)
    elif part == "rejected":
        book.reject(tuple(x["key"]), float(x["time"]))
    elif "index" in x:
        name, key = str(x["link"]), tuple(x["key"])
        if part in ("request", "goal"):
            book.open(name, key, str(x["where"]).rsplit(" ", 1)[0], x["fields"], float(x["time"]), part,
                      not x.get("also"))
        else:
            book.answer(key, part, x["fields"], float(x["time"]), part != "feedback", name)
    elif part == "unjudged":
        book.unjudged(str(x["link"]), str(x["endpoint"]), str(x["reason"]), float(x["time"]))
    elif x.get("orphan") and str(x.get("link", "")).strip("/") in book.links:
        book.orphan(str(x["link"]), tuple(x["key"]), float(x["time"]))  # live, no call of its identity was open


def replay(book: CallBook, lines: Iterable[Mapping[str, Any]]) -> dict[str, Any]:
    """Run ``book`` over a live log's lines in order (:func:`replay_line`)
    and finish it: the offline check of a live run's calls, its summary as
    :meth:`CallBook.finish`.  A deadline that expired live before its late
    answer arrived expires here too (the ``tick`` lines), with the same clock
    in its reason."""
    for x in lines:
        replay_line(book, x)
    return book.finish()


__all__ = ["CALL_LOG_TOPIC", "CLOCK_KEPT_S", "CLOCK_MAX", "CallBook", "LINGER_S", "NAMED", "link_view", "replay", "replay_line"]
