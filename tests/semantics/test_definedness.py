"""Definedness on every proof path (docs/semantics.md, "Definedness").

A division by zero has no value: a Hoare triple, a side condition, a
requirement or a contract's health must not be proved when what it reads
can divide by zero.  Each path is shown failing with the condition named
(the division's ``file:line:col``, the condition ``d != 0``, a
counterexample ``d = 0``) next to a control that only moves the divisor's
range off zero and is discharged.  The last test is the random oracle the
project asks of each decision procedure: on small random formulas with
divisions over small integer ranges, the conditions
:mod:`rclverify.semantics.definedness` generates, decided by Z3, give the
same verdict as brute-force enumeration with the reference evaluator.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from rclverify.backends.base import NodeTarget
from rclverify.backends.hoare import HoareBackend
from rclverify.lang.typecheck import load

HOARE_RCL = """\
node Divider {{
  inputs( n : INTEGER, d : INTEGER )
  outputs( r : REAL )
  guarantee( {low} <= in.d <= 10 -> out.r == in.n / in.d )
}}
"""
PROGRAM = """\
var n, d : INTEGER;
var r : REAL;
r := n / d
"""


def _hoare(tmp_path: Path, low: int, program: str = PROGRAM) -> Any:
    (tmp_path / "contracts").mkdir()
    (tmp_path / "contracts" / "divider.rcl").write_text(HOARE_RCL.format(low=low))
    (tmp_path / "divider.imp").write_text(program)
    checked = load([tmp_path / "contracts" / "divider.rcl"])
    config = {"backend": "hoare", "program": "divider.imp",
              "binding": {"in.n": "n", "in.d": "d", "out.r": "r"}}
    t = NodeTarget(root=tmp_path, checked=checked, node=checked.nodes["Divider"], config=config,
                   contract_files=("contracts/divider.rcl",), plan_file="contracts/plan.yaml",
                   artifacts=tmp_path / "artifacts" / "hoare" / "Divider")
    b = HoareBackend()
    (o,) = b.export(t)
    return b.run(o, t)


def test_hoare_triple_dividing_by_a_possible_zero_fails_with_the_condition_named(tmp_path: Path) -> None:
    ev = _hoare(tmp_path, 0)
    assert ev.status == "failed", ev.explanation
    assert ev.details["failed_vc"] == "defined@3:6"
    assert "divider.imp:3:6" in ev.explanation and "d != 0" in ev.explanation
    assert ev.counterexample is not None and ev.counterexample["d"] == 0
    # the postcondition's own division is a condition too, and it fails as well
    assert ev.details["vcs"]["defined.post1"] == "invalid"
    assert ev.details["vcs"]["main"] == "valid"  # what Z3 alone proved before: n / 0 read as a number


def test_hoare_control_with_the_divisor_off_zero_is_discharged(tmp_path: Path) -> None:
    ev = _hoare(tmp_path, 1)
    assert ev.status == "discharged", ev.explanation
    assert {k for k in ev.details["vcs"]} == {"main", "defined@3:6", "defined.post1"}


def test_hoare_division_guarded_by_a_connective_is_defined_and_its_control_is_not(tmp_path: Path) -> None:
    program = PROGRAM.replace("r := n / d", "if d != 0 and n / d > 1 then skip end\n"
                              "if d == 0 or n / d > 1 then skip end\n"
                              "if d > 0 -> n / d > 1 then skip end\n"
                              "if d == 0 and n / d > 1 then skip end\n"
                              "r := 0")
    ev = _hoare(tmp_path, 0, program)
    vcs = ev.details["vcs"]
    assert (vcs["defined@3:15"], vcs["defined@4:14"], vcs["defined@5:13"]) == ("valid", "valid", "valid")
    assert vcs["defined@6:15"] == "invalid"  # the control: the guard lets d = 0 through
    assert ev.status == "failed" and ev.details["failed_vc"] == "defined@6:15"


def test_hoare_division_in_a_loop_is_checked_at_every_iteration(tmp_path: Path) -> None:
    loop = ("var k : INTEGER;\nk := d\n"
            "while k > 0 invariant k >= 0 do\n  r := n / k\n  k := k - 1\nend\n")
    ev = _hoare(tmp_path, 0, PROGRAM.replace("r := n / d\n", loop) + "r := n / (k + 1)\n")
    vcs = ev.details["vcs"]
    assert vcs["defined@6:8.loop@5.body"] == "valid"     # k > 0 inside the loop
    assert vcs["defined@9:6.loop@5.after"] == "valid"    # k >= 0 after it, so k + 1 != 0
    bad = PROGRAM.replace("r := n / d\n", loop.replace("k > 0", "k >= 0"))
    (tmp_path / "control").mkdir()
    ev = _hoare(tmp_path / "control", 0, bad)
    assert ev.details["vcs"]["defined@6:8.loop@5.body"] == "invalid"


def test_the_tables_partiality_is_where_its_meanings_are_undecided() -> None:
    """``Operator.partial`` (what the conditions are generated from) marks exactly the operands and
    values at which the operator's exact and double meanings answer undecided."""
    from rclverify.semantics.operators import OPERATORS, Undecided
    for op in OPERATORS.values():
        if op.kind != "arithmetic":
            assert op.partial is None, op.symbol
            continue
        for left, right in ((3, 0), (0, 3), (0, 0), (3, 2)):
            undefined = op.partial is not None and (left, right)[op.partial.operand] == op.partial.excluded
            for meaning in (op.exact, op.double):
                if undefined:
                    with pytest.raises(Undecided):
                        meaning(left, right)
                else:
                    meaning(left, right)
    assert [o.symbol for o in OPERATORS.values() if o.partial is not None] == ["/"]


