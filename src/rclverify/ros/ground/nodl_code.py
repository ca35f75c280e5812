"""A node's NoDL document against the endpoints its code creates (the ROS scan) or its running node has
(docs/nodl.md, "Against the code", "Against the running graph").

The scan (:mod:`rclverify.ros.graph.scan`) gives each node of the code its
publishers, subscriptions, service and action servers and clients, each
fully resolved (its namespace, remappings) with its type where the code
says it, and where the code creates it.  A document is matched to a node
by its fully qualified name, in each namespace given for it, else by its
base name where that is unambiguous (:mod:`rclverify.model.nodl.match`;
names compared ignoring case, ``_``, ``-``), and its names are resolved for
that node as rcl resolves them (:func:`resolve`: ``x`` is ``<namespace>/x``,
``~/x`` is ``<node>/x``, ``{node}`` and ``{ns}`` substituted).
Findings, each located at both the code and the document:

* ``nodl-code-undeclared`` (error): the code creates an endpoint the document lacks;
* ``nodl-code-absent`` (warning: the scan may not see every endpoint the
  code makes, docs/ros.md's recall): the document declares an endpoint the
  scanned code does not create;
* ``nodl-code-type`` (error): both have it, with different types (where the code names its type);
* ``nodl-code-qos`` (error): a topic's reliability or durability the code
  asks for literally (:mod:`rclverify.ros.extract.code_qos`) differs from
  the one the document writes (a policy either leaves unsaid is not compared).

The same comparison against the running graph (``side="live"``: the nodes
DDS discovery shows, :func:`rclverify.ros.live.diff_dds.read_dds_graph`, or
rclpy's graph API)
gives ``nodl-live-*`` findings, located at the document and the graph's
source (``DDS domain N``); there an endpoint the document declares and the
running node lacks is an error, and the QoS compared is what each running
endpoint announces (:func:`live_qos_of`).  The ends a running node's client
library makes rather than its code (introspection events, a managed node's
lifecycle interface) are not its own: undeclared, they are no finding.
"""
from __future__ import annotations

from pathlib import Path
from typing import Callable, Mapping, NamedTuple, Protocol, Sequence

from rclverify.lang import ast
from rclverify.model.nodl.contract import type_key
from rclverify.model.nodl.document import Document, Endpoint, QoS
from rclverify.model import names
from rclverify.model.nodl.findings import Finding
from rclverify.model.nodl.match import match_instances
from rclverify.model.nodl.qos import DURATIONS, mismatches
from rclverify.ros.extract import code_qos
from rclverify.ros.extract.model import GraphEdge, GraphNode, Src
from rclverify.ros.live.dds import ros_name
from rclverify.ros.live.dds_discovery import EndpointInfo
from rclverify.ros.live.dds_qos import INFINITE_NS
from rclverify.ros.ground.lifecycle import MANAGEMENT

#: A scanned node's list of each NoDL endpoint list.
GRAPH_LISTS = {"publishers": "publishes", "subscriptions": "subscribes", "service_servers": "service_servers",
               "service_clients": "service_clients", "action_servers": "action_servers",
               "action_clients": "action_clients"}


def resolve(name: str, node: str, namespace: str) -> str:
    """A document's ``name`` fully qualified for node ``node`` (its full name) in ``namespace``, as rcl
    expands it (:func:`rclverify.model.names.expand`: ``~``, ``{node}``, ``{ns}``, relative names); a
    name rcl refuses, or a scanned node whose name is none (``/talker@pkg.exe``), by the plain rule
    (``~/x`` below the node, ``/x`` as written, ``x`` below the namespace)."""
    try:
        return names.expand(name, names.split_fqn(node)[1], namespace)
    except names.BadName:
        pass
    if name == "~":
        return node
    if name.startswith("~/"):
        return f"{node}/{name[2:]}"
    if name.startswith("/"):
        return name
    return f"{namespace.rstrip('/')}/{name}"


def _loc(src: Src | None, fallback: ast.Loc) -> ast.Loc:
    return ast.Loc(src.file, src.line, src.col) if src is not None else fallback


#: What a comparison calls each side and its finding codes' prefix: the scan's code, or the running graph.
SIDES = {"code": ("the scanned code", "nodl-code"), "live": ("the running node", "nodl-live")}


class OtherQos(NamedTuple):
    """The QoS the other side gives a topic's endpoint: ``reliability`` and ``durability`` lower case
    (``None`` where unsaid), ``where`` in words; ``timing`` the deadline, liveliness kind and lease
    as a document's :class:`~rclverify.model.nodl.document.QoS` would write them (0 ns: none),
    ``None`` when that side does not say them (the code's literal QoS)."""

    reliability: str | None
    durability: str | None
    where: str
    timing: QoS | None = None


#: The QoS one side gives the endpoint ``edge`` of list ``kind`` of node ``node`` (its full name); ``None`` when unknown.
QosOf = Callable[[str, str, GraphEdge], "OtherQos | None"]


