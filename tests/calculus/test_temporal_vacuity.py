"""A temporal proof that no run exercises is vacuous, never met (docs/requirements.md,
"A proof no run exercises").

Inc answers what Fwd hands it, Fwd what Inc hands it: a loop.  Without an
initial value neither ever has an input, so neither ever publishes, and
``always Inc.out.b <= 0`` holds of every run because no value of Inc.out.b
is ever read: it is ``proved vacuously`` (status ``failed``) with a reason
naming Inc and Fwd, whatever the evidence says, and ``--strict`` fails.
With Fwd's ``initially( out.a == 0 )`` the loop starts: a true statement is
proved and, once its evidence is discharged, met (the control).  An
``always (P -> Q)`` whose premise P holds on no run of a loop that does
start is vacuous too; one whose premise some run reaches is not.  The
requirements stage runs in-process on small workspaces; real Z3.
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from rclverify.app.pipeline import Workspace, stage_check, stage_requirements
from rclverify.calculus.requirements.published import publication
from rclverify.calculus.requirements.rollup import roll_up
from rclverify.report.build import build_report
from rclverify.report.summary_rows import strict_gate

RCL = """node Inc { inputs( a : NATURAL ) outputs( b : NATURAL )
  guarantee( out.b == in.a + 1 )
  progress( within 0 steps ) }
node Fwd { inputs( b : NATURAL ) outputs( a : NATURAL )
  guarantee( out.a == in.b )
  progress( within 0 steps ) }
