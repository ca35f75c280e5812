"""One clock per recorded run: the run judged in its messages' stamp order.

Every engine that judges a recorded run (the response engine, the deadline,
period and declaration monitors, a live log's calls) reads one pass over the
run.  A message's time on the run's clock is its ``header.stamp`` when it has
one, else the time the trace gives it (the recording or receipt time): the
deadline monitor's clock (it reads :func:`run_clock`) and the live
monitor's, which releases messages from its reorder buffer in that order
(docs/monitors.md, "Ordering and time").  A bag or a log records messages
in arrival order, and a message may arrive after one stamped later (a
sensor driver stamps at acquisition and publishes after processing; a
question recorded late but stamped early).  Judged in recording order, the
response engine would pair a question with an answer stamped before it and
miss the answer stamped right after it, while the deadline monitor reads the
stamps: two clocks, two answers.

:class:`StampWatch` sees the run's events as they are read (in
:class:`.judged.Counted`, which every offline path has) and counts the
messages stamped more than the transport skew (:mod:`.skew`; the engine
already judges both readings within it) before the latest stamp heard,
keeping the largest such lag.  A run with none was judged on one clock,
unless a message was read after one stamped later by no more than the skew
(``near``, its largest lag): that run is read again in stamp order too, and
says nothing of it, so a bag (each message at its source time, a stamp a few
ms before) is judged as its log (each at its stamp).  A
run with some is read again through :func:`in_stamp_order`: a reorder
buffer whose window is the largest lag the first pass measured releases
every message in stamp order (no later message can be stamped before the
latest stamp heard less that lag), each with its stamp as its time, and
every engine judges that order.  A run that cannot be read again (a FIFO
named on the command line) keeps the first pass's verdicts, which are then
inconclusive with the reason (:func:`stale_reason`): never a silent green,
and never a red judged in an order that is not the run's.

**Two clocks.**  :class:`StampWatch` also measures, per writer (topic),
the offset between its header stamps and its messages' trace times
(:class:`~rclverify.traces.event_time.WriterClocks`; a live monitor's log
and bag record each message's source time).  A stamp more than 0.1 s ahead
of its message's trace time or 1 s behind it runs in another clock (:func:`~rclverify.traces.event_time.other_clock`: simulated
time, a driver stamping seconds off); the run is read again with each such
message placed at its trace time (a stamp copied from another writer's in
that clock at that message's:
:class:`~rclverify.traces.event_time.CopiedStamps`) and its stamp set aside (:class:`Reread`,
:func:`placed_clock`), and the note names each writer in one line with its
measured offsets, as the live engine places and names them
(:mod:`.online`).  A stamp within those bounds is the message's time.

A live monitor's log holds a stamp in another clock already set aside
(``header.stamp_aside``, :func:`~rclverify.traces.event_time.without_stamp`;
a copy of one carried into the run's clock keeps it there too), its message
at its source time: such a message is judged as the log has it (no second
read for it), and its writer's offsets are measured from the stamp set aside
(:attr:`StampWatch.writers`), so the note names it in the one line the live
record and the bag give it (:meth:`StampWatch.named`).
"""
from __future__ import annotations

import math
from typing import Any, Callable, Iterable, Iterator, Mapping

from rclverify.traces.event_time import (ASIDE, CopiedStamps, WriterClocks, aside_stamp, carried, other_clock,
                                         published, with_stamp, without_stamp)
from rclverify.traces.events import Event, header_stamp


#: the keys of a message that may hold a stamp set aside (nested, or flattened as ROSMonitoring's stamps are)
_ASIDE_KEYS = ("header", f"header.{ASIDE}.sec", f"header.{ASIDE}.secs")


def run_clock(ev: Event) -> float:
    """The event's time on the run's clock (s): its ``header.stamp``, else
    the time the trace gives it (module docstring)."""
    s = header_stamp(ev.fields) if ev.fields else None
    return ev.time if s is None else s


