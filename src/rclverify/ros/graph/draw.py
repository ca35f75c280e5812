"""One Graphviz drawing of the contract graph beside the recovered ROS graph,
differences coloured (red: a grounding error names the item, orange: a
warning, black: it agrees).  Topics are boxes on solid lines; a service is a
hexagon on dashed lines, an action a double octagon on bold lines, each drawn
client -> service -> server.  The DOT text comes from
``templates/grounding.dot.j2``."""
from __future__ import annotations

from typing import Any, Mapping, Sequence

import jinja2

from rclverify.records.stage_records import GroundingFinding
from rclverify.ros.extract.shapes import EdgeJson, GraphJson, NodeJson

_ENV = jinja2.Environment(loader=jinja2.PackageLoader("rclverify.ros.graph", "templates"), autoescape=False,
                          keep_trailing_newline=True)
_RANK = {"error": 2, "warning": 1}
_COLOUR = {2: "red3", 1: "darkorange2", 0: "black"}


def _q(s: str) -> str:
    return s.replace("\\", "\\\\").replace('"', '\\"')


#: per link kind: the id prefix of its contract/graph node, its shape, its edge style
_LINK = {"service": ("s", "hexagon", "dashed"), "action": ("a", "doubleoctagon", "bold")}
_ROLES = (("service_servers", "service", True), ("service_clients", "service", False),
          ("action_servers", "action", True), ("action_clients", "action", False))


def grounding_dot(checked: Any, graph_json: GraphJson, findings: Sequence[GroundingFinding],
                  pairs: Mapping[str, str]) -> str:
    """DOT text: contract nodes, topics, services and actions (``checked``), graph nodes,
    topics, services and actions (``graph_json``, the JSON graph of docs/ros-graph.schema.json),
    dotted lines between matched nodes (``pairs``: contract node -> graph node).  A finding
    (``{"severity", "node", "topic"}``) colours its node and its topic, service or action on the
    contract side, and on the graph side through ``pairs``."""
    worst_node: dict[str, int] = {}
    worst_topic: dict[tuple[str, str], int] = {}
    for f in findings:
        r = _RANK.get(str(f["severity"]), 0)
        node, topic = f.get("node"), f.get("topic")
        if node:
            worst_node[node] = max(worst_node.get(node, 0), r)
            if topic:
                worst_topic[(node, topic)] = max(worst_topic.get((node, topic), 0), r)
    for c, gname in pairs.items():  # the graph side is coloured by its contract's findings too
        if c in worst_node:
            worst_node[gname] = max(worst_node.get(gname, 0), worst_node[c])
        for (n, t), r in list(worst_topic.items()):
            if n == c:
                worst_topic[(gname, t)] = max(worst_topic.get((gname, t), 0), r)
    c_nodes, c_edges = [], []
    c_topics: dict[str, int] = {}
    c_links: dict[tuple[str, str], int] = {}
    l_edges: list[dict[str, str]] = []
    for name, cn in checked.nodes.items():
        c_nodes.append({"name": _q(name), "colour": _COLOUR[worst_node.get(name, 0)]})
        for t in cn.node.topics:
            col = worst_topic.get((name, t.field), 0)
            c_topics[t.field] = max(c_topics.get(t.field, 0), col)
            out = t.match is not None and (t.match.prefix == "out" or (t.match.prefix is None and t.match.name in cn.outputs))
            src, dst = (f"c:{_q(name)}", f"ct:{_q(t.field)}") if out else (f"ct:{_q(t.field)}", f"c:{_q(name)}")
            c_edges.append({"src": src, "dst": dst, "colour": _COLOUR[col]})
        for lk in getattr(cn.node, "links", ()):
            pre, _shape, style = _LINK[lk.kind]
            col = worst_topic.get((name, lk.name), 0)
            c_links[(lk.kind, lk.name)] = max(c_links.get((lk.kind, lk.name), 0), col)
            a, b = f"c:{_q(name)}", f"c{pre}:{_q(lk.name)}"
            l_edges.append({"src": b, "dst": a, "colour": _COLOUR[col], "style": style} if lk.role == "serves"
                           else {"src": a, "dst": b, "colour": _COLOUR[col], "style": style})
    r_links: dict[tuple[str, str], int] = {}
    r_nodes, r_edges = [], []
    r_topics: dict[str, int] = {}
    for gn in graph_json["nodes"]:
        r_nodes.append({"name": _q(gn["name"]), "colour": _COLOUR[worst_node.get(gn["name"], 0)]})
        for kind, edges in (("publishes", gn["publishes"]), ("subscribes", gn["subscribes"])):
            for ge in edges:
                col = worst_topic.get((gn["name"], ge.get("as_written", ge["topic"])), 0)
                r_topics[ge["topic"]] = max(r_topics.get(ge["topic"], 0), col)
                a, b = f"r:{_q(gn['name'])}", f"rt:{_q(ge['topic'])}"
                r_edges.append({"src": a, "dst": b, "colour": _COLOUR[col]} if kind == "publishes"
                               else {"src": b, "dst": a, "colour": _COLOUR[col]})
        for role, lkind, serves in _ROLES:
            pre, _shape, style = _LINK[lkind]
            for ge in _role_edges(gn, role):
                col = max(worst_topic.get((gn["name"], ge.get("as_written", ge["topic"])), 0),
                          worst_topic.get((gn["name"], ge["topic"]), 0))
                r_links[(lkind, ge["topic"])] = max(r_links.get((lkind, ge["topic"]), 0), col)
                a, b = f"r:{_q(gn['name'])}", f"r{pre}:{_q(ge['topic'])}"
                l_edges.append({"src": b, "dst": a, "colour": _COLOUR[col], "style": style} if serves
                               else {"src": a, "dst": b, "colour": _COLOUR[col], "style": style})

    def link_nodes(side: str, table: dict[tuple[str, str], int]) -> list[dict[str, str]]:
        return [{"id": f"{side}{_LINK[k][0]}:{_q(nm)}", "name": _q(nm), "shape": _LINK[k][1],
                 "colour": _COLOUR[v]} for (k, nm), v in sorted(table.items())]

    return _ENV.get_template("grounding.dot.j2").render(
        contract_nodes=c_nodes, contract_topics=[{"name": _q(k), "colour": _COLOUR[v]} for k, v in c_topics.items()],
        contract_edges=c_edges, ros_nodes=r_nodes,
        ros_topics=[{"name": _q(k), "colour": _COLOUR[v]} for k, v in sorted(r_topics.items())],
        ros_edges=_once(r_edges),  # a topic created at several call sites of a node is one line
        contract_links=link_nodes("c", c_links), ros_links=link_nodes("r", r_links), link_edges=_once(l_edges),
        matches=[{"contract": _q(c), "ros": _q(r)} for c, r in pairs.items()])


def _role_edges(n: NodeJson, role: str) -> list[EdgeJson]:
    """The edges of graph node ``n`` in its service or action list ``role`` (one of :data:`_ROLES`)."""
    return {"service_servers": n["service_servers"], "service_clients": n["service_clients"],
            "action_servers": n["action_servers"], "action_clients": n["action_clients"]}[role]


def _once(edges: list[dict[str, str]]) -> list[dict[str, str]]:
    """``edges`` without repeats (the first of equal ones kept, in order)."""
    seen: set[tuple[tuple[str, str], ...]] = set()
    out = []
    for e in edges:
        k = tuple(sorted(e.items()))
        if k not in seen:
            seen.add(k)
            out.append(e)
    return out
