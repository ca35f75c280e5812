"""What a deadline monitor (:mod:`.deadlines`) reads of a node and of an event:
the topics that carry the node's variables with the message part each maps
from (:func:`topic_bindings`), an event's time on the stamps' clock in
integer nanoseconds (:func:`event_stamp_ns`), and whether a node has a timed
guarantee at all (:func:`has_deadlines`).
"""
from __future__ import annotations

from rclverify.lang.types import CheckedNode
from rclverify.traces.events import Event, header_stamp_ns, to_ns
from rclverify.backends.monitors.verdicts import LINK_TOPICS


def event_stamp_ns(ev: Event) -> int:
    """The event's time on the stamps' clock in integer nanoseconds: a header's
    ``secs``/``nsecs`` (ROS 1) or ``sec``/``nanosec`` (ROS 2, builtin_interfaces/Time)
    exactly, else :func:`~rclverify.traces.events.to_ns` of its own time (:attr:`Event.stamped
    <rclverify.traces.events.Event.stamped>`: the time the trace gives it, or, for a message the live
    engine heard too late to order and released at its clock, the time it was published at).
    Deadlines are compared in these integers (docs/semantics.md, "Deadlines"):
    ``0.7 + 0.2`` in doubles is ``0.8999999999999999``, and an answer stamped at
    0.9 s was reported "0 ms past the deadline"."""
    s = header_stamp_ns(ev.fields)
    return to_ns(ev.stamped) if s is None else s


def topic_bindings(node: CheckedNode) -> dict[str, list[tuple[str, str]]]:
    """topic (no leading ``/``) -> ``[(key, part)]``: ``key`` is ``in.x`` or
    ``out.y``; ``part`` the message part that maps to it (``""``: the whole
    message, ``"goal"``/``"feedback"``/``"result"`` for an actionlib topic)."""
    out: dict[str, list[tuple[str, str]]] = {}
    for t in node.node.topics:
        if t.match is not None:
            prefix = t.match.prefix or ("in" if t.match.name in node.inputs else "out")
            out.setdefault(t.field.lstrip("/"), []).append((f"{prefix}.{t.match.name}", ""))
    for lk in node.node.links:
        for suffix, v in zip(LINK_TOPICS[lk.kind], lk.parts):
            part = suffix if lk.kind == "action" else ""
            out.setdefault(f"{lk.name.lstrip('/')}/{suffix}", []).append((f"{v.prefix}.{v.name}", part))
    return out


def has_deadlines(node: CheckedNode) -> bool:
    """Whether ``node`` has a guarantee with a trigger (with or without a deadline)."""
    return any(c.trigger is not None for c in node.node.guarantees)
