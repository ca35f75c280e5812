"""``ros_discovery_info`` (rmw_dds_common's ``ParticipantEntitiesInfo``):
which ROS node owns which DDS readers and writers.  Its samples decoded
raw, in either GID layout (:func:`decode_participant_info`), encoded
(:func:`encode_participant_info`), and its type as a cyclonedds struct
(:func:`discovery_struct`); names and the participant are :mod:`.dds`'.
"""
from __future__ import annotations

import struct
from dataclasses import dataclass, field
from typing import Any, Iterable

from rclverify.ros.live.dds import DISCOVERY_TYPE, absolute_name, import_cyclonedds


@dataclass
class NodeInfo:
    """One node of a ``ParticipantEntitiesInfo``: namespace, name, and the
    16-byte GUIDs of its readers and writers."""

    namespace: str
    name: str
    readers: list[bytes] = field(default_factory=list)
    writers: list[bytes] = field(default_factory=list)

    @property
    def full_name(self) -> str:
        """``/ns/name`` (``/name`` in the root namespace)."""
        return absolute_name(self.namespace.rstrip("/") + "/" + self.name)


class _Cdr:
    """A little-endian plain-CDR reader (alignment from the data's start)."""

    def __init__(self, data: bytes) -> None:
        self.data, self.pos = data, 0

    def u32(self) -> int:
        self.pos = (self.pos + 3) & ~3
        if self.pos + 4 > len(self.data):
            raise ValueError("truncated")
        (v,) = struct.unpack_from("<I", self.data, self.pos)
        self.pos += 4
        return int(v)

    def raw(self, n: int) -> bytes:
        if self.pos + n > len(self.data):
            raise ValueError("truncated")
        out = self.data[self.pos:self.pos + n]
        self.pos += n
        return bytes(out)

    def string(self) -> str:
        n = self.u32()
        if n == 0 or n > 4096:
            raise ValueError("bad string length")
        return self.raw(n)[:-1].decode("utf-8", errors="replace")


def _decode_info(body: bytes, gid_size: int) -> tuple[bytes, list[NodeInfo]]:
    c = _Cdr(body)

    def gid() -> bytes:
        g = c.raw(gid_size)
        if gid_size > 16 and any(g[16:]):
            raise ValueError("a 24-byte GID is padded with zeros")
        return g[:16]

    part = gid()
    nodes = []
    for _ in range(c.u32()):
        ns, name = c.string(), c.string()
        readers = [gid() for _ in range(c.u32())]
        writers = [gid() for _ in range(c.u32())]
        nodes.append(NodeInfo(ns, name, readers, writers))
    if len(body) - c.pos > 3:  # only the padding to 4 bytes may follow
        raise ValueError("bytes left over")
    return part, nodes


def decode_participant_info(raw: bytes) -> tuple[bytes, list[NodeInfo], int]:
    """``(participant GID, nodes, GID size on the wire)`` of one
    ``ParticipantEntitiesInfo`` sample (with its 4-byte encapsulation
    header), in either GID layout (16 or 24 bytes: module docstring).
    Raises ``ValueError`` when it is neither."""
    if len(raw) < 4 or raw[1] not in (0, 1):
        raise ValueError("not plain CDR")
    if raw[1] == 0:
        raise ValueError("big-endian CDR is not read")
    body = raw[4:]
    errors = []
    for size in (16, 24):
        try:
            gid, nodes = _decode_info(body, size)
            return gid, nodes, size
        except (ValueError, struct.error) as exc:
            errors.append(f"{size}-byte GIDs: {exc}")
    raise ValueError("not a ParticipantEntitiesInfo (" + "; ".join(errors) + ")")


def encode_participant_info(gid: bytes, nodes: Iterable[NodeInfo], gid_size: int = 16) -> bytes:
    """One ``ParticipantEntitiesInfo`` sample as plain little-endian CDR with
    its encapsulation header (the inverse of :func:`decode_participant_info`)."""
    out = bytearray(b"\x00\x01\x00\x00")

    def align() -> None:
        while (len(out) - 4) % 4:
            out.append(0)

    def put_gid(g: bytes) -> None:
        out.extend(g[:16].ljust(gid_size, b"\x00"))

    def put_u32(v: int) -> None:
        align()
        out.extend(struct.pack("<I", v))

    def put_str(s: str) -> None:
        b = s.encode("utf-8") + b"\x00"
        put_u32(len(b))
        out.extend(b)

    put_gid(gid)
    nodes = list(nodes)
    put_u32(len(nodes))
    for n in nodes:
        put_str(n.namespace)
        put_str(n.name)
        put_u32(len(n.readers))
        for g in n.readers:
            put_gid(g)
        put_u32(len(n.writers))
        for g in n.writers:
            put_gid(g)
    align()
    return bytes(out)


def discovery_struct() -> Any:
    """The ``ParticipantEntitiesInfo`` type (16-byte GIDs, Iron's and newer
    layout) as a cyclonedds struct: what the topic is created with.  ROS 2's
    participants match it on the name: rmw_cyclonedds sends no XTypes type
    information, and Fast DDS's (Kilted: the same struct, but no try-construct
    flag on its sequence and array elements) is ignored by the participant
    (:data:`.dds.COMPATIBILITY`).  The samples are read raw, in either layout."""
    import_cyclonedds()
    from cyclonedds.idl import make_idl_struct  # deferred: start-up (loads cyclonedds and more only when called)
    from cyclonedds.idl import types as T  # deferred: start-up (loads cyclonedds and more only when called)
    gid16: Any = T.array[T.uint8, 16]  # type: ignore[misc]
    gid = make_idl_struct("Gid_", "rmw_dds_common::msg::dds_::Gid_", {"data": gid16})
    node = make_idl_struct("NodeEntitiesInfo_", "rmw_dds_common::msg::dds_::NodeEntitiesInfo_", {
        "node_namespace": T.bounded_str[256], "node_name": T.bounded_str[256],  # type: ignore[misc]
        "reader_gid_seq": T.sequence[gid], "writer_gid_seq": T.sequence[gid]})  # type: ignore[misc]
    from rclverify.ros.live.dds_xtypes import as_fast_dds  # deferred: loads cyclonedds' type-object builder
    return as_fast_dds(make_idl_struct("ParticipantEntitiesInfo_", DISCOVERY_TYPE, {
        "gid": gid, "node_entities_info_seq": T.sequence[node]}))  # type: ignore[misc]
