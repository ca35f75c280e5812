"""bench/repair_examples.py on one seeded defect of the project's examples (issue 111; docs/diagnosis.md,
"Seeded defects: figures"): ros2_robot's ``battery_lt`` (``percentage < LOW`` for ``<=``) is found at its
line and its first checked repair is the seeded fix, breaking nothing.  Controls: the robot without the
slip offers nothing (no property test fails), and a "fix" other than the repair is judged a miss."""
from __future__ import annotations

import sys
from dataclasses import replace
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bench"))
import repair_examples  # noqa: E402

pytestmark = pytest.mark.slow  # the property tests of every node of the robot, three times


@pytest.fixture(scope="module")
def battery_lt() -> repair_examples.Defect:
    return next(d for d in repair_examples.defects() if d.name == "battery_lt")


def test_the_seeded_line_and_the_seeded_fix(battery_lt: repair_examples.Defect, tmp_path: Path) -> None:
    assert battery_lt.line == 18
    out = repair_examples.run_defect(battery_lt, tmp_path)
    assert out.failing == "BatteryWatcher.g1.property_tests.e0"
    assert out.cause == "nodes/battery_watcher_logic.py:18" and out.exact
    assert out.offered and out.offered[0] == battery_lt.fixed  # `<` -> `<=`, checked by the harness
    assert out.verdict == "equal" and out.breaks == []


def test_control_the_correct_robot_offers_nothing(battery_lt: repair_examples.Defect, tmp_path: Path) -> None:
    out = repair_examples.run_defect(replace(battery_lt, slipped=battery_lt.fixed), tmp_path)
    assert (out.failing, out.offered, out.verdict) == ("", [], "none")


def test_control_another_fix_is_a_miss(battery_lt: repair_examples.Defect, tmp_path: Path) -> None:
    # a "seeded fix" that is not the repair and fails the guarantee: the repair is neither equal nor equivalent
    wrong = battery_lt.fixed.replace("percentage <= LOW", "percentage <= LOW / 2")
    assert wrong != battery_lt.fixed
    out = repair_examples.run_defect(replace(battery_lt, fixed=wrong), tmp_path)
    assert out.exact and out.offered and out.verdict == "miss"


def test_a_wrong_branch_is_repaired_where_it_is_made(tmp_path: Path) -> None:
    # the bench arm's mode server answers the careful speed for every other mode (`!=` for `==`): the property
    # test names the `return` the failing example takes (line 10); no edit there passes, the search around it
    # finds `==` at line 8, which the diagnosis then names first
    d = next(d for d in repair_examples.defects() if d.name == "mode_wrong_kind")
    from rclverify.app.pipeline import Workspace
    root = repair_examples._workspace(d, tmp_path / "ws", d.slipped)
    assert repair_examples.statuses(root, "ModeServer")["ModeServer.g1.property_tests.e0"] == \
        ("failed", "nodes/mode_server.py:10")  # control: the property test's own line is the return
    assert Workspace(root).plan.evidence["ModeServer"][0].backend == "property_tests"
    out = repair_examples.run_defect(d, tmp_path / "run")
    assert out.cause == "nodes/mode_server.py:8" and out.exact
    assert out.verdict == "equal" and out.breaks == []
