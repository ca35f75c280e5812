"""The transport skew in the deadline rule: an answer stamped just before its trigger.

A monitor hears each topic over its own connection and stamps an unstamped
message when its callback runs, so a node's answer can be stamped a little
before the trigger it answers (seed 331 of the robot generator: a relay's
``sensor_msgs/Range``, stamped by the relay as it published, 0.2-0.3 ms
before the monitor received the unstamped reading it answers).  The
mapping's ``skew`` (:mod:`.skew`) bounds how far apart two messages may be
stamped in the other order than they were published, and the deadline rule
reads it as the guarantee's pairing does (docs/semantics.md, "Transport
skew" and "Deadlines"): a trigger stamped in ``(s, s + skew]`` after an
output stamped ``s``, or at ``s`` but heard after it, may be the question that
output answers.

So an obligation (:class:`~.deadline_records.Pending`) for which such an output
satisfies the guarantee, judged on the trigger's inputs, is marked
(:attr:`~.deadline_records.Pending.maybe`): answered by an output of its own
(stamped at or after the trigger) within the deadline it is ``true`` as
before; left unanswered when the clock passes its deadline it is
``undecided`` (counted with the unaccepted triggers, with why), never
``false``: the skew makes no red and no green.  An output stamped more than
the skew before the trigger is never its answer, and an obligation with no
such output that goes unanswered is ``false`` as before.

So is an output placed before the trigger as the copy of a stamp in another
clock (its stamp set aside, traces/event_time.py, ``CopiedStamps``) but
published after the trigger, within its deadline (:func:`published_after`: the
event's ``source``): a simulated clock standing still gives several messages
alike the stamp it copies, so it may be this trigger's answer; the stamps
cannot say which question it answers (docs/semantics.md, "Event time";
generated seed 1075).
"""
from __future__ import annotations

import dataclasses
from collections import deque
from typing import Callable, Mapping, Protocol

from rclverify.semantics.floatsem import Tolerance, judge
from rclverify.lang import ast
from rclverify.lang.types import Checked, CheckedNode
from rclverify.traces.event_time import aside_stamp
from rclverify.traces.events import Event
from rclverify.backends.monitors.deadline_records import DeadlineResult, DeadlineVerdict, Pending
from rclverify.backends.monitors.deadline_text import ms_ns
from rclverify.backends.monitors.skew import within_before


class DeadlineMonitor(Protocol):
    """What the skew rule reads of :class:`~.deadlines.DeadlineMonitor` (declared here, so that this
    module stays below the monitor that calls it)."""

    skew_ns: int
    timed_k: dict[int, tuple[int, ast.Clause, str, frozenset[str], float]]
    heard: deque[tuple[int, Event, set[str], dict[str, object]]]
    checked: Checked
    node: CheckedNode
    tolerance: Tolerance | None
    result: DeadlineResult
    on_verdict: Callable[[DeadlineVerdict], None] | None
    now_ns: int | None

    def _visible(self, p: Pending, stamp: float | None = None) -> dict[str, object]: ...

    def _withdraw_false(self, p: Pending) -> None: ...


def skew_ns(rules: object) -> int:
    """The transport skew the mapping's rules declare (``rules.skew``, s; none: 0), in integer ns."""
    skew = getattr(rules, "skew", None)
    return round(skew * 1_000_000_000) if isinstance(skew, (int, float)) and skew > 0 else 0


def within_skew_before(mon: DeadlineMonitor, p: Pending, ns: int) -> bool:
    """Whether an output stamped ``ns`` (integer ns), heard before obligation ``p``'s trigger or stamped
    before it, lies within the transport skew before the trigger: ``p.stamp_ns - skew <= ns <= p.stamp_ns``."""
    return mon.skew_ns > 0 and within_before(ns, p.stamp_ns, mon.skew_ns)


def published_after(p: Pending, ev: Event, ns: int) -> bool:
    """Whether output ``ev``, placed at ``ns`` (integer ns) before obligation ``p``'s trigger as the copy of
    a stamp in another clock (:func:`~rclverify.traces.event_time.aside_stamp`), was published after that
    trigger and by its deadline (its ``source``, s): a copy of a stamp a clock standing still shares."""
    if ev.source is None or ns >= p.stamp_ns or not p.stamp_ns < round(ev.source * 1_000_000_000) <= p.due_ns:
        return False
    return aside_stamp(ev.fields) is not None


def may_answer(mon: DeadlineMonitor, p: Pending, ev: Event, ns: int) -> bool:
    """Whether output ``ev``, placed at ``ns`` before ``p``'s trigger, may still be its answer: within the
    skew before it (:func:`within_skew_before`) or published after it (:func:`published_after`)."""
    return within_skew_before(mon, p, ns) or published_after(p, ev, ns)


