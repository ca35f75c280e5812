"""An action's calls as the call taps hear them (:mod:`.services`): its
goals, feedback, results, refusals, status changes and cancels, from the
request and reply topics of its three services, its feedback and status
topics, or (events only) its services' introspection events.

A goal opens its call under its ``goal_id``; the feedback messages and the
get-result reply carrying that goal id answer it (the get-result request
tells which goal its reply is about: by the request header's identity, or
by the order, :class:`~.order.OrderPairer`); a refused goal (``accepted``
false) closes it unjudged; status changes, cancel requests and the goals a
cancel reply names are noted in the call book.  Mixed into
:class:`~.services.CallTaps`, which provides the attributes annotated on
the class.
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any, Mapping

from rclverify.backends.monitors.dds_calls import CallBook
from rclverify.runtime.dds.introspection import SIDES, event_key
from rclverify.runtime.dds.order import OrderPairer, Pending
from rclverify.runtime.dds.types import request_id, to_fields

#: action_msgs/msg/GoalStatus values (ROS 2 design "Actions")
GOAL_STATUS = {0: "unknown", 1: "accepted", 2: "executing", 3: "canceling", 4: "succeeded", 5: "canceled",
               6: "aborted"}


class ActionTaps:
    """The samples of an action's parts (module docstring)."""

    book: CallBook
    counts: dict[str, int]
    _goal_of: dict[tuple[Any, ...], str]  # send-goal/get-result request id (or event key) -> goal id
    _status: dict[str, int]
    _pairers: dict[str, OrderPairer]

    if TYPE_CHECKING:  # provided by the classes that mix this one in
        def _level(self, name: str, writer: bytes | None, s: Any) -> None:
            ...

        def _side(self, name: str, stamp: float, part: str = "event", writer: bytes | None = None) -> str | None:
            ...

        def _pairer(self, name: str) -> OrderPairer:
            ...

        def _open(self, name: str, key: tuple[Any, ...], label: str, fields: Mapping[str, object], stamp: float,
                  part: str = "request", count: bool = True) -> None:
            ...

        def _answer(self, key: tuple[Any, ...], part: str, fields: Mapping[str, object], stamp: float,
                    final: bool, name: str, now: float) -> None:
            ...

    def _action_event(self, name: str, part: str, s: Any, stamp: float, now: float,
                      writer: bytes | None = None) -> None:
        """An introspection event of one of action ``name``'s own services (module docstring, events only)."""
        self._level(name, writer, s)
        side = self._side(name, stamp, part, writer)
        if side is None:
            return
        asked, told = SIDES[side]
        kind, key = int(s.info.event_type), ("ev", *event_key(s))
        body = s.request if kind == asked else s.response if kind == told else None
        if body is None:
            return
        if not body:
            self.counts["no_contents"] += 1
            return  # introspection without CONTENTS: nothing to judge (docs/ros2.md)
        r, link = body[0], name.strip("/")
        if part == "cancel_event":
            self.book.note({"link": link, "part": "cancel", "time": stamp,
                            "key": [bytes(r.goal_info.goal_id.uuid).hex()]} if kind == asked else
                           {"link": link, "part": "canceling", "time": stamp, "return_code": int(r.return_code),
                            "key": [bytes(g.goal_id.uuid).hex() for g in r.goals_canceling]})
        elif kind == asked:
            gid = self._goal_of[key] = bytes(r.goal_id.uuid).hex()
            while len(self._goal_of) > 10_000:
                self._goal_of.pop(next(iter(self._goal_of)))
            if part == "goal_event":
                self._open(name, (gid,), f"{link} goal {gid}", to_fields(r.goal), stamp, "goal")
        else:
            gid = self._goal_of.pop(key, "")
            if not gid:
                self.counts["unknown_writer"] += 1  # its request's event was not heard: which goal, unknown
            elif part == "goal_event" and not r.accepted:
                self.book.reject((gid,), stamp)
            elif part == "result_event":
                self._answer((gid,), "result", to_fields(r.result), stamp, True, name, now)
                self._note_status(name, gid, int(r.status), stamp)

    def _action(self, name: str, part: str, s: Any, stamp: float, now: float, framed: bool,
                writer: bytes | None) -> None:
        if part == "goal_request":
            gid = bytes(s.goal_id.uuid).hex()
            self._ask(name, "send_goal", s, gid, stamp, framed, writer)
            self._open(name, (gid,), f"{name.strip('/')} goal {gid}", to_fields(s.goal), stamp, "goal")
        elif part == "result_request":
            self._ask(name, "get_result", s, bytes(s.goal_id.uuid).hex(), stamp, framed, writer)
        elif part == "goal_reply":
            self._goal_reply(name, s, stamp, framed, writer)
        elif part == "result_reply":
            gid, undecided, why = self._told(name, "get_result", s, stamp, framed, writer)
            for g in undecided:
                self.book.unpaired((g,), stamp, f"its result cannot be told apart: {why}", "result")
            if gid:
                self._answer((gid,), "result", to_fields(s.result), stamp, True, name, now)
                self._note_status(name, gid, int(s.status), stamp)
        elif part == "feedback":
            self._answer((bytes(s.goal_id.uuid).hex(),), "feedback", to_fields(s.feedback), stamp, False, name, now)
        elif part == "status":
            for st in s.status_list:
                self._note_status(name, bytes(st.goal_info.goal_id.uuid).hex(), int(st.status), stamp)
        elif part == "cancel_request":  # a zero goal id (and stamp) asks to cancel every goal (before it)
            self.book.note({"link": name.strip("/"), "part": "cancel", "time": stamp,
                            "key": [bytes(s.goal_info.goal_id.uuid).hex()]})
        elif part == "cancel_reply":  # the goals the server accepted to cancel: their ids, no pairing needed
            self.book.note({"link": name.strip("/"), "part": "canceling", "time": stamp, "return_code":
                            int(s.return_code), "key": [bytes(g.goal_id.uuid).hex() for g in s.goals_canceling]})

    def _ask(self, name: str, svc: str, s: Any, gid: str, stamp: float, framed: bool,
             writer: bytes | None = None) -> None:
        """A send-goal or get-result request about goal ``gid``: remember which goal its reply is about."""
        if framed:
            self._goal_of[request_id(s)] = gid
            while len(self._goal_of) > 10_000:
                self._goal_of.pop(next(iter(self._goal_of)))
        else:
            self._pairer(f"{name}/_action/{svc}").request(Pending((gid,), stamp, f"goal {gid}", writer))

    def _told(self, name: str, svc: str, s: Any, stamp: float, framed: bool,
              writer: bytes | None) -> tuple[str, list[str], str]:
        """The goal a send-goal or get-result reply is about (``""``: unknown), the
        goals it leaves undecided and why."""
        if framed:
            return self._goal_of.pop(request_id(s), ""), [], ""
        pairer = self._pairer(f"{name}/_action/{svc}")
        out = pairer.reply(stamp, writer)
        return (str(out.answers.key[0]) if out.answers else "", [str(p.key[0]) for p in out.undecided],
                out.reason)

    def _goal_reply(self, name: str, s: Any, stamp: float, framed: bool, writer: bytes | None) -> None:
        pool = [str(p.key[0]) for p in self._pairers[f"{name}/_action/send_goal"].pool] \
            if f"{name}/_action/send_goal" in self._pairers else []
        gid, undecided, why = self._told(name, "send_goal", s, stamp, framed, writer)
        if s.accepted:
            return
        if gid:
            self.book.reject((gid,), stamp)
            return
        for g in dict.fromkeys(undecided + pool):  # one of them was refused: none can be judged
            self.book.unpaired((g,), stamp, f"a goal was refused and which one cannot be told: "
                               f"{why or 'its request is one of several unanswered'}", "result")

    def _note_status(self, name: str, gid: str, status: int, stamp: float) -> None:
        if self._status.get(gid) == status:
            return
        self._status[gid] = status
        while len(self._status) > 10_000:
            self._status.pop(next(iter(self._status)))
        self.book.note({"link": name.strip("/"), "part": "status", "time": stamp, "key": [gid],
                        "status": GOAL_STATUS.get(status, str(status))})
