"""A sample's plain CDR read straight into its fields, without the struct.

The live monitor decodes every sample it hears: the struct of the
contract's type (:mod:`.types`) reads the bytes through Cyclone's Python
deserializer, a machine per member, into a dataclass, which
:func:`~.types.to_fields` then turns into dicts and lists.  At 1000
messages/s that was about a quarter of the engine thread's CPU.
:func:`read_fields` gives the same value, ``to_fields(struct.deserialize(raw))``,
key for key and type for type, reading the bytes once with precompiled
:class:`struct.Struct` formats; a struct whose members are all numbers
(``builtin_interfaces/Time``, ``geometry_msgs/Point``) is one unpack where
its start is aligned as its widest member.

Its readers are made, once per struct class, from the very machines
Cyclone's deserializer runs (``cls.__idl__.v1_machine``), so both read the
same layout: plain CDR, XCDR1 (OMG DDS-XTypes 1.3, 7.4.3.5: each primitive
aligned to its size, at most 8, from the end of the 4-byte encapsulation
header; a string a ``uint32`` length counting its closing NUL, then UTF-8;
a sequence a ``uint32`` count then its elements), little or big endian as
the encapsulation header says.  Everything else goes to Cyclone's
deserializer as before, so its result or its error is the one it always
gave: XCDR2 bytes (encapsulation kinds above 3), :class:`~.types.Declared`
bytes (read in the publisher's definition), a machine this module does not
read (unions, enums, optionals, delimited or mutable types, which ROS 2
messages do not make), an empty string length, and any sample whose bytes
end early or do not decode.
"""
from __future__ import annotations

import struct
from typing import Any, Callable

from rclverify.runtime.dds.sample_fields import HEADER_FIELDS, PLACEHOLDER, WIDE, to_fields, wide_text

#: a reader: (the sample's bytes, the position) -> (the value as :func:`~.types.to_fields` gives it, the next position)
Reader = Callable[[bytes, int], "tuple[Any, int]"]
#: the encapsulation header's length: alignment counts from its end
_BODY = 4
#: the widest alignment of XCDR1
_ALIGN_MAX = 8
#: per struct class, its readers (big endian, little endian: indexed by the encapsulation kind's low byte,
#: CDR_BE 0, CDR_LE 1), or ``None`` when it has a member not read here
_READERS: dict[type, tuple[Reader, Reader] | None] = {}


class _Declined(Exception):
    """A machine or a sample this module leaves to Cyclone's deserializer (module docstring)."""


def read_fields(cls: Any, raw: bytes) -> Any:
    """``to_fields(cls.deserialize(raw))``: the fields of the sample ``raw``
    (serialized, its encapsulation header first) of struct class ``cls``
    (:meth:`~.types.TypeBook.struct`).  Raises what Cyclone's deserializer
    raises for bytes that are not that type."""
    readers = _READERS[cls] if cls in _READERS else _compile(cls)
    if readers is not None and len(raw) >= _BODY and raw[1] <= 1 and type(raw) is bytes:
        try:
            return readers[raw[1]](raw, _BODY)[0]
        except Exception:  # noqa: BLE001 - short, malformed or unusual bytes: Cyclone's reading decides
            pass
    return to_fields(cls.deserialize(raw))


def _compile(cls: Any) -> tuple[Reader, Reader] | None:
    """The readers of struct class ``cls`` (big endian, little endian), ``None`` when one of its machines is not
    read here."""
    try:
        idl = cls.__idl__
        idl.populate()
        machine = idl.v1_machine
        readers: tuple[Reader, Reader] | None = (_machine(machine, ">"), _machine(machine, "<"))
    except _Declined:
        readers = None
    _READERS[cls] = readers
    return readers


def _align(p: int, a: int) -> int:
    """Position ``p`` aligned to ``a`` bytes (at most 8) from the end of the encapsulation header."""
    a = min(a, _ALIGN_MAX)
    return ((p - _BODY + a - 1) & ~(a - 1)) + _BODY


def _machine(m: Any, e: str) -> Reader:
    """The reader of one of Cyclone's deserializer machines (``cyclonedds.idl._machinery``), byte order ``e``."""
    kind = type(m).__name__
    if kind == "InstanceMachine":
        if m.use_version_2:
            raise _Declined(kind)
        idl = m.type.__idl__
        idl.populate()
        return _struct(idl.v1_machine, e)
    if kind == "StructMachine":
        return _struct(m, e)
    if kind == "PrimitiveMachine":
        return _primitive(struct.Struct(e + m.code), m.alignment, m.size)
    if kind == "StringMachine":
        return _string(struct.Struct(e + "I"))
    if kind == "PlainCdrV2ArrayOfPrimitiveMachine":
        return _primitive_array(struct.Struct(e + m.code), m.alignment, m.size)
    if kind == "PlainCdrV2SequenceOfPrimitiveMachine":
        return _primitive_sequence(e, m.code, m.alignment, m.size)
    if kind == "ArrayMachine" and not m.add_size_header:
        return _array(_machine(m.submachine, e), m.size)
    if kind == "SequenceMachine" and not m.add_size_header:
        return _sequence(_machine(m.submachine, e), struct.Struct(e + "I"))
    if kind == "BytesMachine":
        return _bytes(struct.Struct(e + "I"))
    if kind == "ByteArrayMachine":
        return _byte_array(m.size)
    raise _Declined(kind)


