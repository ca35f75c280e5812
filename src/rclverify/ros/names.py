"""ROS name resolution (ROS 1 wiki "Names"; ROS 2 design "Topic and Service
Names"): relative names resolve against the node's namespace, private names
(``~x``) against the node's full name, global names (``/x``) stay.
"""
from __future__ import annotations


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
    e.g. ``/rover/sensor``) in namespace ``node_ns``."""
    if name.startswith("~"):
        return join(node_name, name[1:].lstrip("/"))
    return join(node_ns, name)


def split(full: str) -> tuple[str, str]:
    """``/a/b/c`` -> (``/a/b``, ``c``)."""
    full = normalise(full)
    ns, _, base = full.rpartition("/")
    return (ns or "/", base)
