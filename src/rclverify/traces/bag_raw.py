"""A ROS 2 bag's messages as raw columns, in ``rosbags``' own order, without its generators.

:func:`~.bag.read_bag` takes a bag's messages from ``rosbags``' high-level
reader (``AnyReader.messages()``), which hands over one ``(connection,
stamp, bytes)`` tuple a message through four generators (and, for MCAP,
a pure-Python record walk): most of the offline command's time on a bag.
:func:`raw_blocks` gives the same messages, in the same order and with the
same bytes, as :class:`RawMessages` blocks: each message's connection (an
index into ``conns``), its stamp (integer nanoseconds) and where its bytes
lie in one buffer.

The order is ``rosbags``' (0.11), reproduced from what its readers do:

* a bag directory reads its storage files one after the other (its
  ``DirectoryReader``), each message given the directory's connection of
  the same topic, type, serialisation and hash;
* **sqlite3**: the query ``rosbags`` sends, built the same way, on the
  storage's own open ``apsw`` connection: the same SQL on the same
  database through the same SQLite library gives the same rows in the same
  order (ties in ``ORDER BY timestamp`` included), read a block at a time;
* **MCAP**, indexed: ``rosbags`` merges its chunks (``heapq.merge`` of
  ``(stamp, chunk offset, ...)``), each chunk's messages sorted stably by
  stamp, keeping those whose stamp lies in the chunk index's time range and
  whose channel is known.  When the chunks' time ranges, in order, do not
  overlap (each ends before the next begins, or at the stamp the next
  begins with, the earlier chunk lying earlier in the file) the merge is
  the chunks one after the other, and that is read here; a chunk is read
  (and its error raised) where the merge reads it, after every message
  stamped before its first stamp and before any other.  A chunk is decompressed by
  ``rosbags``' own ``decompress`` (its size and CRC checks), its message
  records found through the chunk's message index records and checked to
  tile the chunk with the records between them (walked one by one: no
  message record may be left out), then sorted stably by stamp with numpy.
  A chunk whose index does not check out is read by ``rosbags``' own chunk
  reader (``msgsrc``), which gives its messages or raises its own error at
  the same point of the stream.

Anything else (ROS 1, several bags, per-message or per-file compression,
an unindexed or overlapping MCAP, another ``rosbags`` version or storage
class) gives ``None`` before reading a message: the caller takes
``AnyReader.messages()`` itself.  Errors: what ``rosbags`` raises, after
the blocks of every message before it (tests/traces/test_bag_raw.py compares the
order, bytes and errors with ``AnyReader.messages()``).
"""
from __future__ import annotations

from importlib.metadata import version
from itertools import islice
from operator import itemgetter
from typing import Any, Iterator, Sequence

from rclverify.core.numeric import np

_EMPTY = np.zeros(0, dtype=np.int64)
_FIRST, _SECOND, _THIRD = itemgetter(0), itemgetter(1), itemgetter(2)


class RawMessages:
    """Messages of a bag as columns: ``code`` (index into ``conns``), ``stamps``
    (int64 ns), and each one's bytes ``buf[start[i]:stop[i]]``."""

    __slots__ = ("conns", "code", "stamps", "buf", "start", "stop")

    def __init__(self, conns: Sequence[Any], code: np.ndarray, stamps: np.ndarray, buf: bytes,
                 start: np.ndarray, stop: np.ndarray) -> None:
        self.conns, self.code, self.stamps, self.buf, self.start, self.stop = conns, code, stamps, buf, start, stop

    def __len__(self) -> int:
        return len(self.code)

    def raw(self, i: int) -> bytes:
        """Message ``i``'s bytes."""
        return self.buf[int(self.start[i]):int(self.stop[i])]

    def item(self, i: int) -> tuple[Any, int, bytes]:
        """Message ``i`` as ``rosbags`` gives it: (connection, stamp in ns, bytes)."""
        return self.conns[int(self.code[i])], int(self.stamps[i]), self.raw(i)

    def cut(self, a: int, b: int) -> RawMessages:
        """Messages ``a .. b - 1`` (the same buffer)."""
        return RawMessages(self.conns, self.code[a:b], self.stamps[a:b], self.buf, self.start[a:b], self.stop[a:b])