class StampWatch:
    """Counts the messages of a run, in the order read, stamped more than
    ``skew`` seconds before the latest stamp already heard (``count``; the
    largest such ``lag`` in seconds; ``first``: where the first was read)."""

    __slots__ = ("skew", "latest", "count", "lag", "first", "stamped", "plain", "clocks", "placed_latest",
                 "placed_lag", "near", "copies", "writers")

    def __init__(self, skew: float, reads: Mapping[str, frozenset[str]] | None = None) -> None:
        self.skew = skew
        self.latest = -math.inf
        self.count = 0
        self.lag = 0.0
        self.first = ""
        #: the smallest and largest header stamp, and trace time of a message without one (s)
        self.stamped = [math.inf, -math.inf]
        self.plain = [math.inf, -math.inf]
        #: per writer, its stamps' offset from its trace times (traces/event_time.py)
        self.clocks = WriterClocks()
        #: the latest time and the largest lag with the stamps in another clock placed at their trace times
        self.placed_latest = -math.inf
        self.placed_lag = 0.0
        #: the largest lag (s) of a message read after one stamped later by no more than the skew
        self.near = 0.0
        #: the stamps in another clock seen, to place a copy of one at its question's time (traces/event_time.py)
        self.copies = CopiedStamps(reads)  # ``reads``: whose stamps a writer may copy (node_topics.copy_sources)
        #: per writer, the offset of the stamp it wrote (a stamp set aside in a live log, else the header stamp)
        #: from its trace times: what the live run measured, whose lines name the writers (:meth:`named`);
        #: ``None`` until a stamp set aside is seen (until then it would hold what :attr:`clocks` holds)
        self.writers: WriterClocks | None = None

    def see(self, ev: Event) -> None:
        """Note event ``ev``'s place on the run's clock."""
        s = header_stamp(ev.fields) if ev.fields else None
        t = ev.time if s is None else s
        span = self.plain if s is None else self.stamped
        f = ev.fields
        # the stamp its writer wrote: set aside (looked for only where a header is: a line's keys are not walked)
        own = aside_stamp(f) if f and any(k in f for k in _ASIDE_KEYS) else None
        writers = self.writers
        if own is not None and writers is None:  # the first set aside: the header stamps seen so far go on
            writers = self.writers = WriterClocks()
            writers.offsets = {k: list(o) for k, o in self.clocks.offsets.items()}
        wrote = s if own is None else own
        if writers is not None and wrote is not None:
            writers.see(ev.topic, wrote, ev.time)
        # a stamp a live log carried into the run's clock (beside its own, set aside) is its time, never another clock
        p = ev.time if s is None else self.copies.place(ev.topic, s, ev.time)[0] if (own is None or not carried(f)) \
            and self.clocks.see(ev.topic, s, ev.time) else _own_or_copied(self.copies, ev.topic, s, ev.time)
        if p >= self.placed_latest:
            self.placed_latest = p
        elif self.placed_latest - p > self.placed_lag:
            self.placed_lag = self.placed_latest - p
        if t < span[0]:
            span[0] = t
        if t > span[1]:
            span[1] = t
        latest = self.latest
        if t >= latest:
            self.latest = t
        elif latest - t <= self.skew:
            self.near = max(self.near, latest - t)
        else:
            self.count += 1
            if latest - t > self.lag:
                self.lag = latest - t
            if not self.first:
                self.first = ev.where

    def see_times(self, times: Any, where: Callable[[int], str]) -> None:
        """Note a columnar block of unstamped messages, ``times`` (a numpy
        array, s) in the order read, as :meth:`see` of each (``where(i)``
        says where row ``i`` was read)."""
        if not len(times):
            return
        from rclverify.core.numeric import np  # deferred: optional or conditional (columnar blocks exist with numpy only)
        heard = np.maximum.accumulate(times)  # the latest time of the block up to each row (its last: the block's)
        self.plain = [min(self.plain[0], float(times.min())), max(self.plain[1], float(heard[-1]))]
        placed = np.maximum(heard, self.placed_latest)
        self.placed_lag = max(self.placed_lag, float((placed - times).max()))
        self.placed_latest = float(placed[-1])
        ahead = np.maximum(heard, self.latest)  # the latest time heard up to each row
        behind = ahead - times
        late = behind > self.skew
        self.near = max(self.near, float(np.where(late, 0.0, behind).max()))
        if late.any():
            self.count += int(late.sum())
            self.lag = max(self.lag, float(behind.max()))
            self.first = self.first or where(int(late.argmax()))
        self.latest = float(ahead[-1])

    def other_clocks(self) -> bool:
        """Whether a header stamp of the run ran in another clock than its
        message's trace time (:func:`~rclverify.traces.event_time.other_clock`)."""
        return bool(self.clocks.others())

    def named(self) -> list[str]:
        """One line per writer whose stamps run in another clock, its
        messages placed at their trace times (:meth:`WriterClocks.lines
        <rclverify.traces.event_time.WriterClocks.lines>`, the live record's
        and the bag's wording): measured from the stamps a live log set aside
        as well as from the header stamps; ``[]`` for a run in one clock."""
        return (self.clocks if self.writers is None else self.writers).lines(True)

    def two_clocks(self) -> bool:
        """Whether the header stamps and the times of the messages without one
        read two clocks: both kinds present, and the gap between their ranges
        longer than a minute and than either range (simulated time in the
        stamps, the wall clock in the recording: no one order of the run)."""
        (s0, s1), (p0, p1) = self.stamped, self.plain
        if s0 > s1 or p0 > p1:
            return False
        gap = max(p0 - s1, s0 - p1)
        return gap > max(60.0, s1 - s0, p1 - p0)

    def note(self) -> str:
        """``""`` for a run read in stamp order, else the sentence saying how it was judged."""
        if not self.count:
            return ""
        return (f"judged in stamp order: {self.count} message(s) were recorded after one stamped up to "
                f"{self.lag * 1e3:.1f} ms later (the first at {self.first}; transport skew {self.skew * 1e3:g} ms)")


