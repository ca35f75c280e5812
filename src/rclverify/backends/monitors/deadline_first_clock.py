"""The first ``/clock`` message of a run, and the obligations placed before it (the rule of deadlines in
simulated time: :mod:`.deadline_clock`; docs/semantics.md, "Deadlines in simulated time").

A trigger of a node said to keep simulated time before any ``/clock`` message is held, no verdict given
(:func:`hold`), until the first ``/clock`` message places it as the run read in stamp order does
(:func:`place_held`): stamped at or after that message, at the value it shows, and judged with the
answer that came meanwhile; stamped before it, ``undecided``, saying why: its simulated time is not
known.  With no ``/clock`` heard within the simulated clock's kept window after it (or by the run's end)
it is ``undecided`` so too (:func:`release_held`).  A trigger of a node whose clock is not said, before
the first ``/clock`` message, is placed on the run's clock; once ``/clock`` is heard, such an obligation
still open is never ``false`` and one expired unanswered has its ``false`` withdrawn (``undecided``, no
longer counted unanswered: :func:`_unsaid_before`).

**The first ``/clock`` message heard late.**  Live, a trigger stamped after the
first ``/clock`` message may be released before it (the monitor's ``/clock``
reader is made once it discovers the publisher).  Read in stamp order it is
placed at that message's value; so a trigger of a node said to keep simulated
time is held while no ``/clock`` has been heard (:func:`hold`), its answer
kept, not judged, and placed by the first ``/clock`` message (:func:`place_held`;
its verdict's reason then says it was held and how late that message was
heard).  Memory: at most :data:`HELD` held obligations, each at most the kept
window; past either, the oldest is released as on a run without ``/clock``.
A node whose clock is not said is judged on the run's clock meanwhile, as on
a run without ``/clock`` (no verdict waits); the answer to each such
obligation is recorded in plain values (:func:`record`: its verdict, its
margin noted withdrawable; as many and as long as held ones), and the first
``/clock`` message, heard late, gives again what was given (:func:`unsaid_first`)
to the obligations open, expired (the last 256) or answered since whose
trigger is stamped at or after it, as the stamp order does in both clocks (a
``false`` on the run's clock withdrawn, ``undecided`` or open again, an update
naming that message), and makes ``undecided`` one stamped before it and
answered late after it.
"""
from __future__ import annotations

import dataclasses
from collections import deque

from rclverify.traces.events import Event
from rclverify.backends.monitors.deadline_records import DeadlineVerdict, Pending, Recorded
from rclverify.backends.monitors.deadline_text import ms, ms_ns
from rclverify.backends.monitors import deadline_late
from rclverify.backends.monitors.deadline_place import (DECLARE, FAR, ClockMonitor, answered, band_why, held_margins,
                                                        keep_from, margin_ns, place, undecided, words)

#: the most obligations held while no ``/clock`` has been heard (:func:`hold`): past it the oldest is released
HELD = 4096


