"""The diagnosis stage (stages/diagnoses.py, app/pipeline.py ``stage_diagnosis``): it explains the report's
problems into a sealed record; the report reads that record and never diagnoses.

On the newcomer's three-node system (tests/data/newcomer: Controller's side condition fails, two repairs):
the record is the diagnoses of the report without diagnoses; ``build_report`` attaches it while it is
current, and says why the problems are not explained when it is missing, altered or made from another
report; the orchestrator's report runs the stage again then; the report's modules load no diagnosis
analysis; ``doit verify`` runs the stage as a task of its own, again after a contract edit only.
"""
from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from rclverify.app.pipeline import (Workspace, diagnosed, stage_check, stage_compose, stage_diagnosis, stage_export,
                                    stage_health, stage_report)
from rclverify.diagnosis.build import diagnose
from rclverify.diagnosis.shapes import report_rows
from rclverify.records.report_record import AssuranceReport
from rclverify.records.sealed import is_sealed_path, read_sealed
from rclverify.report.build import build_report, undiagnosed_report
from rclverify.stages.diagnoses import INDEX, report_digest

REPO = Path(__file__).resolve().parents[2]
RCL = "contracts/rover.rcl"


@pytest.fixture()
def newcomer(tmp_path: Path) -> Path:
    shutil.copytree(REPO / "tests" / "data" / "newcomer", tmp_path / "ws")
    return tmp_path / "ws"


def _stages(root: Path) -> Workspace:
    """Every stage of ``root`` up to (not including) the diagnosis."""
    ws = Workspace(root)
    stage_check(ws)
    for n in ws.node_names():
        stage_compose(ws, n)
        stage_health(ws, n)
        stage_export(ws, n)
    return ws


def _problems(report: AssuranceReport) -> list[str]:
    return [p for p in report.summary.problems if p.startswith("Diagnoses: ")]


def test_the_stage_seals_the_diagnoses_of_the_report_and_the_report_reads_them(newcomer: Path) -> None:
    ws = _stages(newcomer)
    pre = undiagnosed_report(ws)
    assert "diagnoses" not in pre
    record = stage_diagnosis(ws, pre)
    assert is_sealed_path(INDEX)
    on_disk, why = read_sealed(ws.path(INDEX))
    assert not why and on_disk == record
    assert record["report_sha256"] == report_digest(pre) == report_digest(undiagnosed_report(ws))
    want = json.loads(json.dumps(diagnose(ws, report_rows(pre)), sort_keys=True))
    assert record["diagnoses"] == want and [d["id"] for d in want][:1] == ["Controller.sc2"]
    assert want[0]["repairs"]  # Z3 checked repairs: the stage did the analysis
    report = build_report(ws)
    assert report.to_json()["diagnoses"] == want and _problems(report) == []
    assert report == diagnosed(ws)  # the orchestrator's report is the same when the record is current


def test_a_missing_record_is_said_never_shown_as_no_problem(newcomer: Path) -> None:
    ws = _stages(newcomer)
    report = build_report(ws)
    assert report.diagnoses == [] and report.summary.diagnoses == []
    (said,) = _problems(report)
    assert "the diagnosis stage has not run" in said and INDEX in said and "doit verify" in said


def test_a_record_of_another_report_is_stale_and_the_orchestrator_makes_it_again(newcomer: Path) -> None:
    ws = _stages(newcomer)
    stage_diagnosis(ws)
    old = read_sealed(ws.path(INDEX))[0]
    rcl = newcomer / RCL
    rcl.write_text(rcl.read_text(encoding="utf-8").replace("1.5", "1.25"), encoding="utf-8")
    ws = _stages(newcomer)  # the edited contract checked and composed again, the diagnosis not
    report = build_report(ws)
    (said,) = _problems(report)
    assert "made from other artifacts than this report" in said and report.diagnoses == []
    again, paths = stage_report(ws, ("text",))  # the orchestrator runs the stage first
    assert paths and _problems(again) == [] and again.diagnoses
    new = read_sealed(ws.path(INDEX))[0]
    assert new is not None and old is not None and new["report_sha256"] != old["report_sha256"]
    assert "1.25" in json.dumps(again.to_json()["diagnoses"]) and build_report(ws) == again


