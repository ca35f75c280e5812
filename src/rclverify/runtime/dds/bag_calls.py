"""The service calls and action goals of a live run written to its ``--record`` bag as ROS 2 records them.

What ROS 2 records of a call (ROS 2 design "Service introspection", REP-2012;
``ros2 bag record --services``; the topics and types
:mod:`rclverify.backends.monitors.bag_calls` reads back):

* a service ``/s`` of type ``pkg/Srv``: ``/s/_service_event``,
  ``pkg/srv/Srv_Event`` (``info`` {``event_type``, ``stamp``,
  ``client_gid``, ``sequence_number``}, ``request[<=1]``,
  ``response[<=1]``);
* an action ``/a`` of type ``pkg/A``: the events of its services
  ``/a/_action/send_goal`` (``pkg/action/A_SendGoal_Event``),
  ``/a/_action/get_result`` (``A_GetResult_Event``) and
  ``/a/_action/cancel_goal`` (``action_msgs/srv/CancelGoal_Event``), and its
  topics ``/a/_action/feedback`` (``A_FeedbackMessage``) and
  ``/a/_action/status`` (``action_msgs/msg/GoalStatusArray``).

Where they come from (:class:`CallRecorder`):

* **heard as they are**: introspection events a node published, feedback
  and status messages, each written as it came off the wire, at its DDS
  source timestamp (the time the live call book used for it);
* **from the call book's lines** (:mod:`.dds_calls`, the live pairing):
  a service call the monitor paired without identity on the wire
  (rmw_fastrtps) becomes a REQUEST_SENT event and, answered, a
  RESPONSE_SENT event, with ``client_gid`` = the request writer's GUID and
  ``sequence_number`` = the monitor's count of that writer's requests (what
  rmw_fastrtps gives: its client gid is that writer's GUID, its sequence
  numbers count the writer's samples from 1); with rmw_cyclonedds' request
  header, the header's 64-bit writer handle in the last 8 bytes of
  ``client_gid`` (the first 8 zero); an answer no call could be given to,
  ``client_gid`` all zero.  A goal becomes a send-goal REQUEST_SENT event
  (its request writer and count), a result a get-result RESPONSE_SENT event
  with the identity of the get-result request about that goal (written
  too, as heard); a cancel request and reply become cancel-goal events;
* **the book's own lines** go to
  :data:`~rclverify.backends.monitors.bag_calls.DECISIONS`
  (``std_msgs/msg/String``, one JSON line each, in the book's order): each
  line without its fields, naming instead the message above that holds
  them (``ref``: topic, bag time in ns, which part), and the lines no ROS 2
  message can carry: the clock ticks that decided something, the calls the
  book could not pair (``unpaired``, with the reason), a call of a service
  with several servers (its key names the server, ``also`` marks the
  second server's call of one request), the goals it closed as rejected
  (their send-goal response event, ``accepted: false``, is written too),
  the endpoints of a link it did not hear with contents (``unjudged``: what
  the live run knew of the graph and of each endpoint's introspection, so
  the bag's check is never greener than the live run).
  So the bag check replays the live book's pairing and clock exactly, the
  values read from the ROS 2 messages.

An event is written at its stamp (``info.stamp`` too), a decision line at
the book's time for it, kept strictly increasing so that reading the bag in
time order gives the lines in the book's order.  A send-goal response that
accepted its goal is not written: the live book pairs it with no goal (the
goal's result and feedback say it was accepted); nor is a reply the book
could not pair (no call can be named in its event: its decision says so).
"""
from __future__ import annotations

import json
from typing import Any, Iterable

from rclverify.lang import ast
from rclverify.lang.types import CheckedNode
from rclverify.backends.monitors.bag_calls import (DECISIONS, REQUEST_SENT, RESPONSE_SENT, link_topics,
                                                   topic_type)
from rclverify.runtime.dds.bag_types import definition
from rclverify.runtime.dds.introspection import event_struct
from rclverify.runtime.dds.call_plan import cancel_types
from rclverify.runtime.dds.types import DdsTypeError, TypeBook, to_fields

#: entries kept per table of identities (the oldest forgotten beyond it)
MAX_KEPT = 10_000
_ZERO = bytes(16)


def _event_type(types: TypeBook, base: str) -> None:
    """Define ``<base>_Event`` (``base``: ``pkg/action/A_SendGoal`` ...) as
    rosidl makes every service's event type (:mod:`.introspection`)."""
    types._synth("service_msgs/msg/ServiceEventInfo", [
        ("event_type", (1, ("uint8", 0))), ("stamp", (2, "builtin_interfaces/msg/Time")),
        ("client_gid", (3, ((1, ("uint8", 0)), 16))), ("sequence_number", (1, ("int64", 0)))])
    types._synth(f"{base}_Event", [("info", (2, "service_msgs/msg/ServiceEventInfo")),
                                   ("request", (4, ((2, f"{base}_Request"), 1))),
                                   ("response", (4, ((2, f"{base}_Response"), 1)))])


