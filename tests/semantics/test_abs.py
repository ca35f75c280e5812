"""``abs(t)``, the absolute value, end to end: parsed, typed (a number's
type, its unit), printed and rendered, and given one meaning by every
translation: the reference evaluator, its compiled closures and straight-line
code, Z3, SMT-LIB text, the experiment criterion, the column monitors of
recorded runs, the C++ and Dafny text, and the evaluator carried into
generated packages.  Each is checked against Python's ``abs`` on exact
rationals, on random small cases (the brute-force oracle)."""
from __future__ import annotations

import random
from fractions import Fraction
from pathlib import Path
from typing import Any

import pytest
import z3

from rclverify.lang import ast
from rclverify.lang.latex import expr_to_latex
from rclverify.lang.parser import parse_text
from rclverify.lang.printer import expr_to_rcl
from rclverify.lang.typecheck import check
from rclverify.semantics.concrete import check_concrete
from rclverify.semantics.evaluate import evaluate
from rclverify.semantics.straightline import compile_exact

SPEC = """
node n {
  inputs( a : INTEGER, b : REAL )
  outputs( y : REAL )
  topics( std_msgs/Int32 a, std_msgs/Float64 b, std_msgs/Float64 y )
  guarantee( abs(in.a - in.b) <= abs(out.y) + 1 or abs(-in.a) == 3 )
}
"""


def _oracle(a: Any, b: Any, y: Any) -> bool:
    return abs(Fraction(a) - Fraction(b)) <= abs(Fraction(y)) + 1 or abs(-a) == 3


def _cases(seed: str, n: int = 60) -> list[dict[str, Any]]:
    rng = random.Random(seed)
    pick = [lambda: Fraction(rng.randint(-9, 9), rng.randint(1, 4)), lambda: float(rng.randint(-6, 6)) / 2]
    return [{"in.a": rng.randint(-5, 5), "in.b": rng.choice(pick)(), "out.y": rng.choice(pick)()} for _ in range(n)]


@pytest.fixture(scope="module")
def spec() -> Any:
    parsed = parse_text(SPEC, "abs.rcl")
    checked = check([parsed])
    return parsed, checked, checked.nodes["n"], parsed.nodes[0].guarantees[0].formula


def test_it_parses_prints_and_renders_as_written(spec: Any) -> None:
    _p, _c, _n, formula = spec
    text = expr_to_rcl(formula)
    assert text == "abs(in.a - in.b) <= abs(out.y) + 1 or abs(-in.a) == 3"
    again = parse_text(SPEC.replace("abs(in.a - in.b) <= abs(out.y) + 1 or abs(-in.a) == 3", text), "again.rcl")
    assert expr_to_rcl(again.nodes[0].guarantees[0].formula) == text
    assert r"\lvert " in expr_to_latex(formula)


def test_a_formula_is_no_number_and_the_unit_is_kept() -> None:
    with pytest.raises(Exception, match="abs needs a number, found BOOL"):
        check([parse_text(SPEC.replace("abs(-in.a) == 3", "abs(TRUE) == 3"), "bad.rcl")])
    units = SPEC.replace("inputs( a : INTEGER, b : REAL )", "inputs( a : INTEGER, b : REAL [m] )") \
        .replace("outputs( y : REAL )", "outputs( y : REAL [s] )")
    with pytest.raises(Exception, match="unit|dimension"):
        check([parse_text(units.replace("abs(out.y) + 1", "abs(out.y) + abs(in.b)"), "units.rcl")])


def test_every_evaluator_and_z3_agree_with_the_oracle(spec: Any) -> None:
    _p, checked, node, formula = spec
    straight = compile_exact(formula, checked, node)
    assert straight.fn is not None
    for values in _cases("evaluators"):
        want = _oracle(values["in.a"], values["in.b"], values["out.y"])
        assert evaluate(formula, checked, node, values) is want, values
        assert straight.fn(values) is want, values
        assert check_concrete(formula, checked, node, values)[0] is want, values


def test_smtlib_text_means_the_absolute_value(spec: Any) -> None:
    from rclverify.targets.smtlib import to_smt
    _p, _checked, node, formula = spec
    used: dict[str, str] = {}
    text = to_smt(formula, node, {("in", "a"): "a", ("in", "b"): "b", ("out", "y"): "y"}, used)
    assert text is not None and "ite" in text
    for values in _cases("smtlib", 30):
        decls = "".join(f"(declare-const {name} {sort})" for name, sort in sorted(used.items()))
        s = z3.Solver()
        s.add(z3.parse_smt2_string(f"{decls}(assert {text})"))
        for name, key in (("a", "in.a"), ("b", "in.b"), ("y", "out.y")):
            v = Fraction(values[key])
            c = z3.Int(name) if used.get(f"|{name}|", used.get(name)) == "Int" else z3.Real(name)
            s.add(c == (z3.IntVal(int(v)) if c.sort() == z3.IntSort() else z3.Q(v.numerator, v.denominator)))
        assert (s.check() == z3.sat) == _oracle(values["in.a"], values["in.b"], values["out.y"]), (values, text)


