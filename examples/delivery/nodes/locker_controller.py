"""The LockerController node's logic: the function its ROS callback calls, and the
implementation its property tests check (docs/property-tests.md: one keyword
argument per RCL input, a mapping of output name to value returned).
Plain floats, as the node computes them."""
from __future__ import annotations

COMPARTMENTS = 4


def locker_controller(dest_id: int) -> dict[str, int]:
    """The parcels are loaded by stop, round robin over the compartments."""
    return {"compartment": dest_id % COMPARTMENTS}
