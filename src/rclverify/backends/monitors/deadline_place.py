"""An obligation placed in the clock its node keeps (the rule: :mod:`.deadline_clock`; docs/semantics.md,
"Deadlines in simulated time"): its due times on the run's clock (:func:`place`, :func:`set_due`), an
answer's time margin in that clock (:func:`margin_ns`), an ``undecided`` verdict (:func:`undecided`) and
what a verdict's reason says of the clock (:func:`words`, :func:`band_why`).  Read by
:mod:`.deadline_first_clock` and :mod:`.deadline_clock` through :class:`ClockMonitor`.
"""
from __future__ import annotations

from collections import deque
from typing import Callable, Protocol

from rclverify.lang.types import CheckedNode
from rclverify.traces.events import Event
from rclverify.traces.sim_clock import SimClock
from rclverify.backends.monitors.deadline_records import DeadlineResult, DeadlineVerdict, Pending, Recorded
from rclverify.backends.monitors.deadline_text import ms_ns
from rclverify.backends.monitors import deadline_late

#: the due time (integer ns) of an obligation whose simulated deadline ``/clock`` has not passed yet
FAR = 1 << 62

#: what a verdict's reason says a ``use_sim_time`` left unsaid would decide
DECLARE = "say which clock the node keeps (the mapping's use_sim_time) to decide it"


class ClockMonitor(Protocol):
    """What this module, :mod:`.deadline_first_clock` and :mod:`.deadline_clock` read and move of a deadline
    monitor (:class:`~.deadlines.DeadlineMonitor`)."""

    node: CheckedNode
    result: DeadlineResult
    on_verdict: Callable[[DeadlineVerdict], None] | None
    sim: SimClock
    sim_mode: bool | None
    awaiting: list[Pending]
    pending: list[Pending]
    expired: deque[Pending]
    skew_ns: int
    now_ns: int | None
    answered_late: deque[deadline_late.Answered]
    unclocked: deque[Pending]
    unsure: deque[Recorded]

    def _judged(self, p: Pending, ev: Event, ns: int, semantics: str) -> None: ...

    def _withdraw_false(self, p: Pending) -> None: ...

    def _emit(self, v: DeadlineVerdict, counted: bool = False) -> None: ...

    def answered_verdict(self, p: Pending, ns: int, ev: Event, d: float, semantics: str = "exact") -> DeadlineVerdict:
        ...


def place(mon: ClockMonitor, p: Pending) -> str:
    """Place new obligation ``p`` (its ``due_ns`` the run's clock's) in its node's clock (:mod:`.deadline_clock`);
    returns why it cannot be judged (``undecided`` at once), ``""`` when placed."""
    sim = mon.sim
    sq = sim.at(p.stamp_ns)
    if sq is None:
        if sim.broken:
            return sim.broken
        if mon.sim_mode is True:
            return ("its node keeps simulated time (use_sim_time) and no /clock message was heard before it: "
                    "its simulated time is not known")
        return ""  # not said, and simulated time had not started: the run's clock
    p.sim_due_ns = sq + p.bound_ns
    p.clock = "sim" if mon.sim_mode else "either"
    p.wall_due_ns = p.due_ns
    w = sim.passed(p.sim_due_ns)
    if w is None:
        p.due_ns = FAR
        p.sure_ns = FAR if p.clock == "sim" else p.wall_due_ns
        mon.awaiting.append(p)
    else:
        set_due(mon, p, w)
    return ""


def set_due(mon: ClockMonitor, p: Pending, w: int) -> None:
    """Obligation ``p``'s due times once ``/clock`` passed its simulated deadline at ``w`` (ns, the run's clock)."""
    skew = mon.skew_ns
    p.sim_passed_ns = w
    if p.clock == "sim":
        p.sure_ns, p.due_ns = w - 1, max(w + skew - 1, w - 1)
    else:
        p.sure_ns, p.due_ns = min(p.wall_due_ns, w - 1), max(p.wall_due_ns, w + skew - 1)
    p.due = p.due_ns / 1e9


