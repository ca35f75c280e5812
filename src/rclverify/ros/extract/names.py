"""ROS name resolution for the code scan (ROS 1 wiki "Names"; ROS 2 design
"Topic and Service Names"): relative names resolve against the node's
namespace, private names (``~x``, the scan's written form of ROS 2's ``~/x``)
against the node's full name, global names (``/x``) stay.

A name ``rcl`` accepts is resolved by the project's one resolver,
:func:`rclverify.model.names.expand` (so ``{node}`` and ``{ns}`` are
substituted as rcl substitutes them); a name it refuses (a ROS 1 form, a
doubled or trailing ``/``, a program kept apart as ``/talker@pkg.exe``) by the
plain rule above with its ``/`` normalised.
"""
from __future__ import annotations

import re

from rclverify.model import names as rcl_names


def join(ns: str, name: str) -> str:
    """``join('/a', 'b/c')`` -> ``/a/b/c``; a global ``name`` is returned normalised."""
    if name.startswith("/"):
        return normalise(name)
    return normalise(f"{ns.rstrip('/')}/{name}")


def normalise(name: str) -> str:
    """Collapse repeated ``/`` and drop a trailing one; the root is ``/``."""
    parts = [p for p in name.split("/") if p]
    return "/" + "/".join(parts)


def resolve(name: str, node_ns: str, node_name: str) -> str:
    """The fully resolved topic ``name`` for a node ``node_name`` (resolved,
    e.g. ``/rover/sensor``) in namespace ``node_ns``: module docstring."""
    private = name.startswith("~")
    written = "~/" + name[1:].lstrip("/") if private and name != "~" else name
    ns = split(node_name)[0] if private else node_ns
    try:
        out = rcl_names.expand(written, split(node_name)[1], ns)
    except rcl_names.BadName:
        out = ""
    if out and rcl_names.full_name_problem(out) is None:
        return out
    if private:
        return join(node_name, name[1:].lstrip("/"))
    return join(node_ns, name)


def split(full: str) -> tuple[str, str]:
    """``/a/b/c`` -> (``/a/b``, ``c``)."""
    full = normalise(full)
    ns, _, base = full.rpartition("/")
    return (ns or "/", base)


_NODE_NAME = re.compile(r"^/?(?:[A-Za-z_][A-Za-z0-9_]*/)*[A-Za-z_][A-Za-z0-9_]*$")


def node_name_problem(name: str) -> str | None:
    """Why ``name`` (a node name as the code gives it) names no node, or ``None``
    when it can: ROS 2's node name rules ("Topic and Service name mapping",
    node names: letters, digits and underscores, not starting with a digit,
    never empty) and ROS 1's (names are tokens joined by ``/``; a node's own
    name holds no ``~``).  An empty or ``~`` name would otherwise be read as
    the node ``/``."""
    if not name.strip("/"):
        return "is empty"
    if not _NODE_NAME.match(name):
        return f"'{name}' is no valid node name"
    return None
