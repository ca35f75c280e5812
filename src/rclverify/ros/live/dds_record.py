"""The running ROS 2 graph as a DDS domain shows it, in the form of the rclpy agent's graph dump, so that
``nodl check --ros2 --source dds --record-graph FILE`` and ``ros diff --ros2 --source dds --record-graph FILE``
record it as the rclpy source's reading is recorded (docs/nodl.md, "A recorded graph";
:mod:`rclverify.model.nodl.graph_record` holds the recording's shape).

:func:`dds_dump` turns a :class:`~.dds_discovery.Discovery` into that dump:

* a node per entry of ``ros_discovery_info`` (``name``, ``ns``), with its topics (``pubs``, ``subs``) and
  services (``servers``: its readers of ``rq/SRequest``; ``clients``: its writers of it), each as
  ``[ROS name, [type]]`` with the ROS type (``pkg/msg/T``, ``pkg/srv/S``, an action's hidden services
  ``pkg/action/A_SendGoal``), as rclpy's ``get_*_names_and_types_by_node`` gives them;
* each ROS topic's (``rt/T``) publishers and subscriptions: the endpoint's GUID (hex), its node and
  namespace (both ``""`` for an endpoint no node lists), its ROS type, the type hash it announces in its
  USER_DATA (``RIHS01_...``; absent when it announces none), reliability, durability, deadline,
  liveliness and its lease (ns; :data:`~.dds_qos.INFINITE_NS` for none).

What the dump leaves out, and so a recording of the DDS source does not hold: topics outside ROS 2's naming
(``ros_discovery_info``, plain DDS), the QoS and GUIDs of service endpoints (rclpy's graph API does not give
them either: :class:`rclverify.runtime.rclpy_source.graph.RclpyDiscovery` gives each server and client a
request and a reply endpoint of default QoS), service endpoints no node lists, and the notes of a graph not
settled within the wait (:func:`.diff_dds.read_dds_graph`'s ``ROS-DDS`` notes).
"""
from __future__ import annotations

from typing import Any

from rclverify.ros.live.dds import announced_type_hash, ros_name, ros_type, service_type
from rclverify.ros.live.dds_discovery import Discovery, EndpointInfo


def _endpoint(e: EndpointInfo, node: tuple[str, str]) -> dict[str, Any]:
    """One topic endpoint of the dump (module docstring); ``node`` is ``(ns, name)``."""
    q = e.qos
    out: dict[str, Any] = {"gid": e.guid.hex(), "node": node[1], "ns": node[0], "type": ros_type(e.type_name),
                           "reliable": bool(q.reliable), "durability": q.durability, "deadline_ns": int(q.deadline_ns),
                           "liveliness": q.liveliness, "lease_ns": int(q.lease_ns)}
    digest = announced_type_hash(q.user_data) if q.user_data else None
    if digest:
        out["hash"] = digest
    return out


def dds_dump(disc: Discovery, source: str) -> dict[str, Any]:
    """The graph ``disc`` has discovered as the rclpy agent's dump (module docstring):
    ``{"what": "graph_all", "rmw": "", "source": source, "nodes": [...], "endpoints": {...}}``, nodes sorted
    by namespace and name, endpoints by GUID; ``source`` is the label the live reading gave
    (``DDS domain N``), kept so that a reading of the recording names the same source."""
    names: dict[str, tuple[str, str]] = {}
    for infos in disc.nodes.values():
        for n in infos:
            names.setdefault(n.full_name, (n.namespace or "/", n.name))
    by_node: dict[str, dict[str, dict[str, set[str]]]] = {
        full: {k: {} for k in ("pubs", "subs", "servers", "clients")} for full in names}
    endpoints: dict[str, dict[str, list[dict[str, Any]]]] = {}
    for table, writer in ((disc.writers, True), (disc.readers, False)):
        for e in sorted(table.values(), key=lambda e: e.guid):
            kind, name = ros_name(e.topic)
            typ = ros_type(e.type_name)
            full = disc.node_of(e.guid)
            if typ is None or kind not in ("topic", "request"):
                continue  # outside ROS 2's naming, or a reply topic (its request says the service)
            if kind == "request":
                svc = service_type(typ)
                if full in by_node and svc:
                    by_node[full]["clients" if writer else "servers"].setdefault(name, set()).add(svc)
                continue
            if full in by_node:
                by_node[full]["pubs" if writer else "subs"].setdefault(name, set()).add(typ)
            roles = endpoints.setdefault(name, {"pubs": [], "subs": []})
            roles["pubs" if writer else "subs"].append(_endpoint(e, names.get(full or "", ("", ""))))
    nodes = [{"name": names[full][1], "ns": names[full][0],
              **{k: [[n, sorted(ts)] for n, ts in sorted(lists[k].items())] for k in lists}}
             for full, lists in sorted(by_node.items(), key=lambda kv: names[kv[0]])]
    return {"what": "graph_all", "rmw": "", "source": source, "nodes": nodes,
            "endpoints": dict(sorted(endpoints.items()))}


__all__ = ["dds_dump"]
