"""One Graphviz drawing of the contract graph beside the recovered ROS graph,
differences coloured (red: a grounding error names the item, orange: a
warning, black: it agrees).  The DOT text comes from
``templates/grounding.dot.j2``."""
from __future__ import annotations

from typing import Any, Mapping

import jinja2

_ENV = jinja2.Environment(loader=jinja2.PackageLoader("rclverify.ros", "templates"), autoescape=False,
                          keep_trailing_newline=True)
_RANK = {"error": 2, "warning": 1}
_COLOUR = {2: "red3", 1: "darkorange2", 0: "black"}


def _q(s: str) -> str:
    return s.replace("\\", "\\\\").replace('"', '\\"')


def grounding_dot(checked: Any, graph_json: Mapping[str, Any], findings: list[Mapping[str, Any]],
                  pairs: Mapping[str, str]) -> str:
    """DOT text: contract nodes and topics (``checked``), graph nodes and topics
    (``graph_json``), dotted lines between matched nodes (``pairs``)."""
    worst_node: dict[str, int] = {}
    worst_topic: dict[tuple[str, str], int] = {}
    for f in findings:
        r = _RANK.get(str(f["severity"]), 0)
        if f.get("node"):
            worst_node[f["node"]] = max(worst_node.get(f["node"], 0), r)
            if f.get("topic"):
                worst_topic[(f["node"], f["topic"])] = max(worst_topic.get((f["node"], f["topic"]), 0), r)
    c_nodes, c_topics, c_edges = [], {}, []
    for name, cn in checked.nodes.items():
        c_nodes.append({"name": _q(name), "colour": _COLOUR[worst_node.get(name, 0)]})
        for t in cn.node.topics:
            col = worst_topic.get((name, t.field), 0)
            c_topics[t.field] = max(c_topics.get(t.field, 0), col)
            out = t.match is not None and (t.match.prefix == "out" or (t.match.prefix is None and t.match.name in cn.outputs))
            src, dst = (f"c:{_q(name)}", f"ct:{_q(t.field)}") if out else (f"ct:{_q(t.field)}", f"c:{_q(name)}")
            c_edges.append({"src": src, "dst": dst, "colour": _COLOUR[col]})
    r_nodes, r_topics, r_edges = [], {}, []
    for n in graph_json["nodes"]:
        r_nodes.append({"name": _q(n["name"]), "colour": _COLOUR[worst_node.get(n["name"], 0)]})
        for kind in ("publishes", "subscribes"):
            for e in n[kind]:
                col = worst_topic.get((n["name"], e.get("as_written", e["topic"])), 0)
                r_topics[e["topic"]] = max(r_topics.get(e["topic"], 0), col)
                a, b = f"r:{_q(n['name'])}", f"rt:{_q(e['topic'])}"
                r_edges.append({"src": a, "dst": b, "colour": _COLOUR[col]} if kind == "publishes"
                               else {"src": b, "dst": a, "colour": _COLOUR[col]})
    return _ENV.get_template("grounding.dot.j2").render(
        contract_nodes=c_nodes, contract_topics=[{"name": _q(k), "colour": _COLOUR[v]} for k, v in c_topics.items()],
        contract_edges=c_edges, ros_nodes=r_nodes,
        ros_topics=[{"name": _q(k), "colour": _COLOUR[v]} for k, v in sorted(r_topics.items())], ros_edges=r_edges,
        matches=[{"contract": _q(c), "ros": _q(r)} for c, r in pairs.items()])
