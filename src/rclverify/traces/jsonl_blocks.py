"""ROSMonitoring's log read a block of lines at a time, as columns (the offline batch path).

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

Before that, a whole read (:data:`BLOCK_BYTES`, cut after its last
``\\n``) is tried **at once**: one msgspec ``decode_lines``
call into a *flat* struct (the same keys, every value but the topic and
the time a JSON scalar -- string, number, boolean or null --, an array
of scalars, a ROS array field or a window, or an object of scalars, a
``/clock`` line's ``{"sec": S, "nanosec": N}``; the time a number), taken only
when the read has no ``\\r``, every line begins with ``{`` and ends with
``}`` (the bytes around each ``\\n``, found with numpy) and the call gives
one object per line.  Then each line is one object and nothing else, so
each object is the one that line decodes to alone: strings cannot hold a
raw line end (JSON forbids control characters in them, msgspec refuses
them), so every line end lies between two tokens, a ``}`` and a ``{``;
inside an object or an array a ``}`` is followed by ``,``, ``}`` or ``]``,
never by ``{``, so every line end lies between two top-level values and
each line holds one or more of them whole; with as many objects as lines,
each line holds exactly one.
(``decode_lines`` alone is lax: it reads two objects on one line, or one
over two lines; a block read as one JSON array was refused for the same
reason, docs/scale.md.)  The typed decoder reads a scalar, an array's
items or an object's values to the values the untyped one gives (integers
of any size exact; a key given twice, the last).
As on the line-by-line fast path, every time must be a finite ``float``.
Once a read is decoded so, its topics (up to :data:`MAX_TOPICS`, as the
lines spell them) are known to the next reads' decoder, which reads the
topic as one of them (a ``Literal``: the same string, one object per name,
so the topic column's set, counts and codes compare objects, not text); a
line of another topic fails that decoder and the read is decoded with the
topic a string, its topics then known too.
Anything else (an integer time, an object holding an object or an array,
an array of arrays or of objects as a value, a new key, a ``\\r``, bad
bytes, a line msgspec refuses) sends the
read to the line-by-line paths above, which give the same events and the
same located error.  No line is split off
as a ``bytes`` object unless a row's event is asked for.
"""
from __future__ import annotations

import os
from collections import Counter
from operator import attrgetter
from pathlib import Path
from typing import Any, Callable, Hashable, Iterable, Iterator, Literal, Sequence, TypeVar, Union

import msgspec
from rclverify.core.numeric import np

from rclverify.traces.event_time import ASIDE
from rclverify.traces.events import FLAT_STAMPS, Event, taken
from rclverify.traces.jsonl import line_event, read_jsonl, read_lines

