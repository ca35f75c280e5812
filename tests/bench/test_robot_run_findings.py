"""The generated-robot runner's findings (bench/_robot_run.py): a seeded defect not red live is a finding,
unless the seeded node is a server the monitor could judge nothing of (its calls unjudged: the rclpy source
hears calls through introspection events only, docs/ros2.md), which the run says apart; a node judged green
is never excused."""
from __future__ import annotations

import sys
from collections import Counter
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bench"))

from _robot_run import findings, victim_unjudged  # noqa: E402


def _res(victim: Counter[str]) -> dict[str, Any]:
    nodes = [{"name": "Sensor0"}, {"name": "Switch1", "defect": True}]
    return {"disagreements": [], "spec": {"nodes": nodes}, "finals": {}, "declarations": {},
            "live": {"Sensor0": Counter(satisfied=5), "Switch1": victim}}


def test_a_seeded_server_judged_nothing_is_said_apart_not_a_finding() -> None:
    res = _res(Counter(unjudged=2))
    assert victim_unjudged(res) and findings(res) == []


def test_control_a_seeded_node_judged_green_is_a_finding() -> None:
    res = _res(Counter(satisfied=3, unjudged=2))
    assert not victim_unjudged(res) and findings(res) == ["Switch1: seeded defect not red live"]


def test_control_a_seeded_node_red_is_no_finding() -> None:
    assert findings(_res(Counter(violated=1))) == []
