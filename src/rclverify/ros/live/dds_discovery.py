"""What a DDS domain shows of a running ROS 2 system: the endpoints DDS
discovery announces (the built-in publication and subscription topics:
GUID, participant, topic, type, QoS) and the node each belongs to (ROS 2's
``ros_discovery_info``, :mod:`.dds`).

:class:`Discovery` only reads: it creates built-in readers and one reader
of ``ros_discovery_info`` (reliable, transient-local, keep-all: the QoS of
rmw's own reader of it, rmw_fastrtps ``init_rmw_context_impl.cpp``; the
writers keep the last one, but the topic has no key, so every participant's
sample falls in one instance and a keep-last reader would lose some), and
:meth:`Discovery.poll` takes what arrived, without blocking.  The live
monitor polls it from its DDS thread; ``rclverify ros diff --ros2`` polls it
for a settling time and reads the graph (:mod:`.diff_dds`).  An endpoint
that goes away is removed, and so is a participant's node list.
"""
from __future__ import annotations

import uuid
from dataclasses import dataclass, field
from typing import Any

from rclverify.ros.live.dds import DISCOVERY_TOPIC, take_raw
from rclverify.ros.live.discovery_info import NodeInfo, decode_participant_info, discovery_struct
from rclverify.ros.live.dds_qos import QosProfile, from_dds, to_dds

ALIVE = 16  # DDS_ALIVE_INSTANCE_STATE


@dataclass(frozen=True)
class EndpointInfo:
    """One discovered reader or writer: its GUID (16 bytes), its participant's,
    the DDS topic and type names, its QoS."""

    guid: bytes
    participant: bytes
    topic: str
    type_name: str
    qos: QosProfile
    #: the XTypes type identifier discovery carries (a hash of the type's layout; None when not sent)
    type_id: Any = None

    @property
    def label(self) -> str:
        """``writer 0110...0203`` (the GUID in hex, as ``ros2 topic info -v`` prints it, dotted)."""
        return ".".join(f"{b:02x}" for b in self.guid)


