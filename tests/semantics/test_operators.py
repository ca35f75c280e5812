"""The semantics table (rclverify.semantics.operators) against independent
oracles: exact rational arithmetic written out here, Python's binary64
floats, the enumerated truth tables, Z3's own evaluation of each entry's Z3
method and SMT-LIB symbol, numpy's ufuncs, and the Python text compiled;
and the evaluator, its closures and the straight-line code agreeing with
the table on random operands."""
from __future__ import annotations

import itertools
import operator
import random
from fractions import Fraction
from typing import Any

import numpy as np
import pytest
import z3

from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check
from rclverify.semantics.evaluate import evaluate
from rclverify.semantics.operators import (ARITHMETIC, COMPARISONS, CONNECTIVES, OPERATORS, UNARY, Undecided)
from rclverify.semantics.straightline import compile_exact

_RAW = {"+": operator.add, "-": operator.sub, "*": operator.mul, "/": operator.truediv, "==": operator.eq,
        "!=": operator.ne, "<": operator.lt, "<=": operator.le, ">": operator.gt, ">=": operator.ge}
_TRUTH = {"and": lambda a, b: a and b, "or": lambda a, b: a or b, "->": lambda a, b: b or not a,
          "<=>": lambda a, b: a is b}


def _numbers(rng: random.Random, n: int) -> list[Any]:
    pick = [lambda: rng.randint(-5, 5), lambda: Fraction(rng.randint(-9, 9), rng.randint(1, 4)),
            lambda: rng.choice([0.1, -2.5, 0.0, 1e300, 3.0, 1 / 3])]
    return [rng.choice(pick)() for _ in range(n)]


def test_the_table_is_complete() -> None:
    assert set(OPERATORS) == {"<=>", "->", "or", "and", "+", "-", "*", "/", "==", "!=", "<", "<=", ">", ">="}
    assert set(UNARY) == {"not", "-", "abs", "sqrt", "sin", "cos"}
    assert CONNECTIVES | COMPARISONS | ARITHMETIC == set(OPERATORS)


@pytest.mark.parametrize("op", sorted(CONNECTIVES))
def test_connectives_against_enumerated_truth_tables(op: str) -> None:
    entry = OPERATORS[op]
    for a, b in itertools.product([False, True], repeat=2):
        assert entry.exact(a, b) is _TRUTH[op](a, b)
        assert entry.double(a, b) is _TRUTH[op](a, b)
        assert eval(str(entry.python).format(l=a, r=b)) is _TRUTH[op](a, b)  # noqa: S307 - the table's own text
        assert z3.is_true(z3.simplify(_z3_binary(entry, z3.BoolVal(a), z3.BoolVal(b)))) is _TRUTH[op](a, b)
        if entry.decisive is not None and a is entry.decisive:  # short circuit: the right operand is not needed
            assert entry.decided is _TRUTH[op](a, b)
    if entry.identity is not None:
        assert all(entry.exact(entry.identity, b) is b for b in (False, True))


def _z3_binary(entry: Any, a: Any, b: Any) -> Any:
    if entry.kind == "connective" and entry.decisive is not None:
        return getattr(z3, entry.z3)(a, b)
    if entry.z3 in ("__eq__", "__ne__"):
        return getattr(z3.ExprRef, entry.z3)(a, b)
    return getattr(z3.ArithRef, entry.z3)(a, b)


def _z3_value(v: Any) -> Any:
    q = Fraction(v)
    return z3.RealVal(f"{q.numerator}/{q.denominator}")


def test_arithmetic_and_comparisons_exact_and_double() -> None:
    rng = random.Random(66)
    for _ in range(300):
        x, y = _numbers(rng, 2)
        for op in sorted(ARITHMETIC | COMPARISONS):
            entry = OPERATORS[op]
            qx, qy = Fraction(x), Fraction(y)
            if op == "/" and qy == 0:
                with pytest.raises(Undecided, match="division by zero"):
                    entry.exact(x, y)
                with pytest.raises(Undecided, match="division by zero"):
                    entry.double(x, y)
                continue
            expect = _RAW[op](qx, qy)
            assert entry.exact(x, y) == expect and type(entry.exact(x, y)) is not float
            fx = x if isinstance(x, int) else float(x)
            fy = y if isinstance(y, int) else float(y)
            assert entry.double(x, y) == _RAW[op](fx, fy)
            got = z3.simplify(_z3_binary(entry, _z3_value(x), _z3_value(y)))
            assert (z3.is_true(got) if entry.kind == "comparison" else Fraction(str(got.as_fraction()))) == expect
            if entry.numpy:
                assert bool(np.all(getattr(np, entry.numpy)(np.float64(fx), np.float64(fy)) ==
                                   _RAW[op](float(fx), float(fy))))
            if entry.converse:
                assert OPERATORS[entry.converse].exact(y, x) == expect
                assert OPERATORS[str(entry.negation)].exact(x, y) == (not expect)
            if entry.identity is not None:
                assert entry.exact(x, entry.identity) == qx


