"""``sqrt(t)``, ``sin(t)``, ``cos(t)`` (docs/semantics.md, "Mathematical functions") end to end:
parsed, printed and rendered; typed and unit-checked with located errors; evaluated against
Python's ``math`` (the oracle) by the reference evaluator, its closures and straight-line code;
``sqrt``'s negative argument undecided and a definedness condition; Z3's proofs with the
uninterpreted functions' facts, a real refutation kept and a spurious one made ``inconclusive``
(the model confirmed with Python's math); each other backend translating or refusing with a
reason."""
from __future__ import annotations

import json
import math
import random
from fractions import Fraction
from pathlib import Path
from typing import Any

import pytest

from rclverify.lang.errors import RclError
from rclverify.lang.latex import expr_to_latex
from rclverify.lang.parser import parse_text
from rclverify.lang.printer import expr_to_rcl
from rclverify.lang.typecheck import check
from rclverify.semantics.definedness import conditions, guarded
from rclverify.semantics.encode import Encoder
from rclverify.semantics.evaluate import evaluate
from rclverify.semantics.operators import UNARY, Undecided
from rclverify.semantics.query import prove
from rclverify.semantics.straightline import compile_exact

SPEC = """
node n {
  inputs( a : REAL [m^2], th : REAL [rad], k : INTEGER )
  outputs( d : REAL [m], y : REAL )
  topics( std_msgs/Float64 a, std_msgs/Float64 th, std_msgs/Int32 k, std_msgs/Float64 d, std_msgs/Float64 y )
  guarantee( FORMULA )
}
"""
FORMULA = "out.d <= sqrt(in.a) or out.y >= sin(in.th) * cos(in.th) + sqrt(in.k)"


def _checked(formula: str = FORMULA, spec: str = SPEC) -> tuple[Any, Any, Any]:
    parsed = parse_text(spec.replace("FORMULA", formula), "math.rcl")
    checked = check([parsed])
    return checked, checked.nodes["n"], parsed.nodes[0].guarantees[0].formula


def _oracle(v: dict[str, Any]) -> bool:
    return bool(float(v["out.d"]) <= math.sqrt(float(v["in.a"])) or
                float(v["out.y"]) >= math.sin(float(v["in.th"])) * math.cos(float(v["in.th"])) + math.sqrt(v["in.k"]))


def test_it_parses_prints_and_renders_as_written() -> None:
    _c, _n, f = _checked()
    assert expr_to_rcl(f) == FORMULA
    again = parse_text(SPEC.replace("FORMULA", expr_to_rcl(f)), "again.rcl")
    assert expr_to_rcl(again.nodes[0].guarantees[0].formula) == FORMULA
    tex = expr_to_latex(f)
    assert r"\sqrt{" in tex and r"\sin\left(" in tex and r"\cos\left(" in tex


@pytest.mark.parametrize("formula, message", [
    ("sqrt(in.th > 0) >= 0", "unexpected '>'"),
    ("sin(TRUE) >= 0", "sin needs a number, found BOOL"),
    ("out.d == sqrt(out.d)", "sqrt of out.d in [m] (length): the unit has no square root"),
    ("out.y == sin(out.d)", "sin takes a dimensionless or [rad] argument; out.d is [m]"),
    ("out.d == sqrt(in.a * in.a)", ""),  # the control: [m^4] has a root, [m^2]; compared with [m]: a unit error
])
def test_type_and_unit_errors_are_located(formula: str, message: str) -> None:
    with pytest.raises(RclError) as exc:
        _checked(formula)
    d = exc.value.diagnostics[0]
    assert d.loc.file == "math.rcl" and d.loc.line == 6 and d.loc.col > 12
    assert message in d.message, d.message


def test_well_formed_units_check_and_an_angle_in_degrees_is_named() -> None:
    _checked("out.d == sqrt(in.a) and out.y == cos(in.th) and out.y == sqrt(4)")  # the control: no error
    deg = SPEC.replace("th : REAL [rad]", "th : REAL [deg]")
    with pytest.raises(RclError, match=r"sin takes radians; in.th is \[deg\].*convert it to \[rad\]"):
        _checked("out.y == sin(in.th)", deg)


def _cases(seed: str, n: int = 60) -> list[dict[str, Any]]:
    rng = random.Random(seed)
    num = [lambda: Fraction(rng.randint(0, 40), rng.randint(1, 4)), lambda: rng.uniform(-4.0, 4.0)]
    return [{"in.a": abs(Fraction(rng.choice(num)())), "in.th": rng.choice(num)(), "in.k": rng.randint(0, 9),
             "out.d": rng.choice(num)(), "out.y": rng.choice(num)()} for _ in range(n)]


