"""The running ROS 2 graph as rclpy's graph API reports it, for ``ros diff
--ros2 --source rclpy`` (docs/ros2.md, "Two sources").

:func:`read_rclpy_graph` runs the agent (:mod:`.agent`) once in the ROS 2
Python (``--graph``: discovery for ``--wait`` seconds, then until the graph
settles) and returns what the DDS reading returns: the graph
(:func:`rclverify.ros.live.diff_dds.graph_of`) and a discovery of the same
face (:class:`RclpyDiscovery`: its endpoints named as ROS 2's DDS mapping
names them, ``rt/``, ``rq/``, ``rr/``, so the diff, the QoS conflicts and
the code's QoS read them as they read the DDS ones).  Services carry no QoS
or GID in rclpy's graph: each server and client is given a request and a
reply endpoint of a GID made from its node and name.  Raises
:class:`~.bus.RclpyUnavailable` (one message).
"""
from __future__ import annotations

import hashlib
from pathlib import Path
from typing import Any

from rclverify.ros.live.dds import dds_type, reply_topic, request_topic, topic_name
from rclverify.ros.live.discovery_info import NodeInfo
from rclverify.ros.live.dds_discovery import EndpointInfo
from rclverify.ros.live.dds_qos import INFINITE_NS, LIVELINESS, QosProfile
from rclverify.runtime.rclpy_source.agent_process import agent_answer


def _ns(value: object) -> int:
    """A duration of the dump in ns, :data:`INFINITE_NS` for none (rmw's 0 "default" or its infinite)."""
    ns = int(value) if isinstance(value, (int, float)) else 0
    return INFINITE_NS if ns <= 0 or ns >= INFINITE_NS else ns


def _qos(p: dict[str, Any]) -> QosProfile:
    """The matching policies of one endpoint of the dump: reliability, durability, and, where the dump
    has them, deadline, liveliness (a kind DDS does not have, rclpy's ``system_default`` or
    ``unknown``, read as the rmw default ``automatic``) and its lease."""
    live = str(p.get("liveliness", "automatic"))
    return QosProfile(reliable=bool(p["reliable"]), durability=p["durability"], deadline_ns=_ns(p.get("deadline_ns")),
                      liveliness=live if live in LIVELINESS else "automatic", lease_ns=_ns(p.get("lease_ns")))


class RclpyDiscovery:
    """The graph dump's endpoints and nodes with the face of
    :class:`~rclverify.ros.live.dds_discovery.Discovery` (module docstring)."""

    def __init__(self, dump: dict[str, Any]) -> None:
        self.dump = dump  # as the agent gave it: what nodl check --record-graph writes (model/nodl/graph_record.py)
        self.rmw = str(dump.get("rmw", ""))
        self.writers: dict[bytes, EndpointInfo] = {}
        self.readers: dict[bytes, EndpointInfo] = {}
        self._node: dict[bytes, str] = {}
        infos = [NodeInfo(n["ns"], n["name"]) for n in dump.get("nodes", [])]
        self.nodes: dict[bytes, list[NodeInfo]] = {b"rclpy": infos}
        full = {(n.namespace, n.name): n.full_name for n in infos}
        for topic, roles in sorted(dump.get("endpoints", {}).items()):
            for role, table in (("pubs", self.writers), ("subs", self.readers)):
                for p in roles.get(role, []):
                    gid = bytes.fromhex(p["gid"])
                    table[gid] = EndpointInfo(gid, gid[:12], topic_name(topic), dds_type(p["type"]), _qos(p))
                    if (p["ns"], p["node"]) in full:
                        self._node[gid] = full[(p["ns"], p["node"])]
        for n in dump.get("nodes", []):
            owner = full[(n["ns"], n["name"])]
            for key, serves in (("servers", True), ("clients", False)):
                for svc, types in n.get(key, []):
                    for t in types:
                        self._service(owner, svc, t, serves)

    def _service(self, owner: str, svc: str, typ: str, serves: bool) -> None:
        for part, topic, suffix in (("rq", request_topic(svc), "_Request"), ("rr", reply_topic(svc), "_Response")):
            gid = hashlib.sha256(f"{owner}|{svc}|{typ}|{part}|{serves}".encode()).digest()[:16]
            # a server reads requests and writes replies; a client the other way round
            table = self.readers if (part == "rq") == serves else self.writers
            table[gid] = EndpointInfo(gid, gid[:12], topic, dds_type(typ + suffix), QosProfile())
            self._node[gid] = owner

    def node_of(self, guid: bytes) -> str | None:
        """The ROS node (``/ns/name``) of an endpoint, or ``None``."""
        return self._node.get(guid)

    def publishers(self, dds_topic: str) -> list[EndpointInfo]:
        return sorted((w for w in self.writers.values() if w.topic == dds_topic), key=lambda w: w.guid)

    def who(self, e: EndpointInfo) -> str:
        n = self.node_of(e.guid)
        return f"node {n}" if n else f"endpoint {e.guid.hex()}"

    def pending(self) -> list[str]:
        return []

    def close(self) -> None:
        pass


def read_rclpy_graph(python: Path, wait_s: float) -> RclpyDiscovery:
    """The settled graph from the agent in ``python`` (module docstring)."""
    return RclpyDiscovery(agent_answer(python, ["--graph", str(wait_s)], wait_s + 60,
                                       f"the rclpy graph reader in {python} did not answer",
                                       f"the rclpy graph reader in {python} failed"))


__all__ = ["RclpyDiscovery", "read_rclpy_graph"]
