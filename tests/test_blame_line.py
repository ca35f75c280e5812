"""Blame the line (issue 64): a property-test failure names the statement
that computed the failing value, not the ``return`` that passes it on; an
output written as a literal in the wrong branch still names that line.  The
implementations are real files traced with sys.settrace."""
from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from typing import Any

from rclverify.backends.property_tests.cause import cause_line

ARM = """\
def step(index):
    base = 0
    joint = index + 1
    checked = joint >= 0
    if not checked:
        return {"joint": base}
    return {"joint": joint}
"""

SPEED = """\
def step(distance):
    if distance < 0.5:
        return {"speed": 1.0}
    slow = distance / 2
    return {"speed": slow}
"""

CLASS = """\
class Arm:
    def __init__(self):
        self.last = 0

    def step(self, index):
        target = index * 2
        self.last = target
        return {"joint": target}
"""


def _load(tmp_path: Path, name: str, text: str, attr: str) -> Any:
    path = tmp_path / f"{name}.py"
    path.write_text(text, encoding="utf-8")
    spec = importlib.util.spec_from_file_location(name, path)
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    sys.modules[name] = mod  # a class's source file is found through its module
    spec.loader.exec_module(mod)
    return getattr(mod, attr)


def test_the_assignment_that_computed_the_output(tmp_path: Path) -> None:
    step = _load(tmp_path, "arm", ARM, "step")
    assert cause_line(step, {"in.index": 5}, None, "nodes/arm.py") == "nodes/arm.py:3"  # joint = index + 1


def test_a_literal_in_the_wrong_branch_is_its_return(tmp_path: Path) -> None:
    step = _load(tmp_path, "speed", SPEED, "step")
    assert cause_line(step, {"in.distance": 0.1}, None, "speed.py") == "speed.py:3"
    assert cause_line(step, {"in.distance": 4.0}, None, "speed.py") == "speed.py:4"  # slow = distance / 2


def test_a_class_step_names_its_assignment(tmp_path: Path) -> None:
    arm = _load(tmp_path, "armc", CLASS, "Arm")
    steps = [{"in.index": 1}, {"in.index": 3}]
    assert cause_line(arm, steps, 2, "armc.py") == "armc.py:6"