def test_the_evaluators_agree_with_python_math() -> None:
    checked, node, f = _checked()
    straight = compile_exact(f, checked, node)
    assert straight.fn is not None
    for v in _cases("evaluators"):
        want = _oracle(v)
        assert evaluate(f, checked, node, v) is want, v
        assert straight.fn(v) is want, v
    assert UNARY["sqrt"].exact(Fraction(9, 4)) == Fraction(3, 2)  # a rational square root stays exact
    assert UNARY["sin"].exact(0) == 0 and UNARY["cos"].exact(0) == 1


def test_a_negative_sqrt_argument_is_undecided_and_a_definedness_condition() -> None:
    for reading in (UNARY["sqrt"].exact, UNARY["sqrt"].double):
        with pytest.raises(Undecided, match="square root of a negative number"):
            reading(-1)
    checked, node, f = _checked("out.y == sqrt(in.th)", SPEC.replace("th : REAL [rad]", "th : REAL"))
    (cond,) = conditions(f)
    assert cond.text == "in.th >= 0" and cond.describe().startswith("the square root at math.rcl:6:")
    assert evaluate(f, checked, node, {"in.th": -2.0, "out.y": 1.0}) is None  # undecided, not a truth value
    assert evaluate(f, checked, node, {"in.th": 4.0, "out.y": 2.0}) is True  # the control


def _prove(hyp: str, goal: str) -> Any:
    spec = SPEC.replace("a : REAL [m^2], th : REAL [rad]", "a : REAL, th : REAL")
    checked, node, f = _checked(f"({hyp}) -> ({goal})", spec.replace("[m]", ""))
    enc = Encoder(checked.env)
    return prove(enc.formula(guarded(f), node), [], enc)


@pytest.mark.parametrize("hyp, goal", [
    ("in.a >= 0", "sqrt(in.a) * sqrt(in.a) == in.a"),
    ("in.a >= 4", "sqrt(in.a) >= 2"),
    ("TRUE", "sin(in.th) * sin(in.th) + cos(in.th) * cos(in.th) == 1"),
    ("TRUE", "cos(in.th) >= 1 - in.th * in.th / 2 and sin(in.th) <= 1"),
    ("in.th == 0", "sin(in.th) == 0 and cos(in.th) == 1"),
])
def test_z3_proves_from_the_facts(hyp: str, goal: str) -> None:
    assert _prove(hyp, goal).status == "proved"


def test_z3_refutes_a_false_sqrt_claim_and_a_negative_argument() -> None:
    r = _prove("in.a >= 0", "sqrt(in.a) <= 1")
    assert r.status == "refuted" and Fraction(r.model["n.in.a"]) > 1
    r = _prove("TRUE", "sqrt(in.a) >= 0")  # no assumption rules out a negative argument: not defined
    assert r.status == "refuted" and Fraction(r.model["n.in.a"]) < 0


def test_a_spurious_sine_counterexample_is_inconclusive_and_a_real_one_refutes() -> None:
    """sin(2) is irrational, so ``sin(in.th) != 0.9092974268256817`` (its double) holds at 2; the facts allow
    the unknown function that very value, Z3 finds the model, Python's math does not reproduce the violation
    within the tolerance and cvc5 does not decide it within its limit: ``inconclusive`` with the reason.
    The control: ``sin(in.th) <= 0.5`` at 2 is false for the real sine, and stays refuted."""
    spurious = _prove("in.th == 2", "sin(in.th) != 0.9092974268256817")
    assert spurious.status == "inconclusive"
    assert "sqrt/sin/cos as unknown functions" in spurious.reason and "does not hold" in spurious.reason
    real = _prove("in.th == 2", "sin(in.th) <= 0.5")
    assert real.status == "refuted" and real.model is not None and real.model["n.in.th"] == "2"


def test_cvc5_proves_what_the_unknown_sine_could_not() -> None:
    """``sin(in.th) >= 0.5`` at 2 (sin(2) = 0.909...): Z3's model gives the unknown function a smaller value,
    unconfirmed; cvc5, deciding the real sine, proves it (the strategy names it)."""
    from rclverify.semantics.query import CVC5
    r = _prove("in.th == 2", "sin(in.th) >= 0.5")
    assert r.status == "proved" and r.strategy == CVC5


