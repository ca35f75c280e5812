"""A ROS 2 bag (sqlite3 or MCAP) read a block of messages at a time, as columns (the offline batch path).

:func:`~.bag.read_bag` decodes every message into a message object, a
dict of its fields and an :class:`~.events.Event`; the offline batch path
(backends/monitors/batch.py) needs, for most messages, only the topic, the
time and one field.  :class:`BagTrace` is what
:func:`~rclverify.traces.read_trace` returns for a bag: iterated, it gives
:func:`~.bag.read_bag`'s events; :meth:`BagTrace.blocks` gives the same
messages, in the same order and with the same bytes (``AnyReader.messages()``'s:
read as raw columns by :mod:`.bag_raw` where it reproduces that order, else
taken from ``rosbags``' reader itself), as :class:`BagBlock`\\ s of at most
``rows`` messages.

A block decodes the ``data`` field of the two message types a batch-path
topic most often carries straight from their CDR bytes, for all the block's
messages of the type at once: ``std_msgs/msg/Float64`` (little-endian CDR,
exactly 12 bytes: the double at offset 4) and ``std_msgs/msg/String``
(little-endian CDR: the length ``L`` at offset 4, then ``L - 1`` bytes of
UTF-8 and the terminating zero, nothing after).  Those are the bytes
``rosbags`` decodes to the same value (a ``float``; a ``str``, strictly
UTF-8), so the column holds what the event would (a block's String
messages are compared as 64-bit words, each distinct one decoded once).
Every other message (of
another type, big-endian, padded, not valid) is decoded at once by
:func:`~.bag.bag_event`, as :func:`~.bag.read_bag` decodes it; one it
cannot decode ends the block: the events before it are given as a list,
then its located :class:`~.events.TraceError` is raised, as the stream
raises it.  A message's event is made on demand by the same
:func:`~.bag.bag_event` (a message decoded here: from its decoded ``data``,
the one field of either type, as :func:`~.bag.bag_event` makes it).  A ROS 1 bag, or a workspace whose own ``.msg``
files redefine either type, is not read in blocks (``blocks`` gives
``None``: the caller reads events).
"""
from __future__ import annotations

import copy
from itertools import islice
from pathlib import Path
from typing import Any, Iterator, Mapping, Sequence

from rclverify.core.numeric import np

from rclverify.traces.bag import bag_event, open_bag, read_bag, typestore
from rclverify.traces.bag_late import of_reader
from rclverify.traces.bag_open import counted_open_error, open_uncounted
from rclverify.traces.bag_raw import RawMessages, from_items, gather, raw_blocks
from rclverify.traces.events import Event, TraceError

FLOAT64, STRING = "std_msgs/msg/Float64", "std_msgs/msg/String"
_WIDE = 64  # a String message longer than this (bytes) is decoded on its own
_DISTINCT = 64  # distinct String messages a block finds by comparison (the others: one at a time)
_MASKS = np.array([(1 << (8 * k)) - 1 for k in range(9)], dtype=np.uint64)  # the low k bytes of a word
_LE = b"\x00\x01"  # CDR little-endian encapsulation (the two bytes rosbags reads; the options after it are not)
_LE_WORD = int.from_bytes(_LE, "little")  # the same two bytes read as a little-endian uint16