def from_items(items: Sequence[tuple[Any, int, bytes]]) -> RawMessages:
    """``rosbags``' message tuples as :class:`RawMessages` (connections by identity: not hashable)."""
    if not items:
        return RawMessages([], _EMPTY, _EMPTY, b"", _EMPTY, _EMPTY)
    n = len(items)
    conns = list(map(_FIRST, items))
    index: dict[int, int] = {}
    order: list[Any] = []
    for c in conns:
        if id(c) not in index:
            index[id(c)] = len(order)
            order.append(c)
    code = np.fromiter(map(index.__getitem__, map(id, conns)), np.int64, n)
    raws = list(map(_THIRD, items))
    lens = np.fromiter(map(len, raws), np.int64, n)
    stop = np.cumsum(lens)
    return RawMessages(order, code, np.fromiter(map(_SECOND, items), np.int64, n), b"".join(raws), stop - lens, stop)


def raw_blocks(reader: Any, rows: int) -> Iterator[RawMessages] | None:
    """The messages of ``reader`` (an open ``AnyReader``) as blocks of at most ``rows``,
    in ``AnyReader.messages()``'s order (module docstring), or ``None`` when that order is
    not reproduced here.  Raises what ``rosbags`` raises, after the blocks before it."""
    try:
        from rosbags.rosbag2.reader import DirectoryReader  # deferred: optional or conditional (inside a block)
        from rosbags.rosbag2.storage_mcap import McapReader  # deferred: optional or conditional (inside a block)
        from rosbags.rosbag2.storage_sqlite3 import Sqlite3Reader  # deferred: optional or conditional (inside a block)
        if not version("rosbags").startswith("0.11."):
            return None
    except Exception:  # noqa: BLE001 - another rosbags: its own reader
        return None
    if not getattr(reader, "is2", False) or len(getattr(reader, "readers", ())) != 1:
        return None
    top: Any = getattr(reader.readers[0], "storage", None)
    parts: list[tuple[Any, dict[int, Any]]]
    if type(top) is DirectoryReader:
        if top.metadata.compression_mode:
            return None
        parts = [(s, _dir_connmap(top.connections, s)) for s in top.storages]
    elif type(top) is McapReader or isinstance(top, Sqlite3Reader):  # (a subclass: bag_open.py's, not counting)
        parts = [(top, {c.id: c for c in top.connections})]
    else:
        return None
    plans: list[Any] = []
    for storage, connmap in parts:
        if not connmap:
            continue
        if isinstance(storage, Sqlite3Reader):
            plans.append(("sqlite3", storage, connmap))
        elif type(storage) is McapReader:
            chunks = _mcap_chunks(storage, connmap)
            if chunks is None:
                return None
            plans.append(("mcap", storage, (connmap, chunks)))
        else:
            return None
    return _read(plans, max(rows, 1))


def _dir_connmap(connections: Sequence[Any], storage: Any) -> dict[int, Any]:
    """A storage file's connection id -> the directory's connection (as rosbags' ``DirectoryReader`` maps)."""
    out: dict[int, Any] = {}
    for x in storage.connections:
        conn = next((y for y in connections if y.topic == x.topic and y.msgtype == x.msgtype and y.ext == x.ext
                     and (not x.digest or not y.digest or y.digest == x.digest)), None)
        if conn is not None:
            out[x.id] = conn
    return out


def _read(plans: list[Any], rows: int) -> Iterator[RawMessages]:
    for kind, storage, extra in plans:
        if kind == "sqlite3":
            yield from _sqlite3(storage, extra, rows)
        else:
            yield from _mcap(storage, extra[0], extra[1], rows)


def _mcap(storage: Any, connmap: dict[int, Any], chunks: list[Any], rows: int) -> Iterator[RawMessages]:
    """The chunks' messages in rosbags' merge order: a chunk is read (and may raise) after
    every message stamped before its start time is given and before any other (module docstring)."""
    pending: list[RawMessages] = []
    for chunk in chunks:
        bound = chunk.message_start_time
        ready = [p.cut(0, int(np.searchsorted(p.stamps, bound))) for p in pending]
        pending = [p.cut(len(r), len(p)) for p, r in zip(pending, ready) if len(r) < len(p)]  # (each holds a chunk)
        yield from _pieces(ready, rows)
        pending.append(_mcap_chunk(storage, chunk, connmap))
    yield from _pieces(pending, rows)


def _pieces(parts: list[RawMessages], rows: int) -> Iterator[RawMessages]:
    for got in parts:
        for a in range(0, len(got), rows):
            yield got.cut(a, a + rows)