@pytest.mark.parametrize(("p", "q", "truth"), [(0.1, 0, None), (0.2, 0, None), (0.1, 1, True), (0.1, 0.25, False)])
def test_a_judgement_on_values_is_undecided_where_the_formula_divides_by_zero(p: float, q: float,
                                                                           truth: bool | None) -> None:
    """The monitors' and property tests' judgement on recorded values (:func:`floatsem.judge`, Z3 on the
    values where direct evaluation cannot decide) reads a division by zero as undefined, as the
    definedness conditions do (the left operand of ``or`` first): Z3 alone reads ``p / 0`` as some number.
    Controls: the same formula with a non-zero divisor is decided, either way."""
    from rclverify.lang.parser import parse_text
    from rclverify.lang.typecheck import check
    from rclverify.semantics.floatsem import judge
    checked = check([parse_text("node N {\n  inputs( p : REAL, q : REAL )\n  outputs( ok : BOOL )\n"
                                "  guarantee( (in.p / in.q <= 0.2) or not (0.15 >= in.p) )\n}\n", "n.rcl")])
    node = checked.nodes["N"]
    j = judge(node.node.guarantees[0].formula, checked, node, {"in.p": p, "in.q": q, "out.ok": True})
    assert j.truth is truth, j
    if truth is None:
        assert "division by zero" in j.reason or "undefined" in j.reason, j.reason


# ---------------------------------------------------------------------------
# side conditions (calculus/compose.py, calculus/side_condition.py)
# ---------------------------------------------------------------------------

LINKED = """\
node Producer {{
  inputs( s : INTEGER )
  outputs( n : INTEGER, d : INTEGER, r : REAL )
  guarantee( {low} <= out.d <= 10 and out.r == out.n / out.d )
}}
node Consumer {{
  inputs( n : INTEGER, d : INTEGER, r : REAL )
  outputs( ok : BOOL )
  assume( in.r == in.n / in.d )
  guarantee( out.ok )
}}
"""


def _side_condition(low: int) -> Any:
    from rclverify.calculus.compose import compose_node
    from rclverify.lang.parser import parse_text
    from rclverify.lang.typecheck import check
    from rclverify.model.system.model import build
    checked = check([parse_text(LINKED.format(low=low), "linked.rcl")])
    (sc,) = compose_node(checked, build(checked), "Consumer").side_conditions
    return sc


def test_side_condition_dividing_by_a_possible_zero_fails_with_the_condition_named() -> None:
    sc = _side_condition(0)
    assert sc.status == "failed", sc.explanation
    assert "the division at linked.rcl:9:19 needs in.d != 0" in sc.explanation
    assert sc.model is not None and sc.model["Producer.out.d"] == "0", sc.model


def test_side_condition_control_with_the_divisor_off_zero_is_discharged() -> None:
    sc = _side_condition(1)
    assert sc.status == "discharged", sc.explanation


# ---------------------------------------------------------------------------
# requirements (calculus/requirements/check.py; own_nodes asks the same query)
# ---------------------------------------------------------------------------

REQ_RCL = """\
node Divider {{
  inputs( n : INTEGER, d : INTEGER )
  outputs( r : REAL, dd : INTEGER, nn : INTEGER )
  guarantee( {low} <= out.dd <= 10 and out.r == out.nn / out.dd )
}}
"""
REQ_PLAN = """\
contracts: [contracts/divider.rcl]
requirements:
  - id: QUOTIENT
    text: the quotient is the numerator over the divisor
    formal: "Divider.out.r == Divider.out.nn / Divider.out.dd"
"""


