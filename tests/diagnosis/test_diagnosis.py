"""Diagnosis records and repairs checked by Z3 (docs/diagnosis.md): the
culprit named by source location, counterexamples as tables, and repairs
shown only after Z3 checked them, on small real workspaces."""
from __future__ import annotations

import json
import os
import shutil
from fractions import Fraction
from pathlib import Path
from typing import Any

import jsonschema
import pytest
import z3

from rclverify.cli.commands import main
from rclverify.diagnosis.build import diagnose
from rclverify.diagnosis.shapes import report_rows
from rclverify.diagnosis.repair_cache import CACHE
from rclverify.diagnosis.table import counterexample_table, decimals, function_table
from rclverify.semantics.values import decimal_text
from rclverify.report.diagnosis_text import natural_sorted
from rclverify.app.pipeline import Workspace, diagnosed, stage_check, stage_compose, stage_export, stage_health, stage_run
from rclverify.report.sarif import sarif_log

REPO = Path(__file__).resolve().parents[2]
SARIF_SCHEMA = REPO / "tests" / "data" / "sarif-schema-2.1.0.json"
RCL_FILE = "contracts/remote_inspection.rcl"


def _run(root: Path) -> tuple[Workspace, dict[str, Any]]:
    """Check, compose, health, export and run every obligation of ``root``; the report dict (the
    orchestrator's: the diagnosis stage run for it)."""
    ws = Workspace(root)
    stage_check(ws)
    for n in ws.node_names():
        stage_compose(ws, n)
        stage_health(ws, n)
        for o in stage_export(ws, n):
            stage_run(ws, n, o.id)
    return ws, diagnosed(ws)


@pytest.fixture()
def newcomer(tmp_path: Path) -> Path:
    """The newcomer's three-node system: Planner guarantees speed <= 2.0, Controller assumes <= 1.5."""
    shutil.copytree(REPO / "tests" / "data" / "newcomer", tmp_path / "ws")
    return tmp_path / "ws"


SENSOR_PLAN = """name: sensor
contracts: [contracts/sensor.rcl]
requirements: []
connections: []
environment: {}
nodes:
  RadiationSensor:
    evidence:
      - backend: hoare
        program: backends/hoare/radiation_sensor_appendix_b.imp
        binding: {in.r: radiation_at(i), out.radiationStatus: output}
"""


@pytest.fixture()
def sensor(tmp_path: Path) -> Path:
    """The case study's Radiation Sensor alone, with appendix B's program (thresholds 10 and 20)."""
    root = tmp_path / "sensor"
    text = (REPO / "contracts" / "remote_inspection.rcl").read_text(encoding="utf-8")
    context = text[text.index("context {"):text.index("\n}", text.index("context {")) + 2]
    node = text[text.index("node RadiationSensor"):]
    (root / "contracts").mkdir(parents=True)
    (root / "contracts" / "sensor.rcl").write_text(context + "\n\n" + node, encoding="utf-8")
    (root / "contracts" / "plan.yaml").write_text(SENSOR_PLAN, encoding="utf-8")
    (root / "backends" / "hoare").mkdir(parents=True)
    shutil.copy(REPO / "backends" / "hoare" / "radiation_sensor_appendix_b.imp", root / "backends" / "hoare")
    return root


# A guarantee made vacuous by another one, as the Agent's guarantee 3 makes guarantees 1 and 2:
# guarantee 2 binds i universally, so at i = 6 its premise holds and it demands c == 0 always.
VACUOUS = """node N {
  inputs( a : NATURAL --> BOOL )
  outputs( c : NATURAL )
  assume( TRUE )
  guarantee( forall(i in NATURAL | in.a(i) == TRUE -> out.c == i + 1) )
  guarantee( forall(i in NATURAL | in.a(i) == FALSE or i > 5 -> out.c == 0) )
}
"""


