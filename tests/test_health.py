"""Contract health: satisfiable assumptions, consistency, non-vacuity (with unsat cores)."""
from __future__ import annotations

from pathlib import Path

import pytest

from rclverify.health.checks import check_node
from rclverify.plan.load import load_plan, resolve
from rclverify.rcl.parser import parse_text
from rclverify.rcl.typecheck import check, load

ROOT = Path(__file__).resolve().parents[1]


def _findings(text: str, node: str, facts=(), instances=None):
    checked = check([parse_text(text, "t.rcl")])
    return {f.id: f for f in check_node(checked, node, facts, instances, timeout_ms=3000)}


def test_unsatisfiable_assumption_is_a_problem_with_core():
    f = _findings("""node n { inputs(x : REAL) outputs(y : REAL)
      assume(in.x > 1) assume(in.x < 0) guarantee(out.y == in.x) }""", "n")
    a = f["n.assumption-satisfiable"]
    assert a.status == "problem"
    assert len(a.core) == 2 and all(c.startswith("assumption") for c in a.core)


def test_self_contradictory_contract():
    f = _findings("""node n { inputs(x : REAL) outputs(y : REAL)
      guarantee(out.y > 1) guarantee(out.y < 0) }""", "n")
    c = f["n.contract-consistent"]
    assert c.status == "problem"
    assert sorted(c.core) == ["guarantee 1 (t.rcl:2:7)", "guarantee 2 (t.rcl:2:28)"]


def test_a_guarantee_without_premise_gets_no_vacuity_verdict():
    f = _findings("""node n { inputs(x : REAL) outputs(y : REAL) guarantee(out.y == in.x) }""", "n")
    assert set(f) == {"n.assumption-satisfiable", "n.contract-consistent"}


def test_vacuous_and_firing_guarantees():
    f = _findings("""context { S : {on, off}; }
      node n { inputs(x : REAL) outputs(s : S)
      assume(in.x >= 0)
      guarantee(forall(k in NATURAL | in.x < 0 -> out.s == on))
      guarantee(forall(k in NATURAL | in.x > k -> out.s == off)) }""", "n")
    assert f["n.g1.non-vacuous"].status == "problem"
    assert any(c.startswith("assumption") for c in f["n.g1.non-vacuous"].core)
    ok = f["n.g2.non-vacuous"]
    assert ok.status == "ok" and ok.model is not None


@pytest.fixture(scope="module")
def agent_findings():
    plan = load_plan(ROOT)
    checked = load([ROOT / c for c in plan.contracts])
    resolve(plan, checked)
    facts = [(f.expr, f.loc) for f in plan.facts["Agent"]]
    return {f.id: f for f in check_node(checked, "Agent", facts, plan.instances["Agent"])}


def test_case_study_agent_guarantee_2_is_vacuous(agent_findings):
    """With 13 waypoints, guarantee 3 (i universally quantified) forces a move to
    waypoint 0 at every step, so the premise of guarantee 2 can never hold."""
    g2 = agent_findings["Agent.g2.non-vacuous"]
    assert g2.status == "problem"
    assert any(c.startswith("guarantee 3") for c in g2.core)
    assert any(c.startswith("premise of guarantee 2") for c in g2.core)


def test_case_study_agent_guarantee_1_vacuous_below_the_last_waypoint(agent_findings):
    g1 = agent_findings["Agent.g1.non-vacuous"]
    assert g1.status == "problem"
    assert g1.instances is not None
    assert all(g1.instances[str(i)] == "vacuous" for i in range(12))
    assert g1.instances["12"] != "vacuous"
    assert agent_findings["Agent.assumption-satisfiable"].status == "ok"
    # undecided checks are never reported as ok
    assert agent_findings["Agent.contract-consistent"].status in ("inconclusive", "ok")
