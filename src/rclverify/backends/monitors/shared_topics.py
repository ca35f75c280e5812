"""One topic, several variables: distinct fields or a located error.

A node may map two of its variables to one topic (``topics(geometry_msgs/Point
target matches(in.x), geometry_msgs/Point target matches(in.y))``).  The
scalar rule (docs/monitors.md, "From messages to RCL values") reads the
first field of a matching type, so without more both variables read the
same field (``x``): the second variable silently holds the first one's
value, and the assumption it then violates was blamed on the environment.

This check, run with the monitors entries of the plan (backends/entry_checks.py),
finds every pair of variables of one node on one topic that would read the
same field: both of one kind (equal types, or two numbers: a REAL reads an
INTEGER field too) and not each given its own, different field list in the
mapping file (``target: {fields: {x: [x], y: [y]}}``, read by
:func:`rclverify.traces.mapping.rule_for`).  Each such pair is one error
located at the second variable's ``topics`` clause in the contract, naming
the field both would read and the mapping entry that separates them.
"""
from __future__ import annotations

from typing import Any, Mapping

from rclverify.lang import ast
from rclverify.lang import types as T
from rclverify.lang.errors import Diagnostic, error
from rclverify.lang.types import Checked
from rclverify.traces.mapping import TopicRule, rule_for

_NUMBERS = ("REAL", "INTEGER", "NATURAL")


def _same_kind(a: T.Type, b: T.Type) -> bool:
    if a == b:
        return True
    return isinstance(a, T.Scalar) and isinstance(b, T.Scalar) and a.name in _NUMBERS and b.name in _NUMBERS


def _key(cn: Any, v: ast.Var) -> str:
    inp = v.prefix == "in" or (v.prefix is None and v.name in cn.inputs)
    return ("in." if inp else "out.") + v.name


def shared_topic_errors(checked: Checked, node: str, rules: Mapping[str, TopicRule],
                        mapping: str = "backends/monitors/mapping.yaml") -> list[Diagnostic]:
    """Located errors (``E-shared-topic``) of ``node``'s variables that share
    a topic and would read one field under ``rules`` (the mapping file
    ``mapping``'s topic rules; empty without one).  Returns ``[]`` for an
    unknown node."""
    cn = checked.nodes.get(node)
    if cn is None:
        return []
    by_topic: dict[str, list[tuple[str, T.Type, ast.Loc]]] = {}
    for t in cn.node.topics:
        typ = cn.io_type(t.match) if t.match is not None else None
        if typ is None or t.match is None:
            continue
        by_topic.setdefault(t.field.lstrip("/"), []).append((_key(cn, t.match), typ, t.loc))
    out: list[Diagnostic] = []
    own = getattr(rules, "by_var", {})
    for topic, vs in by_topic.items():
        for i, (k2, t2, at) in enumerate(vs):
            for k1, t1, _ in vs[:i]:
                if not _same_kind(t1, t2):
                    continue
                n1, n2 = k1.split(".", 1)[1], k2.split(".", 1)[1]
                f1, f2 = rule_for(rules, topic, k1).fields, rule_for(rules, topic, k2).fields
                if (topic, n1) in own and (topic, n2) in own and f1 != f2:
                    continue  # each variable reads its own field
                field = f"field {f1[0]!r}" if f1 else f"its first {t1} field"
                out.append(error(at, f"{node} maps {k1} and {k2} to topic {topic}: both would read {field}, so "
                                     f"{k2} would silently hold {k1}'s value; give each variable its field in the "
                                     f"mapping file ({mapping}): '{topic}: {{fields: {{{n1}: [<field>], "
                                     f"{n2}: [<field>]}}}}' (docs/monitors.md, \"One topic, several variables\")",
                                 "E-shared-topic"))
                break
    return out


__all__ = ["shared_topic_errors"]
