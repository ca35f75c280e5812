"""How late the live monitor heard a recorded message, carried in the bag it recorded.

A live run's log gives each message heard after the lateness bound its
``late_s`` (s: how long after its time it was heard, docs/semantics.md,
"Event time"); a question that read such a value decides no violation.  A
bag written by ``rclverify monitor --live --record`` keeps the same
lateness, so that the bag is judged as the log and the live run were: the
bag's messages carry only their time (rosbag2 has one timestamp per
message), and the lateness of the few late ones goes into the bag's
``metadata.yaml`` under rosbag2's ``custom_data`` (a string-to-string map,
rosbag2 metadata version 6 on; ``ros2 bag`` keeps and ignores keys it does
not know) at :data:`KEY`: a JSON object ``{"/topic": [[time_ns,
late_s], ...]}``, ``time_ns`` the message's time in the bag (ns since the
epoch), ``late_s`` its lateness (s, rounded to 1 µs as the log rounds it).

A bag without the key (any other recorder) has no late message: every
message is judged at its time.
"""
from __future__ import annotations

import bisect
import json
from typing import Any, Mapping, Sequence

#: the ``custom_data`` key of a bag's metadata that holds its late messages (module docstring)
KEY = "rclverify.late_s"

#: how far (ns) a late message's recorded time may be from its time in the bag: the engine holds the time
#: as float seconds since the epoch, exact to about 0.25 µs at today's dates
MATCH_NS = 1000


def encode(late: Mapping[str, Sequence[tuple[float, float]]]) -> str:
    """The :data:`KEY` value of ``late``: topic (without ``/``) -> ``(time_s, late_s)``
    of each late message (s since the epoch, s)."""
    return json.dumps({"/" + t.lstrip("/"): sorted([round(s * 1e9), round(d, 6)] for s, d in xs)
                       for t, xs in sorted(late.items()) if xs}, separators=(",", ":"))


class LateMessages:
    """The late messages of one bag (:func:`of_reader`): :meth:`at` gives a
    message's lateness by its topic and time."""

    __slots__ = ("_by_topic",)

    def __init__(self, by_topic: Mapping[str, list[tuple[int, float]]]) -> None:
        self._by_topic = {t: sorted(xs) for t, xs in by_topic.items() if xs}

    def __bool__(self) -> bool:
        return bool(self._by_topic)

    def at(self, topic: str, time_ns: int) -> float:
        """The lateness (s) of the message of ``topic`` (with its ``/``) at
        ``time_ns`` (ns): the recorded entry of that topic nearest to it
        within :data:`MATCH_NS`, 0.0 (heard in time) without one.  Two
        messages of one topic never share a time to the microsecond (their
        times are their publishers' source timestamps)."""
        xs = self._by_topic.get(topic)
        if xs is None:
            return 0.0
        i = bisect.bisect_left(xs, (time_ns - MATCH_NS, -1.0))
        best, late = MATCH_NS + 1, 0.0
        while i < len(xs) and xs[i][0] <= time_ns + MATCH_NS:
            if abs(xs[i][0] - time_ns) < best:
                best, late = abs(xs[i][0] - time_ns), xs[i][1]
            i += 1
        return late


def decode(text: str | None) -> LateMessages:
    """The late messages a :data:`KEY` value names; nothing for ``None`` or
    a value that is not the object :func:`encode` writes (another tool's
    key of the same name is not read as lateness)."""
    if not text:
        return LateMessages({})
    try:
        obj = json.loads(text)
    except ValueError:
        return LateMessages({})
    out: dict[str, list[tuple[int, float]]] = {}
    if isinstance(obj, dict):
        for topic, xs in obj.items():
            if isinstance(topic, str) and isinstance(xs, list):
                out[topic] = [(x[0], float(x[1])) for x in xs
                              if isinstance(x, list) and len(x) == 2 and type(x[0]) is int
                              and isinstance(x[1], (int, float)) and not isinstance(x[1], bool) and x[1] > 0]
    return LateMessages(out)


def of_reader(reader: Any) -> LateMessages:
    """The late messages of the bag ``reader`` (a ``rosbags`` ``AnyReader``)
    reads (its ROS 2 bag's metadata, which ``rosbags`` 0.11 keeps in the
    reader's directory reader): ``custom_data`` at :data:`KEY`, read once
    and kept on the reader."""
    got = getattr(reader, "_rclverify_late", None)
    if got is None:
        custom = None
        for r in getattr(reader, "readers", ()):  # rosbags' Reader, its directory reader in ``storage``
            for holder in (r, getattr(r, "storage", None)):
                custom = getattr(getattr(holder, "metadata", None), "custom", None)
                if custom:
                    break
            if custom:
                break
        got = decode(custom.get(KEY) if isinstance(custom, dict) else None)
        reader._rclverify_late = got
    return got


__all__ = ["KEY", "LateMessages", "decode", "encode", "of_reader"]
