"""Helpers shared by the experiment and review backend tests: a copy of the
bundled workspace (contracts, plan, experiment and review data) in tmp_path."""
from __future__ import annotations

import shutil
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def copy_workspace(dest: Path) -> Path:
    """Copy what the check stage and the experiment/review backends read."""
    for rel in ("contracts", "backends/experiment", "backends/review"):
        shutil.copytree(REPO / rel, dest / rel)
    return dest


def replace_in_plan(root: Path, old: str, new: str) -> None:
    plan = root / "contracts/plan.yaml"
    text = plan.read_text(encoding="utf-8")
    assert old in text, old
    plan.write_text(text.replace(old, new, 1), encoding="utf-8")


def plan_line(root: Path, needle: str) -> tuple[int, int]:
    """(line, col) of the first occurrence of ``needle`` in the plan (1-based)."""
    for i, line in enumerate((root / "contracts/plan.yaml").read_text(encoding="utf-8").splitlines(), 1):
        if needle in line:
            return i, line.index(needle) + 1
    raise AssertionError(needle)