@pytest.fixture()
def vacuous(tmp_path: Path) -> Path:
    root = tmp_path / "vac"
    (root / "contracts").mkdir(parents=True)
    (root / "contracts" / "n.rcl").write_text(VACUOUS, encoding="utf-8")
    (root / "contracts" / "plan.yaml").write_text(
        "name: vac\ncontracts: [contracts/n.rcl]\nrequirements: []\nconnections: []\nenvironment: {}\nnodes: {}\n",
        encoding="utf-8")
    return root


# ---------------------------------------------------------------------------------------------
# tables and numbers

def test_rationals_are_decimals_where_exact() -> None:
    assert decimal_text(Fraction(1, 5)) == "0.2"
    assert decimal_text(Fraction(-7, 4)) == "-1.75"
    assert decimal_text(Fraction(1, 3)) is None
    assert decimals("move(1/5, 3/2) and 1/3") == "move(0.2, 1.5) and 1/3"
    # where models are printed: Z3 values and the Python values of traces and property tests
    from rclverify.semantics.encode import value_to_rcl
    from rclverify.semantics.values import render
    assert value_to_rcl(z3.RealVal("1/5")) == "0.2" and value_to_rcl(z3.RealVal("1/3")) == "1/3"
    assert render(Fraction(1, 5)) == "0.2" and render(Fraction(2, 3)) == "2/3"


def test_function_values_become_finite_tables_never_if_then_else() -> None:
    nested = "{(p1, p2) -> (if ((p2 == 2) and not (p1 == 39) and (p1 == 41)) then 1 else " \
             "(if ((p1 == 3) and (p2 == 1/2)) then 5 else 17))}"
    t = function_table(nested)
    assert t == {"rows": [["(41, 2)", "1"], ["(3, 0.5)", "5"]], "more": 0, "else": "17"}
    assert function_table("{(0, 0) |-> 3, else |-> 0}") == {"rows": [["(0, 0)", "3"]], "more": 0, "else": "0"}
    big = "{(p1) -> " + "".join(f"(if (p1 == {k}) then {k} else " for k in range(40)) + "0" + ")" * 40 + "}"
    rows = counterexample_table({"Agent.in.f": big, "Agent.out.c": "move(1/5, 2)"})
    f = next(r for r in rows if r["variable"] == "in.f")
    assert f["node"] == "Agent" and f["table"]["more"] == 32 and len(f["table"]["rows"]) == 8
    assert "if" not in f["value"] and "more" in f["value"]
    assert next(r for r in rows if r["variable"] == "out.c")["value"] == "move(0.2, 2)"


def test_ids_sort_naturally() -> None:
    assert natural_sorted(["A.p10_i9", "A.p2_i1", "A.p1_i0"]) == ["A.p1_i0", "A.p2_i1", "A.p10_i9"]


# ---------------------------------------------------------------------------------------------
# side conditions

def test_newcomer_speed_mismatch_gets_side_condition_repairs(newcomer: Path) -> None:
    ws, report = _run(newcomer)
    d = next(x.to_json() for x in report.diagnoses if x.id == "Controller.sc2")
    assert d["kind"] == "side-condition"
    assert "in.speed <= 1.5" in d["sentence"] and "Planner's guarantee 1" in d["sentence"]
    assert "contracts/rover.rcl:15:29" in d["sentence"] and "contracts/rover.rcl:9:3" in d["sentence"]
    assert {"node": "Planner", "variable": "out.speed", "value": "2", "table": None} in d["counterexample"]
    kinds = {r["kind"]: r for r in d["repairs"]}
    assert set(kinds) == {"strengthen-producer", "weaken-consumer"}
    # the producer's bound tightened in place: the same contract as an added `out.speed <= 1.5`, without
    # leaving the old bound redundant (a health warning that --strict fails on)
    sp = kinds["strengthen-producer"]
    assert ("-  guarantee( 0 <= out.speed and out.speed <= 2.0 )\n"
            "+  guarantee( 0 <= out.speed and out.speed <= 1.5 )") in sp["diff"]
    assert "tighten the bound of its guarantee 1 in place" in sp["summary"]
    assert not any("redundant" in c["check"] for c in sp["cost"])
    assert "+  assume( 0 <= in.speed and in.speed <= 2.0 )" in kinds["weaken-consumer"]["diff"]
    for r in d["repairs"]:
        assert {"check": "Controller.sc2", "before": "failed", "after": "discharged"} in r["cost"]
    # SARIF: the repairs as fix objects; the log still validates against the 2.1.0 schema
    log = sarif_log(report)
    jsonschema.validate(log, json.loads(SARIF_SCHEMA.read_text(encoding="utf-8")))
    res = next(r for r in log["runs"][0]["results"] if r["properties"].get("sideCondition") == "Controller.sc2")
    assert res["properties"]["diagnosis"] == d["sentence"]
    fix = res["fixes"][0]["artifactChanges"][0]
    assert fix["artifactLocation"]["uri"] == "contracts/rover.rcl"
    rep = fix["replacements"][0]
    assert rep["insertedContent"]["text"] == "1.5"
    assert rep["deletedRegion"] == {"startLine": 9, "startColumn": 46, "endLine": 9, "endColumn": 49}