def _sqlite3(storage: Any, connmap: dict[int, Any], rows: int) -> Iterator[RawMessages]:
    """rosbags' ``Sqlite3Reader.messages`` for every connection of ``connmap``: its query, its order."""
    conns = [x for x in storage.connections if x.id in connmap]
    ids = tuple({x.id for x in conns})
    query = ' '.join(['SELECT topics.id,messages.timestamp,messages.data',
                      'FROM messages JOIN topics ON messages.topic_id=topics.id',
                      f'WHERE topics.id IN ({",".join("?" for _ in ids)})', 'ORDER BY timestamp'])
    order = [connmap[i] for i in sorted(ids)]  # rosbags yields its storage's connection, mapped by ``connmap``
    known = np.array(sorted(ids), dtype=np.int64)  # a row's connection: its topic id's place among them
    cur = storage.dbconn.execute(query, list(ids))
    while True:
        got: list[tuple[int, int, bytes]] = []
        error: BaseException | None = None
        try:
            got.extend(islice(cur, rows))
        except Exception as exc:  # noqa: BLE001 - the rows before it first, as rosbags' generator gives them
            error = exc
        if got:  # (``zip(*got)`` would call 3 x len(got) iterators)
            n = len(got)
            raws = list(map(_THIRD, got))
            lens = np.fromiter(map(len, raws), np.int64, n)
            stop = np.cumsum(lens)
            code = np.searchsorted(known, np.fromiter(map(_FIRST, got), np.int64, n))  # (the query's ids only)
            yield RawMessages(order, code, np.fromiter(map(_SECOND, got), np.int64, n), b"".join(raws),
                              stop - lens, stop)
        if error is not None:
            raise error
        if len(got) < rows:
            return


def _mcap_chunks(storage: Any, connmap: dict[int, Any]) -> list[Any] | None:
    """The chunks rosbags' ``McapReader.messages`` reads, in the order its merge gives
    them, when their time ranges do not touch; ``None`` otherwise (module docstring)."""
    if not storage.chunks:
        return None  # unindexed: rosbags scans the file
    chunks = [x for x in storage.chunks if any(x.channel_count.get(cid, 0) for cid in connmap)]
    chunks.sort(key=lambda x: (x.message_start_time, x.chunk_start_offset))
    for a, b in zip(chunks, chunks[1:]):  # touching at one stamp: the merge gives the earlier offset first
        if not (a.message_end_time < b.message_start_time or (a.message_end_time == b.message_start_time and
                                                               a.chunk_start_offset < b.chunk_start_offset)):
            return None
    return chunks


def _mcap_chunk(storage: Any, chunk: Any, connmap: dict[int, Any]) -> RawMessages:
    """One chunk's messages, sorted stably by stamp (module docstring); raises rosbags' error."""
    from rosbags.rosbag2.storage_mcap import msgsrc  # deferred: start-up (loads rosbags and more only when called)
    got = None
    try:
        got = _mcap_fast(storage, chunk, connmap)
    except Exception:  # noqa: BLE001 - rosbags' own chunk reader says what is wrong, or reads it
        got = None
    if got is not None:
        return got
    msgs = list(msgsrc(chunk, connmap, chunk.message_start_time, chunk.message_end_time + 1, storage.bio))
    return from_items([(m.connection, m.timestamp, m.data or b"") for m in msgs if m.offset])


def gather(buf: bytes, at: np.ndarray, dtype: Any) -> np.ndarray:
    """The value of numpy type ``dtype`` (a fixed-size, byte-order-explicit type such as ``"<u8"``
    or a structured one) whose bytes begin at each offset of ``at`` in ``buf``, read through one
    unaligned view of ``buf`` with a stride of one byte (no copy of ``buf``; each value copied once).
    Every ``at + itemsize`` must be at most ``len(buf)`` (else ``IndexError``)."""
    dt = np.dtype(dtype)
    view = np.ndarray((max(len(buf) - dt.itemsize + 1, 0),), dtype=dt, buffer=buf, strides=(1,))
    got: np.ndarray = view[at]
    return got


