"""The Planner node's logic: the function its ROS callback calls, and the
implementation its property tests check (docs/property-tests.md: one keyword
argument per RCL input, a mapping of output name to value returned).
Plain floats, as the node computes them."""
from __future__ import annotations

WAREHOUSE_LIMIT = 1.5   # m/s: the speed limit of the warehouse


def planner(goal_x: float, pose_x: float) -> dict[str, float]:
    """A proportional approach to the goal, capped at the warehouse limit;
    feedback is the distance still to go, the result the goal."""
    remaining = abs(goal_x - pose_x)
    speed = 0.0 if pose_x == goal_x else min(WAREHOUSE_LIMIT, 0.5 * remaining)
    return {"speed_cmd": speed, "remaining": remaining, "reached_x": goal_x}


#: The outputs the Planner node holds before its first answer (the property tests judge `initially` on
#: them, docs/property-tests.md): the node keeps the position reached, 0 m until a goal is reached
#: (`ros2_nodes.py` starts its state from this mapping).  It has no speed command nor distance to go
#: before a goal and a position, and publishes nothing until then.
planner.initial = {"reached_x": 0.0}  # type: ignore[attr-defined]