def mark_early(mon: DeadlineMonitor, p: Pending, ev: Event, ns: int, fresh: Mapping[str, object]) -> None:
    """Output ``ev`` (stamped ``ns``, within the skew before ``p``'s trigger; ``fresh`` the outputs it set) may be
    ``p``'s answer: mark ``p`` (:attr:`~.deadline_records.Pending.maybe`) when it satisfies ``p``'s guarantee on
    the trigger's inputs.  The first such output is the one named."""
    if p.maybe:
        return
    k, cl, _, gouts, _ = mon.timed_k[p.k]
    if not (gouts & set(fresh)):
        return
    values = mon._visible(p, ns / 1e9)
    values.update(fresh)
    if judge(cl.formula, mon.checked, mon.node, values, mon.tolerance).truth is not True:
        return
    if within_skew_before(mon, p, ns):
        p.maybe = (f"the output at {ev.where}, stamped {ms_ns(p.stamp_ns - ns)} before the trigger (within the "
                   f"transport skew of {ms_ns(mon.skew_ns)}), satisfies guarantee {k} on the trigger's inputs and may "
                   "be its answer")
    elif ev.source is not None:
        p.maybe = (f"the output at {ev.where}, placed {ms_ns(p.stamp_ns - ns)} before the trigger as the copy of "
                   f"a stamp in another clock but published {ms_ns(round(ev.source * 1_000_000_000) - p.stamp_ns)} "
                   f"after it (a clock standing still gives several messages that stamp), satisfies guarantee {k} "
                   "on the trigger's inputs and may be its answer")


def scan_heard(mon: DeadlineMonitor, p: Pending) -> None:
    """Mark ``p`` from the outputs already heard (the last 64 kept) that may be its answer (:func:`may_answer`:
    stamped within the skew before its trigger, or placed before it and published after it), oldest first."""
    for ns, ev, _, fresh in [h for h in mon.heard if may_answer(mon, p, h[1], h[0])]:
        mark_early(mon, p, ev, ns, fresh)
        if p.maybe:
            return


def undecided(mon: DeadlineMonitor, p: Pending, revised: str = "") -> None:
    """Obligation ``p``, marked, unanswered when the clock passed its deadline: ``undecided`` with why,
    counted with the unaccepted triggers (not in the verdict counts) and given to ``on_verdict`` as a
    verdict ``undecided``, so that every trigger past its deadline has a verdict record on every path;
    ``revised``: the words of a ``false`` it replaces (:func:`revise_false`; the verdict is then an update)."""
    res = mon.result
    res.unaccepted["undecided"] += 1
    reason = f"no answer of its own within the deadline of {ms_ns(p.bound_ns)}, but {p.maybe}"
    if res.first_unaccepted is None:
        res.first_unaccepted = {"guarantee": p.k, "where": p.trigger.where, "stamp": p.stamp, "why": "undecided",
                                "reason": reason}
    if mon.on_verdict is not None:
        mon.on_verdict(DeadlineVerdict(mon.node.name, p.k, "undecided", p.trigger.where, p.stamp, p.due, None, "",
                                       reason + revised, update=bool(revised)))


def revise_false(mon: DeadlineMonitor, p: Pending, ev: Event, ns: int, fresh: Mapping[str, object],
                 answered: bool = False) -> bool:
    """Obligation ``p`` was judged ``false`` when the clock passed its deadline (``answered``: and answered
    since by an output of its own stamped after it, :mod:`.deadline_late`); output ``ev``, stamped ``ns``
    within the skew before its trigger (``fresh``: the outputs it set), was heard only then (later than the
    lateness bound).  Where it satisfies the guarantee on the trigger's inputs (:func:`mark_early`, judged as
    when the trigger came: on none of the outputs published after it), ``p`` is what the run read in stamp
    order makes it, ``undecided``: the ``false`` is withdrawn (its count, the first ``false``, its unanswered
    time margin, unless ``answered``: the caller withdraws the late answer's) and counted ``undecided`` by
    :func:`undecided`, whose verdict is an update saying so.  Returns whether it did."""
    probe = dataclasses.replace(p, outs={})
    mark_early(mon, probe, ev, ns, fresh)
    if not probe.maybe:
        return False
    p.maybe = probe.maybe
    mon._withdraw_false(p)
    margins = mon.result.time_margins
    m = margins.get(p.k)
    if m is not None and not answered:  # counted unanswered when it expired; an undecided trigger counts none
        m.unanswered -= 1
        if not m.answers and not m.unanswered:
            del margins[p.k]
    behind = ms_ns(mon.now_ns - ns) if mon.now_ns is not None else "?"
    undecided(mon, p, f"; heard after the clock had passed the deadline (at {behind} behind it): the false given "
                      "when the clock passed is withdrawn" + (", and its late answer's with it" if answered else ""))
    return True


def decided_late(mon: DeadlineMonitor, p: Pending) -> None:
    """Marked obligation ``p``, counted ``undecided`` when its deadline passed, answered by an output of its own
    stamped in time: no longer undecided (its ``true`` is given by the caller)."""
    res = mon.result
    res.unaccepted["undecided"] -= 1
    first = res.first_unaccepted
    if first is not None and first["where"] == p.trigger.where and first["why"] == "undecided":
        res.first_unaccepted = None


__all__ = ["decided_late", "mark_early", "may_answer", "published_after", "revise_false", "scan_heard", "skew_ns",
           "undecided", "within_skew_before"]
