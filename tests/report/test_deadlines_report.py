"""End-to-end deadlines through ``doit verify`` (issue 33): the deadlines
stage's sealed record, the report's section, SARIF, JUnit, the argument and
``--strict``.  One small workspace (the safety-stop example without its
slower evidence), verified once per module; the refuted case edits the
plan's bound and runs again (incremental), then compares with a clean run.
"""
from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import pytest

from rclverify.cli.commands import main

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "safety_stop"


def _workspace(tmp: Path) -> Path:
    ws = tmp / "ws"
    shutil.copytree(EXAMPLE, ws, ignore=shutil.ignore_patterns("artifacts", "reports", "*.pyc", "__pycache__"))
    plan = ws / "contracts" / "plan.yaml"
    # keep the evidence that runs in a moment: the recorded run's monitors (they check the deadlines)
    text = plan.read_text()
    head, nodes = text.split("\nnodes:\n", 1)
    plan.write_text(head + "\nnodes:\n  Base:\n    evidence:\n      - backend: monitors\n"
                    "        traces: [traces/nominal.jsonl]\n")
    return ws


def _reports(ws: Path) -> dict[str, Any]:
    return {"json": json.loads((ws / "reports" / "assurance.json").read_text()),
            "md": (ws / "reports" / "assurance.md").read_text(),
            "html": (ws / "reports" / "assurance.html").read_text(),
            "sarif": json.loads((ws / "reports" / "assurance.sarif").read_text()),
            "junit": (ws / "reports" / "assurance.junit.xml").read_text(),
            "argument": json.loads((ws / "reports" / "argument.json").read_text())}


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    ws = _workspace(tmp_path_factory.mktemp("dl"))
    assert main(["verify", "-w", str(ws)]) == 0
    proved = _reports(ws)
    index = json.loads((ws / "artifacts" / "deadlines" / "index.json").read_text())
    plan = ws / "contracts" / "plan.yaml"
    plan.write_text(plan.read_text().replace("within: 300 ms", "within: 200 ms"))
    strict = main(["verify", "-w", str(ws), "--strict"])
    refuted = _reports(ws)
    record = (ws / "artifacts" / "deadlines" / "index.json").read_text()
    refuted["summary"] = json.loads((ws / "artifacts" / "report" / "summary.json").read_text())
    clean = tmp_path_factory.mktemp("clean") / "ws"
    shutil.copytree(ws, clean, ignore=shutil.ignore_patterns("artifacts", "reports", ".doit*"))
    assert main(["verify", "-w", str(clean)]) == 0
    return {"proved": proved, "index": index, "refuted": refuted, "strict": strict, "record": record,
            "clean_record": (clean / "artifacts" / "deadlines" / "index.json").read_text()}


def test_the_report_shows_stop_proved_with_its_chain(runs: dict[str, Any]) -> None:
    r = runs["proved"]
    stop = r["json"]["deadlines"][0]
    assert (stop["requirement"], stop["verdict"], stop["total"], stop["within"]) == ("STOP", "proved", "250 ms", "300 ms")
    assert [(h["node"], h["guarantee"], h["within"], h["loc"]) for h in stop["chain"]] == [
        ("Teleop", 1, "50 ms", "contracts/safety_stop.rcl:15:3"), ("Base", 1, "200 ms", "contracts/safety_stop.rcl:23:3")]
    # Teleop's guarantee has no evidence: proved, but no green tick
    assert stop["status"] == "unverified"
    base = stop["chain"][1]["monitors"][0]
    assert base["counts"]["true"] == 2 and base["status"] == "discharged"
    assert "**STOP** ❔ **unverified** **proved** (evidence of its chain unverified): 300 ms along Teleop -\\> Base" in r["md"]
    assert "1. Teleop guarantee 1 ❔ **unverified**: `in.button` -> `out.stop_req` within **50 ms**" in r["md"]
    assert 'id="deadlines"' in r["html"] and "250 ms" in r["html"]
    assert runs["index"]["results"][0]["smt2"] == "artifacts/deadlines/STOP.smt2"
    # the argument: a deadline goal under STOP, supported by Z3's decision, the chain's guarantees, the monitor
    els = {e["id"]: e for e in r["argument"]["elements"]}
    assert "G-STOP.deadline" in els["G-STOP"]["supported_by"]
    assert els["S-STOP.deadline"]["supported_by"] == ["Sn-deadline.STOP", "G-Teleop.g1", "G-Base.g1",
                                                      "Sn-ev.Base.g0.monitors.nominal_jsonl"]
    assert els["Sn-deadline.STOP"]["status"] == "discharged"
    assert not [x for x in r["sarif"]["runs"][0]["results"] if x["ruleId"].startswith("RCL-DEADLINE")]


