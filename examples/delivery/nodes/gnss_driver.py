"""The GnssDriver node's logic: the function its ROS callback calls, and the
implementation its property tests check (docs/property-tests.md: one keyword
argument per RCL input, a mapping of output name to value returned).
Plain floats, as the node computes them."""
from __future__ import annotations


def gnss_driver(cog: float) -> dict[str, float]:
    """The heading is the receiver's course over ground."""
    return {"heading": cog}
