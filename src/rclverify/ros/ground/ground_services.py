"""Grounding of a contract's services and actions (docs/ros.md,
"Grounding services and actions").

A contract links inputs and outputs to a ROS service or action
(``services( std_srvs/SetBool estop serves(in.req, out.resp) )``,
``actions( pkg/Move move calls(out.goal, in.fb, in.res) )``; the link's
representation is ``rcl.ast.Link``, its rules ``lang/timing.py``).  Each link
of a contract node matched to a graph node is held against the graph:

* the node's code serves (``serves``) or calls (``calls``) it: the link is
  the node's server or client written with the link's name in its code (or
  whose last segment it is), else the one resolving to the name in the
  node's namespace (the topic rule of :mod:`rclverify.ros.ground.ground`);
* some node of the graph (or ``ros.external``) serves what a client calls;
* the contract's ``.srv``/``.action`` type is defined by a scanned or
  standard package, and it is the type the code gives;
* a service or action the node's code serves or calls that its contract
  leaves out is reported, as an undocumented topic is.

Every finding is located at the link's RCL line and at the code's line.
"""
from __future__ import annotations

import copy
import difflib
from typing import Callable, Mapping

from rclverify.lang import ast
from rclverify.ros.extract import names
from rclverify.ros.extract.interfaces import TypeTable
from rclverify.ros.extract.model import Graph, GraphEdge, GraphNode, Src, canon_type, short_type
from rclverify.ros.ground.lifecycle import implicit
from rclverify.ros.extract.shapes import LinkJson

#: rule id -> (severity, description), merged into ``ground.RULES`` (SARIF rules)
RULES: dict[str, tuple[str, str]] = {}
for _k, _w in (("SERVICE", "service"), ("ACTION", "action")):
    RULES.update({
        f"ROS-{_k}-NO-SERVER": ("error", f"a {_w} a contract calls that no node of the graph serves"),
        f"ROS-{_k}-NOT-SERVED": ("error", f"a {_w} a contract says its node serves, which the node's code does not"),
        f"ROS-{_k}-NOT-CALLED": ("warning", f"a {_w} a contract says its node calls, which the node's code does not"),
        f"ROS-{_k}-TYPE": ("error", f"a contract {_w}'s type differs from the one the code gives"),
        f"ROS-{_k}-TYPE-UNKNOWN": ("error", f"a contract {_w}'s type that no package defines"),
        f"ROS-{_k}-UNDOCUMENTED": ("warning", f"a {_w} the node's code serves or calls that its contract leaves out"),
    })

Add = Callable[[str, str, "ast.Loc | None", "Src | None", str, str], None]
#: the part a type table holds for each kind (``.srv``: ``T_Request``; ``.action``: ``T_Goal``)
_PART = {"service": "_Request", "action": "_Goal"}


def folded(g: Graph) -> Graph:
    """``g`` with actions written on their raw actionlib topics folded into action
    servers/clients (:func:`rclverify.ros.live.master.fold_actions`); ``g`` itself when
    it has none (no copy), else a copy (``g`` is left as it is)."""
    from rclverify.ros.live.master import fold_actions  # deferred: start-up (loads rclverify.ros.live, http and more only when called)
    if not any(e.topic.endswith("/goal") and (e.msg_type or "").endswith("ActionGoal")
               for n in g.nodes.values() for e in n.publishes + n.subscribes):
        return g
    g2 = copy.deepcopy(g)
    fold_actions(g2)
    return g2


def _own(edges: list[GraphEdge], name: str, gn: GraphNode) -> GraphEdge | None:
    resolved = names.resolve(name, gn.namespace, gn.name)
    return next((e for e in edges if e.written.lstrip("/") == name.lstrip("/") or e.written == name), None) or \
        next((e for e in edges if e.topic == resolved), None) or \
        next((e for e in edges if e.written.rstrip("/").rsplit("/", 1)[-1].lstrip("~") == name), None) or \
        next((e for e in edges if e.written.strip("/~").replace("/", "_").replace("~", "") == name), None)


def servers(graph_nodes: Mapping[str, GraphNode], kind: str) -> dict[str, list[tuple[str, GraphEdge]]]:
    """``{resolved name: [(node, server edge)]}`` of every service (``kind="service"``)
    or action (``"action"``) served in ``graph_nodes`` (with the management services
    of lifecycle nodes, :mod:`lifecycle`)."""
    out: dict[str, list[tuple[str, GraphEdge]]] = {}
    for n in sorted(graph_nodes.values(), key=lambda n: n.name):
        for e in n.edges_of(f"{kind}_servers") + implicit(n, f"{kind}_servers"):
            out.setdefault(e.topic, []).append((n.name, e))
    return out


