"""The Radiation Sensor node as a Python function, tested by the
``property_tests`` backend against the node's contract.

It is the classifier of the paper's listing (shared reference, lines
1482-1491) with the contract's thresholds 120 and 250, plus the
bookkeeping the contract also asks of the node: when the command is
``inspect(i)`` the waypoint ``i`` is reported inspected.

Calling convention (docs/property-tests.md): one keyword argument per RCL
input, a mapping of output name to value returned.
"""
from __future__ import annotations

from typing import Any

from rclverify.semantics.values import FiniteFunction, Term


def classify(r: float) -> str:
    """green below 120, orange from 120 to below 250, red from 250 on."""
    if r < 120:
        return "green"
    if r < 250:
        return "orange"
    return "red"


def radiation_sensor(r: float, command: Term) -> dict[str, Any]:
    """Outputs of one message: ``radiationStatus`` (RadStat) and ``inspected``
    (NATURAL --> BOOL; TRUE only for the waypoint an ``inspect(i)`` names)."""
    table = {(command.args[0],): True} if command.name == "inspect" else {}
    return {"radiationStatus": classify(r), "inspected": FiniteFunction(table, False, 1)}
