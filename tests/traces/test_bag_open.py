"""A sqlite3 bag opened without counting its messages (traces/bag_open.py) against rosbags' own open, the oracle.

Small bags written with rosbags (sqlite3, a bag directory and its bare
``.db3``), their database edited to each schema version rosbags reads (4
as written, 3, 2 and 1): the uncounted open gives rosbags' connections
(but the counts) and the blocks give ``read_bag``'s events.  Damaged
databases (cut short, bytes overwritten on a page, a table missing, a
schema version that is not a number): the blocks give ``read_bag``'s events
and its error, the error of rosbags' counting open where that open fails;
without asking that open (a seeded mistake) they would not.
"""
from __future__ import annotations

import random
import shutil
import sqlite3
import struct
from pathlib import Path
from typing import Any

import pytest

from rclverify.traces import bag_blocks
from rclverify.traces.bag import open_bag, read_bag, typestore
from rclverify.traces.bag_blocks import BagTrace
from rclverify.traces.bag_open import open_uncounted


def _write(path: Path, seed: int, n: int = 400, compress: Any = None) -> None:
    from rosbags.rosbag2 import CompressionFormat, StoragePlugin, Writer
    rnd = random.Random(seed)
    store = typestore([])
    w = Writer(path, version=9, storage_plugin=StoragePlugin.SQLITE3)
    if compress is not None:
        w.set_compression(compress, CompressionFormat.ZSTD)
    with w:
        conns = [w.add_connection(t, ty, typestore=store) for t, ty in
                 (("/reading", "std_msgs/msg/Float64"), ("/status", "std_msgs/msg/String"),
                  ("/pose", "geometry_msgs/msg/Point"))]
        t = 10**9
        for _ in range(n):
            t += rnd.choice([0, 0, 1, 10**7])  # stamps shared between topics and between messages
            w.write(conns[0], t, struct.pack("<4sd", b"\x00\x01\x00\x00", rnd.uniform(0, 400)))
            text = rnd.choice([b"green", b"orange", b"red"]) + b"\x00"
            w.write(conns[1], t, b"\x00\x01\x00\x00" + struct.pack("<I", len(text)) + text)
            if rnd.random() < 0.2:
                w.write(conns[2], t, b"\x00\x01\x00\x00" + struct.pack("<3d", *(rnd.random() for _ in range(3))))


def _edit(db: Path, schema: int) -> None:
    """The database as rosbags reads a bag of ``schema`` (the writer's is 4)."""
    with sqlite3.connect(db) as c:
        if schema == 3:
            c.execute("UPDATE schema SET schema_version = 3")
        if schema <= 2:
            c.execute("DROP TABLE schema")
        if schema == 1:
            c.execute("ALTER TABLE topics DROP COLUMN offered_qos_profiles")
    c.close()


def _oracle(path: Path) -> tuple[list[Any], str | None]:
    out: list[Any] = []
    try:
        for e in read_bag(path):
            out.append((e.index, e.time, e.topic, e.fields))
    except Exception as exc:  # noqa: BLE001 - the oracle's own error, compared as text
        return out, str(exc)
    return out, None


def _blocks(path: Path) -> tuple[list[Any], str | None]:
    out: list[Any] = []
    try:
        blocks = BagTrace(path).blocks(["data"], 97)
        assert blocks is not None
        for b in blocks:
            out += [(e.index, e.time, e.topic, e.fields) for e in (b if isinstance(b, list) else b[:])]
    except Exception as exc:  # noqa: BLE001
        return out, str(exc)
    return out, None


@pytest.fixture(scope="module")
def good(tmp_path_factory: Any) -> Path:
    base = tmp_path_factory.mktemp("bags")
    _write(base / "good", 3)
    return base / "good"


def _strip(conns: Any, counts: bool = False) -> list[Any]:
    """The connections without their reader (and their counts, unless ``counts``)."""
    return [c._replace(owner=None) if counts else c._replace(msgcount=0, owner=None) for c in conns]


@pytest.mark.parametrize("schema", [4, 3, 2, 1])
@pytest.mark.parametrize("bare", [False, True])
def test_uncounted_open_gives_rosbags_connections_and_events(good: Path, tmp_path: Path, schema: int,
                                                             bare: bool) -> None:
    bag = tmp_path / "bag"
    shutil.copytree(good, bag)
    _edit(bag / "good.db3", schema)
    path = bag / "good.db3" if bare else bag
    fast, slow = open_uncounted(path, typestore([])), open_bag(path, typestore([]))
    assert fast is not None
    try:
        assert type(fast.readers[0].storage).__name__ == ("UncountedSqlite3" if bare else "DirectoryReader")
        assert _strip(fast.connections) == _strip(slow.connections)
        if not bare:  # the directory's connections (from metadata.yaml) and its storage's
            assert _strip(fast.connections, counts=True) == _strip(slow.connections, counts=True)
            fs, ss = fast.readers[0].storage.storages[0], slow.readers[0].storage.storages[0]
            assert type(fs).__name__ == "UncountedSqlite3"
            assert _strip(fs.connections) == _strip(ss.connections)
            assert (fs.schema, fs.msgtypes) == (ss.schema, ss.msgtypes)
        assert fast.typestore.fielddefs == slow.typestore.fielddefs
    finally:
        fast.close()
        slow.close()
    want = _oracle(path)
    assert want[1] is None and len(want[0]) > 800
    assert _blocks(path) == want


