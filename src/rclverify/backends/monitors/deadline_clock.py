"""Deadlines kept in simulated time (docs/semantics.md, "Deadlines in simulated time").

A node under ``use_sim_time`` keeps its time from ``/clock`` (REP 2008): its
``within d`` is ``d`` of simulated time, which at a real-time factor of 0.5
takes twice as long on the wall clock and stands still while the simulator is
paused.  The deadline monitor (:class:`~.deadlines.DeadlineMonitor`) reads the
run's ``/clock`` messages into a :class:`~rclverify.traces.sim_clock.SimClock`
(:func:`tick`) and places each obligation in the clock its node keeps, as the
mapping's ``use_sim_time`` says (:func:`~rclverify.traces.mapping.sim_time_of`):

* **simulated time** (said): an obligation whose trigger was placed when
  ``/clock`` stood at ``s`` (:meth:`SimClock.at`) is due at ``s + d``; an answer
  placed before the first ``/clock`` message past ``s + d`` (:meth:`SimClock.passed`,
  at ``w`` on the run's clock) is in time, ``true``; one placed at ``w`` plus
  the transport skew (:mod:`.skew`) or later, or the clock reaching that with
  no answer, is ``false``; an answer from ``w`` to that is ``undecided`` (the
  node may not have received that ``/clock`` message yet).
  A trigger before any ``/clock`` message, or after ``/clock`` went back (a
  reset), is ``undecided`` at once, saying why: its simulated time is not known.
* **the run's clock** (said): ``/clock`` is not read; as on a run without it.
* **not said**, on a run whose ``/clock`` has been heard: both.  ``true`` only
  when in time in both clocks, ``false`` only when late in both, else
  ``undecided``, naming the two clocks and what decides it (the mapping's
  ``use_sim_time``).  A trigger before the first ``/clock`` message is placed
  on the run's clock; once ``/clock`` is heard, such an obligation still open
  is never ``false`` and one expired unanswered has its ``false`` withdrawn
  (``undecided``: :func:`_unsaid_before`).

Each obligation so placed carries its clock (:attr:`~.deadline_records.Pending.clock`),
the last stamp in time in every clock (``sure_ns``) and the first late in every
clock (``due_ns``, what the monitor's expiry reads), both on the run's clock;
until ``/clock`` passes its simulated deadline its ``due_ns`` is :data:`FAR`
(:attr:`awaiting`), so no ``false`` is given while the simulated clock stands.
"""
from __future__ import annotations

from collections import deque
from typing import Callable, Protocol

from rclverify.lang.types import CheckedNode
from rclverify.traces.events import Event
from rclverify.traces.sim_clock import SimClock, clock_value_ns
from rclverify.backends.monitors.deadline_records import DeadlineResult, DeadlineVerdict, Pending
from rclverify.backends.monitors.deadline_text import ms_ns

#: the due time (integer ns) of an obligation whose simulated deadline ``/clock`` has not passed yet
FAR = 1 << 62

#: what a verdict's reason says a ``use_sim_time`` left unsaid would decide
DECLARE = "say which clock the node keeps (the mapping's use_sim_time) to decide it"


class ClockMonitor(Protocol):
    """What this module reads and moves of a deadline monitor (:class:`~.deadlines.DeadlineMonitor`)."""

    node: CheckedNode
    result: DeadlineResult
    on_verdict: Callable[[DeadlineVerdict], None] | None
    sim: SimClock
    sim_mode: bool | None
    awaiting: list[Pending]
    pending: list[Pending]
    expired: deque[Pending]
    skew_ns: int

    def _withdraw_false(self, p: Pending) -> None: ...


def reads_clock(mon: ClockMonitor) -> bool:
    """Whether a new obligation of ``mon`` is placed by this module: its node said to keep simulated time,
    or not said on a run whose ``/clock`` has been heard."""
    return mon.sim_mode is True or (mon.sim_mode is None and mon.sim.heard)


def tick(mon: ClockMonitor, ev: Event, ns: int) -> None:
    """A ``/clock`` message ``ev`` placed at ``ns`` (integer ns, the run's clock): kept in ``mon.sim`` (not by
    a node said to keep the run's clock); each obligation awaiting the simulated clock that it passes gets its
    due times; after a reset every awaiting obligation still open is ``undecided``."""
    value = clock_value_ns(ev.fields)
    if value is None or mon.sim_mode is False:
        return
    sim = mon.sim
    first = not sim.heard
    sim.see(ns, value, ev.where)
    if first and mon.sim_mode is None:
        _unsaid_before(mon, ns)
    if not mon.awaiting:
        return
    if sim.broken:
        waiting, mon.awaiting = mon.awaiting, []
        gone = {id(p) for p in waiting}
        open_ = [p for p in mon.pending if id(p) in gone]
        mon.pending = [p for p in mon.pending if id(p) not in gone]
        for p in open_:
            undecided(mon, p, sim.broken)
        return
    keep = []
    for p in mon.awaiting:
        w = sim.passed(p.sim_due_ns)
        if w is None:
            keep.append(p)
        else:
            _due(mon, p, w)
    mon.awaiting = keep


