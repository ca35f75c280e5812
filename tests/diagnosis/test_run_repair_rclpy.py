"""A monitor violation's code repair, checked by re-running the node's rclpy callback on the recorded run
(diagnosis/run_repair.py, docs/diagnosis.md "Monitor violations: a node re-run on its recorded run").

The run is a real live log of examples/manipulator with its ``charge_lt`` defect (the ChargeMonitor
compares with ``<`` where the contract says ``<=`` at the float32 0.2), recorded by ``watch.py`` (6
rounds, the rclpy source) and kept in ``data/``.  The node is re-run in the ROS 2 Python with discovery
off: nothing is published or heard.  Controls: the repaired callback is judged discharged on the run
(again through ``rejudged``) where the defective one failed (the repair's cost); the correct robot does
not reproduce the defect's recorded answers, so nothing is offered on it.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from _ros2 import ros2_python

from rclverify.diagnosis.edits import Edit
from rclverify.diagnosis.run_repair import rejudged, run_repairs

REPO = Path(__file__).resolve().parents[2]
ROOT = REPO / "examples" / "manipulator"
LOG = Path(__file__).parent / "data" / "manipulator_charge_lt.jsonl"


@pytest.fixture(scope="module")
def ws() -> tuple[Any, Any, Path]:
    from rclverify.app.pipeline import Workspace
    from rclverify.backends.monitors.config import load_mapping
    return Workspace(ROOT).checked, load_mapping(ROOT, "contracts/mapping.yaml", None), ros2_python()


def test_the_charge_monitors_slip_is_repaired_and_checked_on_its_run(ws: tuple[Any, Any, Path]) -> None:
    checked, cfg, python = ws
    text = (ROOT / "robot.py").read_text(encoding="utf-8")
    seeded = next(k for k, x in enumerate(text.splitlines(), 1) if 'bad("charge_lt")' in x)
    got = run_repairs(ROOT, checked, cfg, LOG, "ChargeMonitor", False, "robot.py", "build", [["charge_lt"]], python)
    assert got.repairs, got.why
    first = got.repairs[0]
    assert got.line == f"robot.py:{seeded}"  # the line with the slip, not the callback's first line
    assert (first["edit"]["deleted"], first["edit"]["inserted"]) == ("<", "<=")
    assert first["checks"] == [{"check": "ChargeMonitor", "status": "discharged"}]
    assert first["cost"] == [{"check": "ChargeMonitor", "before": "failed", "after": "discharged"}]
    e = first["edit"]
    repaired = Edit("robot.py", e["line"], e["col"], e["end_line"], e["end_col"], e["inserted"]).apply(text)
    after = rejudged(ROOT, checked, cfg, LOG, "ChargeMonitor", False, "robot.py", repaired, "build",
                     [["charge_lt"]], python)
    assert after["ChargeMonitor"][0] == "discharged"  # the other side: the cost's "before" is the defect's failed
    assert {k for k, v in after.items() if v[0] == "failed"} == set()


def test_a_node_whose_code_does_not_give_the_recorded_answers_is_not_repaired(ws: tuple[Any, Any, Path]) -> None:
    checked, cfg, python = ws
    got = run_repairs(ROOT, checked, cfg, LOG, "ChargeMonitor", False, "robot.py", "build", [[]], python)
    assert got.repairs == [] and "does not give the recorded answers" in got.why
    assert got.line.startswith("robot.py:")
