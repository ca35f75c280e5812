"""The running ROS 2 graph read from DDS, and ``rclverify ros diff --ros2``
(docs/ros.md, "Expected against observed").

:func:`read_dds_graph` joins the domain (``ROS_DOMAIN_ID``,
``CYCLONEDDS_URI``), listens to discovery for ``wait_s`` seconds and on
while the graph settles (every ROS 2 participant's node list and endpoints
in: :meth:`.Discovery.pending`; Fast DDS sends its node list at its next
heartbeat) and makes the same :class:`~.model.Graph` the ROS 1 master
reader makes (:mod:`.master`):

* a node per entry of ``ros_discovery_info`` (``/ns/name``), each endpoint
  given to the node that lists its GUID;
* a writer of ``rt/T`` publishes ``/T``, a reader subscribes to it, with the
  type ``pkg/msg/T`` from ``pkg::msg::dds_::T_``;
* a reader of ``rq/SRequest`` serves service ``/S``, a writer of it calls it
  (ROS 2 registers clients too, unlike a ROS 1 master: they are compared);
* an action ``/A`` is its hidden ``/A/_action/send_goal`` service: its
  server and client; its other hidden services and topics are folded into it;
* ROS 2's own machinery is left out: ``/rosout``, ``/parameter_events``,
  each node's parameter and type-description services,
  ``ros_discovery_info``.

Endpoints no node lists (a participant that publishes no
``ros_discovery_info``: plain DDS, or a ROS 2 process whose announcement
was not received within the wait) are not in any node; each such topic is
a note.  :func:`qos_conflicts` finds, per topic, a subscriber and a
publisher that DDS will not connect because of their QoS (a reliable
subscription beside a best-effort publisher: the subscriber hears nothing).
:func:`diff_dds` compares with :func:`.diff.diff_master`'s rules and adds
the service clients and the QoS conflicts.
"""
from __future__ import annotations

import time
from typing import Any

from rclverify.ros.extract import code_qos
from rclverify.ros.live.dds import ACTION_INFIX, ACTION_SERVICES, DISCOVERY_TOPIC, domain_id, make_participant, ros_name, ros_type
from rclverify.ros.live.dds import service_type as _service_type
from rclverify.ros.live.dds_discovery import Discovery, EndpointInfo
from rclverify.ros.live.dds_qos import mismatches
from rclverify.ros.live.diff import CODE, DiffResult, Expected, Item, _first, _t, diff_master
from rclverify.ros.extract.model import Graph, GraphEdge, GraphNode, Note, Src, short_type

INFRA_TOPICS = {"/rosout", "/parameter_events"}
#: the first character of a hidden node's name (rclpy ``HIDDEN_NODE_PREFIX``; ROS 2's command line tools name theirs so)
HIDDEN_PREFIX = "_"
#: the services every rclcpp/rclpy node offers about itself (its parameters, its types)
INFRA_SERVICE_SUFFIXES = ("/describe_parameters", "/get_parameter_types", "/get_parameters", "/list_parameters",
                          "/set_parameters", "/set_parameters_atomically", "/get_type_description")


def _edge_kind(e: EndpointInfo, writer: bool) -> tuple[str, str, str | None] | None:
    """``(GraphNode edge kind, ROS name, canonical type)`` of an endpoint, or
    ``None`` for what the graph leaves out (module docstring)."""
    kind, name = ros_name(e.topic)
    typ = ros_type(e.type_name)
    if kind == "topic":
        if name in INFRA_TOPICS or ACTION_INFIX in name:
            return None
        return ("pub" if writer else "sub"), name, typ
    if kind != "request":
        return None
    if ACTION_INFIX in name:
        base, _, svc = name.partition(ACTION_INFIX)
        if svc != ACTION_SERVICES[0]:
            return None  # get_result, cancel_goal: folded into the action
        atype = _service_type(typ)
        atype = atype[: -len("_SendGoal")] if atype and atype.endswith("_SendGoal") else atype
        return ("action_clients" if writer else "action_servers"), base or "/", atype
    if name.endswith(INFRA_SERVICE_SUFFIXES):
        return None
    return ("service_clients" if writer else "service_servers"), name, _service_type(typ)


