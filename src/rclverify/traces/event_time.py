"""A message's time on the robot's clock, and the order of a run.

Every path that judges messages (the live sources, the bags and logs they
record, the offline readers) places a message by the time the robot acted
(docs/semantics.md, "Event time"):

* its ``header.stamp`` when it has one (the robot's own statement of when
  the data was taken; a node that copies its input's stamp into its answer
  pairs the two exactly);
* else the **source timestamp** its publisher's middleware wrote when the
  message was published (rmw's ``message_info.source_timestamp`` on the
  rclpy source, the DDS sample's ``source_timestamp`` on Cyclone DDS, the
  time the live monitor recorded in its bag and log);
* else the time the monitor received it (ROS 1, which carries no source
  time; a log with nothing else).

Two messages with equal stamps are ordered by their source times, then by
the order heard: an answer that copies its question's stamp was published
after that question, whichever of the two reached the monitor first.

:func:`event_ns` (:func:`event_s` in seconds) is the rule for one live
sample; :func:`order_key` the key of the one reorder buffer
(:mod:`.reorder`), which every path that orders a run calls.  A message is released for judging only once
no message that could precede it can still arrive: the **watermark** is the
monitor's clock less the lateness bound (``--reorder-window``, seconds), the
event-time watermark of stream processors (Akidau et al., "The Dataflow
Model", VLDB 2015; Basin, Klaedtke and Zalinescu, "Runtime Verification
over Out-of-order Streams", ACM TOCL 2020).  A message heard after the
watermark passed its time is **late**: counted, with the largest lateness.
"""
from __future__ import annotations

from typing import Any, Mapping

from rclverify.traces.events import header_stamp

#: a source time more than this ahead of its receipt (ns) is not the monitor's clock: the receipt stands in
AHEAD_NS = 1_000_000_000


def event_ns(source_ns: int, received_ns: int) -> tuple[int, bool]:
    """``(time, from_source)``: the sample's time on the robot's clock (ns
    since the epoch) and whether it is the publisher's source timestamp.

    ``source_ns`` is the middleware's source timestamp (0 when it gave
    none), ``received_ns`` when the monitor took the sample.  A source time
    later than the receipt by more than :data:`AHEAD_NS` (a publisher whose
    clock runs ahead of the monitor's) cannot be placed on the monitor's
    watermark, so the receipt stands in and ``from_source`` is false; one
    earlier than the receipt is the normal case (the transport's delay)."""
    if source_ns > 0 and source_ns - received_ns <= AHEAD_NS:
        return source_ns, True
    return received_ns, False


def event_s(source: float, received: float) -> float:
    """:func:`event_ns` in seconds: the sample's time on the robot's clock
    (s), its source time ``source`` (s, 0 when none) unless that is more
    than :data:`AHEAD_NS` ahead of its receipt ``received`` (s)."""
    return source if source > 0 and (source - received) * 1e9 <= AHEAD_NS else received


#: a header stamp more than this (s) ahead of its message's source time is on another clock: a node stamps
#: its data before it publishes it, and hosts synchronised to within this bound stamp no later
STAMP_AHEAD_S = 0.1
#: a header stamp more than this (s) behind its message's source time is on another clock: longer than a
#: driver's acquisition-to-publish delay or a relay's processing time when it copies its question's stamp
STAMP_BEHIND_S = 1.0


def other_clock(stamp: float, source: float) -> bool:
    """Whether header stamp ``stamp`` (s) runs in another clock than its
    message's source time ``source`` (s): more than :data:`STAMP_AHEAD_S`
    ahead of it or :data:`STAMP_BEHIND_S` behind it (simulated time beside
    the wall clock, a driver stamping seconds off)."""
    d = stamp - source
    return d > STAMP_AHEAD_S or d < -STAMP_BEHIND_S


def without_stamp(fields: Mapping[str, Any]) -> dict[str, Any]:
    """``fields`` without the header's stamp (nested ``header.stamp`` or
    ROSMonitoring's flattened ``header.stamp.*``), the rest of the header
    kept: the message placed at its source time reads as unstamped to every
    monitor (a stamp in another clock set aside).  The stamp is kept as
    ``header.stamp_aside`` (:data:`ASIDE`; flattened ``header.stamp_aside.*``),
    which no monitor reads as the message's time: the clock of the node that
    stamped it, in which its declared period is judged (:func:`aside_stamp`;
    backends/monitors/periods.py)."""
    out = {k: v for k, v in fields.items() if not k.startswith("header.stamp.")}
    out.update({f"header.{ASIDE}." + k.rsplit(".", 1)[1]: v for k, v in fields.items()
                if k.startswith("header.stamp.")})
    h = out.get("header")
    if isinstance(h, Mapping) and "stamp" in h:
        out["header"] = {**{k: v for k, v in h.items() if k != "stamp"}, ASIDE: h["stamp"]}
    return out


