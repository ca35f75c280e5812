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
* **Window** (a function ``NATURAL --> T`` or ``INTEGER --> T`` of a
  scalar or enumeration ``T`` whose message holds an array field): the
  function from the offsets ``0, 1, ...`` to the array's items, read as
  the sequence rule reads them, the message's whole table (a sampled time
  window, ``in.x(k)`` the sample at offset ``k``: docs/semantics.md,
  "Against the peers"); outside it the plan's ``default``.
* **Constructor** (a constructor set such as ``CommandSet``): the first
  string field names the constructor; its arguments are the next fields of
  the argument types, in order.
* **Sequence** (``seq(T)`` of a scalar or enumeration ``T``): the first
  array field (a ROS array or sequence, bounded or not: ``LaserScan.ranges``;
  or a path through every item of an array of messages,
  ``poses[*].position.x``), each item read as the scalar rule reads a field;
  a NaN or an infinity among the items is no RCL number (the message does
  not map).  A sequence of tuples (``seq((REAL, REAL))``) takes one such
  array per component, in order, zipped item by item
  (``fields: ["poses[*].position.x", "poses[*].position.y"]``).

Which fields a topic's messages contribute, and in which order, is the
plan's ``fields`` list for the topic (all top-level fields in message order
otherwise): bespoke rules in the paper's sense.  A field may be a **path**
into nested messages and arrays, as the ROS grounding reads them
(``linear.x`` of a ``geometry_msgs/Twist``, ``pose.pose.position.x``,
``ranges[0]``, ``ranges[-1]`` the last element, ``poses[*].position.x``
every item's): :func:`rclverify.traces.field_paths.field_value`.

A topic may be declared a **state** (``state: true``, e.g. a latched pose):
only then may a node's output on it that was current before an input event
stand in for the answer to that event (docs/monitors.md, "An answer comes
after its question").
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from fractions import Fraction
from typing import Any, Mapping

from rclverify.lang import types as T
from rclverify.traces.field_paths import EVERY as EVERY, MappingError as MappingError, field_value as field_value
from rclverify.traces.field_paths import is_path as is_path, parse_path as parse_path
from rclverify.semantics.values import FiniteFunction, Term


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

    def take_seq(self, want: T.SeqT, what: str) -> tuple[Any, ...]:
        """The next array field (a list or tuple: a ROS array or sequence, bounded or
        not) as an RCL sequence of ``want.elem`` values, item by item as :meth:`take`
        reads a scalar; a NaN or an infinity among the items is no RCL number."""
        for k, (name, v) in enumerate(self.items):
            if k in self.used or not isinstance(v, (list, tuple)):
                continue
            items = []
            for i, x in enumerate(v):
                if isinstance(x, float) and not math.isfinite(x):
                    raise MappingError(f"item {i} of field {name!r} is {x!r}, not a finite number, for {what} "
                                       f"of type {want}")
                got = _scalar(x, want.elem)
                if got is _NO:
                    raise MappingError(f"item {i} of field {name!r} is {x!r}, not a value of type {want.elem}")
                items.append(got)
            self.used.add(k)
            return tuple(items)
        raise MappingError(f"no array field left for {what} of type {want}")

    def take_tuples(self, want: T.SeqT, elems: tuple[T.Type, ...], what: str) -> tuple[Any, ...]:
        """A sequence of tuples: the next ``len(elems)`` array fields (each a ROS array, or a path through
        the items of one, ``poses[*].position.x``), one per component in order, zipped item by item; the
        arrays must have as many items each."""
        parts = [self.take_seq(T.SeqT(e), f"component {k} of {what}") for k, e in enumerate(elems, 1)]
        if len({len(p) for p in parts}) > 1:
            sizes = ", ".join(str(len(p)) for p in parts)
            raise MappingError(f"the arrays of the components of {what} of type {want} have different lengths "
                               f"({sizes}): no item is a tuple")
        return tuple(zip(*parts))


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


def field_items(fields: Mapping[str, object], rule: TopicRule) -> list[tuple[str, Any]]:
    """The message fields the rule reads, in order (:func:`field_value` for
    each named field; the top-level fields without a ``fields`` list)."""
    if rule.fields:
        out: list[tuple[str, Any]] = []
        missing: list[str] = []
        why = ""
        for f in rule.fields:
            try:
                out.append((f, field_value(fields, f)))
            except MappingError as exc:
                missing.append(f)
                why = why or (str(exc) if is_path(f) else "")
        if missing:
            raise MappingError(why if why and len(missing) == 1 else f"the message has no field {', '.join(missing)}")
        return out
    return list(fields.items())


def map_value(typ: T.Type, fields: Mapping[str, object], rule: TopicRule, previous: Any) -> Any:
    """The variable's new value after one message (``previous`` is its value so far,
    ``None`` at the start).  Raises :class:`MappingError`."""
    fs = _Fields(field_items(fields, rule))
    if isinstance(typ, (T.Scalar, T.EnumT)):
        return fs.take(typ, "the value")
    if isinstance(typ, T.SeqT) and isinstance(typ.elem, (T.Scalar, T.EnumT)):
        return fs.take_seq(typ, "the sequence")
    if isinstance(typ, T.SeqT) and isinstance(typ.elem, T.TupleT) \
            and all(isinstance(e, (T.Scalar, T.EnumT)) for e in typ.elem.elems):
        return fs.take_tuples(typ, typ.elem.elems, "the sequence")
    if isinstance(typ, T.DataT):
        name = fs.take(T.EnumT("constructor", ()), "the constructor name")
        args = typ.ctor(name)
        if args is None:
            raise MappingError(f"{name!r} is not a constructor of {typ.name}")
        return Term(name, tuple(fs.take(a, f"argument {k} of {name}") for k, a in enumerate(args, 1)))
    if isinstance(typ, T.FuncT) and len(typ.args) == 1 and isinstance(typ.args[0], T.Scalar) \
            and typ.args[0].name in ("NATURAL", "INTEGER") and isinstance(typ.result, (T.Scalar, T.EnumT)) \
            and any(isinstance(v, (list, tuple)) for _, v in fs.items):  # a window: offsets 0.. to the array's items
        items = fs.take_seq(T.SeqT(typ.result), "the function's window")
        return FiniteFunction({(k,): v for k, v in enumerate(items)}, rule.default, 1)
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


_NUMBER = (int, float, Fraction)


def value_mapper(typ: T.Type, rule: TopicRule) -> Any:
    """:func:`map_value` for one variable's type and rule, made once:
    ``mapper(fields, previous) -> value`` (raises :class:`MappingError`).

    For a ``REAL`` or an enumeration it is the scalar rule's loop without
    the general machinery (the monitors call it for every message): the
    first field of a matching type, a non-finite float met before it an
    error, the same values and the same messages as :func:`map_value`; for
    any other type it is :func:`map_value` itself."""
    real = isinstance(typ, T.Scalar) and typ.name == "REAL"
    if not (real or isinstance(typ, T.EnumT)):
        return lambda fields, previous: map_value(typ, fields, rule, previous)
    names = rule.fields
    isfinite = math.isfinite

    def mapper(fields: Mapping[str, object], previous: Any) -> Any:
        if names:
            try:  # the named fields as top-level keys (field_value reads such a key first)
                items: Any = [(f, fields[f]) for f in names]
            except (KeyError, TypeError, IndexError):  # a path, a missing field: the general reading and its errors
                items = field_items(fields, rule)
        else:
            items = fields.items()
        for name, v in items:
            if isinstance(v, float) and not isfinite(v):
                raise MappingError(f"field {name!r} is {v!r}, not a finite number, for the value of type {typ}")
            if real:
                if isinstance(v, _NUMBER) and not isinstance(v, bool):
                    return v
            elif isinstance(v, str):
                return v
        raise MappingError(f"no field left for the value of type {typ}")
    if len(names) != 1:
        return mapper
    only = names[0]
    steps = parse_path(only) if is_path(only) else None  # a path read once, not at every message
    path = steps if steps is not None and EVERY not in steps else None

    def one_field(fields: Mapping[str, object], previous: Any) -> Any:
        # one named field (the common rule) holding a finite float or a string, or a path of plain dicts and
        # lists to one: the value itself; anything else (a missing field, another type, NaN) goes the
        # general way above, with its errors
        try:
            v = fields[only]
        except (KeyError, TypeError, IndexError):
            v = _MISSING if path is None else _quick_follow(fields, path)
            if v is _MISSING:
                return mapper(fields, previous)
        if real:
            if type(v) is float and isfinite(v):
                return v
        elif type(v) is str:
            return v
        return mapper(fields, previous)
    return one_field


_MISSING = object()


def _quick_follow(cur: Any, steps: tuple[str | int, ...]) -> Any:
    """What :func:`rclverify.traces.field_paths.field_value` reads at ``steps`` (no :data:`EVERY`) through plain dicts and lists, or
    :data:`_MISSING` where it is anything else or raises (the general reading then gives its error)."""
    for step in steps:
        if type(step) is int:
            if (type(cur) is list or type(cur) is tuple) and -len(cur) <= step < len(cur):
                cur = cur[step]
                continue
            return _MISSING
        if type(cur) is not dict:
            return _MISSING
        cur = cur.get(step, _MISSING)
        if cur is _MISSING:
            return _MISSING
    return cur


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
    :class:`rclverify.semantics.floatsem.Tolerance`, set by the mapping's loader),
    which every monitor given these rules applies (docs/monitors.md,
    "Numbers on the wire")."""

    tolerance: Any = None
    #: the transport skew in seconds (``None``: none; backends/monitors/skew.py)
    skew: float | None = None
    #: which nodes keep their time from ``/clock`` (the mapping's ``use_sim_time``): ``True`` every node,
    #: ``False`` none, a set of contract node names those only, ``None`` not said (:func:`sim_time_of`)
    sim_time: bool | frozenset[str] | None = None
    #: (topic, variable name) -> the rule of one variable of a topic that carries several
    #: (``fields: {x: [x], y: [y]}``); read through :func:`rule_for`
    by_var: Mapping[tuple[str, str], TopicRule] = {}


def sim_time_of(rules: Mapping[str, TopicRule], node: str) -> bool | None:
    """Whether contract node ``node`` keeps its time from ``/clock`` by the mapping's ``use_sim_time``
    (:attr:`RuleSet.sim_time`): ``True`` it does, ``False`` it keeps the wall clock, ``None`` not said."""
    sim = getattr(rules, "sim_time", None)
    if sim is None or isinstance(sim, bool):
        return sim
    return node in sim


def rule_for(rules: Mapping[str, TopicRule], topic: str, key: str, default: TopicRule | None = None) -> TopicRule:
    """The rule that maps the variable ``key`` (``in.x``, ``out.y`` or a bare
    name) from ``topic``: its own (``fields: {x: [...]}``, several variables
    on one topic, docs/monitors.md "One topic, several variables") when the
    mapping gives one, else the topic's, else ``default`` (an empty rule)."""
    name = key.split(".", 1)[1] if key.startswith(("in.", "out.")) else key
    mine = getattr(rules, "by_var", {}).get((topic.lstrip("/"), name))
    if mine is not None:
        return mine  # type: ignore[no-any-return]
    return rules.get(topic, default if default is not None else TopicRule())


def load_rules(raw: Any) -> RuleSet:
    """Topic rules from the plan's ``topics`` mapping (``{topic: {fields, update, default, state}}``):
    ``fields`` a list of field names or paths (:func:`parse_path`), or a
    mapping of each variable name to its list when one topic carries several
    variables (kept in ``by_var``, read by :func:`rule_for`), ``update``
    ``accumulate`` or ``replace``, ``state`` a boolean (default false).

    Raises :class:`RuleError` (a ``ValueError``) naming the topic and the
    key at fault for a malformed rule (``topics`` not a mapping, ``fields``
    not a list of names, a malformed path, an unknown ``update``).
    """
    out = RuleSet()
    if raw is not None and not isinstance(raw, Mapping):
        raise RuleError(f"topics must map each topic to its rule, not {raw!r}", "topics")
    for topic, spec in (raw or {}).items():
        spec = spec or {}
        if not isinstance(spec, Mapping):
            raise RuleError(f"topic {topic}: expected a mapping", "topics", topic)
        fields: Any = spec.get("fields", ()) or ()
        per_var = dict(fields) if isinstance(fields, Mapping) else {}
        for var, fs in (per_var or {None: fields}).items():
            _check_fields(str(topic), fs, () if var is None else (var,))
        if per_var:
            fields = ()
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
        for var, fs in per_var.items():
            out.by_var = {**out.by_var, (str(topic).lstrip("/"), str(var)):
                          TopicRule(tuple(str(f) for f in fs), update, spec.get("default"), state)}
    return out


def _check_fields(topic: str, fields: Any, var: tuple[Any, ...]) -> None:
    """Raise :class:`RuleError` unless ``fields`` is a list of field names
    or paths (``var``: the variable key of a per-variable list, ``()`` else)."""
    whose = f" (variable {var[0]})" if var else ""
    if not isinstance(fields, (list, tuple)) or not all(isinstance(f, (str, int)) and not isinstance(f, bool)
                                                        for f in fields):
        raise RuleError(f"topic {topic}{whose}: fields must be a list of message field names, or map each variable "
                        f"to its list ({{x: [x], y: [y]}}), not {fields!r}", "topics", topic, "fields", *var)
    for k, f in enumerate(fields):
        if isinstance(f, str) and is_path(f) and parse_path(f) is None:
            raise RuleError(f"topic {topic}{whose}: {f!r} is not a field path (write names joined by '.', each "
                            f"with optional integer indexes, and at most one [*] for every item of an array: "
                            f"linear.x, pose.pose.position.x, ranges[0], ranges[-1], poses[*].position.x)",
                            "topics", topic, "fields", *var, k)
