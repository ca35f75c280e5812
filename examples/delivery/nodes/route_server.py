"""The RouteServer node's logic: the function its ROS callback calls, and the
implementation its property tests check (docs/property-tests.md: one keyword
argument per RCL input, a mapping of output name to value returned).
Plain floats, as the node computes them."""
from __future__ import annotations

MAX_WAYPOINTS = 64      # the route planner's limit


def route_server(route_dest: int) -> dict[str, int]:
    """One waypoint every ten stops along the ring road, as many as the planner makes."""
    return {"n_waypoints": min(1 + route_dest // 8, MAX_WAYPOINTS)}
