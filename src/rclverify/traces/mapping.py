"""From ROS messages to RCL values: the paper's mapping rules (lines 535-548)
and the constructor rule the case study needs (CommandMapping, lines 1117-1130).

Which rule applies depends on the RCL variable's type:

* **Scalar** (``REAL``, ``INTEGER``, ``NATURAL``, ``BOOL``): the first
  message field of a matching type (``REAL`` takes any number, the integer
  types an integer, ``BOOL`` a boolean);
* **Collection** (an enumeration): the first string field, which must name
  one of the values; any other string is kept as it is, so the formulas
  see a value outside the enumeration (``in.x in {...}`` is then false);
* **Function** (``A x B --> C``): the arguments are the first fields of the
  argument types, in order; a ``BOOL`` result is ``TRUE`` for that
  argument tuple (the message asserts it), any other result is the next
  field of the result type.  The table accumulates entries over the run
  (``update: accumulate``, the default) or holds the latest message only
  (``update: replace``, for a position); outside the table a ``BOOL``
  function is ``FALSE`` and any other function has the plan's ``default``
  (without one it is partial: an application outside the table equals no
  value);
* **Constructor** (a constructor set such as ``CommandSet``): the first
  string field names the constructor; its arguments are the next fields of
  the argument types, in order.

Which fields a topic's messages contribute, and in which order, is the
plan's ``fields`` list for the topic (all fields in message order
otherwise): bespoke rules in the paper's sense.

A topic may be declared a **state** (``state: true``, e.g. a latched pose):
only then may a node's output on it that was current before an input event
stand in for the answer to that event (docs/monitors.md, "An answer comes
after its question").
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from fractions import Fraction
from typing import Any, Mapping, Sequence

from ..rcl import types as T
from ..values import FiniteFunction, Term


class MappingError(Exception):
    """A message that the rule for its variable cannot map (reason in ``str``)."""


@dataclass(frozen=True)
class TopicRule:
    """The plan's options for one topic: ``fields`` (order), ``update``,
    ``default``, ``state`` (its value persists and may answer a later input
    event; an event topic's output answers only the input events before it)."""

    fields: tuple[str, ...] = ()
    update: str = "accumulate"
    default: Any = None
    state: bool = False


@dataclass
class _Fields:
    items: list[tuple[str, Any]]
    pos: int = 0
    used: set[int] = field(default_factory=set)

    def take(self, want: T.Type, what: str) -> Any:
        for k, (name, v) in enumerate(self.items):
            if k in self.used:
                continue
            if isinstance(v, float) and not math.isfinite(v):
                # NaN or an infinity is no RCL number: the event cannot be mapped (not a reading to compare)
                raise MappingError(f"field {name!r} is {v!r}, not a finite number, for {what} of type {want}")
            got = _scalar(v, want)
            if got is not _NO:
                self.used.add(k)
                return got
        raise MappingError(f"no field left for {what} of type {want}")


_NO = object()


def _scalar(v: Any, t: T.Type) -> Any:
    if isinstance(t, T.Scalar):
        if t.name == "BOOL":
            return v if isinstance(v, bool) else _NO
        if isinstance(v, bool):
            return _NO
        if t.name == "REAL":
            return v if isinstance(v, (int, float, Fraction)) else _NO
        if isinstance(v, int) and (t.name == "INTEGER" or v >= 0):
            return v
        if isinstance(v, float) and v.is_integer() and (t.name == "INTEGER" or v >= 0):
            return _NO
        return _NO
    if isinstance(t, T.EnumT):
        return v if isinstance(v, str) else _NO
    return _NO


def field_items(fields: Mapping[str, Any], rule: TopicRule) -> list[tuple[str, Any]]:
    """The message fields the rule reads, in order."""
    if rule.fields:
        missing = [f for f in rule.fields if f not in fields]
        if missing:
            raise MappingError(f"the message has no field {', '.join(missing)}")
        return [(f, fields[f]) for f in rule.fields]
    return list(fields.items())


def map_value(typ: T.Type, fields: Mapping[str, Any], rule: TopicRule, previous: Any) -> Any:
    """The variable's new value after one message (``previous`` is its value so far,
    ``None`` at the start).  Raises :class:`MappingError`."""
    fs = _Fields(field_items(fields, rule))
    if isinstance(typ, (T.Scalar, T.EnumT)):
        return fs.take(typ, "the value")
    if isinstance(typ, T.DataT):
        name = fs.take(T.EnumT("constructor", ()), "the constructor name")
        args = typ.ctor(name)
        if args is None:
            raise MappingError(f"{name!r} is not a constructor of {typ.name}")
        return Term(name, tuple(fs.take(a, f"argument {k} of {name}") for k, a in enumerate(args, 1)))
    if isinstance(typ, T.FuncT):
        key = tuple(fs.take(a, f"argument {k}") for k, a in enumerate(typ.args, 1))
        is_bool = isinstance(typ.result, T.Scalar) and typ.result.name == "BOOL"
        result = True if is_bool else fs.take(typ.result, "the result")
        default = False if is_bool else rule.default
        table: dict[tuple[Any, ...], Any] = {}
        if rule.update == "accumulate" and isinstance(previous, FiniteFunction):
            table.update(previous.table)
        table[key] = result
        return FiniteFunction(table, default, len(typ.args))
    raise MappingError(f"no mapping rule for a variable of type {typ}")


def initial_value(typ: T.Type, rule: TopicRule) -> Any:
    """The value before any message: an empty table for a function, else ``None`` (unknown)."""
    if isinstance(typ, T.FuncT):
        is_bool = isinstance(typ.result, T.Scalar) and typ.result.name == "BOOL"
        return FiniteFunction({}, False if is_bool else rule.default, len(typ.args))
    return None


class RuleError(ValueError):
    """A malformed topic rule of the mapping file: the message names the
    topic; ``path`` is the key path of the value at fault in the mapping
    file (``("topics", topic, "fields")``), for locating it."""

    def __init__(self, message: str, *path: Any) -> None:
        super().__init__(message)
        self.path = path


class RuleSet(dict):  # type: ignore[type-arg]
    """The mapping file's topic rules (topic -> :class:`TopicRule`) and its
    ``tolerance`` of recorded numbers (``None``: none declared; else a
    :class:`rclverify.logic.floatsem.Tolerance`, set by the mapping's loader),
    which every monitor given these rules applies (docs/monitors.md,
    "Numbers on the wire")."""

    tolerance: Any = None


def load_rules(raw: Any) -> RuleSet:
    """Topic rules from the plan's ``topics`` mapping (``{topic: {fields, update, default, state}}``):
    ``fields`` a list of field names, ``update`` ``accumulate`` or ``replace``,
    ``state`` a boolean (default false).

    Raises :class:`RuleError` (a ``ValueError``) naming the topic and the
    key at fault for a malformed rule (``topics`` not a mapping, ``fields``
    not a list of names, an unknown ``update``).
    """
    out = RuleSet()
    if raw is not None and not isinstance(raw, Mapping):
        raise RuleError(f"topics must map each topic to its rule, not {raw!r}", "topics")
    for topic, spec in (raw or {}).items():
        spec = spec or {}
        if not isinstance(spec, Mapping):
            raise RuleError(f"topic {topic}: expected a mapping", "topics", topic)
        fields: Any = spec.get("fields", ()) or ()
        if not isinstance(fields, (list, tuple)) or not all(isinstance(f, (str, int)) and not isinstance(f, bool)
                                                            for f in fields):
            raise RuleError(f"topic {topic}: fields must be a list of message field names, not {fields!r}",
                            "topics", topic, "fields")
        update = spec.get("update", "accumulate")
        if update not in ("accumulate", "replace"):
            raise RuleError(f"topic {topic}: update must be accumulate or replace, not {update!r}",
                            "topics", topic, "update")
        state = spec.get("state", False)
        if not isinstance(state, bool):
            raise RuleError(f"topic {topic}: state must be true or false, not {state!r}", "topics", topic, "state")
        unknown = sorted(str(k) for k in spec if k not in ("fields", "update", "default", "state"))
        if unknown:
            raise RuleError(f"topic {topic}: unknown key {unknown[0]!r} (expected fields, update, default, state)",
                            "topics", topic, unknown[0])
        out[str(topic).lstrip("/")] = TopicRule(tuple(str(f) for f in fields), update, spec.get("default"), state)
    return out
