"""Grounding: the plan's contracts held against the computation graph of its
``ros:`` section (docs/ros.md "Grounding").

Every finding is located at both ends: the RCL line (the ``topics(...)``
clause, the node, or the plan) and the source, launch or ``.msg`` line it
contradicts.  Findings never change a proof's verdict; ``--strict`` fails
on grounding errors.

How a contract names ROS things (decisions written in docs/ros.md):

* a contract node is the graph node the plan's ``ros.nodes`` names, else the
  graph node whose base name equals the contract's name up to case and
  ``_``/``-`` (``RadiationSensor`` is ``/rover/radiation_sensor``);
* a contract topic ``T`` of that node is the node's publisher/subscriber
  written ``T`` in its code, or resolving to ``T`` in the node's namespace;
  so remapping at launch keeps the contract valid, and the resolved name
  is what other nodes must publish;
* the fields a topic's variable is read from are the plan's
  ``ros.fields[C.T]`` (contract ``C``'s own topic ``T``: one name may carry
  different message types in different contracts), else ``ros.fields[T]``,
  else the ``fields`` list for ``T`` of the plan's one mapping file
  (:func:`rclverify.model.plan.mapping_file.plan_mapping`: ``ros.mapping``,
  else the monitors entries', else ``backends/monitors/mapping.yaml``;
  docs/monitors.md, "The mapping file"), else the message's
  fields in order; paths may be nested (``pose.position.x``) and index
  arrays (``readings[0].value``, ``readings[].value``).

RCL-vs-ROS types (the paper's Scalar, Collection and Function rules,
lines 535-548): ``REAL`` reads any numeric field; ``INTEGER`` any integer;
``NATURAL`` any integer (the paper maps ``int16`` to NATURAL, line 1123);
``BOOL`` a ``bool``; ``STRING`` a ``string``; an enumeration a ``string``
(Collection rule) or an integer field whose constants name its values; a
function its arguments (then its non-BOOL result) in order; a constructor
set a ``string`` (the constructor) first.

The checks of a topic's fields are :mod:`.fields`'.
"""
from __future__ import annotations

import difflib
import re
from dataclasses import dataclass
from typing import Any, Iterable, Mapping

from rclverify.lang import ast
from rclverify.model.plan.ros_section import RosSection
from rclverify.ros.extract import names
from rclverify.ros.graph.scan import ScanResult
from rclverify.ros.ground.ground_services import RULES as SERVICE_RULES
from rclverify.ros.ground.ground_services import folded, ground_links
from rclverify.ros.extract.interfaces import TypeTable
from rclverify.ros.extract.model import GraphEdge, GraphNode, Src, canon_type, library_of, short_type
from rclverify.ros.ground.fields import FieldGrounding
from rclverify.ros.ground.lifecycle import implicit
from rclverify.records.stage_records import GroundingFinding


#: stable rule ids, their severity and one-line description (SARIF rules)
RULES: dict[str, tuple[str, str]] = {
    "ROS-TOPIC-UNPUBLISHED": ("error", "a contract input's topic that no node of the graph publishes"),
    "ROS-TOPIC-ONLY-RECORDED": ("warning", "a contract input's topic that only a recorded run publishes, no scanned node"),
    "ROS-TOPIC-NOT-PUBLISHED": ("error", "a contract output's topic that its node does not publish"),
    "ROS-TOPIC-NOT-SUBSCRIBED": ("warning", "a contract input's topic that its node does not subscribe to"),
    "ROS-TYPE-UNKNOWN": ("error", "a contract topic's message type that no package defines"),
    "ROS-TYPE-DIFFERS": ("error", "a contract topic's message type differs from the graph's"),
    "ROS-TYPE-CLASH": ("error", "a topic two programs make with different types, the contract matching its own "
                                "node's code"),
    "ROS-TYPE-ALTERNATIVE": ("warning", "a contract topic's message type is one of several its node's code "
                                        "makes the topic with, chosen at run time"),
    "ROS-FIELD-MISSING": ("error", "a field path the topic's message does not have"),
    "ROS-FIELD-TYPE": ("error", "an RCL variable's type does not match the ROS field it is read from"),
    "ROS-TOPIC-UNDOCUMENTED": ("warning", "a topic the node's code publishes or subscribes to that its contract leaves out"),
    "ROS-NODE-NO-CONTRACT": ("warning", "a graph node without a contract"),
    "ROS-NODE-NOT-IN-GRAPH": ("error", "a contract node that is not in the graph"),
    "ROS-SCAN": ("warning", "something the scan could not read or resolve statically"),
    **SERVICE_RULES,  # services and actions (ground_services.py)
}


