"""What the diagnosis reads of the report, typed (docs/records.md, "What the diagnosis reads"): the parts
of a report decoded into their records whether handed as a JSON object or as the decoded report, a
requirement's check record decoded with its numbers as written, and the culprit rows the repair cache
keeps read back as they were made; each with the report or record of another shape refused."""
from __future__ import annotations

import gzip
import json
from pathlib import Path
from typing import Any

import msgspec
import pytest

from rclverify.diagnosis.shapes import CulpritRow, ReportRows, culprit_rows, culprit_rows_json, report_rows
from rclverify.records.deadline_rows import DeadlineRow
from rclverify.records.requirement_check import RequirementCheckRow
from rclverify.records.side_condition_rows import SideConditionRow
from rclverify.report.view import decoded_report

STORED = Path(__file__).resolve().parents[1] / "data" / "warehouse-report.json.gz"


@pytest.fixture(scope="module")
def stored() -> dict[str, Any]:
    """The warehouse example's report as written (its JSON object)."""
    out: dict[str, Any] = json.loads(gzip.decompress(STORED.read_bytes()))
    return out


def test_the_parts_are_records_from_the_json_object_and_from_the_decoded_report(stored: dict[str, Any]) -> None:
    rows = report_rows(stored)
    assert all(isinstance(sc, SideConditionRow) for sc in rows.side_conditions) and rows.side_conditions
    assert all(isinstance(d, DeadlineRow) for d in rows.deadlines) and rows.deadlines
    assert [sc.id for sc in rows.side_conditions] == [sc["id"] for sc in stored["side_conditions"]]
    assert report_rows(decoded_report(stored)) == rows  # the decoded report's parts, taken as they are
    assert report_rows(rows) is rows


def test_control_a_report_without_a_part_or_with_a_part_of_another_shape_is_refused(stored: dict[str, Any]) -> None:
    with pytest.raises(ValueError, match="report lacks lint, deadlines"):
        report_rows({k: v for k, v in stored.items() if k not in ("deadlines", "lint")})
    odd = {**stored, "side_conditions": [{**stored["side_conditions"][0], "conjunkt": "x"}]}
    with pytest.raises(msgspec.ValidationError, match="conjunkt"):
        report_rows(odd)
    assert isinstance(report_rows(stored), ReportRows)


def test_a_check_record_keeps_its_numbers_and_reads_null_as_absent() -> None:
    run = {"trace": "runs/a.jsonl", "status": "failed",
           "verdict": {"verdict": "false", "reason": "r", "step": 3, "time": 2, "where": "a.jsonl:4",
                       "witness": [{"operand": "A.out.y", "holds": False, "step": 3, "values": {"A.out.y": "1"}}]}}
    check = RequirementCheckRow.of({"formal": "always A.out.y", "source": "plan.yaml:3:5", "cone": ["A"],
                                    "counterexample": None, "traces": [run], "premises": 4})
    assert check.counterexample == [] and check.temporal is None and check.cone == ["A"]
    verdict = check.traces[0].verdict
    assert verdict is not None and f"{verdict.time}" == "2" and verdict.witness and verdict.witness[0].holds is False
    again = RequirementCheckRow.of({"traces": [{**run, "verdict": {**run["verdict"], "time": 2.0}}]})
    assert again.traces[0].verdict is not None and f"{again.traces[0].verdict.time}" == "2.0"
    with pytest.raises(msgspec.ValidationError, match="cone"):
        RequirementCheckRow.of({"cone": "A"})  # the control: a declared key of another type


def test_culprit_rows_come_back_from_the_cache_as_they_were_made() -> None:
    rows = [CulpritRow("Planner", 1, "bound", "2.0", "1.5", "out.speed <= 2.0", "contracts/rover.rcl:9:3",
                       {"kind": "tighten-bound", "summary": "s", "edit": {"file": "contracts/rover.rcl", "line": 9}})]
    kept = json.loads(json.dumps(culprit_rows_json(rows), sort_keys=True))  # as the repair cache keeps a value
    assert culprit_rows(kept) == rows and culprit_rows(None) == []
    with pytest.raises(msgspec.ValidationError):
        culprit_rows([{"node": "Planner"}])  # the control: a kept value of another shape
