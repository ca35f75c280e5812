"""``first(Node.in.x)`` in temporal requirements (issue 113; docs/semantics.md,
"The first published value"): TRUE at the step whose value of the input is the
first published on it.  Src answers its first input with 0 and every later one
with 1; Mid echoes what Src published a step later.  The first value Mid hears
is 0 (proved) and not 1 (refuted at step 1, where it arrives); without
``first`` the same statement is refuted (the control: the later values are 1);
an input of the environment has its first value at step 0.  Real Z3."""
from __future__ import annotations

import json
from pathlib import Path

import pytest

from rclverify.app.pipeline import Workspace, stage_check, stage_requirements
from rclverify.lang.errors import RclError
from rclverify.lang.parser import parse_formula, parse_text
from rclverify.lang.printer import expr_to_rcl
from rclverify.lang.typecheck import check

RCL = """node Src { inputs( r : NATURAL ) outputs( v : NATURAL )
  guarantee( (first(in.r) -> out.v == 0) and (not first(in.r) -> out.v == 1) )
  progress( within 0 steps ) }
node Mid { inputs( v : NATURAL ) outputs( w : NATURAL )
  guarantee( out.w == in.v )
  progress( within 0 steps ) }
"""
FORMALS = [
    "always (first(Mid.in.v) -> Mid.in.v == 0)",   # T1 proved
    "always (first(Mid.in.v) -> Mid.in.v == 1)",   # T2 refuted at step 1
    "always Mid.in.v == 0",                        # T3 refuted: the control without first
    "eventually first(Mid.in.v)",                  # T4 the first value arrives
    "always (first(Src.in.r) -> Src.out.v == 0)",  # T5 the environment's first value: step 0
    "next (not first(Src.in.r))",                  # T6 true once only
    "first(Src.in.r) -> Src.out.v == 0",           # T7 a state requirement: its first and the contract's are one
    "first(Src.in.r) -> Src.out.v == 1",           # T8 its control
]


@pytest.fixture(scope="module")
def report(tmp_path_factory: pytest.TempPathFactory) -> dict[str, dict]:
    from rclverify.report.build import build_report
    ws = tmp_path_factory.mktemp("first") / "w"
    (ws / "contracts").mkdir(parents=True)
    (ws / "contracts/n.rcl").write_text(RCL)
    reqs = "".join(f"  - id: T{k}\n    text: first {k}\n    formal: {json.dumps(f)}\n" for k, f in enumerate(FORMALS, 1))
    (ws / "contracts/plan.yaml").write_text(f"contracts: [contracts/n.rcl]\nrequirements:\n{reqs}")
    w = Workspace(ws)
    stage_check(w)
    stage_requirements(w)
    return {r["id"]: r["check"]["temporal"] or {"status": r["verdict"]} for r in build_report(w).to_json()["requirements"]}


def test_the_first_published_value_is_proved_and_a_wrong_one_refuted_where_it_arrives(report) -> None:
    assert report["T1"]["status"] == "proved"
    t2 = report["T2"]
    assert t2["status"] == "refuted" and len(t2["trace"]) == 2
    mid = [next(n["values"] for n in st["nodes"] if n["node"] == "Mid") for st in t2["trace"]]
    assert [(m["first.v"], m["heard.v"]) for m in mid] == [("False", "False"), ("True", "True")]
    assert report["T3"]["status"] == "refuted"  # control: every later value is 1


def test_the_first_value_arrives_and_the_environment_gives_its_own_at_step_0(report) -> None:
    assert report["T4"]["status"] == "proved"
    assert report["T5"]["status"] == "proved"
    assert report["T6"]["status"] == "proved"


def test_first_prints_back_as_written() -> None:
    for text in ("first(in.x) -> out.y == 0", "not first(x) and in.x > 1"):
        assert expr_to_rcl(parse_formula(text)) == text
    assert parse_formula("first(in.x)") != parse_formula("first(in.z)")  # control: the argument counts
    from rclverify.lang.latex import expr_to_latex
    assert expr_to_latex(parse_formula("first(in.x) -> out.y == 0")) == \
        r"\mathit{first}(\mathit{in.x}) \Rightarrow \mathit{out.y} = 0"