#: the flattened stamp keys read by the exact reader: a message's own stamp (its event's ``stamp``) and a
#: stamp a live log set aside in another clock (``header.stamp_aside.*``, traces/event_time.py), whose
#: writer the stamp watch measures from the event (backends/monitors/stamp_order.py)
_STAMP_KEYS = FLAT_STAMPS + tuple(f"header.{ASIDE}." + k.rsplit(".", 1)[1] for k in FLAT_STAMPS)
#: Bytes read from the log at once (a block is cut after its last whole line).
BLOCK_BYTES = 1 << 20
#: The most keys the fast path's struct names (a log with more distinct keys reads the rest exactly).
MAX_KEYS = 64
#: The most topics the flat read decodes as ``Literal`` values (the rest as strings, each line its own).
MAX_TOPICS = 256
_TOPIC, _TIME = attrgetter("f0"), attrgetter("f1")
_T = TypeVar("_T")
#: A JSON scalar as the untyped decoder reads it.
_SCALAR = Union[str, float, int, bool, None]
#: A flat line's values (module docstring): a scalar, an array of scalars or an object of scalars (a
#: ``/clock`` line's ``clock``); an array or an object holding an array or an object is refused by the decoder.
_FLAT = Union[str, float, int, bool, None, list[_SCALAR], dict[str, _SCALAR]]


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
    """A struct of the keys seen so far (``f0`` the topic, ``f1`` the time) and its decoders; ``topics``:
    the topics (as the lines spell them) the flat reads have seen so far, which :attr:`decode_known`
    reads as ``Literal`` values (module docstring)."""

    def __init__(self, keys: Sequence[str], topics: Sequence[str] | None = ()) -> None:
        self.keys = list(dict.fromkeys(["topic", "time", *keys]))
        self.attr = {k: f"f{j}" for j, k in enumerate(self.keys)}
        #: ``None``: more than :data:`MAX_TOPICS` seen, every read decoded with the topic a string
        self.topics = None if topics is None else tuple(topics)
        rename = {f"f{j}": k for j, k in enumerate(self.keys)}
        line = msgspec.defstruct("Line", [("f0", str)] + [(f"f{j}", object, None) for j in range(1, len(self.keys))],
                                 rename=rename, forbid_unknown_fields=True, gc=False)
        self.decode = msgspec.json.Decoder(line).decode
        rest = [("f1", Union[float, int])] + [(f"f{j}", _FLAT, None) for j in range(2, len(self.keys))]
        flat = msgspec.defstruct("FlatLine", [("f0", str), *rest], rename=rename, forbid_unknown_fields=True, gc=False)
        self.decode_lines = msgspec.json.Decoder(flat).decode_lines
        #: the flat decoder with the topic one of :attr:`topics` (``None``: none seen yet); a line of
        #: another topic fails it, and the read is decoded by :attr:`decode_lines` instead
        self.decode_known = None if not self.topics else msgspec.json.Decoder(msgspec.defstruct(
            "KnownLine", [("f0", Literal[self.topics]), *rest], rename=rename, forbid_unknown_fields=True,
            gc=False)).decode_lines

    def learn(self, events: list[Event]) -> _Decoder:
        """This decoder, or one that also names the keys of ``events`` (up to :data:`MAX_KEYS`)."""
        seen = dict.fromkeys(self.keys)
        for ev in events:
            seen.update(dict.fromkeys(ev.fields))
        return _Decoder(list(seen), self.topics) if MAX_KEYS >= len(seen) > len(self.keys) else self

    def knowing(self, topics: Iterable[str]) -> _Decoder:
        """This decoder, or one whose :attr:`decode_known` also reads ``topics``; past :data:`MAX_TOPICS`,
        one without it for the rest of the log (a read of an unknown topic would be decoded twice)."""
        if self.topics is None:
            return self
        seen = dict.fromkeys(self.topics)
        seen.update(dict.fromkeys(topics))
        if len(seen) == len(self.topics):
            return self
        return _Decoder(self.keys, list(seen) if len(seen) <= MAX_TOPICS else None)


def _reads(path: Path) -> Iterator[tuple[bytes, int]]:
    """The log's bytes, a read at a time: ``(data, end)``, the read's whole lines ``data[:end]`` (cut after
    its last ``b"\\n"``; the log's end as it is).  From a file that can seek, ``data`` is the read itself,
    the bytes after ``end`` read again by the next read (no copy of the read is made: each would cost as
    much again as the read); from a stream, those bytes are carried to the next read."""
    with path.open("rb", buffering=0) as fh:
        seek = fh.seekable()
        pending: list[bytes | memoryview] = []  # bytes after the last b"\n" read (a line may be longer than a read)
        while True:
            data = fh.read(BLOCK_BYTES)
            if not data:
                break
            cut = data.rfind(b"\n") + 1
            if not cut:
                pending.append(data)
                continue
            tail = data[cut:] if cut < len(data) and not seek else b""
            if cut < len(data) and seek:
                fh.seek(cut - len(data), os.SEEK_CUR)  # the line it cuts is read again, whole, by the next read
            if pending:
                pending.append(memoryview(data)[:cut])  # joined without a copy of its own first
                data = b"".join(pending)
                cut = len(data)
            pending = [tail] if tail else []
            yield data, cut
        if pending:
            data = b"".join(pending)
            yield data, len(data)


