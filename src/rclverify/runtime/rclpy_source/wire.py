"""The frames between the live monitor and its rclpy agent (standard library only).

The agent (:mod:`.agent`) runs in a ROS 2 Python and imports this module as
a top-level module (its folder is the script's); the monitor imports it as
``rclverify.runtime.rclpy_source.wire``.  Both directions are byte streams
(the agent's stdout and stdin):

* **agent -> monitor**: frames of a one-byte kind, a ``uint32`` length (big
  endian) and the payload.  ``S``: a sample, :data:`SAMPLE` (tap id,
  source and receipt stamps in ns since the epoch, the writer's sequence
  number, 0 unknown) then the 16-byte publisher GID, then the serialized
  message as rmw handed it over (CDR with its encapsulation header, as on
  the wire and in a bag); ``J``: a JSON object (``hello``, ``graph``,
  ``tap``, ``error``, ``description``: its ``what`` key says which).  A
  ``description`` answers a ``describe``: ``type``, ``hash`` (the
  publisher's), ``candidates`` (``[{"from": where, "description": {...}}]``,
  each a type_description_interfaces/msg/TypeDescription as a dict:
  ``type_description`` and ``referenced_type_descriptions``, each
  ``{"type_name", "fields": [{"name", "type": {"type_id", "capacity",
  "string_capacity", "nested_type_name"}, "default_value"}]}``, rosidl's
  ``.json`` form) and ``failures`` (why other sources gave none, as text).
* **monitor -> agent**: JSON lines (``op``: ``tap``, ``watch``,
  ``writer``, ``write``, ``describe`` (``type``, ``hash``, and the
  publisher's ``node`` and ``ns``), ``start`` (``linger``: the seconds the
  agent lets samples gather after a round that took some), ``stop``).
"""
from __future__ import annotations

import json
import struct
from typing import IO, Mapping

#: the header of every frame: kind (1 byte), payload length
HEADER = struct.Struct(">cI")
#: a sample's fixed part: tap id, source stamp (ns), receipt stamp (ns), publication sequence number
SAMPLE = struct.Struct(">IqqQ")
GID_BYTES = 16


def sample_frame(tap: int, source_ns: int, received_ns: int, seq: int, gid: bytes, raw: bytes) -> bytes:
    """One ``S`` frame (module docstring); ``gid`` is cut or padded to 16 bytes."""
    body = SAMPLE.pack(tap, source_ns, received_ns, seq) + gid[:GID_BYTES].ljust(GID_BYTES, b"\0") + raw
    return HEADER.pack(b"S", len(body)) + body


def json_frame(obj: Mapping[str, object]) -> bytes:
    """One ``J`` frame holding ``obj``."""
    body = json.dumps(obj, separators=(",", ":")).encode()
    return HEADER.pack(b"J", len(body)) + body


def read_frame(stream: IO[bytes]) -> tuple[bytes, bytes] | None:
    """The next frame's kind and payload, ``None`` at the end of the stream.
    Raises ``ValueError`` for a stream cut inside a frame."""
    head = _read(stream, HEADER.size)
    if not head:
        return None
    if len(head) < HEADER.size:
        raise ValueError("the agent's stream ended inside a frame header")
    kind, size = HEADER.unpack(head)
    body = _read(stream, size)
    if len(body) < size:
        raise ValueError("the agent's stream ended inside a frame")
    return kind, body


class FrameBuffer:
    """Frames cut from a byte stream read in chunks of any size (the monitor reads the agent's pipe a
    large chunk at a time, so one read hands over a batch of frames): :meth:`feed` a chunk, get the
    whole frames it completes, in order; the rest waits for the next chunk."""

    def __init__(self) -> None:
        self._buf = bytearray()

    def feed(self, chunk: bytes) -> list[tuple[bytes, bytes]]:
        """The frames (kind, payload) complete once ``chunk`` is added."""
        buf = self._buf
        buf += chunk
        out: list[tuple[bytes, bytes]] = []
        at, end, head = 0, len(buf), HEADER.size
        while end - at >= head:
            kind, size = HEADER.unpack_from(buf, at)
            if end - at - head < size:
                break
            out.append((kind, bytes(buf[at + head:at + head + size])))
            at += head + size
        del buf[:at]
        return out

    def left(self) -> int:
        """Bytes of a frame not yet complete (0 when the stream ended on a frame boundary)."""
        return len(self._buf)


def parse_sample(body: bytes) -> tuple[int, int, int, int, bytes, bytes]:
    """An ``S`` frame's payload: (tap id, source ns, received ns, sequence number, gid, raw)."""
    tap, source_ns, received_ns, seq = SAMPLE.unpack_from(body)
    gid = body[SAMPLE.size:SAMPLE.size + GID_BYTES]
    return tap, source_ns, received_ns, seq, gid, body[SAMPLE.size + GID_BYTES:]


def _read(stream: IO[bytes], n: int) -> bytes:
    parts = []
    while n > 0:
        chunk = stream.read(n)
        if not chunk:
            break
        parts.append(chunk)
        n -= len(chunk)
    return b"".join(parts)


__all__ = ["FrameBuffer", "GID_BYTES", "HEADER", "SAMPLE", "json_frame", "parse_sample", "read_frame", "sample_frame"]
