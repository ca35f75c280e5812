"""The JSON records the semantics layer writes, as types.

:class:`ToleranceJSON` is a recorded run's tolerance
(:meth:`rclverify.semantics.floatsem.Tolerance.to_json`), as a monitoring
summary and a generated node's manifest carry it.
"""
# No ``from __future__ import annotations``: Python 3.11 reads ``NotRequired`` only from evaluated
# annotations (with string annotations every key would count as required).
from typing import TypedDict


class ToleranceJSON(TypedDict):
    """``{"abs": 1e-09, "rel": 1e-09, "ulps": 4}``: the bounds of a tolerance
    (``abs`` in the variable's unit, ``rel`` a fraction of the larger
    magnitude, ``ulps`` units in the last place; 0 when not set)."""
    abs: float
    rel: float
    ulps: int


__all__ = ["ToleranceJSON"]