class BagTrace:
    """The events of the bag at ``path`` (an iterator, as :func:`~.bag.read_bag`),
    or its blocks (:meth:`blocks`), one or the other."""

    def __init__(self, path: Path, msg_dirs: Sequence[Path] = ()) -> None:
        self.path, self.msg_dirs = path, msg_dirs
        self._events: Iterator[Event] | None = None

    def __iter__(self) -> Iterator[Event]:
        if self._events is None:
            self._events = read_bag(self.path, self.msg_dirs)
        return self._events

    def __next__(self) -> Event:
        return next(iter(self))

    def blocks(self, fields: Sequence[str], rows: int) -> Iterator[BagBlock | list[Event]] | None:
        """The bag's messages in blocks of at most ``rows`` (module docstring); ``None``
        once events were read, or for a bag not read in blocks.  Raises
        :class:`~.events.TraceError` as :func:`~.bag.read_bag`, after yielding the
        events before the message."""
        if self._events is not None:
            return None
        store = typestore(self.msg_dirs)
        from rosbags.typesys import Stores, get_typestore  # deferred: start-up (loads rosbags and more only when called)
        standard = get_typestore(Stores.ROS2_HUMBLE).fielddefs
        if any(store.fielddefs.get(t) != standard[t] for t in (FLOAT64, STRING)):
            return None  # the workspace redefines one: its layout is not the one decoded here
        reader = open_uncounted(self.path, store)  # a sqlite3 bag's messages not counted first (bag_open.py)
        store_asked = store if reader is not None else None
        if reader is None:
            reader = open_bag(self.path, store)
        if not reader.is2:
            reader.close()
            return None
        self._events = iter(())
        return _checked(self.path, _blocks(self.path, reader, max(rows, 1)), store_asked)


def _checked(path: Path, blocks: Iterator[BagBlock | list[Event]], store: Any
             ) -> Iterator[BagBlock | list[Event]]:
    """``blocks``; where a reader opened without counting (``store`` not ``None``) meets an error, the
    error of ``rosbags``' own open of the bag instead when that open fails (traces/bag_open.py)."""
    try:
        yield from blocks
    except TraceError:
        if store is not None and (bad := counted_open_error(path, store)) is not None:
            raise bad from None
        raise


def _blocks(path: Path, reader: Any, rows: int) -> Iterator[BagBlock | list[Event]]:
    index = 0
    # the blocks make their events on demand, also after the last block closed the reader (which then empties
    # its type store): a shallow copy keeps the open reader's type store and decodes as read_bag's reader does
    decoder = copy.copy(reader)
    memo: dict[bytes, Any] = {}
    try:
        source = raw_blocks(reader, rows)  # rosbags' order without its generators (bag_raw.py), when it applies
        if source is None:
            source = _items(reader, rows)
        while True:
            try:
                got = next(source)
            except StopIteration:
                return
            except Exception as exc:  # noqa: BLE001 - read_bag's located error, after the messages before it
                raise TraceError(f"{path}: message {index}: error: cannot read the bag "
                                 f"(truncated?): {exc}") from None
            block, bad = BagBlock.make(path, decoder, got, index, memo)
            if bad is not None:  # the events before a message that cannot be decoded, then its error
                if block:
                    yield block
                raise bad
            yield block
            index += len(got)
    finally:
        try:
            reader.close()
        except Exception:  # noqa: BLE001 - as read_bag: closing never hides the run's own error
            pass


def _items(reader: Any, rows: int) -> Iterator[RawMessages]:
    """``AnyReader.messages()`` in blocks of at most ``rows``; what it raises, after the block before it."""
    messages = reader.messages()
    while True:
        got: list[tuple[Any, int, bytes]] = []
        try:
            got.extend(islice(messages, rows))  # what was read stays in the list if the reader raises
        except Exception:
            if got:
                yield from_items(got)
            raise
        if got:
            yield from_items(got)
        if len(got) < rows:
            return