def test_a_chain_past_the_bound_is_refuted_in_the_report_sarif_junit_and_strict(runs: dict[str, Any]) -> None:
    r = runs["refuted"]
    stop = r["json"]["deadlines"][0]
    assert (stop["verdict"], stop["status"], stop["total"], stop["within"]) == ("refuted", "failed", "250 ms", "200 ms")
    assert stop["reason"].startswith("the chain Teleop guarantee 1 (in.button -> out.stop_req within 50 ms) -> Base "
                                     "guarantee 1 (in.stop_req -> out.stopped within 200 ms) sums to 250 ms > 200 ms")
    req = next(q for q in r["json"]["requirements"] if q["id"] == "STOP")
    assert (req["verdict"], req["status"]) == ("refuted", "failed")  # not met
    assert any(p.startswith("Requirement STOP is refuted: end-to-end deadline 200 ms along Teleop -> Base refuted")
               for p in r["json"]["summary"]["problems"])
    assert any(m["id"] == "STOP" for g in r["json"]["problems"] for m in g["members"])  # what needs attention
    res = [x for x in r["sarif"]["runs"][0]["results"] if x["ruleId"] == "RCL-DEADLINE-REFUTED"]
    assert len(res) == 1 and res[0]["level"] == "error"
    region = res[0]["locations"][0]["physicalLocation"]
    assert region["artifactLocation"]["uri"] == "contracts/plan.yaml" and region["region"]["startLine"] == 12
    assert "Chain: Teleop guarantee 1" in res[0]["message"]["text"] and "sum 250 ms" in res[0]["message"]["text"]
    assert '<testsuite name="deadlines"' in r["junit"] and 'classname="deadline" name="STOP"' in r["junit"]
    assert runs["strict"] == 1
    assert "1 end-to-end deadline is refuted (STOP)" in r["summary"]["strict"]
    els = {e["id"]: e for e in r["argument"]["elements"]}
    assert els["G-STOP"]["status"] == "failed" and els["G-STOP.deadline"]["status"] == "failed"


def test_incremental_equals_clean(runs: dict[str, Any]) -> None:
    assert runs["record"] == runs["clean_record"]


def test_the_end_of_verify_names_each_deadline_and_its_sums(runs: dict[str, Any]) -> None:
    from rclverify.report.summary import deadlines_line
    rows = runs["refuted"]["summary"]["deadlines"]
    assert [r[:4] for r in rows] == [["STOP", "refuted", "250 ms", "200 ms"], ["MOVE-FEEDBACK", "proved", "2 s", "2 s"]]
    assert deadlines_line(rows).startswith("deadlines: STOP refuted (250 ms > 200 ms")


def test_the_reports_match_the_published_schema(runs: dict[str, Any]) -> None:
    """The deadline rows (proved, then refuted) against docs/assurance.schema.json and the status vocabulary
    (tests/_report_schema.py)."""
    from _report_schema import check_report
    for label in ("proved", "refuted"):
        check_report(runs[label]["json"], label)
    assert {d["verdict"] for d in runs["proved"]["json"]["deadlines"]} == {"proved"}
    assert "refuted" in {d["verdict"] for d in runs["refuted"]["json"]["deadlines"]}