#: the header key a stamp set aside in another clock is kept under (:func:`without_stamp`)
ASIDE = "stamp_aside"


def aside_stamp(fields: Mapping[str, Any]) -> float | None:
    """The header stamp (s) :func:`without_stamp` set aside in ``fields``, or
    ``None`` (no stamp set aside: the message's stamp, if any, is its time)."""
    h = fields.get("header")
    if isinstance(h, Mapping) and ASIDE in h:
        return header_stamp({"header": {"stamp": h[ASIDE]}})
    flat = {k.rsplit(".", 1)[1]: v for k, v in fields.items() if k.startswith(f"header.{ASIDE}.")}
    return header_stamp({"header": {"stamp": flat}}) if flat else None


def with_stamp(fields: Mapping[str, Any], stamp: float) -> dict[str, Any]:
    """``fields`` with the header's stamp (nested ``header.stamp`` or
    ROSMonitoring's flattened ``header.stamp.*``, in the keys the message
    has) made ``stamp`` (s, the run's clock): a stamp in another clock
    carried into the run's clock at the time its message was placed
    (:class:`CopiedStamps`), so a log of the run places it there again.  The
    stamp it replaces is kept as ``header.stamp_aside``, as
    :func:`without_stamp` keeps it (the clock of the node that stamped it: a
    message of a simulated clock that stands still is placed as a copy of
    another writer's stamped alike)."""
    sec = int(stamp)
    ns = min(round((stamp - sec) * 1e9), 999_999_999)
    out = dict(fields)
    h = out.get("header")
    old: Any = h.get("stamp") if isinstance(h, Mapping) else None
    kept: dict[str, Any] = {ASIDE: old} if isinstance(h, Mapping) and ASIDE not in h else {}
    if isinstance(h, Mapping) and isinstance(old, Mapping):
        keys = ("secs", "nsecs") if "secs" in old else ("sec", "nanosec")
        out["header"] = {**h, "stamp": {**old, keys[0]: sec, keys[1]: ns}, **kept}
    elif isinstance(h, Mapping) and old is not None:
        out["header"] = {**h, "stamp": stamp, **kept}
    else:
        flat = [k for k in out if k.startswith("header.stamp.")]
        if not any(k.startswith(f"header.{ASIDE}.") for k in out):
            out.update({f"header.{ASIDE}." + k.rsplit(".", 1)[1]: out[k] for k in flat})
        for k in flat:
            out[k] = sec if k.rsplit(".", 1)[1] in ("sec", "secs") else ns
    return out


def carried(fields: Mapping[str, Any]) -> bool:
    """Whether ``fields`` carry a header stamp :func:`with_stamp` carried into
    the run's clock: a stamp beside a stamp set aside (``header.stamp_aside``,
    nested or flattened), as a live log writes a copy of a stamp in another
    clock at its question's time.  Such a stamp is the run's clock's by
    construction, however long before its message's source time it lies (a
    copy of a paused clock's stamp published over :data:`STAMP_BEHIND_S`
    after the first message so stamped): it is the message's time, never a
    stamp in another clock (:func:`other_clock`) to be set aside again."""
    h = fields.get("header")
    if isinstance(h, Mapping):
        return "stamp" in h and ASIDE in h
    return any(k.startswith("header.stamp.") for k in fields) and any(
        k.startswith(f"header.{ASIDE}.") for k in fields)


#: a header stamp more than this (s) before its message's source time is older than its publication: the
#: message may answer any question asked up to its source time (a stamp copied from an earlier question)
STALE_S = 0.02


def published(stamp: float, source: float) -> float | None:
    """``source`` (s) when a message placed at header stamp ``stamp`` (s) was
    published more than :data:`STALE_S` after it, else ``None``: what an
    event placed at its stamp carries as its ``source``
    (:class:`~rclverify.traces.events.Event`)."""
    return source if source - stamp > STALE_S else None


#: how long (s) a stamp in another clock is kept for a copy of it to name its message (a relay's answer
#: published this long after its question at most)
COPY_S = 60.0
#: a message published within this (s) of another writer's with the same stamp in another clock names it not:
#: two writers stamping one simulated clock's time alike within one of its ticks are heard in either order
#: (the transport skew), so which came first, and so which would be the copy, is not the run's to say
COPY_AFTER_S = 0.02