class BagBlock:
    """Messages ``index ..`` of a bag as columns (module docstring): ``topics``, ``times``
    (float64 s, the recording's stamps), :meth:`values`, :meth:`typed`, ``block[i]`` (events)."""

    __slots__ = ("path", "reader", "raw", "index", "_topics", "times", "_made", "_floats", "_is_float",
                 "_which", "_texts", "_is_str")

    def __init__(self, path: Path, reader: Any, raw: RawMessages, index: int) -> None:
        self.path, self.reader, self.raw, self.index = path, reader, raw, index
        self._made: dict[int, Event] = {}
        n = len(raw)
        self._topics: list[str] | None = None
        self.times = raw.stamps / 1e9  # as stamp / 1e9, per message
        self._floats = np.zeros(n, dtype=np.float64)
        self._is_float = np.zeros(n, dtype=bool)
        self._is_str = np.zeros(n, dtype=bool)
        self._which = np.full(n, -1, dtype=np.int64)  # a String row's text: ``_texts[_which[i]]``
        self._texts: list[str] = []

    @classmethod
    def make(cls, path: Path, reader: Any, raw: RawMessages, index: int,
             memo: dict[bytes, Any]) -> tuple[BagBlock | list[Event], TraceError | None]:
        """The block of the messages ``raw`` (messages ``index ..``), or the events before a
        message that cannot be decoded and its error (module docstring); ``memo``: String bytes
        already decoded (a run's statuses repeat), kept across the blocks."""
        block = cls(path, reader, raw, index)
        kinds = np.array([{FLOAT64: 1, STRING: 2}.get(c.msgtype, 0) for c in raw.conns] or [0], dtype=np.int8)
        code = kinds[raw.code]
        at = np.flatnonzero(code == 1)
        if len(at):
            at = at[raw.stop[at] - raw.start[at] == 12]
            start = raw.start[at]  # the encapsulation's two bytes, two of options (not read), the double
            ok = gather(raw.buf, start, "<u2") == _LE_WORD
            block._floats[at[ok]] = gather(raw.buf, start + 4, "<f8")[ok]
            block._is_float[at[ok]] = True
        at = np.flatnonzero(code == 2)
        if len(at):
            block._decode_strings(at, memo)
        for i in np.flatnonzero(~(block._is_float | block._is_str)).tolist():
            try:  # any other message: decoded now, in order, as the stream decodes it
                block._made[i] = bag_event(reader, path, index + i, *raw.item(i))
            except TraceError as exc:
                return [block[j] for j in range(i)], exc
        return block, None

    def _decode_strings(self, at: np.ndarray, memo: dict[bytes, Any]) -> None:
        """The ``data`` of the String messages at ``at``: each distinct message's bytes
        decoded once (:func:`_string`; ``memo`` across blocks), found by comparing the
        messages as 64-bit words (the bytes after a message's end zeroed)."""
        raw = self.raw
        start, size = raw.start[at], raw.stop[at] - raw.start[at]
        width = -(-int(size.max()) // 8) * 8
        which = np.full(len(at), -1, dtype=np.int64)
        picked: list[bytes] = []
        if width <= _WIDE:
            buf = raw.buf if int((start + width).max()) <= len(raw.buf) else raw.buf + bytes(width)
            # word j of every message (its bytes 8j .. 8j + 7), only the message's own bytes kept
            words = [gather(buf, start + 8 * j, "<u8") & _MASKS[np.clip(size - 8 * j, 0, 8)]
                     for j in range(width // 8)]
            left = np.ones(len(at), dtype=bool)
            first = 0
            while len(picked) < _DISTINCT:
                same = left & (size == size[first])
                for w in words:
                    same &= w == w[first]
                which[same] = len(picked)
                picked.append(b"".join(int(w[first]).to_bytes(8, "little") for w in words)[:int(size[first])])
                left &= ~same
                first = int(left.argmax())
                if not left[first]:
                    break
        for i in np.flatnonzero(which < 0).tolist():  # long or too many distinct texts: one at a time
            which[i] = len(picked)
            picked.append(raw.buf[int(start[i]):int(start[i] + size[i])])
        texts = list(map(memo.get, picked))
        for j, (one, t) in enumerate(zip(picked, texts)):
            if t is None:
                t = texts[j] = _string(one)
                if len(memo) < 4096:
                    memo[one] = t
        good = np.array([t is not False for t in texts], dtype=bool)[which]
        self._is_str[at[good]] = True
        self._texts = [t or "" for t in texts]
        self._which[at] = which

    @property
    def topics(self) -> list[str]:
        """Each message's topic (leading ``/`` removed), made when first asked for
        (the batch path reads :meth:`topic_codes` instead)."""
        if self._topics is None:
            codes, names = self.topic_codes()
            self._topics = np.array(names or [""], dtype=object)[codes].tolist()
        return self._topics

    def topic_codes(self) -> tuple[np.ndarray, list[str]]:
        """(each message's topic as an index into the list, the topics' names with their leading ``/`` removed)."""
        return self.raw.code, [c.topic.lstrip("/") for c in self.raw.conns]

    def topic_counts(self) -> dict[str, int]:
        """Messages per topic (leading ``/`` removed) in this block."""
        counts = np.bincount(self.raw.code, minlength=len(self.raw.conns)).tolist()
        out: dict[str, int] = {}
        for c, n in zip(self.raw.conns, counts):
            if n:
                name = c.topic.lstrip("/")
                out[name] = out.get(name, 0) + n
        return out

    def __len__(self) -> int:
        return len(self.raw)

    def values(self, rows: np.ndarray, key: str) -> list[Any]:
        """The value of ``key`` in the messages at ``rows`` (``None`` where a message has none)."""
        out: list[Any] = []
        floats, which, texts = self._floats, self._which, self._texts
        is_float, is_str = self._is_float, self._is_str
        for i in rows.tolist():
            if is_float[i]:
                out.append(float(floats[i]) if key == "data" else None)
            elif is_str[i]:
                out.append(texts[which[i]] if key == "data" else None)
            else:  # decoded whole
                out.append(self[i].fields.get(key))
        return out

    def typed(self, rows: np.ndarray, key: str, kind: str, codes: Mapping[str, int]
              ) -> tuple[np.ndarray, np.ndarray] | None:
        """``key`` at ``rows`` as :func:`~rclverify.targets.columns.column` reads
        it, from the decoded columns; ``None`` when a row's message was decoded whole."""
        if key != "data" or not (self._is_float[rows] | self._is_str[rows]).all():
            return None  # a message decoded whole (its event's fields hold its value)
        if kind == "real":
            col = self._floats[rows]
            return self._is_float[rows] & np.isfinite(col), col
        lut = np.array([codes.get(t, -1) for t in self._texts] + [-1], dtype=np.int64)  # (which -1: no text)
        code = lut[self._which[rows]]
        code[~self._is_str[rows]] = -1
        return code >= 0, code

    def __getitem__(self, i: Any) -> Any:
        if isinstance(i, slice):
            return [self[j] for j in range(*i.indices(len(self.raw)))]
        i = int(i)
        if i < 0:
            i += len(self.raw)
        ev = self._made.get(i)
        if ev is None:
            ev = self._made[i] = self._event(i)
        return ev

    def _event(self, i: int) -> Event:
        """Row ``i``'s event: :func:`~.bag.bag_event`'s, made from the decoded ``data``
        where the row was decoded here (the one field of either type; no header)."""
        if not (self._is_float[i] or self._is_str[i]):
            return bag_event(self.reader, self.path, self.index + i, *self.raw.item(i))
        conn, stamp = self.raw.conns[int(self.raw.code[i])], int(self.raw.stamps[i])
        value = float(self._floats[i]) if self._is_float[i] else self._texts[self._which[i]]
        lates = of_reader(self.reader)  # heard late by the live monitor that recorded the bag, as bag_event reads it
        return Event(self.index + i, stamp / 1e9, conn.topic.lstrip("/"), {"data": value},
                     f"{self.path.name}: message {self.index + i}", late=lates.at(conn.topic, stamp) if lates else 0.0)


def _string(raw: bytes) -> str | bool:
    """The ``data`` of a ``std_msgs/msg/String`` in little-endian CDR with nothing after its terminator
    (module docstring), else ``False``; also ``False`` for a text holding a NUL (a numpy string column
    would drop a trailing one: the message decoder gives it)."""
    if len(raw) < 9 or raw[:2] != _LE:
        return False
    n = int.from_bytes(raw[4:8], "little")
    if n < 1 or len(raw) != 8 + n or raw[-1] != 0 or 0 in raw[8:-1]:
        return False
    try:
        return raw[8:-1].decode()
    except UnicodeDecodeError:
        return False


__all__ = ["BagBlock", "BagTrace"]
