"""Services and actions heard on the DDS bus, paired by identity and fed to
the :class:`~.dds_calls.CallBook`.

For every link a monitored contract declares (``services(...)``,
``actions(...)``), :class:`CallTaps` asks the bus (:mod:`.dds_bus`) for:

* a service ``/s`` of type ``pkg/T``: ``rq/sRequest`` and ``rr/sReply``
  (``pkg::srv::dds_::T_Request_`` / ``T_Response_``, each with rmw_cyclonedds'
  request header);
* an action ``/a``: ``rq``/``rr`` of ``/a/_action/send_goal`` and
  ``/a/_action/get_result``, and ``rt/a/_action/feedback`` and
  ``rt/a/_action/status``.

and turns each sample, in the engine thread, into a call event: a request
opens its call under its identity (the client's writer handle and the
sequence number), the reply with the same identity answers it; a goal opens
its call under its ``goal_id``, the feedback messages and the get-result
reply carrying that goal id answer it (the get-result request tells which
goal its reply is about), a refused goal (``accepted`` false) closes it
unjudged, status changes are logged.  Stamps are the samples' DDS source
timestamps (s).  An answer whose request has not been taken yet (request
and reply travel on different topics) waits up to :data:`EARLY_S` seconds
for it before it counts as an answer without a call.

Services between rmw_fastrtps nodes carry their identity in RTPS's
related-sample-identity, not in the payload: such calls have no header and
are not decoded (docs/monitors.md says so).
"""
from __future__ import annotations

from typing import Any, Iterable

from ...rcl import ast
from ...rcl.types import CheckedNode
from ...ros.dds import ACTION_INFIX, reply_topic, request_topic, topic_name
from .dds_calls import CallBook
from .dds_types import TypeBook, request_id, to_fields

#: seconds an answer waits for its request (or goal) to be taken
EARLY_S = 2.0
#: action_msgs/msg/GoalStatus values (ROS 2 design "Actions")
GOAL_STATUS = {0: "unknown", 1: "accepted", 2: "executing", 3: "canceling", 4: "succeeded", 5: "canceled",
               6: "aborted"}


def _where(link: ast.Link) -> str:
    return f"{link.loc.file}:{link.loc.line}:{link.loc.col}"


