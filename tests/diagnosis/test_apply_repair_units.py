"""diagnosis/apply_repair.py without a pipeline run (issue 111; docs/diagnosis.md "Applying a repair"): a
repair record as diagnosis/repairs.py ``_record`` makes it, written over the text it was computed on and
refused over any other; the ids a report's repairs are found by; why none is offered."""
from __future__ import annotations

import os
import stat
from pathlib import Path
from typing import Any

import msgspec
import pytest

from rclverify.diagnosis.apply_repair import NotApplied, apply_repair, find_repairs, none_offered
from rclverify.diagnosis.edits import Edit
from rclverify.diagnosis.repairs import _record
from rclverify.records.repair_rows import RepairRow
from tests.records._typed_rows import typed_report

CODE = "def gate(x):\n    return {\"ok\": x < 3}\n"


def _repair(text: str, rel: str = "nodes/gate.py") -> RepairRow:
    edit = Edit(rel, 2, 21, 2, 22, "<=")
    return RepairRow.of(_record("code", "x < 3 to x <= 3", edit, text, [], []))


def _ws(tmp_path: Path, data: bytes) -> Path:
    (tmp_path / "nodes").mkdir(parents=True)
    (tmp_path / "nodes/gate.py").write_bytes(data)
    return tmp_path


def test_written_over_the_text_it_was_checked_on_keeping_line_ends_and_mode(tmp_path: Path) -> None:
    ws = _ws(tmp_path, CODE.replace("\n", "\r\n").encode())
    os.chmod(ws / "nodes/gate.py", 0o750)
    apply_repair(ws, _repair(CODE))  # the digest is of the text as read: universal newlines
    assert (ws / "nodes/gate.py").read_bytes() == CODE.replace("<", "<=").replace("\n", "\r\n").encode()
    assert stat.S_IMODE((ws / "nodes/gate.py").stat().st_mode) == 0o750


def test_control_refused_over_another_text_nothing_written(tmp_path: Path) -> None:
    other = CODE + "# a line added after the run\n"
    ws = _ws(tmp_path, other.encode())
    with pytest.raises(NotApplied) as e:
        apply_repair(ws, _repair(CODE))
    assert (e.value.file, e.value.line, e.value.col) == ("nodes/gate.py", 2, 21)
    assert "changed since the last run checked this repair" in e.value.message
    assert (ws / "nodes/gate.py").read_text(encoding="utf-8") == other


def test_refused_outside_the_workspace_and_on_a_region_that_moved(tmp_path: Path) -> None:
    ws = _ws(tmp_path / "ws", CODE.encode())
    (tmp_path / "elsewhere.py").write_text(CODE, encoding="utf-8")
    with pytest.raises(NotApplied, match="not a file of the workspace"):
        apply_repair(ws, _repair(CODE, "../elsewhere.py"))
    moved = _repair(CODE)
    moved = msgspec.structs.replace(moved, edit=msgspec.structs.replace(moved.edit, deleted="<="))  # a record whose region does not hold what it deletes
    with pytest.raises(NotApplied, match="holds '<', not '<='"):
        apply_repair(ws, moved)
    assert (ws / "nodes/gate.py").read_text(encoding="utf-8") == CODE
    assert (tmp_path / "elsewhere.py").read_text(encoding="utf-8") == CODE


REPORT = typed_report({
    "diagnoses": [
        {"id": "Gate.g1.property_tests.e0", "kind": "property-test", "repairs": [{"kind": "code"}, {"kind": "code"}]},
        {"id": "Odd.g1.property_tests.e0", "kind": "property-test", "repairs": []},
        {"id": "Wheel.g0.monitors.run", "kind": "monitor", "repairs": []},
        {"id": "Follower.sc1", "kind": "side-condition", "repairs": [],
         "not_offered": ["Strengthening Router leaves it unimplementable"]},
    ],
    "problems": [
        {"members": [{"id": "Odd.g1.property_tests.e0"}], "repairs": []},
        {"members": [{"id": "Gate.g1.property_tests.e0"}], "repairs": [{"diagnosis": "Gate.g1.property_tests.e0",
                                                                         "index": 1}]},
    ],
})


def test_ids_exact_folded_and_problem_numbers() -> None:
    exact = find_repairs(REPORT, "Gate.g1.property_tests.e0")
    assert exact is not None and [o.index for o in exact.offered] == [0, 1]
    folded = find_repairs(REPORT, "gate.G1.property-tests.E0")
    assert folded is not None and folded.subject == "Gate.g1.property_tests.e0"
    for k in ("2", "p2", "problem 2"):
        p = find_repairs(REPORT, k)
        assert p is not None and p.subject == "problem 2" and [o.index for o in p.offered] == [1]
    assert find_repairs(REPORT, "3") is None and find_repairs(REPORT, "Nothing.g1") is None


def test_why_none_by_kind() -> None:
    def why(i: str) -> str:
        found = find_repairs(REPORT, i)
        assert found is not None and not found.offered
        return " ".join(none_offered(found))
    assert "no edit the diagnosis tried passed its checks" in why("Odd.g1.property_tests.e0")
    assert "re-run" not in why("Odd.g1.property_tests.e0")  # control: only a monitor's violation says it
    assert "no repair is searched" in why("Wheel.g0.monitors.run")
    assert "a node re-run on its recorded run" in why("Wheel.g0.monitors.run")  # where the search is said
    assert "implementation: FILE.py:FUNCTION" in why("Wheel.g0.monitors.run")  # and the plan key it needs
    assert why("Follower.sc1") == "Follower.sc1: Strengthening Router leaves it unimplementable"
    assert "no edit the diagnosis tried" in why("1")
