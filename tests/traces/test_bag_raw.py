"""A bag's messages read as raw columns (traces/bag_raw.py) against rosbags' own reader, the oracle.

Random sqlite3 and MCAP bags written with rosbags (stamps shared between
topics, out of order within a chunk, chunks that touch at one stamp, whole
chunks compressed with zstd), and damaged ones: the raw blocks give
``AnyReader.messages()``'s messages (connection, stamp, bytes) in its
order, and the same error after the same messages; a bag whose order is
not reproduced (overlapping chunks, per-message compression) gives
``None`` and is read by rosbags, with the same events through the blocks.
"""
from __future__ import annotations

import random
import struct
from pathlib import Path
from typing import Any

import pytest

from rclverify.traces.bag import open_bag, read_bag, typestore
from rclverify.traces.bag_blocks import BagTrace
from rclverify.traces.bag_raw import raw_blocks

BLOB = 150_000  # bytes of a /blob message: a chunk (1 MiB) holds seven


def _write(path: Path, storage: str, seed: int, overlap: bool = False, compress: Any = None) -> None:
    from rosbags.rosbag2 import CompressionFormat, StoragePlugin, Writer
    rnd = random.Random(seed)
    store = typestore([])
    w = Writer(path, version=9, storage_plugin=StoragePlugin.MCAP if storage == "mcap" else StoragePlugin.SQLITE3)
    if compress is not None:
        w.set_compression(compress, CompressionFormat.ZSTD)
    with w:
        conns = [w.add_connection(t, ty, typestore=store) for t, ty in
                 (("/reading", "std_msgs/msg/Float64"), ("/status", "std_msgs/msg/String"),
                  ("/blob", "std_msgs/msg/String"))]
        t = 1_000_000_000
        for i in range(300):
            step = rnd.choice([0, 0, 1, 10_000_000])
            t += step
            w.write(conns[0], t, struct.pack("<4sd", b"\x00\x01\x00\x00", rnd.uniform(0, 400)))
            text = rnd.choice([b"green", b"orange", b"red"]) + b"\x00"
            stamp = t - 5 if step > 5 and rnd.random() < 0.3 else t  # out of order within a chunk (not across one)
            w.write(conns[1], stamp, b"\x00\x01\x00\x00" + struct.pack("<I", len(text)) + text)
            if rnd.random() < 0.08:  # a big message at the same stamp: chunks end and begin on shared stamps
                body = bytes(rnd.randrange(97, 123) for _ in range(64)) * (BLOB // 64) + b"\x00"
                back = 200_000_000 if overlap and i > 150 else 0  # stamped before the previous chunk's end
                w.write(conns[2], t - back, b"\x00\x01\x00\x00" + struct.pack("<I", len(body)) + body)


def _stream(path: Path) -> tuple[list[Any], str | None]:
    """``AnyReader.messages()``: (topic, type, stamp, bytes) each, and its error."""
    reader = open_bag(path, typestore([]))
    out: list[Any] = []
    try:
        for c, t, raw in reader.messages():
            out.append((c.topic, c.msgtype, t, raw))
    except Exception as exc:  # noqa: BLE001 - the oracle's own error, compared as text
        return out, str(exc)
    finally:
        reader.close()
    return out, None


def _raw(path: Path, rows: int) -> tuple[list[Any], str | None] | None:
    reader = open_bag(path, typestore([]))
    out: list[Any] = []
    try:
        blocks = raw_blocks(reader, rows)
        if blocks is None:
            return None
        for b in blocks:
            assert 0 < len(b) <= rows
            out += [(c.topic, c.msgtype, t, raw) for c, t, raw in map(b.item, range(len(b)))]
    except Exception as exc:  # noqa: BLE001
        return out, str(exc)
    finally:
        reader.close()
    return out, None


def _mcap_file(path: Path) -> Path:
    return next(path.glob("*.mcap"))


@pytest.fixture(scope="module")
def bags(tmp_path_factory: Any) -> dict[str, Path]:
    from rosbags.rosbag2 import CompressionMode
    root = tmp_path_factory.mktemp("raw")
    out: dict[str, Path] = {}
    for seed in range(3):
        for storage in ("sqlite3", "mcap"):
            out[f"{storage}{seed}"] = root / f"{storage}{seed}"
            _write(out[f"{storage}{seed}"], storage, seed)
    out["zstd"] = root / "zstd"
    _write(out["zstd"], "mcap", 5, compress=CompressionMode.STORAGE)
    out["message"] = root / "message"
    _write(out["message"], "mcap", 6, compress=CompressionMode.MESSAGE)
    out["overlap"] = root / "overlap"
    _write(out["overlap"], "mcap", 7, overlap=True)
    return out


def test_raw_blocks_are_rosbags_messages_in_its_order(bags: dict[str, Path], monkeypatch: Any) -> None:
    from rclverify.traces import bag_raw
    fast = bag_raw._mcap_fast
    read: list[bool] = []  # whether each chunk was read through its index (not by rosbags' chunk reader)
    monkeypatch.setattr(bag_raw, "_mcap_fast", lambda *a: read.append(fast(*a) is not None) or fast(*a))
    chunks = 0
    for name in [f"{s}{k}" for k in range(3) for s in ("sqlite3", "mcap")] + ["zstd"]:
        want = _stream(bags[name])
        assert want[1] is None and len(want[0]) > 600
        for rows in (5, 16384):
            assert _raw(bags[name], rows) == want, (name, rows)
        one = next(bags[name].glob("*.mcap" if "sqlite3" not in name else "*.db3"))  # the storage file named alone
        assert _raw(one, 64) == _stream(one) != ([], None)
        if name.startswith("mcap"):
            reader = open_bag(bags[name], typestore([]))
            chunks += len(reader.readers[0].storage.storages[0].chunks)
            reader.close()
    assert chunks > 6  # bags of several chunks, touching at shared stamps
    assert len(read) > 12 and all(read)


def test_orders_not_reproduced_are_left_to_rosbags(bags: dict[str, Path]) -> None:
    for name in ("overlap", "message"):
        assert _raw(bags[name], 100) is None, name
        want = list(read_bag(bags[name]))
        got: list[Any] = []
        for b in BagTrace(bags[name]).blocks(["data"], 64) or []:
            got += b if isinstance(b, list) else [b[i] for i in range(len(b))]
        assert repr(got) == repr(want)


@pytest.mark.parametrize("damage", ["record", "index", "crc"])
def test_a_damaged_mcap_gives_rosbags_messages_and_error(bags: dict[str, Path], tmp_path: Path,
                                                         damage: str) -> None:
    import shutil
    touching = []  # (bag, chunk) with a chunk beginning at the stamp the one before it ends with
    for name in ("mcap0", "mcap1", "mcap2"):
        reader = open_bag(bags[name], typestore([]))
        chunks = reader.readers[0].storage.storages[0].chunks
        touching += [(name, b) for a, b in zip(chunks, chunks[1:]) if a.message_end_time == b.message_start_time]
        reader.close()
    name, chunk = touching[0]  # its error comes before the messages of the chunk before at that stamp
    path = tmp_path / "bag"
    shutil.copytree(bags[name], path)
    f = _mcap_file(path)
    data = bytearray(f.read_bytes())
    body = chunk.chunk_start_offset + 9 + 40 + len(chunk.compression)  # the chunk's records
    if damage == "record":  # a message record's length: the records no longer tile the chunk
        at = data.index(b"\x05", body + 200)
        data[at + 1:at + 9] = struct.pack("<Q", 7)
    elif damage == "index":  # an indexed offset moved: the index no longer checks out, the records do
        at = next(iter(chunk.message_index_offsets.values())) + 15 + 8
        data[at:at + 8] = struct.pack("<Q", struct.unpack("<Q", data[at:at + 8])[0] + 1)
    else:  # the chunk's checksum (the writer's is 0: none) wrong
        at = chunk.chunk_start_offset + 9 + 24
        data[at:at + 4] = struct.pack("<I", 1)
    f.write_bytes(bytes(data))
    want = _stream(path)
    assert (want[1] is None) == (damage == "index"), want[1]
    assert _raw(path, 64) == want
    if damage != "index":  # through the blocks: read_bag's events, then its located error
        from rclverify.traces.events import TraceError
        got: list[Any] = []
        with pytest.raises(TraceError) as exc:
            for b in BagTrace(path).blocks(["data"], 64) or []:
                got += b if isinstance(b, list) else [b[i] for i in range(len(b))]
        events: list[Any] = []
        with pytest.raises(TraceError) as ref:
            for ev in read_bag(path):
                events.append(ev)
        assert str(exc.value) == str(ref.value)
        assert repr(got) == repr(events)


@pytest.mark.parametrize("storage", ["sqlite3", "mcap"])
def test_many_and_long_strings_are_decoded_as_read_bag(tmp_path: Path, storage: str) -> None:
    """More distinct String messages than a block compares (traces/bag_blocks.py), texts longer
    than it gathers, texts of 7, 8 and 9 bytes (a 64-bit word's edge): read_bag's values."""
    from collections import Counter

    import numpy as np
    from rosbags.rosbag2 import StoragePlugin, Writer
    rnd = random.Random(3)
    store = typestore([])
    path = tmp_path / storage
    with Writer(path, version=9, storage_plugin=StoragePlugin.MCAP if storage == "mcap" else
                StoragePlugin.SQLITE3) as w:
        conn = w.add_connection("/status", "std_msgs/msg/String", typestore=store)
        for i in range(600):
            text = rnd.choice([f"v{rnd.randrange(150)}", "x" * rnd.randrange(6, 11)] +
                              (["y" * rnd.randrange(60, 90)] if i >= 400 else []))  # long ones in the last blocks
            raw = text.encode() + b"\x00"
            w.write(conn, 1000 + i, b"\x00\x01\x00\x00" + struct.pack("<I", len(raw)) + raw)
    want = list(read_bag(path))
    got, typed = [], 0
    for b in BagTrace(path).blocks(["data"], 256) or []:
        rows = np.arange(len(b))
        got += b.values(rows, "data")
        assert b.topic_counts() == dict(Counter(b.topics))
        ok, col = b.typed(rows, "data", "enum", {"v7": 0, "xxxxxxxx": 1})
        typed += int(ok.sum())
        assert col[ok].tolist() == [{"v7": 0, "xxxxxxxx": 1}[v] for v, g in zip(b.values(rows, "data"), ok) if g]
    assert got == [e.fields["data"] for e in want]
    assert typed == sum(e.fields["data"] in ("v7", "xxxxxxxx") for e in want) > 0