def hold(mon: ClockMonitor, p: Pending) -> None:
    """New obligation ``p`` of a node said to keep simulated time, placed while no ``/clock`` has been heard:
    held (no verdict) until the first ``/clock`` message places it (:func:`place_held`), or until it is more
    than the simulated clock's kept window behind the monitor's clock with none heard (:func:`release_held`).
    Its answer meanwhile is kept (:attr:`~.Pending.first_answer`), not judged.  At most :data:`HELD` are held;
    past it the oldest quarter is released."""
    p.unclocked, p.wall_due_ns, p.due_ns = True, p.due_ns, FAR
    held = mon.unclocked
    held.append(p)
    if len(held) > HELD:
        _release(mon, [held.popleft() for _ in range(HELD // 4)])


def place_held(mon: ClockMonitor, ev: Event, ns: int, late: bool) -> None:
    """The first ``/clock`` message ``ev``, placed at ``ns`` (``late``: placed before a message already fed):
    each held obligation placed as the run read in stamp order places it (:func:`.deadline_place.place`: stamped at or after
    ``ns``, at the value ``ev`` shows; before it, ``undecided``, no ``/clock`` heard before it), then its
    answer, if one came meanwhile, judged (:meth:`~.deadlines.DeadlineMonitor._judged`); those still open stay
    open in their clock."""
    held, mon.unclocked = list(mon.unclocked), deque()
    note = ""
    if late:
        note = (f"; held until the first /clock message ({ev.where}, at {ns / 1e9:.3f} s) came"
                + (f", heard {ms(ev.late)} after its time, past the lateness bound" if ev.late > 0 else "")
                + ": the trigger, stamped after it, was heard before it")
    unanswered = {id(p) for p in held if p.first_answer is None}
    opened = {id(p) for p in mon.pending if id(p) in unanswered}
    mon.pending = [p for p in mon.pending if id(p) not in unanswered]
    answered_: list[tuple[int, Pending]] = []
    for p in held:
        _unhold(mon, p)
        why = place(mon, p)
        if why:
            undecided(mon, p, why)
        elif p.first_answer is not None:
            answered_.append((p.first_answer[1], p))
        elif id(p) in opened:
            mon.pending.append(p)
        p.placed = note if p.clock else ""
    answered_.sort(key=lambda x: x[0])  # judged in the order of their answers' stamps, as the stamp order does
    for a, p in answered_:
        assert p.first_answer is not None
        answer, _, semantics = p.first_answer
        p.first_answer = None
        mon._judged(p, answer, a, semantics)


def release_held(mon: ClockMonitor, before_ns: int | None = None) -> None:
    """The held obligations (:func:`hold`) stamped before ``before_ns`` (integer ns, the run's clock; ``None``:
    every one, the run's end) with no ``/clock`` heard: each ``undecided`` as a run without ``/clock`` gives
    it (its simulated time is not known)."""
    held = mon.unclocked
    gone: list[Pending] = []
    while held and (before_ns is None or held[0].stamp_ns < before_ns):
        gone.append(held.popleft())
    if gone:
        _release(mon, gone)


def _release(mon: ClockMonitor, gone: list[Pending]) -> None:
    """Held obligations ``gone`` (taken from :attr:`~.deadlines.DeadlineMonitor.unclocked`, in order) released with no ``/clock`` heard
    (:func:`release_held`): each ``undecided``, its simulated time not known."""
    ids = {id(p) for p in gone if p.first_answer is None}
    if ids:
        mon.pending = [q for q in mon.pending if id(q) not in ids]
    for p in gone:
        _unhold(mon, p)
        p.first_answer = None
        undecided(mon, p, place(mon, p))


def _unhold(mon: ClockMonitor, p: Pending) -> None:
    """Held obligation ``p`` no longer held: its due time on the run's clock again (what :func:`.deadline_place.place` reads)."""
    p.unclocked, p.due_ns = False, p.wall_due_ns


def record(mon: ClockMonitor, p: Pending, ev: Event, ns: int, semantics: str, given: str,
           entry: tuple[int, int, str, str, float]) -> None:
    """Obligation ``p`` of a node whose clock is not said, placed on the run's clock while no ``/clock`` has
    been heard, answered by ``ev`` at ``ns`` (``given``: ``true`` or ``false``; ``entry``: its margin, noted
    withdrawable): recorded, in plain values (:data:`~.deadline_records.Recorded`), while the first ``/clock``
    message, heard late, may be stamped at or before its trigger (:func:`unsaid_first`): until its trigger is
    more than the simulated clock's kept window behind the monitor's clock, or ``/clock`` is heard
    (:func:`drop_records`).  At most :data:`HELD` are kept; past it the oldest quarter is dropped."""
    t = p.trigger
    kept = mon.unsure
    kept.append((p.k, entry, p.stamp_ns, p.stamp, p.due, p.due_ns, t.index, t.time, t.topic, t.where, ev.index,
                 ev.time, ev.topic, ev.where, ns, semantics, given))
    if len(kept) > HELD:
        _drop(mon, [kept.popleft() for _ in range(HELD // 4)])


def drop_records(mon: ClockMonitor, before_ns: int | None = None) -> None:
    """The recorded answers (:func:`record`) to triggers stamped before ``before_ns`` (integer ns; ``None``:
    every one) no longer given again: their margins can no longer be withdrawn."""
    kept = mon.unsure
    gone: list[Recorded] = []
    while kept and (before_ns is None or kept[0][2] < before_ns):
        gone.append(kept.popleft())
    _drop(mon, gone)


def _drop(mon: ClockMonitor, gone: list[Recorded]) -> None:
    settle = mon.result.settle
    for r in gone:
        settle(r[0], r[1])


def _revived(r: Recorded) -> tuple[Pending, Event]:
    """The obligation and the answer recorded in ``r`` (:func:`record`): the messages named, not their fields."""
    (k, entry, stamp_ns, stamp, due, due_ns, t_index, t_time, t_topic, t_where, a_index, a_time, a_topic, a_where,
     a, semantics, given) = r
    p = Pending(k, Event(t_index, t_time, t_topic, {}, t_where), stamp, due, {}, stamp_ns=stamp_ns, due_ns=due_ns)
    answer = Event(a_index, a_time, a_topic, {}, a_where)
    p.given, p.held, p.first_answer = given, entry, (answer, a, semantics)
    return p, answer


def unsaid_first(mon: ClockMonitor, ev: Event, ns: int, late: bool) -> None:
    """The first ``/clock`` message ``ev``, placed at ``ns``, heard by the monitor of a node whose clock is not
    said (``late``: placed before a message already fed).  Each obligation placed on the run's clock whose
    trigger is stamped at or after ``ns`` (open, expired, or answered: :func:`record`; within the kept window) is
    placed again as the run read in stamp order places it, in both clocks (at the value ``ev`` shows), and what
    it was given on the run's clock is given again there: open, it stays open; expired unanswered, its
    ``false`` is withdrawn and it is open again (an update says so); answered in time, its ``true`` stands, its
    margin measured in both clocks; answered late, it is ``undecided`` (late on the run's clock, not in
    simulated time yet), an update.  One stamped before ``ns`` and answered late after it is ``undecided``
    (:func:`_late_after`).  Then those placed before it are made unsure (:func:`_unsaid_before`), and the
    records dropped."""
    if late:
        heard = (f"heard {ms(ev.late)} after its time, past the lateness bound" if ev.late > 0 else
                 "heard after messages stamped after it")
        note = (f"; placed again when the first /clock message ({ev.where}, at {ns / 1e9:.3f} s), stamped before "
                f"the trigger, was {heard}")
        _given_again(mon, ns, note)
        _late_after(mon, ns, heard)
    _unsaid_before(mon, ns)
    drop_records(mon)


def _late_after(mon: ClockMonitor, ns: int, heard: str) -> None:
    """The obligations on the run's clock stamped before the first ``/clock`` message (at ``ns``, ``heard`` as
    late as it says) and answered late after it (recorded, or kept with their late answer): each ``undecided``,
    an update, as the run read in stamp order gives it (open when ``/clock`` came: never ``false`` since,
    :func:`_unsaid_before`); its ``false`` and its answer's margin are withdrawn.  One answered in time keeps
    its ``true``."""
    got: list[tuple[Pending, int, Event, int]] = []  # (obligation, margin withdrawn, answer, its stamp)
    late = [e for e in mon.answered_late if not e[0].clock and not e[0].maybe and e[0].stamp_ns < ns
            and e[0].first_answer is not None and e[0].first_answer[1] >= ns]
    if late:
        gone = {id(e[0]) for e in late}
        mon.answered_late = deque(e for e in mon.answered_late if id(e[0]) not in gone)
        for e in late:
            assert e[0].first_answer is not None
            got.append((e[0], e[1], e[0].first_answer[0], e[0].first_answer[1]))
    kept = [r for r in mon.unsure if r[2] < ns and r[14] >= ns and r[16] == "false"]
    if kept:
        gone = {id(r) for r in kept}
        mon.unsure = deque(r for r in mon.unsure if id(r) not in gone)
        for r in kept:
            p, answer = _revived(r)
            p.held = None
            got.append((p, r[1][0], answer, r[14]))
    why = _unsaid_why(ns)
    for p, margin, answer, a in sorted(got, key=lambda x: x[0].stamp_ns):
        mon._withdraw_false(p)
        deadline_late.withdraw_margin(mon.result, held_margins(mon, p.k), p.k, margin, p.trigger.where)
        p.maybe = why
        undecided(mon, p, f"answered at {answer.where} {ms_ns(a - p.due_ns)} past its deadline, but {why}; the "
                          f"false given is withdrawn: the first /clock message was {heard}", update=True)


def _given_again(mon: ClockMonitor, ns: int, note: str) -> None:
    """:func:`unsaid_first` of the obligations stamped at or after ``ns``, in their triggers' order."""
    horizon = keep_from(mon, ns)
    after = [(p.stamp_ns, 0, p) for p in mon.pending if not p.clock and p.stamp_ns >= ns]
    expired = [p for p in mon.expired if not p.clock and p.stamp_ns >= ns and p.stamp_ns >= horizon]
    if expired:
        gone = {id(p) for p in expired}
        mon.expired = deque((p for p in mon.expired if id(p) not in gone), maxlen=mon.expired.maxlen)
        after += [(p.stamp_ns, 1, p) for p in expired]
    late = [e for e in mon.answered_late if not e[0].clock and e[0].stamp_ns >= ns and e[0].first_answer is not None]
    if late:
        gone = {id(e[0]) for e in late}
        mon.answered_late = deque(e for e in mon.answered_late if id(e[0]) not in gone)
    late_of = {id(e[0]): e for e in late}
    after += [(e[0].stamp_ns, 2, e[0]) for e in late]
    kept = [r for r in mon.unsure if r[2] >= ns]
    if kept:
        gone = {id(r) for r in kept}
        mon.unsure = deque(r for r in mon.unsure if id(r) not in gone)
        after += [(r[2], 3, _revived(r)[0]) for r in kept]
    res = mon.result
    for _, kind, p in sorted(after, key=lambda x: x[0]):
        if kind == 0:  # open: stays open, in both clocks
            place(mon, p)
            p.placed = note
            continue
        if kind == 1:  # expired unanswered: open again
            given = "undecided" if p.maybe else "false"
            if p.maybe:
                res.unaccepted["undecided"] -= 1
            else:
                mon._withdraw_false(p)
                _unanswered_withdrawn(mon, p)
            place(mon, p)
            p.placed = note
            mon.pending.append(p)
            if mon.on_verdict is not None:
                mon.on_verdict(DeadlineVerdict(
                    mon.node.name, p.k, "currently_false", p.trigger.where, p.stamp, p.due, None, "",
                    f"not answered yet; the {given} given when the run's clock passed its deadline is withdrawn"
                    + words(mon, p), update=True))
            continue
        assert p.first_answer is not None
        answer, a, semantics = p.first_answer
        if kind == 2:  # expired, then answered late: the false and the late answer's margin withdrawn
            mon._withdraw_false(p)
            deadline_late.withdraw_margin(res, held_margins(mon, p.k), p.k, late_of[id(p)][1], p.trigger.where)
            _late_again(mon, p, answer, a, semantics, note)
            continue
        assert p.held is not None  # answered on its own: true or false
        old, p.held = p.held, None
        deadline_late.withdraw_margin(res, held_margins(mon, p.k), p.k, old[0], p.trigger.where)
        if p.given == "false":
            mon._withdraw_false(p)
            _late_again(mon, p, answer, a, semantics, note)
            continue
        place(mon, p)
        p.placed = note
        margin = margin_ns(mon, p, a)
        order = res.note_time_margin(p.k, margin, p.trigger.where, answer.where, a / 1e9, held=True)
        answered(mon, p, "true", answer, a, semantics, (margin, order, p.trigger.where, answer.where, a / 1e9))


def _unanswered_withdrawn(mon: ClockMonitor, p: Pending) -> None:
    """Expired obligation ``p``, counted unanswered in its guarantee's time margins when it expired, its
    ``false`` withdrawn: no longer counted (an ``undecided`` or open obligation is not)."""
    margins = mon.result.time_margins
    m = margins.get(p.k)
    if m is not None and m.unanswered:
        m.unanswered -= 1
        if not m.answers and not m.unanswered:
            del margins[p.k]


def _late_again(mon: ClockMonitor, p: Pending, answer: Event, a: int, semantics: str, note: str) -> None:
    """Recorded obligation ``p`` answered by ``answer`` at ``a``, past its deadline on the run's clock, its
    ``false`` and that answer's margin withdrawn: placed in both clocks, ``undecided`` (in the band), an update."""
    place(mon, p)
    p.placed = note
    if p.due_ns < FAR and a > p.due_ns:  # /clock past its deadline too: false, as given
        mon._emit(dataclasses.replace(mon.answered_verdict(p, a, answer, p.bound_ns / 1e9, semantics), update=True),
                  counted=True)
        return
    undecided(mon, p, band_why(mon, p, answer, a) + "; the false given on the run's clock is withdrawn" + note,
              update=True)
    answered(mon, p, "undecided", answer, a, semantics)


def _unsaid_before(mon: ClockMonitor, ns: int) -> None:
    """``/clock`` heard for the first time, at ``ns``, by the monitor of a node whose clock is not said: the
    obligations placed on the run's clock before it may have been kept in simulated time.  Those still open
    are never ``false`` now (``undecided`` if their deadline passes on the run's clock), and those expired
    unanswered have their ``false`` withdrawn, ``undecided``: an update saying why.  One answered late
    before it keeps its ``false``."""
    why = _unsaid_why(ns)
    for p in mon.pending:
        if not p.clock and not p.maybe:
            p.maybe = why
    for p in mon.expired:
        if not p.clock and not p.maybe:
            mon._withdraw_false(p)
            _unanswered_withdrawn(mon, p)
            p.maybe = why
            undecided(mon, p, why + "; the false given is withdrawn", update=True)


def _unsaid_why(ns: int) -> str:
    """Why an obligation of a node whose clock is not said, placed on the run's clock before the first ``/clock``
    message (at ``ns``), is never ``false`` once that message is heard (:func:`_unsaid_before`)."""
    return (f"placed on the run's clock before /clock was first heard (at {ns / 1e9:.3f} s): the node may keep "
            f"simulated time; {DECLARE}")


__all__ = ["HELD", "drop_records", "hold", "place_held", "record", "release_held", "unsaid_first"]
