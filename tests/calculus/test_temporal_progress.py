"""Progress and initial values in the temporal requirements (issue 40).

A two-node robot: Planner reads the goal (the environment's, 0..10) and the
pose Base reports, and sends the goal on as Base's target; Base drives to
its target and reports its pose.  "Eventually the robot arrives" is
``eventually Planner.in.pose == 7`` with the goal held at 7.  Without
progress Base may never answer, so the requirement is refuted by a lasso
whose environment inputs meet their assumptions and which names Base (not
Planner, whose input the goal reads) as missing progress; with progress
declared it is proved by bounded reachability; without initial values the
loop is stuck on the values from before the run, and the producers are
named.  The RCL rules are located errors.  Real Z3, the real pipeline.
"""
from __future__ import annotations

import json
from pathlib import Path

import pytest

from rclverify.cli.commands import main
from rclverify.app.pipeline import Workspace, stage_check, stage_requirements
from rclverify.model.plan.errors import PlanError
from rclverify.lang.errors import RclError

PLANNER = """node Planner {{
  inputs( goal : INTEGER, pose : INTEGER )
  outputs( target : INTEGER )
  assume( 0 <= in.goal and in.goal <= 10 )
  assume( 0 <= in.pose and in.pose <= 10 )
  guarantee( out.target == in.goal )
  {}
}}
"""
BASE = """node Base {{
  inputs( target : INTEGER )
  outputs( pose : INTEGER )
  assume( 0 <= in.target and in.target <= 10 )
  guarantee( out.pose == in.target )
  {}
}}
"""
ARRIVE = {"id": "ARRIVE", "text": "the robot eventually arrives at the goal",
          "formal": "eventually Planner.in.pose == 7", "assuming": "Planner.in.goal == 7"}


def _ws(tmp: Path, planner: str, base: str, reqs: list[dict[str, str]] | None = None) -> Path:
    ws = tmp / "robot"
    (ws / "contracts").mkdir(parents=True)
    (ws / "contracts/r.rcl").write_text(PLANNER.format(planner) + BASE.format(base))
    text = "".join("  - " + "\n    ".join(f"{k}: {json.dumps(v)}" for k, v in r.items()) + "\n"
                   for r in (reqs or [ARRIVE]))
    (ws / "contracts/plan.yaml").write_text(f"contracts: [contracts/r.rcl]\nrequirements:\n{text}")
    return ws


def _records(ws: Path) -> dict[str, dict]:
    from rclverify.report.build import build_report
    w = Workspace(ws)
    stage_check(w)
    stage_requirements(w)
    return {r["id"]: r for r in build_report(w).to_json()["requirements"]}


def _node(step: dict, name: str) -> dict[str, str]:
    return next(x["values"] for x in step["nodes"] if x["node"] == name)


