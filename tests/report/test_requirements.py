"""System requirements checked with Z3, not just traced (issue 21).

The three-node system of tests/data/requirements/stop (ObstacleDetector ->
SpeedController -> MotorDriver) with the requirement "the robot stops when an
obstacle is closer than 0.5 m": with the 0.5 m controller it is proved and,
every obligation being discharged by the Hoare backend, met; with a 0.3 m
controller every obligation still discharges (the Hoare program is the same),
but the requirement is refuted with a counterexample, in the report JSON,
SARIF and JUnit.  Real doit, Z3, Doorstop.
"""
from __future__ import annotations

import json
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET
from fractions import Fraction
from pathlib import Path

import pytest

from rclverify.cli.commands import main
from rclverify.app.pipeline import Workspace, stage_check, stage_requirements

DATA = Path(__file__).parent.parent / "data" / "requirements" / "stop"


def _copy(tmp: Path, controller_m: str = "0.5") -> Path:
    ws = tmp / f"stop-{controller_m}"
    shutil.copytree(DATA, ws)
    if controller_m != "0.5":
        rcl = ws / "contracts/stop.rcl"
        rcl.write_text(rcl.read_text().replace("in.distance < 0.5 ->", f"in.distance < {controller_m} ->"))
    return ws


def _verify(ws: Path) -> subprocess.CompletedProcess[str]:
    r = subprocess.run([sys.executable, "-m", "doit", "verify"], cwd=ws, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stdout + r.stderr
    (ws / "verify.out").write_text(r.stdout)
    return r


def _reqs(ws: Path) -> dict[str, dict]:
    report = json.loads((ws / "reports/assurance.json").read_text())
    return {r["id"]: r for r in report["requirements"]}


@pytest.fixture(scope="module")
def proved(tmp_path_factory: pytest.TempPathFactory) -> Path:
    ws = _copy(tmp_path_factory.mktemp("req"))
    _verify(ws)
    return ws


@pytest.fixture(scope="module")
def refuted(tmp_path_factory: pytest.TempPathFactory) -> Path:
    ws = _copy(tmp_path_factory.mktemp("req"), "0.3")
    _verify(ws)
    return ws


def test_05_controller_proves_the_requirement_and_it_is_met(proved: Path) -> None:
    reqs = _reqs(proved)
    stop = reqs["STOP"]
    assert (stop["verdict"], stop["status"]) == ("met", "discharged")
    assert [p["label"] for p in stop["check"]["used"]] == ["SpeedController guarantee 1"]
    assert stop["check"]["used"][0]["source"] == "contracts/stop.rcl:15:14"
    assert stop["check"]["consistency"] == "consistent" and stop["check"]["vacuity"] == "non-vacuous"
    # an informal requirement is traced, never met
    assert (reqs["SAFE"]["verdict"], reqs["SAFE"]["status"]) == ("informal", "pending")
    sarif = json.loads((proved / "reports/assurance.sarif").read_text())
    ids = {res["ruleId"] for res in sarif["runs"][0]["results"]}
    assert "RCL-REQ-REFUTED" not in ids and "RCL-REQ-INFORMAL" in ids
    cases = {c.get("name"): c for c in ET.parse(proved / "reports/assurance.junit.xml").iter("testcase")
             if c.get("classname") == "requirement"}
    assert set(cases) == {"STOP", "STILL", "SAFE", "DIST"}
    assert len(cases["STOP"]) == 0  # passed: no failure/skipped child
    assert cases["SAFE"].find("skipped") is not None
    md = (proved / "reports/assurance.md").read_text()
    assert "**STOP** ✅ discharged _met_" in md and "**SAFE** ⏳ **pending** _informal_" in md


def test_03_controller_refutes_it_with_a_counterexample_though_every_obligation_discharges(refuted: Path) -> None:
    report = json.loads((refuted / "reports/assurance.json").read_text())
    assert {o["status"] for o in report["obligations"]} == {"discharged"}  # the green-looking case
    stop = {r["id"]: r for r in report["requirements"]}["STOP"]
    assert (stop["verdict"], stop["status"]) == ("refuted", "failed")
    cex = {row["node"]: row["values"] for row in stop["check"]["counterexample"]}
    d = Fraction(cex["SpeedController"]["in.distance"])
    assert Fraction(3, 10) <= d < Fraction(1, 2)
    assert cex["ObstacleDetector"]["out.distance"] == cex["SpeedController"]["in.distance"]
    assert Fraction(cex["MotorDriver"]["in.speed_cmd"]) != 0
    assert [p["label"] for p in stop["check"]["failed_to_prevent"]] == ["SpeedController guarantee 1"]
    assert any("Requirement STOP is refuted" in p for p in report["summary"]["problems"])
    sarif = json.loads((refuted / "reports/assurance.sarif").read_text())
    res = [r for r in sarif["runs"][0]["results"] if r["ruleId"] == "RCL-REQ-REFUTED"]
    assert len(res) == 1 and res[0]["level"] == "error"
    region = res[0]["locations"][0]["physicalLocation"]
    assert region["artifactLocation"]["uri"] == "contracts/plan.yaml" and region["region"]["startLine"] == 7
    assert "SpeedController: in.distance = " in res[0]["message"]["text"]
    case = [c for c in ET.parse(refuted / "reports/assurance.junit.xml").iter("testcase")
            if c.get("classname") == "requirement" and c.get("name") == "STOP"][0]
    failure = case.find("failure")
    assert failure is not None and "counterexample: ObstacleDetector:" in (failure.text or "")
    els = {e["id"]: e for e in json.loads((refuted / "reports/argument.json").read_text())["elements"]}
    assert els["G-STOP"]["status"] == "failed"
    assert els["S-STOP"]["text"].startswith("Argument by formal entailment")
    assert els["S-STOP"]["supported_by"] == ["Sn-req.STOP"] and els["Sn-req.STOP"]["status"] == "failed"
    assert els["G-SAFE"]["undeveloped"] is True  # informal: an undeveloped goal


def test_the_met_requirement_goal_rests_on_the_proof_and_the_evidence_of_the_guarantees_used(proved: Path) -> None:
    els = {e["id"]: e for e in json.loads((proved / "reports/argument.json").read_text())["elements"]}
    assert els["G-STOP"]["status"] == "discharged"
    assert els["S-STOP"]["supported_by"][:2] == ["Sn-req.STOP", "G-SpeedController.g1"]


def test_verify_ends_with_the_requirements_line(refuted: Path, proved: Path) -> None:
    assert "requirements: 1 refuted (STOP), 2 met, 1 informal\n" in (refuted / "verify.out").read_text()
    assert "requirements: 3 met, 1 informal\n" in (proved / "verify.out").read_text()


def test_the_html_report_shows_the_checks_with_balanced_tags(refuted: Path) -> None:
    from test_report_render import _TagBalance
    html = (refuted / "reports/assurance.html").read_text()
    parser = _TagBalance()
    parser.feed(html)
    assert parser.errors == [] and parser.stack == []
    section = html[html.index('id="requirement-checks"'):html.index('<section id="calculus">')]
    assert ">refuted</span>" in section and "did not prevent it: SpeedController guarantee 1" in section
    assert "SpeedController (in.distance = <code>" in section


def test_the_cli_prints_the_counterexample_and_exits_1(refuted: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["requirements", "-w", str(refuted)]) == 1
    out = capsys.readouterr().out
    assert "STOP: refuted [failed]" in out
    assert "counterexample SpeedController: in.distance = " in out
    assert "did not prevent it: SpeedController guarantee 1" in out
    assert "DIST: met [discharged]" in out


def test_an_edit_rechecks_only_the_requirements_whose_cone_contains_it(tmp_path: Path) -> None:
    ws = _copy(tmp_path)
    w = Workspace(ws)
    stage_check(w)
    assert all(now for _, now in stage_requirements(w))
    w = Workspace(ws)
    stage_check(w)
    assert not any(now for _, now in stage_requirements(w))
    rcl = ws / "contracts/stop.rcl"
    rcl.write_text(rcl.read_text().replace("0 <= out.speed_cmd <= 1", "0 <= out.speed_cmd <= 2"))
    w = Workspace(ws)
    stage_check(w)
    again = {rec["id"] for rec, now in stage_requirements(w) if now}
    assert again == {"STOP", "STILL"}  # DIST's cone is ObstacleDetector alone; SAFE is informal


def _tiny(tmp: Path, rcl: str, formal: str, assuming: str | None = None) -> Path:
    ws = tmp / "tiny"
    (ws / "contracts").mkdir(parents=True)
    (ws / "contracts/n.rcl").write_text(rcl)
    extra = f"\n    assuming: {json.dumps(assuming)}" if assuming else ""
    (ws / "contracts/plan.yaml").write_text(
        "contracts: [contracts/n.rcl]\nrequirements:\n  - id: R\n    text: a requirement\n"
        f"    formal: {json.dumps(formal)}{extra}\n")
    return ws


def _check(ws: Path) -> dict:
    from rclverify.report.build import build_report
    w = Workspace(ws)
    stage_check(w)
    stage_requirements(w)
    return build_report(w).to_json()["requirements"][0]


def test_a_proof_from_inconsistent_guarantees_is_not_met(tmp_path: Path) -> None:
    ws = _tiny(tmp_path, "node N { inputs( x : REAL ) outputs( y : REAL )\n"
                         "  guarantee( out.y > 1 )\n  guarantee( out.y < 0 ) }\n", "N.out.y == 5")
    r = _check(ws)
    assert r["verdict"] == "proved from an inconsistency" and r["status"] == "failed"
    assert [p["label"] for p in r["check"]["inconsistent_core"]] == ["N guarantee 1", "N guarantee 2"]


def test_a_proof_whose_premise_never_holds_is_vacuous_not_met(tmp_path: Path) -> None:
    ws = _tiny(tmp_path, "node N { inputs( x : REAL ) outputs( y : REAL )\n  assume( in.x >= 0 )\n"
                         "  guarantee( out.y == in.x ) }\n", "N.in.x < 0 -> N.out.y == 7")
    r = _check(ws)
    assert r["verdict"] == "proved vacuously" and r["status"] == "failed"
    assert [p["label"] for p in r["check"]["vacuity_core"]] == ["N environment assumption 1"]


def test_assuming_is_a_premise_of_this_requirement_only(tmp_path: Path) -> None:
    rcl = "node N { inputs( x : REAL ) outputs( y : REAL )\n  guarantee( out.y == 2 * in.x ) }\n"
    assert _check(_tiny(tmp_path / "a", rcl, "N.out.y <= 10"))["verdict"] == "refuted"
    r = _check(_tiny(tmp_path / "b", rcl, "N.out.y <= 10", "N.in.x <= 5"))
    assert r["verdict"] == "proved, evidence outstanding"
    assert [p["label"] for p in r["check"]["used"]] == ["N guarantee 1", "assuming 1"]


def test_doorstop_items_are_read_checked_and_shown_per_uid(tmp_path: Path) -> None:
    ws = _copy(tmp_path)
    assert main(["requirements", "-w", str(ws), "--plan", "contracts/plan_doorstop.yaml"]) == 1
    from rclverify.report.build import build_report
    w = Workspace(ws, "contracts/plan_doorstop.yaml")
    rows = {r["id"]: r for r in build_report(w).to_json()["requirements"]}
    assert list(rows) == ["SYS001", "SYS002", "SYS003"]
    assert rows["SYS001"]["verdict"] == "proved, evidence outstanding"  # no evidence run here
    assert rows["SYS001"]["check"]["source"] == "reqs/SYS001.yml:7:6"
    assert rows["SYS002"]["verdict"] == "refuted"
    assert rows["SYS002"]["check"]["assuming"] == ["ObstacleDetector.in.range >= 2"]
    assert rows["SYS003"]["verdict"] == "informal"
    from rclverify.report.sarif import sarif_log
    res = [r for r in sarif_log(build_report(w))["runs"][0]["results"] if r["ruleId"] == "RCL-REQ-REFUTED"]
    assert [r["locations"][0]["physicalLocation"]["artifactLocation"]["uri"] for r in res] == ["reqs/SYS002.yml"]


@pytest.mark.parametrize("formal, message", [
    ("Nobody.out.distance < 1", "no node named 'Nobody'"),
    ("ObstacleDetector.out.dist < 1", "node ObstacleDetector has no output named 'dist'"),
    ("ObstacleDetector.in.distance < 1", "'distance' is an output of ObstacleDetector, not an input: write "
                                         "ObstacleDetector.out.distance"),
    ("ObstacleDetector.out.distance < TRUE", "error:"),
    ("out.distance < 1", "names no node"),
    ("ObstacleDetector.out.distance + 1", "must be a formula"),
])
def test_mistakes_in_a_formal_statement_are_located_errors(tmp_path: Path, formal: str, message: str,
                                                           capsys: pytest.CaptureFixture[str]) -> None:
    ws = _copy(tmp_path)
    plan = ws / "contracts/plan.yaml"
    text = plan.read_text()
    plan.write_text(text.replace('"ObstacleDetector.out.distance == ObstacleDetector.in.range"', json.dumps(formal)))
    assert main(["requirements", "-w", str(ws)]) == 1
    err = capsys.readouterr().err
    assert err.startswith("contracts/plan.yaml:19:"), err
    assert message in err and "Traceback" not in err


def test_the_bundle_carries_the_doorstop_tree_and_the_requirement_records(tmp_path: Path) -> None:
    ws = _copy(tmp_path)
    assert main(["requirements", "-w", str(ws), "--plan", "contracts/plan_doorstop.yaml"]) == 1
    from rclverify.report.bundle.manifest import collect
    from rclverify.model.plan.load import load_plan
    files, missing = collect(ws, load_plan(ws, "contracts/plan_doorstop.yaml"))
    assert {"reqs/.doorstop.yml", "reqs/SYS001.yml", "artifacts/requirements/SYS002.json"} <= set(files)
    assert not missing


def test_a_type_error_in_a_doorstop_item_is_located_in_its_file(tmp_path: Path,
                                                               capsys: pytest.CaptureFixture[str]) -> None:
    ws = _copy(tmp_path)
    item = ws / "reqs/SYS001.yml"
    item.write_text(item.read_text().replace("MotorDriver.in.speed_cmd == 0", "MotorDriver.in.speed_cmd == red"))
    assert main(["requirements", "-w", str(ws), "--plan", "contracts/plan_doorstop.yaml"]) == 1
    err = capsys.readouterr().err
    assert err == "reqs/SYS001.yml:7:73: error: unknown name 'red'\n"  # the column of `red` in the item file


def test_init_writes_formal_requirements_that_are_proved(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["init", str(tmp_path / "w")]) == 0
    assert main(["requirements", "-w", str(tmp_path / "w")]) == 0
    out = capsys.readouterr().out
    # proved; not met until the nodes have evidence (the new plan has none yet: the guarantees are unverified)
    assert "REQ1: proved, evidence outstanding [unverified]" in out
    assert "REQ2: proved, evidence outstanding [unverified]" in out
    assert "used: Sensor guarantee 2" in out and "used: Actuator guarantee 2" in out
