"""Which rows of a batch chunk carry a time of their own that the columns do not hold (:mod:`.batch`).

The batch path judges answer pairs (:mod:`.batch_pairs`) and lone slots
(:mod:`.batch_lone`) from a chunk's times and one field per topic.  A
message may carry two more times the streaming engine reads
(:class:`~rclverify.traces.events.Event`): ``late``, how long after its
time the live monitor heard it where that was later than the lateness
bound (a log line's ``late_s``, a bag's ``rclverify.late_s`` metadata,
traces/bag_late.py), and ``source``, its publication time where a header
stamp placed it earlier.  A question reading a late input decides no
violation, its own or a later one's asked before the message was heard
(docs/semantics.md, "Event time"; closing.py ``_violation``), and a
source time lets an output answer earlier questions (engine_state.py
``_reach``).  Neither is in the columns, so :func:`own_times` names the
rows that carry one: the batch path leaves them, and the pairs they
belong to, to the engine.
"""
from __future__ import annotations

from operator import attrgetter
from typing import Any

from rclverify.core.numeric import np

from rclverify.traces.bag_late import of_reader
from rclverify.backends.monitors.rows import BlockRows, EventRows

_SOURCE, _LATE = attrgetter("source"), attrgetter("late")
#: a log line's lateness key (traces/jsonl.py ``read_lines``: popped from the event's fields into ``late``)
LATE_KEY = "late_s"


def _of_events(events: list[Any]) -> np.ndarray | None:
    """Per event, whether it carries a source time or a lateness; ``None`` when none does."""
    n = len(events)
    sources = list(map(_SOURCE, events))
    if sources.count(None) == n and not any(map(_LATE, events)):  # (two passes at C speed: the common case)
        return None
    return np.fromiter((s is not None or bool(ev.late) for s, ev in zip(sources, events)), bool, n)


def _of_block(block: Any) -> np.ndarray | None:
    """Per row of a log or bag block, whether its message was heard late; ``None`` when none was.  A log
    block holds a ``late_s`` column only where its decoder names the key (traces/jsonl_blocks.py: a line
    with a key the decoder does not name is read exactly, as events); a late row's value is a positive
    float, as the exact reader reads it.  A bag block's lateness is the bag's metadata (traces/bag_late.py)."""
    n = len(block)
    attr = getattr(block, "attr", None)
    if attr is not None:  # a log block (traces/jsonl_blocks.py, LogBlock)
        if LATE_KEY not in attr:
            return None
        got = block.values(np.arange(n), LATE_KEY)
        late = np.fromiter((type(v) is float and v > 0 for v in got), bool, n)
        return late if bool(late.any()) else None
    reader = getattr(block, "reader", None)
    if reader is None:  # a table (traces/table.py): no lateness
        return None
    lates = of_reader(reader)
    if not lates:
        return None
    raw = block.raw  # a bag block (traces/bag_blocks.py, BagBlock): its connections and ns stamps
    late = np.fromiter((lates.at(raw.conns[int(c)].topic, int(t)) > 0 for c, t in zip(raw.code, raw.stamps)),
                       bool, n)
    return late if bool(late.any()) else None


def own_times(chunk: EventRows | BlockRows) -> np.ndarray | None:
    """Per row of ``chunk``, whether its message carries a source time or a lateness of its own (module
    docstring); ``None`` when no row does (the common case, read without an array)."""
    if isinstance(chunk, EventRows):
        return _of_events(chunk.events)
    head = _of_events(chunk.head) if chunk.head else None
    rest = _of_block(chunk.block)
    if head is None and rest is None:
        return None
    return np.concatenate([head if head is not None else np.zeros(len(chunk.head), dtype=bool),
                           rest if rest is not None else np.zeros(len(chunk.block), dtype=bool)])


__all__ = ["LATE_KEY", "own_times"]
