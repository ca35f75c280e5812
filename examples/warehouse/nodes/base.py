"""The Base node's logic: the function its ROS callback calls, and the
implementation its property tests check (docs/property-tests.md: one keyword
argument per RCL input, a mapping of output name to value returned).
Plain floats, as the node computes them."""
from __future__ import annotations

MOTOR_LIMIT = 2.0       # m/s: what the motors can do


def base(cmd_vel: float, query: bool) -> dict[str, float]:
    """The wheels follow the command; the limit answered is the motors'."""
    return {"wheel_speed": cmd_vel, "max_speed": MOTOR_LIMIT}
