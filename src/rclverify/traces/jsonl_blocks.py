"""ROSMonitoring's log read a block of lines at a time, as columns (the offline batch path, issue 51).

:func:`~.jsonl.read_jsonl` makes an :class:`~.events.Event` per line; the
offline batch path (``backends/monitors/batch.py``) needs, for most lines,
only the topic, the time and one field.  :class:`JsonlLog` is what
:func:`~rclverify.traces.read_trace` returns for a log: iterated, it gives
:func:`~.jsonl.read_jsonl`'s events; :meth:`JsonlLog.blocks` gives the same
lines as blocks instead, each either

* a :class:`LogBlock` (the **fast path**): every line decoded at once by
  msgspec into a ``msgspec.Struct`` whose fields are the line's keys
  (``topic`` a string, every other value of any JSON type, read by the same
  decoder as :func:`~.jsonl.read_jsonl`'s first try), with its topics and
  times as columns and an :class:`Event` made only for a row someone asks
  for, by :func:`~.jsonl.line_event` (:func:`~.jsonl.read_lines` on that
  one line); or
* a list of the events :func:`~.jsonl.read_lines` reads from the block's
  lines (the **exact path**), whenever the fast path cannot show that it
  reads the block as :func:`~.jsonl.read_jsonl` would.

A block takes the fast path only when every line decodes into the struct
and no line has a key the struct does not name (``forbid_unknown_fields``:
every byte of the line is then decoded, so what msgspec's untyped decoder
accepts and rejects is what it accepts and rejects), every topic is a
string and every time a finite ``float``; any other block (a blank line,
a key not seen before, an integer or missing time, bytes that are not
UTF-8, ``NaN``, a line msgspec rejects) is read by the exact path, which
gives the same events and raises the same located error after yielding the
events before it.  The keys of an exactly read block join the struct (at
most :data:`MAX_KEYS`) for the next blocks.  Lines are split as the exact
reader splits them: after ``\\n``, and at a bare ``\\r``.
"""
from __future__ import annotations

from operator import attrgetter
from pathlib import Path
from typing import Any, Iterator, Sequence

import msgspec
import numpy as np

from .events import FLAT_STAMPS, Event, taken
from .jsonl import line_event, read_jsonl, read_lines

#: Bytes read from the log at once (a block is cut after its last whole line).
BLOCK_BYTES = 1 << 20
#: The most keys the fast path's struct names (a log with more distinct keys reads the rest exactly).
MAX_KEYS = 64
_TOPIC, _TIME = attrgetter("f0"), attrgetter("f1")


