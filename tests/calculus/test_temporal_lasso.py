"""Lassos with finite-table functions refute an unbounded ``eventually``
(issue 34): the search of calculus/requirements/lasso.py over a small system with a
function-typed input, the confirmation of its trace on concrete values
(calculus/requirements/lasso_confirm.py), and a corrupted trace that is not
confirmed.  Real Z3."""
from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import pytest

from rclverify.app.pipeline import Workspace
from rclverify.model.plan.formal import parse_formal
from rclverify.model.plan.temporal import operands
from rclverify.calculus.requirements.check import check_requirement
from rclverify.calculus.requirements.lasso import find_table_lasso
from rclverify.calculus.requirements.lasso_confirm import confirm_lasso
from rclverify.calculus.requirements.temporal_check import statement
from rclverify.calculus.requirements.composed import variable_types
from rclverify.calculus.requirements.transition import build_system
from rclverify.semantics.encode import Encoder
from rclverify.semantics.values import FiniteFunction

# Pick reads a table f of levels (the environment's, bounded by 9) and
# outputs a level f takes; Hold keeps the last level it read.  Both answer
# at every step (progress within 0 steps).
RCL = """context { Levels : REAL --> NATURAL ; }
node Pick { inputs( f : Levels ) outputs( k : NATURAL )
  guarantee( exists(x in REAL | in.f(x) == out.k) )
  progress( within 0 steps ) }
node Hold { inputs( k : NATURAL ) outputs( last : NATURAL )
  guarantee( out.last == in.k )
  progress( within 0 steps ) }
"""
PLAN = """contracts: [contracts/p.rcl]
requirements:
  - id: L1
    text: the held level eventually reaches 7
    formal: "eventually Hold.out.last == 7"
environment:
  Pick:
    facts:
      - "forall(x in REAL | in.f(x) <= 9)"
"""


@pytest.fixture(scope="module")
def system(tmp_path_factory: pytest.TempPathFactory):
    ws = tmp_path_factory.mktemp("lasso") / "ws"
    (ws / "contracts").mkdir(parents=True)
    (ws / "contracts/p.rcl").write_text(RCL)
    (ws / "contracts/plan.yaml").write_text(PLAN)
    w = Workspace(ws)
    checked, model, plan = w.checked, w.model, w.plan
    req = plan.requirements[0]
    goal = operands(statement(req, checked, plan))[0]
    cone = [n for n in model.nodes]
    sys = build_system(cone, checked, model, plan)
    enc = Encoder(checked.env)
    pred = lambda s: enc.formula(goal.expr, goal.scope, sys.statement_symbols(s))  # noqa: E731
    return checked, model, plan, req, goal, cone, sys, pred


def test_table_lasso_refutes_and_is_confirmed(system) -> None:
    checked, model, plan, req, goal, cone, sys, pred = system
    types = variable_types(sys, checked, plan)
    found = find_table_lasso(sys.ts, pred, types, bound=4, points=4)
    assert not isinstance(found, str), found
    assert found.values[-1] == found.values[found.loop]
    f = found.values[0]["Pick.in.f"]
    assert isinstance(f, FiniteFunction)
    # the run never reaches the goal, and every level f takes is at most 9
    assert all(st["Hold.out.last"] != 7 for st in found.values)
    assert all(v <= 9 for st in found.values for v in [*st["Pick.in.f"].table.values(), st["Pick.in.f"].default])
    assert confirm_lasso(found.values, found.loop, cone, sys.variables, types, checked, model, plan, goal, [], pub=sys.pub) is None
    # a corrupted trace is not confirmed: Pick's output is a level its table does not take
    bad = [dict(st) for st in found.values]
    for st in bad:
        st["Pick.in.f"] = FiniteFunction({}, 3, 1)
        st["Pick.out.k"] = 5
    why = confirm_lasso(bad, found.loop, cone, sys.variables, types, checked, model, plan, goal, [], pub=sys.pub)
    assert why is not None and "Pick's guarantee 1 does not hold" in why
    # a trace whose goal holds is not a counterexample
    hit = [dict(st, **{"Hold.in.k": 7, "Hold.out.last": 7, "Pick.out.k": 7, "Pick.in.f": FiniteFunction({}, 7, 1)})
           for st in found.values]
    assert "the goal holds" in confirm_lasso(hit, found.loop, cone, sys.variables, types, checked, model, plan, goal, [], pub=sys.pub)


def test_requirement_record_is_refuted_by_a_lasso(system) -> None:
    checked, model, plan, req, *_ = system
    r = check_requirement(req, checked, model, plan)
    t = r["temporal"]
    assert r["verdict"] == "refuted" and t["method"] == "lasso" and t["loop"] is not None
    last, loop = t["trace"][-1]["nodes"], t["trace"][t["loop"]]["nodes"]
    assert last == loop
    assert all(n["values"]["out.last"] != "7" for st in t["trace"] for n in st["nodes"] if n["node"] == "Hold")
