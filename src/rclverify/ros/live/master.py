"""The computation graph of a running ROS 1 system, read from its master
through the ROS Master API (``getSystemState``, ``getTopicTypes``,
``lookupService``; ROS Master API, wiki.ros.org/ROS/Master_API).

The master is spoken to directly over XML-RPC (:mod:`.master_rpc`), each
call within :data:`~.master_rpc.MASTER_TIMEOUT_S` seconds and each answer
checked for the shape the Master API gives it: a master that does not
answer, or answers something malformed, is one :class:`MasterError`
naming it, the call and the fault, never a hang or a traceback.
(:func:`import_rosgraph` remains for the callers that need rospy's
libraries; reading the master does not.)

Services: ``getSystemState``'s third list gives each service and the nodes
providing it (ROS 1 registers servers only, never clients).  The master
does not know a service's type; like ``rosservice type`` it is read from
the service itself, by the TCPROS probe (a connection header with
``probe=1``; ROS wiki "ROS/TCPROS"), each within
:data:`~.master_rpc.PROBE_TIMEOUT_S` seconds and all of them within
:data:`PROBES_BUDGET_S`.  When a server does not answer, the type is
``None`` and a located note says why.

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
import time
from typing import Any

from rclverify.ros.extract import names
from rclverify.ros.live.master_rpc import (MASTER_TIMEOUT_S, PROBE_TIMEOUT_S, MasterError, lookup_service, probe_service_type,
                         system_state, topic_types)
from rclverify.ros.extract.model import Graph, GraphEdge, GraphNode, Note, Src, canon_type

__all__ = ["ACTION_SERVER_SUBSCRIBES", "ACTION_TOPICS", "INFRA_NODES", "INFRA_TOPICS", "MasterError",
           "PROBES_BUDGET_S", "fold_actions", "import_rosgraph", "read_master", "service_type"]

DEBIAN_DIST = "/usr/lib/python3/dist-packages"


def import_rosgraph() -> Any:
    """``rosgraph`` (the module), from this interpreter or Debian's dist-packages.

    Raises :class:`MasterError` when neither has it."""
    try:
        import rosgraph  # deferred: optional or conditional (inside a block)
        return rosgraph
    except ImportError:
        pass
    if DEBIAN_DIST not in sys.path:
        sys.path.append(DEBIAN_DIST)
    try:
        import rosgraph  # noqa: F811  # deferred: optional or conditional (inside a block)
        return rosgraph
    except ImportError as exc:
        raise MasterError(f"rosgraph is not installed (apt-get install python3-rosgraph): {exc}") from None


# nodes of the ROS 1 infrastructure itself, not part of the robot's graph
INFRA_NODES = {"/rosout"}
INFRA_TOPICS = {"/rosout", "/rosout_agg"}
#: services every roscpp/rospy node offers for its own logging (ROS 1 infrastructure)
INFRA_SERVICE_SUFFIXES = ("/get_loggers", "/set_logger_level")
#: actionlib's topics under an action's name, and which of them the server subscribes to
ACTION_TOPICS = ("goal", "cancel", "status", "feedback", "result")
ACTION_SERVER_SUBSCRIBES = ("goal", "cancel")
#: Seconds all the service probes of one reading of the master may take together.
PROBES_BUDGET_S = 60.0


def service_type(uri: str, name: str, deadline: float, timeout: float = MASTER_TIMEOUT_S) -> tuple[str | None, str]:
    """``(type, "")`` of service ``name`` as ``pkg/srv/Type``, asked of the service itself
    (``lookupService``, then the TCPROS probe), or ``(None, reason)``; nothing is asked
    once the monotonic clock passed ``deadline``."""
    left = deadline - time.monotonic()
    if left <= 0:
        return None, (f"its type is not read: the service probes took their time limit of {PROBES_BUDGET_S:g} s "
                      "together")
    try:
        service_uri = lookup_service(uri, name, timeout=min(timeout, left))
        t = probe_service_type(name, service_uri, timeout=min(PROBE_TIMEOUT_S, max(left, 0.1)))
    except MasterError as exc:  # the server went away, refused, sent no header, or took too long
        return None, f"its type is not read: {' '.join(str(exc).split())[:240]}"
    return canon_type(t, "srv"), ""


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


def read_master(uri: str, caller: str = "/rclverify", service_types: bool = True,
                timeout: float = MASTER_TIMEOUT_S) -> Graph:
    """The graph the master at ``uri`` knows: nodes, what each publishes and
    subscribes to with the registered type, the services each provides (type
    from the TCPROS probe when ``service_types``), and actions recognised on
    their topics (:func:`fold_actions`).  Infrastructure (``/rosout``, the
    logger services) is left out.  Every edge is located at ``Src(uri)``;
    ``graph.notes`` holds why a service's type is unknown.  ``timeout``:
    seconds each call to the master may take.  Raises :class:`MasterError`
    when the master cannot be read within that limit or answers something
    malformed."""
    try:
        pubs, subs, srvs = system_state(uri, timeout)
        types = topic_types(uri, timeout)
    except MasterError as exc:
        raise MasterError(f"cannot read the master at {uri}: {exc}") from None
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
    deadline = time.monotonic() + PROBES_BUDGET_S
    for service, providers in srvs:
        providers = [n for n in providers if n not in INFRA_NODES and n != caller]
        if _infra_service(service):
            for n in providers:  # a node with no topic of its own still has its logger services
                node_of(n)
            continue
        if not providers:
            continue
        stype, why = service_type(uri, service, deadline, timeout) if service_types else (None, "")
        if why:
            g.notes.append(Note(src, f"service {service}: {why}", "ROS-MASTER"))
        for n in providers:
            node_of(n).service_servers.append(GraphEdge(service, stype, src, None, service))
    fold_actions(g)
    return g
