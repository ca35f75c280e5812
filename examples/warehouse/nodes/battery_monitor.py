"""The BatteryMonitor node's logic: the function its ROS callback calls, and the
implementation its property tests check (docs/property-tests.md: one keyword
argument per RCL input, a mapping of output name to value returned).
Plain floats, as the node computes them."""
from __future__ import annotations

LOW_CHARGE = 20.0       # %: the battery is low below this charge


def battery_monitor(charge: float) -> dict[str, bool]:
    """Low battery below LOW_CHARGE per cent."""
    return {"battery_low": charge < LOW_CHARGE}