def _ns(t: float) -> int:
    return max(0, round(t * 1e9))


def _stamp(ns: int) -> dict[str, int]:
    return {"sec": ns // 1_000_000_000, "nanosec": ns % 1_000_000_000}


def _limit(d: dict[Any, Any]) -> None:
    while len(d) > MAX_KEPT:
        d.pop(next(iter(d)))


class CallRecorder:
    """The call topics of ``links`` and what is written on them (module
    docstring).  :attr:`plan`: bag topic (no leading ``/``) -> ``(type,
    definition, hash)``, the connections the bag is opened with
    (:class:`~.bag.BagRecorder`); then :attr:`write` (``write(topic,
    time_ns, raw)``) and :attr:`specs` (the call taps' structs,
    :class:`~.services.CallTaps`) are set, and :meth:`sample` and
    :meth:`line` are fed from the engine thread.  Raises :class:`~.types.DdsTypeError` (with the link's
    location) for a link type that cannot be described for a bag."""

    def __init__(self, types: TypeBook, links: Iterable[tuple[CheckedNode, ast.Link]]) -> None:
        self.types = types
        self.plan: dict[str, tuple[str, str | None, str | None]] = {DECISIONS: ("std_msgs/msg/String", None, None)}
        self.structs: dict[str, type] = {}
        self.kinds: dict[str, str] = {}  # link -> service or action
        for _node, lk in links:
            link = lk.name.strip("/")
            if link in self.kinds:
                continue
            self.kinds[link] = lk.kind
            try:
                self._plan(link, lk)
            except DdsTypeError as exc:
                raise DdsTypeError(f"{lk.loc.file}:{lk.loc.line}:{lk.loc.col}: error: cannot record {lk.kind} "
                                   f"/{link} ({lk.ros_type}): {exc}") from None
        self.string = types.message("std_msgs/String")
        self.write: Any = None
        self.specs: dict[str, tuple[str, Any, Any, str]] = {}  # the call taps' structs (CallTaps.specs)
        self._asked: dict[tuple[str, bytes], int] = {}  # (request topic, writer) -> requests heard
        self._goal: dict[str, tuple[bytes, int]] = {}  # goal id -> its send-goal request's (writer, count)
        self._result: dict[str, tuple[bytes, int]] = {}  # goal id -> its get-result request's (writer, count)
        self._status: dict[float, int] = {}  # get-result reply stamp -> its status
        self._also: dict[tuple[str, int], tuple[str, int, str]] = {}  # (link, request bag time) -> its event
        self._last = 0
        self.failed = 0

    def _plan(self, link: str, lk: ast.Link) -> None:
        t = self.types
        if lk.kind == "service":
            event_struct(t, lk.ros_type)
        else:
            t.action(lk.ros_type)
            cancel_types(t)
            for role in ("send_goal", "get_result", "cancel_goal"):
                _event_type(t, topic_type(lk.ros_type, role)[: -len("_Event")])
        for topic, role in link_topics(lk.kind, link).items():
            name = topic_type(lk.ros_type, role)
            self.structs[topic] = t.struct(name)
            self.plan[topic] = (name, *definition(t, name))

    # -- writing -----------------------------------------------------------------------------------
    def _put(self, topic: str, time_ns: int, raw: bytes) -> None:
        if self.write is not None:
            self.write(topic, time_ns, raw)

    def _event(self, topic: str, kind: int, time: float, gid: bytes, seq: int, request: Any = None,
               response: Any = None) -> int:
        """Write one service event on ``topic`` stamped ``time`` (s), at that time; returns its bag time (ns)."""
        ns = _ns(time)
        data = {"info": {"event_type": kind, "stamp": _stamp(ns), "client_gid": list(gid.ljust(16, b"\0")[:16]),
                         "sequence_number": seq},
                "request": [] if request is None else [request], "response": [] if response is None else [response]}
        cls = self.structs[topic]
        self._put(topic, ns, bytes(self.types.build(cls, data).serialize()))
        return ns

    # -- the wire (heard) ------------------------------------------------------------------------------
    def sample(self, key: str, raw: bytes, source_ns: int, writer: bytes | None) -> None:
        """One sample of call tap ``key`` (``call:/<link>:<part>``, :mod:`.services`), heard with
        source timestamp ``source_ns`` from ``writer`` (its GUID, ``None`` unknown).  Never raises
        (a sample that cannot be written is counted in :attr:`failed`)."""
        try:
            self._sample(key, raw, source_ns, writer or _ZERO)
        except Exception:  # noqa: BLE001 - the live run goes on; counted in the bag's record
            self.failed += 1

    def _sample(self, key: str, raw: bytes, source_ns: int, writer: bytes) -> None:
        name, part = key[len("call:"):].rsplit(":", 1)
        link = name.strip("/")
        a = link + "/_action/"
        at = _ns(source_ns / 1e9)  # the stamp the book gives it, as the book's lines name it (ref)
        if part == "event":
            self._put(link + "/_service_event", at, raw)
        elif part in ("feedback", "status"):
            self._put(a + part, at, raw)
        elif part in ("goal_request", "result_request", "cancel_request", "cancel_reply", "result_reply"):
            s = self.specs[key][1].deserialize(raw)
            t = source_ns / 1e9
            if part == "result_reply":
                self._status[t] = int(s.status)
                _limit(self._status)
                return
            if part == "cancel_reply":
                self._event(a + "cancel_goal/_service_event", RESPONSE_SENT, t, _ZERO, 0, response=to_fields(s))
                return
            svc = {"goal_request": "send_goal", "result_request": "get_result", "cancel_request": "cancel_goal"}[part]
            k = self._asked[(svc + link, writer)] = self._asked.get((svc + link, writer), 0) + 1
            if part == "cancel_request":
                self._event(a + "cancel_goal/_service_event", REQUEST_SENT, t, writer, k, request=to_fields(s))
                return
            gid = bytes(s.goal_id.uuid).hex()
            book = self._goal if part == "goal_request" else self._result
            book[gid] = (writer, k)
            _limit(book)
            if part == "result_request":
                self._event(a + "get_result/_service_event", REQUEST_SENT, t, writer, k, request=to_fields(s))

    # -- the book (paired) ------------------------------------------------------------------------------
    def line(self, obj: dict[str, Any]) -> None:
        """One line the live call book logged (:mod:`.dds_calls`); never raises (counted in :attr:`failed`)."""
        try:
            if obj.get("part") == "rejected":
                self._rejected(obj)
            self._line(obj)
        except Exception:  # noqa: BLE001 - the live run goes on; counted in the bag's record
            self.failed += 1

    def _line(self, obj: dict[str, Any]) -> None:
        """Write the ROS 2 record of one book line (module docstring), then the line itself, without
        its fields and naming the message that holds them (``ref``), on the decisions topic."""
        line = {k: v for k, v in obj.items() if k not in ("topic", "fields")}
        if "fields" in obj:
            ref = self._record(obj)
            if ref is not None:
                line["ref"] = list(ref)
        self._last = max(_ns(float(obj["time"])), self._last + 1)  # the book's order, kept by the bag's
        self._put(DECISIONS, self._last, bytes(self.string(data=json.dumps(line, sort_keys=True)).serialize()))

    def _record(self, obj: dict[str, Any]) -> tuple[str, int, str] | None:
        """Write the event of a line with fields (a part of a call) unless it was written as heard;
        returns ``(topic, bag time, body)``: where its fields are (``None``: nowhere)."""
        part, time, fields = str(obj.get("part")), float(obj["time"]), obj["fields"]
        link = str(obj.get("link", "")).strip("/")
        kind, key = self.kinds.get(link), list(obj.get("key") or [])
        a = link + "/_action/"
        if kind == "service":
            topic, body = link + "/_service_event", "request" if part == "request" else "response"
            if key and key[0] == "ev":
                return topic, _ns(time), body  # the node's own introspection event, written as heard
            if obj.get("also"):  # the same request's call with another server: the same event
                return self._also.get((link, _ns(time)))
            gid, seq = self._identity(key)
            ref = (topic, self._event(topic, REQUEST_SENT if body == "request" else RESPONSE_SENT, time, gid, seq,
                                      **{body: fields}), body)
            if body == "request":
                self._also[(link, ref[1])] = ref
                _limit(self._also)
            return ref
        if part == "feedback":
            return a + "feedback", _ns(time), "feedback"  # written as heard
        if part == "goal":
            writer, k = self._goal.get(str(key[0]), (_ZERO, 0))
            topic = a + "send_goal/_service_event"
            return topic, self._event(topic, REQUEST_SENT, time, writer, k, request={
                "goal_id": {"uuid": list(bytes.fromhex(str(key[0])))}, "goal": fields}), "goal"
        if part == "result":
            writer, k = self._result.get(str(key[0]), (_ZERO, 0))
            topic = a + "get_result/_service_event"
            return topic, self._event(topic, RESPONSE_SENT, time, writer, k,
                                      response={"status": self._status.get(time, 0), "result": fields}), "result"
        return None

    def _rejected(self, obj: dict[str, Any]) -> None:
        """A goal the book closed as refused: its send-goal response event (``accepted: false``)."""
        link = str(obj.get("link", "")).strip("/")
        writer, k = self._goal.get(str(obj["key"][0]), (_ZERO, 0))
        self._event(link + "/_action/send_goal/_service_event", RESPONSE_SENT, float(obj["time"]), writer, k,
                    response={"accepted": False})

    @staticmethod
    def _identity(key: list[Any]) -> tuple[bytes, int]:
        """``(client_gid, sequence_number)`` of a service call's key (module docstring); a server's
        GUID the key may end with (a service with several servers) is in the book's line only."""
        if key and key[0] == "w":
            return (bytes.fromhex(str(key[1])) if key[1] else _ZERO), int(key[2])
        return bytes(8) + int(key[0]).to_bytes(8, "big"), int(key[1])


__all__ = ["CallRecorder", "MAX_KEPT"]