def test_a_broken_checker_shows_no_repair(newcomer: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Every Z3 query answers unknown: the problem is still diagnosed, no repair is shown, and no
    producer guarantee is named (a culprit is named only when Z3 showed it, diagnosis/blame.py)."""
    ws, report = _run(newcomer)
    ws.path(CACHE).unlink(missing_ok=True)
    monkeypatch.setattr(z3.Solver, "check", lambda self, *a, **k: z3.unknown)
    ds = diagnose(ws, report_rows(report))
    d = next(x for x in ds if x["id"] == "Controller.sc2")
    assert "Controller assumes `in.speed <= 1.5`" in d["sentence"] and "Planner's guarantee 1" not in d["sentence"]
    assert "Z3 could not show which" in d["sentence"]
    assert [c["source"] for c in d["culprits"]] == ["contracts/rover.rcl:15:29"]
    assert d["repairs"] == []


def test_a_checker_that_answers_sat_to_everything_shows_no_repair(newcomer: Path,
                                                                  monkeypatch: pytest.MonkeyPatch) -> None:
    """sat means "refuted" for a validity query: a repair needs Z3 to prove the side condition."""
    ws, report = _run(newcomer)
    ws.path(CACHE).unlink(missing_ok=True)
    real_check = z3.Solver.check
    monkeypatch.setattr(z3.Solver, "check", lambda self, *a, **k: (real_check(self, *a, **k), z3.sat)[1])
    assert next(x for x in diagnose(ws, report_rows(report)) if x["id"] == "Controller.sc2")["repairs"] == []


# ---------------------------------------------------------------------------------------------
# Hoare

def test_appendix_b_refutations_name_the_constants_and_get_the_change(sensor: Path) -> None:
    ws, report = _run(sensor)
    hoare = [d.to_json() for d in report.diagnoses if d.kind == "hoare"]
    assert {d["id"].rsplit(".", 1)[1] for d in hoare} == {"c2", "c3"}
    for d in hoare:
        assert "10/20" in d["sentence"] and "120/250" in d["sentence"]
        assert "radiation_sensor_appendix_b.imp:15" in d["sentence"]
        [r] = d["repairs"]
        assert r["kind"] == "constant"
        assert "-IF (input < 10) THEN\n+IF (input < 120) THEN" in r["diff"]
        assert "-   IF (input < 20) THEN\n+   IF (input < 250) THEN" in r["diff"]
        assert {c["after"] for c in r["cost"]} == {"discharged"}
    # the program file itself is untouched
    assert "input < 10" in (sensor / "backends/hoare/radiation_sensor_appendix_b.imp").read_text()


# ---------------------------------------------------------------------------------------------
# vacuity

def test_vacuity_names_the_other_guarantee_and_gets_a_guard(vacuous: Path) -> None:
    ws, report = _run(vacuous)
    d = next(x.to_json() for x in report.diagnoses if x.id == "N.g1.non-vacuous")
    assert d["kind"] == "vacuity"
    assert "guarantee 2 (contracts/n.rcl:6:3)" in d["sentence"]
    assert [c["source"] for c in d["culprits"]] == ["contracts/n.rcl:6:3"]
    [r] = d["repairs"]
    assert r["kind"] == "guard"
    assert "+  guarantee( forall(i in NATURAL | in.a(i) == TRUE and (in.a(i) == FALSE or i > 5) -> out.c == 0) )" \
        in r["diff"]
    assert {"check": "N.g1.non-vacuous", "before": "problem", "after": "ok"} in r["cost"]


# The Agent's pattern in small: guarantee 2 binds i universally and fires for every i without a
# successor waypoint (i = 3 under the facts: waypoints 0..3), so it demands c == 0 always and
# guarantee 1 (c == i + 1 at a waypoint) can never fire.
SUCCESSOR = """context {
  WayP : REAL x REAL --> NATURAL ;
}

node W {
  inputs( wayP : WayP, at : NATURAL, red : BOOL )
  outputs( c : NATURAL )
  assume( TRUE )
  guarantee( forall(i in NATURAL | in.at == i and in.red == FALSE -> out.c == i + 1) )
  guarantee( forall(i in NATURAL |
    in.red == TRUE or not exists(x, y in REAL | in.wayP(x, y) == i + 1) -> out.c == 0) )
}
"""
SUCCESSOR_PLAN = """name: successor
contracts: [contracts/w.rcl]
requirements: []
connections: []
environment:
  W:
    facts:
      - "forall(x, y in REAL | in.wayP(x, y) <= 3)"
      - "forall(k in NATURAL | k <= 3 -> exists(x, y in REAL | in.wayP(x, y) == k))"
nodes: {}
"""


def test_vacuity_repair_restricts_i_to_waypoints_with_a_successor(tmp_path: Path) -> None:
    """Issue 24: the guard offered for the culprit restricts its bound variable to waypoints that
    have a successor (from the facts' bound on the waypoint function), checked by Z3, and says that
    Z3 proved it equivalent to the successor's existence under the facts."""
    root = tmp_path / "succ"
    (root / "contracts").mkdir(parents=True)
    (root / "contracts" / "w.rcl").write_text(SUCCESSOR, encoding="utf-8")
    (root / "contracts" / "plan.yaml").write_text(SUCCESSOR_PLAN, encoding="utf-8")
    ws, report = _run(root)
    d = next(x.to_json() for x in report.diagnoses if x.id == "W.g1.non-vacuous")
    assert "guarantee 2" in d["sentence"]
    [r] = d["repairs"]
    assert r["kind"] == "guard"
    assert r["edit"]["inserted"].startswith("i + 1 <= 3 and (in.red == TRUE or not exists(")
    assert "the same as `exists(x, y in REAL | in.wayP(x, y) == i + 1)` under the environment facts" in r["summary"]
    assert {"check": "W.g1.non-vacuous", "before": "problem", "after": "ok"} in r["cost"]
    assert r["checks"][0] == {"check": "W.contract-consistent", "status": "consistent (Z3: sat, witness found)"}


def test_the_agents_guarantee_3_gets_the_successor_restriction(tmp_path: Path) -> None:
    """The case study's own Agent (issue 24): the guard for guarantee 3, which makes guarantees 1
    (vacuous from i = 0) and 2 vacuous, restricts i to waypoints that have a successor, and Z3 checked
    it.  The health stage's statuses are given (running it takes a minute); the repair search runs."""
    from rclverify.diagnosis.repairs import guard_repair
    root = tmp_path / "cs"
    for d in ("contracts", "backends", "ros"):
        shutil.copytree(REPO / d, root / d)
    ws = Workspace(root)
    before = {"Agent.assumption-satisfiable": "ok", "Agent.contract-consistent": "ok",
              "Agent.g1.non-vacuous": "problem", "Agent.g2.non-vacuous": "problem", "Agent.g3.non-vacuous": "ok"}
    r = guard_repair(ws, "Agent", 3, [(1, 0), (2, None)], before)
    assert r is not None and r["kind"] == "guard"
    assert r["edit"]["inserted"] == ("i + 1 <= 12 and (in.radiationStatus in {red, orange} or "
                                     "not exists(x, y in REAL | in.wayP(x, y) == i + 1))")
    assert "the same as `exists(x, y in REAL | in.wayP(x, y) == i + 1)` under the environment facts" in r["summary"]
    assert {c["check"] for c in r["checks"]} == {"Agent.contract-consistent", "Agent.g1.non-vacuous at 0",
                                                 "Agent.g2.non-vacuous"}
    assert {(c["check"], c["after"]) for c in r["cost"]} == {("Agent.g1.non-vacuous", "ok"),
                                                            ("Agent.g2.non-vacuous", "ok")}
    assert (root / "contracts" / "remote_inspection.rcl").read_text() == (REPO / RCL_FILE).read_text()


def test_without_instances_the_witness_tables_take_the_contracts_numbers() -> None:
    """diagnosis/recheck.py: a table of the plan's instances or 4 points first, then one point per whole
    number up to the largest the formulas write (at most 32), inside quantifiers too."""
    from rclverify.diagnosis.recheck import MAX_NUMERAL_POINTS, numeral_points
    i, x = z3.Int("i"), z3.Real("x")
    f = z3.Function("f", z3.RealSort(), z3.IntSort())
    assert numeral_points([z3.ForAll([x], z3.And(f(x) <= 12, f(x) >= 0)), i + 1 <= 7]) == 13
    assert numeral_points([z3.ForAll([x], f(x) == -20)]) == 21 and numeral_points([x <= z3.RealVal("5/2")]) == 1
    assert numeral_points([i <= 1000]) == MAX_NUMERAL_POINTS and numeral_points([z3.BoolVal(True)]) == 1


def test_the_cut_down_rover_without_instances_gets_the_case_studys_guard(tmp_path: Path) -> None:
    """tests/_incremental.py's rover has no ``instances`` for the Agent, so its witness tables had 4
    points: the weakest guard, ``i + 1 <= 12``, needs a waypoint numbered 1 to 12 and has a witness only
    with 13, the general query ran out of its budget (1.2 s) and a stronger guard was offered.  The
    second table, of the contract's own numbers, finds the witness: the same guard as the case study."""
    import _incremental as inc
    from rclverify.diagnosis.repairs import guard_repair
    root = inc.make_workspace(tmp_path / "ws")
    ws = Workspace(root)
    assert "Agent" not in ws.plan.instances
    before = {"Agent.assumption-satisfiable": "ok", "Agent.contract-consistent": "ok",
              "Agent.g1.non-vacuous": "ok", "Agent.g2.non-vacuous": "problem", "Agent.g3.non-vacuous": "ok"}
    r = guard_repair(ws, "Agent", 3, [(2, None)], before)
    assert r is not None and r["kind"] == "guard"
    assert r["edit"]["inserted"] == ("i + 1 <= 12 and (in.radiationStatus in {red, orange} or "
                                     "not exists(x, y in REAL | in.wayP(x, y) == i + 1))")
    assert {"check": "Agent.g2.non-vacuous", "status": "can fire (Z3: sat, witness found)"} in r["checks"]


def test_explain_and_status_read_the_last_run(newcomer: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["status", "-w", str(newcomer)]) == 1  # no report yet: located error
    assert "no report yet" in capsys.readouterr().err
    ws, report = _run(newcomer)
    from rclverify.app.pipeline import stage_report
    stage_report(ws, report=report)
    html = (newcomer / "reports" / "assurance.html").read_text(encoding="utf-8")
    assert 'id="diagnosis-Controller-sc2"' in html and "+  guarantee( 0 &lt;= out.speed and out.speed &lt;= 1.5 )" in html
    assert ("+  guarantee( 0 <= out.speed and out.speed <= 1.5 )"
            in (newcomer / "reports" / "assurance.md").read_text(encoding="utf-8"))
    assert json.loads((newcomer / "reports" / "assurance.json").read_text())["diagnoses"][0]["id"] == "Controller.sc2"
    assert main(["status", "-w", str(newcomer)]) == 0
    out = capsys.readouterr().out
    # one entry per root cause, as in the report: the side condition and the derived properties it blocks,
    # then each node whose guarantees no obligation covers (the newcomer's plan has no evidence entry)
    assert "4 problems by root cause" in out and "rclverify explain ID" in out, out
    assert "findings: Controller.sc2, Controller.derived, Motor.derived" in out
    assert sum(1 for line in out.splitlines() if line.startswith("  ") and "[unverified]" in line) == 3
    (entry,) = [line for line in out.splitlines() if line.startswith("  1. [failed]")]
    assert "2 repairs (Z3 shows the problem gone, not that the change is safe)" in entry and "findings" in entry
    assert "findings: Controller.sc2" in out
    assert main(["explain", "-w", str(newcomer), "Controller.sc2"]) == 0
    out = capsys.readouterr().out
    assert "counterexample:" in out and "Planner  out.speed  2" in out and "+++ b/contracts/rover.rcl" in out
    assert main(["explain", "-w", str(newcomer), "Nope.sc9"]) == 1
    assert "error: no problem or obligation 'Nope.sc9'" in capsys.readouterr().err


def test_a_broken_checker_shows_no_guard(vacuous: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    ws, report = _run(vacuous)
    ws.path(CACHE).unlink(missing_ok=True)
    monkeypatch.setattr(z3.Solver, "check", lambda self, *a, **k: z3.unknown)
    d = next(x for x in diagnose(ws, report_rows(report)) if x["id"] == "N.g1.non-vacuous")
    assert "guarantee 2 (contracts/n.rcl:6:3)" in d["sentence"] and d["repairs"] == []


def test_parallel_report_tasks_diagnose_one_at_a_time(newcomer: Path) -> None:
    """Two processes diagnosing one workspace (the diagnosis task and `rclverify report`): the second
    waits on the diagnosis lock, then finds the first's repairs in the cache instead of computing them again."""
    import fcntl
    import threading
    from rclverify.diagnosis.repair_cache import LOCK
    ws, report = _run(newcomer)
    ws.path(CACHE).unlink(missing_ok=True)
    fd = os.open(ws.path(LOCK), os.O_RDWR | os.O_CREAT)
    fcntl.flock(fd, fcntl.LOCK_EX)  # another process diagnosing
    done: list[Any] = []
    t = threading.Thread(target=lambda: done.append(diagnose(ws, report_rows(report))))
    t.start()
    t.join(1.0)
    assert not done and not ws.path(CACHE).exists()  # waiting, nothing computed
    os.close(fd)
    t.join(60)
    assert done and ws.path(CACHE).exists()
    assert next(x for x in done[0] if x["id"] == "Controller.sc2")["repairs"]


def test_a_branch_that_is_not_one_point_gives_no_table() -> None:
    """Model-based instantiation writes branches as disjunctions or leaves an
    argument free; then the last ``else`` is not the value elsewhere (the case
    study's replacement counterexample read 128 there although every other
    point maps to 0), so no table is claimed and the text is shown, cut."""
    disjunct = "{(p1, p2) -> (if (((p1 == 1) and (p2 == 2)) or ((p1 == 3) and (p2 == 4))) then 0 else 128)}"
    free = "{(p1, p2) -> (if (not (p1 == 1) and (p2 == 2)) then 0 else 128)}"
    assert function_table(disjunct) is None and function_table(free) is None
    row = counterexample_table({"Agent.in.wayP": disjunct})[0]
    assert row["table"] is None and "128" in row["value"] and "else -> 128" not in row["value"]