def test_without_progress_the_lasso_names_the_node_that_never_answers(tmp_path: Path) -> None:
    """(1) Planner answers at every step, Base declares an initial pose but
    no progress: a lasso in which Base never answers although its input is
    accepted.  The environment's goal meets Planner's assumption at every
    step; the record, the roll-up's note, the diagnosis and the problem row
    name Base (its contract's header), not Planner."""
    ws = _ws(tmp_path, "progress( within 0 steps )", "initially( out.pose == 0 )")
    assert main(["verify", "-w", str(ws)]) == 0
    report = json.loads((ws / "reports/assurance.json").read_text())
    r = next(q for q in report["requirements"] if q["id"] == "ARRIVE")
    t = r["check"]["temporal"]
    assert (r["verdict"], t["status"], t["method"]) == ("refuted", "refuted", "lasso")
    loop = t["trace"][t["loop"]:-1] or [t["trace"][t["loop"]]]
    for st in t["trace"]:  # the environment assumption: the goal Planner reads is in 0..10 (here 7) at every step
        assert 0 <= int(_node(st, "Planner")["in.goal"]) <= 10
    base = [_node(st, "Base") for st in loop]
    assert all(b["answers"] in ("False", "FALSE") for b in base) and any(b["accepts"] in ("True", "TRUE") for b in base)
    assert all(0 <= int(b["in.target"]) <= 10 for b in base if b["accepts"] in ("True", "TRUE"))
    assert [g["node"] for g in t["missing_progress"]] == ["Base"]
    assert t["missing_progress"][0]["source"] == "contracts/r.rcl:9:1" and t["missing_initially"] == []
    assert "Base never answers in its loop although its assumption holds there" in r["note"]
    assert "progress(" in r["note"] and r["check"]["failed_to_prevent"] == []  # no guarantee of Planner blamed
    d = next(x for x in report["diagnoses"] if x["id"] == "ARRIVE")
    assert d["node"] == "Base" and [c["source"] for c in d["culprits"]] == ["contracts/r.rcl:9:1"]
    row = next(g for g in report["problems"] if any(m["id"] == "ARRIVE" for m in g["members"]))
    assert row["key"] == ["contract:Base"] and "Base never answers" in row["sentence"]
    # SARIF and the terminal's explanation say the same
    assert "Base never answers" in (ws / "reports/assurance.md").read_text()
    # the repair: the weakest progress bound tried with which the requirement check proves ARRIVE, checked on
    # the edited contracts; applied, the requirement is proved (declared, not verified: evidence outstanding)
    [rep] = d["repairs"]
    assert rep["kind"] == "declare-progress" and rep["edit"]["inserted"] == "  progress( within 3 steps )\n"
    assert rep["checks"] == [{"check": "ARRIVE", "status": "proved (temporal check: bounded)"}]
    assert "which no backend checks yet" in rep["not_shown"] and row["repairs"]
    from rclverify.diagnosis.edits import Edit
    e = rep["edit"]
    path = ws / e["file"]
    path.write_text(Edit(e["file"], e["line"], e["col"], e["end_line"], e["end_col"], e["inserted"])
                    .apply(path.read_text()))
    fixed = _records(ws)["ARRIVE"]
    assert fixed["check"]["temporal"]["status"] == "proved" and fixed["verdict"] == "proved, evidence outstanding"


def test_with_progress_declared_the_same_requirement_is_proved(tmp_path: Path) -> None:
    """(2) Base answers within one step of accepting a target: every run
    reaches the goal within the bound (proved by bounded reachability), no
    run stops; never met, since the declared progress and initial value are
    claims no evidence backs yet.  ``progress( eventually )`` alone excludes
    the lasso but bounds nothing: inconclusive, never refuted."""
    recs = _records(_ws(tmp_path, "progress( within 0 steps )",
                        "initially( out.pose == 0 )\n  progress( within 1 steps )"))
    r = recs["ARRIVE"]
    t = r["check"]["temporal"]
    assert (t["status"], t["method"]) == ("proved", "bounded") and t["deadlock"].startswith("no run stops"), t
    assert r["verdict"] == "proved, evidence outstanding"
    assert "Base progress (declared, not verified)" in r["note"] and "Base initially 1" in r["note"]
    labels = {p["label"] for p in r["check"]["used"]}
    assert {"Base progress", "Planner progress", "Base initially 1"} <= labels
    eventually = _records(_ws(tmp_path / "ev", "progress( within 0 steps )",
                              "initially( out.pose == 0 )\n  progress( eventually )"))["ARRIVE"]
    assert eventually["verdict"] == "inconclusive" and eventually["check"]["temporal"]["missing_progress"] == []