def code_qos_of(base: Path | None) -> QosOf:
    """The QoS the code asks for literally where it creates a topic's endpoint (:mod:`.code_qos`)."""
    def read(node: str, kind: str, edge: GraphEdge) -> OtherQos | None:
        q = code_qos.read(edge.src, "pub" if kind == "publishers" else "sub", base)
        return None if q is None else OtherQos(q.reliability, q.durability, f"in the code ({q.text})")
    return read


def _doc_ns(ns: int) -> int:
    """A running duration (ns, :data:`INFINITE_NS` for none) as a document writes it (0: none)."""
    return 0 if ns <= 0 or ns >= INFINITE_NS else ns


class Announced(Protocol):
    """What discovery tells of the running endpoints: rclverify's DDS participant
    (:class:`~rclverify.ros.live.dds_discovery.Discovery`) or rclpy's graph API
    (:class:`~rclverify.runtime.rclpy_source.graph.RclpyDiscovery`, the same shape)."""

    writers: dict[bytes, EndpointInfo]
    readers: dict[bytes, EndpointInfo]

    def node_of(self, guid: bytes) -> str | None: ...


def live_qos_of(disc: Announced) -> QosOf:
    """The QoS a running endpoint announces in DDS discovery (:mod:`rclverify.ros.live.dds_discovery`):
    that of the node's writers (publishers) or readers (subscriptions) of the topic, as
    ``ros_discovery_info`` gives endpoints to nodes; unknown (``None``) when the node has none
    there or several that announce different QoS."""
    def read(node: str, kind: str, edge: GraphEdge) -> OtherQos | None:
        table = disc.writers if kind == "publishers" else disc.readers
        got = {("reliable" if e.qos.reliable else "best_effort", e.qos.durability, _doc_ns(e.qos.deadline_ns),
                e.qos.liveliness.upper(), _doc_ns(e.qos.lease_ns)) for e in table.values()
               if disc.node_of(e.guid) == node and ros_name(e.topic) == ("topic", edge.topic)}
        if len(got) != 1:
            return None
        rel, dur, deadline, live, lease = got.pop()
        timing = QoS("SYSTEM_DEFAULT", rel.upper(), deadline_ns=deadline, liveliness=live,
                     liveliness_lease_duration_ns=lease)
        return OtherQos(rel, dur, "announced by the running node", timing)
    return read


def qos_differences(doc_end: Endpoint, edge: GraphEdge, qos_of: QosOf, fqn: str, node: str,
                    code: str) -> list[Finding]:
    """The QoS the other side gives endpoint ``edge`` (``qos_of``) against what document endpoint
    ``doc_end`` writes: one finding ``<code>-qos`` per policy, located at ``edge`` and at the
    document's field (docs/nodl.md).  Reliability and durability must be what the document writes (a
    policy either side leaves unsaid, ``SYSTEM_DEFAULT`` and ``BEST_AVAILABLE`` are not compared).
    Deadline, liveliness and its lease, where the other side says them (a running endpoint), are
    judged by the request-offered rules (:func:`rclverify.model.nodl.qos.mismatches`, the document's
    unsaid policies rmw's defaults): a publisher must offer at least what its document offers, a
    subscription request at most what its document requests, so every end the document admits
    still connects."""
    if doc_end.qos is None or doc_end.kind not in ("publishers", "subscriptions"):
        return []
    got = qos_of(node, doc_end.kind, edge)
    if got is None:
        return []
    out = []
    for policy, said in (("reliability", got.reliability), ("durability", got.durability)):
        written = getattr(doc_end.qos, policy)
        if said is None or written in (None, "SYSTEM_DEFAULT", "BEST_AVAILABLE") or said.upper() == written:
            continue
        out.append(Finding(f"{code}-qos", f"node {node}: {fqn}'s {policy} is {said.upper()} {got.where} and "
                                          f"{written} in its NoDL document",
                           (_loc(edge.src, doc_end.loc), doc_end.qos.where(policy))))
    if got.timing is None:
        return out
    pub = doc_end.kind == "publishers"
    for m in mismatches(got.timing, doc_end.qos) if pub else mismatches(doc_end.qos, got.timing):
        if m.policy in ("reliability", "durability"):
            continue
        what = dict(DURATIONS).get(m.policy, m.policy)
        ran, doc = (m.offered, m.requested) if pub else (m.requested, m.offered)
        verb, other = ("offers", "subscription") if pub else ("requests", "publisher")
        out.append(Finding(f"{code}-qos", f"node {node}: {fqn} {verb} {what} {ran} {got.where} and its NoDL "
                                          f"document {verb} {doc}: a {other} the document admits does not connect "
                                          f"({m.why})", (_loc(edge.src, doc_end.loc), doc_end.qos.where(m.policy))))
    return out


#: the ends of a running node that its client library makes, not its code (:func:`_library_made`)
_LIFECYCLE_ENDS = {(("publishers" if role == "pub" else role), name) for role, name, _t in MANAGEMENT}


