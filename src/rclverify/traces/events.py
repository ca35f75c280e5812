"""One observed message and the error a bad trace raises."""
from __future__ import annotations

import math
from dataclasses import dataclass
from itertools import islice
from typing import Any, Iterable, Mapping

#: the keys of a header stamp as ROSMonitoring flattens a message (ROS 1, ROS 2)
FLAT_STAMPS = ("header.stamp.secs", "header.stamp.sec")


class TraceError(Exception):
    """A trace that cannot be read; ``str`` is ``file:line: error: ...`` for a
    log, ``file: message N (offset B): error: ...`` for a bag."""


@dataclass(frozen=True, init=False)
class Event:
    """A message as a monitor sees it.

    ``index``  0-based position in the trace;
    ``time``   seconds (float) since the epoch or the recording's start;
    ``topic``  topic name without leading ``/``;
    ``fields`` the message's fields flattened beside the topic, as
               ROSMonitoring sends them (``{"posx": 1.0, "id": 3, ...}``);
    ``where``  where it was read (``log.jsonl:12`` or ``run_bag: message 4``);
    ``stamp``  the message's own time when ``time`` is not it (``None``
               otherwise): a live monitor checks a message that arrives too
               late to be ordered at its clock, but whether it answers an
               input event is decided by when it was stamped;
    ``source`` when the message was published (s: its source time), where
               neither ``time`` nor ``stamp`` is it (``None`` otherwise): a
               message placed at a header stamp older than its publication
               (a stamp copied from an earlier question) may answer the
               questions asked up to then (docs/semantics.md, "Event time");
    ``late``   how long after its time (``stamped``, s) the live monitor heard
               it, where that was later than the lateness bound (0.0
               otherwise): the questions asked before then read a value
               the node may not have had, and decide no violation.
    """

    index: int
    time: float
    topic: str
    fields: Mapping[str, Any]
    where: str
    stamp: float | None = None
    source: float | None = None
    late: float = 0.0

    def __init__(self, index: int, time: float, topic: str, fields: Mapping[str, Any], where: str,
                 stamp: float | None = None, source: float | None = None, late: float = 0.0) -> None:
        # Frozen: each attribute is set once, here, in the instance's dict (the dataclass's own
        # __init__ goes through object.__setattr__ per field, twice as slow, and a run has
        # millions of events)
        d = self.__dict__
        d["index"], d["time"], d["topic"], d["fields"], d["where"], d["stamp"] = index, time, topic, fields, where, stamp
        d["source"] = source
        if late:
            d["late"] = late  # else the class's 0.0: most messages are in order

    @property
    def stamped(self) -> float:
        """The message's own time (s): :attr:`stamp` when set, else :attr:`time`."""
        return self.time if self.stamp is None else self.stamp


def to_ns(seconds: float) -> int:
    """``seconds`` (a finite float or int) as integer nanoseconds, the nearest.

    The whole seconds are split off first, so a stamp near the epoch's
    1.7e9 s keeps its fraction's nanoseconds (``1.7e9 * 1e9`` in doubles is
    off by up to 128 ns).  Deadlines are compared in these integers, never in
    sums of doubles (docs/semantics.md, "Deadlines")."""
    whole = math.floor(seconds)
    return int(whole) * 1_000_000_000 + round((seconds - whole) * 1e9)


def header_stamp(fields: Mapping[str, object]) -> float | None:
    """The message's ``header.stamp`` in seconds, or ``None`` when it has none.

    Accepts a nested header (``{"header": {"stamp": {"secs": 1, "nsecs": 5}}}``,
    ROS 1; ``sec``/``nanosec``, ROS 2), a stamp already in seconds, and
    ROSMonitoring's flattened form (``"header.stamp.secs"``).  A stamp that
    is not a finite non-negative number is ignored (``None``).
    """
    h = fields.get("header")
    stamp: Any = None if h is None else h.get("stamp") if type(h) is dict or isinstance(h, Mapping) else None
    if stamp is None and ("header.stamp.secs" in fields or "header.stamp.sec" in fields):
        stamp = {k.rsplit(".", 1)[1]: v for k, v in fields.items() if k.startswith("header.stamp.")}
    if stamp is None:  # (most messages: typing's isinstance of None costs about a microsecond)
        return None
    if type(stamp) is dict or isinstance(stamp, Mapping):  # a dict first: typing's isinstance is slow
        s = stamp.get("secs", stamp.get("sec"))
        ns = stamp.get("nsecs", stamp.get("nanosec", 0))
        if _num(s) and _num(ns):
            t = float(s) + float(ns) / 1e9
            return t if t > 0 else None  # a zero stamp is ROS's "not set"
        return None
    if _num(stamp) and float(stamp) > 0:
        return float(stamp)
    return None


def header_stamp_ns(fields: Mapping[str, object]) -> int | None:
    """The message's ``header.stamp`` in integer nanoseconds, or ``None`` as for
    :func:`header_stamp`: integer ``secs``/``nsecs`` (ROS 1's ``time``) or
    ``sec``/``nanosec`` (ROS 2's ``builtin_interfaces/Time``) exactly, a stamp
    given in seconds rounded to the nearest nanosecond (:func:`to_ns`)."""
    t = header_stamp(fields)
    if t is None:
        return None
    h = fields.get("header")
    stamp: Any = h.get("stamp") if isinstance(h, Mapping) else None
    if stamp is None:
        stamp = {k.rsplit(".", 1)[1]: v for k, v in fields.items() if k.startswith("header.stamp.")}
    if isinstance(stamp, Mapping):
        s, ns = stamp.get("secs", stamp.get("sec")), stamp.get("nsecs", stamp.get("nanosec", 0))
        if type(s) is int and type(ns) is int:
            return s * 1_000_000_000 + ns
    return to_ns(t)


def _num(x: Any) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def taken(events: Iterable[Event], limit: int | None = None) -> tuple[list[Event], BaseException | None]:
    """The events ``events`` gives (at most ``limit``), and what it raised
    after them (``None`` when nothing): a reader's events before a bad line
    are kept, and its error is raised by the caller after handing them on
    (the log readers, :mod:`.jsonl_blocks` and the batch path's chunks)."""
    got: list[Event] = []
    try:
        got.extend(islice(events, limit))  # what was read stays in the list if the source raises
    except BaseException as exc:  # noqa: BLE001 - handed back to the caller, which raises it
        return got, exc
    return got, None
