"""The compliance matrix and the trace matrix exported as CSV (read back with the csv module) and XLSX
(opened with openpyxl), and ``rclverify standards`` printing the standards' gaps
(report/standards_export.py, cli/standards.py, docs/standards.md "Exports")."""
from __future__ import annotations

import csv
from pathlib import Path
from typing import Any

import pytest

from rclverify.cli.commands import main
from rclverify.lang.ast import Loc
from rclverify.model.plan.standards.choice import StandardChoice
from rclverify.model.plan.standards.profiles import load_builtin, parse_profile
from rclverify.report.standards_export import (MATRIX_COLUMNS, TRACE_COLUMNS, gaps, matrix_rows, trace_rows,
                                               write_csv, write_xlsx)
from rclverify.report.standards_rows import standards_part

from test_standards_scope import Report
from _typed_rows import typed_report

#: a workspace profile whose title reads like a spreadsheet formula
FORMULA = parse_profile("""id: t
title: T
edition: T 1
items:
  - {id: F1, title: "=HYPERLINK(\\"x\\")", evidence: [property-tests], strength: tested, recommendation: HR}
""", "std/t.yaml")


def _report() -> dict[str, Any]:
    r = Report()
    for n in ("Lidar", "Base"):
        r.guarantee(n, 1).ev(n, 1, "property_tests")
    r.guarantee("Base", 2, "failed").ev("Base", 2, "monitors", "failed")
    r.review("Base", 1, "Ada", "Ada")
    r.requirements.append({"id": "STOP", "status": "discharged", "verdict": "met",
                           "support": [{"node": "Lidar", "guarantee": 1}, {"node": "Base", "guarantee": 1}]})
    report = r.dict()
    choices = [StandardChoice(load_builtin("iec61508-3"), "2", Loc("contracts/plan.yaml", 4, 5)),
               StandardChoice(FORMULA, None, Loc("contracts/plan.yaml", 5, 5))]
    report["standards"] = standards_part(choices, report)["rows"]
    return report


def _read_csv(path: Path) -> list[dict[str, str]]:
    """The table of an exported CSV, after its header block (``[what, value]`` rows, then an empty row)."""
    with path.open(newline="", encoding="utf-8") as f:
        rows = list(csv.reader(f))
    if rows and rows[0] and rows[0][0] == "read from":
        rows = rows[rows.index([]) + 1:]
    return [dict(zip(rows[0], r)) for r in rows[1:]]


def test_the_compliance_matrix_reads_back_from_csv(tmp_path: Path) -> None:
    report = _report()
    write_csv(tmp_path / "m.csv", matrix_rows(typed_report(report)))
    rows = _read_csv(tmp_path / "m.csv")
    assert list(rows[0]) == list(MATRIX_COLUMNS)
    iec = load_builtin("iec61508-3")
    assert [r["clause"] for r in rows] == [i.id for i in iec.items] + ["F1"]
    b86c = next(r for r in rows if r["clause"] == "B.8 6c")
    assert (b86c["status"], b86c["items in scope"], b86c["items covered"]) == ("open", "3", "0")
    assert b86c["independence asked"] == "person" and b86c["profile origin"] == "built-in (IEC 61508-3:2010)"
    assert "Base g2: 1 failed of its 1 record" in next(r for r in rows if r["clause"] == "A.5 2")["items not covered"]
    a54 = next(r for r in rows if r["clause"] == "A.5 4")
    assert a54["status"] == "partial" and a54["evidence that covers it"] == "Lidar.g1.property_tests.e0; Base.g1.property_tests.e1"
    assert a54["who checked it"] == "property_tests (property_tests 1)"
    # every clause of the JSON is a row, with the same status and why
    json_rows = [(c["id"], c["status"], c["why"]) for s in report["standards"] for c in s["clauses"]]
    assert [(r["clause"], r["status"], r["why"]) for r in rows] == json_rows
    f1 = rows[-1]
    assert f1["what it asks"] == "'=HYPERLINK(\"x\")" and f1["profile origin"].startswith("workspace file std/t.yaml sha256 ")


def test_the_trace_matrix_reads_back_from_csv(tmp_path: Path) -> None:
    write_csv(tmp_path / "t.csv", trace_rows(typed_report(_report())))
    rows = _read_csv(tmp_path / "t.csv")
    assert list(rows[0]) == list(TRACE_COLUMNS)
    stop = [(r["node"], r["guarantee"], r["obligation"], r["evidence status"]) for r in rows if r["requirement"] == "STOP"]
    assert stop == [("Lidar", "g1", "Lidar.g1.property_tests.e0", "discharged"),
                    ("Base", "g1", "Base.g1.property_tests.e1", "discharged"),
                    ("Base", "g1", "Base.g1.review.e3", "discharged"),
                    ("", "", "requirement STOP", "discharged")]  # its own check's row (every row has a check record)
    untraced = [(r["node"], r["guarantee"], r["evidence status"]) for r in rows if r["requirement"] == ""]
    assert untraced == [("Base", "g2", "failed")]  # a guarantee no requirement names is still traced to its evidence


def test_the_workbook_opens_with_openpyxl_and_keeps_text_as_text(tmp_path: Path) -> None:
    openpyxl = pytest.importorskip("openpyxl")
    report = _report()
    write_xlsx(tmp_path / "w.xlsx", {"compliance matrix": matrix_rows(typed_report(report)), "trace matrix": trace_rows(typed_report(report))})
    wb = openpyxl.load_workbook(tmp_path / "w.xlsx")
    assert wb.sheetnames == ["compliance matrix", "trace matrix"]
    sheet = wb["compliance matrix"]
    got = [[("" if c.value is None else str(c.value)) for c in row] for row in sheet.iter_rows()]
    assert got == matrix_rows(typed_report(report))
    cell = sheet.cell(row=sheet.max_row, column=MATRIX_COLUMNS.index("what it asks") + 1)
    assert cell.value == '=HYPERLINK("x")' and cell.data_type == "s"  # never a formula
    assert [[("" if c.value is None else str(c.value)) for c in row] for row in wb["trace matrix"].iter_rows()] == (
        trace_rows(typed_report(report)))


def test_the_gaps_name_each_clause_asked_and_not_covered() -> None:
    lines = gaps(typed_report(_report()))
    assert lines[0].startswith("IEC 61508-3:2010 SIL 2 (built-in profile): ")
    assert any(line.startswith("  B.8 6c [HR] Design review (a static analysis technique; by the tool's rule, by someone other than "
                              "the author): open: ")
               for line in lines)
    assert gaps(typed_report({"standards": []})) == []


def test_the_command_without_a_report_is_one_located_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    capsys.readouterr()
    assert main(["standards", "-w", str(tmp_path), "--csv", str(tmp_path / "m.csv")]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "reports/assurance.json:1:1: error:" in err[0] and not (tmp_path / "m.csv").exists()