def _requirement(tmp_path: Path, low: int, temporal: str = "") -> dict[str, Any]:
    from rclverify.stages.workspace import Workspace
    from rclverify.calculus.requirements import own_nodes
    from rclverify.semantics import world
    (tmp_path / "contracts").mkdir()
    (tmp_path / "contracts/divider.rcl").write_text(REQ_RCL.format(low=low))
    (tmp_path / "contracts/plan.yaml").write_text(REQ_PLAN.replace('formal: "', f'formal: "{temporal}'))
    w = Workspace(tmp_path)
    (req,) = w.plan.requirements
    world.fresh()
    return own_nodes.decide(req, w.checked, w.model, w.plan)


def test_requirement_dividing_by_a_possible_zero_is_refuted_with_the_condition_named(tmp_path: Path) -> None:
    rec = _requirement(tmp_path, 0)
    assert rec["verdict"] == "refuted", rec
    assert "needs Divider.out.dd != 0" in rec["explanation"]
    assert "contracts/plan.yaml:5:" in rec["explanation"]
    values = {f"{row['node']}.{k}": v for row in rec["counterexample"] for k, v in row["values"].items()}
    assert values["Divider.out.dd"] == "0", values


def test_requirement_control_with_the_divisor_off_zero_is_proved(tmp_path: Path) -> None:
    rec = _requirement(tmp_path, 1)
    assert rec["verdict"] == "proved", rec


# ---------------------------------------------------------------------------
# contract health (calculus/health/defined.py)
# ---------------------------------------------------------------------------

HEALTH_RCL = """\
node Divider {{
  inputs( n : INTEGER, d : INTEGER )
  outputs( r : REAL )
  assume( {low} <= in.d and in.d <= 10 )
  assume( in.d == 0 or in.n / in.d >= 0 )
  guarantee( out.r == in.n / in.d )
}}
"""


def _health(low: int) -> dict[str, Any]:
    from rclverify.calculus.health.checks import check_node
    from rclverify.lang.parser import parse_text
    from rclverify.lang.typecheck import check
    checked = check([parse_text(HEALTH_RCL.format(low=low), "divider.rcl")])
    return {f.id: f for f in check_node(checked, "Divider") if f.check == "defined"}


def test_health_guarantee_dividing_by_a_possible_zero_is_a_problem_named() -> None:
    found = _health(0)
    assert found["Divider.a2.defined"].status == "ok"  # guarded by `in.d == 0 or`
    g = found["Divider.g1.defined"]
    assert g.status == "problem", g
    assert "the division at divider.rcl:6:23 needs in.d != 0" in g.message
    assert g.model is not None and g.model["Divider.in.d"] == "0"


def test_health_control_with_the_divisor_off_zero_is_ok() -> None:
    found = _health(1)
    assert set(found) == {"Divider.a2.defined", "Divider.g1.defined"}
    assert all(f.status == "ok" for f in found.values())


# ---------------------------------------------------------------------------
# the random oracle: Z3 on the generated conditions against brute force
# ---------------------------------------------------------------------------

ORACLE_RCL = """\
node N {
  inputs( a : INTEGER, b : INTEGER, c : INTEGER )
  outputs( o : BOOL )
  guarantee( TRUE )
}
"""
#: every value of every input the enumeration tries
RANGE = range(-2, 3)


def _term(draw: Any, depth: int) -> str:
    from hypothesis import strategies as st
    if depth == 0 or draw(st.integers(0, 2)) == 0:
        leaf: str = draw(st.sampled_from(["in.a", "in.b", "in.c", "0", "1", "2", "(in.a * in.a + 1)"]))
        return leaf
    op = draw(st.sampled_from(["+", "-", "*", "/", "/"]))
    return f"({_term(draw, depth - 1)} {op} {_term(draw, depth - 1)})"


def _formula(draw: Any, depth: int) -> str:
    from hypothesis import strategies as st
    if depth == 0 or draw(st.integers(0, 3)) == 0:
        cmp = draw(st.sampled_from(["==", "!=", "<", "<=", ">", ">="]))
        return f"({_term(draw, 2)} {cmp} {_term(draw, 2)})"
    op = draw(st.sampled_from(["and", "or", "->", "<=>", "not"]))
    if op == "not":
        return f"(not {_formula(draw, depth - 1)})"
    return f"({_formula(draw, depth - 1)} {op} {_formula(draw, depth - 1)})"


def _holds_at(w: Any, symbols: list[Any], point: tuple[int, ...]) -> bool:
    import z3
    sub = z3.simplify(z3.substitute(w, *[(s, z3.IntVal(v)) for s, v in zip(symbols, point)]))
    if z3.is_true(sub) or z3.is_false(sub):
        return bool(z3.is_true(sub))
    s = z3.Solver()
    s.add(z3.Not(sub))
    return bool(s.check() == z3.unsat)


