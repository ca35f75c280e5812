"""Which fields of a ROS message a contract skeleton reads, and which it leaves out and why
(``init --from-ros``, docs/ros.md "From ROS field types to RCL").

A skeleton reads a message's base fields (nested messages flattened to
:data:`MAX_DEPTH` levels); arrays, ``header``/``stamp`` and times are left out,
except in a message with no other field: then times' ``sec``/``nanosec`` and
the elements of fixed-size arrays of base types (``kp[0]`` ..., at most
:data:`MAX_FIXED`) are read, so that a message with fields is never ``{}``.
Every field left out is returned with its ROS type and the reason, for the
skeleton's comment: a field is never dropped in silence.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from rclverify.ros.extract.interfaces import ABSENT, TypeTable, describe, elem_type
from rclverify.ros.extract.model import short_type

UNSIGNED = frozenset({"uint8", "uint16", "uint32", "uint64", "byte", "char", "octet"})
SIGNED = frozenset({"int8", "int16", "int32", "int64"})
MAX_DEPTH = 5  # nested messages flattened (a service request wrapping a PoseWithCovarianceStamped: 5)
MAX_FIXED = 16  # elements of a fixed-size array read one by one when nothing else is
# rosidl's placeholder of an empty message (``std_msgs/Empty``: ``uint8
# structure_needs_at_least_one_member``, ROS 2 IDL mapping) is no field of it
PLACEHOLDER = "structure_needs_at_least_one_member"
_STAMPS = {"header": "the message's header (time stamp, frame id), which a skeleton does not read",
           "stamp": "a time stamp, which a skeleton does not read"}
_ONLY_ALONE = "read only in a message with no other field"


def rcl_scalar(ros_type: str) -> str | None:
    """The RCL scalar for a ROS base type (``float64`` -> ``REAL``, ``int16`` ->
    ``INTEGER``, ``uint8`` -> ``NATURAL``, ``bool``, ``string``), ``None`` for others."""
    t = ros_type.split("<=")[0]
    if t in ("float32", "float64"):
        return "REAL"
    if t in SIGNED:
        return "INTEGER"
    if t in UNSIGNED:
        return "NATURAL"
    if t == "bool":
        return "BOOL"
    if t in ("string", "wstring"):
        return "STRING"
    return None


@dataclass
class Reading:
    """The fields a skeleton reads of one message, ``kept`` as ``(path, ROS
    type)`` in order, and those it leaves out, ``left`` as ``(path, ROS type as
    written, why)``."""

    kept: list[tuple[str, str]] = field(default_factory=list)
    left: list[tuple[str, str, str]] = field(default_factory=list)


def read_fields(table: TypeTable, msg: str) -> Reading:
    """The reading of message ``msg`` (``pkg/msg/T``, a service's ``pkg/srv/T_Request`` ...):
    its base fields; when it has none, also its times and fixed-size arrays
    (``whole``).  An unknown message, or one of an absent package, is an empty
    reading; never raises on a known table."""
    part = Reading()
    _walk(table, msg, False, "", 0, part)
    if part.kept:
        return part
    whole = Reading()
    _walk(table, msg, True, "", 0, whole)
    return whole


def _shown(desc: Any) -> str:
    """A field's ROS type as a ``.msg`` file writes it (``float64[]``, ``far_msgs/Blip``)."""
    d = describe(desc)
    return short_type(d["type"]) + (d["array"] or "")


def _fixed_size(desc: Any) -> int:
    """The element count of a fixed-size array field, 0 for any other field."""
    kind, detail = desc
    return detail[1] if int(kind) == 3 and isinstance(detail[1], int) else 0


def _walk(table: TypeTable, msg: str, whole: bool, prefix: str, depth: int, out: Reading) -> None:
    """Add ``msg``'s fields under ``prefix`` to ``out`` (nested messages recursively)."""
    info = table.get(msg)
    for name, desc in info.fields if info is not None else ():
        if name == PLACEHOLDER:
            continue
        t, arr = elem_type(desc)
        path = prefix + name
        if name in _STAMPS:
            out.left.append((path, _shown(desc), _STAMPS[name]))
        elif arr:
            _array(t, desc, whole, path, out)
        elif rcl_scalar(t):
            out.kept.append((path, t))
        else:
            why = _why_not_nested(table, t, whole, depth)
            if why is None:
                _walk(table, t, whole, path + ".", depth + 1, out)
            else:
                out.left.append((path, _shown(desc), why))


def _array(t: str, desc: Any, whole: bool, path: str, out: Reading) -> None:
    """An array field: its elements read one by one, or the field left out with why."""
    size = _fixed_size(desc)
    if whole and rcl_scalar(t) and 0 < size <= MAX_FIXED:  # float64[3]: one field per element
        out.kept.extend((f"{path}[{i}]", t) for i in range(size))
        return
    if not size:
        why = "an array of variable length: no single RCL value holds it"
    elif not rcl_scalar(t):
        why = "an array of messages: no single RCL value holds it"
    elif size > MAX_FIXED:
        why = f"a fixed-size array of {size} elements (at most {MAX_FIXED} are read one by one)"
    else:
        why = f"a fixed-size array: its elements are {_ONLY_ALONE}"
    out.left.append((path, _shown(desc), why))


def _why_not_nested(table: TypeTable, t: str, whole: bool, depth: int) -> str | None:
    """Why the nested field of type ``t`` is not read, or ``None`` when its fields are."""
    if "/" not in t:
        return f"no RCL type reads a ROS 1 {t}" if t in ("time", "duration") else f"no RCL type reads {t}"
    info = table.get(t)
    if info is None:
        return f"{short_type(t)} is defined by no scanned or standard package"
    if info.origin == ABSENT:
        return (f"its interface package {t.split('/')[0]} is in neither the scanned tree nor an installed ROS: "
                f"its fields are unknown")
    if not whole and t.startswith("builtin_interfaces/"):
        return f"a time: its sec and nanosec are {_ONLY_ALONE}"
    if depth + 1 > MAX_DEPTH:
        return f"nested deeper than {MAX_DEPTH} levels"
    return None
