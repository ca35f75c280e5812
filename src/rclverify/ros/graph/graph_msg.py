"""The running ROS 2 graph as a ``rosgraph_msgs/msg/Graph`` message (docs/nodl.md, "The graph message in a
bag"): its definition, and the graph dump rclverify's live sources give turned into one and back.

The definition is the one ``rosgraph_msgs`` releases carry since the graph messages were added to
``rcl_interfaces`` (rosgraph_msgs 1.2.3 on Humble, the 2.x releases after it): ``Graph`` holds a
sequence of ``Node``; a ``Node`` its fully qualified ``name``, its parameters' descriptors and values
(``rcl_interfaces``), its ``publishers`` and ``subscriptions`` (``Topic``), ``service_clients`` and
``service_servers`` (``Service``), ``action_clients`` and ``action_servers`` (``Action``); a ``Topic`` a
``name``, a ``type`` (``InterfaceType``: type ``name`` and ``TypeHash``: RIHS ``version``, 32 bytes
``value``) and the endpoint's ``qos`` (``QoSProfile``: ``depth``, ``deadline``, ``lifespan``, ``history``,
``reliability``, ``durability``, ``liveliness``, ``liveliness_lease_duration``, the policies as ``uint8``
codes, durations as ``builtin_interfaces/Duration``, ``0`` for none); a ``Service`` a ``name``, the
request's and the response's type and QoS; an ``Action`` a ``name``, its ``send_goal``, ``get_result`` and
``cancel_goal`` services and its ``feedback`` and ``status`` topics.  ROS 2 Kilted's wheels
(``rosgraph_msgs`` 2.3.0) have ``Clock`` only, so the definition is written here (:data:`DEFINITIONS`) and
registered in a rosbags type store of its own (:func:`graph_store`).

The dump (:mod:`rclverify.model.nodl.graph_record`) maps onto the message so (:func:`to_message`):

* each node is a ``Node`` named ``ns/name``; its topics are one ``Topic`` per endpoint of the dump, with
  the endpoint's type, type hash (``RIHS01_<hex>`` as version 1 and the 32 bytes; none: version 0) and
  QoS (reliability, durability, deadline, liveliness and its lease; depth, history and lifespan, which
  the dump does not hold, as ``0``, ``HISTORY_UNKNOWN`` and ``0``); a topic the node lists with no
  endpoint read for it is a ``Topic`` whose reliability and durability are ``UNKNOWN``;
* its services (an action's hidden ones included, as rclpy's graph API lists them) are one ``Service``
  per type, request and response types ``T_Request`` and ``T_Response`` with no hash and ``UNKNOWN`` QoS
  (the dump has neither); parameters are left empty.

:func:`from_message` reads any such message back into the dump's form, a foreign one too: an ``Action``
entry becomes its three services and two topics (each under its own name, or ``<action>/_action/<part>``
when it has none).  What the message cannot carry is lost: GIDs (each endpoint read back gets one made
from its node, role, topic and place: ``graph_gid``), the rmw and the reading's label (kept in the bag's
metadata instead: :mod:`.graph_bag`), endpoints no node lists, and liveliness kinds the message has no code
for (DDS's ``manual_by_participant``, read back as ``unknown``).
"""
from __future__ import annotations

import hashlib
from typing import Any

from rclverify.core.numeric import import_numpy

#: rmw's infinite duration (ns), the graph dump's "none" (as :data:`rclverify.ros.live.dds_qos.INFINITE_NS`)
INFINITE_NS = 0x7FFFFFFFFFFFFFFF
GRAPH_TYPE = "rosgraph_msgs/msg/Graph"
_P = "rosgraph_msgs/msg/"