def _blocks(path: Path, fields: Sequence[str], rows: int) -> Iterator[LogBlock | list[Event]]:
    dec = _Decoder(fields)
    lineno = index = 0
    for data, cut in _reads(path):
        flat = _flat(path, dec, data, cut, lineno, index, rows)
        if flat is not None:
            blocks, distinct = flat
            dec = dec.knowing(distinct)
            for whole in blocks:
                lineno += len(whole)
                index += len(whole)
                yield whole
            continue
        lines = (data if cut == len(data) else data[:cut]).splitlines(True)
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


def _flat(path: Path, dec: _Decoder, data: bytes, end: int, lineno: int, index: int, rows: int
          ) -> tuple[list[LogBlock], set[str]] | None:
    """The read ``data[:end]`` as blocks of at most ``rows`` lines when it is decoded at once (module docstring),
    with its distinct topics as the lines spell them; else ``None``."""
    if "header" in dec.attr or any(k in dec.attr for k in _STAMP_KEYS) or data[:1] != b"{" or \
            data[end - 1:end] != b"\n" or data.find(b"\r", 0, end) >= 0:
        return None
    read: bytes | memoryview = data if end == len(data) else memoryview(data)[:end]  # (not a copy)
    u = np.frombuffer(read, np.uint8)
    ends = (u == 10).nonzero()[0]  # each line's b"\n"; a "}" before each, a "{" after each but the last
    n = len(ends)
    if not (u[ends - 1] == 125).all() or not (u[ends[:-1] + 1] == 123).all():
        return None
    structs = None
    decode = dec.decode_lines  # the decoder that read ``data``: a released block's rows are decoded again by it
    if dec.decode_known is not None:
        try:
            structs = dec.decode_known(read)
            decode = dec.decode_known
        except Exception:  # noqa: BLE001 - a topic not seen before (or what decode_lines refuses too): read below
            structs = None
    if structs is None:
        try:
            structs = decode(read)
        except Exception:  # noqa: BLE001 - whatever msgspec refuses: the line-by-line paths say what
            return None
    if len(structs) != n:
        return None
    found = list(map(_TIME, structs))
    if list(map(type, found)).count(float) != n:  # an integer time: the exact reader's (its float() is the event's)
        return None
    times = np.fromiter(found, np.float64, n)  # (each a float: converted as np.array converts it)
    if not np.isfinite(times).all():
        return None
    topics, distinct = _topics(structs)
    lines = _Lines(data, ends)
    named = frozenset(t.lstrip("/") for t in distinct)  # every block's topics are among the read's
    return [LogBlock(path, _Slice(lines, a), structs[a:a + rows], dec.attr, topics[a:a + rows], times[a:a + rows],
                     lineno + a, index + a, _Again(decode, read, a, rows), named) for a in range(0, n, rows)], distinct


class _Again:
    """A released block's rows decoded again: the read ``data`` by the decoder that read it (``decode``,
    msgspec's ``decode_lines``: the same values from the same bytes), rows ``start`` to ``start + rows``."""

    __slots__ = ("decode", "data", "start", "rows")

    def __init__(self, decode: Callable[[bytes | memoryview], list[Any]], data: bytes | memoryview, start: int,
                 rows: int) -> None:
        self.decode, self.data, self.start, self.rows = decode, data, start, rows

    def __call__(self) -> list[Any]:
        got: list[Any] = self.decode(self.data)[self.start:self.start + self.rows]
        return got