def _damaged(good: Path, tmp_path: Path, how: str, at: int) -> Path:
    bag = tmp_path / f"{how}-{at}"
    shutil.copytree(good, bag)
    db = bag / "good.db3"
    data = bytearray(db.read_bytes())
    if how == "cut":
        db.write_bytes(bytes(data[:at * 4096]))
    elif how == "page":  # 200 random bytes inside page ``at``
        rnd = random.Random(at)
        data[at * 4096 + 64:at * 4096 + 264] = bytes(rnd.randrange(256) for _ in range(200))
        db.write_bytes(bytes(data))
    elif how == "table":
        with sqlite3.connect(db) as c:
            c.execute("DROP TABLE messages")
        c.close()
    else:
        with sqlite3.connect(db) as c:
            c.execute("DROP TABLE schema")
            c.execute("CREATE TABLE schema(schema_version TEXT, ros_distro TEXT)")
            c.execute("INSERT INTO schema VALUES ('four', 'rosbags')")
        c.close()
    return bag


def test_damaged_databases_give_read_bags_events_and_error(good: Path, tmp_path: Path, monkeypatch: Any) -> None:
    pages = (good / "good.db3").stat().st_size // 4096
    rnd = random.Random(7)
    cases = [("cut", rnd.randrange(2, pages)) for _ in range(3)] + \
            [("page", p) for p in sorted(rnd.sample(range(1, pages), 8))] + [("table", 0), ("schema", 0)]
    bags = [_damaged(good, tmp_path, how, at) for how, at in cases]
    wants = [_oracle(b) for b in bags]
    assert sum(w[1] is not None and "cannot open the bag" in w[1] for w in wants) >= 4  # the counting open fails
    for bag, want in zip(bags, wants):
        got = _blocks(bag)
        if want[1] is not None and "cannot open the bag" in want[1]:  # the command prints only the error
            assert got[1] == want[1], bag.name
        else:
            assert got == want, bag.name
    # a seeded mistake: the reader's error kept where rosbags' open fails; some damaged bag must then differ
    monkeypatch.setattr(bag_blocks, "counted_open_error", lambda path, store: None)
    assert any(_blocks(b)[1] != w[1] for b, w in zip(bags, wants))


def test_a_bag_of_two_storage_files_reads_as_rosbags_reads_it(good: Path, tmp_path: Path) -> None:
    """A bag directory naming two database files: each opened without counting, read one after the other."""
    import yaml
    _write(tmp_path / "second", 11, 150)
    bag = tmp_path / "split"
    shutil.copytree(good, bag)
    shutil.copy(tmp_path / "second/second.db3", bag / "split_1.db3")
    meta = yaml.safe_load((bag / "metadata.yaml").read_text())
    meta["rosbag2_bagfile_information"]["relative_file_paths"] = ["good.db3", "split_1.db3"]
    (bag / "metadata.yaml").write_text(yaml.safe_dump(meta))
    fast = open_uncounted(bag, typestore([]))
    assert fast is not None
    try:
        assert [type(s).__name__ for s in fast.readers[0].storage.storages] == ["UncountedSqlite3"] * 2
    finally:
        fast.close()
    want = _oracle(bag)
    assert want[1] is None and len(want[0]) > 1100
    assert _blocks(bag) == want


@pytest.mark.parametrize("mode", ["MESSAGE", "FILE"])
def test_a_compressed_bag_reads_as_rosbags_reads_it(tmp_path: Path, mode: str) -> None:
    """Per message or per file zstd: opened without counting (the database rosbags unpacks for a
    compressed file), its messages taken from rosbags' own reader (bag_raw.py does not read those)."""
    from rosbags.rosbag2 import CompressionMode
    _write(tmp_path / "z", 5, 120, compress=getattr(CompressionMode, mode))
    fast = open_uncounted(tmp_path / "z", typestore([]))
    assert fast is not None
    try:
        assert type(fast.readers[0].storage.storages[0]).__name__ == "UncountedSqlite3"
    finally:
        fast.close()
    want = _oracle(tmp_path / "z")
    assert want[1] is None and len(want[0]) > 250
    assert _blocks(tmp_path / "z") == want
