"""The evaluator generated packages carry (``contract_eval.py``) is written from the semantics table.

* Its operator tables hold exactly the table's operators.
* Oracle: on random trees of every operator over small numbers and truth values, its exact and
  double readings equal a brute-force reading written apart from it, from each entry's ``exact``
  and ``double`` meanings (:mod:`rclverify.semantics.operators`), division by zero undecided.
* An operator added to a copy of the table reaches the written evaluator with no other edit, and
  one without the Python text the evaluator needs is refused with its name.
"""
from __future__ import annotations

import dataclasses
import random
import types
from fractions import Fraction
from typing import Any

import pytest

from rclverify.semantics.operators import COMPARISONS, OPERATORS, UNARY, Operator, Undecided
from rclverify.targets.python.carry import evaluator_text


def _load(text: str) -> types.ModuleType:
    mod = types.ModuleType("contract_eval")
    exec(compile(text, "contract_eval.py", "exec"), mod.__dict__)  # noqa: S102 - the generated module under test
    return mod


def test_the_operator_tables_are_the_semantics_table() -> None:
    ev = _load(evaluator_text("m"))
    assert set(ev._UNARY) == set(UNARY)
    assert set(ev._CMP) == set(COMPARISONS)
    assert set(ev._ARITH) | set(ev._TRUTH) | set(ev._CMP) == set(OPERATORS)
    assert ev._SHORT == {s: (o.decisive, o.decided) for s, o in OPERATORS.items()
                         if o.kind == "connective" and o.decisive is not None}
    assert ev._ZERO_UNDECIDED == {s for s, o in OPERATORS.items() if o.zero_divisor == "undecided"}


def _tree(rng: random.Random, want: str, depth: int) -> list[Any]:
    """A random tree of sort ``want`` (``num`` or ``bool``) in the carried evaluator's form."""
    if depth == 0 or rng.random() < 0.25:
        if want == "bool":
            return ["lit", rng.random() < 0.5]
        return ["num", rng.randint(-3, 3), rng.choice([1, 1, 2, 3])]
    if want == "num":
        if rng.random() < 0.3:
            return ["unary", rng.choice(["-", "abs"]), _tree(rng, "num", depth - 1)]
        op = rng.choice(sorted(s for s, o in OPERATORS.items() if o.kind == "arithmetic"))
        return ["bin", op, _tree(rng, "num", depth - 1), _tree(rng, "num", depth - 1)]
    pick = rng.random()
    if pick < 0.2:
        return ["unary", "not", _tree(rng, "bool", depth - 1)]
    if pick < 0.6:
        op = rng.choice(sorted(s for s, o in OPERATORS.items() if o.kind == "connective"))
        return ["bin", op, _tree(rng, "bool", depth - 1), _tree(rng, "bool", depth - 1)]
    ops = [rng.choice(sorted(COMPARISONS)) for _ in range(rng.randint(1, 2))]
    return ["cmp", ops, [_tree(rng, "num", depth - 1) for _ in range(len(ops) + 1)], False]


def _oracle(t: list[Any], mode: str) -> Any:
    """Brute force from the table's meanings: every operand evaluated, then the entry applied."""
    meaning = "double" if mode == "double" else "exact"
    kind = t[0]
    if kind == "lit":
        return t[1]
    if kind == "num":
        q = Fraction(t[1], t[2])
        return float(q) if mode == "double" and t[2] != 1 else (t[1] if t[2] == 1 else q)
    if kind == "unary":
        return getattr(UNARY[t[1]], meaning)(_oracle(t[2], mode))
    if kind == "bin":
        return getattr(OPERATORS[t[1]], meaning)(_oracle(t[2], mode), _oracle(t[3], mode))
    vals = [_oracle(o, mode) for o in t[2]]
    return all(bool(getattr(OPERATORS[op], meaning)(x, y)) for op, x, y in zip(t[1], vals, vals[1:]))


def _decided(f: Any, *args: Any) -> tuple[Any, bool]:
    try:
        return f(*args), True
    except (Undecided, ZeroDivisionError):
        return None, False


@pytest.mark.parametrize("mode", ["exact", "double"])
def test_each_reading_equals_the_table_by_brute_force_on_random_trees(mode: str) -> None:
    ev = _load(evaluator_text("m"))
    rng = random.Random(20261127)
    decided = 0
    for _ in range(3000):
        t = _tree(rng, "bool", rng.randint(1, 4))
        want, ok = _decided(_oracle, t, mode)
        got, _ = ev.run(mode, t, {})
        if not ok:
            continue  # a zero divisor somewhere: the short circuit may or may not reach it (not compared)
        decided += 1
        if mode == "double":
            assert got == bool(want), t
        else:
            assert got is bool(want), t
    assert decided > 2000


def test_an_operator_added_to_the_table_reaches_the_generated_evaluator() -> None:
    sgn = Operator("sgn", "sign", "arithmetic", 1, lambda x: (x > 0) - (x < 0), lambda x: (x > 0) - (x < 0),
                   python="((({x}) > 0) - (({x}) < 0))")
    hi = Operator("max", "maximum", "arithmetic", 2, max, max, python_reading="max({l}, {r})")
    text = evaluator_text("m", {**OPERATORS, "max": hi}, {**UNARY, "sgn": sgn})
    ev = _load(text)
    tree = ["cmp", ["=="], [["unary", "sgn", ["bin", "max", ["num", -3, 1], ["num", -7, 2]]], ["num", -1, 1]], False]
    assert ev.run("exact", tree, {}) == (True, "")
    assert ev.run("double", tree, {}) == (True, "")
    bare = dataclasses.replace(hi, python_reading=None)
    with pytest.raises(ValueError, match=r"'max' \(python_reading\)"):
        evaluator_text("m", {**OPERATORS, "max": bare}, UNARY)
