"""Expected against observed: the computation graph the code promises (the
static scan) beside the graph a running ROS 1 master or a recorded run
shows (``rclverify ros diff``; docs/ros.md, "Expected against observed").

Two lists come out:

* ``missing``: what the code promises and the running system lacks, each
  located at the source ``file:line:col`` where the code creates it (a node
  at its launch line or its ``init_node`` call, an edge where the code
  creates the publisher, subscriber, service or action), and the type
  differences (the code's type and the observed one, both shown);
* ``extra``: what the running system has and the code does not, located at
  the master's URI or the bag.

Against a master (:func:`diff_master`) nodes and, per node present on both
sides, publishers, subscribers, service servers, action servers and action
clients are compared with their types.  ROS 1 registers no service client,
so service clients are not compared.  A node missing (or extra) is one item
naming its edges, not one item per edge.  Against a bag
(:func:`diff_bag`) only topics, actions (on their actionlib topics) and
types are compared: a bag records no node names.  A type the code does not
say statically (``None``) or the master could not tell is not compared.

The expected side is the code by default; ``rclverify ros diff --nodl``
gives the graph the NoDL documents declare instead (:mod:`rclverify.ros.ground.diff_nodl`), and
the items then name the documents (:data:`NODL`) where they name the code
(:data:`CODE`).
"""
from __future__ import annotations

import copy
from dataclasses import dataclass, field
from typing import Iterable

from rclverify.ros.extract.model import Graph, GraphEdge, GraphNode, Src, short_type
from rclverify.ros.live.master import ACTION_TOPICS, INFRA_TOPICS, fold_actions
from rclverify.ros.extract.shapes import BagJson, BagTopic, DiffItemJson, DiffJson

SCHEMA_ID = "rclverify-ros-diff/1"

#: what is compared per node against a master: (GraphNode edge kind, category, verb)
MASTER_KINDS: tuple[tuple[str, str, str], ...] = (
    ("pub", "publisher", "publishes"),
    ("sub", "subscriber", "subscribes to"),
    ("service_servers", "service server", "serves"),
    ("action_servers", "action server", "serves action"),
    ("action_clients", "action client", "calls action"),
)
_VERB = {k: v for k, _c, v in MASTER_KINDS} | {"service_clients": "calls"}


@dataclass(frozen=True)
class Expected:
    """How the items name the expected side: ``side`` (the headings: ``in the code, not in ...``),
    ``within`` (an edge ``in the code``), ``its`` (a node's ``its code``), ``lacks`` (``the code has no
    such node``), ``nowhere`` (``the code names`` a name ``nowhere``), ``type_of`` (``the code's type``)."""

    side: str
    within: str
    its: str
    lacks: str
    nowhere: str
    type_of: str


#: The expected side is the code (the static scan).
CODE = Expected("the code", "in the code", "its code", "the code has no such node", "the code names {} nowhere",
                "the code's type")
#: The expected side is the graph the NoDL documents declare (:mod:`rclverify.ros.ground.diff_nodl`).
NODL = Expected("the NoDL documents", "in its NoDL document", "its NoDL document", "no NoDL document declares it",
                "no NoDL document names {}", "its NoDL document's type")


@dataclass(frozen=True)
class Item:
    """One difference.  ``category``: ``node``, ``topic``, ``action``, ``type`` or one of
    :data:`MASTER_KINDS`' categories; ``name`` the node, topic, service or action name;
    ``node`` the node it belongs to (``None`` for a node item or a bag comparison);
    ``src`` the code's location (``None`` for an item only the running side has);
    ``observed`` the master URI or bag path; ``msg_type``/``observed_type`` canonical types."""

    category: str
    name: str
    node: str | None
    msg_type: str | None
    observed_type: str | None
    src: Src | None
    observed: str
    message: str

    def where(self) -> str:
        """``file:line:col`` of the code for what the code has, else the master URI or bag."""
        return str(self.src) if self.src is not None else self.observed

    def __str__(self) -> str:
        return f"{self.where()}: {self.message}"

    def to_json(self) -> DiffItemJson:
        return {"category": self.category, "name": self.name, "node": self.node, "type": self.msg_type,
                "observed_type": self.observed_type, "at": self.src.to_json() if self.src else None,
                "observed": self.observed, "message": self.message}


@dataclass
class DiffResult:
    """``missing`` and ``extra`` items, what was compared and what could not be, and the
    observed side (``kind`` ``"master"`` or ``"bag"``, ``source`` its URI or path)."""

    kind: str
    source: str
    missing: list[Item] = field(default_factory=list)
    extra: list[Item] = field(default_factory=list)
    compared: list[str] = field(default_factory=list)
    not_compared: list[str] = field(default_factory=list)
    #: what the running side could not be read completely (a ROS 2 node list still on its way): never equal then
    incomplete: list[str] = field(default_factory=list)
    #: the expected side (the code, or the NoDL documents)
    expected: Expected = CODE

    @property
    def equal(self) -> bool:
        return not self.missing and not self.extra and not self.incomplete

    def to_json(self) -> DiffJson:
        """The documented JSON shape (docs/ros.md, "Expected against observed")."""
        return {"schema": SCHEMA_ID, "observed": {"kind": self.kind, "source": self.source},
                "equal": self.equal, "compared": list(self.compared), "not_compared": list(self.not_compared),
                "incomplete": list(self.incomplete),
                "missing": [i.to_json() for i in self.missing], "extra": [i.to_json() for i in self.extra]}


