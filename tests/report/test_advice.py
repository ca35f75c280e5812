"""Advice a user can act on (issue 40): the right culprit and a repair that
costs the user least, on small workspaces of ``tests/data/advice``.

* a deadline chain over its budget is its own problem row naming its chain,
  each hop's bound and the budget, with repairs that split the budget,
  checked by Z3 deciding rule D3 again;
* millimetres published where metres are assumed: the first repair fixes the
  producer (a strengthening that would leave it unimplementable is said, not
  offered), the consumer's assumption is widened last and only with the
  evidence it invalidates named;
* a coefficient (``1000 * in.r``, ``in.d / 10``) is never rewritten as a bound.
"""
from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import pytest

from rclverify.cli.commands import main

DATA = Path(__file__).parent.parent / "data" / "advice"


def _verify(tmp: Path, name: str, plan_extra: str = "") -> tuple[Path, dict[str, Any]]:
    ws = tmp / name
    shutil.copytree(DATA / name, ws)
    if plan_extra:
        plan = ws / "contracts" / "plan.yaml"
        plan.write_text(plan.read_text(encoding="utf-8").replace("requirements: []\n", plan_extra), encoding="utf-8")
    assert main(["verify", "-w", str(ws)]) == 0
    return ws, json.loads((ws / "reports" / "assurance.json").read_text(encoding="utf-8"))


def _diag(report: dict[str, Any], did: str) -> dict[str, Any]:
    return next(d for d in report["diagnoses"] if d["id"] == did)


@pytest.fixture(scope="module")
def deadline(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, Any]]:
    return _verify(tmp_path_factory.mktemp("advice"), "deadline")


def test_a_deadline_over_its_budget_is_its_own_row_naming_chain_hops_and_budget(deadline) -> None:
    ws, report = deadline
    d = _diag(report, "STOP.deadline")
    assert (d["kind"], d["status"]) == ("deadline", "failed")
    s = d["sentence"]
    assert s.startswith("The end-to-end deadline of STOP (150 ms along Lidar -> Detector -> Planner, "
                        "contracts/plan.yaml:9:15) is refuted")
    for hop in ("Lidar guarantee 1 within 40 ms (contracts/chain.rcl:9:3)",
                "Detector guarantee 1 within 60 ms (contracts/chain.rcl:16:3)",
                "Planner guarantee 1 within 100 ms (contracts/chain.rcl:23:3)"):
        assert hop in s
    assert "sums to 200 ms, 50 ms over the budget" in s
    # the requirement is not blamed on a bound of its cone (Lidar's 30 m): its formula is proved
    assert not any(x["id"] == "STOP" for x in report["diagnoses"])
    [row] = [g for g in report["problems"] if "STOP.deadline" in [m["id"] for m in g["members"]]]
    assert row["key"] == ["deadline:STOP"] and row["status"] == "failed"
    assert [m["id"] for m in row["members"]] == ["STOP.deadline", "STOP"]
    assert [(c["what"], c["source"]) for c in row["culprits"]] == [
        ("guarantee 1 of Lidar: within 40 ms", "contracts/chain.rcl:9:3"),
        ("guarantee 1 of Detector: within 60 ms", "contracts/chain.rcl:16:3"),
        ("guarantee 1 of Planner: within 100 ms", "contracts/chain.rcl:23:3")]
    assert row["sentence"].startswith("The end-to-end deadline of STOP")
    # no other row holds it
    assert sum("STOP.deadline" in [m["id"] for m in g["members"]] for g in report["problems"]) == 1


