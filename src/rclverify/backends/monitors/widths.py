"""The width each monitored input and output carries, from the message definitions.

A variable is read from the fields its topic's rule names (all top-level
fields without a ``fields`` list), by the rule of its type
(:mod:`rclverify.traces.mapping`): a ``REAL`` from the first numeric field,
an ``INTEGER`` or ``NATURAL`` from the first integer field, a ``BOOL`` from
the first ``bool``, an enumeration from the first string, a ``seq(T)`` from
the first array field (or a path through every item of an array of
messages, ``poses[*].position.x``), a sequence of tuples from one array per
component.  Where the contract names the topic's message type
(``topics( sensor_msgs/BatteryState battery matches(in.p) )``) and the
type's definition is known (ROS 2's standard types, rosbags' store, and the
workspace's ``.msg`` files), that field's IDL type is what the variable
carries (:class:`rclverify.semantics.widths.Carried`: the primitive, a
string's bound, a sequence's bound or fixed length): :func:`carried_fields`.
A ``float32`` or ``float64`` width makes the contract's constants compared
with the variable the width's values (:func:`carried_widths`,
:mod:`rclverify.semantics.widths`; docs/semantics.md, "Widths"); an integer
width keeps them exact and bounds what the field can hold.  Where the field
cannot be told from the definitions alone (a type not found, a field that
is a nested message, no field of the variable's kind), nothing is carried
and the comparisons keep their meaning.  Without the ``ros`` extra
(rosbags) no definition is known.

:func:`refuse_out_of_range` refuses a recorded log whose message holds a
value its field cannot carry (300 in a ``uint8``): no such message crossed
the wire, so the run was made by hand; the error names ``file:line``.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Iterable, Iterator, Mapping, Sequence

from rclverify.core.extras import installed
from rclverify.lang import ast
from rclverify.lang import types as T
from rclverify.lang.types import Checked, CheckedNode
from rclverify.semantics.widths import FLOAT_WIDTHS, INT_RANGES, Carried, Width, at_widths, carried_fault, idl_name
from rclverify.traces.events import Event, TraceError
from rclverify.traces.guard import LOG_SUFFIXES
from rclverify.traces.mapping import EVERY, MappingError, TopicRule, field_value, parse_path, rule_for

#: A field that is a nested message (no primitive to carry), and one that is an array of messages.
_MESSAGE, _MESSAGES = "message", "messages"


@dataclass(frozen=True)
class FieldSource:
    """Where one variable is read: its ``topic`` (no leading ``/``), the
    ``fields`` (names or paths) its value comes from, in order, and what
    they carry (``carried``)."""

    topic: str
    fields: tuple[str, ...]
    carried: Carried


def _store_name(msg_type: str) -> str:
    parts = msg_type.strip("/").split("/")
    return f"{parts[0]}/msg/{parts[-1]}" if len(parts) == 2 else "/".join(parts)


def _width(kind: Any) -> Width | None:
    """A rosbags field kind as a :class:`Width` (``None`` unless a primitive)."""
    if kind[0].name != "BASE" or not isinstance(kind[1][0], str):
        return None
    return Width(idl_name(kind[1][0]), int(kind[1][1] or 0))


def _array(kind: Any) -> tuple[Any, int | None, bool]:
    """``(item kind, bound, fixed)`` of a rosbags ARRAY or SEQUENCE kind (a bound 0 is none)."""
    item, n = kind[1]
    fixed = kind[0].name == "ARRAY"
    return item, (int(n) if n else None) if not fixed else int(n), fixed


def resolve(defs: Mapping[str, Any], msg: str, path: str) -> Carried | str | None:
    """What field ``path`` (a top-level name or a path, :func:`~rclverify.traces.mapping.parse_path`)
    of message ``msg`` carries: a :class:`Carried`, ``"message"`` for a nested message (read as no
    value), ``"messages"`` for an array of messages, ``None`` when the definitions cannot tell (no such
    field, a malformed path, an array inside each item of a ``[*]`` path)."""
    steps = parse_path(path) if ("." in path or "[" in path) else (path,)
    if steps is None:
        return None
    kind: Any = None
    every: tuple[int | None, bool] | None = None
    for step in steps:
        if isinstance(step, int) or step == EVERY:
            if kind is None or kind[0].name not in ("ARRAY", "SEQUENCE"):
                return None
            item, bound, fixed = _array(kind)
            if step == EVERY:
                every = (bound, fixed)
            kind = item
            continue
        name = kind[1] if kind is not None and kind[0].name == "NAME" else (msg if kind is None else None)
        if name is None or name not in defs:
            return None
        fields = dict(defs[name][1])
        if step not in fields:
            return None
        kind = fields[step]
    if kind is None:
        return None
    if kind[0].name in ("ARRAY", "SEQUENCE"):
        if every is not None:
            return None  # an array in each item: a sequence of sequences is not mapped
        item, bound, fixed = _array(kind)
        w = _width(item)
        return _MESSAGES if w is None else Carried((w,), True, bound, fixed)
    w = _width(kind)
    if w is None:
        return _MESSAGE
    return Carried((w,)) if every is None else Carried((w,), True, every[0], every[1])


def _takes(typ: T.Type, c: Carried) -> bool:
    """Whether the scalar rule for ``typ`` takes a field carrying ``c`` (traces/mapping.py's ``_scalar``)."""
    if c.seq:
        return False
    idl = c.items[0].idl
    if isinstance(typ, T.EnumT):
        return idl == "string"
    if isinstance(typ, T.Scalar):
        if typ.name == "BOOL":
            return idl == "bool"
        if typ.name == "REAL":
            return idl in FLOAT_WIDTHS or idl in INT_RANGES
        return idl in INT_RANGES
    return False


def _scalar_type(t: T.Type | None) -> bool:
    return isinstance(t, (T.Scalar, T.EnumT))


def carried_by(defs: Mapping[str, Any], msg: str, typ: T.Type,
               names: Sequence[str]) -> tuple[tuple[str, ...], Carried] | None:
    """The fields among ``names`` a variable of RCL type ``typ`` is read from and what they carry,
    following the mapping's rule for the type (module docstring); ``None`` when the definitions cannot
    tell.  ``names``: the rule's ``fields`` list, else the message's top-level fields."""
    if isinstance(typ, T.SeqT) and isinstance(typ.elem, T.TupleT) and all(map(_scalar_type, typ.elem.elems)):
        want = len(typ.elem.elems)
    elif isinstance(typ, T.SeqT) and _scalar_type(typ.elem):
        want = 1
    elif _scalar_type(typ):
        want = 0
    else:
        return None
    picked: list[tuple[str, Carried]] = []
    for name in names:
        c = resolve(defs, msg, name)
        if c is None:
            return None
        if c == _MESSAGES and want:
            return None  # the sequence rule takes this array and cannot read its items: the mapping says so
        if not isinstance(c, Carried):
            continue
        if want == 0 and _takes(typ, c):
            return (name,), c
        if want and c.seq:
            picked.append((name, c))
            if len(picked) == want:
                break
    if not want or len(picked) < want:
        return None
    first = picked[0][1]
    if want == 1:
        return (picked[0][0],), first
    items = tuple(c.items[0] for _, c in picked)
    bounds = [c.max_len for _, c in picked if c.max_len is not None]
    return tuple(n for n, _ in picked), Carried(items, True, min(bounds) if bounds else None,
                                                all(c.fixed for _, c in picked))


def carried_fields(node: CheckedNode, rules: Mapping[str, TopicRule],
                   msg_dirs: Sequence[Path]) -> dict[str, FieldSource]:
    """``"in.x"``/``"out.y"`` -> where each input and output of ``node``
    mapped from a topic is read and what its field carries, for those the
    definitions tell (module docstring); ``{}`` without the ``ros`` extra
    or when a definition does not load (the monitors report that where they
    read a bag)."""
    if not node.node.topics or not installed("rosbags"):
        return {}
    from rclverify.traces.bag import field_definitions  # deferred: start-up (loads rosbags only when called)
    try:  # the topics' types and those they name, kept between runs by the command (traces/bag.py)
        defs = field_definitions(list(msg_dirs), [_store_name(t.msg_type) for t in node.node.topics])
    except Exception:  # noqa: BLE001 - a definition rosbags refuses: the monitors report it where they read a bag
        return {}
    out: dict[str, FieldSource] = {}
    for t in node.node.topics:
        var = t.match
        if var is None or not var.prefix:
            continue
        key = var.qualified
        typ = (node.inputs if var.prefix == "in" else node.outputs).get(var.name)
        msg = _store_name(t.msg_type)
        if typ is None or msg not in defs:
            continue
        topic = t.field.strip("/")
        rule = rule_for(rules, topic, key)
        names = list(rule.fields) or [n for n, _ in defs[msg][1]]
        got = carried_by(defs, msg, typ, names)
        if got is not None:
            out[key] = FieldSource(topic, got[0], got[1])
    return out


def carried_widths(node: CheckedNode, rules: Mapping[str, TopicRule], msg_dirs: Sequence[Path]) -> dict[str, str]:
    """``"in.x"``/``"out.y"`` -> ``float32`` or ``float64`` for each ``REAL``
    input and output of ``node`` whose field's width the definitions tell, and
    for each ``seq(REAL)`` one its items' width (:func:`carried_fields`);
    ``{}`` without the ``ros`` extra."""
    return float_widths(node, carried_fields(node, rules, msg_dirs))


def float_widths(node: CheckedNode, fields: Mapping[str, FieldSource]) -> dict[str, str]:
    """:func:`carried_widths` from ``node``'s :func:`carried_fields` already read."""
    out: dict[str, str] = {}
    for key, src in fields.items():
        var = key.split(".", 1)[1]
        typ = (node.inputs if key.startswith("in.") else node.outputs).get(var)
        real = T.Scalar("REAL")
        if (typ == real or typ == T.SeqT(real)) and len(src.carried.items) == 1 \
                and src.carried.items[0].idl in FLOAT_WIDTHS:
            out[key] = src.carried.items[0].idl
    return out


def at_carried_widths(node: CheckedNode, widths: Mapping[str, str],
                      constants: Mapping[str, tuple[T.Type, ast.Expr]] | None = None) -> CheckedNode:
    """``node`` with every formula of its contract (assumptions, guarantees,
    initial values) comparing its constants at the widths ``widths`` carries
    (:func:`rclverify.semantics.widths.at_widths`; ``constants`` the
    context's named constants, ``Env.constants``, read at the width as a
    literal is); ``node`` itself without widths."""
    if not widths:
        return node
    n = node.node

    def clauses(cs: tuple[ast.Clause, ...]) -> tuple[ast.Clause, ...]:
        return tuple(dataclasses.replace(c, formula=at_widths(c.formula, widths, constants)) for c in cs)
    return dataclasses.replace(node, node=dataclasses.replace(n, assumes=clauses(n.assumes),
                                                              guarantees=clauses(n.guarantees),
                                                              initially=clauses(n.initially)))


def judged_at_widths(checked: Checked, node: CheckedNode, rules: Mapping[str, TopicRule],
                     msg_dirs: Sequence[Path]) -> tuple[CheckedNode, dict[str, FieldSource]]:
    """``(node as judged, its fields)``: ``node`` with its contract's constants, literals and the
    context's named constants (``checked.env.constants``) alike, compared at the widths its fields
    carry (:func:`at_carried_widths` of :func:`float_widths`), and :func:`carried_fields` of it.  The
    one route every monitor takes to the widths: the offline check (:mod:`.recorded`, :mod:`.backend`)
    and the live monitor (``rclverify monitor --live``), so a named constant compared with a ``float32``
    field gets the same verdict live and offline (docs/monitors.md, "Widths live and offline").
    ``msg_dirs``: the mapping's message directories, resolved."""
    fields = carried_fields(node, rules, msg_dirs)
    return at_carried_widths(node, float_widths(node, fields), checked.env.constants), fields


def _bounded(c: Carried) -> bool:
    """Whether a field carrying ``c`` has a range a JSON log's value may leave: an integer, a bounded
    string, a bounded or fixed sequence (a ``float32`` beyond its range is not looked for: every log
    with a ``float32`` field would lose its columnar reading for a value no logger writes)."""
    return c.max_len is not None or any(w.idl in INT_RANGES or w.bound for w in c.items)


def refuse_out_of_range(events: Iterable[Event], trace: Path,
                        sources: Iterable[tuple[str, FieldSource]]) -> Iterable[Event]:
    """``events`` (read from ``trace``), raising :class:`~rclverify.traces.events.TraceError`
    (``log.jsonl:12: error: ...``) at the first event holding, in a field a
    variable is read from (``sources``: ``(key, FieldSource)`` pairs,
    :func:`carried_fields`), a value the field cannot carry
    (:func:`rclverify.semantics.widths.carried_fault`: 300 in a ``uint8``,
    five items in a ``T[<=4]``).  Only a log is looked at (a bag's messages
    are decoded from their wire types, which cannot hold such a value), and
    only when some field has such a range; ``events`` itself otherwise (a log
    keeps its columnar reading).  A field the message lacks is left to the
    mapping (its event is inconclusive with the reason)."""
    by_topic: dict[str, list[tuple[str, FieldSource]]] = {}
    for key, src in sources:
        if _bounded(src.carried):
            by_topic.setdefault(src.topic, []).append((key, src))
    if not by_topic or trace.suffix not in LOG_SUFFIXES:
        return events
    return _refusing(events, by_topic)


def _refusing(events: Iterable[Event], by_topic: Mapping[str, list[tuple[str, FieldSource]]]) -> Iterator[Event]:
    for ev in events:
        for key, src in by_topic.get(ev.topic, ()):
            try:
                parts = [field_value(ev.fields, f) for f in src.fields]
            except MappingError:
                continue
            value: Any = parts[0]
            if len(parts) > 1 and all(isinstance(p, (list, tuple)) for p in parts):
                value = list(zip(*parts))
            why = carried_fault(value, src.carried)
            if why:
                raise TraceError(f"{ev.where}: error: {key} on topic {src.topic} (field {', '.join(src.fields)}, "
                                 f"{src.carried}): {why}; no message on the wire holds it")
        yield ev


__all__ = ["FieldSource", "at_carried_widths", "carried_by", "carried_fields", "carried_widths", "float_widths",
           "judged_at_widths", "refuse_out_of_range", "resolve"]