def test_each_backend_translates_or_refuses_with_a_reason() -> None:
    from rclverify.backends.experiment.criterion import CriterionError, dimension
    from rclverify.lang.parser import parse_formula
    from rclverify.model.plan.errors import PlanError
    from rclverify.targets.columns import ColumnCompiler, Unsupported
    from rclverify.targets.cpp.expr import CppTranslator
    from rclverify.targets.dafny.translate import Translator
    from rclverify.targets.smtlib import to_smt
    checked, node, f = _checked()
    cpp = CppTranslator(checked, node).translate(f)
    assert "std::sqrt(" in cpp and "std::sin(" in cpp and "std::cos(" in cpp
    with pytest.raises(PlanError, match="sqrt has no Dafny counterpart"):
        Translator(checked.env, node, {k: k.split(".")[1] for k in ("in.a", "in.th", "in.k", "out.d", "out.y")}) \
            .formula(f)
    assert to_smt(f, node, {("in", "a"): "a", ("in", "th"): "th", ("in", "k"): "k", ("out", "d"): "d",
                            ("out", "y"): "y"}, {}) is None  # outside the SMT-LIB text: the encoder decides it
    with pytest.raises(Unsupported, match=r"sqrt\(...\): the columns keep no error bound"):
        ColumnCompiler(checked, node).compile(f)
    with pytest.raises(CriterionError, match="sqrt is not part of an experiment criterion"):
        dimension(parse_formula("sqrt(error) <= 0.5"), {"error": "1"})


MONITORED = """node Root {
  inputs( r : REAL )
  outputs( d : REAL )
  topics( std_msgs/Float64 r matches(in.r), std_msgs/Float64 d matches(out.d) )
  assume( TRUE )
  guarantee( out.d == sqrt(in.r) + sin(0.5 * in.r) ) triggered by in.r within 100 ms
}
"""


def test_a_monitor_judges_a_log_with_python_math(tmp_path: Path) -> None:
    """The node's own double computation satisfies the guarantee, a wrong answer violates it, a negative
    argument leaves the answer inconclusive, naming the square root's condition."""
    from rclverify.backends.monitors.check import check_trace
    from rclverify.lang.typecheck import load
    from rclverify.traces import read_trace
    (tmp_path / "root.rcl").write_text(MONITORED)
    checked = load([tmp_path / "root.rcl"])
    run = [{"topic": "r", "time": 0.0, "data": 2.0}, {"topic": "d", "time": 0.01, "data": math.sqrt(2.0) + math.sin(1.0)},
           {"topic": "r", "time": 1.0, "data": 3.0}, {"topic": "d", "time": 1.01, "data": 1.5},
           {"topic": "r", "time": 2.0, "data": -1.0}, {"topic": "d", "time": 2.01, "data": 0.0},
           {"topic": "clock", "time": 9.0}]
    log = tmp_path / "run.jsonl"
    log.write_text("".join(json.dumps(x) + "\n" for x in run))
    seen: list[Any] = []
    _, (res,) = check_trace(checked, [checked.nodes["Root"]], read_trace(log), {}, 5.0, seen.append)
    assert [v.verdict for v in seen[:3]] == ["satisfied", "violated", "inconclusive"]
    assert "run.jsonl:4" in seen[1].reason
    assert "in.r >= 0 does not hold (a square root of a negative number)" in seen[2].reason


def test_a_concrete_check_is_decided_only_where_python_math_agrees() -> None:
    """Z3 with values for every input and output (semantics/concrete.py): true or false where the
    formula keeps its truth around Python's math value, undecided on the boundary itself."""
    from rclverify.semantics.concrete import check_concrete
    checked, node, f = _checked("out.y <= sin(in.th)")
    assert check_concrete(f, checked, node, {"in.th": 2.0, "out.y": 0.5, "in.a": 0, "in.k": 0, "out.d": 0}) \
        == (True, "")
    assert check_concrete(f, checked, node, {"in.th": 2.0, "out.y": 0.95, "in.a": 0, "in.k": 0, "out.d": 0}) \
        == (False, "")
    ok, why = check_concrete(f, checked, node, {"in.th": 2.0, "out.y": math.sin(2.0), "in.a": 0, "in.k": 0,
                                                "out.d": 0})
    assert ok is None and "unknown functions" in why



def test_the_carried_evaluator_of_generated_packages_reads_the_table() -> None:
    """contract_eval.py, written from the semantics table (targets/python/carry.py): Python's math, and a
    negative square root undecided as in the reference evaluator."""
    from rclverify.targets.python.carry import evaluator_text
    ns: dict[str, Any] = {}
    exec(compile(evaluator_text("# test"), "contract_eval.py", "exec"), ns)  # noqa: S102 - the project's own text
    unary = ns["_UNARY"]
    assert unary["sqrt"](2.0) == math.sqrt(2.0) and unary["sin"](1.0) == math.sin(1.0) and unary["cos"](0) == 1
    with pytest.raises(ns["Undecided"], match="square root of a negative number"):
        unary["sqrt"](-1.0)
