"""The MissionManager node's logic: the function its ROS callback calls, and the
implementation its property tests check (docs/property-tests.md: one keyword
argument per RCL input, a mapping of output name to value returned).
Plain floats, as the node computes them."""
from __future__ import annotations


def mission_manager(order_x: float, remaining: float, reached_x: float, battery_low: bool) -> dict[str, object]:
    """The next goal is the order's shelf; a low battery asks for the dock."""
    return {"goal_x": order_x, "dock": battery_low}
