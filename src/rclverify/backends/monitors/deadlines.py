"""Deadlines of timed guarantees checked against message stamps.

A guarantee ``G(phi) triggered by in.x within d`` (rule D1,
docs/decisions.md) is monitored per trigger event: the event on ``in.x``
with stamp ``t`` opens an obligation due at ``t + d``; the first later
message on an output ``phi`` mentions, with ``phi`` true on the trigger's
inputs and the outputs published since the trigger (an output current
before it answered an earlier question; only a topic the mapping declares a
``state`` stands in with its current value), answers it.  Verdicts, in
ROSMonitoring's terms:

* ``true``: answered with a stamp ``<= t + d``;
* ``false``: the deadline expired, the clock (the latest stamp seen, or a
  live monitor's timer) passed ``t + d`` with no answer; a late answer's
  stamp is given when it came.  Where an output stamped within the
  transport skew before the trigger satisfies the guarantee on its inputs
  (it may be the trigger's answer), the obligation is ``undecided`` instead,
  counted with the unaccepted triggers (:mod:`.deadline_skew`);
* ``currently_false``: not answered yet and the deadline not yet expired (a
  run that ends then, or a live query before the deadline).

**Only accepted inputs are obligations**: a trigger whose inputs the node's
assumption does not accept gets no deadline verdict (:mod:`.deadline_questions`).

A ``triggered by`` without ``within`` is checked the same way with the
monitor's ``horizon`` as its bound (offline, and live on the monitored
topics, :mod:`.logchecks`; the per-call monitors of ROS 1's proxy and of
DDS calls have none, so they check only guarantees with a deadline).

**Clock.**  An event's time is its message's ``header.stamp`` when it has one
(:func:`~.online.header_stamp`), else the time the trace gives it (the
recording time of a bag, ``time`` of a ROSMonitoring log line).  A service
call seen through the monitor's proxy is two events, ``<svc>/request`` and
``<svc>/response``, both stamped by the proxy's clock when it received the
request and when the server's response came back (docs/monitors.md).  All
stamps of one check must come from one clock (rule D2's side condition (c)).

**Topics.**  A node's timed guarantee reads the node's ``topics(...)`` and its
links: service ``s`` is ``s/request`` and ``s/response``; action ``a`` is
actionlib's ``a/goal``, ``a/feedback`` and ``a/result`` (the message's
``goal``/``feedback``/``result`` part is what maps to the contract variable).
"""
from __future__ import annotations

import dataclasses
from collections import deque
from typing import Callable, Iterable, Mapping

from rclverify.semantics.floatsem import Judgement, Tolerance, judge
from rclverify.lang import ast
from rclverify.lang.timing import seconds
from rclverify.lang.types import Checked, CheckedNode
from rclverify.lang.walk import subexpressions
from rclverify.traces.events import Event, to_ns
from rclverify.traces.mapping import MappingError, TopicRule, map_value, rule_for, sim_time_of
from rclverify.traces.sim_clock import CLOCK_TOPIC, SimClock
from rclverify.traces.questions import QuestionStream
from rclverify.backends.monitors.verdicts import names
from rclverify.backends.monitors.deadline_records import DeadlineResult, DeadlineVerdict, Pending, Recorded
from rclverify.backends.monitors.deadline_topics import event_stamp_ns, topic_bindings
from rclverify.backends.monitors.deadline_text import VerdictWords, ms_ns, rejected
from rclverify.backends.monitors import deadline_clock, deadline_first_clock, deadline_late, deadline_place
from rclverify.backends.monitors import deadline_questions, deadline_skew