def _primitive(s: struct.Struct, alignment: int, size: int) -> Reader:
    unpack = s.unpack_from

    def read(d: bytes, p: int) -> tuple[Any, int]:
        p = _align(p, alignment)
        return unpack(d, p)[0], p + size
    return read


def _string(count: struct.Struct) -> Reader:
    unpack = count.unpack_from

    def read(d: bytes, p: int) -> tuple[Any, int]:
        p = _align(p, 4)
        n = unpack(d, p)[0]
        end = p + 3 + n  # the closing NUL's position
        if n == 0 or end >= len(d):
            raise _Declined("string")
        return d[p + 4:end].decode("utf-8"), end + 1
    return read


def _bytes(count: struct.Struct) -> Reader:
    unpack = count.unpack_from

    def read(d: bytes, p: int) -> tuple[Any, int]:
        p = _align(p, 4)
        n = unpack(d, p)[0]
        end = p + 4 + n
        if end > len(d):
            raise _Declined("bytes")
        return list(d[p + 4:end]), end
    return read


def _byte_array(size: int) -> Reader:
    def read(d: bytes, p: int) -> tuple[Any, int]:
        if p + size > len(d):
            raise _Declined("byte array")
        return list(d[p:p + size]), p + size
    return read


def _primitive_array(s: struct.Struct, alignment: int, size: int) -> Reader:
    unpack = s.unpack_from

    def read(d: bytes, p: int) -> tuple[Any, int]:
        p = _align(p, alignment)
        return list(unpack(d, p)), p + size
    return read


def _primitive_sequence(e: str, code: str, alignment: int, size: int) -> Reader:
    count = struct.Struct(e + "I").unpack_from

    def read(d: bytes, p: int) -> tuple[Any, int]:
        p = _align(p, 4)
        n = count(d, p)[0]
        p += 4
        if not n:
            return [], p
        p = _align(p, alignment)
        return list(struct.unpack_from(f"{e}{n}{code}", d, p)), p + n * size
    return read


def _array(sub: Reader, size: int) -> Reader:
    def read(d: bytes, p: int) -> tuple[Any, int]:
        out = []
        for _ in range(size):
            v, p = sub(d, p)
            out.append(v)
        return out, p
    return read


def _sequence(sub: Reader, count: struct.Struct) -> Reader:
    unpack = count.unpack_from

    def read(d: bytes, p: int) -> tuple[Any, int]:
        p = _align(p, 4)
        n = unpack(d, p)[0]
        p += 4
        if n > len(d):  # more elements than bytes: not this type (Cyclone's reading says how)
            raise _Declined("sequence")
        out = []
        for _ in range(n):
            v, p = sub(d, p)
            out.append(v)
        return out, p
    return read


def _struct(m: Any, e: str) -> Reader:
    """A struct's reader: its members in order, into a dict of the members :func:`~.types.to_fields` keeps
    (the request header and rosidl's placeholder left out, a ``wstring`` as its text)."""
    names = list(m.members_machines)
    if names != list(getattr(m.type, "__dataclass_fields__", {})):
        raise _Declined("struct members")
    wide = getattr(m.type, WIDE, {})
    keep = [n not in HEADER_FIELDS and n != PLACEHOLDER for n in names]
    machines = list(m.members_machines.values())
    fused = _fused(names, keep, machines, e) if not wide else None
    if fused is not None:
        return fused
    members = [(n, k, wide.get(n), _machine(mm, e)) for n, k, mm in zip(names, keep, machines)]

    def read(d: bytes, p: int) -> tuple[Any, int]:
        out: dict[str, Any] = {}
        for name, kept, depth, sub in members:
            v, p = sub(d, p)
            if kept:
                out[name] = v if depth is None else wide_text(v, depth)
        return out, p
    return read


def _fused(names: list[str], keep: list[bool], machines: list[Any], e: str) -> Reader | None:
    """A struct of numbers only read in one unpack where its start is aligned to its widest member (else
    member by member); ``None`` for a struct with another member."""
    if not machines or any(type(mm).__name__ != "PrimitiveMachine" for mm in machines):
        return None
    widest = min(max(mm.alignment for mm in machines), _ALIGN_MAX)
    fmt, at = e, 0
    for mm in machines:
        pad = -at % min(mm.alignment, _ALIGN_MAX)
        fmt += "x" * pad + mm.code
        at += pad + mm.size
    whole = struct.Struct(fmt).unpack_from
    first = machines[0].alignment
    slow = [(n, k, _machine(mm, e)) for n, k, mm in zip(names, keep, machines)]
    every = all(keep)

    def read(d: bytes, p: int) -> tuple[Any, int]:
        p = _align(p, first)
        if (p - _BODY) % widest == 0:
            values = whole(d, p)
            if every:
                return dict(zip(names, values)), p + at
            return {n: v for n, k, v in zip(names, keep, values) if k}, p + at
        out: dict[str, Any] = {}
        for name, k, sub in slow:
            v, p = sub(d, p)
            if k:
                out[name] = v
        return out, p
    return read


__all__ = ["read_fields"]
