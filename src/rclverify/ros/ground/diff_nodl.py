"""The declared interface as ``ros diff``'s expected graph: ``rclverify ros diff --nodl DIR``
(docs/nodl.md, "ros diff against the documents"; docs/ros.md, "Expected against observed").

Each NoDL document named after a node (a document another one includes is a
part, not a node) is one node of the expected graph, its publishers,
subscriptions, service and action servers and clients its edges, each
located at the document's entry.  A document does not name its node's
namespace: each namespace given for it (``--namespace NODE=NS``) is one
instance, the node ``NS/<Node>``, matched to the running node of that fully
qualified name; a document given none is matched by its base name where
that is unambiguous (:func:`rclverify.model.nodl.match.match_instances`;
case, ``_`` and ``-`` ignored).  Its names are resolved for the node it
matched as rcl resolves them (:func:`rclverify.ros.ground.nodl_code.resolve`),
so a running node wired to another instance's topic (``/r1/odom`` in
``/r2``'s relay, whose document says ``odom``) differs from its document
there; an instance that matches no running node is the node ``NS/<Node>``
(``/<Node>`` with no namespace), which is then missing.  Types are compared as ``pkg/<msg|srv|action>/Name``.

The graph is compared by :func:`rclverify.ros.live.diff_dds.diff_dds`'s rules (nodes,
publishers, subscribers, service servers and clients, action servers and
clients, types, and the running endpoints' QoS conflicts), with the items
naming the documents (:data:`rclverify.ros.live.diff.NODL`).  QoS is compared as ``nodl check
--ros2`` compares it: the reliability and durability each document writes
for a topic's publisher or subscription against what the node's running
endpoint announces, and its deadline, liveliness and lease by the
request-offered rules (a running publisher offers at least, a running
subscription requests at most, what the document says)
(:func:`rclverify.ros.ground.nodl_code.live_qos_of`,
:func:`~rclverify.ros.ground.nodl_code.qos_differences`), each difference a
``qos`` item located at the document's field.  The ends ROS 2 makes for
itself (``/rosout``, ``/parameter_events``, parameter services) are left out
as ``ros diff --ros2`` leaves them out.
"""
from __future__ import annotations

from typing import Any, Mapping, Sequence

from rclverify.model.nodl.contract import full_type
from rclverify.model.nodl.document import Document
from rclverify.ros.extract.model import Graph, GraphEdge, GraphNode, Src
from rclverify.model.nodl.match import Instance, match_instances
from rclverify.ros.ground.nodl_code import GRAPH_LISTS, Announced, live_qos_of, qos_differences, resolve
from rclverify.ros.live.diff import NODL, DiffResult, Item, _t
from rclverify.ros.live.diff_dds import diff_dds

#: the GraphNode edge list of each NoDL list (:meth:`GraphNode.edges_of`'s kinds)
_KIND = {"publishers": "pub", "subscriptions": "sub", "service_servers": "service_servers",
         "service_clients": "service_clients", "action_servers": "action_servers", "action_clients": "action_clients"}


def nodes_of(documents: list[Document]) -> dict[str, Document]:
    """The documents that are nodes, by node: each one no other document of ``documents`` includes."""
    included = {f for d in documents for f in d.files[1:]}
    return {d.node: d for d in documents if d.file not in included}


def nodl_graph(documents: Mapping[str, Document], instances: Sequence[Instance]) -> Graph:
    """The expected graph ``documents`` (by node) declare, one node per instance
    (:func:`rclverify.model.nodl.match.match_instances`) named :attr:`Instance.expected` (the
    running node it matched, else ``NS/<node>``), each endpoint an edge located at the document's entry."""
    g = Graph()
    for inst in instances:
        doc = documents[inst.node]
        full = inst.expected
        ns = full.rsplit("/", 1)[0] or "/"
        gn = GraphNode(full, ns, None, None, sources=list(doc.files), declared_at=Src(doc.file, 1, 1), origin="nodl")
        for e in doc.endpoints:
            edge = GraphEdge(resolve(e.name, full, ns), full_type(e.type, e.kind), Src(e.loc.file, e.loc.line, e.loc.col),
                             written=e.name)
            getattr(gn, GRAPH_LISTS[e.kind]).append(edge)
        g.nodes[full] = gn
    return g


def diff_nodl(documents: Mapping[str, Document], running: Graph, source: str, conflicts: list[Any],
              disc: Announced | None, namespaces: Mapping[str, Sequence[str]] | None = None) -> DiffResult:
    """The documents (by node) as the expected graph against ``running`` (:func:`rclverify.ros.live.diff_dds.graph_of`
    of ``disc``, read through either source), with ``conflicts`` (:func:`rclverify.ros.live.diff_dds.qos_conflicts`)
    and, with ``disc``, each document's topic QoS against what its running endpoint announces
    (module docstring), each document in each of the ``namespaces`` given for it (by node).  Pure:
    raises nothing."""
    instances = match_instances(documents, running.nodes, namespaces)
    static = nodl_graph(documents, instances)
    res = diff_dds(static, running, source, conflicts, None, NODL, names=disc)  # disc names the endpoints of a conflict
    res.not_compared = [n for n in res.not_compared if not n.startswith("the QoS the code asks for")]
    if disc is None:
        res.not_compared.append("the QoS the documents write (no discovery of the running endpoints' QoS)")
        return res
    qos_of = live_qos_of(disc)
    for inst in instances:
        if inst.running is None:
            continue
        full = inst.running
        gn = static.nodes[full]
        for e in documents[inst.node].endpoints:
            if e.kind not in ("publishers", "subscriptions"):
                continue
            edge = next(x for x in gn.edges_of(_KIND[e.kind]) if x.written == e.name)
            for f in qos_differences(e, edge, qos_of, edge.topic, full, "nodl-live"):
                at = f.locs[1]
                res.missing.append(Item("qos", edge.topic, full, edge.msg_type, None, Src(at.file, at.line, at.col),
                                        source, f"{full} {'publishes' if e.kind == 'publishers' else 'subscribes to'} "
                                                f"{edge.topic}{_t(edge.msg_type)}: {f.message.split(': ', 1)[1]}"))
    res.compared.append("the reliability and durability each document writes for a topic, against what the running "
                        "endpoint announces, and its deadline and liveliness by the request-offered rules")
    return res


__all__ = ["diff_nodl", "nodes_of", "nodl_graph"]
