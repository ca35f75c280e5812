"""Answers a deadline monitor hears after the clock passed the deadline (docs/semantics.md, "Deadlines").

An answer stamped within the deadline and heard after the clock passed it
(later than the lateness bound, or a stamp the node copied from its
question) meets it on its own stamp, the ``false`` given withdrawn
(:func:`met_late`).

Live, an obligation judged ``false`` when the watermark passed its deadline
and then answered by an output of its own stamped after the deadline keeps
its ``false`` (an update names the late answer).  An output stamped within
the transport skew before its trigger that satisfies the guarantee on the
trigger's inputs may still be heard after both (later than the lateness
bound); the run read in stamp order puts it before the trigger and finds
the deadline ``undecided`` (:mod:`.deadline_skew`).  So such an obligation
is kept with its late answer (the last :data:`KEPT`), and an output of that
kind heard later makes it ``undecided`` as
:func:`.deadline_skew.revise_false` does an unanswered one: its ``false``
and its late answer's time margin are withdrawn, and the verdict that
follows says so.  Offline a run is read in stamp order, so that output
comes first and nothing is kept here to revise.

A late answer's margin is counted when it comes, marked withdrawable
(:meth:`~.deadline_records.DeadlineResult.note_time_margin`, ``held``);
withdrawn, the guarantee's smallest margin becomes the smallest of those
no revision can withdraw (:attr:`~.deadline_records.DeadlineResult.floor`)
and of the late answers still kept and the answers kept for a late
``/clock`` (:mod:`.deadline_clock`), the first noted of equals, as if the
withdrawn one had never been counted (:func:`withdraw_margin`).
"""
from __future__ import annotations

from collections import deque
from typing import Iterable, Mapping, Protocol

from rclverify.traces.events import Event
from rclverify.backends.monitors import deadline_skew
from rclverify.backends.monitors.deadline_records import DeadlineResult, DeadlineVerdict, Pending, Recorded
from rclverify.backends.monitors.deadline_text import ms_ns

#: how many late-answered obligations are kept for a revision (as many as the expired ones, deadlines.py)
KEPT = 256

#: one kept obligation: (the obligation, its late answer's margin in ns, the order that margin was noted in,
#: the answer's place, its stamp s)
Answered = tuple[Pending, int, int, str, float]
#: one margin still withdrawable, as :attr:`~.deadline_records.DeadlineResult.floor` holds one: (margin ns, the
#: order it was noted in, the trigger's place, the answer's place, its stamp s)
Held = tuple[int, int, str, str, float]


class LateAnswers(deadline_skew.DeadlineMonitor, Protocol):
    """What this module reads of :class:`~.deadlines.DeadlineMonitor` beyond the skew rule's."""

    answered_late: deque[Answered]
    awaiting: list[Pending]
    unsure: deque[Recorded]
    result: DeadlineResult

    def _emit(self, v: DeadlineVerdict) -> None: ...


def hold(mon: LateAnswers, p: Pending, ns: int, ev: Event, margin: int | None = None) -> None:
    """Expired obligation ``p`` (judged ``false``, not marked by the skew) answered by output ``ev`` stamped
    ``ns``, after its deadline: its margin (``margin``, ns, in the clock ``p`` is kept in; ``None``: its due
    time less ``ns``) counted (withdrawable) and ``p`` kept for :func:`revise`; the oldest kept one past
    :data:`KEPT` leaves, its margin no longer withdrawable."""
    if margin is None:
        margin = p.due_ns - ns
    p.answer_ns = ns
    order = mon.result.note_time_margin(p.k, margin, p.trigger.where, ev.where, ns / 1e9, was_unanswered=True,
                                        held=True)
    kept = mon.answered_late
    if len(kept) >= KEPT:
        gone = kept.popleft()
        mon.result.settle(gone[0].k, (gone[1], gone[2], gone[0].trigger.where, gone[3], gone[4]))
    kept.append((p, margin, order, ev.where, ns / 1e9))


def revise(mon: LateAnswers, ev: Event, ns: int, fresh: Mapping[str, object]) -> None:
    """Output ``ev`` stamped ``ns`` (``fresh``: the outputs it set): each kept obligation whose trigger it is
    stamped within the skew before, and whose guarantee it satisfies on the trigger's inputs, is
    ``undecided`` (:func:`.deadline_skew.revise_false`), its late answer's margin withdrawn."""
    for entry in list(mon.answered_late):
        p = entry[0]
        if ns < p.stamp_ns and deadline_skew.may_answer(mon, p, ev, ns) and \
                deadline_skew.revise_false(mon, p, ev, ns, fresh, answered=True):
            mon.answered_late.remove(entry)
            _withdraw_margin(mon, entry)


