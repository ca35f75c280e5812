"""The generated-robot runner's findings (bench/_robot_run.py): a seeded defect not red live is a finding,
unless the seeded node is a server the monitor could judge nothing of (its calls unjudged: the rclpy source
hears calls through introspection events only, docs/ros2.md), which the run says apart; a node judged green
is never excused.  A node seeded to answer late on a ``/clock`` whose mapping leaves ``use_sim_time``
unsaid, its deadlines undecided (the wall clock and ``/clock`` time disagree), is said apart too; with
``use_sim_time`` declared it must be red.  A run's figures count the false verdicts of correct nodes
apart from the seeded node's."""
from __future__ import annotations

import sys
from collections import Counter
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bench"))

from _robot_run import figures, findings, in_subset, late_unsaid, victim_unjudged  # noqa: E402


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


def _late(victim: Counter[str], use_sim_time: bool) -> dict[str, Any]:
    nodes = [{"name": "Sensor0"}, {"name": "Alarm1", "defect": True, "defect_kind": "late"}]
    return {"disagreements": [], "errors": [], "spec": {"nodes": nodes, "use_sim_time": use_sim_time}, "finals": {},
            "declarations": {}, "live": {"Sensor0": Counter(satisfied=5), "Alarm1": victim}}


def test_a_late_node_undecided_with_use_sim_time_unsaid_is_said_apart() -> None:
    res = _late(Counter({"satisfied": 3, "deadline undecided": 4}), use_sim_time=False)
    assert late_unsaid(res) and findings(res) == []


def test_control_a_late_node_undecided_with_use_sim_time_declared_is_a_finding() -> None:
    res = _late(Counter({"satisfied": 3, "deadline undecided": 4}), use_sim_time=True)
    assert not late_unsaid(res) and findings(res) == ["Alarm1: seeded defect not red live"]
    green = _late(Counter({"satisfied": 3, "deadline true": 4}), use_sim_time=False)  # never undecided: not excused
    assert not late_unsaid(green) and findings(green) == ["Alarm1: seeded defect not red live"]


def test_a_runs_figures_count_correct_nodes_apart_from_the_seeded_one() -> None:
    def rec(node: str, item: str, verdict: str, time: float) -> dict[str, Any]:
        return {"node": node, "item": item, "topic": "t", "time": time, "verdict": verdict}
    res = _late(Counter({"satisfied": 3, "deadline false": 2, "deadline true": 1, "deadline undecided": 1}), True)
    res["live"]["Sensor0"].update({"deadline true": 4})
    res["finals"] = {"live": {("Alarm1", "deadline", "t", 0): [rec("Alarm1", "deadline", "false", 1.0)],
                              ("Sensor0", "guarantee", "t", 0): [rec("Sensor0", "guarantee", "violated", 2.0)]},
                     "log": {("Sensor0", "deadline", "t", 0): [rec("Sensor0", "deadline", "false", 3.0)]}}
    res["declarations"] = {"live": {("Sensor0", "periodic out.x", "r:1:1"): {"verdict": "false"},
                                    ("Alarm1", "progress", "r:2:1"): {"verdict": "false"}}}
    fig = figures(res)
    assert (fig["violated_correct"], fig["false_deadlines_correct"], fig["false_declarations_correct"]) == (1, 1, 1)
    assert (fig["deadlines"], fig["undecided"], fig["agree"]) == (8, 1, True)
    assert (fig["victim"], fig["kind"], fig["red"], fig["red_deadlines"]) == ("Alarm1", "late", 2, 2)


def test_the_subset_answering_one_input_within_its_period() -> None:
    """Alarms, stamping relays, copying relays no slower than their reading's period and servers are in the
    subset the issue bounds at 1 % undecided; a fuse (two inputs) and a copying relay slower than its reading's
    period are not; the subset's figures count its correct nodes' answers and deadlines."""
    nodes = {"S": {"name": "S", "kind": "sensor", "period_ms": 300},
             "A": {"name": "A", "kind": "alarm"}, "F": {"name": "F", "kind": "fuse"},
             "R": {"name": "R", "kind": "relay", "copy": True, "source": "S", "delay_ms": 300},
             "Q": {"name": "Q", "kind": "relay", "copy": True, "source": "S", "delay_ms": 301},
             "P": {"name": "P", "kind": "relay", "copy": False, "source": "S", "delay_ms": 90},
             "V": {"name": "V", "kind": "service"}}
    assert [n for n in nodes if in_subset(nodes[n], nodes)] == ["A", "R", "P", "V"]
    res = {"spec": {"nodes": list(nodes.values())}, "finals": {}, "disagreements": [], "errors": [],
           "live": {"A": Counter({"satisfied": 9, "undecided": 1, "deadline true": 10}),
                    "F": Counter({"satisfied": 5, "undecided": 5}), "Q": Counter({"undecided": 3}),
                    "R": Counter({"satisfied": 4, "deadline undecided": 1})}}
    fig = figures(res)
    assert (fig["subset_answers"], fig["subset_undecided"]) == (25, 2)
