"""The links of a side-condition record read back as names: which producer's output feeds which consumer's input."""
from __future__ import annotations

import re

from rclverify.records.side_condition_rows import SideConditionRow


def link_pairs(sc: SideConditionRow) -> list[tuple[str, str, str, str]]:
    """``(producer, out var, consumer, in var)`` of each of the side condition
    row's ``links`` (``Planner.out.speed -> Controller.in.speed (via
    name)``), in order; a link of another shape is left out."""
    out = []
    for l in sc.links:
        m = re.match(r"^(\w+)\.out\.(\w+) -> (\w+)\.in\.(\w+)", l)
        if m:
            out.append((m.group(1), m.group(2), m.group(3), m.group(4)))
    return out
