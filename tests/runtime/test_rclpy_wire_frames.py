"""The rclpy agent's stream read in chunks (runtime/rclpy_source/wire.py, FrameBuffer): the monitor reads
the pipe a large chunk at a time, so a frame may be split anywhere; the frames come out whole and in order."""
from __future__ import annotations

import io

from rclverify.runtime.rclpy_source.wire import FrameBuffer, json_frame, parse_sample, read_frame, sample_frame


def _stream() -> tuple[bytes, list[tuple[bytes, bytes]]]:
    frames = [json_frame({"what": "hello", "node": "n"})]
    frames += [sample_frame(k % 3, 10 + k, 20 + k, k + 1, bytes([k]) * 16, b"\0\1\0\0" + bytes(k * 7))
               for k in range(40)]
    frames.append(json_frame({"what": "stopped"}))
    data = b"".join(frames)
    whole = []
    s = io.BytesIO(data)
    while (f := read_frame(s)) is not None:
        whole.append(f)
    return data, whole


def test_frames_split_at_any_byte_come_out_whole_and_in_order() -> None:
    data, whole = _stream()
    assert len(whole) == 42
    for size in (1, 2, 5, 13, 64, 1000, len(data)):
        buf = FrameBuffer()
        got = [f for at in range(0, len(data), size) for f in buf.feed(data[at:at + size])]
        assert got == whole, size
        assert buf.left() == 0
    assert parse_sample(whole[5][1])[:4] == (4 % 3, 14, 24, 5)


def test_a_stream_cut_inside_a_frame_leaves_its_bytes_waiting() -> None:
    data, whole = _stream()
    buf = FrameBuffer()
    got = buf.feed(data[:-3])  # the last frame ("stopped") lacks its last three bytes
    assert got == whole[:-1]
    assert buf.left() == len(whole[-1][1]) + 5 - 3
    assert buf.feed(data[-3:]) == whole[-1:] and buf.left() == 0  # control: the rest completes it
