"""A name created through a node handle, resolved and remapped by ROS's rules
(docs/ros.md, "Reading real code").

roscpp resolves a ``ros::NodeHandle``'s namespace when the handle is made,
and applies the node's remappings to it then: ``NodeHandle("input")`` in a
node started with ``<remap from="input" to="turtlesim1/turtle1"/>`` has
namespace ``/turtlesim1/turtle1``, so its ``"pose"`` is
``/turtlesim1/turtle1/pose``.  ``NodeHandle(parent, "ns")`` extends the
parent's (already remapped) namespace the same way; ``"~"`` is the node's
own name.  A name created through the handle is then resolved in that
namespace and remapped as a whole (the last matching remap wins).  An rclcpp
sub-node (``create_sub_node("ns")``) extends the node's namespace likewise.
Sources: roscpp ``NodeHandle::NodeHandle``/``resolveName`` (ROS 1 wiki
"roscpp/Overview/NodeHandles", "Names" section 2: remapping); ROS 2 design
"Topic and Service Names".
"""
from __future__ import annotations

from rclverify.ros.extract import names
from rclverify.ros.extract.model import Src
from rclverify.ros.extract.symbols import under


def remap(name: str, ns: str, full: str, remaps: list[tuple[str, str, Src]]) -> tuple[str, Src | None]:
    """``name`` (resolved) after the node's remaps (each ``from`` and ``to``
    resolved in the node's namespace; the last match wins).  A rule written
    ``node:from`` applies only to the node named ``node`` (its name without
    namespace, after its own renaming: rcl's ``rcl_remap_topic_name`` matches
    a rule's node name against the node's; ROS 2 design "ROS command line
    arguments", "Node-specific rules")."""
    at = None
    base = full.rsplit("/", 1)[-1]
    for frm, to, rsrc in remaps:
        only, frm = rule(frm)
        if only is not None and only != base:
            continue
        if names.resolve(frm, ns, full) == name:
            name, at = names.resolve(to, ns, full), rsrc
    return name, at


def rule(frm: str) -> tuple[str | None, str]:
    """The ``from`` side of a remapping rule as ``(node, name)``: ``node:from``
    names the node it applies to (``None``: every node); a ``rostopic://`` or
    ``rosservice://`` scheme is dropped (a ROS name holds no colon; rcl's
    remapping rule syntax)."""
    only, sep, rest = frm.partition(":")
    if not sep or not rest:
        return None, frm
    if only in ("rostopic", "rosservice") and rest.startswith("//"):
        return None, rest[2:]
    if only and not only.startswith(("/", "~")):
        return only, rule(rest)[1]
    return None, frm


def resolve(written: str, handle: tuple[str, ...], ns: str, full: str,
            remaps: list[tuple[str, str, Src]]) -> tuple[str, Src | None]:
    """The resolved, remapped name of ``written`` created through a handle of
    namespaces ``handle`` by node ``full`` in namespace ``ns``, and the remap
    that renamed it last (``None`` when none did)."""
    at = None
    cur = ns
    for seg in handle:
        cur = names.resolve(seg, cur, full) if seg.startswith("~") else names.join(cur, seg)
        cur, hit = remap(cur, ns, full, remaps)
        at = hit or at
    if written.startswith("~") or not handle:
        topic = names.resolve(written, ns if not handle else cur, full)
    else:
        topic = names.join(cur, written)
    topic, hit = remap(topic, ns, full, remaps)
    return topic, hit or at


def shown(written: str, handle: tuple[str, ...]) -> str:
    """The name as the code writes it, with its handle's namespaces (``~status``,
    ``left/scan``): the form contracts name a topic by."""
    return under(list(handle), written)
