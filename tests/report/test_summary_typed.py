"""The terminal summary and the --strict clauses read the report decoded once (report/summary.py,
report/strict.py): a stored report of another shape is one located error, an unset field reads as
its rule says (a deadline without a status is not outstanding), an acknowledged lint row passes."""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from _typed_rows import complete
from rclverify.lang.errors import RclError
from rclverify.records.report_record import AssuranceReport
from rclverify.report.strict import strict_reasons
from rclverify.report.summary import read_summary


def _report(**parts: Any) -> dict[str, Any]:
    """A whole report of one node (``parts`` given), its summary failed and --strict failing."""
    given: dict[str, Any] = {"meta": {"workspace": "w", "strict_ok": False},
                             "summary": {"status": "failed", "headline": "h", "problems": []},
                             "nodes": [{"name": "N", "status": "discharged"}], **parts}
    return complete(AssuranceReport, given)


def _write(root: Path, report: dict[str, Any]) -> None:
    (root / "reports").mkdir(parents=True, exist_ok=True)
    (root / "reports/assurance.json").write_text(json.dumps(report), encoding="utf-8")


def test_a_stored_report_with_a_key_no_record_declares_is_one_located_error(tmp_path: Path) -> None:
    report = _report()
    _write(tmp_path, report)
    assert read_summary(tmp_path)["meta"]["workspace"] == "w"  # control: the report as written reads
    report["nodes"][0]["colour"] = "red"
    _write(tmp_path, report)
    with pytest.raises(RclError) as err:
        read_summary(tmp_path)
    text = str(err.value)
    assert "reports/assurance.json" in text and "colour" in text and "\n" not in text.strip()


def test_a_proved_deadline_without_a_status_is_not_outstanding() -> None:
    proved = {"requirement": "STOP", "path": ["A", "B"], "within": "300 ms", "source": "p.yaml:1:1",
              "verdict": "proved"}
    assert strict_reasons(_report(deadlines=[proved])) == []
    reasons = strict_reasons(_report(deadlines=[{**proved, "status": "pending"}]))  # control: outstanding evidence
    assert len(reasons) == 1 and "proved from a chain whose evidence is outstanding" in reasons[0] and "STOP" in reasons[0]


def test_only_unacknowledged_lint_rows_fail_strict() -> None:
    lint = [{"severity": "warning", "location": "c.rcl:1:1", "message": "m", "code": "W-x"},
            {"severity": "warning", "location": "c.rcl:2:1", "message": "m", "code": "W-x",
             "acknowledged": {"reason": "known", "at": "p.yaml:3:5"}}]
    assert strict_reasons(_report(lint=lint)) == ["1 lint diagnostic (`rclverify check`: c.rcl:1:1)"]
    assert strict_reasons(_report(lint=lint[1:])) == []  # control: the acknowledged one alone passes
    passed = _report(lint=lint)
    passed["meta"]["strict_ok"] = True
    assert strict_reasons(passed) == []  # the gate passed: no clause at all
