"""Endpoints that Python library helpers create for the node (docs/ros.md,
"Reading real code"), by the helper's import path (from each library's
documented API):

| helper | endpoints |
| --- | --- |
| ``tf.TransformBroadcaster``, ``tf2_ros.TransformBroadcaster`` (also rclpy's, given the node) | publishes ``/tf`` (``tf2_msgs/msg/TFMessage``) |
| ``tf2_ros.StaticTransformBroadcaster`` | publishes ``/tf_static`` |
| ``tf.TransformListener``, ``tf2_ros.TransformListener`` | subscribes ``/tf`` and ``/tf_static`` |
| ``message_filters.Subscriber(name, T)`` (ROS 1) / ``(node, T, name)`` (ROS 2) | subscribes ``name`` |
| ``rospy.wait_for_message(name, T)`` / rclpy ``wait_for_message(T, node, name)`` | subscribes ``name`` |
| ``InteractiveMarkerServer(ns)`` (ROS 1) / ``(node, ns)`` (ROS 2) | as the C++ server (:mod:`cpp_helpers`) |
| rclpy ``ParameterEventHandler(node)`` | subscribes ``/parameter_events`` |
| ``diagnostic_updater.Updater()`` (ROS 1) / ``Updater(node)`` (ROS 2) | publishes ``/diagnostics`` |
| ``dynamic_reconfigure.server.Server(Config, cb[, namespace])`` | serves ``set_parameters``, publishes ``parameter_descriptions``, ``parameter_updates`` in ``~`` (a relative ``namespace`` is under ``~``) |
| ``dynamic_reconfigure.client.Client(name, ...)`` | calls ``name/set_parameters``, subscribes ``name/parameter_descriptions``, ``name/parameter_updates`` |

A spec is ``(role, name value or the argument holding it, type argument,
handle)``; :mod:`sources_py` reads the arguments.
"""
from __future__ import annotations

from typing import Any

from rclverify.ros.extract import symbols
from rclverify.ros.extract.cpp_helpers import DIAGNOSTICS, EVENTS, RECONF, TF, VIS
from rclverify.ros.extract.pyrecords import PyCall, PyVal

_BROADCASTERS = {"TransformBroadcaster": "/tf", "StaticTransformBroadcaster": "/tf_static"}


def _arg(c: PyCall, i: int, kw: str) -> PyVal | None:
    return c.kwargs.get(kw) or (c.args[i] if len(c.args) > i else None)


def helper(origin: str, c: PyCall, ros2: bool) -> list[tuple[str, Any, Any]] | None:
    """``[(role, name, type)]`` for call ``c`` of ``origin`` (its import path); ``name``
    and ``type`` are a :class:`PyVal` argument, a :mod:`symbols` value or a
    type string; ``None`` when ``origin`` is no helper."""
    parts = origin.split(".")
    last, top = parts[-1], parts[0]
    if top in ("tf", "tf2_ros") and last in _BROADCASTERS:
        return [("pub", symbols.lit(_BROADCASTERS[last]), TF)]
    if top in ("tf", "tf2_ros") and last == "TransformListener":
        return [("sub", symbols.lit("/tf"), TF), ("sub", symbols.lit("/tf_static"), TF)]
    if top == "message_filters" and last == "Subscriber":
        if len(c.args) >= 3 or "topic" in c.kwargs or "msg_type" in c.kwargs:
            return [("sub", _arg(c, 2, "topic"), _arg(c, 1, "msg_type"))]
        return [("sub", _arg(c, 0, "name"), _arg(c, 1, "data_class"))]
    if origin in ("rospy.wait_for_message", "rospy.client.wait_for_message"):
        return [("sub", _arg(c, 0, "topic"), _arg(c, 1, "topic_type"))]
    if top == "rclpy" and last == "wait_for_message":
        return [("sub", _arg(c, 2, "topic"), _arg(c, 0, "msg_type"))]
    if top == "interactive_markers" and last == "InteractiveMarkerServer":
        ns = _arg(c, 1, "namespace") if ros2 else _arg(c, 0, "topic_ns")
        out = [("pub", ("under", ns, "update"), VIS + "InteractiveMarkerUpdate"),
               ("sub", ("under", ns, "feedback"), VIS + "InteractiveMarkerFeedback")]
        out.append(("service_servers", ("under", ns, "get_interactive_markers"),
                    "visualization_msgs/srv/GetInteractiveMarkers") if ros2 else
                   ("pub", ("under", ns, "update_full"), VIS + "InteractiveMarkerInit"))
        return out
    if top == "rclpy" and last == "ParameterEventHandler":
        return [(EVENTS[0], EVENTS[1], EVENTS[2])]
    if top == "diagnostic_updater" and last == "Updater":
        return [(DIAGNOSTICS[0], DIAGNOSTICS[1], DIAGNOSTICS[2])]
    if top == "dynamic_reconfigure" and last in ("Server", "Client"):
        return _reconfigure(last, c)
    return None


def _reconfigure(last: str, c: PyCall) -> list[tuple[str, Any, Any]]:
    """dynamic_reconfigure's Python server (its namespace: ``~`` by default, a
    relative one under ``~``) or client (the server's name)."""
    parts = (("set_parameters", RECONF + "srv/Reconfigure"), ("parameter_descriptions", RECONF + "msg/ConfigDescription"),
             ("parameter_updates", RECONF + "msg/Config"))
    if last == "Client":
        name = _arg(c, 0, "name")
        return [(role, ("under", name, n), t) for role, (n, t) in zip(("service_clients", "sub", "sub"), parts)]
    ns = _arg(c, 2, "namespace")
    if ns is not None and ns.kind != "str":  # relative or not is known only at run time: not guessed
        return [(role, ("under", None, n), t) for role, (n, t) in zip(("service_servers", "pub", "pub"), parts)]
    text = ns.text if ns is not None else ""
    prefix = "~" if not text else (text if text[0] in "/~" else "~" + text).rstrip("/") + "/"
    return [(role, symbols.lit((prefix + n).replace("~/", "~")), t)
            for role, (n, t) in zip(("service_servers", "pub", "pub"), parts)]
