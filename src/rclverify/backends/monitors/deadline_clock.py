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
  A trigger before any ``/clock`` message is held, no verdict given
  (:func:`hold`), until the first ``/clock`` message places it as the run read
  in stamp order does (:func:`place_held`): stamped at or after that message,
  at the value it shows, and judged with the answer that came meanwhile;
  stamped before it, ``undecided``, saying why: its simulated time is not
  known.  With no ``/clock`` heard within the simulated clock's kept window
  after it (or by the run's end) it is ``undecided`` so too
  (:func:`release_held`).  A trigger after ``/clock`` went back (a reset) is
  ``undecided`` at once.
* **the run's clock** (said): ``/clock`` is not read; as on a run without it.
* **not said**, on a run whose ``/clock`` has been heard: both.  ``true`` only
  when in time in both clocks, ``false`` only when late in both, else
  ``undecided``, naming the two clocks and what decides it (the mapping's
  ``use_sim_time``).  A trigger before the first ``/clock`` message is placed
  on the run's clock; once ``/clock`` is heard, such an obligation still open
  is never ``false`` and one expired unanswered has its ``false`` withdrawn
  (``undecided``, no longer counted unanswered: :func:`_unsaid_before`).

Each obligation so placed carries its clock (:attr:`~.deadline_records.Pending.clock`),
the last stamp in time in every clock (``sure_ns``) and the first late in every
clock (``due_ns``, what the monitor's expiry reads), both on the run's clock;
until ``/clock`` passes its simulated deadline its ``due_ns`` is :data:`FAR`
(:attr:`awaiting`), so no ``false`` is given while the simulated clock stands.

**A ``/clock`` message heard late.**  Live, the engine releases messages in
stamp order under a lateness bound; a ``/clock`` message heard later than the
bound comes after messages stamped after it, where the run read in stamp order
(its log, its bag) has it before them.  So an obligation answered before
``/clock`` passed its simulated deadline stays in :attr:`awaiting` with its
verdict (:func:`answered`), and when a ``/clock`` message passes that deadline
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
from typing import Callable, Protocol

from rclverify.lang.types import CheckedNode
from rclverify.traces.events import Event
from rclverify.traces.sim_clock import SimClock, clock_value_ns
from rclverify.backends.monitors.deadline_records import DeadlineResult, DeadlineVerdict, Pending, Recorded
from rclverify.backends.monitors.deadline_text import ms, ms_ns
from rclverify.backends.monitors import deadline_late

#: the due time (integer ns) of an obligation whose simulated deadline ``/clock`` has not passed yet
FAR = 1 << 62

#: the most obligations held while no ``/clock`` has been heard (:func:`hold`): past it the oldest is released
HELD = 4096

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
    now_ns: int | None
    answered_late: deque[deadline_late.Answered]
    unclocked: deque[Pending]
    unsure: deque[Recorded]

    def _judged(self, p: Pending, ev: Event, ns: int, semantics: str) -> None: ...

    def _withdraw_false(self, p: Pending) -> None: ...

    def _emit(self, v: DeadlineVerdict, counted: bool = False) -> None: ...

    def answered_verdict(self, p: Pending, ns: int, ev: Event, d: float, semantics: str = "exact") -> DeadlineVerdict:
        ...


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
    each held obligation placed as the run read in stamp order places it (:func:`place`: stamped at or after
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
    """Held obligation ``p`` no longer held: its due time on the run's clock again (what :func:`place` reads)."""
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
        deadline_late.withdraw_margin(mon.result, _held(mon, p.k), p.k, margin, p.trigger.where)
        p.maybe = why
        undecided(mon, p, f"answered at {answer.where} {ms_ns(a - p.due_ns)} past its deadline, but {why}; the "
                          f"false given is withdrawn: the first /clock message was {heard}", update=True)


def _given_again(mon: ClockMonitor, ns: int, note: str) -> None:
    """:func:`unsaid_first` of the obligations stamped at or after ``ns``, in their triggers' order."""
    horizon = _horizon(mon, ns)
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
            deadline_late.withdraw_margin(res, _held(mon, p.k), p.k, late_of[id(p)][1], p.trigger.where)
            _late_again(mon, p, answer, a, semantics, note)
            continue
        assert p.held is not None  # answered on its own: true or false
        old, p.held = p.held, None
        deadline_late.withdraw_margin(res, _held(mon, p.k), p.k, old[0], p.trigger.where)
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
    undecided(mon, p, _band_why(mon, p, answer, a) + "; the false given on the run's clock is withdrawn" + note,
              update=True)
    answered(mon, p, "undecided", answer, a, semantics)


def _held(mon: ClockMonitor, k: int) -> list[deadline_late.Held]:
    """The margins of guarantee ``k`` still withdrawable (:func:`.deadline_late.held`), the recorded answers'
    (:func:`record`) among them."""
    return deadline_late.held(mon.answered_late, mon.awaiting, k, mon.unsure)


def reads_clock(mon: ClockMonitor) -> bool:
    """Whether a new obligation of ``mon`` is placed by this module: its node said to keep simulated time,
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
    horizon = _horizon(mon, ns)
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
            _due(mon, p, w)
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
    horizon = _horizon(mon, ns)
    for p in again:
        _again(mon, p, ev, ns)
        _keep_or_settle(mon, p, mon.awaiting, horizon)


def _horizon(mon: ClockMonitor, ns: int) -> int:
    """The time (ns, the run's clock) before which an answer is no longer kept for a late ``/clock``: the
    simulated clock's kept window behind the monitor's clock (``ns``, the ``/clock`` message's, before any)."""
    return (mon.now_ns if mon.now_ns is not None else ns) - mon.sim.kept_ns


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
    deadline_late.withdraw_margin(res, _held(mon, p.k), p.k, entry[0],
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
        rest = [e for e in _held(mon, p.k) if e[1] != order]
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
            rest = _held(mon, p.k)  # its own no longer held
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
               else _band_why(mon, p, answer, a))
        p.given = "undecided"
        undecided(mon, p, why + withdrawn, update=True)
        return
    v = mon.answered_verdict(p, a, answer, p.bound_ns / 1e9, p.semantics)
    p.given = "false"
    mon._emit(dataclasses.replace(v, reason=v.reason + withdrawn, update=True), counted=True)
    margin = margin_ns(mon, p, a)  # held: a /clock message heard later, placed before the answer, moves it
    order = res.note_time_margin(p.k, margin, p.trigger.where, answer.where, a / 1e9, held=True)
    p.held = (margin, order, p.trigger.where, answer.where, a / 1e9)


def answered(mon: ClockMonitor, p: Pending, given: str, ev: Event, ns: int, semantics: str = "",
             entry: tuple[int, int, str, str, float] | None = None) -> None:
    """Obligation ``p`` placed in a clock was given ``given`` (``true``, or ``undecided`` in the band) by
    answer ``ev`` stamped ``ns`` (its ``semantics``; ``entry``: its margin noted withdrawable, given while
    ``/clock`` was not heard after ``ns``).  Before ``/clock`` passed its simulated deadline (:data:`FAR`) it
    is kept for a ``/clock`` message heard late (:func:`tick`); after, only its margin is."""
    if p.due_ns < FAR:
        if entry is not None:  # its margin reads /clock at the answer, which a later /clock placed before moves
            p.answer_ns, p.held = ns, entry
            mon.awaiting.append(p)
        return
    p.given, p.answer, p.answer_ns, p.semantics, p.held = given, ev, ns, semantics, entry


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
    its first late in every clock: ``undecided``, saying why (kept for a late ``/clock``: :func:`answered`)."""
    undecided(mon, p, _band_why(mon, p, ev, ns))
    answered(mon, p, "undecided", ev, ns)


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
    """What a verdict's reason adds for obligation ``p`` placed in a clock (``""`` for the run's clock), with
    how it was placed when the first ``/clock`` message was heard late (:func:`place_held`)."""
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


__all__ = ["DECLARE", "FAR", "HELD", "answered", "band", "band_late", "drop_records", "hold", "judge_again",
           "margin_ns", "place", "place_held", "reads_clock", "record", "release_held", "tick", "undecided",
           "unsaid_first", "words"]
