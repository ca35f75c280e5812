"""A matrix an assessor files (report/standards_sheets.py, report/standards_export.py, cli/standards.py,
docs/standards.md "Exports"), and each clause taking only the evidence it asks for
(model/plan/standards/field_data.py, the built-in profiles).

Each attempt an assessor made to have the mapping overclaim or the export mislead is a case beside an
honest control: the CSV is read back with the csv module and the workbook opened with openpyxl."""
from __future__ import annotations

import csv
import gzip
import hashlib
import json
from pathlib import Path
from typing import Any

import pytest

from rclverify.cli.commands import main
from rclverify.lang.ast import Loc
from rclverify.model.plan.errors import PlanError
from rclverify.model.plan.standards.choice import ClauseNote, StandardChoice
from rclverify.model.plan.standards.mapping import clause_rows
from rclverify.model.plan.standards.profiles import load_builtin, load_profile_file
from rclverify.report.standards_export import (FORMULA_START, escape_cell, evidence_digests, export_header,
                                               matrix_rows, trace_rows, write_csv, write_xlsx)
from rclverify.report.standards_rows import standards_part
from rclverify.report.standards_sheets import MATRIX_COLUMNS, TRACE_COLUMNS
from _typed_rows import typed_report

REPO = Path(__file__).resolve().parents[2]


def _report(runs: int = 60, origin: str = "operation", reviewer: str = "Charles Babbage") -> dict[str, Any]:
    """Two nodes on a connection, each property-tested and reviewed, and a run set of ``runs`` runs
    meeting a 5 % target at 95 % (the bound a clean run set of that size gives)."""
    bound = 1 - 0.05 ** (1 / runs)
    ev: list[dict[str, Any]] = []
    obligations: list[dict[str, Any]] = []
    for n in ("Lidar", "Base"):
        for backend, kind, extra in (("property_tests", "testing", {}), ("review", "review", {"figures": [
                ["reviewer", reviewer], ["author", "Ada Lovelace"], ["date", "2026-03-01"]]})):
            ob = f"{n}.g1.{backend}.e{len(ev)}"
            obligations.append({"id": ob, "node": n, "guarantee": 1, "status": "discharged"})
            ev.append({"obligation": ob, "backend": backend, "kind": kind, "status": "discharged", "tool": backend,
                       "tool_version": "1", "started": "2026-03-02T10:00:00+00:00", **extra})
    ob = "Base.g0.monitors.runs_day_e2"
    obligations.append({"id": ob, "node": "Base", "guarantee": 0, "status": "discharged"})
    decision = {"n": runs, "k": 0, "bound": bound, "level": 0.95, "target": {"bound": 0.05, "text": "<= 5 %"}}
    ev.append({"obligation": ob, "backend": "monitors", "kind": "monitoring", "status": "discharged",
               "tool": "rclverify monitor", "tool_version": "1", "started": "2026-03-02T11:00:00+00:00",
               "strength": {"kind": "statistical", "doubt": 0.05},
               "statistics": {"origin": origin, "environment": "day", "decision": decision}})
    return {"meta": {"version": "0.1.0", "z3_version": "5.4.1", "plan": "contracts/plan.yaml", "workspace": "w",
                     "strict_ok": True, "contracts": ["contracts/robot.rcl"], "inputs_sha256": "ab" * 32},
            "summary": {"status": "discharged", "solvers": {"two solvers": 1}, "headline": "", "problems": []},
            "system": {"connections": [{"from_node": "Lidar", "to_node": "Base"}]},
            "nodes": [{"name": n, "status": "discharged", "guarantees": [{"index": 1, "status": "discharged",
                                                                        "text": "TRUE"}]} for n in ("Lidar", "Base")],
            "obligations": obligations, "evidence": ev,
            "side_conditions": [{"id": "Base.sc1", "node": "Base", "status": "discharged", "verdict": "discharged"}],
            "requirements": [{"id": "STOP", "status": "discharged", "verdict": "met",
                              "support": [{"node": "Base", "guarantee": 1}],
                              "check": {"cone": ["Base"], "used": [{"label": "Base guarantee 1", "kind": "guarantee",
                                                                     "text": "out.v <= 1"}]}}],
            "findings": [], "unverified": []}


