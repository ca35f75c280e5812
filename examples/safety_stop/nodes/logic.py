"""The safety-stop example's node logic as plain Python functions, shared by
the property tests (``property_tests`` backend: one keyword argument per RCL
input, a mapping of output name to value returned; docs/property-tests.md)
and the ROS 1 nodes of ``nodes/ros1_nodes.py``."""
from __future__ import annotations


def base(stop_req: bool) -> dict[str, bool]:
    """The estop server: the response says the robot is stopped when asked."""
    return {"stopped": bool(stop_req)}


def mover(target: float) -> dict[str, float | bool]:
    """The move action server's step: progress is the distance covered so far
    (never negative); arrived once the whole target distance is covered."""
    progress = max(0.0, float(target)) * 0.5
    return {"progress": progress, "arrived": False}
