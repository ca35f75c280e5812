"""Contract health: satisfiable assumptions, consistency, non-vacuity (with unsat cores)."""
from __future__ import annotations

from pathlib import Path

import pytest

from rclverify.calculus.health.checks import check_node
from rclverify.semantics import world
from rclverify.model.plan.load import load_plan, resolve
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check, load

ROOT = Path(__file__).resolve().parents[2]


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
    assert set(f) == {"n.assumption-satisfiable", "n.contract-consistent", "n.realizable"}
    assert f["n.realizable"].status == "ok"  # y = x answers every input: proved realizable


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
    world.fresh()  # the Z3 state of the node task (semantics/world.py), whatever this worker ran before
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
    # at i = 12 (no waypoint 13) guarantee 3 demands the move to waypoint 0 that guarantee 1 allows there:
    # a finite-table witness of that instance's premise shows it, where the general query gives up
    assert g1.instances["12"] == "can fire"
    assert "it can fire only for i in {12}" in g1.message
    assert agent_findings["Agent.assumption-satisfiable"].status == "ok"
    # undecided checks are never reported as ok
    assert agent_findings["Agent.contract-consistent"].status in ("inconclusive", "ok")


def _rcl_value(text: str):
    """A value of a witness as the report prints it: a number, TRUE/FALSE, an
    enumeration value or a constructor term with numeric arguments."""
    import re
    from fractions import Fraction
    from rclverify.semantics.values import Term
    text = text.strip()
    if text in ("TRUE", "FALSE"):
        return text == "TRUE"
    m = re.fullmatch(r"(\w+)\((.*)\)", text)
    if m:
        return Term(m.group(1), tuple(_rcl_value(a) for a in m.group(2).split(",")))
    if re.fullmatch(r"-?[\d.]+(/\d+)?", text):
        q = Fraction(text)
        return int(q) if q.denominator == 1 else q
    return text


def _witness_values(model: dict[str, str], node: str) -> dict[str, object]:
    """The witness's values keyed ``in.x``/``out.y``, tables as FiniteFunction."""
    import re
    from rclverify.semantics.values import FiniteFunction
    out: dict[str, object] = {}
    for name, text in model.items():
        key = name.removeprefix(f"{node}.")
        if text.startswith("{"):
            rows = re.findall(r"\(([^)]*)\) -> ([^,}]+(?:\([^)]*\))?)", text)
            default = re.search(r"else -> ([^,}]+)\}$", text)
            assert default is not None, text
            table = {tuple(_rcl_value(a) for a in args.split(",")): _rcl_value(v) for args, v in rows}
            out[key] = FiniteFunction(table, _rcl_value(default.group(1)), len(next(iter(table))))
        else:
            out[key] = _rcl_value(text)
    return out


def test_case_study_agent_consistency_witness_is_a_finite_table_that_meets_the_contract(agent_findings):
    """The Agent's consistency is decided by a witness of finite tables
    (calculus/health/witness.py), asked before the general query: the reported
    witness, read back from its RCL text, satisfies the assumption, every
    guarantee and every environment fact by direct evaluation (the monitors'
    engine, not Z3)."""
    from rclverify.semantics.evaluate import evaluate
    c = agent_findings["Agent.contract-consistent"]
    assert c.status == "ok" and c.model is not None and "finite table" in c.explanation
    assert c.model["Agent.in.wayP"].startswith("{(0, 0) -> ")
    plan = load_plan(ROOT)
    checked = load([ROOT / p for p in plan.contracts])
    resolve(plan, checked)
    node = checked.nodes["Agent"]
    values = _witness_values(c.model, "Agent")
    formulas = [a.formula for a in node.node.assumes] + [g.formula for g in node.node.guarantees] \
        + [f.expr for f in plan.facts["Agent"]]
    assert [evaluate(f, checked, node, values) for f in formulas] == [True] * len(formulas)
    assert "(declare-fun Agent.in.wayP (Real Real) Int)" in c.smt2  # the statement is the general query's