def _clauses(profile: str, level: str | None, report: dict[str, Any],
             unstated: frozenset[tuple[str, str]] = frozenset()) -> dict[str, dict[str, Any]]:
    return {c["id"]: c for c in clause_rows(load_builtin(profile), level, report, None, unstated)}


# --- each clause takes only what it asks for ------------------------------------------------------------

def test_three_runs_meeting_a_weak_target_are_no_probabilistic_testing() -> None:
    """3 runs against a 70 % per-run target met it; A.5 1 and UL 4600 16 ask 30 independent runs."""
    few = _report(runs=3)
    few["evidence"][-1]["statistics"]["decision"]["target"] = {"bound": 0.7, "text": "<= 70 %"}
    for profile, level, cid in (("iec61508-3", "2", "A.5 1"), ("ul4600", None, "16")):
        clause = _clauses(profile, level, few)[cid]
        assert clause["status"] == "not covered", (cid, clause["why"])
        assert "3 independent runs; the clause asks at least 30" in clause["scope"][0]["detail"]
        # control: 60 clean runs meeting 5 % at 95 % cover it, the figures in the item's detail
        clause = _clauses(profile, level, _report(runs=60))[cid]
        assert clause["status"] == "covered" and clause["scope"][0]["detail"].startswith(
            "60 independent run(s), 0 violating; bound 4.87 % at 95 % confidence against the target 5 %; "
            "environment day, origin operation")


def test_a_run_set_that_states_no_origin_is_no_field_data() -> None:
    report = _report()
    clause = _clauses("ul4600", None, report, frozenset({("Base", "day")}))["16"]
    assert clause["status"] == "not covered" and clause["scope"][0]["state"] == "not counted"
    assert "states no origin" in clause["scope"][0]["detail"]
    assert _clauses("ul4600", None, report, frozenset({("Base", "night")}))["16"]["status"] == "covered"


def test_code_reviews_contract_proofs_and_python_tests_cover_no_object_code_table() -> None:
    """DO-333 FM.A-7 asks reviews of the verification results and coverage; FM.A-6 evidence on the object
    code: no backend of rclverify gives either, so both stay uncovered however much else there is."""
    report = _report()
    report["evidence"] += [{**report["evidence"][0], "obligation": "Base.g1.hoare.e9", "backend": "hoare",
                            "kind": "proof"}]
    report["obligations"].append({"id": "Base.g1.hoare.e9", "node": "Base", "guarantee": 1})
    rows = _clauses("do-333", "B", report)
    assert rows["FM.A-7"]["status"] == "open" and rows["FM.A-7"]["accepts"] == ["coverage-analysis",
                                                                               "verification-review"]
    assert rows["FM.A-6"]["status"] != "covered" and rows["FM.A-6"]["accepts"] == ["object-code"]
    # control: the same reviews do cover a clause that takes reviews (IEC 61508-3 B.8 6c)
    assert _clauses("iec61508-3", "2", report)["B.8 6c"]["status"] == "covered"


def test_interface_testing_takes_tests_not_side_condition_proofs() -> None:
    report = _report()
    for e in report["evidence"]:
        if e["backend"] == "property_tests":
            e["status"] = "failed"
    a57 = _clauses("iec61508-3", "3", report)["A.5 7"]
    assert a57["status"] == "not covered" and "Base.sc1" not in a57["covered_by"]
    # control: A.4 4 takes proofs, so the proved side condition is among what covers it
    assert "Base.sc1" in _clauses("iec61508-3", "3", report)["A.4 4"]["covered_by"]


# --- editions are reserved however they are spelt --------------------------------------------------------

@pytest.mark.parametrize("edition", ["IEC 61508-3:2010 ", "IEC 61508\u20113:2010", "iec 61508-3:2010",
                                     "IEC 61508 - 3 : 2010", "IEC\u00a061508-3:2010"])