#: Each message of the graph, as ``.msg`` text: the released definition's fields and constants.
DEFINITIONS: dict[str, str] = {
    _P + "TypeHash": "uint8 version\nuint8[32] value\n",
    _P + "InterfaceType": "string name\nTypeHash hash\n",
    _P + "QoSProfile": "\n".join([
        "uint8 HISTORY_SYSTEM_DEFAULT=0", "uint8 HISTORY_KEEP_LAST=1", "uint8 HISTORY_KEEP_ALL=2",
        "uint8 HISTORY_UNKNOWN=3",
        "uint8 RELIABILITY_SYSTEM_DEFAULT=0", "uint8 RELIABILITY_RELIABLE=1", "uint8 RELIABILITY_BEST_EFFORT=2",
        "uint8 RELIABILITY_UNKNOWN=3", "uint8 RELIABILITY_BEST_AVAILABLE=4",
        "uint8 DURABILITY_SYSTEM_DEFAULT=0", "uint8 DURABILITY_TRANSIENT_LOCAL=1", "uint8 DURABILITY_VOLATILE=2",
        "uint8 DURABILITY_UNKNOWN=3", "uint8 DURABILITY_BEST_AVAILABLE=4",
        "uint8 LIVELINESS_SYSTEM_DEFAULT=0", "uint8 LIVELINESS_AUTOMATIC=1", "uint8 LIVELINESS_MANUAL_BY_TOPIC=3",
        "uint8 LIVELINESS_UNKNOWN=4", "uint8 LIVELINESS_BEST_AVAILABLE=5",
        "uint32 depth", "builtin_interfaces/Duration deadline", "builtin_interfaces/Duration lifespan",
        "uint8 history", "uint8 reliability", "uint8 durability", "uint8 liveliness",
        "builtin_interfaces/Duration liveliness_lease_duration", ""]),
    _P + "Topic": "string name\nInterfaceType type\nQoSProfile qos\n",
    _P + "Service": "string name\nInterfaceType request_type\nQoSProfile request_qos\n"
                    "InterfaceType response_type\nQoSProfile response_qos\n",
    _P + "Action": "string name\nService send_goal\nService get_result\nService cancel_goal\n"
                   "Topic feedback\nTopic status\n",
    _P + "Node": "string name\nrcl_interfaces/ParameterDescriptor[] parameters\n"
                 "rcl_interfaces/ParameterValue[] parameter_values\nTopic[] publishers\nTopic[] subscriptions\n"
                 "Service[] service_clients\nService[] service_servers\nAction[] action_clients\n"
                 "Action[] action_servers\n",
    GRAPH_TYPE: "Node[] nodes\n",
}

RELIABLE, BEST_EFFORT, UNKNOWN = 1, 2, 3  # reliability codes (UNKNOWN is also durability's)
TRANSIENT_LOCAL, VOLATILE = 1, 2
HISTORY_UNKNOWN = 3
_LIVELINESS = {"system_default": 0, "automatic": 1, "manual_by_topic": 3, "unknown": 4, "best_available": 5}
_LIVELINESS_NAME = {v: k for k, v in _LIVELINESS.items()}
_INT32_MAX_S = 2**31 - 1
_STORE: list[Any] = []


def graph_store() -> Any:
    """A rosbags type store (ROS 2 Humble's types, which hold ``builtin_interfaces`` and ``rcl_interfaces``)
    with :data:`DEFINITIONS` registered; made once per process."""
    if not _STORE:
        from rosbags.typesys import Stores, get_typestore, get_types_from_msg  # deferred: start-up (loads rosbags only when called)
        store = get_typestore(Stores.ROS2_HUMBLE)
        for name, text in DEFINITIONS.items():
            store.register(get_types_from_msg(text, name))
        _STORE.append(store)
    return _STORE[0]


def graph_type_hash() -> str:
    """The ``RIHS01_...`` type hash of ``rosgraph_msgs/msg/Graph`` (REP-2011), computed from :data:`DEFINITIONS`
    by rosbags' rule (which differs from rosidl's only for ``char`` fields, which none of the graph's messages
    has: :mod:`rclverify.ros.live.type_hash`)."""
    return str(graph_store().hash_rihs01(GRAPH_TYPE))


def _duration(store: Any, ns: int) -> Any:
    """``builtin_interfaces/Duration`` of ``ns``; none (``<= 0``, infinite, or beyond the message's int32
    seconds) as ``0``, the message's "none"."""
    d = store.types["builtin_interfaces/msg/Duration"]
    if ns <= 0 or ns >= INFINITE_NS or ns // 1_000_000_000 > _INT32_MAX_S:
        return d(sec=0, nanosec=0)
    return d(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)


