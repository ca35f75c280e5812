"""The speed governor's logic as a plain Python function, shared by the
property tests (``property_tests`` backend: one keyword argument per RCL
input, a mapping of output name to value returned; docs/property-tests.md)
and the fleet simulation of ``simulate_runs.py``."""
from __future__ import annotations

#: The fleet's speed limit (m/s).
LIMIT = 1.5


def governor(requested: float) -> dict[str, float]:
    """The commanded speed: the request, capped at the limit (never negative)."""
    return {"cmd": min(max(0.0, float(requested)), LIMIT)}
