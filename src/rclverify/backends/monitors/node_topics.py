"""The topics that carry a node's variables, as the monitors read them: its
``topics(...)`` clauses and the parts of its service and action links
(docs/monitors.md, "From messages to RCL values"; topic names without their
leading ``/``, docs/rcl-language.md, "Topic and service names")."""
from __future__ import annotations

from typing import Any

from rclverify.lang.types import Checked, CheckedNode
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


def copy_sources(checked: Checked) -> dict[str, frozenset[str]]:
    """Per topic a node of ``checked`` publishes (no leading ``/``), the
    topics the nodes publishing it read (:func:`node_topics`, every node of
    the workspace, so the live run and a read of its log or bag say the same):
    the only topics whose header stamps a message of it may carry as copies
    (:class:`~rclverify.traces.event_time.CopiedStamps`; a node with no input,
    a sensor, copies none).  A topic no node publishes is not a key."""
    out: dict[str, set[str]] = {}
    for node in checked.nodes.values():
        topics, _ = node_topics(node)
        inputs = {t for t, vs in topics.items() if any(i for *_, i in vs)}
        for t, vs in topics.items():
            if any(not i for *_, i in vs):
                out.setdefault(t, set()).update(inputs - {t})
    return {t: frozenset(r) for t, r in out.items()}


__all__ = ["copy_sources", "node_topics"]