def test_initial_values_unstick_the_loop_and_are_used_by_safety(tmp_path: Path) -> None:
    """(3) Without initial values the loop is stuck: each node waits for a
    value the other never publishes (docs/semantics.md), so neither ever
    answers, whatever progress both declare; the producers are named.  With
    Base's initial pose the same system proves ARRIVE, and ``always next``
    reads the initial value."""
    safe = {"id": "SAFE", "text": "the pose Planner reads is never negative",
            "formal": "always next Planner.in.pose >= 0"}
    stuck = _records(_ws(tmp_path, "progress( within 0 steps )", "progress( within 1 steps )", [ARRIVE, safe]))
    t = stuck["ARRIVE"]["check"]["temporal"]
    assert stuck["ARRIVE"]["verdict"] == "refuted" and t["method"] == "lasso" and t["missing_progress"] == []
    assert {(g["node"], g["consumer"]) for g in t["missing_initially"]} >= {("Base", "Planner.in.pose")}
    loop = t["trace"][t["loop"]]
    assert _node(loop, "Planner")["heard.pose"] in ("False", "FALSE") and _node(loop, "Base")["answers"] in ("False", "FALSE")
    assert "initially(" in stuck["ARRIVE"]["note"]
    # no pose is ever published: nothing for SAFE to judge (before issue 47 a pose "from before the run" refuted it)
    assert stuck["SAFE"]["check"]["temporal"]["status"] == "proved"
    fixed = _records(_ws(tmp_path / "fixed", "progress( within 0 steps )",
                         "initially( out.pose == 0 )\n  progress( within 1 steps )", [ARRIVE, safe]))
    assert fixed["ARRIVE"]["check"]["temporal"]["status"] == "proved"
    assert fixed["SAFE"]["check"]["temporal"]["status"] == "proved"


def test_a_table_lasso_that_breaks_fairness_is_not_confirmed(tmp_path: Path) -> None:
    """The independent confirmation of a lasso (calculus/requirements/lasso_confirm.py)
    checks the progress rules on the values: a Base that declares progress
    but never answers what it accepts in the loop is not a run."""
    from rclverify.model.plan.temporal import operands
    from rclverify.calculus.requirements.lasso_confirm import confirm_lasso
    from rclverify.calculus.requirements.temporal_check import statement
    from rclverify.calculus.requirements.composed import variable_types
    from rclverify.calculus.requirements.transition import build_system
    from rclverify.model.plan.formal import parse_formal
    ws = _ws(tmp_path, "progress( within 0 steps )", "initially( out.pose == 0 )")
    w = Workspace(ws)
    checked, model, plan = w.checked, w.model, w.plan
    req = plan.requirements[0]
    goal = operands(statement(req, checked, plan))[0]
    sys = build_system(list(model.nodes), checked, model, plan)
    types = variable_types(sys, checked, plan)
    common = {"Planner.in.goal": 7, "Planner.in.pose": 0, "Planner.out.target": 7, "Planner.accepts": True,
              "Base.in.target": 7, "Base.out.pose": 0, "Base.answers": False, "Base.accepts": True,
              "Base.published": True}  # Base's initial pose is published from the start
    # step 0: Planner has not heard the pose yet; step 1: it has and answers; step 2: Base has heard the target
    st0 = {**common, "Planner.answers": False, "Planner.published": False, "Planner.heard.pose": False,
           "Base.heard.target": False}
    st1 = {**st0, "Planner.answers": True, "Planner.published": True, "Planner.heard.pose": True}
    st = {**st1, "Base.heard.target": True}
    assuming = [parse_formal(a, checked, "ARRIVE assuming") for a in req.assuming]
    args = (list(model.nodes), sys.variables, types, checked, model, plan, goal, assuming)
    assert confirm_lasso([st0, st1, st, dict(st)], 2, *args, pub=sys.pub) is None  # Base may stay idle
    why = confirm_lasso([st0, st1, st, dict(st)], 2, *args, ["Base"], sys.pub)
    assert why is not None and "Base accepts its input in the loop but never answers" in why
    lazy = {**st, "Planner.answers": False}
    why = confirm_lasso([st0, lazy, dict(lazy)], 1, *args, pub=sys.pub)
    assert why is not None and "Planner accepts its input but does not answer" in why
    # the published-value flags are checked too: a node answering before it heard its input is no run
    early = {**st0, "Planner.answers": True, "Planner.published": True}
    why = confirm_lasso([early, st1, st, dict(st)], 2, *args, pub=sys.pub)
    assert why is not None and "before every input it reads was published" in why