class DeadlineMonitor(VerdictWords):
    """Streams events through the timed guarantees of one node.

    ``feed(ev)`` one event; ``advance(now)`` the clock (expires deadlines);
    ``pending_verdicts()`` the ``currently_false`` obligations now;
    ``finish()`` the result.  ``on_verdict`` gets every decided verdict.
    ``tolerance`` as for :class:`~.check.NodeMonitor` (default: ``rules``'
    ``tolerance`` attribute when it has one)."""

    def __init__(self, checked: Checked, node: CheckedNode, rules: Mapping[str, TopicRule],
                 on_verdict: Callable[[DeadlineVerdict], None] | None = None, horizon: float | None = None,
                 tolerance: Tolerance | None = None, clock: bool = True) -> None:
        self.checked, self.node, self.rules, self.on_verdict = checked, node, rules, on_verdict
        #: the clock the node keeps its deadlines in (:mod:`.deadline_clock`): ``True`` simulated time, ``False``
        #: the run's clock, ``None`` not said (both, once ``/clock`` is heard); ``clock=False``: the run's clock
        self.sim_mode: bool | None = sim_time_of(rules, node.name) if clock else False
        #: the run's ``/clock`` as heard (:func:`.deadline_clock.tick`)
        self.sim = SimClock()
        #: obligations placed in simulated time whose deadline ``/clock`` has not passed yet
        self.awaiting: list[Pending] = []
        #: obligations held until the first ``/clock`` message places them, in the order they came (their node
        #: said to keep simulated time; at most :data:`.deadline_first_clock.HELD`: :func:`.deadline_first_clock.hold`)
        self.unclocked: deque[Pending] = deque()
        #: the answers to obligations of a node whose clock is not said, placed on the run's clock while no ``/clock``
        #: has been heard, in the order given: given again if the first ``/clock`` message, heard late, is stamped
        #: before their trigger (at most :data:`.deadline_first_clock.HELD`: :func:`.deadline_first_clock.record`)
        self.unsure: deque[Recorded] = deque()
        self.tolerance = tolerance if tolerance is not None else getattr(rules, "tolerance", None)
        self.assumption = tuple(c.formula for c in node.node.assumes)
        self.bindings = topic_bindings(node)
        self.timed: list[tuple[int, ast.Clause, str, frozenset[str], float]] = []
        #: guarantee -> its bound in integer nanoseconds (what deadlines are compared in)
        self.bounds_ns: dict[int, int] = {}
        for k, cl in enumerate(node.node.guarantees, 1):
            if cl.trigger is None:
                continue
            # `triggered by` without `within`: answered at all, judged after the monitor's horizon (s)
            bound = seconds(cl.deadline) if cl.deadline is not None else horizon
            if bound is None:
                continue
            outs = frozenset(f"out.{e.name}" for e in subexpressions(cl.formula)
                             if isinstance(e, ast.Var) and e.prefix == "out")
            self.timed.append((k, cl, f"in.{cl.trigger.name}", outs, float(bound)))
            self.bounds_ns[k] = round(bound * 1_000_000_000)  # exact: `within 200 ms` is 200_000_000 ns
        #: guarantee -> its entry of ``timed``: what an obligation reads of its guarantee, found by its number
        self.timed_k = {t[0]: t for t in self.timed}
        # /clock kept back to a trigger that may still be placed: the longest bound, and a minute of lateness
        self.sim.kept_ns = max(self.bounds_ns.values(), default=0) + 60 * 1_000_000_000
        # an output whose every topic the mapping declares a state may stand in
        # with its current value; any other answers only triggers before it
        event_outs = {key for topic, keys in self.bindings.items() for key, part in keys
                      if key.startswith("out.") and (part or not rules.get(topic, TopicRule()).state)}
        self.state_outs = frozenset(key for keys in self.bindings.values() for key, _ in keys
                                    if key.startswith("out.") and key not in event_outs)
        mentioned: set[str] = set()
        for f in self.assumption + tuple(c.formula for c in node.node.guarantees):
            names(f, mentioned)
        #: every input the contract reads: a trigger before all have a value raises no question (docs/semantics.md)
        self.needed = sorted(f"in.{v}" for v in node.inputs if v in mentioned or f"in.{v}" in mentioned)
        #: the node's questions: an answer is judged on the latest at its stamp (a superseded trigger is carried)
        self.stream = QuestionStream()
        self.values: dict[str, object] = {}
        #: before the first question: each input's values as its messages set them, (stamp ns, value), the last
        #: 64: a trigger heard late finds the inputs in force at its stamp there (:func:`.deadline_questions.inputs_at`)
        self.before_first: dict[str, deque[tuple[int, object]]] = {}
        #: input -> the stamp (integer ns) of the message whose value is in force: one heard late and stamped before
        #: it leaves that value in force (its own is read at its stamp, :func:`.deadline_questions.inputs_at`)
        self.set_ns: dict[str, int] = {}
        #: keys whose latest message did not map (NaN, a missing field): key -> why; their stale value never
        #: stands in (docs/semantics.md, "Values")
        self.invalid: dict[str, str] = {}
        self.pending: list[Pending] = []
        self.expired: deque[Pending] = deque(maxlen=256)  # judged false, waiting for a late answer to show
        #: judged false and answered late since, kept for an output within the skew before the trigger
        #: heard later still (:mod:`.deadline_late`)
        self.answered_late: deque[deadline_late.Answered] = deque()
        #: the last outputs heard: (stamp ns, event, outputs it set, their values): a trigger heard after them
        #: but stamped before them is answered by them
        self.heard: deque[tuple[int, Event, set[str], dict[str, object]]] = deque(maxlen=64)
        self.now = float("-inf")
        self.now_ns: int | None = None
        #: the mapping's transport skew in integer ns: an output stamped this much before a trigger may be its
        #: answer (:mod:`.deadline_skew`; 0: none)
        self.skew_ns = deadline_skew.skew_ns(rules)
        self.result = DeadlineResult(node.name)
        #: the ``false`` verdicts given, in order, by (trigger where, guarantee): the first still standing is
        #: the result's first (a false withdrawn by an answer stamped in time, :func:`.deadline_late.met_late`)
        self._falses: dict[tuple[str, int], DeadlineVerdict] = {}
        self._last_false: DeadlineVerdict | None = None

    def expired_verdict(self, p: Pending, now_ns: int) -> DeadlineVerdict:
        return self._in_clock(p, super().expired_verdict(p, now_ns), None)

    def answered_verdict(self, p: Pending, ns: int, ev: Event, d: float, semantics: str = "exact") -> DeadlineVerdict:
        return self._in_clock(p, super().answered_verdict(p, ns, ev, d, semantics), ns)

    def late_verdict(self, p: Pending, ns: int, ev: Event) -> DeadlineVerdict:
        return self._in_clock(p, super().late_verdict(p, ns, ev), ns)

    def _in_clock(self, p: Pending, v: DeadlineVerdict, ns: int | None) -> DeadlineVerdict:
        """Verdict ``v`` on obligation ``p``, with what its clock adds when it is placed in one
        (:func:`.deadline_place.words`; the time margin of an answer at ``ns`` in that clock)."""
        if not p.clock:
            return v
        margin = v.time_margin if ns is None else deadline_place.margin_ns(self, p, ns) / 1e9
        return dataclasses.replace(v, reason=v.reason + deadline_place.words(self, p), time_margin=margin)

    def _emit(self, v: DeadlineVerdict, counted: bool = False) -> None:
        """Verdict ``v`` given: counted (an update only when ``counted``: a verdict that replaces one the
        caller withdrew from the counts, :func:`.deadline_clock.tick`) and passed to ``on_verdict``."""
        if v.update and not counted:  # the answer of an expired obligation: shown, not counted again
            if self.result.first_false is not None and self.result.first_false.trigger_where == v.trigger_where:
                self.result.first_false = v
            if (v.trigger_where, v.guarantee) in self._falses:
                self._falses[(v.trigger_where, v.guarantee)] = v
            if self.on_verdict is not None:
                self.on_verdict(v)
            return
        self.result.counts[v.verdict] += 1
        if v.verdict == "false":
            self._last_false = v
            if len(self._falses) < 1024:  # bounded; past it the latest false stands in (deadline_late.met_late)
                self._falses[(v.trigger_where, v.guarantee)] = v
            first = self.result.first_false
            if first is None or (counted and v.trigger_stamp < first.trigger_stamp):  # its place in stamp order
                self.result.first_false = v
        if self.on_verdict is not None:
            self.on_verdict(v)

    def feed(self, ev: Event) -> None:
        """Process one event (any topic; only the node's move its state)."""
        ns = event_stamp_ns(ev)
        topic = ev.topic.lstrip("/")
        if topic == CLOCK_TOPIC:  # the run's simulated clock (deadline_clock.py)
            again = deadline_clock.tick(self, ev, ns)
            if self.now_ns is not None and ns < self.now_ns:  # heard late: what it shows passed expires now
                self._expire(self.now_ns)
            self._advance_ns(ns)
            if again:  # answers judged before it passed their deadline, after what it expires (stamp order)
                deadline_clock.judge_again(self, again, ev, ns)
            return
        late = self.now_ns is not None and ns < self.now_ns  # stamped before a message heard already
        keys = self.bindings.get(topic)
        if not keys or not self.timed:
            self._advance_ns(ns)
            return
        changed: list[str] = []
        own: dict[str, object] = {}  # an input's value set by this message heard late, not the one in force now
        for key, part in keys:
            fields = ev.fields.get(part) if part else ev.fields
            if not isinstance(fields, Mapping):
                continue
            fields = {k: v for k, v in fields.items() if k != "header"}
            typ = self.node.inputs.get(key[3:]) if key.startswith("in.") else self.node.outputs.get(key[4:])
            if typ is None:
                continue
            try:
                value = map_value(typ, fields, rule_for(self.rules, ev.topic, key), self.values.get(key))
                if key.startswith("in.") and ns < self.set_ns.get(key, ns):  # a message stamped after it set it
                    own[key] = value
                else:
                    self.values[key] = value
                    if key.startswith("in."):
                        self.set_ns[key] = ns
            except MappingError as exc:
                # never the value before it: what reads this input is undecided until a message maps again
                self.invalid[key] = f"{key}: the latest message at {ev.where} does not map ({exc})"
                if key.startswith("in."):
                    changed.append(key)
                continue
            self.invalid.pop(key, None)
            changed.append(key)
        outs = {c for c in changed if c.startswith("out.")}
        if outs:
            fresh = {c: self.values[c] for c in outs if c not in self.state_outs}
            for p in (*self.pending, *self.expired):
                if ns >= p.stamp_ns:
                    p.outs.update(fresh)
            self._answer(ev, ns, outs)
        self._advance_ns(ns)
        if any(c.startswith("in.") for c in changed):
            deadline_questions.ask(self, ev, ns, changed, own, late)

    def _oblige(self, k: int, ev: Event, ns: int, inputs: dict[str, object]) -> None:
        """Accepted trigger ``ev`` (stamp ``ns``, integer ns; judged on ``inputs``) opens the obligation of
        guarantee ``k``: due its bound after the stamp, or placed in the clock its node keeps
        (:mod:`.deadline_clock`); a trigger heard after outputs stamped after it is answered by them."""
        d_ns = self.bounds_ns[k]
        p = Pending(k, ev, ns / 1e9, (ns + d_ns) / 1e9, inputs, stamp_ns=ns, due_ns=ns + d_ns)
        if self.sim_mode and not self.sim.heard:  # kept in simulated time: placed by the first /clock message
            deadline_first_clock.hold(self, p)
        elif deadline_clock.reads_clock(self):  # kept in simulated time, or in a clock not said
            why = deadline_place.place(self, p)
            if why:
                deadline_place.undecided(self, p, why)
                return
        if not (self.now_ns is not None and ns < self.now_ns and self._heard_late(p)):
            deadline_skew.scan_heard(self, p)
            self.pending.append(p)

    def _answer(self, ev: Event, ns: int, outs: set[str]) -> None:
        stamp = ns / 1e9
        for p in list(self.expired):
            if ns < p.stamp_ns:  # stamped before its trigger, heard after the clock passed its deadline
                if not p.maybe and deadline_skew.may_answer(self, p, ev, ns):
                    deadline_skew.revise_false(self, p, ev, ns, {c: self.values[c] for c in outs
                                                                  if c not in self.state_outs})
                continue
            semantics = self._answers(p, ns, outs)
            if semantics is not None:
                self.expired.remove(p)
                if ns <= p.due_ns:  # stamped within the deadline, heard after the clock passed it
                    if p.clock and ns > p.sure_ns:  # in time in one clock it may be kept in, not in every one
                        deadline_clock.band_late(self, p, ev, ns)
                        continue
                    deadline_late.met_late(self, p, ev, ns, self._margin(p, ns))
                    continue
                if p.maybe:  # answered late, or in time by the output within the skew before it: still undecided
                    continue
                self._emit(self.late_verdict(p, ns, ev))
                deadline_late.hold(self, p, ns, ev, self._margin(p, ns))  # an output within the skew before it may come
                if self.sim_mode is None and not self.sim.heard:  # given again by a first /clock heard late
                    p.first_answer = (ev, ns, semantics)
        if self.answered_late:
            deadline_late.revise(self, ev, ns, {c: self.values[c] for c in outs if c not in self.state_outs})
        self.pending = [p for p in self.pending if not self._try(p, ev, ns, outs)]
        self.heard.append((ns, ev, outs, {c: self.values[c] for c in outs if c not in self.state_outs}))

    def _withdraw_false(self, p: Pending) -> None:
        """The ``false`` obligation ``p`` was given when the clock passed its deadline, withdrawn from the
        counts and, where it was the first, from the result's first ``false`` (its replacement: the caller's)."""
        counts = self.result.counts
        counts["false"] -= 1
        key = (p.trigger.where, p.k)
        self._falses.pop(key, None)
        first = self.result.first_false
        if first is not None and (first.trigger_where, first.guarantee) == key:
            self.result.first_false = next(iter(self._falses.values()), None) or (
                self._last_false if counts["false"] else None)

    def _try(self, p: Pending, ev: Event, ns: int, outs: set[str]) -> bool:
        """Whether output ``ev`` (stamp ``ns``, setting ``outs``) answers obligation ``p``:
        its verdict given (``true``, or ``false`` when late), else ``False`` (still pending)."""
        k, cl, _, gouts, _ = self.timed_k[p.k]
        if not (gouts & outs):
            return False
        if ns < p.stamp_ns:  # stamped before the trigger: within the skew, or published after it, it may be its answer
            if deadline_skew.may_answer(self, p, ev, ns):
                deadline_skew.mark_early(self, p, ev, ns, {c: self.values[c] for c in outs if c not in self.state_outs})
            return False
        stamp = ns / 1e9
        j = judge(cl.formula, self.checked, self.node, self._visible(p, stamp), self.tolerance)
        if j.truth is not True:
            p.rejected = rejected(k, ev, j)
            return False
        if p.unclocked:  # held until /clock is first heard: judged when it places the obligation
            p.first_answer = (ev, ns, j.semantics)
            return True
        self._judged(p, ev, ns, j.semantics)
        return True

    def _judged(self, p: Pending, ev: Event, ns: int, semantics: str) -> None:
        """Obligation ``p`` answered by output ``ev`` stamped ``ns`` (its guarantee held in ``semantics``): its
        verdict given (``true``, ``false`` when late, ``undecided`` in a clock's band or when
        :attr:`~.deadline_records.Pending.maybe` and late) and its time margin noted."""
        stamp = ns / 1e9
        if p.maybe and ns > p.due_ns:  # its own answer after the deadline: undecided, as when the clock passed first
            deadline_skew.undecided(self, p)
            return
        if p.clock and p.sure_ns < ns <= p.due_ns:  # in time in one clock it may be kept in, not in every one
            deadline_clock.band(self, p, ev, ns)
            return
        self._emit(self.answered_verdict(p, ns, ev, self.timed_k[p.k][4], semantics))
        margin = self._margin(p, ns)
        # placed in a clock, before /clock passed its deadline or was heard after the answer: a /clock message
        # heard later may change its verdict or its margin (deadline_clock.tick)
        held = bool(p.clock) and (p.due_ns >= deadline_place.FAR or not self.sim.heard_after(ns))
        # the node's clock not said, no /clock heard yet: given again if the first one, heard late, comes before
        recorded = not held and self.sim_mode is None and not self.sim.heard
        order = self.result.note_time_margin(p.k, margin, p.trigger.where, ev.where, stamp, held=held or recorded)
        if held:
            deadline_place.answered(self, p, "true", ev, ns, semantics, (margin, order, p.trigger.where, ev.where, stamp))
        elif recorded:
            deadline_first_clock.record(self, p, ev, ns, semantics, "true" if ns <= p.due_ns else "false",
                                  (margin, order, p.trigger.where, ev.where, stamp))

    def _margin(self, p: Pending, ns: int) -> int:
        """The time margin (integer ns) of an answer stamped ``ns`` to obligation ``p``: its deadline less the
        answer in the clock it is kept in (:func:`.deadline_place.margin_ns`), or on the run's clock."""
        return deadline_place.margin_ns(self, p, ns) if p.clock else p.due_ns - ns

    def _heard_late(self, p: Pending) -> bool:
        """A trigger heard after outputs stamped after it (docs/semantics.md, "Answers"):
        those outputs (the last 64 kept), in the order heard, answer it as they would
        have had it been heard first.  Returns whether one did (its verdict given)."""
        for ns, ev, outs, fresh in self.heard:
            if ns > p.stamp_ns:  # equal stamps: heard before it, no answer to it (the run's order)
                p.outs.update(fresh)
                if self._try(p, ev, ns, outs):
                    return True
        return False

    def _answers(self, p: Pending, ns: int, outs: set[str]) -> str | None:
        """Whether outputs ``outs`` now (stamp ``ns``, integer ns) answer obligation ``p``: the arithmetic its
        guarantee held in, ``None`` when they do not."""
        _, cl, _, gouts, _ = self.timed_k[p.k]
        if not (gouts & outs) or ns < p.stamp_ns:
            return None
        j = judge(cl.formula, self.checked, self.node, self._visible(p, ns / 1e9), self.tolerance)
        return j.semantics if j.truth is True else None

    def _visible(self, p: Pending, stamp: float | None = None) -> dict[str, object]:
        """What obligation ``p`` is judged on for an output stamped ``stamp``:
        the inputs of the latest question at that stamp (the trigger's own, or
        the accepted question that superseded it: docs/semantics.md), with the
        trigger input's value as the trigger message set it (a press released
        before its answer still demands the press's answer: an output computed
        from the release does not answer it), the state outputs as they stand
        and the outputs published since its trigger."""
        q = self.stream.at(stamp) if stamp is not None else None
        values = dict(q.inputs if q is not None and q.owed and q.stamp >= p.stamp else p.inputs)
        trig = self.timed_k[p.k][2]
        if trig in p.inputs:
            values[trig] = p.inputs[trig]
        values.update({key: v for key, v in self.values.items() if key in self.state_outs and v is not None})
        values.update(p.outs)
        return values

    def advance(self, now: float) -> None:
        """Move the clock to ``now`` (s); obligations due before it are ``false``."""
        self._advance_ns(to_ns(now))

    def _advance_ns(self, now_ns: int) -> None:
        """Move the clock to ``now_ns`` (integer ns); obligations due strictly before it are ``false``."""
        if self.now_ns is not None and now_ns <= self.now_ns:
            return
        self.now_ns = now_ns
        self.now = now_ns / 1e9
        if self.unclocked and self.unclocked[0].stamp_ns < now_ns - self.sim.kept_ns:
            deadline_first_clock.release_held(self, now_ns - self.sim.kept_ns)  # no /clock in the kept window after it
        if self.unsure and self.unsure[0][2] < now_ns - self.sim.kept_ns:
            deadline_first_clock.drop_records(self, now_ns - self.sim.kept_ns)  # no longer given again by a /clock
        self._expire(now_ns)

    def _expire(self, now_ns: int) -> None:
        """Obligations due strictly before ``now_ns`` (integer ns, the monitor's clock) are ``false``."""
        keep = []
        for p in self.pending:
            if p.due_ns < now_ns and p.maybe:  # its answer may be the output within the skew before it
                deadline_skew.undecided(self, p)
                self.expired.append(p)
            elif p.due_ns < now_ns:
                self._emit(self.expired_verdict(p, now_ns))
                self.result.note_time_margin(p.k, None, p.trigger.where, "", 0.0)  # until a late answer comes
                self.expired.append(p)
            else:
                keep.append(p)
        self.pending = keep

    def pending_verdicts(self) -> list[DeadlineVerdict]:
        """The obligations not answered whose deadline has not expired yet."""
        return [DeadlineVerdict(self.node.name, p.k, "currently_false", p.trigger.where, p.stamp, p.due, None, "",
                                "not answered yet; " + (
                                    "no /clock message heard yet to place it in simulated time" if p.unclocked else
                                    "/clock has not passed its deadline in simulated time yet"
                                    if p.due_ns >= deadline_place.FAR else
                                    f"{ms_ns(p.due_ns - (self.now_ns or 0))} left") + deadline_place.words(self, p))
                for p in self.pending]

    def finish(self) -> DeadlineResult:
        """End of the run: obligations still within their deadline are ``currently_false``;
        those and the expired ones never answered are counted unanswered in the time margins."""
        deadline_first_clock.release_held(self)  # held with no /clock heard: undecided, as on a run without it
        if self.now_ns is not None:  # a due time set behind the clock (deadline_place.py) expires before the end
            self._expire(self.now_ns)
        for v in self.pending_verdicts():
            self._emit(v)
        for p in self.pending:
            self.result.note_time_margin(p.k, None, p.trigger.where, "", 0.0)
        self.pending = []
        return self.result


def check_deadlines(checked: Checked, nodes: Iterable[CheckedNode], events: Iterable[Event],
                    rules: Mapping[str, TopicRule], on_verdict: Callable[[DeadlineVerdict], None] | None = None,
                    horizon: float | None = None, tolerance: Tolerance | None = None) -> list[DeadlineResult]:
    """The deadline monitors of ``nodes`` run over a recorded trace, in
    order; ``horizon`` (s) bounds a ``triggered by`` without ``within``;
    ``tolerance`` as for :class:`DeadlineMonitor`."""
    monitors = [DeadlineMonitor(checked, n, rules, on_verdict, horizon, tolerance) for n in nodes]
    for ev in events:
        for m in monitors:
            m.feed(ev)
    return [m.finish() for m in monitors]


__all__ = ["DeadlineMonitor", "check_deadlines", "rejected"]