class JsonlLog:
    """The events of the ROSMonitoring log at ``path`` (an iterator, as
    :func:`~.jsonl.read_jsonl`: the file is opened at the first event), or
    its blocks (:meth:`blocks`), one or the other."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self._events: Iterator[Event] | None = None

    def __iter__(self) -> Iterator[Event]:
        if self._events is None:  # the reader's generator itself: a for loop pays no call of ours per event
            self._events = read_jsonl(self.path)
        return self._events

    def __next__(self) -> Event:
        return next(iter(self))

    def blocks(self, fields: Sequence[str], rows: int) -> Iterator[LogBlock | list[Event]] | None:
        """The log's lines in blocks of at most ``rows`` lines: a :class:`LogBlock`
        or a list of events (module docstring); ``fields``: the keys a reader of
        the blocks asks for (:meth:`LogBlock.values`).  ``None`` once events were
        read.  Raises :class:`~.events.TraceError` as :func:`~.jsonl.read_jsonl`,
        after yielding the events before the line (a block of them)."""
        if self._events is not None:
            return None
        self._events = iter(())
        return _blocks(self.path, fields, max(rows, 1))


class _Decoder:
    """A struct of the keys seen so far (``f0`` the topic, ``f1`` the time) and its decoder."""

    def __init__(self, keys: Sequence[str]) -> None:
        self.keys = list(dict.fromkeys(["topic", "time", *keys]))
        self.attr = {k: f"f{j}" for j, k in enumerate(self.keys)}
        line = msgspec.defstruct("Line", [("f0", str)] + [(f"f{j}", object, None) for j in range(1, len(self.keys))],
                                 rename={f"f{j}": k for j, k in enumerate(self.keys)},
                                 forbid_unknown_fields=True, gc=False)
        self.decode = msgspec.json.Decoder(line).decode

    def learn(self, events: list[Event]) -> _Decoder:
        """This decoder, or one that also names the keys of ``events`` (up to :data:`MAX_KEYS`)."""
        seen = dict.fromkeys(self.keys)
        for ev in events:
            seen.update(dict.fromkeys(ev.fields))
        return _Decoder(list(seen)) if MAX_KEYS >= len(seen) > len(self.keys) else self


def _lines(path: Path) -> Iterator[list[bytes]]:
    """The log's lines, some at a time, each with its end (``b"\\n"``, ``b"\\r\\n"``,
    a bare ``b"\\r"``; the last line may have none), as :func:`~.jsonl.read_lines` splits them."""
    with path.open("rb") as fh:
        pending: list[bytes] = []  # a line not ended yet, in pieces (a line may be longer than a read)
        while True:
            data = fh.read1(BLOCK_BYTES)
            if not data:
                break
            if pending and b"\n" not in data and b"\r" not in data:
                pending.append(data)
                continue
            lines = data.splitlines(True)
            if pending:  # the line begun before ends here; a b"\r" before the read's first b"\n" ends it there
                pending.append(lines[0])
                lines[0:1] = b"".join(pending).splitlines(True)
                pending = []
            if lines[-1][-1:] != b"\n":  # not ended, or ended by a b"\r" a b"\n" may follow
                pending.append(lines.pop())
            if lines:
                yield lines
        if pending:
            yield b"".join(pending).splitlines(True)


def _blocks(path: Path, fields: Sequence[str], rows: int) -> Iterator[LogBlock | list[Event]]:
    dec = _Decoder(fields)
    lineno = index = 0
    for lines in _lines(path):
        for at in range(0, len(lines), rows):
            part = lines[at:at + rows] if at or len(lines) > rows else lines
            block = _fast(path, dec, part, lineno, index)
            if block is not None:
                lineno += len(part)
                index += len(part)
                yield block
                continue
            end = [lineno, index]
            got, error = taken(read_lines(path, part, lineno, index, end))
            if got:
                yield got
            if error is not None:
                raise error
            lineno, index = end
            dec = dec.learn(got)


def _fast(path: Path, dec: _Decoder, lines: list[bytes], lineno: int, index: int) -> LogBlock | None:
    """The block of ``lines`` when the fast path reads it as the exact one would (module docstring), else ``None``."""
    if "header" in dec.attr or any(k in dec.attr for k in FLAT_STAMPS):
        return None  # a message's own stamp is read by the exact reader (its event's ``stamp``)
    try:
        structs = list(map(dec.decode, lines))
    except Exception:  # noqa: BLE001 - whatever msgspec refuses (a blank line, a new key, bad bytes, depth): exact path
        return None
    times = list(map(_TIME, structs))
    if set(map(type, times)) != {float}:
        return None
    column = np.array(times, dtype=np.float64)
    if not np.isfinite(column).all():
        return None
    topics = list(map(_TOPIC, structs))
    distinct = set(topics)
    if any(t[:1] == "/" for t in distinct):
        strip = {t: t.lstrip("/") for t in distinct}
        topics = list(map(strip.__getitem__, topics))
    return LogBlock(path, lines, structs, dec.attr, topics, column, lineno, index)


class LogBlock:
    """Lines ``lineno + 1 ..`` of a log read by the fast path: rows ``0 ..
    len - 1`` are events ``index ..``.

    ``topics``: each row's topic (leading ``/`` removed, as the event's);
    ``times``: float64 seconds; :meth:`values`: a key's value per row;
    ``block[i]`` / ``block[i:j]``: the row's :class:`Event` (events), made by
    :func:`~.jsonl.line_event` from the row's line the first time it is asked
    for, the same object after that.  Raises :class:`RuntimeError` should
    the exact reader skip a row's line (a defect: the fast path takes only
    lines with a string topic and a finite float time, which it reads)."""

    __slots__ = ("path", "lines", "structs", "attr", "topics", "times", "lineno", "index", "_made")

    def __init__(self, path: Path, lines: list[bytes], structs: list[Any], attr: dict[str, str], topics: list[str],
                 times: np.ndarray, lineno: int, index: int) -> None:
        self.path, self.lines, self.structs, self.attr = path, lines, structs, attr
        self.topics, self.times, self.lineno, self.index = topics, times, lineno, index
        self._made: dict[int, Event] = {}

    def __len__(self) -> int:
        return len(self.structs)

    def values(self, rows: np.ndarray, key: str) -> list[Any]:
        """The value of ``key`` in the messages at ``rows`` (``None`` where a message
        has none, as for ``topic`` and ``time``, which are not message fields)."""
        attr = self.attr.get(key)
        if attr is None or key in ("topic", "time"):
            return [None] * len(rows)
        structs = self.structs
        if len(rows) > 1:
            first, last, step = int(rows[0]), int(rows[-1]), int(rows[1] - rows[0])
            if step > 0 and last == first + step * (len(rows) - 1) and bool((np.diff(rows) == step).all()):
                return list(map(attrgetter(attr), structs[first:last + 1:step]))
        return [getattr(structs[i], attr) for i in rows.tolist()]

    def __getitem__(self, i: Any) -> Any:
        if isinstance(i, slice):
            return [self[j] for j in range(*i.indices(len(self.structs)))]
        i = int(i)
        if i < 0:
            i += len(self.structs)
        ev = self._made.get(i)
        if ev is None:
            ev = line_event(self.path, self.lineno + i + 1, self.index + i, self.lines[i])
            if ev is None:  # the fast path read a line the exact reader skips: a defect, never a silent gap
                raise RuntimeError(f"{self.path}:{self.lineno + i + 1}: the log's two readers disagree")
            self._made[i] = ev
        return ev


__all__ = ["BLOCK_BYTES", "JsonlLog", "LogBlock", "MAX_KEYS"]