def test_no_finite_table_witness_leaves_consistency_to_the_general_query():
    """A contradictory contract over a function-typed input has no witness of
    finite tables; the general query then answers, and the finding is a
    problem with its unsat core (the witness never answers anything but ok)."""
    f = _findings("""context { T : REAL --> REAL; }
      node n { inputs(f : T) outputs(y : REAL)
      guarantee(out.y == in.f(1)) guarantee(out.y > in.f(1)) }""", "n")
    c = f["n.contract-consistent"]
    assert c.status == "problem" and "finite table" not in c.explanation
    assert sorted(c.core) == ["guarantee 1 (t.rcl:3:7)", "guarantee 2 (t.rcl:3:35)"]


def test_case_study_agent_guarantee_3_can_fire(agent_findings):
    """Guarantee 3 of the Agent can fire (its premise holds whenever i has no
    successor waypoint).  The general query does not decide it in its first
    budget nor any instance in the scan's first look; no instance being
    vacuous, the consistency check's witness of finite tables, extended to
    the premise's variables, decides it (issue 44: decide first with what
    decides; a new witness of finite tables if it did not), in a context of
    its own.  The witness, read back
    from its RCL text, meets the assumption, every guarantee, every fact
    and the premise at its ``i``, by direct evaluation (not Z3)."""
    from rclverify.semantics.evaluate import Evaluator, evaluate
    from rclverify.lang import ast
    g3 = agent_findings["Agent.g3.non-vacuous"]
    assert g3.status == "ok" and g3.model is not None and g3.instances is None
    assert g3.model["Agent.in.wayP"].startswith("{(0, 0) -> ")
    plan = load_plan(ROOT)
    checked = load([ROOT / p for p in plan.contracts])
    resolve(plan, checked)
    node = checked.nodes["Agent"]
    model = {k: v for k, v in g3.model.items() if k.startswith("Agent.")}
    values = _witness_values(model, "Agent")
    formulas = [a.formula for a in node.node.assumes] + [g.formula for g in node.node.guarantees] \
        + [f.expr for f in plan.facts["Agent"]]
    assert [evaluate(f, checked, node, values) for f in formulas] == [True] * len(formulas)
    g = node.node.guarantees[2].formula
    while isinstance(g, ast.Quant) and g.kind == "forall":
        g = g.body
    assert isinstance(g, ast.Binary) and g.op == "->"
    i = int(g3.model["i (witness for guarantee 3)"])
    assert Evaluator(checked, node, values).eval(g.left, {"i": i}) is True  # the premise at the witness's i
    assert "(declare-fun Agent.in.wayP (Real Real) Int)" in g3.smt2  # the statement is the general query's


def test_the_natural_components_of_a_tuple_are_typed():
    """A ``(NATURAL, NATURAL)`` is two integers to Z3 (a ``seq(NATURAL)`` a sequence of integers): without their ``>= 0`` a guarantee only a negative
    component meets read consistent, an assumption only one meets satisfiable (semantics/natural.py)."""
    out = ("node C { inputs( x : INTEGER ) outputs( y : (NATURAL, NATURAL) ) assume( TRUE ) "
           "guarantee( exists(a, b in INTEGER | out.y == (a, b) and a < 0) ) }")
    status = {f.check: f.status for f in _findings(out, "C").values()}
    assert status["contract-consistent"] == "problem" and status.get("realizable") != "ok", status
    inp = ("node C { inputs( x : (NATURAL, NATURAL) ) outputs( y : INTEGER ) "
           "assume( exists(a, b in INTEGER | in.x == (a, b) and b < 0) ) guarantee( out.y == 1 ) }")
    assert {f.check: f.status for f in _findings(inp, "C").values()}["assumption-satisfiable"] == "problem"
    seq = ("node C { inputs( x : INTEGER ) outputs( y : seq(NATURAL) ) assume( TRUE ) "
           "guarantee( exists(v in INTEGER | v in out.y and v < 0) ) }")  # a sequence's elements, by a quantifier
    world.fresh()  # as the pipeline asks each node: in a fresh Z3 context
    assert {f.check: f.status for f in _findings(seq, "C").values()}["contract-consistent"] != "ok"