def test_the_deadlines_repairs_split_the_budget_and_z3_checked_them(deadline) -> None:
    ws, report = deadline
    reps = _diag(report, "STOP.deadline")["repairs"]
    assert [r["kind"] for r in reps] == ["tighten-hop", "tighten-hop", "split-budget"]
    # which hop must become how fast: the smallest relative cut first (Planner 100 -> 50 ms halves it)
    assert reps[0]["summary"].startswith("Make Planner answer within 50 ms instead of 100 ms")
    assert reps[0]["edit"]["deleted"] == "within 100 ms" and reps[0]["edit"]["inserted"] == "within 50 ms"
    assert reps[1]["summary"].startswith("Make Detector answer within 10 ms instead of 60 ms")
    assert "Lidar 40 ms -> 30 ms, Detector 60 ms -> 45 ms, Planner 100 ms -> 75 ms" in reps[2]["summary"]
    for r in reps:
        assert r["checks"] == [{"check": "STOP.deadline", "status": "proved (Z3: unsat: no run later than 150 ms)"}]
        assert {"check": "STOP.deadline", "before": "refuted", "after": "proved"} in r["cost"]
        assert r["proves"] == "the end-to-end deadline of STOP follows from the chain (rule D3)"
        assert "must show it" in r["not_shown"]
        # only time budgets are edited: never Lidar's 30 m range or any other bound
        assert all(line.count("within") == 1 for line in r["diff"].splitlines() if line[:1] in "+-"
                   and not line.startswith(("+++", "---")))
    # the contract file is untouched
    assert "within 100 ms" in (ws / "contracts" / "chain.rcl").read_text(encoding="utf-8")
    # SARIF: the deadline's result carries the diagnosis and the repairs as fixes
    sarif = json.loads((ws / "reports" / "assurance.sarif").read_text(encoding="utf-8"))
    [res] = [x for x in sarif["runs"][0]["results"] if x["ruleId"] == "RCL-DEADLINE-REFUTED"]
    assert res["properties"]["diagnosis"] == _diag(report, "STOP.deadline")["sentence"]
    assert len(res["fixes"]) == 3


@pytest.fixture(scope="module")
def millimetres(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, Any]]:
    return _verify(tmp_path_factory.mktemp("advice"), "millimetres")


def test_millimetres_against_metres_fixes_the_producer_first(millimetres) -> None:
    ws, report = millimetres
    d = _diag(report, "Controller.sc2")
    reps = d["repairs"]
    assert reps and reps[0]["kind"] != "weaken-consumer"
    # the producer's coefficient rescaled as a unit conversion, never the consumer widened first
    assert reps[0]["kind"] == "rescale-producer"
    assert reps[0]["edit"]["deleted"] == "1000 * in.r" and reps[0]["edit"]["inserted"] == "in.r"
    assert "a factor of 1000" in reps[0]["summary"] and "unit conversion, not a bound" in reps[0]["summary"]
    assert {"check": "Ranger implementable",
            "status": "yes: every input its assumption allows has an answer (Z3: proved)"} in reps[0]["checks"]
    assert reps[0]["proves"] == "Controller.sc2 follows from the edited contracts"
    assert "which unit is right" in reps[0]["not_shown"]
    # adding `out.d <= 30` to Ranger discharges the side condition but leaves Ranger unimplementable: said, not offered
    assert not any(r["kind"] == "strengthen-producer" for r in reps)
    [why] = d["not_offered"]
    assert why.startswith("Strengthening Ranger by `out.d <= 30` discharges Controller.sc2 but leaves Ranger "
                          "unimplementable: for Ranger.in.r = ")


def test_a_weakened_assumption_comes_last_naming_the_evidence_it_invalidates(millimetres) -> None:
    ws, report = millimetres
    reps = _diag(report, "Controller.sc2")["repairs"]
    weak = [k for k, r in enumerate(reps) if r["kind"] == "weaken-consumer"]
    assert weak == [len(reps) - 1]
    w = reps[-1]
    assert "`in.d <= 30` becomes `in.d <= 30000`" in w["summary"]
    # the consumer's guarantee that reads the widened input, and its evidence established under the old assumption
    assert "guarantee 1 `0 <= out.v and out.v <= in.d / 10` must then hold for the wider inputs" in w["summary"]
    assert ("Controller.g1.hoare.controller.c1 (discharged), Controller.g1.hoare.controller.c2 (discharged) must be "
            "established again") in w["summary"]
    assert "Probably unsafe: the ranges differ by a factor of 1000" in w["summary"]


COEFFICIENTS = """requirements:
  - id: HALF
    text: The controller commands at most a twentieth of the distance as speed.
    formal: "Controller.out.v <= Controller.in.d / 20"
  - id: MM
    text: Ranger's output is at most half its input.
    formal: "Ranger.out.d <= 0.5 * Ranger.in.r"
"""