def met_late(mon: LateAnswers, p: Pending, ev: Event, ns: int, margin: int | None = None) -> None:
    """Obligation ``p`` was judged ``false`` when the clock passed its deadline;
    output ``ev``, stamped ``ns`` (within it), answers it, heard after the
    clock passed (a message later than the lateness bound, or a stamp the
    node copied from its question): the deadline is met, on the answer's
    own stamp, as a run read in stamp order finds it (docs/semantics.md,
    "Event time": lateness never makes a violation).  The ``false`` given
    is withdrawn from the counts; the verdict that follows says why.
    ``margin``: the answer's (ns, in the clock ``p`` is kept in; ``None``: its due time less ``ns``)."""
    if margin is None:
        margin = p.due_ns - ns
    if p.maybe:  # counted undecided, not false: now met on its own answer's stamp
        deadline_skew.decided_late(mon, p)
        mon._emit(DeadlineVerdict(mon.node.name, p.k, "true", p.trigger.where, p.stamp, p.due, ns / 1e9,
                                  ev.where, f"answered after {ms_ns(ns - p.stamp_ns)} (deadline "
                                  f"{ms_ns(p.bound_ns)}), heard after the clock had passed the "
                                  "deadline: met on the answer's own stamp", time_margin=margin / 1e9))
        mon.result.note_time_margin(p.k, margin, p.trigger.where, ev.where, ns / 1e9)
        return
    mon._withdraw_false(p)
    mon.result.counts["true"] += 1
    late = ms_ns(mon.now_ns - ns) if mon.now_ns is not None else "?"
    v = DeadlineVerdict(mon.node.name, p.k, "true", p.trigger.where, p.stamp, p.due, ns / 1e9, ev.where,
                        f"answered after {ms_ns(ns - p.stamp_ns)} (deadline {ms_ns(p.bound_ns)}), "
                        f"heard after the clock had passed the deadline (at {late} behind it): met on the "
                        "answer's own stamp; the false given when the clock passed is withdrawn",
                        update=True, time_margin=margin / 1e9)
    if mon.on_verdict is not None:
        mon.on_verdict(v)
    mon.result.note_time_margin(p.k, margin, p.trigger.where, ev.where, ns / 1e9, was_unanswered=True)


def _withdraw_margin(mon: LateAnswers, entry: Answered) -> None:
    """The late answer's margin of ``entry`` out of its guarantee's time margins (module docstring)."""
    p = entry[0]
    withdraw_margin(mon.result, held(mon.answered_late, mon.awaiting, p.k, mon.unsure), p.k, entry[1],
                    p.trigger.where)


def held(answered_late: Iterable[Answered], awaiting: Iterable[Pending], k: int,
         recorded: Iterable[Recorded] = ()) -> list[Held]:
    """The margins of guarantee ``k`` a revision may still withdraw: the late answers kept (``answered_late``)
    and the answers given while ``/clock`` may still move their verdict or margin (``awaiting``'s
    :attr:`~.deadline_records.Pending.held`, given before ``/clock`` passed their deadline; ``recorded``, given
    before the first ``/clock``: :func:`.deadline_first_clock.record`), each in
    :attr:`~.deadline_records.DeadlineResult.floor`'s shape."""
    got = [(e[1], e[2], e[0].trigger.where, e[3], e[4]) for e in answered_late if e[0].k == k]
    return got + [p.held for p in awaiting if p.k == k and p.held is not None] + [r[1] for r in recorded if r[0] == k]


def withdraw_margin(result: DeadlineResult, rest: list[Held], k: int, margin: int, trigger_where: str) -> None:
    """One answer's margin ``margin`` (ns; of the trigger at ``trigger_where``) out of guarantee ``k``'s time
    margins in ``result``; where it was the smallest, the smallest becomes the least of ``rest`` (the
    margins still withdrawable, it not among them) and of those no revision can withdraw
    (:attr:`~.deadline_records.DeadlineResult.floor`), the first noted of equals."""
    margins = result.time_margins
    m = margins.get(k)
    if m is None:
        return
    m.answers -= 1
    if not m.answers:  # none left: as if none had been noted
        if not m.unanswered:
            del margins[k]
        m.margin_ns, m.trigger_where, m.answer_where, m.answer = 0, "", "", 0.0
        return
    if (m.margin_ns, m.trigger_where) != (margin, trigger_where):
        return  # not the smallest: the smallest stands
    low = result.floor.get(k)
    best = min(rest + ([low] if low is not None else []), default=None, key=lambda e: e[:2])
    if best is not None:
        m.margin_ns, _, m.trigger_where, m.answer_where, m.answer = best


__all__ = ["KEPT", "Answered", "Held", "LateAnswers", "held", "hold", "met_late", "revise", "withdraw_margin"]
