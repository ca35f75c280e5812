"""The online verdict engine: the offline checker fed one message at a time.

:class:`OnlineEngine` wraps one :class:`~.check.NodeMonitor` per node (the
very code :func:`~.check.check_trace` runs over a recorded trace) with what
a running system adds (docs/monitors.md, "Live monitoring"):

* **ordering**: a message is stamped with its ``header.stamp`` when it has
  one (ROS 1 ``secs``/``nsecs``, ROS 2 ``sec``/``nanosec``, nested or
  flattened), else with its event time (the publisher's source timestamp on
  ROS 2, the receipt on ROS 1: :mod:`rclverify.traces.event_time`); messages
  wait in a reorder buffer until the watermark passes them (the clock less
  ``reorder_window`` seconds, the lateness bound, held back by each writer
  that could still send a message stamped before it; where the source names
  each sample's writer and matches each topic's writers, as the ROS 2
  sources do, as far as every matched writer has been heard, earlier than
  the bound: :meth:`OnlineEngine.watermark`) and are
  released to the monitors in stamp order (equal stamps by event time, then
  in arrival order), all held in the one reorder buffer
  (:mod:`rclverify.traces.reorder`).  A message stamped before the
  watermark already reached (or before one already released) is counted in
  ``late`` (the largest lag in ``max_late_s``); one older than a message
  already released arrives too late to be ordered: it is still checked (at
  the current clock, never dropped silently); its own stamp decides what it answers, and
  an input put at its stamp revises what was judged without it, as offline
  (``late.py``, docs/semantics.md "Answers");
* **clocks**: per writer (topic) the offset between its header stamps and
  its source times is measured (:attr:`clocks`); a stamp more than 0.1 s
  ahead of its message's source time or 1 s behind it runs in another
  clock, and its message is placed at its source time (a stamp copied from
  another writer's in that clock at that message's time, its stamp carried
  there: :class:`~rclverify.traces.event_time.CopiedStamps`), its stamp set aside,
  as a recorded run read again is (:mod:`.stamp_order`); :meth:`clock_lines`
  names each such writer;
* **the simulated clock**: ``/clock`` messages (:mod:`rclverify.traces.sim_clock`)
  are ordered with the rest at their source times, their writer held by the
  watermark like a contract topic's, and released to ``on_event`` and
  ``admit`` (no node's monitor reads them): the deadline checks that judge a
  node under ``use_sim_time`` read them there, live as on the run's log;
* **time**: :meth:`tick` (a timer, e.g. every 50 ms) moves every monitor's
  clock to the watermark (``now - reorder_window`` or before it, past it in
  an early release), so an obligation whose horizon (the contract's
  response time) has passed is resolved ``violated`` without waiting for
  the next message;
* **silence**: a contract topic that has not been received for
  ``silence_s`` seconds is reported once by :meth:`tick` (and again when it
  comes back);
* **provisional verdicts**: with a lateness bound, a verdict is final once
  the watermark has passed its time (every writer of the engine heard past
  it, or silent for longer than the bound): what comes later is later than
  the bound, and changes it only to undecided (docs/semantics.md).  The
  verdicts :meth:`finish` gives on messages the watermark had not yet
  passed when the run stopped go to ``on_verdict`` marked ``provisional``
  (:meth:`early`): a message in flight may have been missed.

Memory per node is the monitor's (state, bounded cache, obligations within
the horizon) plus the reorder buffer (messages within the window).
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Callable, Iterable, Mapping, Union

from rclverify.semantics.floatsem import Tolerance
from rclverify.lang.types import Checked, CheckedNode
from rclverify.traces.event_time import CopiedStamps, WriterClocks, published, with_stamp, without_stamp
from rclverify.traces.events import Event, header_stamp, header_stamp_ns
from rclverify.traces.reorder import ReorderBuffer
from rclverify.traces.sim_clock import CLOCK_TOPIC
from rclverify.traces.mapping import TopicRule
from rclverify.backends.monitors.check import NodeMonitor, NodeResult, Verdict
from rclverify.backends.monitors.node_topics import copy_sources


#: a writer not heard yet: (the latest time heard, the most it published after its stamp)
_UNHEARD = (-math.inf, 0.0)

#: a writer's id as a source gives it with each sample (a DDS writer's GUID, an rclpy publisher's GID)
WriterId = Union[bytes, str]
#: what the engine keeps a writer under: the topic alone (a source that names no writer: ROS 1, a
#: recorded run), or ``(topic, writer id)``
WriterKey = Union[str, tuple[str, WriterId]]


def _heard_upto(last: float, lag: float, now: float, window: float) -> float:
    """The time (s, the run's clock) a writer has been heard past at ``now`` (s): the time its last message
    was placed at (``last``), or, once it has been silent for longer than the lateness bound ``window`` on its
    own clock (``lag``: the most it published after its stamp), ``now - window - lag``; the one rule
    :meth:`OnlineEngine.watermark` and a node's ``answers_heard_past`` read."""
    return max(last, now - window - lag)


@dataclass
class TopicStatus:
    """Per contract topic: messages received, last receipt time (s), silent now?"""

    received: int = 0
    last: float | None = None
    silent: bool = False


@dataclass
class OnlineEngine:
    """Every node's monitor, fed message by message.

    ``on_event(Event)`` receives each message as it is released to the
    monitors (in order, before its verdicts); ``on_verdict(Verdict)``
    receives each event's verdict when decided;
    ``on_silence(topic, seconds, silent)`` when a topic goes silent
    (``silent`` True) or comes back (False).  Times are seconds on one clock
    (ROS time live, the trace's clock in a replay).
    """

    checked: Checked
    nodes: Iterable[CheckedNode]
    rules: Mapping[str, TopicRule]
    horizon: float
    reorder_window: float = 0.0
    silence_s: float = 0.0
    on_verdict: Callable[[Verdict], None] | None = None
    on_silence: Callable[[str, float, bool], None] | None = None
    on_event: Callable[[Event], None] | None = None
    #: ``on_late(topic, source, late)``: a message released late (its topic, its time as pushed and its
    #: lateness, s), for what records the run beside the log (the bag: :mod:`rclverify.traces.bag_late`)
    on_late: Callable[[str, float, float], None] | None = None
    #: the declared tolerance of recorded numbers (default: ``rules.tolerance``, see :class:`NodeMonitor`)
    tolerance: Tolerance | None = None
    #: topics no contract maps a variable to that are still ordered with the rest and released to
    #: ``on_event`` and ``admit`` (a managed node's transition events, :mod:`rclverify.runtime.lifecycle`)
    gate_topics: frozenset[str] = frozenset()
    #: ``admit(Event)``: whether a released message goes on to the monitors (after ``on_event``); it sees
    #: every message in the order released, so what it decides is the same live and on the run's log
    admit: Callable[[Event], bool] | None = None
    monitors: list[NodeMonitor] = field(init=False)
    topics: dict[str, TopicStatus] = field(init=False)
    released: int = field(init=False, default=0)
    #: messages a :meth:`tick` released with the watermark past the clock less the bound (early release)
    released_early: int = field(init=False, default=0)
    #: the reorder buffer (traces/reorder.py, the one every path uses): (topic, fields, where) by stamp
    _buffer: ReorderBuffer[tuple[str, Mapping[str, object], str]] = field(init=False, default_factory=ReorderBuffer)
    _readers: dict[str, list[NodeMonitor]] = field(init=False)
    _clock: float = field(init=False, default=-math.inf)
    #: per writer (topic), its header stamps' offset from its source times (traces/event_time.py)
    clocks: WriterClocks = field(init=False, default_factory=WriterClocks)
    #: the stamps in another clock heard, to place a copy of one at its question's time
    copies: CopiedStamps = field(init=False)
    #: per writer (:data:`WriterKey`: its topic, or its topic and id where the source names it): (the
    #: latest time heard on the run's clock, the most it published after its stamp, s): its own
    #: watermark (:meth:`watermark`)
    writers: dict[WriterKey, tuple[float, float]] = field(init=False, default_factory=dict)
    #: per contract topic, the writers heard on it (the keys of :attr:`writers`)
    heard_on: dict[str, list[WriterKey]] = field(init=False, default_factory=dict)
    #: the writers a message of which was placed before their own previous one (stamps copied from two
    #: inputs): never counted past ``now - reorder_window - lag`` while the release is early
    went_back: set[WriterKey] = field(init=False, default_factory=set)
    #: per contract topic, the writers the source matches on it (:meth:`match`); ``None``: not told.
    #: Replaced whole, never changed in place, so a source's thread may hand a new one over at any time
    matched: Mapping[str, frozenset[WriterId]] | None = field(init=False, default=None)
    #: :meth:`_early`'s answer and what it was given: (:attr:`matched`, :attr:`gate_topics`, the bound,
    #: the answer), so the hot path (:meth:`watermark`, :meth:`due`) walks the topics once per matched set
    _early_of: tuple[object, object, float, Mapping[str, frozenset[WriterId]] | None] | None = \
        field(init=False, default=None)
    #: the matched set every writer of which has been heard (:meth:`_unheard`: a writer once heard stays)
    _heard_all: object = field(init=False, default=None)

    #: the watermark (s) the last :meth:`tick` reached: a verdict on a later time given by :meth:`finish` is
    #: provisional (:meth:`early`)
    _upto: float = field(init=False, default=-math.inf)
    #: the clock (s) of the last :meth:`tick`
    _now: float = field(init=False, default=-math.inf)
    #: :meth:`finish` is releasing what the watermark had not passed
    _stopping: bool = field(init=False, default=False)

    def __post_init__(self) -> None:
        self.monitors = [NodeMonitor(self.checked, n, self.rules, self.horizon, self.on_verdict, self.tolerance)
                         for n in self.nodes]
        self.copies = CopiedStamps(copy_sources(self.checked))  # whose stamps a writer may copy: the contracts say
        self.topics = {t: TopicStatus() for m in self.monitors for t in m.topics}
        #: per topic, the monitors that read it: a released message is fed to those only (every monitor's
        #: clock is moved to it first, which is all a message off its topics does to a monitor)
        self._readers = {t: [m for m in self.monitors if t in m.topics] for t in self.topics}
        if self.reorder_window > 0:
            for m in self.monitors:
                m.answers_heard_past = self._heard_past([t for t, vs in m.topics.items() if any(not i for *_, i in vs)])
                if self.on_verdict is not None:
                    m.on_verdict = self._giver(self.on_verdict)

    def early(self, t: float) -> bool:
        """Whether a verdict decided at ``t`` (s, the run's clock) is given
        early: by :meth:`finish`, on a time the watermark of the last
        :meth:`tick` had not passed (the run stopped before every writer was
        heard past ``t`` or silent for longer than the lateness bound).
        Never without a lateness bound (messages judged in the order heard)."""
        return self._stopping and self.reorder_window > 0 and t > self._upto

    def _giver(self, emit: Callable[[Verdict], None]) -> Callable[[Verdict], None]:
        """``emit`` for a node's monitor, marking a verdict :meth:`early` ``provisional``."""
        def give(v: Verdict) -> None:
            emit(dataclasses.replace(v, provisional=True) if not v.provisional and self.early(v.decided_at) else v)
        return give

    def _heard_past(self, answers: list[str]) -> Callable[[float], bool]:
        """Whether every writer of ``answers`` (a node's output topics) has been
        heard past ``t`` (s) at the last :meth:`tick`: a message of it placed at
        ``t`` or later, or silent for longer than the lateness bound on its own
        clock (as :meth:`watermark` counts each writer, :meth:`_held`); a topic no
        writer of which was heard yet has not, nor, where the source matches the
        writers (:meth:`match`), one with a matched writer not heard yet.
        A ``superseded`` given before is provisional (:attr:`NodeMonitor.answers_heard_past`)."""
        writers, heard_on = self.writers, self.heard_on

        def past(t: float) -> bool:
            matched = self._early()
            for topic in answers:
                keys = heard_on.get(topic)
                if not keys:
                    return False
                for key in keys:
                    if self._held(key, self._now, matched is not None) < t:
                        return False
                if matched is not None and self._unheard(matched) \
                        and any((topic, w) not in writers for w in matched[topic]):
                    return False
            return True
        return past

    def match(self, sets: Mapping[str, Iterable[WriterId]]) -> None:
        """The writers a source matches now on each topic (``topic`` with or
        without ``/`` -> the writer ids its samples carry): :attr:`matched`,
        replaced whole (thread safe: a source's discovery thread calls it while
        the engine's thread reads the mapping).  Once every contract topic has a
        writer matched, the watermark is no longer held at the clock less the
        lateness bound (:meth:`watermark`)."""
        self.matched = {t.lstrip("/"): frozenset(ws) for t, ws in sets.items()}

    def _early(self) -> Mapping[str, frozenset[WriterId]] | None:
        """The matched writer sets when the release is early (:meth:`watermark`): a lateness bound, no
        gate topic (their writers are not matched), and every contract topic with a writer matched;
        else ``None``.  Worked out once per matched set (:attr:`_early_of`)."""
        matched, gates, window = self.matched, self.gate_topics, self.reorder_window
        of = self._early_of
        if of is not None and of[0] is matched and of[1] is gates and of[2] == window:
            return of[3]
        early = None if matched is None or gates or window <= 0 \
            or any(not matched.get(topic) for topic in self.topics) else matched
        self._early_of = (matched, gates, window, early)
        return early

    def _unheard(self, matched: Mapping[str, frozenset[WriterId]]) -> bool:
        """Whether a writer ``matched`` on a contract topic, or on ``/clock``, has not been heard yet; once
        every one has, remembered for that set (:attr:`_heard_all`: :attr:`writers` only grows)."""
        if self._heard_all is matched:
            return False
        writers = self.writers
        if any((topic, w) not in writers for topic in (*self.topics, CLOCK_TOPIC) for w in matched.get(topic, ())):
            return True
        self._heard_all = matched
        return False

    def _held(self, key: WriterKey, now: float, early: bool) -> float:
        """The time (s) writer ``key`` (heard) has been heard past at ``now`` (s): :func:`_heard_upto`,
        but, in an early release, ``now`` less the bound less its lag for a writer that went back."""
        last, lag = self.writers[key]
        if early and key in self.went_back:
            return now - self.reorder_window - lag
        return _heard_upto(last, lag, now, self.reorder_window)

    # -- input -------------------------------------------------------------------
    def push(self, topic: str, fields: Mapping[str, object], received: float, where: str = "",
             writer: WriterId | None = None) -> None:
        """One message as heard: ``topic`` (with or without ``/``), its fields,
        its event time (s: the publisher's source timestamp where the source
        gives one, else the receipt; :mod:`rclverify.traces.event_time`), where it
        is (for the verdicts; default ``message N``) and its ``writer``'s id where
        the source names it (``None``: the topic is its writer).
        Ordered by its header stamp when it has one, else by that time; equal
        stamps by that time, then in the order heard."""
        topic = topic.lstrip("/")
        status = self.topics.get(topic)
        if status is None:
            if topic == CLOCK_TOPIC:  # the run's simulated clock: a writer the watermark waits for, no monitor's
                self._heard(topic, writer, received, received)
                self._buffer.push(received, received, (topic, fields, where))
            elif topic in self.gate_topics:  # ordered with the rest for the gate, no writer of the contracts
                self._buffer.push(received, received, (topic, fields, where))
            else:
                return  # no contract names it
            if self.reorder_window <= 0:
                self._release(math.inf)
            return
        status.received += 1
        status.last = received if status.last is None else max(status.last, received)
        if status.silent:
            status.silent = False
            if self.on_silence is not None:
                self.on_silence(topic, 0.0, False)
        stamp = header_stamp(fields)
        if stamp is not None and self.clocks.see(topic, stamp, received):
            # another clock: placed at its source time, a copied stamp at its question's (traces/event_time.py)
            stamp, copied = self.copies.place(topic, stamp, received)
            fields = with_stamp(fields, stamp) if copied else without_stamp(fields)
        elif stamp is not None:
            at = self.copies.copy_of(topic, stamp, received)
            if at is not None:  # a copy of a stamp set aside in another clock: at its question's time (event_time.py)
                stamp, fields = at, with_stamp(fields, at)
        t = received if stamp is None else stamp
        self._heard(topic, writer, t, received)
        self._buffer.push(t, received, (topic, fields, where))
        if self.reorder_window <= 0:
            self._release(math.inf)

    def _heard(self, topic: str, writer: WriterId | None, t: float, received: float) -> None:
        """Writer ``writer`` of ``topic`` (``None``: the topic is its writer) heard with a message placed at
        ``t`` and published at ``received`` (s): its own watermark (:attr:`writers`) moves."""
        key: WriterKey = topic if writer is None else (topic, writer)
        heard = self.writers.get(key)
        if heard is None:
            self.heard_on.setdefault(topic, []).append(key)
            heard = _UNHEARD
        last, lag = heard
        if t < last:  # placed before its own previous message: never counted past its bound again (_held)
            self.went_back.add(key)
        after = received - t  # how long after its stamp it was published, at most the horizon
        if self.horizon < after:
            after = self.horizon
        self.writers[key] = (t if t > last else last, after if after > lag else lag)

    def due(self) -> float:
        """When (s, on the engine's clock) the earliest buffered message is
        released if no other message comes: when the watermark reaches it
        (:meth:`watermark`), its time plus the reorder window plus the lag of
        the writers not heard past it; ``-inf`` when an early release has it
        due already (every writer heard past it), ``inf`` with nothing
        buffered.  The live worker ticks then, so a verdict waits the lateness
        bound and not a timer period more."""
        head = self._buffer.head()
        if head == math.inf:
            return head
        matched = self._early()
        # the most any writer not yet heard past it published after its stamp; without an early release the
        # clock less the bound holds it anyway (0)
        most = 0.0 if matched is None else -math.inf
        back = self.went_back if matched is not None else ()
        writers = self.writers
        for key, (last, lag) in writers.items():
            if (last < head or key in back) and lag > most:
                most = lag
        if matched is not None and most < 0 and self._unheard(matched):
            most = 0.0  # a matched writer not heard yet: held at the clock less the bound
        return head + self.reorder_window + most

    def watermark(self, now: float) -> float:
        """The time (s, the run's clock) up to which every writer has been
        heard at ``now`` (s) (docs/semantics.md, "Event time").  A writer (the
        topic, or the topic and the writer's id where the source gives one) is
        past time ``T`` when a message of it was placed at ``T`` or later, or
        when it has been silent for longer than the lateness bound on its own
        clock: ``now`` less the most it published after its stamp (a node
        copying its question's stamp onto an answer it publishes later, capped
        at the horizon) less the bound.

        * **Early release**, where the source matches the writers (:meth:`match`)
          and every contract topic has one (:meth:`_early`): the least time
          every matched and every heard writer is past.  A matched writer not
          heard yet is past ``now`` less the bound; one whose message was once
          placed before its own previous one (it copies the stamps of two
          inputs) is past ``now`` less the bound less its lag, never more.
        * **Otherwise** (no writer matched on some topic, a ROS 1 or recorded
          run, gate topics): the clock less the lateness bound, and no further
          than any writer heard whose message could still come stamped before it.

        A writer not heard yet (not matched either) holds nothing: its first
        message, when it comes after the watermark passed its stamp, is a late
        message."""
        window = self.reorder_window
        bound = now - window
        matched = self._early()
        if matched is None:
            upto = bound
            for last, lag in self.writers.values():
                if last < upto:
                    upto = min(upto, _heard_upto(last, lag, now, window))
            return upto
        upto = math.inf
        writers, back = self.writers, self.went_back
        for key, (last, lag) in writers.items():
            held = bound - lag if key in back else _heard_upto(last, lag, now, window)
            if held < upto:
                upto = held
        if upto > bound and self._unheard(matched):
            upto = bound  # a matched writer not heard yet
        return upto

    def tick(self, now: float) -> float:
        """The timer: release the messages every writer has been heard past
        (:meth:`watermark`), resolve obligations whose horizon has passed,
        report silent topics.  Returns the watermark (s) it released up to:
        what else runs on the engine's clock advances to it, not to a
        :meth:`watermark` read again (a source's thread may hand a matched set
        over in between, :meth:`match`, and move it past what was released)."""
        upto = self.watermark(now)
        self._upto = max(self._upto, upto)
        if now > self._now:
            self._now = now
        before = self.released
        self._release(upto)
        if upto > now - self.reorder_window:
            self.released_early += self.released - before
        for m in self.monitors:
            m.advance(max(self._clock, upto))
        if self.silence_s > 0:
            for topic, st in self.topics.items():
                if st.last is not None and not st.silent and now - st.last > self.silence_s:
                    st.silent = True
                    if self.on_silence is not None:
                        self.on_silence(topic, now - st.last, True)
        return upto

    @property
    def late(self) -> int:
        """How many messages were released after one stamped later (the buffer's count)."""
        return self._buffer.late

    @property
    def max_late_s(self) -> float:
        """The largest lateness (s) of a late message."""
        return self._buffer.max_late_s

    def _release(self, upto: float) -> None:
        monitors, readers = self.monitors, self._readers
        for t, src, (topic, fields, where), late in self._buffer.release(upto):
            stamp = None
            source = published(t, src)  # published after its stamp: it may answer what was asked until then
            if t < self._clock:  # older than one released: checked at the clock; its own stamp decides what it answers
                stamp, t, source = t, self._clock, src
            elif source is not None:
                stamp = t
            self._clock = t
            if self.reorder_window <= 0:  # no lateness bound, no watermark: judged in the order heard, never late
                late = 0.0
            elif late:  # heard after the watermark had passed it: about that much more than the bound after its time
                late += self.reorder_window
                if self.on_late is not None:
                    self.on_late(topic, src, late)
            ev = Event(self.released, t, topic, fields, where or f"message {self.released}", stamp, source, late)
            self.released += 1
            if self.on_event is not None:
                self.on_event(ev)
            for m in monitors:
                m.advance(t)
            if self.admit is not None and not self.admit(ev):
                continue
            for m in readers.get(topic, ()):
                m.feed(ev)

    def clock_lines(self) -> list[str]:
        """One line per writer whose header stamps ran in another clock than
        its source times (:class:`~rclverify.traces.event_time.WriterClocks`),
        with its measured offsets."""
        return self.clocks.lines(True)

    def finish(self) -> list[NodeResult]:
        """Release what is buffered, close the horizons up to the last message,
        and give each node's result (obligations still within it are ``open``)."""
        self._stopping = True
        self._release(math.inf)
        for m in self.monitors:
            m.advance(self._clock)
        return [m.finish() for m in self.monitors]


__all__ = ["OnlineEngine", "TopicStatus", "header_stamp", "header_stamp_ns"]
