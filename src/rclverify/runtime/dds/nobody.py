"""The line a live ROS 2 run ends with when it discovered nobody (docs/ros2.md, "A run that
discovers nobody").

A run whose every tap (contract topic, service and action topic) matched no
publisher and took no sample heard nothing, and the items it was asked to
judge are each ``nothing heard`` (:mod:`rclverify.backends.monitors.judged`).
Such a run is almost always one that could not reach the robot at all: another
``ROS_DOMAIN_ID``, a discovery range (``ROS_AUTOMATIC_DISCOVERY_RANGE``,
``ROS_STATIC_PEERS``) that keeps the robot out of reach, or a DDS configuration
(``CYCLONEDDS_URI``) whose interfaces are not the robot's network (only ``lo``,
no peer).  :func:`nobody_line` says so in one line, with the run's middleware
and, for the DDS source, how many other participants discovery found at all;
the run exits as any run that heard nothing does (0, 1 under ``--strict``).
"""
from __future__ import annotations

from typing import Mapping

from rclverify.runtime.shapes import TapJson


def nobody_line(qos: Mapping[str, TapJson], seconds: float, middleware: str,
                participants: int | None) -> str | None:
    """The warning line of a run that discovered no publisher of any tap, or ``None``.

    ``qos``: tap key -> what its tap heard (``publishers_heard``, ``samples``; the record's ``qos``);
    ``seconds``: how long the run listened; ``middleware``: where it listened (``DDS domain 7
    (cyclonedds 0.10.5)``); ``participants``: the other DDS participants discovery found (``None``
    where the source cannot tell: the rclpy source)."""
    if not qos or any(t["publishers_heard"] or t["samples"] for t in qos.values()):
        return None
    others = "" if participants is None else (
        "; no other DDS participant was discovered at all" if participants == 0 else
        f"; {participants} other DDS participant(s) were, none publishing on them")
    config = ("the DDS configuration's interfaces (CYCLONEDDS_URI)" if participants is not None else
              "the middleware's own configuration (the network interfaces its DDS may use)")
    return (f"rclverify monitor --live: warning: no publisher was discovered on any of the {len(qos)} watched "
            f"topic(s) during the run ({seconds:.1f} s on {middleware}){others}; nothing was heard: check that "
            "the robot runs in this ROS_DOMAIN_ID, that the discovery range (ROS_AUTOMATIC_DISCOVERY_RANGE, "
            f"ROS_STATIC_PEERS) reaches it, and that {config} reach the robot's network")


__all__ = ["nobody_line"]