def _t(t: str | None) -> str:
    return f" ({short_type(t)})" if t else ""


def _summary(n: GraphNode, kinds: Iterable[str]) -> str:
    parts = []
    for kind in kinds:
        es = sorted({e.topic for e in n.edges_of(kind)})
        if es:
            parts.append(f"{_VERB[kind]} {', '.join(es)}")
    return "; ".join(parts) or "no topic, service or action"


def _node_src(n: GraphNode) -> Src | None:
    """Where the code declares node ``n``: its launch line or init call, else its first edge."""
    if n.declared_at is not None:
        return n.declared_at
    edges = [e for k in ("pub", "sub", "service_servers", "service_clients", "action_servers", "action_clients")
             for e in n.edges_of(k)]
    if edges:
        return min((e.src for e in edges), key=lambda s: (s.file, s.line, s.col))
    return Src(n.sources[0]) if n.sources else None


def _first(edges: list[GraphEdge]) -> dict[str, GraphEdge]:
    out: dict[str, GraphEdge] = {}
    for e in sorted(edges, key=lambda e: (e.topic, e.src.file, e.src.line, e.src.col)):
        out.setdefault(e.topic, e)
    return out


def diff_master(static: Graph, running: Graph, uri: str, said: Expected = CODE) -> DiffResult:
    """Compare the code's graph ``static`` with the graph read from the master at ``uri``
    (``running``, from :func:`rclverify.ros.live.master.read_master`); ``said`` names the
    expected side in the items (:data:`CODE`, :data:`NODL`).  Lists are sorted by
    category, node and name.  Pure: raises nothing."""
    static = copy.deepcopy(static)
    fold_actions(static)  # an action written on its raw actionlib topics is compared as the action
    res = DiffResult("master", uri, compared=["nodes", "topics", "types", "publishers", "subscribers",
                                               "service servers", "action servers", "action clients"],
                     not_compared=["service clients: a ROS 1 master registers only a service's servers"], expected=said)
    kinds = [k for k, _c, _v in MASTER_KINDS]
    static_names = {e.topic for n in static.nodes.values() for k in kinds + ["service_clients"] for e in n.edges_of(k)}
    running_names = {e.topic for n in running.nodes.values() for k in kinds for e in n.edges_of(k)}
    for name in sorted(set(static.nodes) - set(running.nodes)):
        n = static.nodes[name]
        res.missing.append(Item("node", name, None, None, None, _node_src(n), uri,
                                f"node {name} is not running ({said.its} {_summary(n, kinds)})"))
    for name in sorted(set(running.nodes) - set(static.nodes)):
        n = running.nodes[name]
        res.extra.append(Item("node", name, None, None, None, None, uri,
                              f"node {name} runs, but {said.lacks} (it {_summary(n, kinds)})"))
    for name in sorted(set(static.nodes) & set(running.nodes)):
        sn, rn = static.nodes[name], running.nodes[name]
        for kind, cat, verb in MASTER_KINDS:
            se, re_ = _first(sn.edges_of(kind)), _first(rn.edges_of(kind))
            for t in sorted(set(se) - set(re_)):
                e = se[t]
                gone = "" if t in running_names else f"; nothing running has {t}"
                res.missing.append(Item(cat, t, name, e.msg_type, None, e.src, uri,
                                        f"{name} {verb} {t}{_t(e.msg_type)} {said.within}, not in the running "
                                        f"system{gone}"))
            for t in sorted(set(re_) - set(se)):
                e = re_[t]
                unknown = "" if t in static_names else f"; {said.nowhere.format(t)}"
                res.extra.append(Item(cat, t, name, None, e.msg_type, None, uri,
                                      f"{name} {verb} {t}{_t(e.msg_type)} in the running system, not "
                                      f"{said.within}{unknown}"))
            for t in sorted(set(se) & set(re_)):
                a, b = se[t].msg_type, re_[t].msg_type
                if a and b and a != b:
                    res.missing.append(Item("type", t, name, a, b, se[t].src, uri,
                                            f"{name} {verb} {t}: {said.type_of} is {short_type(a)}, the running "
                                            f"system's {short_type(b)}"))
    return res


def bag_actions(topics: list[BagTopic]) -> tuple[dict[str, str | None], set[str]]:
    """``({action: pkg/action/T}, {its topics})`` of the actionlib topic groups a bag
    recorded: a topic ``P/goal`` whose type ends in ``ActionGoal`` (the rule of
    :mod:`rclverify.ros.live.master`)."""
    acts: dict[str, str | None] = {}
    for t in topics:
        ty = t.get("type") or ""
        if t["name"].endswith("/goal") and ty.endswith("ActionGoal"):
            pkg, _, tn = ty.partition("/msg/")
            acts[t["name"][: -len("/goal")] or "/"] = f"{pkg}/action/{tn[: -len('ActionGoal')]}" if tn else None
    parts = {f"{a}/{p}" for a in acts for p in ACTION_TOPICS}
    return acts, parts