def _topics(structs: list[Any]) -> tuple[list[str], set[str]]:
    """Each struct's topic, without its leading ``/`` (as the event's), and the distinct topics as the
    lines spell them."""
    topics = list(map(_TOPIC, structs))
    distinct = set(topics)
    if any(t[:1] == "/" for t in distinct):
        strip = {t: t.lstrip("/") for t in distinct}
        topics = list(map(strip.__getitem__, topics))
    return topics, distinct


class _Lines:
    """The lines of a read decoded at once (``ends``: the offset of each one's ``b"\\n"``),
    a line split off only when it is asked for."""

    __slots__ = ("data", "ends")

    def __init__(self, data: bytes, ends: np.ndarray) -> None:
        self.data, self.ends = data, ends

    def line(self, i: int) -> bytes:
        """Line ``i`` (0-based) with its ``b"\\n"``."""
        return self.data[int(self.ends[i - 1]) + 1 if i else 0:int(self.ends[i]) + 1]


class _Slice:
    """The lines of :class:`_Lines` from ``start`` on, indexed as a list."""

    __slots__ = ("lines", "start")

    def __init__(self, lines: _Lines, start: int) -> None:
        self.lines, self.start = lines, start

    def __getitem__(self, i: int) -> bytes:
        return self.lines.line(self.start + i)


def _fast(path: Path, dec: _Decoder, lines: list[bytes], lineno: int, index: int) -> LogBlock | None:
    """The block of ``lines`` when the fast path reads it as the exact one would (module docstring), else ``None``."""
    if "header" in dec.attr or any(k in dec.attr for k in _STAMP_KEYS):
        return None  # a message's own stamp, or one set aside, is read by the exact reader (its event's ``stamp``)
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
    decode = dec.decode
    return LogBlock(path, lines, structs, dec.attr, _topics(structs)[0], column, lineno, index,
                    lambda: list(map(decode, lines)))


