"""The ROS 2 graph as the rclpy agent (:mod:`agent`) reads it through
rclpy's graph API: an endpoint as the monitor reads it (:func:`endpoint`),
whether a subscription's QoS matches every publisher (:func:`matches`),
the serving, calling and introspecting nodes of each watched service or
action (:class:`GraphReading`, mixed into the agent), and the whole graph
dumped once it is settled (:func:`graph_dump`, ``agent.py --graph``).

Imported by the agent as a top-level module (its folder is the script's):
rclpy and the standard library only, and :mod:`wire` beside it.
"""
from __future__ import annotations

import os
import time
from typing import Any, TypedDict

import rclpy
from rclpy.action import graph as action_graph
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, ReliabilityPolicy
from rclpy.utilities import get_rmw_implementation_identifier

import wire  # type: ignore[import-not-found]  # beside this script (agent.py's docstring)


class Endpoint(TypedDict):
    """One endpoint of rclpy's graph as the monitor reads it (:func:`_endpoint`)."""
    gid: str
    node: str
    ns: str
    type: str
    hash: str
    reliable: bool
    durability: str
    #: the offered (publisher) or requested (subscription) deadline and liveliness lease in ns, as
    #: rmw reports them (``RMW_DURATION_INFINITE``, 2**63 - 1, for none), and the liveliness kind's name
    deadline_ns: int
    liveliness: str
    lease_ns: int


class GraphReading:
    """The agent's readings of the graph for its watched services and actions (module docstring)."""

    node: Any  # the agent's rclpy node
    name: str  # the agent's node name (its own endpoints are left out)
    services: dict[str, bool]  # service or action name -> whether an action

    def _publishers(self, topic: str) -> list[Any]:
        return [p for p in self.node.get_publishers_info_by_topic(topic)
                if not (p.node_name == self.name and p.node_namespace == "/")]

    def _service_ends(self) -> dict[str, dict[str, list[str]]]:
        """Each watched service's or action's serving and calling nodes
        (``/ns/name``), and ``events``: the nodes that publish its
        introspection events (:func:`_introspecting`; a node whose
        introspection is off has no such publisher; whether one publishes
        metadata or contents its events tell the monitor)."""
        ends: dict[str, dict[str, set[str]]] = {n: {"servers": set(), "clients": set(), "events": set()}
                                                for n in self.services}
        for svc, is_action in self.services.items():
            ends[svc]["events"] = self._introspecting(svc, is_action)
        for name, ns in self.node.get_node_names_and_namespaces():
            if name == self.name and ns == "/":
                continue
            full = ns.rstrip("/") + "/" + name
            try:
                served = {s for s, _ in self.node.get_service_names_and_types_by_node(name, ns)}
                called = {s for s, _ in self.node.get_client_names_and_types_by_node(name, ns)}
                acts = {s for s, _ in action_graph.get_action_server_names_and_types_by_node(self.node, name, ns)}
                acts_c = {s for s, _ in action_graph.get_action_client_names_and_types_by_node(self.node, name, ns)}
            except Exception:  # noqa: BLE001 - a node that left between the two calls: read again next time
                continue
            for svc, is_action in self.services.items():
                if svc in (acts if is_action else served):
                    ends[svc]["servers"].add(full)
                if svc in (acts_c if is_action else called):
                    ends[svc]["clients"].add(full)
        return {n: {k: sorted(v) for k, v in e.items()} for n, e in ends.items()}

    def _introspecting(self, svc: str, is_action: bool) -> set[str]:
        """The nodes (``/ns/name``) that publish the introspection events of
        service ``svc`` (``<svc>/_service_event``), or of action ``svc``'s
        send-goal and get-result services both (a goal and its result)."""
        topics = ([f"{svc}/_action/send_goal/_service_event", f"{svc}/_action/get_result/_service_event"]
                  if is_action else [f"{svc}/_service_event"])
        found: set[str] | None = None
        for t in topics:
            nodes = {p.node_namespace.rstrip("/") + "/" + p.node_name for p in self._publishers(t)}
            found = nodes if found is None else found & nodes
        return found or set()


def endpoint(p: Any) -> Endpoint:
    """One endpoint of rclpy's graph (a ``TopicEndpointInfo``) as the monitor reads it."""
    return {"gid": bytes(p.endpoint_gid[:wire.GID_BYTES]).hex(), "node": p.node_name, "ns": p.node_namespace,
            "type": p.topic_type, "hash": str(p.topic_type_hash),
            "reliable": p.qos_profile.reliability == ReliabilityPolicy.RELIABLE,
            "durability": "transient_local" if p.qos_profile.durability == DurabilityPolicy.TRANSIENT_LOCAL
            else "volatile",
            "deadline_ns": int(p.qos_profile.deadline.nanoseconds), "liveliness": p.qos_profile.liveliness.name.lower(),
            "lease_ns": int(p.qos_profile.liveliness_lease_duration.nanoseconds)}


def matches(qos: tuple[bool, bool] | None, pubs: list[Endpoint]) -> bool:
    """Whether a subscription of ``qos`` (reliable, transient-local) matches every publisher of ``pubs``."""
    if qos is None:
        return False
    reliable, latched = qos
    return all((p["reliable"] or not reliable) and (p["durability"] == "transient_local" or not latched)
               for p in pubs)


def graph_dump(wait_s: float, settle_s: float = 8.0, quiet_s: float = 1.5) -> dict[str, object]:
    """The whole graph as rclpy's graph API reports it, once it is settled:
    after ``wait_s`` seconds of discovery, and on (up to ``settle_s`` more)
    until it has not changed for ``quiet_s``.  Each node with its publishers,
    subscribers, service servers and clients (hidden names included: an
    action's services), and each topic's publishers and subscriptions (GID,
    node, type, reliability, durability, deadline, liveliness and its lease)."""
    rclpy.init()
    name = f"_rclverify_graph_{os.getpid()}"
    node = Node(name)

    def snapshot() -> dict[str, object]:
        nodes = []
        for n, ns in sorted(node.get_node_names_and_namespaces()):
            if n == name:
                continue
            nodes.append({"name": n, "ns": ns,
                          "pubs": node.get_publisher_names_and_types_by_node(n, ns),
                          "subs": node.get_subscriber_names_and_types_by_node(n, ns),
                          "servers": node.get_service_names_and_types_by_node(n, ns),
                          "clients": node.get_client_names_and_types_by_node(n, ns)})
        ends: dict[str, dict[str, list[Endpoint]]] = {}
        for topic, _types in node.get_topic_names_and_types():
            ends[topic] = {role: [endpoint(p) for p in infos if p.node_name != name]
                           for role, infos in (("pubs", node.get_publishers_info_by_topic(topic)),
                                               ("subs", node.get_subscriptions_info_by_topic(topic)))}
        return {"nodes": nodes, "endpoints": ends}

    start = time.monotonic()
    last, since = None, start
    while True:
        rclpy.spin_once(node, timeout_sec=0.1)
        now = time.monotonic()
        if now - start < wait_s:
            continue
        snap = snapshot()
        if snap != last:
            last, since = snap, now
        if now - since >= quiet_s or now - start >= wait_s + settle_s:
            break
    node.destroy_node()
    rclpy.try_shutdown()
    return {"what": "graph_all", "rmw": get_rmw_implementation_identifier(), **(last or {})}