def _unsaid_before(mon: ClockMonitor, ns: int) -> None:
    """``/clock`` heard for the first time, at ``ns``, by the monitor of a node whose clock is not said: the
    obligations placed on the run's clock before it may have been kept in simulated time.  Those still open
    are never ``false`` now (``undecided`` if their deadline passes on the run's clock), and those expired
    unanswered have their ``false`` withdrawn, ``undecided``: an update saying why.  One answered late
    before it keeps its ``false``."""
    why = (f"placed on the run's clock before /clock was first heard (at {ns / 1e9:.3f} s): the node may keep "
           f"simulated time; {DECLARE}")
    for p in mon.pending:
        if not p.clock and not p.maybe:
            p.maybe = why
    for p in mon.expired:
        if not p.clock and not p.maybe:
            mon._withdraw_false(p)
            p.maybe = why
            undecided(mon, p, why + "; the false given is withdrawn", update=True)


def place(mon: ClockMonitor, p: Pending) -> str:
    """Place new obligation ``p`` (its ``due_ns`` the run's clock's) in its node's clock (module docstring);
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
        _due(mon, p, w)
    return ""


def _due(mon: ClockMonitor, p: Pending, w: int) -> None:
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


def band(mon: ClockMonitor, p: Pending, ev: Event, ns: int) -> None:
    """Obligation ``p`` answered by ``ev`` at ``ns``, after its last time in time in every clock and not after
    its first late in every clock: ``undecided``, saying why."""
    undecided(mon, p, _band_why(mon, p, ev, ns))


def band_late(mon: ClockMonitor, p: Pending, ev: Event, ns: int) -> None:
    """Expired obligation ``p`` (its ``false`` given, or ``undecided`` when it was :attr:`~.Pending.maybe`)
    answered by ``ev`` at ``ns``, heard after the clock passed its deadline, in the band of :func:`band`: the
    ``false`` is withdrawn and the obligation is ``undecided``, an update saying so."""
    if p.maybe:
        return  # counted undecided already
    mon._withdraw_false(p)
    undecided(mon, p, _band_why(mon, p, ev, ns) + "; the false given when the clock passed is withdrawn",
              update=True)


def _band_why(mon: ClockMonitor, p: Pending, ev: Event, ns: int) -> str:
    if p.clock == "sim":
        return (f"answered at {ev.where} {ms_ns(ns - p.sim_passed_ns)} after /clock passed the deadline "
                f"({p.sim_due_ns / 1e9:.3f} s simulated), within the transport skew: the node may not have "
                "received that /clock message yet")
    wall = "in time" if ns <= p.wall_due_ns else "late"
    return (f"answered at {ev.where}: {wall} on the run's clock, {'late' if wall == 'in time' else 'in time'} in "
            f"simulated time (/clock); the node's clock is not said: {DECLARE}")


def margin_ns(mon: ClockMonitor, p: Pending, ns: int) -> int:
    """The time margin (integer ns) of an answer at ``ns`` to obligation ``p`` placed in a clock: in simulated
    time the deadline less ``/clock`` at the answer; with both clocks the smaller of the two."""
    at = mon.sim.at(ns)
    sim = p.sim_due_ns - at if at is not None else p.wall_due_ns - ns
    return sim if p.clock == "sim" else min(sim, p.wall_due_ns - ns)


def words(mon: ClockMonitor, p: Pending) -> str:
    """What a verdict's reason adds for obligation ``p`` placed in a clock (``""`` for the run's clock)."""
    if not p.clock:
        return ""
    passed = f", passed by /clock at {p.sim_passed_ns / 1e9:.3f} s on the run's clock" if p.sim_passed_ns else ""
    if p.clock == "sim":
        return (f"; in simulated time (use_sim_time): due at {p.sim_due_ns / 1e9:.3f} s on /clock{passed}")
    return (f"; judged on the run's clock and in simulated time (due at {p.sim_due_ns / 1e9:.3f} s on /clock"
            f"{passed}): the node's clock is not said")


__all__ = ["DECLARE", "FAR", "band", "band_late", "margin_ns", "place", "reads_clock", "tick", "undecided",
           "words"]
