"""A monitor violation's code repair, checked by re-running the node's rclpy callback on the recorded run
(diagnosis/run_repair.py, docs/diagnosis.md "Monitor violations: a node re-run on its recorded run").

The run is a real live log of examples/manipulator with its ``charge_lt`` defect (the ChargeMonitor
compares with ``<`` where the contract says ``<=`` at the float32 0.2), recorded by ``watch.py`` (6
rounds, the rclpy source) and kept in ``data/``.  The node is re-run in the ROS 2 Python with discovery
off: nothing is published or heard.  Controls: the repaired callback is judged discharged on the run
(again through ``rejudged``) where the defective one failed (the repair's cost); the correct robot does
not reproduce the defect's recorded answers, so nothing is offered on it.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from _ros2 import ros2_python

from rclverify.diagnosis.edits import Edit
from rclverify.diagnosis.run_repair import rejudged, run_repairs

REPO = Path(__file__).resolve().parents[2]
ROOT = REPO / "examples" / "manipulator"
LOG = Path(__file__).parent / "data" / "manipulator_charge_lt.jsonl"


@pytest.fixture(scope="module")
def ws() -> tuple[Any, Any, Path]:
    from rclverify.app.pipeline import Workspace
    from rclverify.backends.monitors.config import load_mapping
    return Workspace(ROOT).checked, load_mapping(ROOT, "contracts/mapping.yaml", None), ros2_python()


def test_the_charge_monitors_slip_is_repaired_and_checked_on_its_run(ws: tuple[Any, Any, Path]) -> None:
    checked, cfg, python = ws
    text = (ROOT / "robot.py").read_text(encoding="utf-8")
    seeded = next(k for k, x in enumerate(text.splitlines(), 1) if 'bad("charge_lt")' in x)
    got = run_repairs(ROOT, checked, cfg, LOG, "ChargeMonitor", False, "robot.py", "build", [["charge_lt"]], python)
    assert got.repairs, got.why
    first = got.repairs[0]
    assert got.line == f"robot.py:{seeded}"  # the line with the slip, not the callback's first line
    assert (first["edit"]["deleted"], first["edit"]["inserted"]) == ("<", "<=")
    assert first["checks"] == [{"check": "ChargeMonitor", "status": "discharged"}]
    assert first["cost"] == [{"check": "ChargeMonitor", "before": "failed", "after": "discharged"}]
    e = first["edit"]
    repaired = Edit("robot.py", e["line"], e["col"], e["end_line"], e["end_col"], e["inserted"]).apply(text)
    after = rejudged(ROOT, checked, cfg, LOG, "ChargeMonitor", False, "robot.py", repaired, "build",
                     [["charge_lt"]], python)
    assert after["ChargeMonitor"][0] == "discharged"  # the other side: the cost's "before" is the defect's failed
    assert {k for k, v in after.items() if v[0] == "failed"} == set()


def test_a_node_whose_code_does_not_give_the_recorded_answers_is_not_repaired(ws: tuple[Any, Any, Path]) -> None:
    checked, cfg, python = ws
    got = run_repairs(ROOT, checked, cfg, LOG, "ChargeMonitor", False, "robot.py", "build", [[]], python)
    assert got.repairs == [] and "does not give the recorded answers" in got.why
    assert got.line.startswith("robot.py:")


# The report's diagnosis of a monitored violation (diagnosis/monitor_repair.py): the plan's monitors entry
# names the function making the node (implementation: charge.py:build), so `rclverify verify` re-runs it.
CHARGE_WS = Path(__file__).parent / "data" / "charge_ws"


def _named(python: Path, argv: list[str]) -> int:
    """``rclverify ARGV`` in process with the ROS 2 Python named (``RCLVERIFY_ROS2_PYTHON``), as it was after."""
    import os

    from rclverify.cli.commands import main
    before = os.environ.get("RCLVERIFY_ROS2_PYTHON")
    os.environ["RCLVERIFY_ROS2_PYTHON"] = str(python)
    try:
        return main(argv)
    finally:
        if before is None:
            del os.environ["RCLVERIFY_ROS2_PYTHON"]
        else:
            os.environ["RCLVERIFY_ROS2_PYTHON"] = before


def _verify(ws: Path, python: Path) -> tuple[dict[str, Any], str]:
    """``rclverify verify`` in process with the ROS 2 Python named: the report and its Markdown."""
    import json
    _named(python, ["verify", "-w", str(ws)])
    return (json.loads((ws / "reports/assurance.json").read_text(encoding="utf-8")),
            (ws / "reports/assurance.md").read_text(encoding="utf-8"))


def _editor_and_sarif(work: Path) -> None:
    """The repair as a SARIF 2.1.0 fix saying what checked it, and as the editor's quick fix on the result's
    line (the node's header in its contract), editing the Python file."""
    import json

    from lsprotocol import types as lsp

    from rclverify.tools.lsp.actions import quick_fixes
    from rclverify.tools.lsp.workspace import LspWorkspace
    sarif = json.loads((work / "reports/assurance.sarif").read_text(encoding="utf-8"))
    [res] = [r for r in sarif["runs"][0]["results"] if r.get("fixes")]
    [fix] = res["fixes"]
    assert "The monitors backend on the recorded run, the node re-run in rclpy shows" in fix["description"]["text"]
    [change] = fix["artifactChanges"]
    assert change["artifactLocation"]["uri"] == "charge.py"
    assert change["replacements"][0]["insertedContent"]["text"] == "<="
    rel = "contracts/charge.rcl"
    at = lsp.Range(lsp.Position(1, 0), lsp.Position(1, 4))
    params = lsp.CodeActionParams(lsp.TextDocumentIdentifier((work / rel).as_uri()), at, lsp.CodeActionContext([]))
    [action] = quick_fixes(LspWorkspace(work), {}, rel, params)
    assert action.title.startswith("At charge.py:17, change") and action.edit is not None
    [(uri, [edit])] = list((action.edit.changes or {}).items())
    assert uri.endswith("/charge.py") and edit.new_text == "<=" and edit.range.start == lsp.Position(16, 26)
    elsewhere = lsp.CodeActionParams(params.text_document, lsp.Range(lsp.Position(5, 0), lsp.Position(5, 4)),
                                     lsp.CodeActionContext([]))
    assert quick_fixes(LspWorkspace(work), {}, rel, elsewhere) == []  # the control: another line offers none


def test_the_report_shows_the_run_checked_repair_of_a_monitored_violation_and_reruns_it_only_on_change(
        ws: tuple[Any, Any, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    import shutil
    python = ws[2]
    work = tmp_path / "ws"
    shutil.copytree(CHARGE_WS, work)
    oid = "ChargeMonitor.g0.monitors.charge_jsonl"
    report, md = _verify(work, python)
    [d] = [x for x in report["diagnoses"] if x["id"] == oid]
    [rep] = d["repairs"]  # `<` for `<=` at the slip, checked on the run; nothing else passes
    assert (rep["edit"]["line"], rep["edit"]["deleted"], rep["edit"]["inserted"]) == (17, "<", "<=")
    assert rep["cost"] == [{"check": "ChargeMonitor", "before": "failed", "after": "discharged"}]
    assert "charge.py:17" in d["sentence"] and d["culprits"][0]["source"] == "charge.py:17"
    [row] = [p for p in report["problems"] if p["members"][0]["id"] == oid]
    assert row["repairs"] == [{"diagnosis": oid, "index": 0}]
    first = md.split("## What needs attention", 1)[1].split("\n## ", 1)[0]  # the first screen's problems
    assert "At charge.py:17, change" in first and "The monitors backend on the recorded run" in first
    assert "+        data=m.percentage <= limit)), 100)" in md
    _editor_and_sarif(work)
    index = work / "artifacts/diagnosis/index.json"
    sealed = index.read_bytes()
    _verify(work, python)  # nothing changed: the diagnosis is not made again
    assert index.read_bytes() == sealed
    capsys.readouterr()
    assert _named(python, ["repair", oid, "--apply", "-w", str(work)]) == 0
    said = capsys.readouterr().out
    assert f"{oid}: failed -> discharged" in said and "until the run is recorded again" in said
    again, _ = _verify(work, python)  # the code changed: the run's evidence and its diagnosis are made again
    [d2] = [x for x in again["diagnoses"] if x["id"] == oid]
    assert d2["repairs"] == [] and "does not give the recorded answers" in d2["not_offered"][0]
    clean = tmp_path / "clean"
    shutil.copytree(CHARGE_WS, clean)
    shutil.copy(work / "charge.py", clean / "charge.py")
    fresh, _ = _verify(clean, python)  # incremental equals clean
    assert [x for x in fresh["diagnoses"] if x["id"] == oid] == [d2]


def test_control_a_monitors_entry_naming_no_implementation_offers_nothing(ws: tuple[Any, Any, Path],
                                                                          tmp_path: Path) -> None:
    import shutil
    work = tmp_path / "ws"
    shutil.copytree(CHARGE_WS, work)
    plan = work / "contracts/plan.yaml"
    plan.write_text(plan.read_text(encoding="utf-8").replace("        implementation: charge.py:build\n", ""),
                    encoding="utf-8")
    report, _ = _verify(work, ws[2])
    [d] = [x for x in report["diagnoses"] if x["id"] == "ChargeMonitor.g0.monitors.charge_jsonl"]
    assert d["status"] == "failed" and d["repairs"] == [] and "not_offered" not in d