"""
STARTED = RCL.replace("guarantee( out.a == in.b )", "guarantee( out.a == in.b )\n  initially( out.a == 0 )")


def _records(root: Path, rcl: str, formals: dict[str, str]) -> dict[str, dict[str, Any]]:
    """The requirement rows of the report of a workspace with contracts ``rcl`` and requirements ``formals``,
    each with its stage record (``record``)."""
    ws = root / "ws"
    (ws / "contracts").mkdir(parents=True)
    (ws / "contracts/n.rcl").write_text(rcl)
    reqs = "".join(f"  - id: {rid}\n    text: {rid}\n    formal: {json.dumps(f)}\n" for rid, f in formals.items())
    (ws / "contracts/plan.yaml").write_text(f"contracts: [contracts/n.rcl]\nrequirements:\n{reqs}")
    w = Workspace(ws)
    stage_check(w)
    records = {rec["id"]: rec for rec, _ in stage_requirements(w)}
    return {r["id"]: {**r, "record": records[r["id"]]} for r in build_report(w).to_json()["requirements"]}


@pytest.fixture(scope="module")
def stuck(tmp_path_factory: pytest.TempPathFactory) -> dict[str, dict[str, Any]]:
    return _records(tmp_path_factory.mktemp("stuck"), RCL, {
        "ZERO": "always Inc.out.b <= 0",                                      # the hostile tester's row
        "NEXT": "always next Fwd.in.b >= 1",
        "RESP": "always (Inc.out.b >= 1 -> eventually[<= 2] Fwd.out.a >= 1)",
    })


@pytest.fixture(scope="module")
def started(tmp_path_factory: pytest.TempPathFactory) -> dict[str, dict[str, Any]]:
    return _records(tmp_path_factory.mktemp("started"), STARTED, {
        "POS": "always Inc.out.b >= 1",                                       # the control
        "NEVER": "always (Inc.out.b == 0 -> Fwd.out.a == 7)",                 # Inc.out.b is never 0
        "SOME": "always (Inc.out.b >= 3 -> Inc.out.b >= 2)",                  # reached at step 2
    })


def _discharged(record: dict[str, Any]) -> tuple[str, str, str]:
    """The roll-up of ``record`` with every guarantee, side condition and declaration discharged."""
    return roll_up(record, lambda n, k: "discharged", {}, "discharged",
                   lambda n, kind, i: ("discharged", "declaration, discharged: 1 discharged of 1 record"))


def _strict(verdict: str) -> bool:
    """The ``--strict`` gate of a run whose only open item is a requirement of ``verdict``."""
    from _typed_rows import typed_report
    return strict_gate(typed_report({"requirements": [{"verdict": verdict}]}), lambda: True, True)


def test_a_loop_that_never_starts_proves_nothing(stuck: dict[str, dict[str, Any]]) -> None:
    r = stuck["ZERO"]
    c = r["check"]
    assert c["temporal"]["status"] == "proved"  # the induction holds: no value of Inc.out.b is ever read
    # whatever the evidence: every guarantee and declaration discharged still does not make it met
    verdict, status, _ = _discharged(r["record"])
    assert (verdict, status) == ("proved vacuously", "failed")
    assert not _strict(verdict)
    assert (r["verdict"], r["status"]) == ("proved vacuously", "failed")
    assert "Inc and Fwd never publish" in r["note"] and "Inc.out.b never has a value" in r["note"]
    assert "initially" in r["note"]
    assert (c["consistency"], c["vacuity"]) == ("consistent", "vacuous")
    assert c["temporal"]["never_publish"] == ["Inc", "Fwd"]


@pytest.mark.parametrize("rid", ["NEXT", "RESP"])
def test_every_safety_shape_over_the_stuck_loop_is_vacuous(stuck: dict[str, dict[str, Any]], rid: str) -> None:
    r = stuck[rid]
    assert r["check"]["temporal"]["status"] == "proved", r["check"]["temporal"]
    assert (r["verdict"], r["status"]) == ("proved vacuously", "failed")
    assert "never publish" in r["note"]


def test_the_same_loop_with_an_initial_value_is_proved_and_met(started: dict[str, dict[str, Any]]) -> None:
    r = started["POS"]
    c = r["check"]
    assert (c["temporal"]["status"], c["consistency"]) == ("proved", "consistent")
    assert r["verdict"] == "proved, evidence outstanding"  # no evidence in this workspace: never met
    verdict, status, _ = _discharged(r["record"])
    assert (verdict, status) == ("met", "discharged")
    assert _strict(verdict)


def test_the_initial_value_that_starts_the_loop_is_a_premise_used(started: dict[str, dict[str, Any]]) -> None:
    """Without Fwd's initially the statement is proved too, but by no run: the declaration the non-vacuous
    proof rests on is used (its evidence asked for), not traced as not needed."""
    c = started["POS"]["check"]
    assert "Fwd initially 1" in {p["label"] for p in c["used"]}
    assert c["traced_not_needed"] == []
    assert c["vacuity"] == "non-vacuous"


def test_a_premise_no_run_reaches_is_vacuous(started: dict[str, dict[str, Any]]) -> None:
    never = started["NEVER"]
    assert never["check"]["temporal"]["status"] == "proved"
    assert (never["verdict"], never["status"]) == ("proved vacuously", "failed")
    assert "Inc.out.b == 0" in never["note"] and "holds on no run" in never["note"]
    assert _discharged(never["record"])[0] == "proved vacuously"


def test_a_premise_some_run_reaches_is_met(started: dict[str, dict[str, Any]]) -> None:
    some = started["SOME"]
    assert some["check"]["temporal"]["status"] == "proved"
    assert _discharged(some["record"])[:2] == ("met", "discharged")


def test_silent_nodes_are_those_no_initial_value_or_environment_input_starts() -> None:
    # S reads the environment; L1 <-> L2 a loop with no initial value; D reads L1; M reads S and L2
    links = [("L1.in.x", "L2.out.y"), ("L2.in.y", "L1.out.x"), ("D.in.x", "L1.out.x"),
             ("M.in.s", "S.out.s"), ("M.in.y", "L2.out.y")]
    reads = {"S": {"r"}, "L1": {"x"}, "L2": {"y"}, "D": {"x"}, "M": {"s", "y"}}
    nodes = ["S", "L1", "L2", "D", "M"]
    assert publication(nodes, links, reads, []).silent() == ["L1", "L2", "D", "M"]
    assert publication(nodes, links, reads, ["L2"]).silent() == []
    # an input the contract does not read does not hold the node back
    assert publication(nodes, links, {**reads, "M": {"s"}}, []).silent() == ["L1", "L2", "D"]