def test_a_workspace_profile_taking_a_builtin_edition_is_refused(tmp_path: Path, edition: str) -> None:
    (tmp_path / "p.yaml").write_text(f"id: ours\ntitle: Ours\nedition: {json.dumps(edition)}\nitems:\n"
                                     "  - {id: R1, title: proved, evidence: [proof], strength: proof, "
                                     "recommendation: HR}\n", encoding="utf-8")
    with pytest.raises(PlanError) as exc:
        load_profile_file(tmp_path / "p.yaml", "std/p.yaml")
    assert str(exc.value).startswith("std/p.yaml:3:") and ": error: standard profile: edition " in str(exc.value)
    assert "is the built-in profile 'iec61508-3'" in str(exc.value)


def test_control_a_workspace_profile_with_its_own_edition_is_read(tmp_path: Path) -> None:
    (tmp_path / "p.yaml").write_text("id: ours\ntitle: Ours\nedition: IEC 61508-3:2010, company rules rev 2\n"
                                     "items:\n  - {id: R1, title: proved, evidence: [proof], strength: proof, "
                                     "recommendation: HR}\n", encoding="utf-8")
    assert load_profile_file(tmp_path / "p.yaml", "std/p.yaml").edition == "IEC 61508-3:2010, company rules rev 2"


# --- the CSV: formula injection, read back ----------------------------------------------------------------

@pytest.mark.parametrize("start", FORMULA_START)
def test_a_cell_a_spreadsheet_would_run_is_escaped(tmp_path: Path, start: str) -> None:
    cell = f"{start}HYPERLINK(\"http://x\",\"y\")"
    write_csv(tmp_path / "m.csv", [["clause", "plan's justification"], ["B.8 6c", cell], ["A.9 1", "plain text"]])
    with (tmp_path / "m.csv").open(newline="", encoding="utf-8") as f:
        rows = list(csv.reader(f))
    assert rows[1] == ["B.8 6c", "'" + cell] and escape_cell(cell) == "'" + cell
    assert rows[2] == ["A.9 1", "plain text"]  # control: text that starts otherwise is written as it is