def test_the_column_monitors_agree_with_the_row_engine() -> None:
    """The batch path's columns (float64 with a bound on their distance to the exact value): where they
    are sure, they give the oracle's truth."""
    import numpy as np

    from rclverify.targets.columns import ColumnCompiler
    parsed = parse_text(SPEC.replace("a : INTEGER", "a : REAL").replace("abs(-in.a) == 3", "abs(-in.a) >= 3"),
                        "cols.rcl")
    checked = check([parsed])
    fn = ColumnCompiler(checked, checked.nodes["n"]).compile(parsed.nodes[0].guarantees[0].formula)
    cases = _cases("columns", 40)
    cols = {k: np.array([float(c[k]) for c in cases]) for k in ("in.a", "in.b", "out.y")}
    value, sure = fn(cols)
    decided = 0
    for k, c in enumerate(cases):
        if bool(sure[k]):
            decided += 1
            a, b, y = (Fraction(c[x]) for x in ("in.a", "in.b", "out.y"))
            assert bool(value[k]) == (abs(a - b) <= abs(y) + 1 or abs(-a) >= 3), c
    assert decided >= 30


def test_the_experiment_criterion_reads_it() -> None:
    from rclverify.backends.experiment.criterion import _to_z3, dimension
    from rclverify.lang.parser import parse_formula
    crit = parse_formula("abs(error) <= 0.5")
    assert dimension(crit, {"error": "1"}) == "bool"  # a plain number: dimension 1
    for v, want in ((-0.25, True), (-0.75, False), (0.5, True)):
        got = z3.simplify(_to_z3(crit, {"error": z3.RealVal(v)}))
        assert z3.is_true(got) is want, v


def test_cpp_and_dafny_text(spec: Any) -> None:
    from rclverify.targets.dafny.translate import Translator
    from rclverify.targets.cpp.expr import CppTranslator
    _p, checked, node, formula = spec
    assert "std::abs(" in CppTranslator(checked, node).translate(formula)
    dafny = Translator(checked.env, node, {"in.a": "a", "in.b": "b", "out.y": "y"}).formula(formula)
    assert "(if ((a as real) - b) >= 0.0 then ((a as real) - b) else -((a as real) - b))" in dafny, dafny
    assert "(if (-a) >= 0 then (-a) else -(-a))" in dafny, dafny


def test_the_carried_evaluator_of_a_generated_package_agrees(spec: Any, tmp_path: Path) -> None:
    import importlib.util

    from rclverify.cli.commands import main
    ws = tmp_path / "ws"
    (ws / "contracts").mkdir(parents=True)
    (ws / "contracts/n.rcl").write_text(SPEC)
    (ws / "contracts/plan.yaml").write_text("contracts: [contracts/n.rcl]\n")
    assert main(["generate", "ros2", "-w", str(ws), "-o", str(tmp_path / "out")]) == 0
    (layer_file,) = (tmp_path / "out").glob("*/*/contract.py")
    mod_spec = importlib.util.spec_from_file_location("abs_layer", layer_file)
    assert mod_spec is not None and mod_spec.loader is not None
    layer = importlib.util.module_from_spec(mod_spec)
    mod_spec.loader.exec_module(layer)
    for values in _cases("carried", 40):
        floats = {k: float(v) for k, v in values.items()}
        want = _oracle(floats["in.a"], floats["in.b"], floats["out.y"])
        got = layer.judge(floats)
        assert got["verdict"] == ("satisfied" if want else "violated"), (values, got)


def test_property_tests_draw_within_an_absolute_bound_of_the_assumption() -> None:
    """``abs(in.a) <= 2.5`` bounds ``a`` to [-2.5, 2.5] and ``4 > abs(in.b)`` ``b`` to (-4, 4): the
    strategies draw the inputs the assumption allows (and its ends)."""
    from rclverify.backends.property_tests.strategies import assumption_bounds
    text = SPEC.replace("  guarantee(", "  assume( abs(in.a) <= 2.5 and 4 > abs(in.b) )\n  guarantee(") \
        .replace("a : INTEGER, b : REAL", "a : REAL, b : INTEGER").replace("std_msgs/Int32 a, std_msgs/Float64 b",
                                                                            "std_msgs/Float64 a, std_msgs/Int32 b")
    checked = check([parse_text(text, "bounds.rcl")])
    got = {k: (v.lo, v.lo_strict, v.hi, v.hi_strict) for k, v in assumption_bounds(checked.nodes["n"]).items()}
    assert got == {"a": (Fraction(-5, 2), False, Fraction(5, 2), False), "b": (-4, True, 4, True)}
