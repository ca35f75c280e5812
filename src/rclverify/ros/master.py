"""The computation graph of a running ROS 1 system, read from its master
through ``rosgraph``'s master API (``getSystemState``, ``getTopicTypes``;
ROS Master API, wiki.ros.org/ROS/Master_API).

Debian installs rosgraph for its own Python (``/usr/lib/python3/dist-packages``).
When the running interpreter cannot import it, :func:`import_rosgraph`
retries once with that directory appended to ``sys.path`` (appended, so it
never shadows this interpreter's own packages).
"""
from __future__ import annotations

import sys
from typing import Any

from . import names
from .model import Graph, GraphEdge, GraphNode, Src, canon_type

DEBIAN_DIST = "/usr/lib/python3/dist-packages"
# nodes of the ROS 1 infrastructure itself, not part of the robot's graph
INFRA_NODES = {"/rosout"}
INFRA_TOPICS = {"/rosout", "/rosout_agg"}


class MasterError(Exception):
    """The master cannot be reached or rosgraph is not installed (reason in ``str``)."""


def import_rosgraph() -> Any:
    """``rosgraph`` (the module), from this interpreter or Debian's dist-packages.

    Raises :class:`MasterError` when neither has it."""
    try:
        import rosgraph  # type: ignore[import-not-found]
        return rosgraph
    except ImportError:
        pass
    if DEBIAN_DIST not in sys.path:
        sys.path.append(DEBIAN_DIST)
    try:
        import rosgraph  # type: ignore[import-not-found]  # noqa: F811
        return rosgraph
    except ImportError as exc:
        raise MasterError(f"rosgraph is not installed (apt-get install python3-rosgraph): {exc}") from None


def read_master(uri: str, caller: str = "/rclverify") -> Graph:
    """The graph the master at ``uri`` knows: nodes, and what each
    publishes and subscribes to with the registered type.  Infrastructure
    (``/rosout``) is left out. Raises :class:`MasterError`."""
    rosgraph = import_rosgraph()
    master = rosgraph.Master(caller, master_uri=uri)
    try:
        pubs, subs, _srvs = master.getSystemState()
        types = dict(master.getTopicTypes())
    except Exception as exc:  # socket errors, master errors
        raise MasterError(f"cannot read the master at {uri}: {exc}") from None
    g = Graph()
    src = Src(uri, 1, 1)
    for kind, table in (("pub", pubs), ("sub", subs)):
        for topic, nodes in table:
            if topic in INFRA_TOPICS:
                continue
            for n in nodes:
                if n in INFRA_NODES or n == caller:
                    continue
                ns, _ = names.split(n)
                node = g.nodes.setdefault(n, GraphNode(n, ns, None, None, origin="master", declared_at=src))
                e = GraphEdge(topic, canon_type(types.get(topic)), src, None, topic)
                (node.publishes if kind == "pub" else node.subscribes).append(e)
    return g
