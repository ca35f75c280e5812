"""The bag blocks' byte-level decoding (traces/bag_raw.py ``gather``, traces/bag_blocks.py) against
per-message references: ``struct.unpack_from`` for each gathered value, ``_string`` (the one-message
check of a ``std_msgs/msg/String``) for each String message a block decodes in bulk.

Random buffers and offsets, and random String messages chosen to be hard for the bulk comparison
(many distinct texts, texts sharing their first bytes, lengths around the 8-byte words and past the
64-byte limit, padded, big-endian, not UTF-8, holding a NUL, lengths that disagree with the bytes);
the comparison must fail when the bulk decoder is broken on purpose (its masks or its gather).
"""
from __future__ import annotations

import random
import struct
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from rclverify.traces import bag_blocks
from rclverify.traces.bag_blocks import BagBlock, _string
from rclverify.traces.bag_raw import RawMessages, gather


@pytest.mark.parametrize("seed", range(4))
def test_gather_equals_unpack_from(seed: int) -> None:
    rnd = random.Random(seed)
    buf = bytes(rnd.getrandbits(8) for _ in range(rnd.randint(8, 600)))
    for fmt, dtype in (("<Q", "<u8"), ("<H", "<u2"), ("<d", "<f8"), (">I", ">u4"), ("<q", "<i8")):
        size = struct.calcsize(fmt)
        at = sorted(rnd.randrange(0, len(buf) - size + 1) for _ in range(rnd.randint(0, 50)))
        got = gather(buf, np.array(at, dtype=np.int64), dtype)
        want = [struct.unpack_from(fmt, buf, a)[0] for a in at]
        assert got.dtype == np.dtype(dtype)
        np.testing.assert_array_equal(got, np.array(want, dtype=dtype))
    with pytest.raises(IndexError):  # a value past the buffer's end is never read
        gather(buf, np.array([len(buf) - 7]), "<u8")


def _message(rnd: random.Random, prefixes: list[bytes]) -> bytes:
    text = rnd.choice(prefixes) + bytes(rnd.choice(b"abz\xc3\xa9") for _ in range(rnd.choice([0, 0, 1, 2, 7, 8, 9, 70])))
    kind = rnd.random()
    n = len(text) + 1
    if kind < 0.04:
        n += rnd.choice([-1, 1, 5])  # a length that disagrees with the bytes
    raw = b"\x00\x01" + bytes([0, rnd.choice([0, 0, 1])]) + struct.pack("<I", n) + text + b"\x00"
    if kind > 0.97:
        raw += b"\x00"  # padded
    elif kind > 0.94:
        raw = b"\x00\x00" + raw[2:]  # big-endian encapsulation
    elif kind > 0.92:
        raw = raw[:-1] + b"\x01"  # no terminator
    elif kind > 0.90:
        raw = raw[:8] + b"\x00" + raw[9:]  # a NUL inside the text
    return raw


def _strings(seed: int) -> tuple[list[bytes], RawMessages]:
    rnd = random.Random(seed)
    prefixes = [b"", b"green", b"orange", b"abcdefgh", b"abcdefg", b"\xff\xfe"] + \
        [bytes(rnd.choice(b"xy") for _ in range(rnd.randint(1, 12))) for _ in range(rnd.choice([2, 80]))]
    msgs = [_message(rnd, prefixes) for _ in range(rnd.randint(1, 400))]
    lens = np.array([len(m) for m in msgs], dtype=np.int64)
    stop = np.cumsum(lens)
    conn = type("Conn", (), {"topic": "/status", "msgtype": bag_blocks.STRING})()
    raw = RawMessages([conn], np.zeros(len(msgs), dtype=np.int64), np.arange(len(msgs), dtype=np.int64),
                      b"".join(msgs), stop - lens, stop)
    return msgs, raw


def _mismatches(seed: int) -> int:
    """Rows of a random block of String messages whose bulk-decoded text (or its absence) differs
    from ``_string`` of the message alone."""
    msgs, raw = _strings(seed)
    block = BagBlock(Path("x"), None, raw, 0)
    block._decode_strings(np.arange(len(msgs)), {})
    bad = 0
    for i, m in enumerate(msgs):
        want: Any = _string(m)
        got: Any = block._texts[block._which[i]] if block._is_str[i] else False
        bad += got != want or type(got) is not type(want)
    return bad


@pytest.mark.parametrize("seed", range(30))
def test_bulk_strings_equal_one_at_a_time(seed: int) -> None:
    assert _mismatches(seed) == 0


def test_bulk_strings_check_fails_on_seeded_mistakes(monkeypatch: pytest.MonkeyPatch) -> None:
    with monkeypatch.context() as m:  # every byte after a message's end compared too: equal texts look distinct,
        m.setattr(bag_blocks, "_MASKS", np.zeros(9, dtype=np.uint64))  # and with no byte kept all look the same
        assert sum(_mismatches(s) for s in range(30)) > 0
    with monkeypatch.context() as m:  # the words read one byte too far
        m.setattr(bag_blocks, "gather", lambda buf, at, dtype: gather(buf + bytes(8), at + 1, dtype))
        assert sum(_mismatches(s) for s in range(30)) > 0
