"""The parts of an RML specification (:mod:`.rml`): its event types
(:class:`EventType`, declared once per name by :class:`EventTypes`, each
message field chosen for the RCL type it carries: the Function rule), the
terms of its guarantees (:class:`Term`), the node's :class:`Spec`, RML
identifiers (:func:`rml_id`) and what RML cannot express
(:class:`Inexpressible`).
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Any, Mapping

from rclverify.lang import ast
from rclverify.lang import types as T
from rclverify.lang.printer import expr_to_rcl
from rclverify.traces.mapping import TopicRule

#: Words the RML grammar reserves (RML.g4 and its later versions).
KEYWORDS = frozenset({"not", "matches", "with", "empty", "all", "let", "var", "if", "else", "abs", "true",
                      "false", "min", "max"})
_FLOAT_TYPES = ("float32", "float64")
_INT_TYPES = ("int8", "int16", "int32", "int64", "uint8", "uint16", "uint32", "uint64", "byte", "char")


class Inexpressible(Exception):
    """A part of a guarantee RML cannot express: ``part`` (RCL) and ``why``."""

    def __init__(self, part: ast.Expr, why: str) -> None:
        super().__init__(f"{expr_to_rcl(part)}: {why}")
        self.part, self.why = expr_to_rcl(part), why


@dataclass(frozen=True)
class EventType:
    """``name(params) [not] matches {topic: 't', field: param, ...} [with guard];``"""

    name: str
    params: tuple[str, ...]
    topic: str
    fields: tuple[tuple[str, str], ...]
    negated: bool = False
    guard: str = ""

    @property
    def text(self) -> str:
        head = self.name + (f"({', '.join(self.params)})" if self.params else "")
        body = ", ".join([f"topic: '{self.topic}'"] + [f"{k}: {v}" for k, v in self.fields])
        guard = f" with {self.guard}" if self.guard else ""
        return f"{head} {'not matches' if self.negated else 'matches'} {{{body}}}{guard};"


@dataclass(frozen=True)
class Term:
    """One guarantee's equation ``G<k> = ...;`` or why it has none."""

    guarantee: int
    rcl: str
    text: str = ""
    part: str = ""
    why: str = ""


@dataclass
class Spec:
    """A node's RML specification: event types, one term per guarantee, ``Main``."""

    node: str
    event_types: list[EventType] = field(default_factory=list)
    terms: list[Term] = field(default_factory=list)

    @property
    def main(self) -> str:
        names = [f"G{t.guarantee}" for t in self.terms if t.text]
        return " /\\ ".join(names)


def rml_id(name: str) -> str:
    """An RML lower-case identifier for an RCL name (``x'`` -> ``xp``, ``Agent`` -> ``agent``)."""
    s = name.replace("'", "p")
    s = re.sub(r"[^A-Za-z0-9_]", "_", s)
    s = s[:1].lower() + s[1:]
    if not s or not s[0].isalpha():
        s = "v" + s
    return s + "_" if s in KEYWORDS else s


def literal_text(v: Any) -> str:
    """An RCL literal value as RML writes it (``true``/``false``, a fraction parenthesised)."""
    if isinstance(v, bool):
        return "true" if v else "false"
    text = str(v)
    if "/" in text:
        num, den = text.split("/")
        return f"({num}/{den})"
    return text


class EventTypes:
    """The event types of one node's specification, declared once each
    (mixed into :class:`~.rml.Translator`, which provides the attributes
    annotated on the class)."""

    rules: Mapping[str, TopicRule]
    msg_fields: Mapping[str, list[tuple[str, str]]]  # message type -> [(field, ROS type)]
    topic_of: dict[str, ast.Topic]  # "in.x" / "out.y" -> the topic that carries it
    spec: Spec
    _declared: dict[tuple[str, bool], EventType]

    def _fields(self, topic: ast.Topic, wants: list[T.Type]) -> list[str]:
        """Message fields for the wanted RCL types, in order (the Function rule)."""
        pkg, _, name = topic.msg_type.partition("/")
        defs = self.msg_fields.get(f"{pkg}/msg/{name}")
        rule = self.rules.get(topic.field.lstrip("/"), TopicRule())
        if defs is None:
            return [f"arg{k}" for k in range(1, len(wants) + 1)]
        kinds = dict(defs)
        order = list(rule.fields) or [f for f, _ in defs]
        used: set[str] = set()
        out = []
        for k, w in enumerate(wants, 1):
            for f in order:
                if f in used:
                    continue
                ros = kinds.get(f, "")
                ok = (ros == "string" if isinstance(w, (T.EnumT, T.DataT)) else
                      ros == "bool" if isinstance(w, T.Scalar) and w.name == "BOOL" else
                      ros in _FLOAT_TYPES + _INT_TYPES if isinstance(w, T.Scalar) and w.name == "REAL" else
                      ros in _INT_TYPES if isinstance(w, T.Scalar) else False)
                if ok:
                    used.add(f)
                    out.append(f)
                    break
            else:
                out.append(f"arg{k}")
        return out

    def event_type(self, key: str, name: str, wants: list[T.Type], fixed: tuple[tuple[int, str], ...] = (),
                   negated: bool = False, guard: str = "") -> EventType:
        topic = self.topic_of.get(key)
        if topic is None:  # e.g. a variable bound only to a service or action link
            prefix, _, var = key.partition(".")
            raise Inexpressible(ast.Var(var, prefix), "no topic in topics(...) carries it, so no RML event "  # type: ignore[arg-type]
                                "type observes it")
        fields = self._fields(topic, wants)
        fixed_map = dict(fixed)
        params = tuple(f"x{k}" for k in range(1, len(wants) + 1) if (k - 1) not in fixed_map)
        pairs = []
        p = iter(params)
        for k, f in enumerate(fields):
            pairs.append((f, fixed_map[k] if k in fixed_map else next(p)))
        full = ("not_" if negated else "") + name
        et = EventType(full, params, topic.field.lstrip("/"), tuple(pairs), negated, guard)
        prev = self._declared.get((full, negated))
        if prev is None:
            self._declared[(full, negated)] = et
            self.spec.event_types.append(et)
        return et