def _mcap_fast(storage: Any, chunk: Any, connmap: dict[int, Any]) -> RawMessages | None:
    """The chunk read through its message index, or ``None`` when the index does not check out."""
    from rosbags.rosbag2.storage_mcap import decompress, deserialize_uint32, read_exact  # deferred: start-up (loads rosbags and more only when called)
    bio = storage.bio
    bio.seek(chunk.chunk_start_offset + 9 + 24)
    crc = deserialize_uint32(read_exact(bio, 4))[0]
    bio.seek(chunk.chunk_start_offset + 9 + 40 + len(chunk.compression))
    data = decompress(read_exact(bio, chunk.compressed_size), chunk.compression, chunk.uncompressed_size, crc)
    offsets = _index_offsets(storage, chunk)
    if offsets is None:
        return None
    size = len(data)
    o = np.sort(offsets, kind="stable")  # (each channel's offsets in order already: merged runs)
    if not len(o) or (len(o) > 1 and not (np.diff(o) > 0).all()) or int(o[-1]) + 31 > size:
        return None
    length = gather(data, o + 1, "<u8")  # a message record (the MCAP specification): opcode 0x05, length,
    if not (np.frombuffer(data, np.uint8)[o] == 5).all() or not (length >= 22).all() or int(length.max()) > size:
        return None  # then the channel id (2 bytes), sequence (4), log time (8), publish time (8), data
    nxt = o + 9 + length.astype(np.int64)
    apart = nxt[:-1] != o[1:]
    gaps = [(0, int(o[0]))] + list(zip(nxt[:-1][apart].tolist(), o[1:][apart].tolist()))
    gaps.append((int(nxt[-1]), size))
    if not all(_other_records(data, a, b) for a, b in gaps):
        return None
    channel, stamp = gather(data, o + 9, "<u2"), gather(data, o + 15, "<u8")
    if (stamp >= 1 << 63).any():
        return None
    stamp = stamp.astype(np.int64)
    known = np.zeros(1 << 16, dtype=bool)  # a channel id is 16 bits: a table of the known ones
    known[[c for c in connmap if 0 <= c < 1 << 16]] = True
    keep = (stamp >= chunk.message_start_time) & (stamp < chunk.message_end_time + 1) & known[channel]
    if not keep.all():
        o, nxt, channel, stamp = o[keep], nxt[keep], channel[keep], stamp[keep]
    if len(stamp) > 1 and not bool((stamp[1:] >= stamp[:-1]).all()):  # already in order: as a stable sort keeps it
        at = np.argsort(stamp, kind="stable")
        o, nxt, channel, stamp = o[at], nxt[at], channel[at], stamp[at]
    ids = np.flatnonzero(np.bincount(channel, minlength=1)).tolist()  # the channels present, ascending
    lut = np.zeros(ids[-1] + 1 if ids else 1, dtype=np.int64)
    lut[ids] = np.arange(len(ids))
    return RawMessages([connmap[c] for c in ids], lut[channel], stamp, data, o + 31, nxt)


def _other_records(data: bytes, a: int, b: int) -> bool:
    """Whether ``data[a:b]`` is whole records, none of them a message (op 0x05)."""
    while a < b:
        if data[a] == 5 or a + 9 > b:
            return False
        a += 9 + int.from_bytes(data[a + 1:a + 9], "little")
    return a == b


def _index_offsets(storage: Any, chunk: Any) -> np.ndarray | None:
    """The offsets (in the decompressed chunk) of the chunk's indexed messages, from
    its message index records; ``None`` when they cannot be read as such."""
    bio = storage.bio
    begin = chunk.chunk_start_offset + chunk.chunk_length
    bio.seek(begin)
    raw = bio.read(chunk.message_index_length)
    if len(raw) != chunk.message_index_length:
        return None
    found: list[np.ndarray] = []
    for cid, at in chunk.message_index_offsets.items():
        p = at - begin
        if p < 0 or p + 15 > len(raw) or raw[p] != 7:
            return None
        n = int.from_bytes(raw[p + 11:p + 15], "little")
        if int.from_bytes(raw[p + 9:p + 11], "little") != cid or n % 16 or p + 15 + n > len(raw) or \
                int.from_bytes(raw[p + 1:p + 9], "little") != 6 + n:
            return None
        found.append(np.frombuffer(raw, "<u8", n // 8, p + 15)[1::2])
    if not found:
        return None
    got = np.concatenate(found)
    return None if (got >= 1 << 62).any() else got.astype(np.int64)


__all__ = ["RawMessages", "from_items", "raw_blocks"]
