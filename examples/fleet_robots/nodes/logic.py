"""The fleet's node logic: the functions the ROS callbacks of nodes/robots.py call, and the
implementations the property tests check (docs/property-tests.md: one keyword argument per RCL
input, a mapping of output name to value returned).  Plain floats, as the nodes compute them."""
from __future__ import annotations

FLEET_LIMIT = 1.0   # m/s: the fleet's speed limit
LOW = 0.2           # the charge (a fraction) below which a robot stops


def speed_limit() -> dict[str, float]:
    """The fleet's speed limit."""
    return {"limit": FLEET_LIMIT}


class Planner:
    """A planner's speed, one a step: a ramp from 0 to 2 m/s and back, never negative."""

    def __init__(self) -> None:
        self.k = 0

    def step(self) -> dict[str, float]:
        self.k += 1
        return {"cmd_raw": abs(float(self.k % 40) - 20.0) / 10.0}


class Battery:
    """A battery's charge, one reading a step: draining from 1 by 1 % a step, recharged at 10 %."""

    def __init__(self) -> None:
        self.k = 0

    def step(self) -> dict[str, float]:
        self.k += 1
        return {"level": 1.0 - (self.k % 91) / 100.0}


def guard(cmd_raw: float, level: float, limit: float) -> dict[str, float]:
    """The planner's speed capped at the fleet's limit; a stop below LOW charge."""
    return {"cmd_vel": 0.0 if level < LOW else max(0.0, min(cmd_raw, limit))}