def graph_of(disc: Discovery, source: str) -> Graph:
    """The :class:`~.model.Graph` of what ``disc`` has discovered (module
    docstring); every edge located at ``Src(source)``; endpoints outside any
    node as notes (``ROS-DDS``)."""
    g = Graph()
    src = Src(source, 1, 1)
    for gid_nodes in disc.nodes.values():
        for n in gid_nodes:
            ns = "/" + n.namespace.strip("/")
            g.nodes.setdefault(n.full_name, GraphNode(n.full_name, ns, None, None, origin="dds", declared_at=src))
    orphans: set[str] = set()
    for table, writer in ((disc.writers, True), (disc.readers, False)):
        for e in sorted(table.values(), key=lambda e: (e.topic, e.guid)):
            if e.topic == DISCOVERY_TOPIC:
                continue
            what = _edge_kind(e, writer)
            if what is None:
                continue
            kind, name, typ = what
            node = disc.node_of(e.guid)
            if node is None or node not in g.nodes:
                orphans.add(f"{'publisher' if writer else 'subscriber'} of {e.topic} ({e.type_name}), "
                            f"participant {e.participant.hex()}")
                continue
            edges = g.nodes[node].edges_of(kind)
            if not any(x.topic == name for x in edges):
                edges.append(GraphEdge(name, typ, src, None, name))
    for o in sorted(orphans):
        g.notes.append(Note(src, f"the {o} is in no ROS 2 node: its participant announced no node on "
                                 f"ros_discovery_info (plain DDS, or not received within the wait)", "ROS-DDS"))
    return g


def qos_conflicts(disc: Discovery) -> list[tuple[str, EndpointInfo, EndpointInfo, list[str]]]:
    """``(ROS topic, writer, reader, why)`` for each publisher and subscriber of
    one topic and type that DDS does not connect because of their QoS."""
    out = []
    for r in sorted(disc.readers.values(), key=lambda e: (e.topic, e.guid)):
        kind, name = ros_name(r.topic)
        if kind != "topic" or name in INFRA_TOPICS:
            continue
        for w in disc.publishers(r.topic):
            if w.type_name == r.type_name:
                why = mismatches(w.qos, r.qos)
                if why:
                    out.append((name, w, r, why))
    return out


#: seconds past ``--wait`` that :func:`read_dds_graph` keeps listening while a ROS 2 participant's node
#: list or endpoints are still on their way (two of Fast DDS's 3-second heartbeat periods)
SETTLE_S = 6.0
#: seconds without news from discovery after which a settled graph is taken as complete
QUIET_S = 0.5
#: the words of a note saying the running graph was not read completely (the diff is then never equal)
INCOMPLETE = "the graph may be incomplete"


def read_dds_graph(wait_s: float = 2.0, domain: int | None = None,
                   settle_s: float = SETTLE_S) -> tuple[Graph, Discovery, str, Any]:
    """Listen to the domain for ``wait_s`` seconds, then on, up to ``settle_s``
    seconds more, while discovery brought news in the last :data:`QUIET_S`
    seconds or :meth:`.Discovery.pending` names a ROS 2 participant
    whose node list or endpoints have not arrived (what is still pending then
    is a ``ROS-DDS`` note of the graph: its nodes may be reported not running).
    Returns the graph, the discovery (for :func:`qos_conflicts`), the source
    label (``DDS domain N``) and the participant (delete it when done).
    Raises :class:`~.dds.DdsUnavailable`."""
    d = domain_id() if domain is None else domain
    dp = make_participant(d)
    disc = Discovery(dp)
    start = last = time.monotonic()
    while True:
        now = time.monotonic()
        if disc.poll():
            last = now
        spent = now - start
        quiet = now - last >= QUIET_S
        if spent >= wait_s and (spent >= wait_s + settle_s or quiet and not disc.pending()):
            break
        time.sleep(0.05)
    source = f"DDS domain {d}"
    g = graph_of(disc, source)
    for p in disc.pending():
        g.notes.append(Note(Src(source, 1, 1), f"after {time.monotonic() - start:.1f} s of listening, {p}: "
                                               f"{INCOMPLETE} (give --wait longer)", "ROS-DDS"))
    return g, disc, source, dp


