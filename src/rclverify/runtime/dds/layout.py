"""Whether a publisher's type has the layout of the contract's type: what the
live monitor decides before it counts a publisher as heard, and for each
sample, which publisher it came from (:mod:`.dds_bus`).

DDS discovery tells a publisher's type name; for the layout, two sources:

* **the XTypes type identifier** (DDS-XTypes 1.3, 7.3.4), which Cyclone DDS
  publishers announce: identical to the contract's struct's identifier, the
  layout is the same; otherwise the publisher's type object is fetched
  (Cyclone's type lookup, :func:`cyclonedds.dynamic.get_types_for_typeid`)
  and compared with the contract's struct member by member: names, in
  order, and types (primitive kind, array length, sequence, nested struct;
  the bounds of sequences and strings are not compared: XCDR1 writes the
  same bytes whatever the bound).  Identifiers differ for reasons that do
  not change the bytes (flags, annotations), so they are never compared
  alone.  The first member that differs is named;
* **the ROS 2 type hash** (``typehash=RIHS01_...;`` in USER_DATA, REP-2011:
  a SHA-256 over the type description, fields and nested types, the same
  whichever middleware computes it), which every ROS 2 publisher from Iron
  on announces, Fast DDS's included (whose type information the monitor's
  participant ignores, :data:`rclverify.ros.live.dds.COMPATIBILITY`): compared
  with the hash of the contract's type as rosbags computes it from the
  same definitions.  A hash does not say which field differs: the warning
  says the definitions differ, gives both hashes, and what to do (the
  robot's ``.msg`` with ``--interfaces``, or the rclpy source, which reads
  the publisher's own definition).

A publisher that announces neither (ROS 2 Humble, plain DDS) is taken at
its type name, as ROS 2's middlewares take each other.
"""
from __future__ import annotations

import time
import typing
from typing import Any, Callable

SAME, OTHER, PENDING = "same", "other", "pending"
#: seconds a type identifier may stay unresolved (type lookup under way); past it, Cyclone's own
#: assignability check alone decides whether the reader matches, and no layout warning is said
RESOLVE_GRACE_S = 5.0
_PLAIN = {str: "string", bool: "bool", int: "int64", float: "float64"}


def shape(ann: Any) -> Any:
    """The layout of one member annotation of a cyclonedds IDL class: a
    primitive's name (``float64``, ``string``), ``("sequence", elem)``,
    ``("array", n, elem)`` or ``("struct", ((name, shape), ...))``."""
    meta = getattr(ann, "__metadata__", ())
    if meta:
        tag = meta[0]
        if isinstance(tag, str):
            return tag
        kind = type(tag).__name__
        if kind == "sequence":
            return ("sequence", shape(tag.subtype))
        if kind == "array":
            return ("array", int(tag.length), shape(tag.subtype))
        if kind == "bounded_str":
            return "string"
        if kind == "typedef":
            return shape(tag.subtype)
        return repr(tag)
    if ann in _PLAIN:
        return _PLAIN[ann]
    if hasattr(ann, "__idl__"):
        hints = typing.get_type_hints(ann, include_extras=True)
        return ("struct", tuple((k, shape(v)) for k, v in hints.items()))
    return repr(ann)


def _say(s: Any) -> str:
    if isinstance(s, str):
        return s
    if s[0] == "sequence":
        return f"a sequence of {_say(s[1])}"
    if s[0] == "array":
        return f"an array of {s[1]} {_say(s[2])}"
    return "a struct"


