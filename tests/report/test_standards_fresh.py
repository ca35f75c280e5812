"""``rclverify standards`` on a verified workspace (cli/standards.py, report/standards_export.py,
docs/standards.md "Exports"): the exports of the last report written, and a report that no longer says
what the workspace's files and recorded evidence give refused in one located line, compared by sha256,
never by modification time; each case beside its control."""
from __future__ import annotations

import csv
import gzip
import json
import os
import shutil
from pathlib import Path
from typing import Any

import pytest

from rclverify.cli.commands import main
from rclverify.report.standards_export import matrix_rows
from _typed_rows import typed_report

REPO = Path(__file__).resolve().parents[2]


def _read_csv(path: Path) -> list[dict[str, str]]:
    """The table of an exported CSV, after its header block (``[what, value]`` rows, then an empty row)."""
    with path.open(newline="", encoding="utf-8") as f:
        rows = list(csv.reader(f))
    rows = rows[rows.index([]) + 1:]
    return [dict(zip(rows[0], r)) for r in rows[1:]]


def _verified(root: Path) -> dict[str, Any]:
    """A one-node workspace with IEC 61508-3 SIL 2 mapped and a requirement, verified; its report."""
    (root / "contracts").mkdir()
    (root / "contracts/plan.yaml").write_text(
        "name: s\ncontracts: [contracts/robot.rcl]\nstandards:\n  - {profile: iec61508-3, sil: 2}\n"
        "requirements:\n  - {id: R1, text: y is never negative, supported_by: [{node: Base, guarantees: [1]}]}\n",
        encoding="utf-8")
    (root / "contracts/robot.rcl").write_text(
        "node Base {\n  inputs( x : INTEGER )\n  outputs( y : INTEGER )\n  guarantee( out.y >= 0 )\n}\n", encoding="utf-8")
    assert main(["verify", "-w", str(root)]) == 0
    report: dict[str, Any] = json.loads((root / "reports/assurance.json").read_text(encoding="utf-8"))
    return report


def _stored_report(root: Path) -> dict[str, Any]:
    """The stored case study's report (what a run writes), put in ``root/reports``."""
    with gzip.open(REPO / "tests" / "data" / "case-study-report.json.gz", "rt", encoding="utf-8") as f:
        report: dict[str, Any] = json.load(f)
    (root / "reports").mkdir(exist_ok=True)
    (root / "reports" / "assurance.json").write_text(json.dumps(report), encoding="utf-8")
    return report