def test_a_coefficient_is_never_rewritten_as_a_bound(tmp_path: Path) -> None:
    """``in.d / 10`` -> ``in.d / 20`` and ``1000 * in.r`` -> ``0.5 * in.r`` would let Z3 prove the two
    requirements, and say nothing an engineer can implement: no repair touches a coefficient."""
    ws, report = _verify(tmp_path, "millimetres", COEFFICIENTS)
    half, mm = _diag(report, "HALF"), _diag(report, "MM")
    for d in (half, mm):
        for r in d["repairs"]:
            assert r["kind"] != "tighten-bound", r
            assert r["edit"]["deleted"] not in ("10", "1000")
            assert "becomes 0.5" not in r["summary"] and "1000 becomes" not in r["summary"]
    # HALF: the controller's guarantee strengthened by the statement, which it can implement
    [r] = half["repairs"]
    assert r["kind"] == "strengthen-guarantee" and "`out.v <= in.d / 20`" in r["summary"]
    assert {"check": "Controller implementable",
            "status": "yes: every input its assumption allows has an answer (Z3: proved)"} in r["checks"]
    # MM: Ranger strengthened by `out.d <= 0.5 * in.r` would answer only in.r = 0: no repair, no culprit
    assert mm["repairs"] == [] and mm["culprits"] == []
    assert "no single strengthening Z3 tried proves it" in mm["sentence"]


THRESHOLDS = """// Off-by-one at a threshold: the battery is low below 20 %, the requirement says at 20 % or less;
// the overheat flag is raised at 80 degrees, the requirement says only above 80.
node Battery {
  inputs( charge : REAL )
  outputs( low : BOOL )
  assume( 0 <= in.charge and in.charge <= 100 )
  guarantee( out.low <=> in.charge < 20 )
}

node Mission {
  inputs( low : BOOL )
  outputs( dock : BOOL )
  assume( TRUE )
  guarantee( out.dock <=> in.low )
}

node Thermo {
  inputs( temp : REAL )
  outputs( hot : BOOL )
  assume( 0 <= in.temp and in.temp <= 150 )
  guarantee( out.hot <=> in.temp >= 80 )
}
"""


def test_an_off_by_one_at_a_threshold_names_the_threshold_and_moves_it(tmp_path: Path) -> None:
    """A requirement that includes its threshold (``<= 20``) against a guarantee that excludes it (``< 20``):
    no bound of the cone to tighten (the numbers are equal), yet the culprit is the threshold guarantee and
    the repair its strictness, checked by Z3; the other way round (``>= 80`` where the requirement says
    ``> 80``) the threshold is excluded.  Before, no culprit was named ("no single strengthening Z3 tried
    proves it")."""
    ws = tmp_path / "t"
    (ws / "contracts").mkdir(parents=True)
    (ws / "contracts" / "t.rcl").write_text(THRESHOLDS, encoding="utf-8")
    (ws / "contracts" / "plan.yaml").write_text(
        "contracts: [contracts/t.rcl]\nrequirements:\n"
        "  - {id: DOCK, text: dock at 20 % or less, formal: \"Battery.in.charge <= 20 -> Mission.out.dock\"}\n"
        "  - {id: HOT, text: hot only above 80, formal: \"Thermo.out.hot -> Thermo.in.temp > 80\"}\n",
        encoding="utf-8")
    assert main(["verify", "-w", str(ws)]) == 0
    report = json.loads((ws / "reports" / "assurance.json").read_text(encoding="utf-8"))
    dock, hot = _diag(report, "DOCK"), _diag(report, "HOT")
    assert [c["source"] for c in dock["culprits"]] == ["contracts/t.rcl:7:3"]
    assert "its threshold `in.charge < 20` has the other strictness than DOCK's" in dock["sentence"]
    [r] = dock["repairs"]
    assert r["kind"] == "move-threshold" and (r["edit"]["deleted"], r["edit"]["inserted"]) == ("<", "<=")
    assert "Make the threshold of guarantee 1 of Battery (contracts/t.rcl:7:3) include 20 itself" in r["summary"]
    assert "-  guarantee( out.low <=> in.charge < 20 )\n+  guarantee( out.low <=> in.charge <= 20 )" in r["diff"]
    assert r["checks"][0] == {"check": "DOCK", "status": "proved (Z3: unsat)"}
    [h] = hot["repairs"]
    assert (h["kind"], h["edit"]["deleted"], h["edit"]["inserted"]) == ("move-threshold", ">=", ">")
    assert "exclude 80 itself" in h["summary"] and [c["source"] for c in hot["culprits"]] == ["contracts/t.rcl:21:3"]
    rows = {tuple(g["key"]): [m["id"] for m in g["members"]] for g in report["problems"]}
    assert rows[("guarantee:Battery:1",)] == ["DOCK"] and rows[("guarantee:Thermo:1",)] == ["HOT"]