def _ns(d: Any) -> int:
    ns = int(d.sec) * 1_000_000_000 + int(d.nanosec)
    return INFINITE_NS if ns <= 0 else ns


def _itype(store: Any, name: str, hash_text: str | None) -> Any:
    numpy = import_numpy()  # deferred: start-up (loaded with rosbags), one OpenBLAS thread
    value = numpy.zeros(32, dtype=numpy.uint8)
    version = 0
    if hash_text and hash_text.startswith("RIHS01_") and len(hash_text) == 7 + 64:
        version, value = 1, numpy.frombuffer(bytes.fromhex(hash_text[7:]), dtype=numpy.uint8).copy()
    th = store.types[_P + "TypeHash"](version=version, value=value)
    return store.types[_P + "InterfaceType"](name=name, hash=th)


def _qos(store: Any, e: dict[str, Any] | None) -> Any:
    q = store.types[_P + "QoSProfile"]
    if e is None:
        return q(depth=0, deadline=_duration(store, 0), lifespan=_duration(store, 0), history=HISTORY_UNKNOWN,
                 reliability=UNKNOWN, durability=UNKNOWN, liveliness=_LIVELINESS["unknown"],
                 liveliness_lease_duration=_duration(store, 0))
    return q(depth=0, deadline=_duration(store, int(e["deadline_ns"])), lifespan=_duration(store, 0),
             history=HISTORY_UNKNOWN, reliability=RELIABLE if e["reliable"] else BEST_EFFORT,
             durability=TRANSIENT_LOCAL if e["durability"] == "transient_local" else VOLATILE,
             liveliness=_LIVELINESS.get(str(e["liveliness"]), _LIVELINESS["unknown"]),
             liveliness_lease_duration=_duration(store, int(e["lease_ns"])))


def fqn(name: str, ns: str) -> str:
    """A node's fully qualified name from its name and namespace (``/`` + ``Base``: ``/Base``)."""
    return ns.rstrip("/") + "/" + name


def to_message(dump: dict[str, Any]) -> Any:
    """The ``rosgraph_msgs/msg/Graph`` message of graph dump ``dump`` (module docstring), an object of
    :func:`graph_store`'s ``Graph`` class, ready for ``serialize_cdr``."""
    store = graph_store()
    t = store.types
    endpoints: dict[str, dict[str, list[dict[str, Any]]]] = dump.get("endpoints", {})
    nodes = []
    for n in dump.get("nodes", []):
        name, ns = n["name"], n["ns"]
        roles = {}
        for role in ("pubs", "subs"):
            topics = []
            for topic, types in n.get(role, []):
                mine = [e for e in endpoints.get(topic, {}).get(role, []) if e["node"] == name and e["ns"] == ns]
                for ty in types:
                    found = [e for e in mine if e["type"] == ty]
                    topics += [t[_P + "Topic"](name=topic, type=_itype(store, ty, e.get("hash")), qos=_qos(store, e))
                               for e in found] or [t[_P + "Topic"](name=topic, type=_itype(store, ty, None),
                                                                   qos=_qos(store, None))]
            roles[role] = topics
        for role in ("servers", "clients"):
            roles[role] = [t[_P + "Service"](name=s, request_type=_itype(store, ty + "_Request", None),
                                             request_qos=_qos(store, None),
                                             response_type=_itype(store, ty + "_Response", None),
                                             response_qos=_qos(store, None))
                           for s, types in n.get(role, []) for ty in types]
        nodes.append(t[_P + "Node"](name=fqn(name, ns), parameters=[], parameter_values=[],
                                    publishers=roles["pubs"], subscriptions=roles["subs"],
                                    service_clients=roles["clients"], service_servers=roles["servers"],
                                    action_clients=[], action_servers=[]))
    return t[GRAPH_TYPE](nodes=nodes)


def graph_gid(node: str, role: str, topic: str, k: int) -> str:
    """The GID (hex, 16 bytes) given to the ``k``-th endpoint of node ``node`` (FQN) in ``role`` on ``topic``
    read from a message that has none: its first 12 bytes (the participant's part) from the node, the last 4
    from the endpoint, so a node's endpoints share a participant as rmw's do."""
    head = hashlib.sha256(node.encode()).digest()[:12]
    tail = hashlib.sha256(f"{role}\0{topic}\0{k}".encode()).digest()[:4]
    return (head + tail).hex()