def test_an_altered_record_is_not_believed(newcomer: Path) -> None:
    ws = _stages(newcomer)
    stage_diagnosis(ws)
    path = ws.path(INDEX)
    path.write_text(path.read_text(encoding="utf-8").replace("Controller", "Planner", 1), encoding="utf-8")
    report = build_report(ws)
    (said,) = _problems(report)
    assert "altered outside rclverify" in said and report.diagnoses == []


def test_the_report_loads_no_diagnosis_analysis(newcomer: Path) -> None:
    """Building the report imports no module of diagnosis/ that diagnoses (the stage's build, repairs,
    blame, re-checks): only the pure text helpers it reads records with."""
    ws = _stages(newcomer)
    stage_diagnosis(ws)
    code = ("import sys; from pathlib import Path; from rclverify.stages.workspace import Workspace; "
            "from rclverify.report.build import build_report; r = build_report(Workspace(Path(sys.argv[1]))); "
            "assert r.diagnoses, 'no diagnoses read'; "
            "print(sorted(m for m in sys.modules if m.startswith('rclverify.diagnosis.')))")
    out = subprocess.run([sys.executable, "-c", code, str(newcomer)], capture_output=True, text=True, check=True)
    loaded = set(json.loads(out.stdout.replace("'", '"')))
    assert not loaded & {"rclverify.diagnosis.build", "rclverify.diagnosis.repairs", "rclverify.diagnosis.blame",
                         "rclverify.diagnosis.recheck", "rclverify.diagnosis.sidecond"}, loaded


def _verify(root: Path) -> str:
    p = subprocess.run([sys.executable, "-m", "doit", "-f", str(root / "dodo.py"), "-d", str(root), "verify"],
                       capture_output=True, text=True, check=False, cwd=root)
    assert p.returncode == 0, p.stdout[-2000:] + p.stderr[-2000:]
    return p.stdout


def test_doit_runs_the_stage_as_a_task_again_only_when_its_inputs_change(newcomer: Path) -> None:
    shutil.copy(REPO / "dodo.py", newcomer / "dodo.py")
    first = _verify(newcomer)
    assert "diagnosis: " in first and "problem(s) explained" in first
    report = json.loads((newcomer / "reports" / "assurance.json").read_text(encoding="utf-8"))
    assert report["diagnoses"] and not _problems(AssuranceReport.of(report))
    assert "diagnosis: " not in _verify(newcomer)  # nothing changed: the task is up to date
    rcl = newcomer / RCL
    rcl.write_text(rcl.read_text(encoding="utf-8").replace("1.5", "1.25"), encoding="utf-8")
    third = _verify(newcomer)
    assert "diagnosis: " in third
    edited = json.loads((newcomer / "reports" / "assurance.json").read_text(encoding="utf-8"))
    assert "1.25" in json.dumps(edited["diagnoses"]) and not _problems(AssuranceReport.of(edited))


def test_the_digest_leaves_out_when_and_how_long_a_run_took() -> None:
    """Two runs of the same inputs differ only in their timings: one digest (a clean run's record is an
    incremental run's); a changed status is another report."""
    from rclverify.stages.diagnoses import report_digest
    one = {"evidence": [{"id": "N.g1.hoare", "status": "discharged", "duration_s": 0.06,
                         "started": "2026-11-27T05:17:25+00:00"}], "meta": {"inputs_sha256": {"a.rcl": "ab"}}}
    two = {"evidence": [{"id": "N.g1.hoare", "status": "discharged", "duration_s": 0.005,
                         "started": "2026-11-27T05:17:23+00:00"}], "meta": {"inputs_sha256": {"a.rcl": "ab"}}}
    failed = {**two, "evidence": [{**two["evidence"][0], "status": "failed"}]}
    assert report_digest(one) == report_digest(two) != report_digest(failed)
    # a timing inside a row's record (a requirement's check) is left out too, and nothing else is
    req = {"id": "REQ1", "verdict": "met", "check": {"verdict": "proved", "duration_s": 0.4}}
    slow = {**one, "requirements": [req]}
    quick = {**one, "requirements": [{**req, "check": {**req["check"], "duration_s": 0.1}}]}
    refuted = {**one, "requirements": [{**req, "check": {"verdict": "refuted", "duration_s": 0.4}}]}
    assert report_digest(slow) == report_digest(quick) != report_digest(refuted)
