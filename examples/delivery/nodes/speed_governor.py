"""The SpeedGovernor node's logic: the function its ROS callback calls, and the
implementation its property tests check (docs/property-tests.md: one keyword
argument per RCL input, a mapping of output name to value returned).
Plain floats, as the node computes them."""
from __future__ import annotations

SLOW_ZONE = 2.0         # m: within this clearance, at most SLOW_SPEED
SLOW_SPEED = 0.5        # m/s
STOP_ZONE = 0.5         # m: closer than this, a stop


def speed_governor(clearance: float, cmd_vel: float) -> dict[str, float]:
    """The Navigator's command, slowed near obstacles."""
    if clearance < STOP_ZONE:
        return {"safe_cmd": 0.0}
    if clearance < SLOW_ZONE:
        return {"safe_cmd": min(cmd_vel, SLOW_SPEED)}
    return {"safe_cmd": max(0.0, cmd_vel)}