BAD_PLAN = """name: deadline chain
contracts:
  - contracts/chain.rcl
requirements:
  - id: STOP
    text: The planner orders the stop within 150 ms of a scan.
    formal: "eventualy Planner.out.stop"
    deadline: {path: [Lidar, Detektor, Planner], within: 150 ms}
  - id: NEAR
    text: The planner stops near an obstacle.
    formal: "Planer.in.d <= 1 -> Planner.out.stop"
  - id: SYNTAX
    text: A statement with a missing operator.
    formal: "Planner.in.d <= 1 Planner.out.stop"
nodes: {}
"""


def test_check_reads_the_plans_statements_with_located_messages(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                               monkeypatch: pytest.MonkeyPatch) -> None:
    """`rclverify check` reports what `doit verify` would stop on in the plan's statements: an unknown node
    in `formal:` and in `deadline:`, a misspelled temporal operator, a syntax error, each located and in the
    plan's own words (never the parser's internal placeholder names)."""
    ws = tmp_path / "ws"
    shutil.copytree(DATA / "deadline", ws)
    (ws / "contracts" / "plan.yaml").write_text(BAD_PLAN, encoding="utf-8")
    monkeypatch.chdir(ws)
    assert main(["check", "contracts/chain.rcl"]) == 1
    err = capsys.readouterr().err.splitlines()
    assert ("contracts/plan.yaml:7:14: error: STOP formal: unknown temporal operator 'eventualy': did you mean "
            "'eventually'? The operators are always, eventually, eventually[<= N], next, previous and until "
            "(docs/requirements.md, Temporal requirements)") in err
    assert ("contracts/plan.yaml:11:14: error: NEAR formal: no node named 'Planer' in the system; nodes are: "
            "Lidar, Detector, Planner") in err
    assert ("contracts/plan.yaml:8:15: error: no node named 'Detektor' in the contracts; nodes are: "
            "Lidar, Detector, Planner") in err
    syntax = [x for x in err if x.startswith("contracts/plan.yaml:14:")]
    assert syntax and "unexpected 'Planner.out.stop'" in syntax[0], err
    assert not any("__q" in x for x in err)
    # the same plan without its mistakes checks clean
    (ws / "contracts" / "plan.yaml").write_text((DATA / "deadline" / "contracts" / "plan.yaml").read_text(), encoding="utf-8")
    assert main(["check", "contracts/chain.rcl"]) == 0
    assert "0 errors" in capsys.readouterr().out


# -- one severity per finding ---------------------------------------------------------------------------------

#: What the terminal prints for a gating item of each kind, in `verify --strict`'s last sentence.
STRICT_CLAUSE = {"obligation": "not discharged", "guarantee": "unverified (no obligation covers",
                 "side-condition": "side condition", "health:error": "found a problem or could not decide",
                 "health:warning": "contract health warning", "requirement": "formal requirement",
                 "deadline": "end-to-end deadline", "lint": "lint diagnostic"}
#: JUnit outcomes an item of each severity may have (report/severity.py).
JUNIT = {"error": {"failure", "error"}, "warning": {"failure", "skipped"}, "note": {"skipped"}}


def _junit_cases(xml: str) -> dict[tuple[str, str], str]:
    import xml.etree.ElementTree as ET
    out = {}
    for case in ET.fromstring(xml).iter("testcase"):
        child = next(iter(case), None)
        out[(case.get("classname", ""), case.get("name", ""))] = child.tag if child is not None else "pass"
    return out