def difference(contract: Any, publisher: Any, path: str = "") -> str | None:
    """The first member where layout ``publisher`` differs from ``contract``
    (both :func:`shape` results), as a phrase naming the field by its path
    (``layout.dim[].size``); ``None`` when they are the same."""
    if contract == publisher:
        return None
    if isinstance(contract, tuple) and isinstance(publisher, tuple) and contract[0] == publisher[0]:
        if contract[0] == "struct":
            mine, theirs = contract[1], publisher[1]
            for (a, sa), (b, sb) in zip(mine, theirs):
                if a != b:
                    return f"field {path}{a}: the publisher's type has {path}{b} in its place"
                found = difference(sa, sb, f"{path}{a}.")
                if found:
                    return found
            if len(mine) > len(theirs):
                return f"field {path}{mine[len(theirs)][0]}: the publisher's type has no such field"
            return f"field {path}{theirs[len(mine)][0]}: the publisher's type has it, the contract's has not"
        if contract[0] == "sequence":
            return difference(contract[1], publisher[1], path.rstrip(".") + "[].")
        if contract[0] == "array" and contract[1] == publisher[1]:
            return difference(contract[2], publisher[2], path.rstrip(".") + "[].")
    where = path.rstrip(".") or "(the whole message)"
    return f"field {where}: the publisher's is {_say(publisher)}, the contract's {_say(contract)}"


class LayoutJudge:
    """Judges publishers against contract structs (module docstring), with
    the answers cached.  ``type_hash(struct)`` gives the contract type's
    RIHS01 hash (``None`` when it cannot be computed)."""

    def __init__(self, dp: Any, type_hash: Callable[[type], str | None], timeout_s: float = 0.02) -> None:
        self.dp, self.type_hash, self.timeout_s = dp, type_hash, timeout_s
        self._hashes: dict[type, str | None] = {}
        self._shapes: dict[Any, Any] = {}
        self._first_try: dict[Any, float] = {}

    def judge(self, struct: type, type_id: Any, user_data: bytes) -> tuple[str, str]:
        """``(SAME | OTHER | PENDING, reason)`` for a publisher announcing
        ``type_id`` (``None``: none) and ``user_data``; ``reason`` names the
        field that differs, or the hashes."""
        from rclverify.ros.live.dds import announced_type_hash  # deferred: start-up (loads rclverify.ros, rclverify.ros.live and more only when called)
        if type_id is not None:
            return self._by_type_object(struct, type_id)
        theirs = announced_type_hash(user_data)
        if struct not in self._hashes:
            self._hashes[struct] = self.type_hash(struct)
        mine = self._hashes[struct]
        if theirs is None or mine is None or theirs == mine:
            return SAME, ""
        from rclverify.ros.live.dds import ros_type  # deferred: as announced_type_hash above
        pkg, _, name = (ros_type(getattr(struct, "__idl_typename__", "")) or "pkg/msg/T").partition("/msg/")
        return OTHER, (f"its ROS 2 type hash {theirs[:19]}... differs from the contract's type's {mine[:19]}... "
                       "(REP-2011; the definitions differ: fields, their types or names): give the robot's "
                       f"definition as DIR/{pkg}/msg/{name}.msg with --interfaces DIR, or hear it with --source rclpy, "
                       "which reads the publisher's own definition")

    def _by_type_object(self, struct: type, type_id: Any) -> tuple[str, str]:
        try:
            if type_id == struct.__idl__.get_type_id():  # type: ignore[attr-defined]
                return SAME, ""
        except Exception:  # noqa: BLE001 - no identifier of ours: compare the type objects
            pass
        theirs = self._publisher_shape(type_id)
        if theirs is None:
            first = self._first_try.setdefault(type_id, time.monotonic())
            return (PENDING, "") if time.monotonic() - first < RESOLVE_GRACE_S else (SAME, "")
        why = difference(shape(struct), theirs)
        return (SAME, "") if why is None else (OTHER, why)

    def _publisher_shape(self, type_id: Any) -> Any:
        """The layout of the type ``type_id`` names, fetched by Cyclone's type lookup (``None`` while not
        resolved within the timeout)."""
        if type_id in self._shapes:
            return self._shapes[type_id]
        from cyclonedds.dynamic import get_types_for_typeid  # deferred: start-up (loads cyclonedds and more only when called)
        try:
            cls, _deps = get_types_for_typeid(self.dp, type_id, int(self.timeout_s * 1e9))
        except Exception:  # noqa: BLE001 - not resolved yet (type lookup under way), or a kind the binding lacks
            return None
        self._shapes[type_id] = shape(cls)
        return self._shapes[type_id]


__all__ = ["LayoutJudge", "OTHER", "PENDING", "SAME", "difference", "shape"]