class CopiedStamps:
    """Places the messages whose header stamps run in another clock
    (:func:`other_clock`).  A message is placed at its source time, unless
    its stamp equals the stamp of an earlier message of another writer in
    that clock: a stamp copied from a question onto an answer, both in the
    clock the two stamps share (simulated time), names that question, so the
    answer is placed at the time its question was placed, its stamp carried
    into the run's clock there (:func:`with_stamp`), and judged, like a
    stale copied stamp in the run's clock, against that question and those
    asked until it was published (docs/semantics.md, "Event time").

    A clock standing still (a paused simulator) gives several messages one
    stamp: a writer's readings, the copies of them, the messages of writers
    stamping with the clock's time.  A stamp heard once before is fresh: a
    message of another writer carrying it copies it (a running clock gives
    two writers one stamp only within one of its ticks, below), and teaches
    that its writer copies the other's stamps.  A stamp heard more than once
    stands still: a message carrying it copies it only when its writer has
    copied two fresh stamps of that writer before (a relay copying a paused
    sensor's readings: placed at the first message so stamped and judged
    against every question asked until it was published, generated seed
    1069); any other is its own writer's, placed at its source time (a
    sensor stamping a paused clock's time, whose readings were all placed
    at another sensor's message: a false deadline and six verdicts live !=
    log, generated seed 1072; relays stamping with their own clock, one
    placed at another's later answer: ``violated``, generated seed 1074).
    A message published within :data:`COPY_AFTER_S` of the one it would
    name is no copy of it: two writers stamping a simulated clock's time
    alike within one tick are heard in either order, and the live run and
    its bag would place them apart (generated seed 1091).  ``copied``
    counts the messages so placed.

    ``reads`` (topic -> the topics its writer reads, from the contracts:
    :func:`rclverify.backends.monitors.node_topics.copy_sources`) settles
    whose stamp a message may copy where the stamps alone cannot: a message
    of a topic ``reads`` names copies a stamp only from a message of a topic
    its writer reads (a sensor copies nothing; a relay copies its input's
    stamp however many other relays copied it before, or a second sensor
    stamped it alike), and is placed at the first such message, judged
    against every question until it was published, whether the stamp stood
    still or not (a relay stamping a paused clock's time, which its input
    stamped too, is judged against every reading it could answer: generated
    seeds 1149, 1178, 1187, where the rule by stamps alone left relays'
    answers at their own times, ``violated``).  A topic ``reads`` does not
    name (no contract writes it) keeps the rule by stamps alone."""

    __slots__ = ("_heard", "_copier", "_by", "reads", "copied")

    def __init__(self, reads: Mapping[str, frozenset[str]] | None = None) -> None:
        #: per stamp, each writer that carried it as its own and the source time (s) it first did, in the
        #: order heard (the first: the stamp's first writer; the stamps too in the order first heard)
        self._by: dict[float, dict[str, float]] = {}
        self.reads: Mapping[str, frozenset[str]] = reads or {}
        #: per stamp, how many messages carried it (2 or more: it stands still)
        self._heard: dict[float, int] = {}
        #: per (writer, the writer whose stamps it copied), how many fresh stamps it copied
        self._copier: dict[tuple[str, str], int] = {}
        self.copied = 0

    def _name(self, topic: str, stamp: float, source: float) -> float | None:
        """The source time (s) of the message of another writer that a
        message of ``topic`` stamped ``stamp`` and published at ``source``
        (s) copies the stamp of (class docstring), counted; else ``None``."""
        by = self._by.get(stamp)
        if not by:
            return None
        reads = self.reads.get(topic)
        if reads is not None:  # whose stamps its writer may copy: the contracts say (class docstring)
            at = min((t for w, t in by.items() if w in reads and w != topic and COPY_AFTER_S < source - t <= COPY_S),
                     default=None)
            if at is not None:
                self.copied += 1
            return at
        writer, at = next(iter(by.items()))  # its first writer
        if writer == topic or not COPY_AFTER_S < source - at <= COPY_S:
            return None
        pair = (topic, writer)
        if self._heard.get(stamp, 0) <= 1:  # fresh: a copy, and its writer a copier of that writer's stamps
            self._copier[pair] = self._copier.get(pair, 0) + 1
        elif self._copier.get(pair, 0) < 2:  # standing still, and its writer no copier of that writer's
            return None
        self.copied += 1
        self._heard[stamp] += 1
        return at

    def place(self, topic: str, stamp: float, source: float) -> tuple[float, bool]:
        """``(time, copied)``: the time (s, the run's clock) a message of
        ``topic`` with header stamp ``stamp`` (s, another clock) and source
        time ``source`` (s) is placed at: the source time of the first message
        of another writer stamped ``stamp`` within :data:`COPY_S` before it
        and more than :data:`COPY_AFTER_S` that it copies (class docstring;
        ``copied`` true), else ``source``."""
        named = self._name(topic, stamp, source)
        if named is not None:
            return named, True
        stamps = self._by
        by = stamps.get(stamp)
        if by is None:
            stamps[stamp] = {topic: source}
            self._heard[stamp] = 1
            while stamps:  # stamps too old to be copied any more are forgotten (insertion order: oldest first)
                k = next(iter(stamps))
                if next(iter(stamps[k].values())) >= source - COPY_S:
                    break
                del stamps[k]
                self._heard.pop(k, None)
        else:
            by.setdefault(topic, source)
            self._heard[stamp] += 1
        return source, False

    def copy_of(self, topic: str, stamp: float, source: float) -> float | None:
        """The time (s, the run's clock) a message of ``topic`` whose header
        stamp ``stamp`` (s) runs in the run's clock by its own offset, with
        source time ``source`` (s), is placed at when that stamp equals the
        stamp in another clock of an earlier message of another writer within
        :data:`COPY_S` before it (and more than :data:`COPY_AFTER_S`) that it
        copies (class docstring): that message's source time (a relay copying
        a driver's stamp 0.3 s ahead and publishing 0.22 s later carries a
        stamp only 0.08 s ahead of its own publication, within the bounds, yet
        copied from its question); ``None`` when it copies none (its stamp
        stands).  Counted in ``copied``."""
        return self._name(topic, stamp, source)