def test_every_finding_kind_has_one_severity_in_all_five_outputs(tmp_path: Path,
                                                                 capsys: pytest.CaptureFixture[str]) -> None:
    """Issue 40: a redundant conjunct was `warning` on the terminal and in HTML, SARIF `error`, JUnit failures,
    and `--strict` ignored it.  Every finding kind of a small workspace (obligations failed and pending, a
    guarantee no obligation covers, a refuted side condition, health problems and warnings, requirements
    refuted and informal, a refuted deadline, a lint warning) has the one severity of report/severity.py in the
    terminal, the HTML report, SARIF, JUnit and --strict."""
    from rclverify.report.render import anchor
    from rclverify.report.severity import items
    ws = tmp_path / "severity"
    shutil.copytree(DATA / "severity", ws)
    from rclverify.report.strict import strict_sentence
    from rclverify.report.summary import read_summary
    assert main(["verify", "-w", str(ws), "--strict"]) == 1
    capsys.readouterr()
    # the terminal: what `verify` ends with (`status` prints the same), the lint of `check`, --strict's sentence
    assert main(["status", "-w", str(ws)]) == 0
    assert main(["check", "--plan", "contracts/plan.yaml", "-w", str(ws), str(ws / "contracts" / "plant.rcl")]) == 0
    got = capsys.readouterr()
    terminal = got.out + got.err + strict_sentence(read_summary(ws)) + "\n"
    rep = ws / "reports"
    report = json.loads((rep / "assurance.json").read_text(encoding="utf-8"))
    sarif = json.loads((rep / "assurance.sarif").read_text(encoding="utf-8"))["runs"][0]["results"]
    junit = _junit_cases((rep / "assurance.junit.xml").read_text(encoding="utf-8"))
    html = (rep / "assurance.html").read_text(encoding="utf-8")
    found = items(report)
    assert {(k, sev) for k, _, _, sev in found} >= {
        ("obligation", "error"), ("obligation", "warning"), ("guarantee", "warning"), ("side-condition", "error"),
        ("health", "error"), ("health", "warning"), ("requirement", "error"), ("requirement", "note"),
        ("deadline", "error"), ("lint", "warning")}
    [strict_line] = [x for x in terminal.splitlines() if x.startswith("--strict failed: ")]
    assert report["meta"]["strict_ok"] is False
    for kind, ident, status, sev in found:
        where = f"{kind} {ident} ({status}, {sev})"
        # SARIF: the level is the severity
        key = {"guarantee": f"guarantee:{ident}", "deadline": f"deadline:{ident.rsplit('.', 1)[0]}",
               "lint": f"lint:{ident}:"}.get(kind, f"{kind}:{ident}")
        res = [r for r in sarif if r["partialFingerprints"]["rclverifyItem/v1"].startswith(key)
               and (kind == "lint" or r["partialFingerprints"]["rclverifyItem/v1"] == key)]
        assert [r["level"] for r in res] == [sev], where
        # JUnit: a failure or error for an error, a failure or a skip for a warning, a skip for a note
        loc, _, code = ident.rpartition(":")
        name = {"deadline": ("deadline", ident.rsplit(".", 1)[0]), "requirement": ("requirement", ident),
                "lint": ("lint", f"{code} {loc}")}.get(kind)
        outcome = junit[name] if name else next(v for (c, n), v in junit.items() if n == ident)
        assert outcome in JUNIT[sev], where
        # --strict: an error or a warning fails it and is named in its last sentence; a note does not
        clause = STRICT_CLAUSE.get(f"{kind}:{sev}", STRICT_CLAUSE.get(kind, ""))
        if sev in ("error", "warning"):
            assert clause in strict_line, where
        else:
            assert ident not in strict_line, where
        # HTML: the item's row shows its status word (the badge's word and colour follow it)
        node = ident.split(".", 1)[0]
        a = {"obligation": anchor("ob", ident), "guarantee": anchor("g", node, ident.rsplit(".g", 1)[-1]),
             "side-condition": anchor("sc", ident), "health": anchor("finding", ident),
             "requirement": anchor("req", ident), "deadline": anchor("deadline", ident.rsplit(".", 1)[0]),
             "lint": anchor("lint", 1)}[kind]
        i = html.index(f'id="{a}"')
        row = html[i:html.index("</tr>", i)]
        assert f">{status}<" in row, where
        # the terminal: the same word where the item is counted or named
        term = {"obligation": f"{status}", "guarantee": ident.rpartition(".")[2], "side-condition": "0/1 proved",
                "health": status,
                "requirement": f"{status} (" if sev != "note" else f"1 {status}",
                "deadline": f"{ident.rsplit('.', 1)[0]} {status}", "lint": f"{loc}: {sev}:"}[kind]
        assert term in terminal, where
    # the redundant conjunct of the issue: one word, warning, everywhere
    red = "Sense.g1.c3.redundant"
    assert [r["level"] for r in sarif if r["partialFingerprints"]["rclverifyItem/v1"] == f"health:{red}"] == ["warning"]
    assert "2 contract health warnings (Sense.g1.c3.redundant, Act.g2.c1.redundant)" in strict_line
    assert "| 1 problem, 1 warning " in terminal


