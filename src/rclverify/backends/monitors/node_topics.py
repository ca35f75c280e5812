"""The topics that carry a node's variables, as the monitors read them: its
``topics(...)`` clauses and the parts of its service and action links
(docs/monitors.md, "From messages to RCL values"; topic names without their
leading ``/``, docs/rcl-language.md, "Topic and service names")."""
from __future__ import annotations

from typing import Any

from rclverify.lang.types import CheckedNode
from rclverify.backends.monitors.verdicts import LINK_TOPICS


def node_topics(node: CheckedNode) -> tuple[dict[str, list[tuple[str, Any, bool]]], dict[tuple[str, str], str]]:
    """The topics that carry ``node``'s variables: topic (no leading ``/``) ->
    ``[(key, type, is_input)]`` with ``key`` ``in.x``/``out.x``, from its
    ``topics(...)`` and the parts of its service and action links
    (:data:`LINK_TOPICS`); and ``(topic, key)`` -> the actionlib part of the
    message that maps to the variable."""
    topics: dict[str, list[tuple[str, Any, bool]]] = {}
    for t in node.node.topics:
        if t.match is None:
            continue
        typ = node.io_type(t.match)
        if typ is None:
            continue
        is_input = t.match.prefix == "in" or (t.match.prefix is None and t.match.name in node.inputs)
        key = ("in." if is_input else "out.") + t.match.name
        topics.setdefault(t.field.lstrip("/"), []).append((key, typ, is_input))
    parts: dict[tuple[str, str], str] = {}
    for lk in node.node.links:
        for suffix, v in zip(LINK_TOPICS.get(lk.kind, ()), lk.parts):
            typ = node.io_type(v)
            if typ is None or v.prefix not in ("in", "out"):
                continue
            topic, key = f"{lk.name.lstrip('/')}/{suffix}", f"{v.prefix}.{v.name}"
            topics.setdefault(topic, []).append((key, typ, v.prefix == "in"))
            if lk.kind == "action":
                parts[(topic, key)] = suffix
    return topics, parts


__all__ = ["node_topics"]
