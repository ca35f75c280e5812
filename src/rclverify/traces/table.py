"""A recorded run held as columns in memory: a topic and a time per message, each topic's fields as arrays.

A run that is already in memory (decoded from a bag by one's own tools, a
numpy recording, a data frame) need not be written out as a log to be
checked: :class:`ColumnTrace` holds it as columns and is an event source
like the log and bag readers of :func:`~rclverify.traces.read_trace`.

* **rows**: message ``i`` has the topic ``topic[i]`` and the time
  ``time[i]`` (float seconds, finite); the rows are the run's messages in
  the order they were observed (the order of a ROSMonitoring log, which is
  the order the monitor judges them in, docs/semantics.md);
* **fields**: per topic, each field's values in that topic's rows, in row
  order (a numpy ``float64`` array, a numpy string array, or any sequence
  of JSON-like values); a topic with no entry has messages with no fields.

Iterated, it gives one :class:`~.events.Event` per row (``where`` is
``NAME: row I``), as the streaming engine reads any trace; a message's
field holds the Python value (a ``float`` for a ``float64`` entry, a
``str`` for a string one).  For the offline batch path
(backends/monitors/batch.py) :meth:`ColumnTrace.blocks` gives the same rows
a block at a time as :class:`ColumnBlock`\\ s, which hand over a field's
values as columns (:meth:`ColumnBlock.typed`) without a Python object per
row, and make a row's event only when it is asked for.  A message's own
header stamp is not held: every row's time is its stamp.
"""
from __future__ import annotations

from typing import Any, Iterator, Mapping, Sequence

from rclverify.core.numeric import np

from rclverify.traces.events import Event


class ColumnTrace:
    """A run as columns (module docstring).

    ``topic``: each row's topic name (a sequence of ``str`` or a numpy string
    array; a leading ``/`` is dropped, as the readers drop it); ``time``: each
    row's time in seconds; ``fields``: topic -> field -> that topic's values,
    one per row of the topic; ``name``: the run's name in each event's
    ``where``; ``names``, when given: the topics' names, and ``topic`` holds
    each row's index into them (integers) instead of a name.  Raises :class:`ValueError` when the lengths disagree, a time
    is not finite, or a field is given for a topic with no rows."""

    def __init__(self, topic: Sequence[str] | np.ndarray, time: Sequence[float] | np.ndarray,
                 fields: Mapping[str, Mapping[str, Sequence[object] | np.ndarray]] | None = None, name: str = "columns",
                 names: Sequence[str] | None = None) -> None:
        if names is None:
            found, codes = np.unique(np.asarray(topic, dtype=str), return_inverse=True)
            names = found.tolist()
        else:  # ``topic`` holds each row's index into ``names``
            codes = np.asarray(topic)
            if codes.dtype.kind not in "iu" or (len(codes) and not 0 <= int(codes.min()) <= int(codes.max())
                                                < len(names)):
                raise ValueError(f"{name}: a topic index is not an index into the {len(names)} names")
            if len(set(names)) != len(names):
                raise ValueError(f"{name}: a topic is named twice")
        self.names: list[str] = [str(t).lstrip("/") for t in names]
        self.codes = codes.astype(np.int64).reshape(-1)
        self.times = np.ascontiguousarray(time, dtype=np.float64).reshape(-1)
        if len(self.times) != len(self.codes):
            raise ValueError(f"{name}: {len(self.codes)} topics but {len(self.times)} times")
        if not np.isfinite(self.times).all():
            raise ValueError(f"{name}: a time is not a finite number of seconds")
        self.name = name
        #: each row's position among its topic's rows
        self.pos = np.zeros(len(self.codes), dtype=np.int64)
        counts = np.bincount(self.codes, minlength=len(self.names))
        for c in range(len(self.names)):
            rows = np.flatnonzero(self.codes == c)
            self.pos[rows] = np.arange(len(rows))
        given = {str(t).lstrip("/"): cols for t, cols in (fields or {}).items()}
        #: per topic code, field -> its column (a float64 or string array, else a list)
        self.columns: list[dict[str, np.ndarray | list[object]]] = []
        for c, t in enumerate(self.names):
            cols = {f: _column(v) for f, v in given.pop(t, {}).items()}
            for f, v in cols.items():
                if len(v) != counts[c]:
                    raise ValueError(f"{name}: topic {t} has {counts[c]} rows but {len(v)} values of {f}")
            self.columns.append(cols)
        if given:
            raise ValueError(f"{name}: fields given for topics with no rows: {', '.join(sorted(given))}")

    def __len__(self) -> int:
        return len(self.codes)

    def __iter__(self) -> Iterator[Event]:
        for a in range(0, len(self), 16384):
            yield from ColumnBlock(self, a, min(len(self), a + 16384))

    def blocks(self, fields: Sequence[str], rows: int) -> Iterator[ColumnBlock]:
        """The rows in blocks of at most ``rows`` (``fields``, the keys a reader asks for, are all held)."""
        step = max(rows, 1)
        return (ColumnBlock(self, a, min(len(self), a + step)) for a in range(0, len(self), step))