def test_a_nan_compares_false_in_the_double_reading() -> None:
    nan = float("nan")
    for op in sorted(COMPARISONS - {"!="}):
        assert OPERATORS[op].double(nan, 1.0) is False
    assert OPERATORS["!="].double(nan, nan) is True


def test_smtlib_symbols_mean_the_entry() -> None:
    for op in sorted(COMPARISONS | ARITHMETIC):
        entry = OPERATORS[op]
        if entry.smtlib is None:
            continue
        for x, y in [(3, 2), (2, 3), (2, 2), (-1, 4)]:
            rel = f"({entry.smtlib} {x}.0 {y}.0)" if entry.kind == "comparison" else \
                f"(= ({entry.smtlib} {x}.0 {y}.0) {float(Fraction(_RAW[op](Fraction(x), Fraction(y))))})"
            if entry.kind == "arithmetic" and op == "/":
                q = Fraction(x, y)
                rel = f"(= (/ {x}.0 {y}.0) (/ {q.numerator}.0 {q.denominator}.0))"
            solver = z3.Solver()
            solver.add(z3.parse_smt2_string(f"(assert {rel})"))
            holds = solver.check() == z3.sat
            assert holds == (bool(_RAW[op](x, y)) if entry.kind == "comparison" else True)


SPEC = """
node n {
  inputs(a : INTEGER, b : REAL, p : BOOL)
  outputs(q : BOOL)
  topics()
  guarantee(OPS)
}
"""


@pytest.mark.parametrize("op", ["+", "-", "*", "/"])
def test_evaluator_closures_and_straight_line_read_the_table(op: str) -> None:
    text = SPEC.replace("OPS", f"(in.a {op} in.b) <= in.b {op} 2 or in.p -> not out.q")
    spec = parse_text(text, "ops.rcl")
    checked = check([spec])
    node = checked.nodes["n"]
    formula = spec.nodes[0].guarantees[0].formula
    rng = random.Random(op)
    straight = compile_exact(formula, checked, node)
    assert straight.fn is not None
    for _ in range(40):
        a, b = rng.randint(-3, 3), rng.choice([0.5, -1.25, 0.0, 2.0])
        p, q = rng.random() < 0.5, rng.random() < 0.5
        values = {"in.a": a, "in.b": b, "in.p": p, "out.q": q}
        try:
            left = OPERATORS[op].exact(a, b)
            lhs = OPERATORS["<="].exact(left, OPERATORS[op].exact(b, 2))
            expect: bool | None = (not (lhs or p)) or not q  # (A or p) -> not q
        except Undecided:
            expect = None
        assert evaluate(formula, checked, node, values) is expect
        if expect is not None:
            assert straight.fn(values) is expect


def test_the_formula_core_keeps_no_copy_of_the_table() -> None:
    """No module of the formula core states a comparison's or an arithmetic
    operator's meaning again as a lambda (they read the table)."""
    import re
    from pathlib import Path

    import rclverify

    root = Path(rclverify.__file__).parent
    files = [*(root / "semantics").glob("*.py"), *(root / "backends" / "hoare").glob("*.py"),
             *(root / "backends" / "model_checking" / "ajpf").glob("*.py"), *(root / "targets").rglob("*.py"),
             root / "backends" / "experiment" / "criterion.py"]
    copy = re.compile(r"lambda (\w+), (\w+): \(?\1 (==|!=|<=|>=|<|>|\+|-|\*|/) \2")
    found = [f"{f.name}: {m.group(0)}" for f in files if f.name != "operators.py"
             for m in copy.finditer(f.read_text(encoding="utf-8"))]
    assert len(files) > 30 and found == []