@pytest.mark.parametrize("arg,why", [
    ("out.y", "out.y is an output"),
    ("K", "K is not an input"),
    ("in.w", "node N has no input named 'w'"),
])
def test_first_of_what_is_not_an_input_is_a_located_error(arg: str, why: str) -> None:
    src = f"context {{ K = 3; }}\nnode N {{ inputs( x : REAL ) outputs( y : REAL )\n  guarantee( first({arg}) ) }}\n"
    with pytest.raises(RclError) as e:
        check([parse_text(src, "f.rcl")])
    assert str(e.value).startswith("f.rcl:3:20: error:") and why in str(e.value), str(e.value)
    check([parse_text(src.replace(f"first({arg})", "first(in.x)"), "f.rcl")])  # control


def test_a_state_requirement_reads_the_first_flag_its_contract_reads(report) -> None:
    """One step: first(Src.in.r) is one Boolean for the requirement and for Src's guarantee."""
    assert report["T7"]["status"].startswith("proved")
    assert report["T8"]["status"] == "refuted"


# A lasso found with finite tables is confirmed on its values, first(...) flags included (lasso_confirm.py):
# Hold answers the first level it hears with 0 and echoes every later one.
TABLES = """context { Levels : REAL --> NATURAL ; }
node Pick { inputs( f : Levels ) outputs( k : NATURAL )
  guarantee( exists(x in REAL | in.f(x) == out.k) )
  progress( within 0 steps ) }
node Hold { inputs( k : NATURAL ) outputs( last : NATURAL )
  guarantee( (first(in.k) -> out.last == 0) and (not first(in.k) -> out.last == in.k) )
  progress( within 0 steps ) }
"""


def test_a_table_lasso_over_first_is_confirmed_and_a_wrong_flag_is_not(tmp_path) -> None:
    from rclverify.calculus.requirements.lasso import find_table_lasso
    from rclverify.calculus.requirements.lasso_confirm import confirm_lasso
    from rclverify.calculus.requirements.temporal_check import statement
    from rclverify.calculus.requirements.composed import variable_types
    from rclverify.calculus.requirements.transition import build_system
    from rclverify.model.plan.temporal import operands
    from rclverify.semantics.encode import Encoder
    ws = tmp_path / "ws"
    (ws / "contracts").mkdir(parents=True)
    (ws / "contracts/p.rcl").write_text(TABLES)
    (ws / "contracts/plan.yaml").write_text(
        'contracts: [contracts/p.rcl]\nrequirements:\n  - id: L1\n    text: reaches 7\n'
        '    formal: "eventually Hold.out.last == 7"\n'
        'environment:\n  Pick:\n    facts:\n      - "forall(x in REAL | in.f(x) <= 9)"\n')
    w = Workspace(ws)
    checked, model, plan = w.checked, w.model, w.plan
    goal = operands(statement(plan.requirements[0], checked, plan))[0]
    cone = list(model.nodes)
    sys = build_system(cone, checked, model, plan)
    assert sys.pub.first == {"Hold.in.k": "Hold.first.k"}  # the contract's first(in.k) has its flag
    enc = Encoder(checked.env)
    types = variable_types(sys, checked, plan)
    found = find_table_lasso(sys.ts, lambda s: enc.formula(goal.expr, goal.scope, sys.statement_symbols(s)),
                             types, bound=4, points=4)
    assert not isinstance(found, str), found
    assert confirm_lasso(found.values, found.loop, cone, sys.variables, types, checked, model, plan, goal, [],
                         pub=sys.pub) is None
    bad = [dict(st, **{"Hold.first.k": True}) for st in found.values]  # control: first at every step
    why = confirm_lasso(bad, found.loop, cone, sys.variables, types, checked, model, plan, goal, [], pub=sys.pub)
    assert why is not None and "Hold.first.k" in why, why


def test_first_stays_a_name_where_no_parenthesis_follows() -> None:
    """An enumeration value (or constant, node, input) named first is still written as before; first( is the
    built-in (the control: the same text with the parenthesis)."""
    src = ("context { Phase : {first, second}; }\nnode first { inputs( x : REAL ) outputs( p : Phase )\n"
           "  guarantee( out.p == first and in.x > 0 ) }\n")
    g = check([parse_text(src, "f.rcl")]).nodes["first"].node.guarantees[0].formula
    assert expr_to_rcl(g) == "out.p == first and in.x > 0"
    assert "First(" in repr(parse_formula("out.p == first and first(in.first)"))
