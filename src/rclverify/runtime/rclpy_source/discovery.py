"""The running graph as the rclpy source's agent reports it during a live run
(:mod:`.bus`), with the DDS discovery's face, and the names that tie it to
the DDS path: a DDS topic's ROS name (:func:`ros_name`) and a contract
struct's ROS 2 type (:func:`ros_type`), as ROS 2's DDS mapping names them
(docs/ros2.md, "Two sources").
"""
from __future__ import annotations

from typing import Any

from rclverify.ros.live.dds_discovery import EndpointInfo
from rclverify.ros.live.dds_qos import QosProfile


def ros_name(dds_topic: str) -> str | None:
    """The ROS name of a DDS topic of ROS 2's conventions (``rt/a/b`` -> ``/a/b``),
    ``None`` for a service's request or reply topic (``rq/``, ``rr/``: rclpy cannot read them)."""
    if dds_topic.startswith("rt/"):
        return "/" + dds_topic[3:]
    return None


def ros_type(struct: type) -> str:
    """``pkg/msg/T`` of a contract struct (``pkg::msg::dds_::T_``)."""
    parts = [p for p in struct.__idl_typename__.split("::") if p != "dds_"]  # type: ignore[attr-defined]
    return "/".join(parts[:-1] + [parts[-1].rstrip("_")])


class AgentDiscovery:
    """The graph as the agent reports it (its ``graph`` lines: per topic its publishers' GID, node,
    namespace, type, type hash and QoS; per service its servers' and clients' nodes), with the face of
    :class:`~rclverify.ros.live.dds_discovery.Discovery` that the live run and the bus read."""

    def __init__(self) -> None:
        self.topics: dict[str, list[dict[str, Any]]] = {}
        self.services: dict[str, dict[str, list[str]]] = {}
        self._node: dict[bytes, str] = {}

    def update(self, graph: dict[str, Any]) -> None:
        self.topics = graph.get("topics", {})
        self.services = graph.get("services", {})
        self._node = {bytes.fromhex(p["gid"]): (p["ns"].rstrip("/") + "/" + p["node"])
                      for ps in self.topics.values() for p in ps}

    def publishers(self, dds_topic: str) -> list[EndpointInfo]:
        """The publishers on ``dds_topic`` (its ROS name), by GID."""
        name = ros_name(dds_topic)
        out = [EndpointInfo(bytes.fromhex(p["gid"]), bytes.fromhex(p["gid"])[:12], dds_topic, p["type"],
                            QosProfile(reliable=p["reliable"], durability=p["durability"]))
               for p in self.topics.get(name or "", [])]
        return sorted(out, key=lambda e: e.guid)

    def node_of(self, guid: bytes) -> str | None:
        """The ROS node (``/ns/name``) of a publisher's GID, or ``None``."""
        return self._node.get(guid)

    def who(self, e: EndpointInfo) -> str:
        n = self.node_of(e.guid)
        return f"node {n}" if n else f"publisher {e.guid.hex()}"

    def hash_of(self, dds_topic: str, guid: bytes) -> str:
        name = ros_name(dds_topic) or ""
        return next((p["hash"] for p in self.topics.get(name, []) if bytes.fromhex(p["gid"]) == guid), "")


__all__ = ["AgentDiscovery", "ros_name", "ros_type"]
