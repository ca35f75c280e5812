"""The Navigator node's logic: the function its ROS callback calls, and the
implementation its property tests check (docs/property-tests.md: one keyword
argument per RCL input, a mapping of output name to value returned).
Plain floats, as the node computes them."""
from __future__ import annotations

CRUISE = 0.8            # m/s: the speed along a route
CRAWL = 0.3             # m/s: the speed near an obstacle
STOP_SPACING = 2.0      # m: the distance between two stops of the map


def navigator(dest_id: int, yaw: float, clearance: float, n_waypoints: int) -> dict[str, float]:
    """Cruise along the route, crawl closer than 1 m to an obstacle; the route is
    asked for the goal's stop; the feedback is the distance to it."""
    speed = CRAWL if clearance < 1.0 else CRUISE
    return {"cmd_vel": speed, "route_dest": dest_id, "remaining": STOP_SPACING * n_waypoints,
            "delivered_id": dest_id}