def test_the_command_writes_the_exports_of_the_last_report(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A report a run wrote, read by the command: gaps printed, files written; the stored case study's
    report, whose files the workspace does not hold, is refused as not what the workspace gives."""
    report = _verified(tmp_path)
    capsys.readouterr()
    assert main(["standards", "-w", str(tmp_path), "--csv", str(tmp_path / "m.csv"),
                 "--trace", str(tmp_path / "t.csv")]) == 0
    out = capsys.readouterr().out
    assert out.startswith("IEC 61508-3:2010 SIL 2 (built-in profile): ") and "\n  B.8 6c [HR] " in out
    assert len(_read_csv(tmp_path / "m.csv")) == sum(len(s["clauses"]) for s in report["standards"])
    assert {r["requirement"] for r in _read_csv(tmp_path / "t.csv")} >= {"R1"}
    _stored_report(tmp_path)
    assert main(["standards", "-w", str(tmp_path), "--csv", str(tmp_path / "n.csv")]) == 1
    assert "run `rclverify verify` and export again" in capsys.readouterr().err and not (tmp_path / "n.csv").exists()


#: A workspace ``verify`` builds in seconds: one node, IEC 61508-3 at SIL 2 mapped.
_PLAN = "name: s\ncontracts: [contracts/robot.rcl]\nstandards:\n  - {profile: iec61508-3, sil: 2}\n"
_RCL = "node Base {\n  inputs( x : INTEGER )\n  outputs( y : INTEGER )\n  guarantee( out.y >= 0 )\n}\n"


@pytest.fixture(scope="module")
def verified(tmp_path_factory: pytest.TempPathFactory) -> Path:
    ws = tmp_path_factory.mktemp("standards_fresh") / "ws"
    (ws / "contracts").mkdir(parents=True)
    (ws / "contracts/plan.yaml").write_text(_PLAN, encoding="utf-8")
    (ws / "contracts/robot.rcl").write_text(_RCL, encoding="utf-8")
    assert main(["verify", "-w", str(ws)]) == 0
    return ws


def _refused(ws: Path, capsys: pytest.CaptureFixture[str]) -> str:
    capsys.readouterr()
    assert main(["standards", "-w", str(ws), "--csv", str(ws / "m.csv")]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"{ws / 'reports/assurance.json'}:1:1: error: ")
    assert err[0].endswith("run `rclverify verify` and export again") and not (ws / "m.csv").exists()
    return err[0]


def test_a_file_edited_and_given_back_an_older_time_is_caught_by_its_sha256(
        verified: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The report records its inputs' sha256 (meta.inputs_sha256): a file restored with an older
    modification time than the report's still differs in content."""
    ws = Path(shutil.copytree(verified, tmp_path / "ws"))
    rcl = ws / "contracts/robot.rcl"
    older = (ws / "reports/assurance.json").stat().st_mtime - 100
    rcl.write_text(_RCL.replace(">= 0", ">= 1"), encoding="utf-8")
    os.utime(rcl, (older, older))
    assert "built from other inputs than the workspace holds now" in _refused(ws, capsys)
    # the control: the same bytes given back are the report's inputs again, whatever their time
    rcl.write_text(_RCL, encoding="utf-8")
    later = (ws / "reports/assurance.json").stat().st_mtime + 100
    os.utime(rcl, (later, later))
    assert main(["standards", "-w", str(ws), "--csv", str(ws / "m.csv")]) == 0 and (ws / "m.csv").exists()


def test_a_plan_that_no_longer_loads_refuses_the_export(verified: Path, tmp_path: Path,
                                                        capsys: pytest.CaptureFixture[str]) -> None:
    """A verify that failed at the plan left the previous report: the command refuses it in one line."""
    ws = Path(shutil.copytree(verified, tmp_path / "ws"))
    (ws / "contracts/plan.yaml").write_text(_PLAN + "bogus_key: 1\n", encoding="utf-8")
    assert "no longer build a report (contracts/plan.yaml:" in _refused(ws, capsys)


def test_a_workspace_profile_file_changed_is_caught_and_the_report_as_verified_is_exported(
        verified: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    ws = Path(shutil.copytree(verified, tmp_path / "ws"))
    assert main(["standards", "-w", str(ws), "--csv", str(ws / "m.csv")]) == 0  # the control
    report = json.loads((ws / "reports/assurance.json").read_text(encoding="utf-8"))
    edition = report["standards"][0]["origin"]["edition"]
    report["standards"][0]["origin"] = {"kind": "workspace", "file": "std/mine.yaml", "sha256": "0" * 64}
    (ws / "std").mkdir()
    (ws / "std/mine.yaml").write_text("id: mine\n", encoding="utf-8")
    (ws / "m.csv").unlink()
    # an origin without its edition is no standard's row: refused in one line before anything is compared
    (ws / "reports/assurance.json").write_text(json.dumps(report), encoding="utf-8")
    capsys.readouterr()
    assert main(["standards", "-w", str(ws), "--csv", str(ws / "m.csv")]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "not an rclverify report" in err[0] and "edition" in err[0] and "Traceback" not in err[0]
    report["standards"][0]["origin"]["edition"] = edition
    (ws / "reports/assurance.json").write_text(json.dumps(report), encoding="utf-8")
    assert "built from another std/mine.yaml (sha256 000000000000..." in _refused(ws, capsys)


def test_without_openpyxl_the_workbook_is_one_line_naming_the_extra(tmp_path: Path) -> None:
    """In an interpreter that cannot import openpyxl: one line, exit 1, no workbook; the CSV still works."""
    from _blocked import cli_without
    report = _verified(tmp_path)
    r = cli_without("openpyxl", "standards", "-w", str(tmp_path), "--xlsx", str(tmp_path / "w.xlsx"))
    assert r.returncode == 1 and "Traceback" not in r.stderr and not (tmp_path / "w.xlsx").exists()
    assert r.stderr.strip().splitlines() == [
        "error: an XLSX export of the compliance matrix needs rclverify's [xlsx] extra (openpyxl is not installed): "
        "pip install 'rclverify[xlsx]'"]
    r = cli_without("openpyxl", "standards", "-w", str(tmp_path), "--csv", str(tmp_path / "m.csv"))
    assert r.returncode == 0 and len(_read_csv(tmp_path / "m.csv")) == len(matrix_rows(typed_report(report))) - 1
