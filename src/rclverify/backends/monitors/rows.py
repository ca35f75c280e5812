"""A chunk of a recorded run as the offline batch path reads it: columns, and the events on demand.

The batch path (:mod:`.batch`) judges a trace a chunk at a time.  A chunk is
either a list of :class:`~rclverify.traces.events.Event` (any event source:
:class:`EventRows`) or a block of a ROSMonitoring log read as columns
(:class:`~rclverify.traces.jsonl_blocks.LogBlock`, :class:`BlockRows`),
each after the events carried over from the chunk before.  Both give the
same things: the topics, the times (float64 seconds), which events carry a
stamp of their own, one field's values at some rows (``None`` where a
message has none), and ``rows[i]`` / ``rows[i:j]``, the events themselves
(a log block makes an event only when it is asked for).

:func:`chunks` cuts an event source, or a log's blocks (``blocks()``,
:class:`~rclverify.traces.jsonl_blocks.JsonlLog`), into these chunks.
"""
from __future__ import annotations

from itertools import repeat
from operator import attrgetter, is_
from typing import Any, Iterable, Iterator, Mapping, Sequence

from rclverify.core.numeric import np

from rclverify.traces.events import Event, taken
from rclverify.targets.columns import column, field_values

_TOPIC, _TIME, _STAMP, _FIELDS = attrgetter("topic"), attrgetter("time"), attrgetter("stamp"), attrgetter("fields")


class EventRows:
    """A list of events as a chunk (module docstring)."""

    __slots__ = ("events", "topics", "times", "_fields")

    def __init__(self, events: list[Event]) -> None:
        self.events = events
        self._fields: list[Any] | None = None
        self.topics: list[str] = list(map(_TOPIC, events))
        self.times: np.ndarray = np.fromiter(map(_TIME, events), np.float64, len(events))

    def __len__(self) -> int:
        return len(self.events)

    def __getitem__(self, i: Any) -> Any:
        return self.events[i]

    def unstamped(self) -> np.ndarray | None:
        """Per row, whether the event has no stamp of its own; ``None`` when none has."""
        stamps = list(map(_STAMP, self.events))
        if stamps.count(None) == len(stamps):
            return None
        return np.fromiter(map(is_, stamps, repeat(None)), bool, len(stamps))

    def values(self, rows: np.ndarray, field: str) -> list[Any]:
        """Field ``field`` of the messages at ``rows`` (``None`` where one has none)."""
        if self._fields is None:
            self._fields = list(map(_FIELDS, self.events))
        return field_values(self._fields, rows, field)

    def typed(self, rows: np.ndarray, field: str, kind: str, codes: Mapping[str, int]) -> tuple[np.ndarray, np.ndarray]:
        """Field ``field`` at ``rows`` as :func:`~.columns.column` reads it: (mapped, column)."""
        return column(self.values(rows, field), kind, codes)

    @property
    def last_time(self) -> float:
        """The last event's time."""
        return self.events[-1].time


class BlockRows:
    """The events ``head`` carried over, then a log block (module docstring)."""

    __slots__ = ("head", "block", "_topics", "times")

    def __init__(self, head: list[Event], block: Any) -> None:
        self.head, self.block = head, block
        self._topics: list[str] | None = None
        if head:
            self.times = np.concatenate([np.fromiter(map(_TIME, head), np.float64, len(head)), block.times])
        else:
            self.times = block.times

    @property
    def topics(self) -> list[str]:
        """Each row's topic (made when first asked for: :meth:`kinds` reads a block's topic codes instead)."""
        if self._topics is None:
            self._topics = list(map(_TOPIC, self.head)) + self.block.topics if self.head else self.block.topics
        return self._topics

    def kinds(self, table: Mapping[str, int]) -> np.ndarray | None:
        """Each row's topic mapped through ``table`` (0 for a topic it does not name) as int8, from
        the block's topic codes (``topic_codes``: no string a row); ``None`` for a block without them."""
        codes = getattr(self.block, "topic_codes", None)
        if codes is None:
            return None
        at, names = codes()
        lut = np.array([table.get(t, 0) for t in names] or [0], dtype=np.int8)
        kind: np.ndarray = lut[at]
        if self.head:
            kind = np.concatenate([np.array([table.get(ev.topic, 0) for ev in self.head], dtype=np.int8), kind])
        return kind

    def __len__(self) -> int:
        return len(self.head) + len(self.block)

    def __getitem__(self, i: Any) -> Any:
        h = len(self.head)
        if isinstance(i, slice):
            return [self[j] for j in range(*i.indices(h + len(self.block)))]
        i = int(i)
        if i < 0:
            i += h + len(self.block)
        return self.head[i] if i < h else self.block[i - h]

    def unstamped(self) -> np.ndarray | None:
        """As :meth:`EventRows.unstamped` (a log's messages have no stamp of their own)."""
        if all(ev.stamp is None for ev in self.head):
            return None
        return np.array([ev.stamp is None for ev in self.head] + [True] * len(self.block), dtype=bool)

    def values(self, rows: np.ndarray, field: str) -> list[Any]:
        """As :meth:`EventRows.values`."""
        h = len(self.head)
        if not h:
            got: list[Any] = self.block.values(rows, field)
            return got
        cut = int(np.searchsorted(rows, h))
        carried = field_values(list(map(_FIELDS, self.head)), rows[:cut], field)
        rest: list[Any] = self.block.values(rows[cut:] - h, field)
        return carried + rest

    def typed(self, rows: np.ndarray, field: str, kind: str, codes: Mapping[str, int]) -> tuple[np.ndarray, np.ndarray]:
        """As :meth:`EventRows.typed`; a block that holds its values as arrays
        (traces/table.py, ``typed``) hands them over without a Python value per row."""
        typed = getattr(self.block, "typed", None)
        h = len(self.head)
        cut = int(np.searchsorted(rows, h)) if h else 0
        got: tuple[np.ndarray, np.ndarray] | None = typed(rows[cut:] - h, field, kind, codes) if typed else None
        if got is None:
            return column(self.values(rows, field), kind, codes)
        if not cut:
            return got
        good, col = column(field_values(list(map(_FIELDS, self.head)), rows[:cut], field), kind, codes)
        return np.concatenate([good, got[0]]), np.concatenate([col, got[1]])

    @property
    def last_time(self) -> float:
        """The last event's time (as its event gives it)."""
        return float(self.times[-1])


def chunks(events: Iterable[Event], size: int, fields: Sequence[str]) -> Iterator[list[Event] | Any]:
    """``events`` in chunks: lists of at most ``size`` events, or, from a log
    that gives blocks, its blocks (:class:`~rclverify.traces.jsonl_blocks.LogBlock`
    or lists of events) of at most ``size`` lines.  What the source raises
    propagates after the chunk of the events read before it was yielded."""
    blocks = getattr(events, "blocks", None)
    if blocks is not None:
        source = blocks(fields, size)
        if source is not None:
            yield from source
            return
    it = iter(events)
    while True:
        got, error = taken(it, size)
        if got:
            yield got
        if error is not None:
            raise error
        if not got:
            return


def rows_of(head: list[Event], chunk: list[Event] | Any) -> EventRows | BlockRows:
    """The chunk after the events ``head`` carried over, as rows."""
    if isinstance(chunk, list):
        return EventRows(head + chunk if head else chunk)
    return BlockRows(head, chunk)


__all__ = ["BlockRows", "EventRows", "chunks", "rows_of"]
