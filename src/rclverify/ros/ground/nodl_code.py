"""A node's NoDL document against the endpoints its code creates (the ROS scan; docs/nodl.md, "Against the code").

The scan (:mod:`rclverify.ros.graph.scan`) gives each node of the code its
publishers, subscriptions, service and action servers and clients, each
fully resolved (its namespace, remappings) with its type where the code
says it, and where the code creates it.  A document is matched to a scanned
node as a contract is (:func:`rclverify.ros.ground.ground.match_nodes`: by
name, ignoring case, ``_``, ``-``), and its names are resolved in that
node's namespace (``x`` is ``<namespace>/x``, ``~/x`` is ``<node>/x``).
Findings, each located at both the code and the document:

* ``nodl-code-undeclared`` (error): the code creates an endpoint the document lacks;
* ``nodl-code-absent`` (warning: the scan may not see every endpoint the
  code makes, docs/ros.md's recall): the document declares an endpoint the
  scanned code does not create;
* ``nodl-code-type`` (error): both have it, with different types (where the code names its type);
* ``nodl-code-qos`` (error): a topic's reliability or durability the code
  asks for literally (:mod:`rclverify.ros.extract.code_qos`) differs from
  the one the document writes (a policy either leaves unsaid is not compared).
"""
from __future__ import annotations

from pathlib import Path
from typing import Mapping

from rclverify.lang import ast
from rclverify.model.nodl.contract import type_key
from rclverify.model.nodl.document import Document, Endpoint
from rclverify.model.nodl.findings import Finding
from rclverify.ros.extract import code_qos
from rclverify.ros.extract.model import GraphEdge, GraphNode, Src
from rclverify.ros.ground.ground import match_nodes

#: A scanned node's list of each NoDL endpoint list.
GRAPH_LISTS = {"publishers": "publishes", "subscriptions": "subscribes", "service_servers": "service_servers",
               "service_clients": "service_clients", "action_servers": "action_servers",
               "action_clients": "action_clients"}


def resolve(name: str, node: str, namespace: str) -> str:
    """A document's ``name`` fully qualified for node ``node`` (its full name) in ``namespace``."""
    if name == "~":
        return node
    if name.startswith("~/"):
        return f"{node}/{name[2:]}"
    if name.startswith("/"):
        return name
    return f"{namespace.rstrip('/')}/{name}"


def _loc(src: Src | None, fallback: ast.Loc) -> ast.Loc:
    return ast.Loc(src.file, src.line, src.col) if src is not None else fallback


def _qos(doc_end: Endpoint, edge: GraphEdge, kind: str, base: Path | None, fqn: str, node: str) -> list[Finding]:
    """The reliability and durability the code asks for against the document's."""
    if doc_end.qos is None or kind not in ("publishers", "subscriptions"):
        return []
    code = code_qos.read(edge.src, "pub" if kind == "publishers" else "sub", base)
    if code is None:
        return []
    out = []
    for policy, said in (("reliability", code.reliability), ("durability", code.durability)):
        written = getattr(doc_end.qos, policy)
        if said is None or written in (None, "SYSTEM_DEFAULT", "BEST_AVAILABLE") or said.upper() == written:
            continue
        out.append(Finding("nodl-code-qos", f"node {node}: {fqn}'s {policy} is {said.upper()} in the code "
                                            f"({code.text}) and {written} in its NoDL document",
                           (_loc(edge.src, doc_end.loc), doc_end.qos.where(policy))))
    return out


def compare_code(doc: Document, gn: GraphNode, base: Path | None = None) -> list[Finding]:
    """The findings of document ``doc`` against scanned node ``gn`` (module docstring); ``base``
    is the folder the scan's file names are relative to (for reading the code's QoS)."""
    top = ast.Loc(doc.file, 1, 1)
    node_loc = _loc(gn.declared_at, top)
    code: dict[tuple[str, str], GraphEdge] = {}
    for kind, attr in GRAPH_LISTS.items():
        for edge in getattr(gn, attr):
            code.setdefault((kind, edge.topic), edge)
    out: list[Finding] = []
    seen: set[tuple[str, str]] = set()
    for e in doc.endpoints:
        key = (e.kind, resolve(e.name, gn.name, gn.namespace))
        seen.add(key)
        edge = code.get(key)
        if edge is None:
            out.append(Finding("nodl-code-absent", f"node {gn.name}'s NoDL document declares {key[1]} ({e.type}) in "
                                                   f"{e.kind}, and the scanned code creates no such endpoint",
                               (e.loc, node_loc), "warning"))
            continue
        if edge.msg_type and type_key(edge.msg_type) != type_key(e.type):
            out.append(Finding("nodl-code-type", f"node {gn.name}: {key[1]} has type {edge.msg_type} in the code and "
                                                 f"{e.type} in its NoDL document", (_loc(edge.src, top), e.type_loc)))
            continue
        out += _qos(e, edge, e.kind, base, key[1], gn.name)
    for key, edge in code.items():
        if key not in seen:
            out.append(Finding("nodl-code-undeclared", f"node {gn.name}'s code creates {key[1]} "
                                                       f"({edge.msg_type or 'type unknown'}) in {key[0]}, and its "
                                                       f"NoDL document {doc.file} does not declare it",
                               (_loc(edge.src, top), top)))
    return out


def check_code(documents: Mapping[str, Document], nodes: Mapping[str, GraphNode],
               base: Path | None = None) -> tuple[dict[str, str], list[Finding]]:
    """Each document of ``documents`` (by node) against the scanned node it matches among
    ``nodes`` (the scan's graph nodes by full name); returns ``({document's node: scanned node},
    findings)``.  A document matching no scanned node is not compared."""
    matched = match_nodes(list(documents), nodes, {})
    out: list[Finding] = []
    for name, full in sorted(matched.items()):
        out += compare_code(documents[name], nodes[full], base)
    return matched, out


__all__ = ["GRAPH_LISTS", "check_code", "compare_code", "resolve"]
