"""The WheelController node's logic: the function its ROS callback calls, and the
implementation its property tests check (docs/property-tests.md: one keyword
argument per RCL input, a mapping of output name to value returned).
Plain floats, as the node computes them."""
from __future__ import annotations


def wheel_controller(safe_cmd: float) -> dict[str, float]:
    """The wheels' command is the governed one."""
    return {"wheel_cmd": max(0.0, safe_cmd)}


class WheelControllerNode:
    """The node's callbacks: a governed command is passed on at once, and the
    watchdog timer (every 100 ms) re-sends the wheels' command to feed the
    motor driver's watchdog."""

    def __init__(self) -> None:
        self.safe_cmd: float | None = None
        self.wheel_cmd: float | None = None

    def on_safe_cmd(self, safe_cmd: float) -> float:
        self.safe_cmd = safe_cmd
        return wheel_controller(safe_cmd)["wheel_cmd"]

    def on_watchdog(self) -> float | None:
        """The command to re-send, or None before the first one."""
        if self.safe_cmd is None:
            return None
        if self.wheel_cmd is None:
            self.wheel_cmd = wheel_controller(self.safe_cmd)["wheel_cmd"]
        return self.wheel_cmd