def _library_made(key: tuple[str, str], gn: GraphNode) -> bool:
    """Whether the running node's end ``key`` (``(kind, ROS name)``) is one its client library makes
    rather than its code, which a NoDL document does not declare: a service's or an action's
    introspection events (``<name>/_service_event``, made when introspection is configured) and a
    managed node's lifecycle interface (``~/change_state``, ``~/transition_event``, ...,
    :data:`~rclverify.ros.ground.lifecycle.MANAGEMENT`; ROS 2 design, "Managed nodes")."""
    kind, name = key
    if name.endswith("/_service_event"):
        return True
    prefix = gn.name.rstrip("/") + "/"
    return name.startswith(prefix) and (kind, name[len(prefix):]) in _LIFECYCLE_ENDS


def compare_code(doc: Document, gn: GraphNode, base: Path | None = None, side: str = "code",
                 qos_of: QosOf | None = None) -> list[Finding]:
    """The findings of document ``doc`` against node ``gn`` of the scan (``side="code"``) or of the
    running graph (``"live"``; codes ``nodl-live-*``): module docstring.  ``qos_of`` gives the
    other side's QoS of a topic's endpoint (default: the code's, read from the files the scan
    names, relative to ``base``)."""
    what, code = SIDES[side]
    qos_of = qos_of or code_qos_of(base)
    top = ast.Loc(doc.file, 1, 1)
    node_loc = _loc(gn.declared_at, top)
    ends: dict[tuple[str, str], GraphEdge] = {}
    for kind, attr in GRAPH_LISTS.items():
        for edge in getattr(gn, attr):
            ends.setdefault((kind, edge.topic), edge)
    out: list[Finding] = []
    seen: set[tuple[str, str]] = set()
    for e in doc.endpoints:
        key = (e.kind, resolve(e.name, gn.name, gn.namespace))
        seen.add(key)
        edge = ends.get(key)
        if edge is None:
            out.append(Finding(f"{code}-absent", f"node {gn.name}'s NoDL document declares {key[1]} ({e.type}) in "
                                                 f"{e.kind}, and {what} has no such endpoint",
                               (e.loc, node_loc), "warning" if side == "code" else "error"))
            continue
        if edge.msg_type and type_key(edge.msg_type) != type_key(e.type):
            out.append(Finding(f"{code}-type", f"node {gn.name}: {key[1]} has type {edge.msg_type} in {what} and "
                                               f"{e.type} in its NoDL document", (_loc(edge.src, top), e.type_loc)))
            continue
        out += qos_differences(e, edge, qos_of, key[1], gn.name, code)
    for key, edge in ends.items():
        if key not in seen and not (side == "live" and _library_made(key, gn)):
            out.append(Finding(f"{code}-undeclared", f"node {gn.name} has {key[1]} "
                                                     f"({edge.msg_type or 'type unknown'}) in {key[0]} in {what}, "
                                                     f"and its NoDL document {doc.file} does not declare it",
                               (_loc(edge.src, top), top)))
    return out


def check_code(documents: Mapping[str, Document], nodes: Mapping[str, GraphNode], base: Path | None = None,
               side: str = "code", qos_of: QosOf | None = None,
               namespaces: Mapping[str, Sequence[str]] | None = None) -> tuple[dict[str, str], list[Finding]]:
    """Each document of ``documents`` (by node), in each namespace ``namespaces`` gives it, against
    the node it matches among ``nodes`` (a graph's nodes by fully qualified name;
    :func:`rclverify.model.nodl.match.match_instances`: by fully qualified name, by base name only
    when unambiguous; :func:`compare_code` for ``base``, ``side``, ``qos_of``); returns
    ``({instance: graph node}, findings)``, an instance named by its document's node, ``in NS``
    when a namespace was given.  An instance matching no node is not compared, and says so, with
    why (``nodl-code-unmatched``, a warning; ``nodl-live-unmatched``, an error: a node not
    running, or not yet discovered, is never checked green)."""
    code = SIDES[side][1]
    matched: dict[str, str] = {}
    out: list[Finding] = []
    for inst in match_instances(documents, nodes, namespaces):
        doc = documents[inst.node]
        if inst.running is not None:
            matched[inst.label] = inst.running
            out += compare_code(doc, nodes[inst.running], base, side, qos_of)
            continue
        where = "the scanned code" if side == "code" else "the running graph (not running, or not yet discovered)"
        inside = "" if inst.namespace is None else f" in {inst.namespace}"
        out.append(Finding(f"{code}-unmatched", f"node {inst.node}'s NoDL document{inside} matches no node of {where}: "
                                                f"{inst.why}; nothing of it was compared", (ast.Loc(doc.file, 1, 1),),
                           "warning" if side == "code" else "error"))
    return matched, out


__all__ = ["Announced", "GRAPH_LISTS", "OtherQos", "QosOf", "SIDES", "check_code", "code_qos_of", "compare_code", "live_qos_of",
           "qos_differences", "resolve"]