def undecided(mon: ClockMonitor, p: Pending, why: str, update: bool = False) -> None:
    """Obligation ``p`` ``undecided`` because of its clock (``why``): counted with the unaccepted triggers
    (not in the verdict counts) and given to ``on_verdict`` (``update``: it replaces a verdict given)."""
    res = mon.result
    res.unaccepted["undecided"] += 1
    if res.first_unaccepted is None:
        res.first_unaccepted = {"guarantee": p.k, "where": p.trigger.where, "stamp": p.stamp, "why": "undecided",
                                "reason": why}
    if mon.on_verdict is not None:
        mon.on_verdict(DeadlineVerdict(mon.node.name, p.k, "undecided", p.trigger.where, p.stamp, p.due, None, "",
                                       why, update=update))


def answered(mon: ClockMonitor, p: Pending, given: str, ev: Event, ns: int, semantics: str = "",
             entry: tuple[int, int, str, str, float] | None = None) -> None:
    """Obligation ``p`` placed in a clock was given ``given`` (``true``, or ``undecided`` in the band) by
    answer ``ev`` stamped ``ns`` (its ``semantics``; ``entry``: its margin noted withdrawable, given while
    ``/clock`` was not heard after ``ns``).  Before ``/clock`` passed its simulated deadline (:data:`FAR`) it
    is kept for a ``/clock`` message heard late (:func:`.deadline_clock.tick`); after, only its margin is."""
    if p.due_ns < FAR:
        if entry is not None:  # its margin reads /clock at the answer, which a later /clock placed before moves
            p.answer_ns, p.held = ns, entry
            mon.awaiting.append(p)
        return
    p.given, p.answer, p.answer_ns, p.semantics, p.held = given, ev, ns, semantics, entry


def margin_ns(mon: ClockMonitor, p: Pending, ns: int) -> int:
    """The time margin (integer ns) of an answer at ``ns`` to obligation ``p`` placed in a clock: in simulated
    time the deadline less ``/clock`` at the answer; with both clocks the smaller of the two."""
    at = mon.sim.at(ns)
    sim = p.sim_due_ns - at if at is not None else p.wall_due_ns - ns
    return sim if p.clock == "sim" else min(sim, p.wall_due_ns - ns)


def words(mon: ClockMonitor, p: Pending) -> str:
    """What a verdict's reason adds for obligation ``p`` placed in a clock (``""`` for the run's clock), with
    how it was placed when the first ``/clock`` message was heard late (:func:`.deadline_first_clock.place_held`)."""
    if not p.clock:
        return ""
    if p.placed:
        return _words(p) + p.placed
    return _words(p)


def _words(p: Pending) -> str:
    passed = f", passed by /clock at {p.sim_passed_ns / 1e9:.3f} s on the run's clock" if p.sim_passed_ns else ""
    if p.clock == "sim":
        return (f"; in simulated time (use_sim_time): due at {p.sim_due_ns / 1e9:.3f} s on /clock{passed}")
    return (f"; judged on the run's clock and in simulated time (due at {p.sim_due_ns / 1e9:.3f} s on /clock"
            f"{passed}): the node's clock is not said")


def band_why(mon: ClockMonitor, p: Pending, ev: Event, ns: int) -> str:
    if p.clock == "sim":
        return (f"answered at {ev.where} {ms_ns(ns - p.sim_passed_ns)} after /clock passed the deadline "
                f"({p.sim_due_ns / 1e9:.3f} s simulated), within the transport skew: the node may not have "
                "received that /clock message yet")
    wall = "in time" if ns <= p.wall_due_ns else "late"
    return (f"answered at {ev.where}: {wall} on the run's clock, {'late' if wall == 'in time' else 'in time'} in "
            f"simulated time (/clock); the node's clock is not said: {DECLARE}")


def held_margins(mon: ClockMonitor, k: int) -> list[deadline_late.Held]:
    """The margins of guarantee ``k`` still withdrawable (:func:`.deadline_late.held`), the recorded answers'
    (:func:`.deadline_first_clock.record`) among them."""
    return deadline_late.held(mon.answered_late, mon.awaiting, k, mon.unsure)


def keep_from(mon: ClockMonitor, ns: int) -> int:
    """The time (ns, the run's clock) before which an answer is no longer kept for a late ``/clock``: the
    simulated clock's kept window behind the monitor's clock (``ns``, the ``/clock`` message's, before any)."""
    return (mon.now_ns if mon.now_ns is not None else ns) - mon.sim.kept_ns


__all__ = ["DECLARE", "FAR", "ClockMonitor", "answered", "band_why", "held_margins", "keep_from", "margin_ns", "place",
           "set_due", "undecided", "words"]