def _hash_of(itype: Any) -> str | None:
    if int(itype.hash.version) != 1:
        return None
    return "RIHS01_" + bytes(bytearray(int(b) for b in itype.hash.value)).hex()


def _service_type(name: str) -> str:
    return name[:-len("_Request")] if name.endswith("_Request") else name


def _action_parts(a: Any) -> tuple[list[tuple[str, Any]], list[tuple[str, Any]]]:
    """An ``Action`` entry's services and topics, each with the name it is read under."""
    def named(part: str, entry: Any) -> str:
        return str(entry.name) if str(entry.name).startswith("/") else f"{a.name}/_action/{part}"
    services = [(named(p, getattr(a, p)), getattr(a, p)) for p in ("send_goal", "get_result", "cancel_goal")]
    topics = [(named(p, getattr(a, p)), getattr(a, p)) for p in ("feedback", "status")]
    return services, topics


def from_message(msg: Any) -> dict[str, Any]:
    """The graph dump (``nodes``, ``endpoints``; no ``rmw``) of a ``rosgraph_msgs/msg/Graph`` message as rosbags
    deserialises it (module docstring).  Never raises on a well-typed message."""
    nodes: list[dict[str, Any]] = []
    ends: dict[str, dict[str, list[dict[str, Any]]]] = {}
    for n in msg.nodes:
        full = str(n.name)
        ns, _, name = full.rpartition("/")
        ns = ns or "/"
        out: dict[str, Any] = {"name": name, "ns": ns, "pubs": [], "subs": [], "servers": [], "clients": []}
        lists: dict[str, list[tuple[str, Any]]] = {
            "pubs": [(str(x.name), x) for x in n.publishers], "subs": [(str(x.name), x) for x in n.subscriptions],
            "servers": [(str(x.name), x) for x in n.service_servers],
            "clients": [(str(x.name), x) for x in n.service_clients]}
        # an action server publishes its feedback and status, a client subscribes to them
        for role, topic_role, actions in (("servers", "pubs", n.action_servers), ("clients", "subs", n.action_clients)):
            for a in actions:
                services, topics = _action_parts(a)
                lists[role] += services
                lists[topic_role] += topics
        for role in ("pubs", "subs"):
            by_name: dict[str, list[str]] = {}
            for k, (topic, x) in enumerate(lists[role]):
                ty = str(x.type.name)
                if ty not in by_name.setdefault(topic, []):
                    by_name[topic].append(ty)
                q = x.qos
                if int(q.reliability) not in (RELIABLE, BEST_EFFORT) or int(q.durability) not in (TRANSIENT_LOCAL, VOLATILE):
                    continue  # listed with no endpoint read for it
                e: dict[str, Any] = {"gid": graph_gid(full, role, topic, k), "node": name, "ns": ns, "type": ty,
                                     "reliable": int(q.reliability) == RELIABLE,
                                     "durability": "transient_local" if int(q.durability) == TRANSIENT_LOCAL else "volatile",
                                     "deadline_ns": _ns(q.deadline),
                                     "liveliness": _LIVELINESS_NAME.get(int(q.liveliness), "unknown"),
                                     "lease_ns": _ns(q.liveliness_lease_duration)}
                if (h := _hash_of(x.type)) is not None:
                    e["hash"] = h
                ends.setdefault(topic, {"pubs": [], "subs": []})[role].append(e)
            out[role] = [[topic, types] for topic, types in by_name.items()]
        for role in ("servers", "clients"):
            by_service: dict[str, list[str]] = {}
            for s, x in lists[role]:
                ty = _service_type(str(x.request_type.name))
                if ty not in by_service.setdefault(s, []):
                    by_service[s].append(ty)
            out[role] = [[s, types] for s, types in by_service.items()]
        nodes.append(out)
    nodes.sort(key=lambda d: (d["name"], d["ns"]))
    return {"what": "graph_all", "nodes": nodes, "endpoints": dict(sorted(ends.items()))}


__all__ = ["DEFINITIONS", "GRAPH_TYPE", "fqn", "from_message", "graph_gid", "graph_store", "graph_type_hash",
           "to_message"]
