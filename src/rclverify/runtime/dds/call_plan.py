"""Which topics the live monitor taps for each service and action a
monitored contract declares, and the struct each is read with
(:class:`CallPlan`; :mod:`.services` decodes and pairs what they carry).

For a service ``/s`` of type ``pkg/T``: ``rq/sRequest`` and ``rr/sReply``
(``pkg::srv::dds_::T_Request_`` / ``T_Response_``, with rmw_cyclonedds'
request header when ``framed``) and its introspection events
``rt/s/_service_event`` (:mod:`.introspection`).  For an action ``/a``: the
request and reply topics of ``/a/_action/send_goal``, ``get_result`` and
``cancel_goal``, ``rt/a/_action/feedback`` and ``rt/a/_action/status``;
with ``events`` (the rclpy source) also the introspection events of the
three services (``rt/a/_action/send_goal/_service_event`` ...).  Topic
names follow ROS 2's DDS conventions (:mod:`rclverify.ros.live.dds`).
"""
from __future__ import annotations

from typing import Any, Iterable

from rclverify.lang import ast
from rclverify.lang.types import CheckedNode
from rclverify.ros.live.dds import ACTION_INFIX, reply_topic, request_topic, topic_name
from rclverify.runtime.dds.introspection import EVENT_SUFFIX, event_struct
from rclverify.runtime.dds.types import DdsTypeError, TypeBook


def cancel_types(t: TypeBook) -> tuple[type, type, type, type]:
    """The plain and the framed request and reply of ``action_msgs/srv/CancelGoal``
    (ROS 2 design "Actions": the request a ``GoalInfo``, goal id and stamp;
    the reply a return code and the ``GoalInfo`` of each goal now canceling),
    defined here when the interface files do not (rosbags' store has no
    services)."""
    info = (2, "action_msgs/msg/GoalInfo")
    req, rep = "action_msgs/srv/CancelGoal_Request", "action_msgs/srv/CancelGoal_Response"
    t._synth(req, [("goal_info", info)])
    t._synth(rep, [("return_code", (1, ("int8", 0))), ("goals_canceling", (4, (info, 0)))])
    return t.struct(req), t.struct(rep), t.struct(req, header=True), t.struct(rep, header=True)


def _where(link: ast.Link) -> str:
    return f"{link.loc.file}:{link.loc.line}:{link.loc.col}"


class CallPlan:
    """The call taps' plan (module docstring): ``specs`` (tap key
    ``call:/s:part`` -> link name, the struct read, the header struct or
    ``None``, part), ``plan`` (tap key, DDS topic, struct, ``file:line:col``),
    ``pair_taps`` (pairer name -> its request and reply tap keys), ``kinds``
    and ``where`` per link name.  Raises :class:`~.types.DdsTypeError` (with
    the link's location) for a link type the interface files do not define."""

    def __init__(self, types: TypeBook, links: Iterable[tuple[CheckedNode, ast.Link]], framed: bool,
                 events: bool) -> None:
        self.types, self.framed, self.events = types, framed, events
        self.kinds: dict[str, str] = {}
        self.where: dict[str, str] = {}
        self.specs: dict[str, tuple[str, Any, Any, str]] = {}
        self.plan: list[tuple[str, str, Any, str]] = []
        self.pair_taps: dict[str, tuple[str, str]] = {}
        seen: set[str] = set()
        for _node, lk in links:
            name = "/" + lk.name.strip("/")
            if name in seen:
                continue
            seen.add(name)
            try:
                self._plan(name, lk)
            except DdsTypeError as exc:
                raise DdsTypeError(f"{_where(lk)}: error: {lk.kind} {name} ({lk.ros_type}): {exc}") from None

    def _plan(self, name: str, lk: ast.Link) -> None:
        t = self.types
        self.kinds[name], self.where[name] = lk.kind, _where(lk)
        if lk.kind == "service":
            req, rep = t.service(lk.ros_type)
            pkg, _, rest = lk.ros_type.replace("/srv/", "/").partition("/")
            self._add(name, "request", request_topic(name), t.struct(f"{pkg}/srv/{rest}_Request"), req, lk)
            self._add(name, "reply", reply_topic(name), t.struct(f"{pkg}/srv/{rest}_Response"), rep, lk)
            self._add(name, "event", topic_name(name + EVENT_SUFFIX), event_struct(t, lk.ros_type), None, lk)
            self.pair_taps[name] = (f"call:{name}:request", f"call:{name}:reply")
            return
        a = t.action(lk.ros_type)
        pkg, _, rest = lk.ros_type.replace("/action/", "/").partition("/")
        plain = f"{pkg}/action/{rest}"
        base = name + ACTION_INFIX
        for svc, part, (hreq, hrep) in (("send_goal", "goal", a.send_goal), ("get_result", "result", a.get_result)):
            kind = "SendGoal" if svc == "send_goal" else "GetResult"
            self._add(name, f"{part}_request", request_topic(base + svc), t.struct(f"{plain}_{kind}_Request"), hreq,
                      lk)
            self._add(name, f"{part}_reply", reply_topic(base + svc), t.struct(f"{plain}_{kind}_Response"), hrep, lk)
        for svc, part in (("send_goal", "goal"), ("get_result", "result")):
            self.pair_taps[f"{name}/_action/{svc}"] = (f"call:{name}:{part}_request", f"call:{name}:{part}_reply")
        self._add(name, "feedback", topic_name(base + "feedback"), a.feedback, None, lk)
        self._add(name, "status", topic_name(base + "status"), a.status, None, lk)
        cq, cr, hq, hr = cancel_types(t)
        self._add(name, "cancel_request", request_topic(base + "cancel_goal"), cq, hq, lk)
        self._add(name, "cancel_reply", reply_topic(base + "cancel_goal"), cr, hr, lk)
        if self.events:  # the introspection events of the action's own services (module docstring)
            for svc, part, srv in (("send_goal", "goal_event", f"{plain}_SendGoal"),
                                   ("get_result", "result_event", f"{plain}_GetResult"),
                                   ("cancel_goal", "cancel_event", "action_msgs/srv/CancelGoal")):
                self._add(name, part, topic_name(base + svc + EVENT_SUFFIX), event_struct(t, srv), None, lk)

    def _add(self, name: str, part: str, dds_topic: str, plain: Any, header: Any, lk: ast.Link) -> None:
        key = f"call:{name}:{part}"
        self.specs[key] = (name, header if self.framed and header is not None else plain, header, part)
        self.plan.append((key, dds_topic, header if self.framed and header is not None else plain, _where(lk)))


__all__ = ["CallPlan", "cancel_types"]
