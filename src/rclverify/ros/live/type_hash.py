"""The ROS 2 type hash of a message type (REP-2011, ``RIHS01_<sha256>``),
computed from the definitions the workspace reads, as ROS 2 Iron and newer
announce it in each endpoint's USER_DATA (``typehash=...;``).

The rule (REP-2011 "Type Description Distribution", and the type
description messages of ``type_description_interfaces``): the hashed text is
the JSON of ``{"type_description": T, "referenced_type_descriptions": [R,
...]}`` (Python's default separators), where a description is ``{"type_name":
"pkg/msg/T", "fields": [...]}`` and each field ``{"name", "type": {"type_id",
"capacity", "string_capacity", "nested_type_name"}}`` (default values and
constants are not part of it); the referenced descriptions are every nested
type, transitively, sorted by name; a type without fields has the one field
``uint8 structure_needs_at_least_one_member``.  A field's ``type_id`` is the
``FieldType`` constant of its element (``int8`` 2 ... ``double`` 11,
``bool`` 15, ``byte`` 16, a ``.msg`` file's ``char`` 3 (it is ``uint8`` in
ROS 2's interface mapping), ``string`` 17, ``wstring`` 18,
bounded ``string`` 21, bounded ``wstring`` 22, a nested type 1) plus 48 for a
fixed array, 96 for a bounded sequence, 144 for an unbounded one.

rosbags' own hash gives ``char`` the IDL ``char``'s constant (13), which
changes the hash of every type that holds one; this module gives it ``uint8``'s,
as rosidl does for a ``.msg`` definition.
"""
from __future__ import annotations

import hashlib
import json
from typing import Any, Callable, Sequence

from rclverify.ros.extract.shapes import FieldDescription, TypeDescription

_IDS = {"int8": 2, "uint8": 3, "int16": 4, "uint16": 5, "int32": 6, "uint32": 7, "int64": 8, "uint64": 9,
        "float32": 10, "float64": 11, "float128": 12, "char": 3, "wchar": 14, "bool": 15, "byte": 16,
        "octet": 16, "string": 17, "wstring": 18}
_BOUNDED = {"string": 21, "wstring": 22}
_EMPTY = [("structure_needs_at_least_one_member", (1, ("uint8", 0)))]
Fields = Sequence[tuple[str, Any]]


class UnknownType(KeyError):
    """A nested type the definitions do not hold."""


def _element(desc: Any, visit: Callable[[str], None]) -> tuple[int, int, str]:
    """``(type_id, string_capacity, nested_type_name)`` of an element description."""
    kind, detail = int(desc[0]), desc[1]
    if kind == 1:
        base, bound = detail
        if bound and base in _BOUNDED:
            return _BOUNDED[base], int(bound), ""
        return _IDS[base], 0, ""
    name = str(detail)
    for wide in ("wstring", "string"):  # a parser that gives a (bounded) string as a named type
        if name == wide or name.endswith("/" + wide):
            return _IDS[wide], 0, ""
    visit(name)
    return 1, 0, name


def _field(name: str, desc: Any, visit: Callable[[str], None]) -> FieldDescription:
    kind = int(desc[0])
    increment = capacity = 0
    elem = desc
    if kind == 3:
        increment, capacity, elem = 48, int(desc[1][1]), desc[1][0]
    elif kind == 4:
        bound = int(desc[1][1] or 0)
        increment, capacity, elem = (96, bound, desc[1][0]) if bound else (144, 0, desc[1][0])
    tid, string_capacity, nested = _element(elem, visit)
    return {"name": name, "type": {"type_id": tid + increment, "capacity": capacity,
                                   "string_capacity": string_capacity, "nested_type_name": nested}}


def rihs01(name: str, fields_of: Callable[[str], Fields | None]) -> str:
    """The type hash of message ``name`` (``pkg/msg/T``); ``fields_of(type)``
    gives a type's fields as rosbags' parser describes them (``(field name,
    (node kind, detail))``, kinds 1 base, 2 named, 3 array, 4 sequence) or
    ``None`` when it is unknown.  Raises :class:`UnknownType` naming a type
    that is not defined."""
    described: dict[str, TypeDescription] = {}
    todo = [name]

    def visit(t: str) -> None:
        if t not in described and t not in todo:
            todo.append(t)
    while todo:
        t = todo.pop()
        fields = fields_of(t)
        if fields is None:
            raise UnknownType(t)
        described[t] = {"type_name": t, "fields": [_field(n, d, visit) for n, d in (list(fields) or _EMPTY)]}
    doc = {"type_description": described[name],
           "referenced_type_descriptions": [d for t, d in sorted(described.items()) if t != name]}
    return "RIHS01_" + hashlib.sha256(json.dumps(doc).encode()).hexdigest()


__all__ = ["UnknownType", "rihs01"]
