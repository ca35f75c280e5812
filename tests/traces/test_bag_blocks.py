"""A ROS 2 bag read in blocks (traces/bag_blocks.py) against read_bag, its oracle.

Small sqlite3 and MCAP bags of the classifier's run, written with rosbags,
with every kind of message the block reader must leave to the message
decoder (another type, big-endian, padded, a string that is not UTF-8, a
non-enumeration status, NaN and infinite readings, an empty string): the
blocks' events, values and typed columns are read_bag's, the batch path on
the blocks gives the streaming engine's verdicts on read_bag's events, and
a message that cannot be decoded raises the same located error after the
same verdicts.
"""
from __future__ import annotations

import math
import random
import struct
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from _classifier import CLASSIFIER
from rclverify.backends.monitors.check import check_trace
from rclverify.targets.columns import column
from rclverify.lang.typecheck import load
from rclverify.traces import read_trace
from rclverify.traces.bag import read_bag, typestore
from rclverify.traces.bag_blocks import BagBlock, BagTrace
from rclverify.traces.events import TraceError
from rclverify.traces.mapping import load_rules

BANDS = ["green", "orange", "red"]


def _write(path: Path, storage: str, seed: int, bad_at: int | None = None) -> None:
    from rosbags.rosbag2 import StoragePlugin, Writer
    store = typestore([])
    rnd = random.Random(seed)
    plugin = StoragePlugin.MCAP if storage == "mcap" else StoragePlugin.SQLITE3
    with Writer(path, version=9, storage_plugin=plugin) as w:
        reading = w.add_connection("/reading", "std_msgs/msg/Float64", typestore=store)
        status = w.add_connection("/status", "std_msgs/msg/String", typestore=store)
        count = w.add_connection("/count", "std_msgs/msg/Int32", typestore=store)
        for i in range(400):
            t = 1_700_000_000_000_000_000 + i * 10_000_000 + rnd.choice([0, 0, 0, 3])
            r = rnd.choice([rnd.uniform(0, 400), 120.0, 119.99999999999999, 250.0, math.nan, math.inf, -1.0])
            raw = struct.pack("<4sd", b"\x00\x01\x00\x00", r)
            kind = rnd.random()
            if kind < 0.03:
                raw = struct.pack(">4sd", b"\x00\x00\x00\x00", r)  # big-endian: the decoder's
            elif kind < 0.05:
                raw += b"\x00\x00"  # padded: the decoder's
            if bad_at is not None and i == bad_at:
                raw = b"\x00\x01\x00\x00\x01"  # too short for a double: cannot be decoded
            w.write(reading, t, raw)
            band = BANDS[0 if r < 120 else 1 if r < 250 else 2] if rnd.random() < 0.9 else rnd.choice(
                BANDS + ["purple", ""])
            text = band.encode() + (b"\x00" if rnd.random() < 0.97 else b"\x00\x00")  # a NUL in the text too
            sraw = b"\x00\x01\x00\x00" + struct.pack("<I", len(text)) + text
            kind = rnd.random()
            if kind < 0.03:
                sraw = b"\x00\x01\x00\x00" + struct.pack("<I", 3) + b"\xff\xfe\x00"  # not UTF-8: the decoder's error
            elif kind < 0.06:
                sraw += b"\x00"  # padded
            if not (kind < 0.03 and bad_at is None):
                w.write(status, t + rnd.choice([0, 0, 1_000_000]), sraw)
            if rnd.random() < 0.05:
                w.write(count, t, store.serialize_cdr(store.types["std_msgs/msg/Int32"](data=i), "std_msgs/msg/Int32"))


def _events_of(blocks: Any) -> list[Any]:
    out: list[Any] = []
    for b in blocks:
        out += b if isinstance(b, list) else [b[i] for i in range(len(b))]
    return out


@pytest.fixture(scope="module")
def bags(tmp_path_factory: Any) -> dict[str, Path]:
    root = tmp_path_factory.mktemp("bags")
    out = {}
    for storage in ("sqlite3", "mcap"):
        out[storage] = root / f"run_{storage}"
        _write(out[storage], storage, 7)
        out[f"{storage}-bad"] = root / f"bad_{storage}"
        _write(out[f"{storage}-bad"], storage, 8, bad_at=300)
    return out