@dataclass(frozen=True)
class Finding:
    """One grounding finding: ``code`` (a :data:`RULES` key), ``severity``,
    ``message``, the RCL/plan location ``rcl`` and the ROS location ``ros``."""

    code: str
    severity: str
    message: str
    rcl: ast.Loc | None
    ros: Src | None
    node: str = ""
    topic: str = ""

    def __str__(self) -> str:
        where = str(self.rcl) if self.rcl else (str(self.ros) if self.ros else "<ros>")
        other = f" [{self.ros}]" if self.rcl and self.ros else ""
        return f"{where}: {self.severity}: {self.message}{other} ({self.code})"

    def to_json(self) -> GroundingFinding:
        return {"code": self.code, "severity": self.severity, "message": self.message, "node": self.node,
                "topic": self.topic,
                "rcl": {"file": self.rcl.file, "line": self.rcl.line, "col": self.rcl.col} if self.rcl else None,
                "ros": self.ros.to_json() if self.ros else None}


def _key(name: str) -> str:
    # ``@`` and ``.``: a program kept apart by its executable (``/talker@pkg.exe``, graph.apart_name)
    return re.sub(r"[_\-@.]", "", names.split(name)[1] if name.startswith("/") else name).lower()


def match_nodes(contract_nodes: Iterable[str], graph: Mapping[str, GraphNode],
                explicit: Mapping[str, str]) -> dict[str, str]:
    """``{contract node: graph node}`` for the nodes that correspond."""
    out: dict[str, str] = {}
    by_key: dict[str, list[str]] = {}
    for g in sorted(graph):
        by_key.setdefault(_key(g), []).append(g)
    for c in contract_nodes:
        if c in explicit:
            target = names.normalise(explicit[c])
            if target in graph:
                out[c] = target
            continue
        cands = by_key.get(_key(c), [])
        if len(cands) == 1:
            out[c] = cands[0]
    return out