class LogBlock:
    """Lines ``lineno + 1 ..`` of a log read by the fast path: rows ``0 ..
    len - 1`` are events ``index ..``.

    ``topics``: each row's topic (leading ``/`` removed, as the event's);
    ``times``: float64 seconds; :meth:`values`: a key's value per row;
    ``block[i]`` / ``block[i:j]``: the row's :class:`Event` (events), made by
    :func:`~.jsonl.line_event` from the row's line the first time it is asked
    for, the same object after that.  Raises :class:`RuntimeError` should
    the exact reader skip a row's line (a defect: the fast path takes only
    lines with a string topic and a finite float time, which it reads).

    :meth:`release` frees the decoded rows (``structs``) once the reader
    that judges the block is done with it: its topics, times, kept columns
    and events stay, and a later :meth:`values` decodes the rows again from
    the lines (``again``: the decoder that read them, so the same values)."""

    __slots__ = ("path", "lines", "structs", "attr", "topics", "times", "lineno", "index", "_made", "_columns", "_codes",
                 "_kept", "_n", "_again", "_named")

    def __init__(self, path: Path, lines: Sequence[bytes] | _Slice, structs: list[Any], attr: dict[str, str], topics: list[str],
                 times: np.ndarray, lineno: int, index: int, again: Callable[[], list[Any]],
                 named: frozenset[str] | None = None) -> None:
        self.path, self.lines, self.attr = path, lines, attr
        #: the rows decoded (``None`` once released: :meth:`values` decodes them again)
        self.structs: list[Any] | None = structs
        self.topics, self.times, self.lineno, self.index = topics, times, lineno, index
        self._n = len(structs)
        self._again = again
        self._made: dict[int, Event] = {}
        #: a key's value at every row (an object column), made when a reader asks for many rows of it
        self._columns: dict[str, np.ndarray] = {}
        self._codes: tuple[np.ndarray, list[str]] | None = None
        self._kept: dict[Hashable, Any] = {}
        #: topics among which every row's is (``topics``' spelling; ``None``: not known, read from ``topics``)
        self._named = named

    def kept(self, key: Hashable, make: Callable[[], _T]) -> _T:
        """``make()``, made the first time ``key`` is asked for and kept with the block after that: a
        column two readers of the block derive alike (the deadline judge and the untimed check's batch
        path read the same fields at the same rows).  ``key`` must name everything ``make`` reads
        besides the block, which does not change."""
        if key in self._kept:
            got: _T = self._kept[key]
            return got
        made = self._kept[key] = make()
        return made

    def __len__(self) -> int:
        return self._n

    def release(self) -> None:
        """Free the decoded rows and the object columns made of them (class docstring): called by the reader
        that judges the block last, once it has (``backends/monitors/batch.py``), so that they are freed while
        the memory they take is still in the processor's cache rather than whenever the last event, question
        or answer kept from the block goes."""
        self.structs = None
        self._columns.clear()

    def topic_counts(self) -> dict[str, int]:
        """Rows per topic (as ``topics`` names them; a topic no row has is not named): a count per topic
        (a log has a few), the last one's the rows the others leave."""
        topics = self.topics
        named = self._named if self._named is not None else set(topics)
        if len(named) > 16:
            return dict(Counter(topics))
        *counted, last = named or ("",)
        counts = {t: c for t in counted if (c := topics.count(t))}
        left = len(topics) - sum(counts.values())
        if left:
            counts[last] = left
        return counts

    def topic_codes(self) -> tuple[np.ndarray, list[str]]:
        """(each row's topic as an index into the list, the distinct topics as ``topics`` names them, in the
        order they first come), made once per block: a reader classifying the rows reads the few names."""
        if self._codes is None:
            topics = self.topics
            names = list(dict.fromkeys(topics))
            index = {t: j for j, t in enumerate(names)}
            if len(names) <= 256:  # one byte a row, made at C speed
                codes: np.ndarray = np.frombuffer(bytes(map(index.__getitem__, topics)), np.uint8)
            else:
                codes = np.fromiter(map(index.__getitem__, topics), np.int64, len(topics))
            self._codes = (codes, names)
        return self._codes

    def values(self, rows: np.ndarray, key: str) -> list[Any]:
        """The value of ``key`` in the messages at ``rows`` (``None`` where a message
        has none, as for ``topic`` and ``time``, which are not message fields)."""
        attr = self.attr.get(key)
        if attr is None or key in ("topic", "time"):
            return [None] * len(rows)
        structs = self.structs
        if structs is None:  # released: decoded again (the same values, from the same lines)
            structs = self.structs = self._again()
        if len(rows) > 1:
            first, last, step = int(rows[0]), int(rows[-1]), int(rows[1] - rows[0])
            if step > 0 and last == first + step * (len(rows) - 1) and bool((np.diff(rows) == step).all()):
                return list(map(attrgetter(attr), structs[first:last + 1:step]))
        col = self._columns.get(attr)
        if col is None:
            if 8 * len(rows) < len(structs):  # a few rows: read alone
                return [getattr(structs[i], attr) for i in rows.tolist()]
            col = self._columns[attr] = np.fromiter(map(attrgetter(attr), structs), dtype=object, count=len(structs))
        picked: list[Any] = col[rows].tolist()  # (an object column gives back the values themselves)
        return picked

    def __getitem__(self, i: Any) -> Any:
        if isinstance(i, slice):
            return [self[j] for j in range(*i.indices(self._n))]
        i = int(i)
        if i < 0:
            i += self._n
        ev = self._made.get(i)
        if ev is None:
            ev = line_event(self.path, self.lineno + i + 1, self.index + i, self.lines[i])
            if ev is None:  # the fast path read a line the exact reader skips: a defect, never a silent gap
                raise RuntimeError(f"{self.path}:{self.lineno + i + 1}: the log's two readers disagree")
            self._made[i] = ev
        return ev


__all__ = ["BLOCK_BYTES", "JsonlLog", "LogBlock", "MAX_KEYS"]