@pytest.mark.parametrize("clause, words", [
    ("initially( in.goal == 0 )", "it cannot read input in.goal"),
    ("progress( within 2 ms )", "progress is counted in steps of the composed system"),
    ("progress( within 1001 steps )", "at most 1000"),
    ("progress( eventually )\n  progress( within 1 steps )", "declares progress twice"),
    ("periodic( in.goal, 100 ms )", "a period is a rate of an output"),
    ("periodic( out.target, 0 steps )", "a whole number from 1 to 1000"),
    ("periodic( out.target, 3 m )", "'m' is a unit of length, not of time in period"),
], ids=["initially-input", "progress-time", "progress-bound", "progress-twice", "periodic-input", "periodic-0",
        "periodic-unit"])
def test_declarations_are_checked_with_located_errors(tmp_path: Path, clause: str, words: str) -> None:
    ws = _ws(tmp_path, clause, "")
    with pytest.raises((RclError, PlanError)) as e:
        Workspace(ws).checked
    d = str(e.value.diagnostics[0])
    assert d.startswith("contracts/r.rcl:") and "error" in d and words in d, d


def test_fmt_and_latex_keep_the_declarations(tmp_path: Path) -> None:
    from rclverify.lang.latex import to_latex
    from rclverify.lang.parser import parse_text
    from rclverify.lang.printer import to_rcl
    text = PLANNER.format("progress( eventually )\n  periodic( out.target, 100 ms )") + BASE.format(
        "initially( out.pose == 0 )\n  progress( within 2 steps )")
    spec = parse_text(text, "r.rcl")
    printed = to_rcl(spec)
    assert parse_text(printed, "r.rcl") == spec
    assert "  progress( within 2 steps )\n" in printed and "  initially( out.pose == 0 )\n" in printed
    assert "  periodic( out.target, 100 ms )\n" in printed and "  progress( eventually )\n" in printed
    tex = to_latex(spec)
    assert "progress & within 2 steps" in tex and r"periodic & $\mathit{out.target}$, 100~\textrm{ms}" in tex


def test_an_initial_value_no_output_meets_is_an_inconsistency(tmp_path: Path) -> None:
    """``initially( out.pose == 0 and out.pose == 1 )`` would force Base to
    answer at step 0 and so silently remove the runs whose first target it
    cannot accept: a proof over it is `proved from an inconsistency`, never
    met, with the initial value as the core."""
    safe = {"id": "SAFE", "text": "the pose Planner reads is never negative",
            "formal": "always next Planner.in.pose >= 0"}
    r = _records(_ws(tmp_path, "progress( within 0 steps )",
                     "initially( out.pose == 0 and out.pose == 1 )\n  progress( within 1 steps )", [safe]))["SAFE"]
    assert r["check"]["temporal"]["status"] == "proved"
    assert (r["verdict"], r["status"]) == ("proved from an inconsistency", "failed")
    assert [p["label"] for p in r["check"]["inconsistent_core"]] == ["Base initially 1"]


def test_declaring_progress_rechecks_and_equals_a_clean_run(tmp_path: Path) -> None:
    """The declarations are in the node's snapshot: adding one re-checks the
    requirements whose cone holds the node, and the result equals a clean run."""
    ws = _ws(tmp_path, "progress( within 0 steps )", "initially( out.pose == 0 )")
    assert _records(ws)["ARRIVE"]["verdict"] == "refuted"
    rcl = ws / "contracts/r.rcl"
    rcl.write_text(rcl.read_text().replace("initially( out.pose == 0 )",
                                           "initially( out.pose == 0 )\n  progress( within 1 steps )"))
    w = Workspace(ws)
    stage_check(w)
    again = stage_requirements(w)
    assert [r["id"] for r, now in again if now] == ["ARRIVE"]
    inc = _records(ws)["ARRIVE"]
    clean = _records(_ws(tmp_path / "clean", "progress( within 0 steps )",
                         "initially( out.pose == 0 )\n  progress( within 1 steps )"))["ARRIVE"]
    assert inc["verdict"] == clean["verdict"] == "proved, evidence outstanding"
    assert inc["check"]["temporal"] | {"duration_s": 0} == clean["check"]["temporal"] | {"duration_s": 0}