class WriterClocks:
    """Per writer (a topic), the offset between its header stamps and its
    messages' source times, measured: ``offsets[topic] = [lo, hi, n,
    other]`` (the smallest and largest ``stamp - source`` in s, the stamped
    messages seen, how many of them ran in another clock,
    :func:`other_clock`).  :meth:`lines` names each writer with stamps in
    another clock in one line."""

    __slots__ = ("offsets",)

    def __init__(self) -> None:
        self.offsets: dict[str, list[Any]] = {}

    def see(self, topic: str, stamp: float, source: float) -> bool:
        """Note one stamped message of ``topic``; whether its stamp runs in another clock."""
        d = stamp - source
        o = self.offsets.get(topic)
        if o is None:
            o = self.offsets[topic] = [d, d, 0, 0]
        if d < o[0]:
            o[0] = d
        if d > o[1]:
            o[1] = d
        o[2] += 1
        other = other_clock(stamp, source)
        if other:
            o[3] += 1
        return other

    def others(self) -> list[str]:
        """The writers with a stamp in another clock, by name."""
        return sorted(t for t, o in self.offsets.items() if o[3])

    def lines(self, placed: bool) -> list[str]:
        """One line per writer with stamps in another clock: its measured
        offsets and what became of them (``placed``: its messages were put at
        their source times, else they were not related)."""
        out = []
        for t in self.others():
            lo, hi, n, other = self.offsets[t]
            fate = ("placed at their source times, a stamp copied from another writer's at that message's" if placed else
                    "not related to the run's clock")
            out.append(f"/{t}: header stamps {_signed(lo)} to {_signed(hi)} from its source times, another clock "
                       f"({other} of {n} stamped message(s) beyond -{STAMP_BEHIND_S:g} s .. +{STAMP_AHEAD_S:g} s, "
                       f"{fate})")
        return out


def _signed(d: float) -> str:
    """An offset (s) to the millisecond at any size: a simulated clock's stamps lie about the epoch's
    seconds from the wall clock's, and six significant digits made two different offsets read alike."""
    return f"{d:+.3f} s"


def order_key(stamp: float, source: float, seq: int) -> tuple[float, float, int]:
    """The reorder buffers' key: a message's time on the run's clock
    (``stamp``, s: its header stamp, else its event time), then its source
    time (``source``, s: equal stamps in the order they were published),
    then the order heard (``seq``)."""
    return (stamp, source, seq)


__all__ = ["AHEAD_NS", "ASIDE", "aside_stamp", "carried", "STALE_S", "STAMP_AHEAD_S", "published", "STAMP_BEHIND_S", "event_ns", "event_s", "order_key", "other_clock",
           "without_stamp", "WriterClocks"]
