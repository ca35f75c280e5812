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
  A trigger before any ``/clock`` message is held until the first one places it
  (:mod:`.deadline_first_clock`).  A trigger after ``/clock`` went back (a reset)
  is ``undecided`` at once.
* **the run's clock** (said): ``/clock`` is not read; as on a run without it.
* **not said**, on a run whose ``/clock`` has been heard: both.  ``true`` only
  when in time in both clocks, ``false`` only when late in both, else
  ``undecided``, naming the two clocks and what decides it (the mapping's
  ``use_sim_time``).  A trigger before the first ``/clock`` message is placed
  on the run's clock, and made unsure once ``/clock`` is heard
  (:mod:`.deadline_first_clock`).

Each obligation so placed carries its clock (:attr:`~.deadline_records.Pending.clock`),
the last stamp in time in every clock (``sure_ns``) and the first late in every
clock (``due_ns``, what the monitor's expiry reads), both on the run's clock;
until ``/clock`` passes its simulated deadline its ``due_ns`` is :data:`~.deadline_place.FAR`
(:attr:`awaiting`), so no ``false`` is given while the simulated clock stands.

**A ``/clock`` message heard late.**  Live, the engine releases messages in
stamp order under a lateness bound; a ``/clock`` message heard later than the
bound comes after messages stamped after it, where the run read in stamp order
(its log, its bag) has it before them.  So an obligation answered before
``/clock`` passed its simulated deadline stays in :attr:`awaiting` with its
verdict (:func:`.deadline_place.answered`), and when a ``/clock`` message passes that deadline
at or before the answer's stamp the answer is judged again by the rule above
(:func:`_again`): a ``true`` becomes ``false`` (past the skew) or
``undecided`` (within it), an ``undecided`` of a clock not said ``false``,
each an update that replaces the verdict in the counts and names the late
message and how late it was heard (:func:`judge_again`, after what the
message expires, as the run read in stamp order gives them).  ``/clock``'s
one writer publishes in order, so once a ``/clock`` message placed after
the answer was heard, none placed before it comes: the verdict stands.  A late
``/clock`` message also places again each awaiting obligation whose trigger
is stamped after it (at the value it shows), and the margin of an answer it
precedes (``s + d`` less ``/clock`` at the answer) is measured again: an
answer's margin stays withdrawable, its obligation in :attr:`awaiting`, until
``/clock`` is heard after the answer (a late answer's, kept by
:mod:`.deadline_late`, while it is kept there).  Memory: an answered
obligation leaves :attr:`awaiting` once ``/clock`` was heard after its
answer (usually the next ``/clock`` message), or once its answer is more than the simulated
clock's kept window (:attr:`~rclverify.traces.sim_clock.SimClock.kept_ns`:
the node's longest bound and a minute) behind the monitor's clock; a
``/clock`` message later than that leaves it as judged.

The first ``/clock`` message, and what comes before it, is
:mod:`.deadline_first_clock`'s; placing an obligation in its clock, and what
its verdict says of that clock, :mod:`.deadline_place`'s.
"""
from __future__ import annotations

import dataclasses

from rclverify.traces.events import Event
from rclverify.traces.sim_clock import clock_value_ns
from rclverify.backends.monitors.deadline_records import Pending
from rclverify.backends.monitors.deadline_text import ms, ms_ns
from rclverify.backends.monitors import deadline_late
from rclverify.backends.monitors.deadline_place import (FAR, ClockMonitor, answered, band_why, held_margins, keep_from,
                                                        margin_ns, set_due, undecided)
from rclverify.backends.monitors.deadline_first_clock import place_held, unsaid_first


def reads_clock(mon: ClockMonitor) -> bool:
    """Whether a new obligation of ``mon`` is placed in a clock (:func:`.deadline_place.place`): its node said to keep simulated time,
    or not said on a run whose ``/clock`` has been heard."""
    return mon.sim_mode is True or (mon.sim_mode is None and mon.sim.heard)


def tick(mon: ClockMonitor, ev: Event, ns: int) -> list[Pending]:
    """A ``/clock`` message ``ev`` placed at ``ns`` (integer ns, the run's clock): kept in ``mon.sim`` (not by
    a node said to keep the run's clock); each obligation awaiting the simulated clock that it passes gets its
    due times; after a reset every awaiting obligation still open is ``undecided``.  Heard late (placed
    before a message already fed), it also places again each awaiting obligation whose trigger is stamped at
    or after it, at the simulated time it shows (the trigger's place in the run's stamp order), and measures
    again the margins of the answers it precedes.  Returns the obligations answered before ``/clock`` passed
    their deadline that it passes, to be judged again (:func:`judge_again`, once what it expires is)."""
    value = clock_value_ns(ev.fields)
    if value is None or mon.sim_mode is False:
        return []
    sim = mon.sim
    first = not sim.heard
    late = mon.now_ns is not None and ns < mon.now_ns
    sim.see(ns, value, ev.where)
    if first and mon.unclocked:
        place_held(mon, ev, ns, late)
    if first and mon.sim_mode is None:
        unsaid_first(mon, ev, ns, late)
    if late and mon.answered_late:
        _late_margins_again(mon, ns)
    if not mon.awaiting:
        return []
    if sim.broken:
        waiting, mon.awaiting = mon.awaiting, []
        gone = {id(p) for p in waiting}
        open_ = [p for p in mon.pending if id(p) in gone]
        mon.pending = [p for p in mon.pending if id(p) not in gone]
        for p in open_:
            undecided(mon, p, sim.broken)
        for p in waiting:
            _settle(mon, p)
        return []
    horizon = keep_from(mon, ns)
    keep: list[Pending] = []
    again: list[Pending] = []
    remeasure: list[Pending] = []  # answers whose margin this message may move
    judged: list[Pending] = []  # of them, those past their deadline: kept or settled once measured again
    for p in mon.awaiting:
        if p.due_ns >= FAR:  # /clock had not passed its simulated deadline
            if late and p.stamp_ns >= ns:  # placed before this message was heard: at the value it shows
                at = sim.at(p.stamp_ns)
                if at is not None:
                    p.sim_due_ns = at + p.bound_ns
            w = sim.passed(p.sim_due_ns)
            if w is None:
                if p.given and (p.answer_ns < horizon or sim.heard_after(p.answer_ns)):
                    _settle(mon, p)  # /clock heard after its answer: a later one passes it after the answer
                else:
                    if p.held is not None and (ns <= p.answer_ns or (late and p.stamp_ns >= ns)):
                        remeasure.append(p)
                    keep.append(p)
                continue
            set_due(mon, p, w)
            if p.given:
                again.append(p)
            continue
        if p.held is not None and ns <= p.answer_ns:  # judged already: its margin read on this /clock
            remeasure.append(p)
            judged.append(p)
            keep.append(p)
            continue
        _keep_or_settle(mon, p, keep, horizon)
    mon.awaiting = keep
    if remeasure:  # in the order of the answers' stamps: the order the stamp order notes them in
        for p in sorted(remeasure, key=lambda q: q.answer_ns):
            _margin_again(mon, p)
        stay: list[Pending] = []
        for p in judged:
            _keep_or_settle(mon, p, stay, horizon)
        if len(stay) < len(judged):
            settled = {id(p) for p in judged} - {id(p) for p in stay}
            mon.awaiting = [p for p in keep if id(p) not in settled]
    return again


def judge_again(mon: ClockMonitor, again: list[Pending], ev: Event, ns: int) -> None:
    """The obligations ``again`` that ``/clock`` message ``ev`` (placed at ``ns``) passed after their answer
    was judged (:func:`tick`), each judged again (:func:`_again`); kept while their margin may still move."""
    horizon = keep_from(mon, ns)
    for p in again:
        _again(mon, p, ev, ns)
        _keep_or_settle(mon, p, mon.awaiting, horizon)


def _keep_or_settle(mon: ClockMonitor, p: Pending, keep: list[Pending], horizon: int) -> None:
    """Answered obligation ``p``, ``/clock`` past its deadline: kept (appended to ``keep``) while its margin
    may still move (no ``/clock`` heard after its answer, within the kept window), else settled."""
    if p.held is not None and not mon.sim.heard_after(p.answer_ns) and p.answer_ns >= horizon:
        keep.append(p)
    else:
        _settle(mon, p)


def _settle(mon: ClockMonitor, p: Pending) -> None:
    """Obligation ``p`` leaves the obligations kept for a late ``/clock``: its answer's margin, where one was
    held, can no longer be withdrawn."""
    if p.held is not None:
        mon.result.settle(p.k, p.held)
        p.held = None


def _margin_again(mon: ClockMonitor, p: Pending) -> None:
    """The margin of ``p``'s answer (held) measured again on the ``/clock`` now heard: where it differs, the
    one noted is withdrawn and the new one noted (held)."""
    assert p.held is not None
    margin = margin_ns(mon, p, p.answer_ns)
    entry = p.held
    if margin == entry[0]:
        return
    p.held = None
    res = mon.result
    deadline_late.withdraw_margin(res, held_margins(mon, p.k), p.k, entry[0],
                                  entry[2])
    order = res.note_time_margin(p.k, margin, entry[2], entry[3], entry[4], held=True)
    p.held = (margin, order, entry[2], entry[3], entry[4])


def _late_margins_again(mon: ClockMonitor, ns: int) -> None:
    """A ``/clock`` message placed at ``ns`` heard late: the margin of each late answer kept
    (:mod:`.deadline_late`) to an obligation placed in a clock, stamped at or after ``ns``, measured again on
    it (the one noted withdrawn where it differs, the new one noted withdrawable)."""
    kept = mon.answered_late
    for i, (p, margin, order, where, stamp) in enumerate(kept):
        if not p.clock or p.answer_ns < ns:
            continue
        now = margin_ns(mon, p, p.answer_ns)
        if now == margin:
            continue
        rest = [e for e in held_margins(mon, p.k) if e[1] != order]
        deadline_late.withdraw_margin(mon.result, rest, p.k, margin, p.trigger.where)
        kept[i] = (p, now, mon.result.note_time_margin(p.k, now, p.trigger.where, where, stamp, held=True), where,
                   stamp)


def _again(mon: ClockMonitor, p: Pending, ev: Event, ns: int) -> None:
    """Obligation ``p``, answered (its verdict :attr:`~.Pending.given`) before ``/clock`` passed its simulated
    deadline, now that ``/clock`` message ``ev`` placed at ``ns`` passed it (``p``'s due times set): judged
    again as the run read in stamp order judges its answer (``true`` up to ``sure_ns``, ``undecided`` to
    ``due_ns``, ``false`` after; :attr:`~.Pending.maybe`: never ``false``).  A verdict that differs replaces
    the one given, in the counts and as an update to ``on_verdict`` naming ``ev`` and how late it was heard."""
    a, answer = p.answer_ns, p.answer
    assert answer is not None
    if a <= p.sure_ns:
        if p.held is not None and ns <= a:
            _margin_again(mon, p)
        return
    want = "undecided" if a <= p.due_ns or p.maybe else "false"
    if want == p.given:
        return
    res = mon.result
    if p.given == "true":
        res.counts["true"] -= 1
        if p.held is not None:
            entry, p.held = p.held, None
            rest = held_margins(mon, p.k)  # its own no longer held
            deadline_late.withdraw_margin(res, rest, p.k, entry[0], p.trigger.where)
    else:
        res.unaccepted["undecided"] -= 1
    if mon.now_ns is not None and ns < mon.now_ns:
        late = ms(ev.late) if ev.late > 0 else ms_ns(mon.now_ns - ns)
        heard = (f"heard {late} after its time, past the lateness bound"
                 if ev.late > 0 else f"heard when the monitor's clock stood {late} after it")
    else:
        heard = "read after the answer"
    withdrawn = (f"; the {p.given} given when the answer came is withdrawn: the /clock message at {ev.where} "
                 f"(at {ns / 1e9:.3f} s, /clock at {(clock_value_ns(ev.fields) or 0) / 1e9:.3f} s, past the "
                 f"simulated deadline before the answer) was {heard}")
    if want == "undecided":
        why = (f"answered at {answer.where} {ms_ns(a - p.due_ns)} past its deadline, but {p.maybe}" if p.maybe
               else band_why(mon, p, answer, a))
        p.given = "undecided"
        undecided(mon, p, why + withdrawn, update=True)
        return
    v = mon.answered_verdict(p, a, answer, p.bound_ns / 1e9, p.semantics)
    p.given = "false"
    mon._emit(dataclasses.replace(v, reason=v.reason + withdrawn, update=True), counted=True)
    margin = margin_ns(mon, p, a)  # held: a /clock message heard later, placed before the answer, moves it
    order = res.note_time_margin(p.k, margin, p.trigger.where, answer.where, a / 1e9, held=True)
    p.held = (margin, order, p.trigger.where, answer.where, a / 1e9)


def band(mon: ClockMonitor, p: Pending, ev: Event, ns: int) -> None:
    """Obligation ``p`` answered by ``ev`` at ``ns``, after its last time in time in every clock and not after
    its first late in every clock: ``undecided``, saying why (kept for a late ``/clock``: :func:`.deadline_place.answered`)."""
    undecided(mon, p, band_why(mon, p, ev, ns))
    answered(mon, p, "undecided", ev, ns)


def band_late(mon: ClockMonitor, p: Pending, ev: Event, ns: int) -> None:
    """Expired obligation ``p`` (its ``false`` given, or ``undecided`` when it was :attr:`~.Pending.maybe`)
    answered by ``ev`` at ``ns``, heard after the clock passed its deadline, in the band of :func:`band`: the
    ``false`` is withdrawn and the obligation is ``undecided``, an update saying so."""
    if p.maybe:
        return  # counted undecided already
    mon._withdraw_false(p)
    undecided(mon, p, band_why(mon, p, ev, ns) + "; the false given when the clock passed is withdrawn",
              update=True)


__all__ = ["band", "band_late", "judge_again", "reads_clock", "tick"]
