"""The Controller node's logic: the function its ROS callback calls, and the
implementation its property tests check (docs/property-tests.md: one keyword
argument per RCL input, a mapping of output name to value returned).
Plain floats, as the node computes them."""
from __future__ import annotations


def controller(obstacle: float, speed_cmd: float, max_speed: float) -> dict[str, object]:
    """Stop for an obstacle closer than 0.5 (read as metres); otherwise the
    Planner's command, capped at the base's limit."""
    cmd = 0.0 if obstacle < 0.5 else min(speed_cmd, max_speed)
    return {"cmd_vel": max(0.0, cmd), "query": True}