def test_the_severity_table() -> None:
    """The one table every output reads (report/severity.py), for the statuses a small workspace does not
    show: stale, inconclusive and error records, evidence outstanding, a grounding warning."""
    from rclverify.report.severity import blocking, junit_outcome, of
    assert [of("obligation", s) for s in ("discharged", "failed", "error", "stale", "inconclusive", "pending")] == [
        None, "error", "error", "warning", "warning", "warning"]
    assert [of("health", s) for s in ("ok", "problem", "warning", "inconclusive", "stale", "error")] == [
        None, "error", "warning", "warning", "warning", "error"]
    assert [of("requirement", v) for v in ("met", "refuted", "proved vacuously", "proved, evidence outstanding",
                                           "inconclusive", "stale", "error", "informal")] == [
        None, "error", "error", "warning", "warning", "warning", "error", "note"]
    assert [of("deadline", v) for v in ("proved", "refuted", "inconclusive", "pending", "stale", "error")] == [
        None, "error", "warning", "warning", "warning", "error"]
    assert of("lint", "warning") == "warning" and of("lint", "error") == "error" and of("obligation", "??") == "error"
    assert [junit_outcome("obligation", s) for s in ("discharged", "failed", "error", "stale", "pending")] == [
        "pass", "failure", "error", "failure", "skipped"]
    assert junit_outcome("health", "warning") == "failure" and junit_outcome("requirement", "informal") == "skipped"
    # a ROS grounding warning names software the contracts need not describe: it does not fail --strict
    from _typed_rows import typed_report
    report = typed_report({"grounding": {"findings": [{"severity": "warning", "code": "ROS-NODE-NO-CONTRACT"},
                                                      {"severity": "error", "code": "ROS-NODE-NOT-IN-GRAPH"}]}})
    assert blocking(report) == [("grounding", "ROS-NODE-NOT-IN-GRAPH", "error", "error")]


def test_an_undecided_deadline_is_its_own_row_naming_where_the_chain_breaks(tmp_path: Path) -> None:
    ws = tmp_path / "deadline"
    shutil.copytree(DATA / "deadline", ws)
    rcl = ws / "contracts" / "chain.rcl"
    rcl.write_text(rcl.read_text().replace("guarantee( out.d == in.r ) triggered by in.r within 60 ms",
                                           "guarantee( out.d == in.r )"))
    assert main(["verify", "-w", str(ws)]) == 0
    report = json.loads((ws / "reports" / "assurance.json").read_text(encoding="utf-8"))
    d = _diag(report, "STOP.deadline")
    assert (d["kind"], d["status"], d["repairs"]) == ("deadline", "inconclusive", [])
    assert d["sentence"] == ("The end-to-end deadline of STOP (150 ms along Lidar -> Detector -> Planner, "
                             "contracts/plan.yaml:9:15) is not decided: no timed guarantee of Detector is triggered "
                             "by an output of Lidar's timed guarantees (out.r).")
    assert [c["what"] for c in d["culprits"]] == ["the contract of Detector"]
    [row] = [g for g in report["problems"] if g["key"] == ["deadline:STOP"]]
    assert row["status"] == "inconclusive" and [c["what"] for c in row["culprits"]] == ["the contract of Detector"]