class CallTaps:
    """The taps of every monitored link and the decoding of their samples
    (module docstring).  Raises :class:`~.dds_types.DdsTypeError` (with the
    link's location) for a link type the interface files do not define."""

    def __init__(self, book: CallBook, types: TypeBook, links: Iterable[tuple[CheckedNode, ast.Link]]) -> None:
        from .dds_types import DdsTypeError
        self.book, self.types = book, types
        self.specs: dict[str, tuple[str, Any, str]] = {}  # tap key -> (link name, struct, part)
        self.plan: list[tuple[str, str, Any, str]] = []  # (tap key, dds topic, struct, where)
        seen: set[str] = set()
        for _node, lk in links:
            name = "/" + lk.name.strip("/")
            if name in seen:
                continue
            seen.add(name)
            try:
                if lk.kind == "service":
                    req, rep = types.service(lk.ros_type)
                    self._add(name, "request", request_topic(name), req, lk)
                    self._add(name, "reply", reply_topic(name), rep, lk)
                else:
                    a = types.action(lk.ros_type)
                    base = name + ACTION_INFIX
                    self._add(name, "goal_request", request_topic(base + "send_goal"), a.send_goal[0], lk)
                    self._add(name, "goal_reply", reply_topic(base + "send_goal"), a.send_goal[1], lk)
                    self._add(name, "result_request", request_topic(base + "get_result"), a.get_result[0], lk)
                    self._add(name, "result_reply", reply_topic(base + "get_result"), a.get_result[1], lk)
                    self._add(name, "feedback", topic_name(base + "feedback"), a.feedback, lk)
                    self._add(name, "status", topic_name(base + "status"), a.status, lk)
            except DdsTypeError as exc:
                raise DdsTypeError(f"{_where(lk)}: error: {lk.kind} {name} ({lk.ros_type}): {exc}") from None
        self._goal_of: dict[tuple[int, int], str] = {}  # send-goal/get-result request id -> goal id
        self._status: dict[str, int] = {}
        self._early: dict[tuple[Any, ...], list[tuple[str, dict[str, Any], float, bool, float, str]]] = {}

    def _add(self, name: str, part: str, dds_topic: str, struct: Any, lk: ast.Link) -> None:
        key = f"call:{name}:{part}"
        self.specs[key] = (name, struct, part)
        self.plan.append((key, dds_topic, struct, _where(lk)))

    # -- samples (engine thread) -------------------------------------------------------------
    def handle(self, key: str, raw: bytes, stamp: float, now: float) -> None:
        """One sample of tap ``key`` (serialized, source stamp ``stamp``, received ``now``)."""
        name, struct, part = self.specs[key]
        s = struct.deserialize(raw)
        if part == "request":
            guid, seq = request_id(s)
            self._open(name, (guid, seq), f"{name.strip('/')} call {guid:016x}:{seq}", to_fields(s), stamp)
        elif part == "reply":
            self._answer(request_id(s), "response", to_fields(s), stamp, True, name, now)
        elif part == "goal_request":
            gid = bytes(s.goal_id.uuid).hex()
            self._remember(request_id(s), gid)
            self._open(name, (gid,), f"{name.strip('/')} goal {gid}", to_fields(s.goal), stamp, "goal")
        elif part == "goal_reply":
            gid = self._goal_of.pop(request_id(s), "")
            if gid and not s.accepted:
                self.book.reject((gid,), stamp)
        elif part == "result_request":
            self._remember(request_id(s), bytes(s.goal_id.uuid).hex())
        elif part == "result_reply":
            gid = self._goal_of.pop(request_id(s), "")
            if gid:
                self._answer((gid,), "result", to_fields(s.result), stamp, True, name, now)
                self._note_status(name, gid, int(s.status), stamp)
        elif part == "feedback":
            self._answer((bytes(s.goal_id.uuid).hex(),), "feedback", to_fields(s.feedback), stamp, False, name, now)
        elif part == "status":
            for st in s.status_list:
                self._note_status(name, bytes(st.goal_info.goal_id.uuid).hex(), int(st.status), stamp)

    def _remember(self, rid: tuple[int, int], gid: str) -> None:
        """Which goal the reply to request ``rid`` (send-goal or get-result) is about (bounded)."""
        self._goal_of[rid] = gid
        while len(self._goal_of) > 10_000:
            self._goal_of.pop(next(iter(self._goal_of)))

    def _open(self, name: str, key: tuple[Any, ...], label: str, fields: dict[str, Any], stamp: float,
              part: str = "request") -> None:
        self.book.open(name, key, label, fields, stamp, part)
        for apart, afields, astamp, final, _t, aname in self._early.pop(key, ()):
            self.book.answer(key, apart, afields, astamp, final, aname)

    def _answer(self, key: tuple[Any, ...], part: str, fields: dict[str, Any], stamp: float, final: bool,
                name: str, now: float) -> None:
        if key in self.book.calls:
            self.book.answer(key, part, fields, stamp, final, name)
        else:
            self._early.setdefault(key, []).append((part, fields, stamp, final, now, name))

    def _note_status(self, name: str, gid: str, status: int, stamp: float) -> None:
        if self._status.get(gid) == status:
            return
        self._status[gid] = status
        while len(self._status) > 10_000:
            self._status.pop(next(iter(self._status)))
        self.book.note({"link": name.strip("/"), "part": "status", "time": stamp, "key": [gid],
                        "status": GOAL_STATUS.get(status, str(status))})

    def tick(self, now: float) -> None:
        """Answers that waited :data:`EARLY_S` s for their call count as answers without one."""
        for key in [k for k, xs in self._early.items() if now - xs[0][4] > EARLY_S]:
            for part, fields, stamp, final, _t, name in self._early.pop(key):
                self.book.answer(key, part, fields, stamp, final, name)


__all__ = ["CallTaps", "EARLY_S", "GOAL_STATUS"]