@pytest.mark.parametrize("storage", ["sqlite3", "mcap"])
def test_blocks_carry_read_bags_events_and_values(bags: dict[str, Path], storage: str) -> None:
    path = bags[storage]
    want = list(read_bag(path))
    assert any(e.fields.get("data") == "red\x00" for e in want)
    typed = 0
    for rows in (7, 4096):
        blocks = list(BagTrace(path).blocks(["data"], rows) or [])
        assert all(isinstance(b, BagBlock) for b in blocks)
        assert repr(_events_of(blocks)) == repr(want)
        k = 0
        for b in blocks:
            assert b.topics == [e.topic for e in want[k:k + len(b)]]
            assert b.times.tolist() == [e.time for e in want[k:k + len(b)]]
            for topic, kind, codes in (("reading", "real", {}), ("status", "enum", {v: j for j, v in enumerate(BANDS)})):
                at = np.flatnonzero(np.array(b.topics) == topic)
                vals = b.values(at, "data")
                assert repr(vals) == repr([want[k + i].fields.get("data") for i in at.tolist()])
                got = b.typed(at, "data", kind, codes)
                typed += got is not None
                if got is not None:
                    ref = column(vals, kind, codes)
                    assert got[0].tolist() == ref[0].tolist()
                    assert got[1][ref[0]].tolist() == ref[1][ref[0]].tolist()
            k += len(b)
        assert k == len(want)
    assert typed > 20  # the columns were read from the bytes, not only through the decoder


@pytest.mark.parametrize("storage", ["sqlite3", "mcap"])
def test_batch_on_bag_blocks_equals_streaming(bags: dict[str, Path], storage: str, tmp_path: Path) -> None:
    (tmp_path / "c.rcl").write_text(CLASSIFIER)
    checked = load([tmp_path / "c.rcl"])
    node = [checked.nodes["Classifier"]]
    rules = load_rules({"reading": {"fields": ["data"]}, "status": {"fields": ["data"]}})
    for name in (storage, f"{storage}-bad"):
        runs = []
        for batch in (False, True):
            seen: list[Any] = []
            try:
                n, res = check_trace(checked, node, read_trace(bags[name]), rules, 0.005, seen.append, batch=batch)
                runs.append((n, res, seen, None))
            except TraceError as exc:
                runs.append((None, None, seen, str(exc)))
        assert repr(runs[1]) == repr(runs[0]), name
        assert (runs[0][3] is not None) == name.endswith("bad")
        # verdicts came (the bad bag stops at its undecodable message; a NaN reading supersedes the question
        # in force with an undecided one: one verdict, not one per output that follows)
        assert len(runs[0][2]) > (15 if name.endswith("bad") else 20)
    assert "cannot decode std_msgs/msg/" in str(runs[0][3])  # a string that is not UTF-8 comes first


@pytest.mark.parametrize("storage", ["sqlite3", "mcap"])
def test_batch_in_small_blocks_equals_streaming(bags: dict[str, Path], storage: str, tmp_path: Path,
                                                monkeypatch: pytest.MonkeyPatch) -> None:
    """Blocks of a few messages, so that a block often begins with an input carried over from the one
    before (the rows' topics then come from the carried events and the block's topic codes)."""
    from rclverify.backends.monitors import rows
    from rclverify.backends.monitors.batch import check_batch
    (tmp_path / "c.rcl").write_text(CLASSIFIER)
    checked = load([tmp_path / "c.rcl"])
    node = checked.nodes["Classifier"]
    rules = load_rules({"reading": {"fields": ["data"]}, "status": {"fields": ["data"]}})
    kinds, carried = rows.BlockRows.kinds, []

    def spy(self: Any, table: Any) -> Any:
        got = kinds(self, table)
        if self.head and got is not None:
            carried.append([table.get(t, 0) for t in self.topics] == got.tolist())
        return got
    monkeypatch.setattr(rows.BlockRows, "kinds", spy)

    def run(chunk: int | None) -> str:
        seen: list[Any] = []
        if chunk is None:
            n, (res,) = check_trace(checked, [node], read_trace(bags[storage]), rules, 0.005, seen.append, batch=False)
            got: Any = (n, res)
        else:
            stats: dict[str, int] = {}
            got = check_batch(checked, node, read_trace(bags[storage]), rules, 0.005, seen.append, chunk=chunk,
                              stats=stats)
            assert stats["batched"] > 20
        return repr((got, seen))
    want = run(None)
    for chunk in (3, 8, 61):
        assert run(chunk) == want, chunk
    assert len(carried) > 50 and all(carried)  # blocks with carried events, their kinds the topics' own