def test_definedness_conditions_agree_with_brute_force_enumeration() -> None:
    import itertools

    import z3
    from hypothesis import HealthCheck, given, settings
    from hypothesis import strategies as st

    from rclverify.lang.parser import parse_formula, parse_text
    from rclverify.lang.typecheck import check
    from rclverify.semantics.definedness import conditions, defined
    from rclverify.semantics.encode import Encoder
    from rclverify.semantics.evaluate import why_undecided
    from rclverify.semantics.query import prove

    checked = check([parse_text(ORACLE_RCL, "oracle.rcl")])
    node = checked.nodes["N"]
    seen = {"undefined somewhere": 0, "defined everywhere": 0, "guarded": 0}

    @settings(max_examples=150, deadline=None, derandomize=True,
              suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
    @given(st.data())
    def one(data: Any) -> None:
        text = _formula(data.draw, 3)
        e = parse_formula(text, "oracle.rcl")
        enc = Encoder(checked.env)
        w = enc.formula(defined(e), node)
        symbols = [enc.io_symbol(node, "in", v) for v in ("a", "b", "c")]
        points = list(itertools.product(RANGE, repeat=3))
        brute = {p: why_undecided(e, checked, node, dict(zip(("in.a", "in.b", "in.c"), p))) for p in points}
        assert set(brute.values()) <= {"", "division by zero"}, text
        for p in points:  # pointwise: the condition holds exactly where the evaluator decides
            assert _holds_at(w, symbols, p) == (brute[p] == ""), (text, p, brute[p])
        ranges = [z3.And(s >= min(RANGE), s <= max(RANGE)) for s in symbols]
        verdict = prove(w, ranges, enc).status  # the verdict a proof path gives: defined on the whole range?
        assert verdict == ("proved" if all(v == "" for v in brute.values()) else "refuted"), text
        if verdict == "refuted":
            seen["undefined somewhere"] += 1
        elif conditions(e):
            seen["defined everywhere"] += 1
        if any(c.formula is not c.requires for c in conditions(e)):
            seen["guarded"] += 1

    one()
    assert all(n >= 5 for n in seen.values()), seen  # the corpus exercised each kind of answer


@pytest.mark.parametrize("low, verdict", [(0, "refuted"), (1, "proved")])
def test_temporal_requirement_holds_only_where_its_state_formula_is_defined(tmp_path: Path, low: int,
                                                                            verdict: str) -> None:
    rec = _requirement(tmp_path, low, "always ")
    assert rec["verdict"] == verdict, rec


# ---------------------------------------------------------------------------
# end to end: the tester's triple through `rclverify verify`
# ---------------------------------------------------------------------------

E2E_RCL = """\
node Divider {{
  inputs( n : INTEGER, d : INTEGER )
  outputs( r : REAL )
  assume( {low} <= in.d and in.d <= 10 )
  guarantee( out.r == in.n / in.d )
}}
"""
E2E_PLAN = """\
contracts: [contracts/divider.rcl]
nodes:
  Divider:
    evidence:
      - backend: hoare
        program: divider.imp
        binding: {in.n: n, in.d: d, out.r: r}
"""


@pytest.mark.parametrize("low", [0, 1])
def test_verify_reports_the_division_by_zero_and_its_diagnosis(tmp_path: Path, low: int,
                                                              capsys: pytest.CaptureFixture[str]) -> None:
    """`{0 <= d <= 10} r := n / d {r == n / d}` through the whole pipeline: the triple fails on its
    definedness VC and the diagnosis blames the division (not a constant); the contract's health names the
    guarantee's own division.  The control, `1 <= d`, verifies with the triple discharged."""
    import json

    from rclverify.cli.commands import main
    (tmp_path / "contracts").mkdir()
    (tmp_path / "contracts/divider.rcl").write_text(E2E_RCL.format(low=low))
    (tmp_path / "contracts/plan.yaml").write_text(E2E_PLAN)
    (tmp_path / "divider.imp").write_text(PROGRAM)
    assert main(["verify", "-w", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    report = json.loads((tmp_path / "reports/assurance.json").read_text())
    (ob,) = report["obligations"]
    if low == 1:
        assert ob["status"] == "discharged", ob
        assert "divide by zero" not in out
        return
    assert ob["status"] == "failed", ob
    assert "divider.imp can divide by zero under guarantee 1 of Divider" in out
    assert "d != 0 for the division at divider.imp:3:6" in out
    assert "the division at contracts/divider.rcl:5:23 needs in.d != 0" in out  # health, check `defined`