def _column(values: Sequence[object] | np.ndarray) -> np.ndarray | list[object]:
    """A field's values as kept: a float64 or string array as given, anything else as a list
    (another array's values as Python numbers, the type a log's message gives: an ``int64``
    array's as ``int``, never a numpy scalar)."""
    if isinstance(values, np.ndarray):
        if values.dtype == np.float64 or values.dtype.kind == "U":
            return values.reshape(-1)
        return values.reshape(-1).tolist()
    return list(values)


class ColumnBlock:
    """Rows ``start .. end - 1`` of a :class:`ColumnTrace`, as the batch path reads a
    block (backends/monitors/rows.py): ``topics`` (names), ``times`` (float64 s),
    :meth:`values` and :meth:`typed` (a field at some rows), ``block[i]`` (events)."""

    __slots__ = ("trace", "start", "end", "topics", "times", "_codes", "_made")

    def __init__(self, trace: ColumnTrace, start: int, end: int) -> None:
        self.trace, self.start, self.end = trace, start, end
        self._codes = trace.codes[start:end]
        self.topics: list[str] = np.array(trace.names, dtype=object)[self._codes].tolist()
        self.times = trace.times[start:end]
        self._made: dict[int, Event] = {}

    def __len__(self) -> int:
        return self.end - self.start

    def _groups(self, rows: np.ndarray) -> Iterator[tuple[np.ndarray, Any]]:
        """(the entries of ``rows`` of one topic, positions in that topic's columns), per topic present."""
        codes = self._codes[rows]
        pos = self.trace.pos[self.start + rows]
        first = int(codes[0]) if len(codes) else 0
        if len(codes) and bool((codes == first).all()):
            yield np.arange(len(rows)), (first, pos)
            return
        for c in np.unique(codes).tolist():
            sel = np.flatnonzero(codes == c)
            yield sel, (c, pos[sel])

    def values(self, rows: np.ndarray, key: str) -> list[Any]:
        """The value of ``key`` in the messages at ``rows`` (``None`` where a message has none)."""
        out: list[Any] = [None] * len(rows)
        for sel, (c, pos) in self._groups(rows):
            col = self.trace.columns[c].get(key)
            if col is None:
                continue
            got = col[pos].tolist() if isinstance(col, np.ndarray) else [col[p] for p in pos.tolist()]
            for j, v in zip(sel.tolist(), got):
                out[j] = v
        return out

    def typed(self, rows: np.ndarray, key: str, kind: str, codes: Mapping[str, int]
              ) -> tuple[np.ndarray, np.ndarray] | None:
        """``key`` at ``rows`` as :func:`~rclverify.targets.columns.column`
        reads it ((mapped, column): a finite float for ``kind`` ``"real"``, an
        enumeration value's code for ``"enum"``), from the arrays themselves;
        ``None`` when a topic's values are not a float64 or string array."""
        n = len(rows)
        good = np.zeros(n, dtype=bool)
        col = np.zeros(n, dtype=np.float64 if kind == "real" else np.int64)
        for sel, (c, pos) in self._groups(rows):
            values = self.trace.columns[c].get(key)
            if values is None:
                continue  # no such field: not mapped (good stays false)
            if not isinstance(values, np.ndarray):
                return None
            got = values[pos]
            if kind == "real" and got.dtype == np.float64:
                col[sel] = got
                good[sel] = np.isfinite(got)
            elif kind == "enum" and got.dtype.kind == "U" and len(got):
                code = np.full(len(got), -1, dtype=np.int64)
                for value, k in codes.items():  # an enumeration has a few values: a comparison each
                    code[got == value] = k
                col[sel] = code
                good[sel] = code >= 0
        return good, col

    def __getitem__(self, i: Any) -> Any:
        if isinstance(i, slice):
            return [self[j] for j in range(*i.indices(len(self)))]
        i = int(i)
        if i < 0:
            i += len(self)
        ev = self._made.get(i)
        if ev is None:
            ev = self._made[i] = self._event(i)
        return ev

    def __iter__(self) -> Iterator[Event]:
        return (self[i] for i in range(len(self)))

    def _event(self, i: int) -> Event:
        t = self.trace
        row = self.start + i
        c, p = int(t.codes[row]), int(t.pos[row])
        fields = {f: (v[p].item() if isinstance(v, np.ndarray) else v[p]) for f, v in t.columns[c].items()}
        return Event(row, float(t.times[row]), t.names[c], fields, f"{t.name}: row {row}")


__all__ = ["ColumnBlock", "ColumnTrace"]
