"""Publishers of a contract type with another ROS 2 type hash than the
monitor's definition, on the rclpy source's bus (:mod:`.bus`, whose module
docstring gives the rule): each is read in the definition it declares, asked
of the agent once per type and hash and checked to hash to it
(:func:`~rclverify.runtime.dds.types.declare`), or, when none checks out,
never heard, with one located warning that says what to do.
"""
from __future__ import annotations

from typing import Any, Callable, Mapping

from rclverify.runtime.dds.bus import Tap
from rclverify.runtime.dds.type_descriptions import declare
from rclverify.runtime.dds.types import DdsTypeError, Declaration
from rclverify.runtime.rclpy_source.discovery import AgentDiscovery, ros_name, ros_type


class DeclaredTypes:
    """The bus's part that decides how a publisher's samples are read
    (:meth:`_admit`), asks the agent for a publisher's own definition
    (:meth:`_ask`) and takes its answer (:meth:`_described`).  The bus
    (:class:`~.bus.RclpyBus`) sets the attributes below and hands a sample
    frame back to :meth:`_sample` and a request to the agent to :meth:`_send`."""

    taps: list[Tap]
    discovery: AgentDiscovery
    warn: Callable[[str], None]
    #: the ROS 2 type hash of a contract struct (``None``: not known)
    type_hash: Callable[[type], str | None]
    #: (type, publisher's hash) -> the declaration its samples are read with, ``None`` when refused
    _declared: dict[tuple[str, str], Declaration | None]
    _why: dict[tuple[str, str], str]
    _asking: set[tuple[str, str]]
    _held: dict[tuple[int, bytes], list[bytes]]
    _warned: set[tuple[str, bytes, str]]

    #: one request to the agent (the bus's method)
    _send: Callable[[Mapping[str, object]], None]
    #: one sample frame of the agent, handed on or held (the bus's method)
    _sample: Callable[[bytes], None]

    def _admit(self, t: Tap, gid: bytes) -> bool | Declaration | None:
        """How publisher ``gid``'s samples are read: ``True`` in the contract's layout (its ROS 2 type
        hash is the contract type's, REP-2011, or a hash is not known: taken at its type name), a
        :class:`~rclverify.runtime.dds.types.Declaration` in the definition it declares, ``False``
        not at all (no declaration checked out: warned once), ``None`` not known yet (asked for)."""
        theirs, ours = self.discovery.hash_of(t.dds_topic, gid), self.type_hash(t.struct)
        if not theirs or not ours or theirs == ours:
            return True
        key = (ros_type(t.struct), theirs)
        if key not in self._declared:
            self._ask(t, gid, key)
            return None
        decl = self._declared[key]
        if decl is not None:
            return decl
        pkg, _, name = key[0].partition("/msg/")
        self._warn_once(t.key, gid, "layout", f"{t.where}: warning: {t.key}: {self._who(t, gid)} publishes "
                        f"{key[0]} with the type hash {theirs}, the monitor's definition of it hashes to {ours}, "
                        f"and the publisher's own definition could not be had ({self._why[key]}): its messages "
                        f"are not heard; give the robot's definition as DIR/{pkg}/msg/{name}.msg with "
                        "--interfaces DIR (or the mapping's msg_dirs)")
        return False

    def _who(self, t: Tap, gid: bytes) -> str:
        node = self.discovery.node_of(gid)
        return f"node {node} (publisher {gid.hex()})" if node else f"publisher {gid.hex()}"

    def _ask(self, t: Tap, gid: bytes, key: tuple[str, str]) -> None:
        """Ask the agent, once per type and hash, for the description publisher ``gid`` declares."""
        if key in self._asking or key in self._declared:
            return
        self._asking.add(key)
        pub = next((p for p in self.discovery.topics.get(ros_name(t.dds_topic) or "", [])
                    if bytes.fromhex(p["gid"]) == gid), {})
        self._send({"op": "describe", "type": key[0], "hash": key[1], "node": pub.get("node", ""),
                    "ns": pub.get("ns", "/")})

    def _described(self, obj: dict[str, Any]) -> None:
        """The agent's answer to a ``describe`` (:mod:`.wire`): the first candidate that hashes to
        the publisher's hash is the type's declaration; each that does not is said; the samples held
        for it are handed on (or dropped, with the warning, when none checks out)."""
        key = (str(obj.get("type", "")), str(obj.get("hash", "")))
        self._asking.discard(key)
        decl: Declaration | None = None
        why = [str(f) for f in obj.get("failures", [])]
        for cand in obj.get("candidates", []):
            try:
                decl = declare(key[0], key[1], cand.get("description", {}), str(cand.get("from", "the agent")))
                break
            except DdsTypeError as exc:  # a stale or forged description: said where the contract names the type
                why.append(str(exc))
                for t in self.taps:
                    if ros_type(t.struct) == key[0]:
                        self.warn(f"{t.where}: warning: {t.key}: {exc}")
        self._declared[key] = decl
        self._why[key] = "; ".join(why) or "nothing answered"
        for t in self.taps:  # refused: each such publisher said at once (the warning of _admit), not at its sample
            if decl is None and ros_type(t.struct) == key[0]:
                for p in self.discovery.publishers(t.dds_topic):
                    if self.discovery.hash_of(t.dds_topic, p.guid) == key[1]:
                        self._admit(t, p.guid)
        if decl is not None:
            for t in self.taps:
                if ros_type(t.struct) == key[0]:
                    self.warn(f"{t.where}: note: {t.key}: publishers of {key[0]} with the type hash {key[1]} (not "
                              f"the monitor's {self.type_hash(t.struct)}) are read in their own definition, from "
                              f"{decl.origin}")
        for (k, gid), bodies in list(self._held.items()):
            t = self.taps[k]
            if ros_type(t.struct) == key[0] and self.discovery.hash_of(t.dds_topic, gid) == key[1]:
                del self._held[(k, gid)]
                for body in bodies:
                    self._sample(body)

    def _warn_once(self, key: str, gid: bytes, why: str, text: str) -> None:
        if (key, gid, why) not in self._warned:
            self._warned.add((key, gid, why))
            self.warn(text)


__all__ = ["DeclaredTypes"]
