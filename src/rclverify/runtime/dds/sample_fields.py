"""A received Cyclone DDS sample of a :class:`~.types.TypeBook` struct as
the fields the monitor reads (:func:`to_fields`), the request identity of a
service part (:func:`request_id`), and the struct members that carry no
field of the ROS 2 type: rmw_cyclonedds' request header
(:data:`HEADER_FIELDS`) and rosidl's placeholder member of a type without
fields (:data:`PLACEHOLDER`).  A ``wstring`` travels as its 4-byte code
units (:mod:`.types`); :data:`WIDE` names a struct's such fields and
:func:`wide_text` / :func:`wide_units` turn code units into text and back.
"""
from __future__ import annotations

from typing import Any

#: rmw_cyclonedds' request header, as the first members of a service part's struct
HEADER_FIELDS = ("client_guid_", "sequence_number_")
#: rosidl's one member of a type without fields (module docstring)
PLACEHOLDER = "structure_needs_at_least_one_member"
#: the class attribute naming a struct's wstring fields: field -> how many arrays or sequences hold the text
WIDE = "__rclverify_wstrings__"


def wide_depth(desc: Any) -> int | None:
    """0 for a ``wstring`` field description, 1 for an array or sequence of them; ``None`` otherwise."""
    kind, detail = int(desc[0]), desc[1]
    if kind == 2:
        return 0 if str(detail).endswith("/wstring") else None
    if kind in (3, 4):
        inner = wide_depth(detail[0])
        return None if inner is None else inner + 1
    return None


def wide_text(units: Any, depth: int) -> Any:
    """A wstring's code units as text (``depth`` arrays or sequences of them: lists of text)."""
    if depth:
        return [wide_text(u, depth - 1) for u in units]
    return "".join(chr(c) if 0 <= c <= 0x10FFFF and not 0xD800 <= c <= 0xDFFF else "\ufffd" for c in units)


def wide_units(text: Any, depth: int) -> Any:
    """The inverse of :func:`wide_text`."""
    if depth:
        return [wide_units(t, depth - 1) for t in text]
    return [ord(c) for c in str(text)] if isinstance(text, str) else list(text)


#: the types a received value is as it is (a number, a text, a Boolean)
_PLAIN = frozenset((float, int, str, bool, type(None)))
#: per struct class, its fields as :func:`to_fields` gives them: (name, wstring depth or None); None: no struct
_PLANS: dict[type, tuple[tuple[str, int | None], ...] | None] = {}


def _plan(cls: type) -> tuple[tuple[str, int | None], ...] | None:
    fs = getattr(cls, "__dataclass_fields__", None)
    wide = getattr(cls, WIDE, {})
    plan = None if fs is None else tuple((k, wide.get(k)) for k in fs if k not in HEADER_FIELDS and k != PLACEHOLDER)
    _PLANS[cls] = plan
    return plan


def to_fields(sample: Any) -> Any:
    """A received struct as JSON-ready data: a dict per struct (the request
    header and rosidl's placeholder member left out), lists for arrays and
    sequences (an array of bytes as a list of ints), as the bag reader
    gives a ROS 2 bag's message (``traces/bag.py``).  A struct's fields are
    listed once per class (the live monitor decodes every sample)."""
    cls = type(sample)
    if cls in _PLAIN:
        return sample
    plan = _PLANS[cls] if cls in _PLANS else _plan(cls)
    if plan is not None:
        out: dict[str, Any] = {}
        for k, depth in plan:
            v = getattr(sample, k)
            out[k] = wide_text(v, depth) if depth is not None else v if type(v) in _PLAIN else to_fields(v)
        return out
    if isinstance(sample, (bytes, bytearray)):
        return list(sample)
    if isinstance(sample, (list, tuple)):
        return [x if type(x) in _PLAIN else to_fields(x) for x in sample]
    return sample


def request_id(sample: Any) -> tuple[int, int]:
    """``(client writer handle, sequence number)`` of a request or reply struct:
    the identity that pairs a reply with its request."""
    return int(getattr(sample, HEADER_FIELDS[0])), int(getattr(sample, HEADER_FIELDS[1]))


__all__ = ["HEADER_FIELDS", "PLACEHOLDER", "WIDE", "request_id", "to_fields", "wide_depth", "wide_text", "wide_units"]