def test_a_plan_justification_starting_with_a_formula_reaches_the_csv_escaped(tmp_path: Path) -> None:
    report = _report()
    why = "=cmd|' /C calc'!A0 and the rest of the justification is words"
    note = ClauseNote(None, "", why, "contracts/plan.yaml:9:7")
    report["standards"] = standards_part([StandardChoice(load_builtin("iec61508-3"), "2",
                                                         Loc("contracts/plan.yaml", 4, 5),
                                                         clauses={"B.8 6c": note})], report)["rows"]
    write_csv(tmp_path / "m.csv", matrix_rows(typed_report(report)))
    with (tmp_path / "m.csv").open(newline="", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    b86c = next(r for r in rows if r["clause"] == "B.8 6c")
    assert b86c["plan's justification"] == "'" + why  # in full, escaped
    assert b86c["assessor's decision"] == "" and b86c["comment"] == ""


# --- the command: the header, the figures, the trace, a stale report ---------------------------------------

def _workspace(root: Path) -> dict[str, Any]:
    report = _report()
    report["standards"] = standards_part([StandardChoice(load_builtin("iec61508-3"), "2", Loc("contracts/plan.yaml", 4, 5)),
                                          StandardChoice(load_builtin("ul4600"), None, Loc("contracts/plan.yaml", 5, 5))],
                                         report)["rows"]
    for rel, text in (("contracts/plan.yaml", "contracts: [robot.rcl]\n"), ("contracts/robot.rcl", "node Base {}\n"),
                      ("artifacts/evidence/Base.g1.review.e3.json", "{}\n")):
        (root / rel).parent.mkdir(parents=True, exist_ok=True)
        (root / rel).write_text(text, encoding="utf-8")
    (root / "reports").mkdir(exist_ok=True)
    (root / "reports/assurance.json").write_text(json.dumps(report), encoding="utf-8")
    return report


def _export(root: Path, report: dict[str, Any], csv_: Path | None = None, trace: Path | None = None,
            xlsx: Path | None = None) -> None:
    """What ``rclverify standards`` writes for ``report`` (cli/standards.py), without its freshness check,
    which a hand-made report cannot pass (tested below on a verified workspace)."""
    header = export_header(root, typed_report(report))
    matrix = matrix_rows(typed_report(report), evidence_digests(root, typed_report(report)))
    if csv_:
        write_csv(csv_, matrix, header)
    if trace:
        write_csv(trace, trace_rows(typed_report(report)), header)
    if xlsx:
        write_xlsx(xlsx, {"about this export": [["what", "value"], *header], "compliance matrix": matrix,
                          "trace matrix": trace_rows(typed_report(report))})


def _blocks(path: Path) -> tuple[list[list[str]], list[list[str]]]:
    with path.open(newline="", encoding="utf-8") as f:
        rows = list(csv.reader(f))
    cut = rows.index([])
    return rows[:cut], rows[cut + 1:]


def test_the_export_carries_a_header_the_figures_and_an_extended_trace(tmp_path: Path,
                                                                      capsys: pytest.CaptureFixture[str]) -> None:
    _export(tmp_path, _workspace(tmp_path), csv_=tmp_path / "m.csv", trace=tmp_path / "t.csv")
    header, table = _blocks(tmp_path / "m.csv")
    said = dict((r[0], r[1]) for r in header if r[0] != "contract")
    assert said["report sha256"] == hashlib.sha256((tmp_path / "reports/assurance.json").read_bytes()).hexdigest()
    assert said["rclverify version"] == "0.1.0" and said["Z3 version"] == "5.4.1"
    assert said["plan"] == "contracts/plan.yaml sha256 " + hashlib.sha256(b"contracts: [robot.rcl]\n").hexdigest()
    assert said["inputs sha256"] == "ab" * 32 and said["report written (UTC)"].endswith("+00:00")
    assert ["contract", "contracts/robot.rcl sha256 " + hashlib.sha256(b"node Base {}\n").hexdigest()] in header
    assert table[0] == list(MATRIX_COLUMNS)  # the header row of the table itself
    rows = [dict(zip(table[0], r)) for r in table[1:]]
    a51 = next(r for r in rows if r["clause"] == "A.5 1")
    assert (a51["runs (n)"], a51["violations"], a51["target"], a51["confidence"], a51["environment"],
            a51["origin"], a51["status"]) == ("60", "0", "5 %", "95 %", "day", "operation", "covered")
    assert a51["bound"] == "4.87 %" and a51["accepted kinds"] == "run-statistics"
    b86c = next(r for r in rows if r["clause"] == "B.8 6c")
    assert ("Base.g1.review.e3 (sha256 " + hashlib.sha256(b"{}\n").hexdigest()
            + ", started 2026-03-02T10:00:00+00:00)") in b86c["evidence that covers it"]
    # a record the workspace no longer holds says so
    assert "Lidar.g1.review.e1 (sha256 missing, started 2026-03-02T10:00:00+00:00)" in b86c["evidence that covers it"]
    assert b86c["items in scope and their state"] == "Lidar g1: covered; Base g1: covered"
    ul5 = next(r for r in rows if r["standard"].startswith("ANSI/UL 4600") and r["clause"] == "5")
    assert ul5["status"] == "partial" and "the safety case must add" in ul5["why"]
    _, trace = _blocks(tmp_path / "t.csv")
    assert trace[0] == list(TRACE_COLUMNS)
    tr = [dict(zip(trace[0], r)) for r in trace[1:]]
    proof = next(r for r in tr if r["obligation"] == "requirement STOP")
    assert proof["premises used"] == "Base guarantee 1: out.v <= 1" and proof["kind"] == "proof"
    sc = next(r for r in tr if r["obligation"] == "side condition Base.sc1")
    assert "IEC 61508-3:2010 A.4 4" in sc["clauses it supports"]
    tested = next(r for r in tr if r["obligation"] == "Base.g1.property_tests.e2")
    assert "IEC 61508-3:2010 B.2 1" in tested["clauses it supports"]


def test_the_workbook_has_the_header_sheet_and_text_cells(tmp_path: Path) -> None:
    openpyxl = pytest.importorskip("openpyxl")
    _export(tmp_path, _workspace(tmp_path), xlsx=tmp_path / "w.xlsx")
    wb = openpyxl.load_workbook(tmp_path / "w.xlsx")
    assert wb.sheetnames == ["about this export", "compliance matrix", "trace matrix"]
    about = {r[0].value: r[1].value for r in wb["about this export"].iter_rows(min_row=2)}
    assert about["report sha256"] == hashlib.sha256((tmp_path / "reports/assurance.json").read_bytes()).hexdigest()
    first = [c.value for c in next(wb["compliance matrix"].iter_rows(max_row=1))]
    assert first == list(MATRIX_COLUMNS)
    assert all(c.data_type == "s" for row in wb["compliance matrix"].iter_rows() for c in row if c.value is not None)


def test_every_clause_of_the_stored_case_study_is_one_row_agreeing_with_the_json() -> None:
    with gzip.open(REPO / "tests" / "data" / "case-study-report.json.gz", "rt", encoding="utf-8") as f:
        report = json.load(f)
    rows = matrix_rows(typed_report(report))
    assert rows[0] == list(MATRIX_COLUMNS) and all(len(r) == len(MATRIX_COLUMNS) for r in rows)
    want = [(c["id"], c["status"], c["why"]) for s in report["standards"] for c in s["clauses"]]
    col = MATRIX_COLUMNS.index
    assert [(r[col("clause")], r[col("status")], r[col("why")]) for r in rows[1:]] == want
    assert trace_rows(typed_report(report))[0] == list(TRACE_COLUMNS)


# --- the tool classification per chosen profile and level ----------------------------------------------------

@pytest.mark.parametrize("level,tql", [("A", "TQL-4"), ("B", "TQL-4"), ("C", "TQL-5"), ("D", "TQL-5")])
def test_the_tool_classification_names_the_criterion_and_tql_at_the_chosen_level(level: str, tql: str) -> None:
    from rclverify.report.templating import environment
    report = _report()
    rows = standards_part([StandardChoice(load_builtin("do-333"), level, Loc("contracts/plan.yaml", 4, 5))],
                          report)["rows"]
    text = " ".join(environment().get_template("parts/tool_classification.j2").render(rows=rows).split())
    assert f"criterion 2, so at software level {level} rclverify qualifies at {tql} " in text
    assert "T2 off-line support tool" in text and "7.4.4.6 then also asks" in text
    assert "UL 4600 clause 13" not in text  # control: said only when UL 4600 is chosen
    rows = standards_part([StandardChoice(load_builtin("ul4600"), None, Loc("contracts/plan.yaml", 4, 5))],
                          report)["rows"]
    text = " ".join(environment().get_template("parts/tool_classification.j2").render(rows=rows).split())
    assert "UL 4600 clause 13 asks the safety case to address the tools" in text and "software level" not in text


def test_iso13482_chosen_strict_does_not_pass_on_the_tools_evidence_alone() -> None:
    """ISO 13482 with strict: true passed --strict on a toy workspace: its clauses 5 and 7 are about the
    whole robot, never covered by the tool alone.  The control: a workspace profile's clause about the
    system, with nothing left to the safety case, is covered by the same evidence and passes."""
    from rclverify.model.plan.standards.profiles import parse_profile
    from rclverify.report.standards_rows import strict_reason
    report = _report()
    part = standards_part([StandardChoice(load_builtin("iso13482"), "d", Loc("contracts/plan.yaml", 4, 5),
                                          strict=True)], report)
    assert part["ok"] is False and part["rows"][0]["required_not_covered"] == ["5", "7"]
    assert strict_reason({"standards": part["rows"]}) == [
        "ISO 13482:2014 PL d: required items not covered (5, 7)"]
    tested = parse_profile("id: t\ntitle: T\nedition: T 1\nitems:\n  - {id: S, title: tested, about: system, "
                           "evidence: [property-tests, review], strength: tested, recommendation: required}\n", "t.yaml")
    part = standards_part([StandardChoice(tested, None, Loc("contracts/plan.yaml", 4, 5), strict=True)], report)
    assert part["ok"] is True and part["rows"][0]["clauses"][0]["status"] == "covered"