class Grounder(FieldGrounding):
    def __init__(self, scan: ScanResult, checked: Any, plan_file: str, ros: RosSection | Mapping[str, Any],
                 fields_by_topic: Mapping[str, list[str]], plan_loc: ast.Loc) -> None:
        self.scan = scan
        self.g = folded(scan.graph)  # actions on raw actionlib topics are actions (master.py's rule)
        self.table: TypeTable = scan.table
        self.checked = checked
        self.plan_file = plan_file
        self.ros = RosSection.of(ros)  # the plan's ros: section as written, or its record
        self.fields = fields_by_topic
        self.plan_loc = plan_loc
        self.findings: list[Finding] = []

    def add(self, code: str, message: str, rcl: ast.Loc | None, ros: Src | None, node: str = "", topic: str = "") -> None:
        self.findings.append(Finding(code, RULES[code][0], message, rcl, ros, node, topic))

    def run(self) -> list[Finding]:
        ignore = {names.normalise(n) for n in self.ros.ignore}
        external = {names.normalise(t) for t in self.ros.external}
        graph_nodes = {k: v for k, v in self.g.nodes.items() if k not in ignore}
        self.graph_nodes, self.external = graph_nodes, external
        explicit = dict(self.ros.nodes)
        pairs = match_nodes(self.checked.nodes, graph_nodes, explicit)
        publishers: dict[str, list[tuple[str, GraphEdge]]] = {t: [] for t in external}
        for n in graph_nodes.values():
            for e in n.publishes + implicit(n, "pub"):  # a lifecycle node's transition events too
                publishers.setdefault(e.topic, []).append((n.name, e))
        all_topics = sorted(set(publishers) | {e.topic for n in graph_nodes.values() for e in n.subscribes})
        self.recorded: dict[str, list[tuple[str, str | None]]] = {}
        for b in self.g.bags:
            for t in b["topics"]:
                self.recorded.setdefault(t["name"], []).append((b["path"], t["type"]))
        first_launch = next((n.declared_at for n in graph_nodes.values() if n.declared_at), None)
        for cname, cn in self.checked.nodes.items():
            node: ast.Node = cn.node
            gname = pairs.get(cname)
            if gname is None:
                want = explicit.get(cname)
                if self._ambiguous(cname, want, graph_nodes, node):
                    continue
                hint = (f"the plan's ros.nodes names {want}, which the graph does not have" if want else
                        "no graph node has its name (up to case and _); map it in the plan's ros.nodes")
                close = difflib.get_close_matches(_key(cname), [_key(k) for k in graph_nodes], 1, 0.5)
                closest = next((k for k in sorted(graph_nodes) if close and _key(k) == close[0]), None)
                self.add("ROS-NODE-NOT-IN-GRAPH", f"contract node {cname} is not in the ROS graph: {hint}"
                         + (f"; closest graph node: {closest}" if closest else ""),
                         node.loc, graph_nodes[closest].declared_at if closest else first_launch, cname)
                continue
            self._node(cn, graph_nodes[gname], publishers, all_topics)
        matched = set(pairs.values())
        for gname in sorted(graph_nodes):
            if gname not in matched:
                gn = graph_nodes[gname]
                self.add("ROS-NODE-NO-CONTRACT", f"graph node {gname} ({gn.package or '?'}/{gn.executable or '?'}) "
                         f"has no contract", self.plan_loc, gn.declared_at, gname)
        return self.findings

    def _ambiguous(self, cname: str, want: str | None, graph_nodes: Mapping[str, GraphNode], node: ast.Node) -> bool:
        """When several programs of the graph bear the name the contract node
        (or its ``ros.nodes`` entry ``want``) asks for (kept apart by their
        executables, ``/gripper@pkg.exe``), add one finding naming every
        candidate with its package, executable and where it is declared
       , and return ``True``; else ``False``."""
        def base(g: str) -> str:
            return g.split("@", 1)[0]
        if want:
            target = names.normalise(want)
            cands = sorted(g for g in graph_nodes if base(g) == target or _key(base(g)) == _key(target))
        else:
            cands = sorted(g for g in graph_nodes if _key(base(g)) == _key(cname))
        if len(cands) < 2:
            return False
        gns = [graph_nodes[g] for g in cands]
        listed = "; ".join(f"{g} ({gn.package or '?'}/{gn.executable or '?'}"
                           + (f", {gn.declared_at.file}:{gn.declared_at.line}" if gn.declared_at else "") + ")"
                           for g, gn in zip(cands, gns))
        asked = f"the plan's ros.nodes names {want}, and" if want else "its name is that of"
        self.add("ROS-NODE-NOT-IN-GRAPH", f"contract node {cname} is ambiguous: {asked} {len(cands)} programs "
                 f"of the graph: {listed}; name the one it describes in the plan's ros.nodes "
                 f"({cname}: {cands[0]})", node.loc, gns[0].declared_at, cname)
        return True

    def _own_edge(self, gn: GraphNode, kind: str, topic: str) -> GraphEdge | None:
        edges = gn.publishes if kind == "pub" else gn.subscribes
        resolved = names.resolve(topic, gn.namespace, gn.name.split("@", 1)[0])  # a program kept apart: its ROS name
        return next((e for e in edges if e.written.lstrip("/") == topic or e.written == topic), None) or \
            next((e for e in edges if e.topic == resolved), None) or \
            next((e for e in edges if e.written.rstrip("/").rsplit("/", 1)[-1].lstrip("~") == topic), None) or \
            next((e for e in edges if e.written.strip("/~").replace("/", "_").replace("~", "") == topic), None)

    def _node(self, cn: Any, gn: GraphNode, publishers: dict[str, list[tuple[str, GraphEdge]]],
              all_topics: list[str]) -> None:
        node: ast.Node = cn.node
        documented: set[int] = set()
        for tp in node.topics:
            var = tp.match
            is_out = var is not None and (var.prefix == "out" or (var.prefix is None and var.name in cn.outputs
                                                                 and var.name not in cn.inputs))
            kind = "pub" if is_out else "sub"
            edge = self._own_edge(gn, kind, tp.field)
            other = self._own_edge(gn, "sub" if is_out else "pub", tp.field)
            ctype = canon_type(tp.msg_type)
            resolved = edge.topic if edge else names.resolve(tp.field, gn.namespace, gn.name)
            # every call site creating the topic is documented by the one entry
            for e in ([edge] if edge else []) + ([other] if other else []):
                documented |= {id(x) for x in gn.publishes + gn.subscribes if x.topic == e.topic}
            rcl_loc = tp.loc
            if is_out and edge is None:
                close = difflib.get_close_matches(tp.field, [e.written for e in gn.publishes], 1, 0.6)
                near = next((e for e in gn.publishes if close and e.written == close[0]), None)
                self.add("ROS-TOPIC-NOT-PUBLISHED",
                         f"{node.name}'s output {var.qualified if var else ''} is on topic '{tp.field}', which "
                         f"{gn.name} does not publish" + (f"; closest: '{near.written}' ({near.topic})" if near else
                                                          f"; it publishes: {', '.join(sorted(e.topic for e in gn.publishes)) or 'nothing'}"),
                         rcl_loc, near.src if near else gn.declared_at, node.name, tp.field)
            if not is_out:
                if edge is None:
                    self.add("ROS-TOPIC-NOT-SUBSCRIBED",
                             f"{node.name}'s input {var.qualified if var else ''} is on topic '{tp.field}', which "
                             f"{gn.name} does not subscribe to", rcl_loc, gn.declared_at, node.name, tp.field)
                if resolved not in publishers and resolved in self.recorded:
                    bag = self.recorded[resolved][0][0]
                    self.add("ROS-TOPIC-ONLY-RECORDED",
                             f"{resolved} ({node.name}'s input {var.qualified if var else tp.field}) is published in "
                             f"the recorded run {bag}, but by no node of the scanned software",
                             rcl_loc, edge.src if edge else Src(bag, 1), node.name, tp.field)
                elif resolved not in publishers:
                    close = difflib.get_close_matches(resolved, [t for t in publishers if publishers[t]], 1, 0.5)
                    where = publishers[close[0]][0][1].src if close else (edge.src if edge else gn.declared_at)
                    self.add("ROS-TOPIC-UNPUBLISHED",
                             f"no node of the graph publishes {resolved} ({node.name}'s input "
                             f"{var.qualified if var else tp.field})" + (f"; closest published topic: {close[0]}" if close else ""),
                             rcl_loc, where, node.name, tp.field)
            self._topic_type(cn, gn, tp, kind, edge, resolved, publishers)
        for e in gn.publishes + gn.subscribes:
            # the client library's and other libraries' (tf, bond, diagnostics ...): no contract need name them
            if id(e) not in documented and library_of(e.topic, e.msg_type) is None:
                what = "publishes" if e in gn.publishes else "subscribes to"
                self.add("ROS-TOPIC-UNDOCUMENTED", f"{gn.name} {what} {e.topic} ({short_type(e.msg_type)}), which "
                         f"{node.name}'s contract leaves out of topics(...)", node.loc, e.src, node.name, e.written)
        ground_links(self.add, node, gn, self.graph_nodes, self.external, self.table)

    def _topic_type(self, cn: Any, gn: GraphNode, tp: ast.Topic, kind: str, edge: GraphEdge | None,
                    resolved: str, publishers: dict[str, list[tuple[str, GraphEdge]]]) -> None:
        """The message type of contract topic ``tp`` of ``cn`` (``kind``: ``pub`` or ``sub`` of graph
        node ``gn``, its own ``edge`` if the code makes it) against the types the graph, the other
        programs (``publishers``: resolved topic -> (program, edge)) and the recorded runs carry on
        ``resolved``; then its fields (:meth:`_fields`).  Adds ROS-TYPE-UNKNOWN, -ALTERNATIVE, -CLASH or
        -DIFFERS findings."""
        node: ast.Node = cn.node
        var = tp.match
        ctype = canon_type(tp.msg_type)
        rcl_loc = tp.loc
        # message type
        info = self.table.get(ctype)
        graph_types = {e.msg_type for e in ([edge] if edge else []) + [pe for _, pe in publishers.get(resolved, [])]
                       if e.msg_type}
        graph_types |= {t for _b, t in self.recorded.get(resolved, []) if t}
        type_src = edge.src if edge else (publishers[resolved][0][1].src if publishers.get(resolved) else None)
        if info is None:
            self.add("ROS-TYPE-UNKNOWN", f"message type {tp.msg_type} of topic '{tp.field}' is defined by no "
                     f"scanned or standard package" + (f"; the graph carries {', '.join(short_type(t) for t in sorted(graph_types))}"
                                                       if graph_types else ""),
                     rcl_loc, type_src, node.name, tp.field)
            return
        assert ctype is not None  # the table knows no type without a name
        # the node's own code may make the topic with several types, one chosen at run time (a
        # parameter picks TwistStamped or Twist): the contract naming one of them is that choice
        own = {e.msg_type for e in (gn.publishes if kind == "pub" else gn.subscribes)
               if edge is not None and e.topic == edge.topic and e.msg_type}
        chosen = ctype in own and len(own) > 1
        differs = sorted(t for t in graph_types if t != ctype and not (chosen and t in own))
        if chosen and not differs:
            self.add("ROS-TYPE-ALTERNATIVE", f"topic '{tp.field}' is made as "
                     f"{', '.join(short_type(t) for t in sorted(own))} in {gn.name}'s code, one of them chosen "
                     f"at run time; the contract says {tp.msg_type}, checked as that", rcl_loc, type_src,
                     node.name, tp.field)
        clash = [(name, pe) for name, pe in publishers.get(resolved, [])
                 if name != gn.name and pe.msg_type in differs] if edge is not None and edge.msg_type == ctype else []
        if clash and edge is not None:  # the contract matches its own node's code: another program differs
            other_node, pe = clash[0]
            self.add("ROS-TYPE-CLASH", f"topic {resolved} is made with {short_type(pe.msg_type)} by {other_node} "
                     f"({pe.src}) and with {short_type(ctype)} by {gn.name} ({edge.src}), as {node.name}'s "
                     f"contract says: the two programs differ, not the contract", rcl_loc, pe.src,
                     node.name, tp.field)
            return
        if differs:
            self.add("ROS-TYPE-DIFFERS", f"topic '{tp.field}' carries {', '.join(short_type(t) for t in differs)} "
                     f"in the code, the contract says {tp.msg_type}", rcl_loc, type_src, node.name, tp.field)
            return
        if var is not None:
            self._fields(cn, tp, var, ctype, rcl_loc)

def ground(scan: ScanResult, checked: Any, plan_file: str, ros: RosSection | Mapping[str, Any],
           fields_by_topic: Mapping[str, list[str]], plan_loc: ast.Loc) -> list[Finding]:
    """All grounding findings, contract by contract, then graph nodes without contract,
    then the scan's own located warnings (``ROS-SCAN``)."""
    fs = Grounder(scan, checked, plan_file, ros, fields_by_topic, plan_loc).run()
    for n in scan.graph.notes:
        fs.append(Finding("ROS-SCAN", n.severity, f"{n.message} ({n.code})", None, n.src))
    return fs