class Reread(float):
    """The window (s) of a second read in stamp order, and whether the stamps
    in another clock are ``placed`` at their messages' trace times in it
    (:meth:`StampWatch.other_clocks`)."""

    placed: bool

    def __new__(cls, value: float, placed: bool = False) -> Reread:
        self = super().__new__(cls, value)
        self.placed = placed
        return self


def placed_clock(ev: Event, copies: CopiedStamps | None = None) -> tuple[float, str]:
    """``(time, how)``: the event's time on the run's clock when stamps in
    another clock are placed at their trace times, and how its stamp was
    placed: ``""`` (its own time), ``"aside"`` (set aside: the message is
    then judged as unstamped) or ``"copied"`` (a stamp copied from another
    writer's in that clock, whether or not the copy's own offset is within
    the bounds, through ``copies``:
    :class:`~rclverify.traces.event_time.CopiedStamps`; carried into the
    run's clock at that message's time)."""
    s = header_stamp(ev.fields) if ev.fields else None
    if s is None:
        return ev.time, ""
    if other_clock(s, ev.time) and not carried(ev.fields):  # a stamp a live log carried is the run's clock's
        if copies is None:
            return ev.time, "aside"
        t, copied = copies.place(ev.topic, s, ev.time)
        return t, "copied" if copied else "aside"
    at = None if copies is None else copies.copy_of(ev.topic, s, ev.time)
    return (s, "") if at is None else (at, "copied")


def _own_or_copied(copies: CopiedStamps, topic: str, stamp: float, time: float) -> float:
    """A stamp in the run's clock (s), or, a copy of a stamp set aside in another clock, its question's time
    (:meth:`~rclverify.traces.event_time.CopiedStamps.copy_of`)."""
    at = copies.copy_of(topic, stamp, time)
    return stamp if at is None else at


def in_stamp_order(events: Iterable[Event], lag: float,
                   reads: Mapping[str, frozenset[str]] | None = None) -> Iterator[Event]:
    """``events`` in the order of their stamps on the run's clock (equal
    stamps by their recorded times, the publishers' source times in a bag
    the live monitor wrote, then in the order read:
    :func:`rclverify.traces.event_time.order_key`), each with that stamp as its ``time`` and its index in
    the new order; ``lag`` (s) is the largest lag a :class:`StampWatch`
    measured on the same run, which bounds what the buffer holds; ``reads``, whose
    stamps a writer may copy, as the first pass had it (:func:`.node_topics.copy_sources`)."""
    from rclverify.traces.reorder import ReorderBuffer  # deferred: start-up (loaded only by a run read again in stamp order)
    buffer: ReorderBuffer[Event] = ReorderBuffer()  # the one reorder buffer (traces/reorder.py)
    latest = -math.inf
    out = 0
    place = isinstance(lag, Reread) and lag.placed
    copies = CopiedStamps(reads)  # as the first pass placed them (StampWatch.see)
    for ev in events:
        if place:
            t, how = placed_clock(ev, copies)
            if how:
                ev = Event(ev.index, ev.time, ev.topic, with_stamp(ev.fields, t) if how == "copied" else
                           without_stamp(ev.fields), ev.where, late=ev.late)
        else:
            t = run_clock(ev)
        latest = max(latest, t)
        buffer.push(t, ev.time, ev)
        for t0, src, e0, _ in buffer.release(latest - lag, strict=True):
            yield _placed(out, t0, src, e0)
            out += 1
    for t0, src, e0, _ in buffer.drain():
        yield _placed(out, t0, src, e0)
        out += 1