def diff_dds(static: Graph, running: Graph, source: str,
             conflicts: list[tuple[str, EndpointInfo, EndpointInfo, list[str]]] = (),  # type: ignore[assignment]
             disc: Discovery | None = None, said: Expected = CODE, names: Any = None) -> DiffResult:
    """Compare the code's graph with the running ROS 2 graph: what
    :func:`.diff.diff_master` compares, the service clients, and each QoS
    conflict as a ``qos`` item of the missing list (the connection the code
    promises is not made).  With ``disc``, also the reliability and
    durability each publisher and subscriber asks for in the code against
    its running endpoint (:func:`code_qos_items`; reads the code's files,
    relative to the current directory as the scan showed them).  ``said`` names the expected side
    (the code, or the NoDL documents: :mod:`rclverify.ros.ground.diff_nodl`, which passes no ``disc``).
    A QoS conflict names its endpoints' nodes as ``names`` (default ``disc``; anything with a
    ``who(endpoint)``) gives them (``node /viewer``), else by GUID."""
    hidden = sorted(n for n in running.nodes if n.rsplit("/", 1)[-1].startswith(HIDDEN_PREFIX) and n not in static.nodes)
    if hidden:  # ROS 2's tools (the ros2cli daemon, ros2 topic echo): left out as `ros2 node list` leaves them out
        running = Graph(nodes={k: v for k, v in running.nodes.items() if k not in hidden}, notes=running.notes)
    res = diff_master(static, running, source, said)
    res.kind = "dds"
    res.incomplete = [n.message for n in running.notes if n.code == "ROS-DDS" and INCOMPLETE in n.message]
    res.compared += ["service clients", "QoS of the publishers and subscribers of each topic"]
    res.not_compared = ["history depth (DDS discovery does not announce it)"]
    if hidden:
        res.not_compared.append(f"{len(hidden)} hidden node(s) the code does not have ({', '.join(hidden[:3])}"
                                f"{', ...' if len(hidden) > 3 else ''}): a name starting with '_' is a ROS 2 tool's")
    if disc is not None:
        items, unread = code_qos_items(static, disc, source)
        res.missing += items
        res.compared.append("the reliability and durability the code asks for, against the running endpoint")
        if unread:
            res.not_compared.append(f"the QoS of {len(unread)} publisher(s)/subscriber(s) the code does not say "
                                    f"literally ({', '.join(unread[:3])}{', ...' if len(unread) > 3 else ''})")
    else:
        res.not_compared.append("the QoS the code asks for (the diff reports the running endpoints' conflicts)")
    for name in sorted(set(static.nodes) & set(running.nodes)):
        se, re_ = _first(static.nodes[name].edges_of("service_clients")), \
            _first(running.nodes[name].edges_of("service_clients"))
        for t in sorted(set(se) - set(re_)):
            res.missing.append(Item("service client", t, name, se[t].msg_type, None, se[t].src, source,
                                    f"{name} calls {t}{_t(se[t].msg_type)} {said.within}, not in the running system"))
        for t in sorted(set(re_) - set(se)):
            res.extra.append(Item("service client", t, name, None, re_[t].msg_type, None, source,
                                  f"{name} calls {t}{_t(re_[t].msg_type)} in the running system, not {said.within}"))
    namer = names if names is not None else disc
    for topic, w, r, why in conflicts:
        who_w = namer.who(w) if namer is not None else w.label
        who_r = namer.who(r) if namer is not None else r.label
        res.missing.append(Item("qos", topic, None, ros_type(w.type_name), None, None, source,
                                f"{topic} ({short_type(ros_type(w.type_name))}): {who_r} subscribes with "
                                f"{_announced(r.qos)}, {who_w} publishes with {_announced(w.qos)}; DDS does not "
                                f"connect them ({'; '.join(why)}), so the subscriber receives nothing from it"))
    return res


def _announced(q: Any) -> str:
    """``q.describe()`` without the history, which discovery does not announce (the
    reader fills in keep_last(1), DDS's default, whatever the endpoint keeps)."""
    return ", ".join(p for p in q.describe().split(", ") if not p.startswith(("keep_last(", "keep_all")))


def _policies(q: Any) -> tuple[str, str]:
    return ("reliable" if q.reliable else "best_effort"), q.durability


def code_qos_items(static: Graph, disc: Discovery, source: str) -> tuple[list[Item], list[str]]:
    """``qos`` items (located at the code's call) for each publisher and
    subscriber of a node running under its code's name whose running
    endpoints on that topic all differ from the reliability or durability the
    code asks for (:mod:`.code_qos`); and, as ``node topic``, those whose QoS
    the code does not say literally (not compared).  Endpoints are given to
    nodes by ``ros_discovery_info`` (:meth:`.Discovery.node_of`)."""
    items: list[Item] = []
    unread: list[str] = []
    for name in sorted(static.nodes):
        for kind, verb, side in (("pub", "publishes", disc.writers), ("sub", "subscribes to", disc.readers)):
            for topic, e in sorted(_first(static.nodes[name].edges_of(kind)).items()):
                run = [x for x in side.values() if disc.node_of(x.guid) == name and ros_name(x.topic) == ("topic", topic)]
                if not run:
                    continue
                cq = code_qos.read(e.src, kind)
                if cq is None or (cq.reliability is None and cq.durability is None):
                    unread.append(f"{name} {topic}")
                    continue
                off = [x for x in run if (cq.reliability or _policies(x.qos)[0], cq.durability or _policies(x.qos)[1])
                       != _policies(x.qos)]
                if len(off) < len(run):
                    continue
                got = _policies(off[0].qos)
                why = [f"{p}: {c} in the code, {r} running" for p, c, r in
                       (("reliability", cq.reliability, got[0]), ("durability", cq.durability, got[1])) if c and c != r]
                items.append(Item("qos", topic, name, e.msg_type, None, e.src, source,
                                  f"{name} {verb} {topic}{_t(e.msg_type)} with {cq.text} ({cq.describe()}) in the "
                                  f"code; its running {'publisher' if kind == 'pub' else 'subscriber'} has "
                                  f"{', '.join(got)} ({'; '.join(why)})"))
    return items, unread


__all__ = ["INFRA_SERVICE_SUFFIXES", "INFRA_TOPICS", "code_qos_items", "diff_dds", "graph_of", "qos_conflicts",
           "read_dds_graph"]
