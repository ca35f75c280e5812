"""The computation graph of a running ROS 1 system, read from its master
through ``rosgraph``'s master API (``getSystemState``, ``getTopicTypes``,
``lookupService``; ROS Master API, wiki.ros.org/ROS/Master_API).

Debian installs rosgraph for its own Python (``/usr/lib/python3/dist-packages``).
When the running interpreter cannot import it, :func:`import_rosgraph`
retries once with that directory appended to ``sys.path`` (appended, so it
never shadows this interpreter's own packages).

Services: ``getSystemState``'s third list gives each service and the nodes
providing it (ROS 1 registers servers only, never clients).  The master
does not know a service's type; like ``rosservice type`` it is read from
the service itself, by the TCPROS probe (a connection header with
``probe=1``; ROS wiki "ROS/TCPROS") through Debian's ``rosservice`` module.
Without that module, or when a server does not answer, the type is ``None``
and a located note says why.

Actions (actionlib, ROS 1 has no action registry): an action ``P`` runs on
the topics ``P/goal``, ``P/cancel`` (the server subscribes) and
``P/status``, ``P/feedback``, ``P/result`` (the server publishes).  A topic
named ``P/goal`` whose type ends in ``ActionGoal`` marks action ``P``: a
node subscribing to it is an action server, one publishing it an action
client, of type ``pkg/action/T`` from the goal type ``pkg/TActionGoal``.
That node's five ``P/...`` topics are folded into the action (they leave
its ``publishes``/``subscribes``), as the code declares the action, not
its topics (docs/ros.md, "Expected against observed").
"""
from __future__ import annotations

import sys
from typing import Any

from . import names
from .model import Graph, GraphEdge, GraphNode, Note, Src, canon_type

DEBIAN_DIST = "/usr/lib/python3/dist-packages"
# nodes of the ROS 1 infrastructure itself, not part of the robot's graph
INFRA_NODES = {"/rosout"}
INFRA_TOPICS = {"/rosout", "/rosout_agg"}
#: services every roscpp/rospy node offers for its own logging (ROS 1 infrastructure)
INFRA_SERVICE_SUFFIXES = ("/get_loggers", "/set_logger_level")
#: actionlib's topics under an action's name, and which of them the server subscribes to
ACTION_TOPICS = ("goal", "cancel", "status", "feedback", "result")
ACTION_SERVER_SUBSCRIBES = ("goal", "cancel")


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


def _rosservice() -> Any | None:
    """Debian's ``rosservice`` module (its TCPROS probe), or ``None`` when it does not import."""
    import_rosgraph()  # puts Debian's dist-packages on the path when needed
    try:
        import rosservice  # type: ignore[import-not-found]
        return rosservice
    except Exception:  # ImportError, or rospy's own import-time errors
        return None


def service_type(master: Any, name: str, probe: Any) -> tuple[str | None, str]:
    """``(type, "")`` of service ``name`` as ``pkg/srv/Type``, asked of the service itself
    (TCPROS probe, ``rosservice.get_service_headers``), or ``(None, reason)``."""
    if probe is None:
        return None, "its type is not read: Debian's rosservice module is not installed (python3-rosservice)"
    try:
        uri = master.lookupService(name)
        header = probe.get_service_headers(name, uri)  # connects with its own 5 s timeout
    except Exception as exc:  # the server went away, refused, or sent no header
        return None, f"its type is not read: the server did not answer the probe ({' '.join(str(exc).split())[:200]})"
    t = header.get("type") if isinstance(header, dict) else None
    return (canon_type(t, "srv"), "") if t else (None, "its type is not read: the probe's header has no type")


def _infra_service(name: str) -> bool:
    return name.endswith(INFRA_SERVICE_SUFFIXES)


def fold_actions(g: Graph) -> None:
    """Turn each node's actionlib topics into ``action_servers``/``action_clients``
    (the rule in this module's docstring); edits ``g`` in place."""
    for node in g.nodes.values():
        for kind, role in (("sub", "action_servers"), ("pub", "action_clients")):
            for e in list(node.edges_of(kind)):
                if not e.topic.endswith("/goal") or not (e.msg_type or "").endswith("ActionGoal"):
                    continue
                base = e.topic[: -len("/goal")]
                pkg, _, tname = (e.msg_type or "").partition("/msg/")
                atype = f"{pkg}/action/{tname[: -len('ActionGoal')]}" if tname else None
                node.edges_of(role).append(GraphEdge(base or "/", atype, e.src, None, base or "/"))
                parts = {f"{base}/{p}" for p in ACTION_TOPICS}
                node.publishes[:] = [x for x in node.publishes if x.topic not in parts]
                node.subscribes[:] = [x for x in node.subscribes if x.topic not in parts]


def read_master(uri: str, caller: str = "/rclverify", service_types: bool = True) -> Graph:
    """The graph the master at ``uri`` knows: nodes, what each publishes and
    subscribes to with the registered type, the services each provides (type
    from the TCPROS probe when ``service_types``), and actions recognised on
    their topics (:func:`fold_actions`).  Infrastructure (``/rosout``, the
    logger services) is left out.  Every edge is located at ``Src(uri)``;
    ``graph.notes`` holds why a service's type is unknown.  Raises
    :class:`MasterError` when the master cannot be read."""
    rosgraph = import_rosgraph()
    master = rosgraph.Master(caller, master_uri=uri)
    try:
        pubs, subs, srvs = master.getSystemState()
        types = dict(master.getTopicTypes())
    except Exception as exc:  # socket errors, master errors
        raise MasterError(f"cannot read the master at {uri}: {' '.join(str(exc).split())}") from None
    g = Graph()
    src = Src(uri, 1, 1)

    def node_of(n: str) -> GraphNode:
        ns, _ = names.split(n)
        return g.nodes.setdefault(n, GraphNode(n, ns, None, None, origin="master", declared_at=src))

    for kind, table in (("pub", pubs), ("sub", subs)):
        for topic, nodes in table:
            for n in nodes:
                if n in INFRA_NODES or n == caller:
                    continue
                if topic in INFRA_TOPICS:  # every node publishes /rosout: it still shows the node runs
                    node_of(n)
                    continue
                node_of(n).edges_of(kind).append(GraphEdge(topic, canon_type(types.get(topic)), src, None, topic))
    probe = _rosservice() if service_types else None
    said_missing = False
    for service, providers in srvs:
        providers = [n for n in providers if n not in INFRA_NODES and n != caller]
        if _infra_service(service):
            for n in providers:  # a node with no topic of its own still has its logger services
                node_of(n)
            continue
        if not providers:
            continue
        stype, why = service_type(master, service, probe) if service_types else (None, "")
        if why and not (probe is None and said_missing):
            g.notes.append(Note(src, f"service {service}: {why}", "ROS-MASTER"))
            said_missing = said_missing or probe is None
        for n in providers:
            node_of(n).service_servers.append(GraphEdge(service, stype, src, None, service))
    fold_actions(g)
    return g