def ground_links(add: Add, node: ast.Node, gn: GraphNode, graph_nodes: Mapping[str, GraphNode],
                 external: set[str], table: TypeTable) -> None:
    """Report, through ``add(code, message, rcl_loc, ros_src, node, name)``, every
    finding of contract ``node``'s service and action links against its graph node
    ``gn`` (``graph_nodes``: the graph without ignored nodes; ``external``: resolved
    names served outside the scanned software; ``table``: the scan's types)."""
    documented: set[int] = set()
    served = {k: servers(graph_nodes, k) for k in ("service", "action")}
    for lk in node.links:
        K = lk.kind.upper()
        what = lk.kind
        own_s = _own(gn.edges_of(f"{lk.kind}_servers"), lk.name, gn)
        own_c = _own(gn.edges_of(f"{lk.kind}_clients"), lk.name, gn)
        documented |= {id(x) for e in (own_s, own_c) if e is not None
                       for x in gn.edges_of(f"{lk.kind}_servers") + gn.edges_of(f"{lk.kind}_clients")
                       if x.topic == e.topic}
        mine = own_s if lk.role == "serves" else own_c
        resolved = mine.topic if mine else names.resolve(lk.name, gn.namespace, gn.name)
        ctype = canon_type(lk.ros_type, "srv" if lk.kind == "service" else "action")
        if lk.role == "serves" and own_s is None:
            near = own_c or _closest(gn.edges_of(f"{lk.kind}_servers"), lk.name)
            hint = ("; its code calls it instead" if own_c else
                    f"; closest: '{near.written}' ({near.topic})" if near else
                    f"; it serves: {', '.join(sorted(e.topic for e in gn.edges_of(f'{lk.kind}_servers'))) or 'none'}")
            add(f"ROS-{K}-NOT-SERVED", f"{node.name} serves {what} '{lk.name}' in its contract, which {gn.name}'s "
                f"code does not serve{hint}", lk.loc, near.src if near else gn.declared_at, node.name, lk.name)
        if lk.role == "calls":
            if own_c is None:
                hint = "; its code serves it instead" if own_s else ""
                add(f"ROS-{K}-NOT-CALLED", f"{node.name} calls {what} '{lk.name}' in its contract, which "
                    f"{gn.name}'s code does not call{hint}", lk.loc, own_s.src if own_s else gn.declared_at,
                    node.name, lk.name)
            if resolved not in served[lk.kind] and resolved not in external:
                close = difflib.get_close_matches(resolved, list(served[lk.kind]), 1, 0.5)
                where = served[lk.kind][close[0]][0][1].src if close else (own_c.src if own_c else gn.declared_at)
                add(f"ROS-{K}-NO-SERVER", f"no node of the graph serves the {what} {resolved} that {node.name} "
                    f"calls" + (f"; closest served {what}: {close[0]}" if close else ""),
                    lk.loc, where, node.name, lk.name)
        carried = [e for e in ([mine] if mine else []) + [e for _n, e in served[lk.kind].get(resolved, [])]
                   if e.msg_type]
        if not known(table, ctype, lk.kind):
            kinds = sorted({short_type(e.msg_type) for e in carried})
            add(f"ROS-{K}-TYPE-UNKNOWN", f"{what} type {lk.ros_type} of '{lk.name}' is defined by no scanned or "
                f"standard package" + (f"; the code gives {', '.join(kinds)}" if kinds else ""),
                lk.loc, carried[0].src if carried else (mine.src if mine else None), node.name, lk.name)
            continue
        differs = [e for e in carried if e.msg_type != ctype]
        if differs:
            add(f"ROS-{K}-TYPE", f"{what} '{lk.name}' ({resolved}) has type "
                f"{', '.join(sorted({short_type(e.msg_type) for e in differs}))} in the code, the contract says "
                f"{lk.ros_type}", lk.loc, differs[0].src, node.name, lk.name)
    for kind in ("service", "action"):
        for role, verb in (("servers", "serves"), ("clients", "calls")):
            for e in gn.edges_of(f"{kind}_{role}"):
                if id(e) not in documented:
                    add(f"ROS-{kind.upper()}-UNDOCUMENTED", f"{gn.name} {verb} {kind} {e.topic} "
                        f"({short_type(e.msg_type)}), which {node.name}'s contract leaves out of {kind}s(...)",
                        node.loc, e.src, node.name, e.written or e.topic)


def known(table: TypeTable, ctype: str | None, kind: str) -> bool:
    """Whether the ``.srv`` (``kind="service"``) or ``.action`` type ``ctype``
    (``pkg/srv/T``, ``pkg/action/T``) is defined: by the scanned workspace, Debian's
    interface packages the scan registered (``TypeTable.add_debian_standard``), or
    rosbags' store."""
    return bool(ctype) and table.get(f"{ctype}{_PART[kind]}") is not None


def _closest(edges: list[GraphEdge], name: str) -> GraphEdge | None:
    close = difflib.get_close_matches(name, [e.written for e in edges], 1, 0.6)
    return next((e for e in edges if close and e.written == close[0]), None)


def link_json(node: ast.Node) -> list[LinkJson]:
    """The links of contract ``node`` for the drawing: ``{kind, name, role}``."""
    return [{"kind": lk.kind, "name": lk.name, "role": lk.role} for lk in node.links]
