"""The LidarDriver node's logic: the function its ROS callback calls, and the
implementation its property tests check (docs/property-tests.md: one keyword
argument per RCL input, a mapping of output name to value returned).
Plain floats, as the node computes them."""
from __future__ import annotations


def lidar_driver(range: float) -> dict[str, float]:
    """The range to the nearest obstacle, as the vendor SDK reports it (mm)."""
    return {"obstacle": range * 1000.0}