def diff_bag(static: Graph, bag: BagJson) -> DiffResult:
    """Compare the code's graph ``static`` with a recorded run (``bag`` as
    :func:`rclverify.ros.graph.bag.bag_topics` returns it): topics the code publishes that the
    bag lacks, topics the bag has that the code names nowhere, actions, and types."""
    shown = str(bag["path"])
    res = DiffResult("bag", shown, compared=["topics", "types", "actions"],
                     not_compared=["nodes, publishers, subscribers and services: a bag records topics and "
                                   "their types, not the nodes that published them"])
    topics = [t for t in bag["topics"] if t["name"] not in INFRA_TOPICS]
    acts, act_topics = bag_actions(topics)
    recorded: dict[str, set[str]] = {}
    for bt in topics:
        if bt["name"] not in act_topics:
            recorded.setdefault(bt["name"], set()).update([bt["type"]] if bt.get("type") else [])
    pubs: dict[str, list[tuple[str, GraphEdge]]] = {}
    named: dict[str, list[tuple[str, GraphEdge]]] = {}
    for n in sorted(static.nodes.values(), key=lambda n: n.name):
        for kind in ("pub", "sub"):
            for e in n.edges_of(kind):
                named.setdefault(e.topic, []).append((n.name, e))
                if kind == "pub":
                    pubs.setdefault(e.topic, []).append((n.name, e))
    for t in sorted(set(pubs) - set(recorded)):
        who, e = pubs[t][0]
        res.missing.append(Item("topic", t, None, e.msg_type, None, e.src, shown,
                                f"{who} publishes {t}{_t(e.msg_type)} in the code; the recorded run has no {t}"))
    for t in sorted(set(recorded) - set(named)):
        ty = sorted(recorded[t])
        res.extra.append(Item("topic", t, None, None, ty[0] if ty else None, None, shown,
                              f"the recorded run has {t}" + (f" ({', '.join(short_type(x) for x in ty)})" if ty else "")
                              + "; no node of the code publishes or subscribes to it"))
    for t in sorted(set(recorded) & set(named)):
        for who, e in named[t]:
            other = sorted(x for x in recorded[t] if e.msg_type and x != e.msg_type)
            if other:
                res.missing.append(Item("type", t, who, e.msg_type, other[0], e.src, shown,
                                        f"{t}: the code's type is {short_type(e.msg_type)} ({who}), the recorded "
                                        f"run's {', '.join(short_type(x) for x in other)}"))
                break
    code_acts = static.services("action")
    first_src: dict[str, tuple[str, GraphEdge]] = {}
    for n in sorted(static.nodes.values(), key=lambda n: n.name):
        for kind in ("action_servers", "action_clients"):
            for e in n.edges_of(kind):
                first_src.setdefault(e.topic, (n.name, e))
    for a in sorted(set(code_acts) - set(acts)):
        who, e = first_src[a]
        res.missing.append(Item("action", a, None, e.msg_type, None, e.src, shown,
                                f"{who} has action {a}{_t(e.msg_type)} in the code; the recorded run has none "
                                f"of its topics"))
    for a in sorted(set(acts) - set(code_acts)):
        res.extra.append(Item("action", a, None, None, acts[a], None, shown,
                              f"the recorded run has action {a}{_t(acts[a])} (its actionlib topics); the code "
                              f"has no such action"))
    for a in sorted(set(acts) & set(code_acts)):
        who, e = first_src[a]
        if e.msg_type and acts[a] and e.msg_type != acts[a]:
            res.missing.append(Item("type", a, who, e.msg_type, acts[a], e.src, shown,
                                    f"action {a}: the code's type is {short_type(e.msg_type)}, the recorded run's "
                                    f"{short_type(acts[a])}"))
    return res


def render_text(res: DiffResult) -> list[str]:
    """The lines ``ros diff`` prints: the missing list, the extra list, what was not
    compared, and one summary line."""
    where = f"the recorded run {res.source}" if res.kind == "bag" else f"the running system at {res.source}"
    lines: list[str] = []
    if res.missing:
        lines.append(f"in {res.expected.side}, not in {where}:")
        lines += [f"  {i}" for i in res.missing]
    if res.extra:
        lines.append(f"in {where}, not in {res.expected.side}:")
        lines += [f"  {i}" for i in res.extra]
    for nc in res.not_compared:
        lines.append(f"not compared: {nc}")
    for inc in res.incomplete:
        lines.append(f"incomplete: {inc}")
    verdict = "equal" if res.equal else "they differ" if res.missing or res.extra else "incomplete, not equal"
    lines.append(f"ros diff: {len(res.missing)} missing, {len(res.extra)} extra ({verdict}); compared "
                 f"{', '.join(res.compared)}")
    return lines
