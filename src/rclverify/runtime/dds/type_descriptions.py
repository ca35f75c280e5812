"""A publisher's own definition of its message type, from its type
description (REP-2011).

A ROS 2 publisher announces the type
hash of the definition it was built with (REP-2011, ``RIHS01_``); when that
is not the hash of the book's definition (the robot runs another
distribution: Kilted's ``sensor_msgs/Range`` has ``float32 variance``,
rosbags' Humble store has not), :func:`declare` makes the struct of the
publisher's **type description** (``type_description_interfaces/msg/
TypeDescription`` as a dict: what its node's ``~/get_type_description``
service answers, and what rosidl writes beside the interface,
``share/<pkg>/msg/<T>.json``), after checking that the description hashes
to the publisher's hash (:func:`rclverify.ros.live.type_hash.rihs01` over
the fields read from it): a description that does not is refused, so no
sample is read with a layout the publisher did not declare.  A sample of
such a publisher is handed on as :class:`~.types.Declared` bytes, and every struct
of a book reads those with their declaration's struct
(:meth:`~.types.TypeBook.struct`), so a field only the publisher's definition has
is decoded (docs/ros2.md, "The publisher's own definition").
"""
from __future__ import annotations

from typing import Any, Mapping

from rclverify.ros.live.type_hash import UnknownType, rihs01
from rclverify.runtime.dds.types import DdsTypeError, Declaration, TypeBook


#: FieldType's base ids (type_description_interfaces/msg/FieldType.msg) -> the ``.msg`` base type; the others
#: (``long double``, IDL ``char`` and ``wchar``, fixed strings) have no ``.msg`` spelling and are refused
_FIELD_BASES = {2: "int8", 3: "uint8", 4: "int16", 5: "uint16", 6: "int32", 7: "uint32", 8: "int64",
                9: "uint64", 10: "float32", 11: "float64", 15: "bool", 16: "byte", 17: "string", 21: "string"}
#: FieldType's id offsets of a collection: (kind in rosbags' form, whether capacity is its size or bound)
_FIELD_KINDS = {1: 3, 2: 4, 3: 4}


def _field_desc(t: Mapping[str, Any], owner: str, fname: str) -> tuple[int, Any]:
    """A FieldType dict (``type_id``, ``capacity``, ``string_capacity``,
    ``nested_type_name``) in rosbags' form; raises :class:`DdsTypeError` for an
    id this module cannot carry."""
    tid, cap = int(t.get("type_id", 0)), int(t.get("capacity", 0))
    scap, nested = int(t.get("string_capacity", 0)), str(t.get("nested_type_name", ""))
    coll, base = divmod(tid, 48)
    elem: tuple[int, Any]
    if base == 1 and nested:
        elem = (2, nested)
    elif base == 18:
        elem = (2, owner.split("/")[0] + "/msg/wstring")  # how rosbags' parser names a wstring
    elif base in _FIELD_BASES:
        elem = (1, (_FIELD_BASES[base], scap if base == 21 else 0))
    else:
        raise DdsTypeError(f"{owner}: field {fname} has the type id {tid}, which has no .msg type this monitor "
                           "can carry")
    if coll == 0:
        return elem
    if coll not in _FIELD_KINDS:
        raise DdsTypeError(f"{owner}: field {fname} has the type id {tid}, which no ROS 2 type description uses")
    return _FIELD_KINDS[coll], (elem, cap if coll in (1, 2) else 0)


def description_fields(description: Mapping[str, Any]) -> dict[str, list[tuple[str, Any]]]:
    """Every type of a type description (``{"type_description": {"type_name",
    "fields": [{"name", "type": {...}}]}, "referenced_type_descriptions": [...]}``,
    type_description_interfaces/msg/TypeDescription as a dict): type name ->
    its fields in rosbags' form, in the description's order.  Raises
    :class:`DdsTypeError` for a description that is not one."""
    try:
        described = [description["type_description"], *description.get("referenced_type_descriptions", [])]
        return {str(d["type_name"]): [(str(f["name"]), _field_desc(f["type"], str(d["type_name"]), str(f["name"])))
                                      for f in d["fields"]] for d in described}
    except (KeyError, TypeError, ValueError, AttributeError) as exc:
        raise DdsTypeError(f"not a type description ({type(exc).__name__}: {exc})") from None


def declare(name: str, type_hash: str, description: Mapping[str, Any], origin: str) -> Declaration:
    """The :class:`Declaration` of message ``name`` (``pkg/msg/T``) from a type
    description (:func:`description_fields`) said to come from ``origin``,
    checked against the publisher's ``type_hash``: the REP-2011 hash of the
    fields read from the description must equal it.  Raises
    :class:`DdsTypeError` (one line) for a description of another type, one
    lacking a type it uses, one that hashes to another value (a forged or
    stale description), or one with a field Cyclone cannot carry."""
    types = description_fields(description)
    top = str(description.get("type_description", {}).get("type_name", ""))
    if top != name:
        raise DdsTypeError(f"the type description from {origin} describes {top or 'no type'}, not {name}")
    try:
        got = rihs01(name, types.get)
    except UnknownType as exc:
        raise DdsTypeError(f"the type description of {name} from {origin} lacks {exc.args[0]}, which it uses") \
            from None
    except (KeyError, ValueError, TypeError) as exc:
        raise DdsTypeError(f"the type description of {name} from {origin} cannot be hashed: {exc}") from None
    if got != type_hash:
        raise DdsTypeError(f"the type description of {name} from {origin} hashes to {got}, not to the "
                           f"publisher's {type_hash}: not used")
    book = TypeBook.described(types)
    return Declaration(name, type_hash, origin, book.struct(name), types)


__all__ = ["declare", "description_fields"]
