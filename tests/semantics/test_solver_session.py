"""Queries sharing one incremental solver (semantics/solvers.py, ``solver_session``):
the same verdicts and cores as fresh solvers, nothing left behind by a
query, and the same answers every time a unit of work is repeated."""
from __future__ import annotations

from pathlib import Path

import z3

from rclverify.calculus.compose import compose_node
from rclverify.calculus.health.checks import check_node
from rclverify.semantics import solvers
from rclverify.semantics.query import prove, satisfiable, solver_session
from rclverify.semantics.world import fresh as fresh_z3
from rclverify.model.plan.load import load_plan
from rclverify.lang.typecheck import load
from rclverify.model.system.model import build

ROOT = Path(__file__).resolve().parents[2]


def _queries() -> list[tuple[str, object]]:
    x, y = z3.Reals("x y")
    return [
        ("prove", lambda: prove(x + 1 > x, [])),
        ("prove-hyp", lambda: prove(y > 0, [x > 0, y > x])),
        ("refute", lambda: prove(y > 1, [x > 0, y > x])),
        ("sat", lambda: satisfiable([("a", x > 0), ("b", y > x)])),
        ("unsat", lambda: satisfiable([("a", x > 0), ("b", y > x), ("c", y < 0), ("d", x < 5)])),
        ("after-unsat", lambda: satisfiable([("a", x > 0), ("d", x < 5)])),
    ]


def test_a_session_gives_the_verdicts_and_cores_of_fresh_solvers() -> None:
    fresh = {name: q() for name, q in _queries()}  # type: ignore[operator]
    with solver_session():
        shared = {name: q() for name, q in _queries()}  # type: ignore[operator]
    for name in fresh:
        assert shared[name].status == fresh[name].status, name
        assert shared[name].core == fresh[name].core, name
    assert fresh["unsat"].core == ["a", "b", "c"] and fresh["after-unsat"].status == "sat"
    # a refutation's model is a real counterexample in both: y > x > 0 and not y > 1
    for r in (fresh["refute"], shared["refute"]):
        assert r.status == "refuted" and r.model is not None


def test_a_query_leaves_no_assertion_behind_and_sessions_nest() -> None:
    x = z3.Real("x")
    with solver_session():
        outer = solvers._SESSIONS[-1].solver
        assert satisfiable([("neg", x < 0)]).status == "sat"
        with solver_session():
            assert solvers._SESSIONS[-1].solver is not outer
            assert satisfiable([("pos", x > 0)]).status == "sat"  # not in the scope of `neg`
        assert solvers._SESSIONS[-1].solver is outer
        assert len(outer.assertions()) == 0 and outer.num_scopes() == 0
        assert prove(x * x >= 0, []).status == "proved"
    assert solvers._SESSIONS == []


def _verdicts(findings: list) -> list:
    return [(f.id, f.status, f.core, f.instances, f.model is None) for f in findings]


def test_a_node_checked_again_gives_the_same_verdicts_and_cores() -> None:
    # Witness values may differ between the two runs: a Z3 model depends on the term ids of
    # the process's context, which the first run's garbage changes (docs/decisions.md,
    # "Determinism").  Verdicts, cores and instance scans may not.
    plan = load_plan(ROOT)
    checked = load([ROOT / c for c in plan.contracts])
    model = build(checked, plan.connections)
    for node in ("Agent", "Navigation", "RadiationSensor"):
        # as the pipeline asks it (pipeline.stage_health): Z3's world made fresh, the plan's facts and
        # instance range, so the Agent's instance scan and its vacuity cores are what is compared
        facts = [(f.expr, f.loc) for f in plan.facts.get(node, ())]
        once, again = ((fresh_z3(), check_node(checked, node, facts, plan.instances.get(node)))[1] for _ in range(2))
        assert _verdicts(once) == _verdicts(again), node
        c1, c2 = compose_node(checked, model, node), compose_node(checked, model, node)
        assert [(s.id, s.status) for s in c1.side_conditions] == [(s.id, s.status) for s in c2.side_conditions], node
