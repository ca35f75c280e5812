"""The width each monitored input and output carries, from the message definitions.

A ``REAL`` variable is read from the first numeric field of the fields its
topic's rule names (all top-level fields without a ``fields`` list:
:func:`rclverify.traces.mapping.value_mapper`).  Where the contract names
the topic's message type (``topics( sensor_msgs/BatteryState battery
matches(in.p) )``) and the type's definition is known (ROS 2's standard
types, rosbags' store, and the workspace's ``.msg`` files), that field's IDL
type is the variable's width; a ``float32`` or ``float64`` width makes the
contract's constants compared with the variable the width's values
(:mod:`rclverify.semantics.widths`; docs/semantics.md, "Widths").  Where the
field cannot be told from the definitions alone (a type not found, a field
that is a nested message, no numeric field), the width is unknown and the
comparisons keep their meaning.  Without the ``ros`` extra (rosbags) no
definition is known.
"""
from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any, Mapping, Sequence

from rclverify.core.extras import installed
from rclverify.lang import ast
from rclverify.lang import types as T
from rclverify.lang.types import CheckedNode
from rclverify.semantics.widths import FLOAT_WIDTHS, at_widths
from rclverify.traces.mapping import TopicRule, parse_path, rule_for

#: IDL primitive types a REAL variable takes (rosidl's numeric types).
NUMERIC = frozenset({"float32", "float64", "double", "float", "int8", "uint8", "int16", "uint16", "int32", "uint32",
                     "int64", "uint64", "byte", "octet"})


def _store_name(msg_type: str) -> str:
    parts = msg_type.strip("/").split("/")
    return f"{parts[0]}/msg/{parts[-1]}" if len(parts) == 2 else "/".join(parts)


def _field_type(defs: Mapping[str, Any], msg: str, path: str) -> str | None:
    """The IDL primitive type of field ``path`` of message ``msg``, or ``None``."""
    steps = parse_path(path) if ("." in path or "[" in path) else (path,)
    if steps is None:
        return None
    cur = msg
    kind: Any = None
    for i, step in enumerate(steps):
        if isinstance(step, int):
            if kind is None or kind[0].name not in ("ARRAY", "SEQUENCE"):
                return None
            kind = kind[1][0]
            if kind[0].name == "NAME":
                cur = kind[1]
            continue
        fields = dict(defs.get(cur, ((), ()))[1])
        if step not in fields:
            return None
        kind = fields[step]
        if kind[0].name == "NAME":
            cur = kind[1]
    if kind is None or kind[0].name != "BASE":
        return None
    name = kind[1][0]
    return str(name) if isinstance(name, str) else None


def _first_array_items(defs: Mapping[str, Any], msg: str, names: Sequence[str]) -> str | None:
    """The IDL type of the items of the first array field among ``names`` (top-level fields; the mapping's
    sequence rule takes the first array), ``None`` when it is not an array of a primitive type."""
    fields = dict(defs.get(msg, ((), ()))[1])
    for name in names:
        kind = fields.get(name)
        if kind is None:
            return None
        if kind[0].name in ("ARRAY", "SEQUENCE"):
            item = kind[1][0]
            return str(item[1][0]) if item[0].name == "BASE" and isinstance(item[1][0], str) else None
    return None


def _first_numeric(defs: Mapping[str, Any], msg: str, names: Sequence[str]) -> str | None:
    """The IDL type of the first numeric field among ``names`` (a field that is a message or a string is
    passed over, as the mapping passes over it); ``None`` when one of them cannot be told."""
    for name in names:
        t = _field_type(defs, msg, name)
        if t is None:
            fields = dict(defs.get(msg, ((), ()))[1])
            kind = fields.get(name)
            if kind is not None and kind[0].name in ("NAME", "ARRAY", "SEQUENCE"):
                continue  # a nested message or an array at the top level: not a number, skipped
            return None
        if t in NUMERIC:
            return t
    return None


def carried_widths(node: CheckedNode, rules: Mapping[str, TopicRule], msg_dirs: Sequence[Path]) -> dict[str, str]:
    """``"in.x"``/``"out.y"`` -> ``float32`` or ``float64`` for each ``REAL``
    input and output of ``node`` whose field's width the definitions tell, and
    for each ``seq(REAL)`` one its array's items' width (module docstring);
    ``{}`` without the ``ros`` extra."""
    if not node.node.topics or not installed("rosbags"):
        return {}
    from rclverify.traces.bag import typestore  # deferred: start-up (loads rosbags only when called)
    try:
        defs = typestore(list(msg_dirs)).fielddefs
    except Exception:  # noqa: BLE001 - a definition rosbags refuses: the monitors report it where they read a bag
        return {}
    out: dict[str, str] = {}
    for t in node.node.topics:
        var = t.match
        if var is None or not var.prefix:
            continue
        key = var.qualified
        typ = (node.inputs if var.prefix == "in" else node.outputs).get(var.name)
        seq = isinstance(typ, T.SeqT) and isinstance(typ.elem, T.Scalar) and typ.elem.name == "REAL"
        if not (seq or isinstance(typ, T.Scalar) and typ.name == "REAL"):
            continue
        msg = _store_name(t.msg_type)
        if msg not in defs:
            continue
        rule = rule_for(rules, t.field.strip("/"), key)
        names = list(rule.fields) or [n for n, _ in defs[msg][1]]
        width = _first_array_items(defs, msg, names) if seq else _first_numeric(defs, msg, names)
        width = {"double": "float64", "float": "float32"}.get(width or "", width)
        if width in FLOAT_WIDTHS:
            out[key] = width
    return out


def at_carried_widths(node: CheckedNode, widths: Mapping[str, str]) -> CheckedNode:
    """``node`` with every formula of its contract (assumptions, guarantees,
    initial values) comparing its constants at the widths ``widths`` carries
    (:func:`rclverify.semantics.widths.at_widths`); ``node`` itself without widths."""
    if not widths:
        return node
    n = node.node

    def clauses(cs: tuple[ast.Clause, ...]) -> tuple[ast.Clause, ...]:
        return tuple(dataclasses.replace(c, formula=at_widths(c.formula, widths)) for c in cs)
    changes: dict[str, Any] = {"assumes": clauses(n.assumes), "guarantees": clauses(n.guarantees)}
    return dataclasses.replace(node, node=dataclasses.replace(n, **changes))


__all__ = ["at_carried_widths", "carried_widths"]
