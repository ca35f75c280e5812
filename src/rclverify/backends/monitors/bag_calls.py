"""Service calls and action goals read back from a ROS 2 bag (``rclverify monitor BAG``).

A ROS 2 bag holds a service's calls as its introspection events: topic
``<service>/_service_event``, type ``<pkg>/srv/<Srv>_Event`` (``info``:
``service_msgs/msg/ServiceEventInfo`` {``event_type``, ``stamp``,
``client_gid`` (``uint8[16]``), ``sequence_number``}, ``request[<=1]``,
``response[<=1]``; ROS 2 design "Service introspection", REP-2012;
``ros2 bag record --services``), and an action's as the events of its three
services (``<action>/_action/send_goal/_service_event``,
``.../get_result/...``, ``.../cancel_goal/...``) and its ``feedback`` and
``status`` topics (ROS 2 design "Actions").  ``rclverify monitor --live
--ros2 --record`` writes them so (:mod:`rclverify.runtime.dds.bag_calls`),
with the pairing the live monitor decided.

:class:`BagCalls` turns those messages back into the call lines the live
call book wrote (:mod:`.dds_calls`) and gives them to a
:class:`~.log_calls.LogCalls`, so a bag's calls are judged by the same
book, as a log's are:

* a call is named by ``client_gid`` + ``sequence_number``; its request
  comes from the request event of one side and its answer from the
  response event of the same side: the server's (REQUEST_RECEIVED,
  RESPONSE_SENT) when the bag has a REQUEST_RECEIVED event of the
  service, else the clients' (REQUEST_SENT, RESPONSE_RECEIVED) when it has
  a RESPONSE_RECEIVED one; both are real introspection (identity ``ev``, as
  live).  A service with only REQUEST_SENT and RESPONSE_SENT events is the
  monitor's own record of a wire without identity: ``client_gid`` is the
  request writer's GUID and ``sequence_number`` its count (identity ``w``,
  as live), or, its first 8 bytes zero, rmw_cyclonedds' 64-bit request
  writer handle in the last 8 (the request header's identity); all zero,
  an answer no call could be given to;
* an action's goal is its ``goal_id`` (the send-goal request), its
  feedback carries it, and a get-result response is given to the goal of
  the get-result request with the same ``client_gid`` + ``sequence_number``;
* the topic :data:`DECISIONS` (``std_msgs/msg/String``), which only
  rclverify writes, holds the live book's lines in its order, each without
  its fields but naming the message above that holds them (``ref``), and
  with them what no ROS 2 message can say: the book's clock ticks that
  decided something, the calls it could not pair (``unpaired``, with the
  live reason), the calls of a service with several servers, the goals it
  closed as rejected, the endpoints it did not hear with contents
  (``unjudged``, with the live reason: the link is not judged for them, so
  the bag's check is never greener than its live run).  With it the lines are replayed as they are, their
  fields read from the ROS 2 messages: the live pairing and clock, exactly.
  Without it (a bag ``ros2 bag record`` made) the lines are made from the
  events alone, in their stamps' order, the book's clock each line's stamp
  and, at the end, the bag's last time; a goal whose send-goal response
  says ``accepted: false`` is rejected; the bag's ``/clock`` messages, when a
  node with a call deadline may keep simulated time, are clock lines at
  their bag times among them (a call at the same time after them).

Without :data:`DECISIONS`, stamps are the events' ``info.stamp`` (a
feedback message has none: its bag time).  A bag without the topics of a
link cannot tell its calls: :meth:`BagCalls.explain` says so in the
not-judged list (never green).  Errors (a message that does not decode, a
topic of another type than its link's, a line naming a message the bag does
not hold) are :class:`~rclverify.traces.events.TraceError` naming the bag
and the topic.
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Iterable, Iterator, Mapping

from rclverify.lang.types import CheckedNode
from rclverify.traces.events import Event, TraceError
from rclverify.traces.sim_clock import clock_value_ns, is_clock_topic
from rclverify.backends.monitors.dds_calls import CALL_LOG_TOPIC
from rclverify.backends.monitors.log_calls import LogCalls

#: the suffix of a service's introspection event topic (rcl ``RCL_SERVICE_INTROSPECTION_TOPIC_POSTFIX``)
EVENT_SUFFIX = "/_service_event"
#: the topic of the live call book's lines, which pair the ROS 2 messages and say what they cannot (module docstring)
DECISIONS = "rclverify/call_decisions"
#: service_msgs/msg/ServiceEventInfo.event_type values
REQUEST_SENT, REQUEST_RECEIVED, RESPONSE_SENT, RESPONSE_RECEIVED = 0, 1, 2, 3
#: the bag's suffixes of a ROS 2 bag file (a directory is one too)
_BAG_SUFFIXES = (".mcap", ".db3")


def link_topics(kind: str, name: str) -> dict[str, str]:
    """The bag topics (no leading ``/``) of link ``name`` of ``kind``
    (``service``, ``action``) -> their role (``service``, ``send_goal``,
    ``get_result``, ``cancel_goal``, ``feedback``, ``status``)."""
    n = name.strip("/")
    if kind == "service":
        return {n + EVENT_SUFFIX: "service"}
    a = n + "/_action/"
    return {a + "send_goal" + EVENT_SUFFIX: "send_goal", a + "get_result" + EVENT_SUFFIX: "get_result",
            a + "cancel_goal" + EVENT_SUFFIX: "cancel_goal", a + "feedback": "feedback", a + "status": "status"}


def topic_type(ros_type: str, role: str) -> str:
    """The ROS 2 type of a link topic of ``role`` for link type ``ros_type``
    (``pkg/Srv``, ``pkg/srv/Srv``, ``pkg/A``, ``pkg/action/A``), as rosidl
    names it (``<Srv>_Event``, ``<A>_SendGoal_Event``, ``<A>_FeedbackMessage``)."""
    if role == "cancel_goal":
        return "action_msgs/srv/CancelGoal_Event"
    if role == "status":
        return "action_msgs/msg/GoalStatusArray"
    pkg, _, rest = ros_type.replace("/srv/", "/").replace("/action/", "/").partition("/")
    if role == "service":
        return f"{pkg}/srv/{rest}_Event"
    tail = {"send_goal": "_SendGoal_Event", "get_result": "_GetResult_Event", "feedback": "_FeedbackMessage"}[role]
    return f"{pkg}/action/{rest}{tail}"


def is_ros2_bag(path: Path) -> bool:
    """Whether ``path`` is a ROS 2 bag (a directory, an ``.mcap`` or ``.db3`` file)."""
    return path.is_dir() or path.suffix in _BAG_SUFFIXES


def _is_call_topic(topic: str) -> bool:
    return topic.endswith(EVENT_SUFFIX) or "/_action/" in topic


def _gid(fields: Mapping[str, Any]) -> bytes:
    return bytes(int(x) & 0xFF for x in fields["info"]["client_gid"])


def _stamp(fields: Mapping[str, Any]) -> float:
    t = fields["info"]["stamp"]
    return (int(t["sec"]) * 1_000_000_000 + int(t["nanosec"])) / 1e9


def _uuid(v: Mapping[str, Any]) -> str:
    return bytes(int(x) & 0xFF for x in v["uuid"]).hex()


class BagCalls:
    """The calls of ``nodes``' links in the bag at ``path`` (named ``trace``
    in messages), given to ``calls`` (module docstring).  ``connections``:
    the bag's topics (no leading ``/``) -> their types.  Raises
    :class:`TraceError` for a link topic of another type than its link's."""

    def __init__(self, nodes: Iterable[CheckedNode], calls: LogCalls, trace: str,
                 connections: Mapping[str, str]) -> None:
        self.calls, self.trace = calls, trace
        self.roles: dict[str, tuple[str, str]] = {}  # topic -> (link, role)
        self.links: dict[str, tuple[str, str]] = {}  # link -> (kind, ros type)
        self.node_links: dict[str, list[str]] = {}  # node -> its links
        for n in nodes:
            for lk in n.node.links:
                link = lk.name.strip("/")
                self.node_links.setdefault(n.name, []).append(link)
                self.links.setdefault(link, (lk.kind, lk.ros_type))
                for topic, role in link_topics(lk.kind, link).items():
                    self.roles[topic] = (link, role)
                    have, want = connections.get(topic), topic_type(lk.ros_type, role)
                    if have is not None and have != want:
                        raise TraceError(f"{trace}: topic /{topic}: error: its type is {have}, but the contract's "
                                         f"{lk.kind} /{link} is {lk.ros_type} (expected {want})")
        self.present = {t for t in self.roles if t in connections}
        self.items: list[Event] = []
        self.clocks: list[Event] = []  # the bag's /clock messages (tap), when the book reads /clock
        self.end = float("-inf")  # the bag's last time (s)
        #: link -> its events without the request or response they should hold (introspection METADATA)
        self.skipped: dict[str, int] = {}

    @property
    def active(self) -> bool:
        return self.calls.active and bool(self.roles)

    def explain(self, items: list[dict[str, str]]) -> None:
        """Say in not-judged ``items`` (:func:`.judged.not_judged`'s) which call topics the bag
        lacks: a link's detail names them, a node's too when it has links and none of them is in
        the bag (its silence is then the bag's, not the robot's); a link's endpoints the live run
        did not hear with contents (its ``unjudged`` lines) are named with the live reason."""
        missing = self.missing()
        book = self.calls.book
        for i in items:
            link = i["name"].strip("/")
            ends = book.unjudged_ends.get(link) if book is not None else None
            if i["kind"] in ("service", "action") and i["reason"] == "endpoint not heard" and ends:
                i["detail"] += " (" + "; ".join(ends.values()) + ")"  # the live run's reasons, in the bag's lines
            elif i["kind"] in ("service", "action") and link in missing:
                i["detail"] = _lacks(self.trace, missing[link])
            elif i["kind"] in ("service", "action") and i["reason"] == "nothing heard" and self.skipped.get(link):
                i["detail"] += (f"; {self.skipped[link]} of its events in the bag carry no request or response "
                                "(introspection with METADATA, not CONTENTS): nothing to judge")
            elif i["kind"] == "node" and i["reason"] == "nothing heard":
                links = self.node_links.get(i["node"], [])
                if links and all(lk in missing for lk in links):
                    i["detail"] += "; " + _lacks(self.trace, [t for lk in links for t in missing[lk]])

    def missing(self) -> dict[str, list[str]]:
        """Link -> its call topics the bag does not have (``/``-prefixed); links with all of them absent."""
        out: dict[str, list[str]] = {}
        for topic, (link, role) in self.roles.items():
            if role in ("status", "cancel_goal"):
                continue  # never needed to judge a goal
            if topic not in self.present:
                out.setdefault(link, []).append("/" + topic)
        return {k: v for k, v in out.items() if len(v) == sum(1 for t, (lk, r) in self.roles.items()
                                                              if lk == k and r not in ("status", "cancel_goal"))}

    def tap(self, events: Iterable[Event]) -> Iterator[Event]:
        """``events`` unchanged; the call topics' messages are kept, and given to the
        book as call lines once the bag has been read."""
        for ev in events:
            if ev.topic in self.roles or ev.topic == DECISIONS or _is_call_topic(ev.topic):
                self.items.append(ev)  # every link's: the book's lines name them all, as its log does
            elif is_clock_topic(ev.topic) and self.calls.book is not None and self.calls.book.reads_clock:
                self.clocks.append(ev)  # the run's /clock, for a bag without the book's lines
            self.end = max(self.end, ev.time)
            yield ev
        self.replay()

    # -- the lines ----------------------------------------------------------------------------------
    def replay(self) -> None:
        """Give the kept messages to the book as call lines (module docstring)."""
        if any(ev.topic == DECISIONS for ev in self.items):
            self._replay_decided()
            return
        sides, goals = self._sides(), self._goals()
        lines: list[tuple[float, int, dict[str, Any], Event]] = []
        for ev in self.items:
            if ev.topic not in self.roles:
                continue  # a link of no selected node
            try:
                got = self._line(ev, sides, goals)
            except (KeyError, TypeError, ValueError, IndexError, AttributeError) as exc:
                raise self._error(ev, exc) from None
            if got is not None:
                lines.append((float(got["time"]), ev.index, got, ev))
        if lines:
            for ev in self.clocks:
                value = clock_value_ns(ev.fields)
                if value is not None:  # before a call line of the same time (-1), as the live taps take it
                    clock = {"sec": value // 1_000_000_000, "nanosec": value % 1_000_000_000}
                    lines.append((ev.time, -1, {"kind": "call", "part": "clock", "time": ev.time, "clock": clock}, ev))
        lines.sort(key=lambda x: x[:2])
        for _t, _i, line, ev in lines:  # the book's clock: each line's stamp, in stamp order
            self._feed({"kind": "call", "part": "tick", "time": line["time"]}, ev)
            self._feed(self._as_live(line), ev)
        if lines:  # and the bag's end: what its horizon or deadline passed by then is decided
            self._feed({"kind": "call", "part": "tick", "time": max(self.end, lines[-1][0])}, lines[-1][3])

    def _replay_decided(self) -> None:
        """The live book's lines, in its order, each part's fields from the ROS 2 message it names."""
        bodies: dict[tuple[str, float], list[Event]] = {}
        for ev in self.items:
            if ev.topic != DECISIONS:
                bodies.setdefault((ev.topic, ev.time), []).append(ev)
        for ev in sorted((e for e in self.items if e.topic == DECISIONS), key=lambda e: (e.time, e.index)):
            try:
                line = self._decision(ev)
                ref = line.pop("ref", None)
                if ref is not None:
                    line["fields"] = self._body(bodies, ref, line)
            except (KeyError, TypeError, ValueError, IndexError, AttributeError) as exc:
                raise self._error(ev, exc) from None
            self._feed(line, ev)

    def _body(self, bodies: Mapping[tuple[str, float], list[Event]], ref: list[Any],
              line: Mapping[str, Any]) -> dict[str, Any]:
        """The fields of the part ``ref`` (``[topic, bag time in ns, body]``) names."""
        topic, at, body = str(ref[0]), int(ref[1]), str(ref[2])
        key = list(line.get("key") or [])
        for ev in bodies.get((topic, at / 1e9), []):
            f = ev.fields
            if body == "feedback":
                return dict(f["feedback"])
            if key[:1] == ["ev"] and [_gid(f).hex(), int(f["info"]["sequence_number"])] != key[1:3]:
                continue
            part = f["request"] if body in ("request", "goal") else f["response"]
            if part:
                inner = part[0]
                return dict(inner["goal"] if body == "goal" else inner["result"] if body == "result" else inner)
        raise ValueError(f"the call line of {line.get('where') or line.get('link')} names a message of /{topic} "
                         f"at {at} ns that the bag does not hold")

    def _error(self, ev: Event, exc: Exception) -> TraceError:
        return TraceError(f"{self.trace}: topic /{ev.topic}: error: {ev.where}: not a call message the monitor "
                          f"can read ({type(exc).__name__}: {exc})")

    def _as_live(self, line: dict[str, Any]) -> dict[str, Any]:
        """An answer to no open call as the live book logs it: an orphan (counted); a feedback dropped ({})."""
        book = self.calls.book
        if line["part"] in ("request", "goal", "rejected", "clock") or book is None or tuple(line["key"]) in book.calls:
            return line
        if line["part"] == "feedback":
            return {}
        return {k: v for k, v in line.items() if k not in ("index", "where")} | {"orphan": True}

    def _feed(self, line: dict[str, Any], ev: Event) -> None:
        if not line:
            return
        try:
            self.calls.feed(Event(ev.index, float(line["time"]), CALL_LOG_TOPIC, line, ev.where))
        except TraceError as exc:
            raise TraceError(f"{self.trace}: topic /{ev.topic}: error: {ev.where}: a call line the live monitor "
                             f"could not have written ({str(exc).rsplit('(', 1)[-1].rstrip(')')})") from None

    def _decision(self, ev: Event) -> dict[str, Any]:
        line = json.loads(str(ev.fields["data"]))
        if not isinstance(line, dict) or line.get("kind") != "call":
            raise ValueError("not a call line")
        float(line["time"])
        return line

    def _sides(self) -> dict[str, tuple[int, int]]:
        """Per event topic the (request, response) event types that tell its calls."""
        kinds: dict[str, set[int]] = {}
        for ev in self.items:
            if ev.topic in self.roles and ev.topic.endswith(EVENT_SUFFIX):  # (selected links only)
                kinds.setdefault(ev.topic, set()).add(int(ev.fields["info"]["event_type"]))
        out = {}
        for topic, ks in kinds.items():
            out[topic] = ((REQUEST_RECEIVED, RESPONSE_SENT) if REQUEST_RECEIVED in ks else
                          (REQUEST_SENT, RESPONSE_RECEIVED) if RESPONSE_RECEIVED in ks else
                          (REQUEST_SENT, RESPONSE_SENT))
        return out

    def _goals(self) -> dict[tuple[str, bytes, int], str]:
        """``(event topic, client gid, sequence number)`` -> goal id of every send-goal and get-result request."""
        out = {}
        for ev in self.items:
            role = self.roles.get(ev.topic, ("", ""))[1]
            if role in ("send_goal", "get_result") and ev.fields["request"]:
                out[(ev.topic, _gid(ev.fields), int(ev.fields["info"]["sequence_number"]))] = \
                    _uuid(ev.fields["request"][0]["goal_id"])
        return out

    def _line(self, ev: Event, sides: Mapping[str, tuple[int, int]],
              goals: Mapping[tuple[str, bytes, int], str]) -> dict[str, Any] | None:
        """The call line of one bag message, ``None`` for one the book does not read."""
        link, role = self.roles[ev.topic]
        f = ev.fields
        if role == "feedback":
            return {"kind": "call", "link": link, "part": "feedback", "index": ev.index, "time": ev.time,
                    "key": [_uuid(f["goal_id"])], "where": f"{link} goal {_uuid(f['goal_id'])} feedback",
                    "fields": dict(f["feedback"])}
        if role in ("status", "cancel_goal"):
            return None  # logged by the live book, judged by nothing
        asked, told = sides[ev.topic]
        kind, gid, seq = int(f["info"]["event_type"]), _gid(f), int(f["info"]["sequence_number"])
        if kind not in (asked, told):
            return None
        body = f["request"] if kind == asked else f["response"]
        if not body:
            self.skipped[link] = self.skipped.get(link, 0) + 1
            return None
        time = _stamp(f)
        if role == "service":
            key, label = self._identity(link, gid, seq, (asked, told) != (REQUEST_SENT, RESPONSE_SENT))
            part = "request" if kind == asked else "response"
            line = {"kind": "call", "link": link, "part": part, "time": time, "key": key, "fields": dict(body[0])}
            return {**line, "index": ev.index, "where": f"{label} {part}"}
        if role == "send_goal":
            if kind == asked:
                goal = _uuid(body[0]["goal_id"])
                return {"kind": "call", "link": link, "part": "goal", "index": ev.index, "time": time, "key": [goal],
                        "where": f"{link} goal {goal} goal", "fields": dict(body[0]["goal"])}
            goal = goals.get((ev.topic, gid, seq), "")
            if body[0]["accepted"] or not goal:
                return None
            return {"kind": "call", "link": link, "part": "rejected", "time": time, "key": [goal]}
        if kind == asked:
            return None  # a get-result request: tells which goal its response is about (_goals)
        goal = goals.get((ev.topic, gid, seq), "")
        return {"kind": "call", "link": link, "part": "result", "index": ev.index, "time": time, "key": [goal],
                "where": f"{link} goal {goal} result", "fields": dict(body[0]["result"])}

    @staticmethod
    def _identity(link: str, gid: bytes, seq: int, introspected: bool) -> tuple[list[Any], str]:
        """A service call's key and label as the live book made them (module docstring)."""
        if introspected:
            return ["ev", gid.hex(), seq], f"{link} call {gid.hex()}:{seq}"
        if not any(gid):
            return ["w", "", seq], f"{link} call #{seq}"
        if not any(gid[:8]):
            guid = int.from_bytes(gid[8:], "big")
            return [guid, seq], f"{link} call {guid:016x}:{seq}"
        return ["w", gid.hex(), seq], f"{link} call {gid.hex()}#{seq}"


def bag_connections(path: Path, msg_dirs: list[Path]) -> dict[str, str]:
    """The bag's topics (no leading ``/``) -> their types; raises :class:`TraceError` as the bag reader does."""
    from rclverify.traces.bag import open_bag, typestore  # deferred: start-up (loads rosbags only for a bag)
    from rclverify.traces.bag_open import open_uncounted  # deferred: start-up (loads rosbags only for a bag)
    store = typestore(msg_dirs)
    reader = open_uncounted(path, store) or open_bag(path, store)
    try:
        return {c.topic.lstrip("/"): c.msgtype for c in reader.connections}
    finally:
        try:
            reader.close()
        except Exception:  # noqa: BLE001 - a reader only opened to list its topics
            pass


def _lacks(trace: str, topics: list[str]) -> str:
    return (f"{trace} has no {', '.join(topics)} topic: its calls were not recorded (a bag `ros2 bag record` made "
            "without the service's introspection events, or one rclverify recorded before it wrote calls); "
            "nothing in the bag can tell whether they were answered right")


__all__ = ["BagCalls", "DECISIONS", "EVENT_SUFFIX", "REQUEST_RECEIVED", "REQUEST_SENT", "RESPONSE_RECEIVED",
           "RESPONSE_SENT", "bag_connections", "is_ros2_bag", "link_topics", "topic_type"]