def _placed(index: int, t: float, source: float, ev: Event) -> Event:
    """``ev`` as the ``index``-th of the run in stamp order, at its time ``t`` (s);
    published more than :data:`~rclverify.traces.event_time.STALE_S` after it
    (``source``, s), it carries that as its source time (and ``t`` as its
    stamp: it is judged by the streaming engine, which reads both)."""
    src = published(t, source)
    if src is None:
        return Event(index, t, ev.topic, ev.fields, ev.where, late=ev.late)
    return Event(index, t, ev.topic, ev.fields, ev.where, t, src, ev.late)


def stale_reason(watch: StampWatch, trace: str) -> str:
    """Why the first pass's verdicts are not given: the run cannot be read
    again in stamp order (a stream), or its stamps and its other messages'
    times read two clocks (:meth:`StampWatch.two_clocks`)."""
    late = (f"{watch.count} message(s) were recorded after one stamped up to {watch.lag * 1e3:.1f} ms later (the "
            f"first at {watch.first})")
    if watch.other_clocks():
        return (f"{trace} reads two clocks: " + "; ".join(watch.clocks.lines(False)) + f", and it cannot be read a "
                "second time to place them (a stream): no one order of the run decides which question an answer "
                "answers")
    if watch.two_clocks():
        (s0, s1), (p0, p1) = watch.stamped, watch.plain
        return (f"{trace} reads two clocks: header stamps from {s0:.3f} s to {s1:.3f} s, the messages without one "
                f"from {p0:.3f} s to {p1:.3f} s (simulated time beside the wall clock?), and {late}: no one order "
                "of the run decides which question an answer answers")
    return (f"{trace} cannot be read a second time in stamp order (a stream): {late}, so the verdicts judged in "
            "recording order may not hold on the run's clock")


def second_read(watch: StampWatch, trace: str, readable: bool) -> tuple[float | None, str, str]:
    """After a first read that ``watch`` saw: ``(lag, note, stale)``.  ``lag``
    is the window to read the run again in stamp order with (``None``: no
    second read), ``note`` says so for the evidence, ``stale`` is why the
    first read's greens are not given (two clocks, or a run that cannot be
    read again: ``readable`` false); all empty for a run read in stamp order.
    ``note`` names each writer in another clock (:meth:`StampWatch.named`),
    also when its stamps were set aside in a live log and nothing is read
    again for them."""
    lag, note, stale = _second_read(watch, trace, readable)
    named = "" if watch.other_clocks() else "; ".join(watch.named())  # set aside in a log: placed already
    return lag, "; ".join(x for x in (named, note) if x), stale


def _second_read(watch: StampWatch, trace: str, readable: bool) -> tuple[float | None, str, str]:
    """:func:`second_read` of the header stamps alone (a stamp set aside is not the message's time)."""
    if watch.other_clocks():  # writers in another clock: read again with their stamps placed (module docstring)
        if not readable:
            return None, "", stale_reason(watch, trace)
        note = "; ".join(watch.named())
        if watch.placed_lag:
            note += (f"; judged in stamp order with those stamps placed (a lag of up to "
                     f"{watch.placed_lag * 1e3:.1f} ms)")
        return Reread(watch.placed_lag, placed=True), note, ""
    if not watch.count:  # read out of stamp order within the skew only: read again in stamp order, said nowhere
        return (watch.near, "", "") if watch.near and readable and not watch.two_clocks() else (None, "", "")
    if watch.two_clocks() or not readable:
        return None, "", stale_reason(watch, trace)
    return watch.lag, watch.note(), ""


def unless_stale(status: tuple[str, str], stale: str) -> tuple[str, str]:
    """``(status, explanation)``, or ``inconclusive`` with ``stale`` (the reason)
    where it would otherwise be ``discharged``, ``pending``, ``failed`` or
    ``inconclusive`` for another reason: a run judged in an order that is
    not its clock's gives no verdict either way (a violation there may be
    the order's, docs/semantics.md "Event time"), and says why."""
    if stale and status[0] in ("discharged", "pending", "failed", "inconclusive"):
        return "inconclusive", f"{stale}; in recording order: {status[1]}"
    return status


__all__ = ["Reread", "StampWatch", "in_stamp_order", "placed_clock", "run_clock", "second_read", "stale_reason",
           "unless_stale"]
