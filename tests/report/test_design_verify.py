"""The design stage of ``doit verify`` (docs/nodl.md, "The design stage"): a plan naming an Autoware System
Designer design (``design: DIR``) has its monitoring fields decided by the pipeline, incrementally, with the
verdicts and findings in reports/assurance.json and the Markdown report.

tests/model/test_design.py's design of our own is imported into a workspace (its filter answers within 150 ms)
and copied into it; the plan names it.  Verified as it is (the control): every timeout and rate proved but the
goal's, which nothing bounds (undecided, a warning).  Run again with nothing changed, the stage does not run.
With the filter's contract deadline made 250 ms (the seeded defect), the tracker's timeout (300 ms) and error
rate (4 Hz) and the planner's timeout (600 ms) are refuted, each at the design's field and at the contract
clauses of its chain, and ``--strict`` fails on them.
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from _report_schema import check_report
from rclverify.cli.commands import main
from rclverify.stages.design import INDEX
from test_design import _design

pytestmark = pytest.mark.slow  # two runs of the whole pipeline


def _read(ws: Path) -> Any:
    return json.loads((ws / "reports" / "assurance.json").read_text(encoding="utf-8"))


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    root = tmp_path_factory.mktemp("design_verify")
    _design(root / "design")
    assert main(["import", "autoware-design", str(root / "design"), "-o", str(root / "ws")]) == 0
    ws = root / "ws"
    _design(ws / "design")
    plan = ws / "contracts" / "plan.yaml"
    plan.write_text(plan.read_text(encoding="utf-8").rstrip("\n") + "\ndesign: design\n", encoding="utf-8")
    out: dict[str, Any] = {"ws": ws, "code": main(["verify", "-w", str(ws)]), "clean": _read(ws),
                           "clean_md": (ws / "reports" / "assurance.md").read_text(encoding="utf-8")}
    made = (ws / INDEX).stat().st_mtime_ns
    out["again"] = main(["verify", "-w", str(ws)])
    out["rerun"] = (ws / INDEX).stat().st_mtime_ns != made
    rcl = ws / "contracts" / "design.rcl"
    rcl.write_text(rcl.read_text(encoding="utf-8").replace("in.points within 150 ms", "in.points within 250 ms"),
                   encoding="utf-8")
    out["strict"] = main(["verify", "-w", str(ws), "--strict"])
    out["seeded"] = _read(ws)
    out["seeded_md"] = (ws / "reports" / "assurance.md").read_text(encoding="utf-8")
    return out


def test_the_design_that_fits_is_proved_by_verify(runs: dict[str, Any]) -> None:
    report = runs["clean"]
    check_report(report, "design clean")
    d = report["design"]
    assert runs["code"] == 0 and d["design"] == "design" and d["system"] == "Rover"
    assert (d["counts"]["proved"], d["counts"]["refuted"], d["counts"]["undecided"], d["counts"]["error"]) == (5, 0, 1, 0)
    tracker = [f for f in d["decided"] if f["node"] == "perception_tracker" and f["field"] == "timeout"]
    assert tracker and tracker[0]["status"] == "proved" and tracker[0]["bound"] == "250 ms" and tracker[0]["limit"] == "300 ms"
    assert [f["code"] for f in d["findings"]] == ["design-undecided"]
    assert set(d["inputs"]) >= {"contracts/plan.yaml", "contracts/design.rcl", "design/node/Tracker.node.yaml"}
    assert "stale" not in d and not [p for p in report["summary"]["problems"] if p.startswith("design")]
    assert "## Design: monitoring fields against the contracts" in runs["clean_md"]
    assert "| perception\\_tracker | in.objects | timeout | 300 ms | 250 ms | **proved** |" in runs["clean_md"]


def test_the_stage_does_not_run_again_when_nothing_changed(runs: dict[str, Any]) -> None:
    assert runs["again"] == 0 and runs["rerun"] is False


def test_a_deadline_the_design_cannot_meet_is_refuted_in_the_report_and_fails_strict(runs: dict[str, Any]) -> None:
    report, ws = runs["seeded"], runs["ws"]
    check_report(report, "design seeded")
    d = report["design"]
    assert (d["counts"]["refuted"], d["counts"]["error"]) == (3, 3) and "stale" not in d
    timeout = [f for f in d["findings"] if f["code"] == "design-timeout" and f["message"].startswith("perception_tracker ")]
    assert len(timeout) == 1 and "350 ms > 300 ms" in timeout[0]["message"]
    places = [p["file"] for p in timeout[0]["places"]]
    assert places == ["design/node/Tracker.node.yaml", "contracts/design.rcl", "contracts/design.rcl"]
    tracker_yaml = (ws / "design/node/Tracker.node.yaml").read_text(encoding="utf-8").splitlines()
    assert "timeout: 0.3" in tracker_yaml[timeout[0]["places"][0]["line"] - 1]
    assert any(p.startswith("design design-timeout at design/node/Tracker.node.yaml:") for p in report["summary"]["problems"])
    assert runs["strict"] != 0 and report["meta"]["strict_ok"] is False
    assert "| perception\\_tracker | in.objects | timeout | 300 ms | 350 ms | **refuted** |" in runs["seeded_md"]
