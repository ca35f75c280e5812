"""The MissionPlanner node's logic: the function its ROS callback calls, and the
implementation its property tests check (docs/property-tests.md: one keyword
argument per RCL input, a mapping of output name to value returned).
Plain floats, as the node computes them."""
from __future__ import annotations

MAP_ENTRIES = 501       # the map's table of stops: 0 (the depot) to 500
DEPOT = 0


def mission_planner(order_id: int, remaining: float, delivered_id: int) -> dict[str, int]:
    """The goal is the order's stop when the map has it, else the depot."""
    return {"dest_id": order_id if order_id <= MAP_ENTRIES else DEPOT}