@dataclass
class Discovery:
    """The domain's endpoints and nodes as discovery reports them (see the
    module docstring).  ``own`` is the GUID of participants whose endpoints
    are left out (the monitor's own)."""

    dp: Any
    own: set[bytes] = field(default_factory=set)
    writers: dict[bytes, EndpointInfo] = field(default_factory=dict)
    readers: dict[bytes, EndpointInfo] = field(default_factory=dict)
    nodes: dict[bytes, list[NodeInfo]] = field(default_factory=dict)
    gid_sizes: set[int] = field(default_factory=set)
    bad_info: int = 0

    def __post_init__(self) -> None:
        from cyclonedds.builtin import (BuiltinDataReader, BuiltinTopicDcpsParticipant,
                                        BuiltinTopicDcpsPublication, BuiltinTopicDcpsSubscription)  # deferred: start-up (loads cyclonedds and more only when called)
        from cyclonedds.sub import DataReader  # deferred: start-up (loads cyclonedds and more only when called)
        from cyclonedds.topic import Topic  # deferred: start-up (loads cyclonedds and more only when called)
        self.own.add(self.dp.guid.bytes)
        self._pubs = BuiltinDataReader(self.dp, BuiltinTopicDcpsPublication)
        self._subs = BuiltinDataReader(self.dp, BuiltinTopicDcpsSubscription)
        self._parts = BuiltinDataReader(self.dp, BuiltinTopicDcpsParticipant)
        qos = to_dds(QosProfile(reliable=True, durability="transient_local", depth=None))
        self._info = DataReader(self.dp, Topic(self.dp, DISCOVERY_TOPIC, discovery_struct()), qos=qos)
        self._by_endpoint: dict[bytes, str] = {}

    def conditions(self) -> list[Any]:
        """Read conditions that trigger when discovery has news (for a wait set)."""
        from cyclonedds.core import InstanceState, ReadCondition, SampleState, ViewState  # deferred: start-up (loads cyclonedds and more only when called)
        mask = SampleState.Any | ViewState.Any | InstanceState.Any
        return [ReadCondition(r, mask) for r in (self._pubs, self._subs, self._info, self._parts)]

    def poll(self) -> bool:
        """Take what discovery reported since the last call; True when anything changed."""
        changed = False
        for reader, table in ((self._pubs, self.writers), (self._subs, self.readers)):
            for e in reader.take(N=1000):
                key = e.key.bytes
                info = getattr(e, "sample_info", None)
                if e.topic_name is None or (info is not None and info.instance_state != ALIVE):
                    changed = table.pop(key, None) is not None or changed
                    continue
                part = e.participant_key.bytes
                if part in self.own:
                    continue
                table[key] = EndpointInfo(key, part, e.topic_name, e.type_name, from_dds(e.qos),
                                          getattr(e, "type_id", None))
                changed = True
        for raw, info in take_raw(self._info, 1000):
            try:
                gid, nodes, size = decode_participant_info(raw)
            except ValueError:
                self.bad_info += 1
                continue
            if gid in self.own:
                continue
            self.nodes[gid] = nodes
            self.gid_sizes.add(size)
            changed = True
        for p in self._parts.take(N=1000):  # a participant gone: its node list goes with it
            info = getattr(p, "sample_info", None)
            if info is not None and info.instance_state != ALIVE and self.nodes.pop(p.key.bytes, None) is not None:
                changed = True
        if changed:
            self._by_endpoint = {g: n.full_name for nodes in self.nodes.values() for n in nodes
                                 for g in n.readers + n.writers}
        return changed

    def pending(self) -> list[str]:
        """What discovery has not yet told of the ROS 2 participants it knows,
        one sentence each (empty when the graph is settled).  A ROS 2 participant
        is one with a writer on ``ros_discovery_info`` (rmw_dds_common's graph
        cache: every ROS 2 context has one, a plain DDS participant none); it is
        settled when its node list has arrived, every endpoint of it is in one of
        its nodes, and every endpoint its nodes list has been discovered.  Fast
        DDS sends a newly matched reader the transient-local node list at its
        next heartbeat, seconds later, so a reader polls until this is empty
        (:func:`.diff_dds.read_dds_graph`)."""
        ros = {w.participant for w in self.writers.values() if w.topic == DISCOVERY_TOPIC}
        out = [f"participant {uuid.UUID(bytes=p)}: its node list (ros_discovery_info) has not arrived"
               for p in sorted(ros - set(self.nodes))]
        for table in (self.writers, self.readers):
            for e in sorted(table.values(), key=lambda e: e.guid):
                if e.participant in ros and e.participant in self.nodes and e.topic != DISCOVERY_TOPIC \
                        and self.node_of(e.guid) is None:
                    out.append(f"endpoint {e.label} on {e.topic}: no node of its participant lists it yet")
        known = set(self.writers) | set(self.readers)
        for p, nodes in sorted(self.nodes.items()):
            for n in nodes:
                lost = [g for g in n.readers + n.writers if g not in known]
                if lost:
                    out.append(f"node {n.full_name}: {len(lost)} of its endpoints not yet discovered")
        return out

    def node_of(self, endpoint: bytes) -> str | None:
        """The ROS node (``/ns/name``) an endpoint GUID belongs to, or ``None``."""
        return self._by_endpoint.get(endpoint)

    def publishers(self, dds_topic: str) -> list[EndpointInfo]:
        """The writers on ``dds_topic``, by GUID."""
        return sorted((w for w in self.writers.values() if w.topic == dds_topic), key=lambda w: w.guid)

    def who(self, e: EndpointInfo) -> str:
        """``node /sensor`` when ros_discovery_info names the endpoint's node, else
        ``participant <guid>`` (a DDS participant outside ROS 2's conventions)."""
        n = self.node_of(e.guid)
        return f"node {n}" if n else f"participant {uuid.UUID(bytes=e.participant)}"

    def close(self) -> None:
        """Delete the readers (the participant stays)."""
        for r in (self._info, self._parts, self._subs, self._pubs):
            r.__del__()


__all__ = ["Discovery", "EndpointInfo"]
