"""The fast renderer of Z3 model terms (logic/encode.term_to_rcl) gives the
same text as the tree walk it replaces, on random terms shaped like Z3's
function-table ``else`` branches (chains of ``if`` sharing conditions)."""
from __future__ import annotations

import random

import z3

from rclverify.semantics.encode import _term_to_rcl_reference, term_to_rcl


def _random_term(rng: random.Random, depth: int, p1: z3.ArithRef, p2: z3.ArithRef, shared: list[z3.BoolRef]) -> z3.ExprRef:
    if depth == 0:
        return rng.choice([z3.IntVal(rng.randint(-3, 60)), z3.RealVal(f"{rng.randint(-9, 9)}/{rng.randint(1, 7)}"),
                           z3.ToReal(p1) + 1, p2])
    cond = rng.choice(shared) if shared and rng.random() < 0.5 else z3.And(
        p2 == rng.randint(0, 5), z3.Not(p1 == rng.randint(0, 50)), z3.Distinct(p1, p2 + 1))
    shared.append(cond)
    other = _random_term(rng, depth - 1, p1, p2, shared)
    leaf = rng.choice([z3.IntVal(rng.randint(0, 12)), p1 * 2 - p2, z3.If(z3.Or(p1 < 3, p2 >= 1), p1, p2)])
    return z3.If(cond, leaf, other)


def test_fast_render_matches_the_tree_walk() -> None:
    rng = random.Random(7)
    p1, p2 = z3.Ints("p1 p2")
    for _ in range(15):
        t = _random_term(rng, rng.randint(0, 40), p1, p2, [])
        assert term_to_rcl(t) == _term_to_rcl_reference(t)


def test_deep_chain_beyond_the_recursion_limit() -> None:
    p1 = z3.Int("p1")
    t: z3.ExprRef = z3.IntVal(0)
    for k in range(1200):
        t = z3.If(p1 == k, z3.IntVal(k % 13), t)
    text = term_to_rcl(t)
    assert text == _term_to_rcl_reference(t)
    assert text.startswith("(if (p1 == 1199) then 3 else (if (p1 == 1198)")


def test_a_function_model_names_its_arguments_in_order() -> None:
    """In a function interpretation Var(j) is argument j: f(x, y) = x - 2y is
    printed with p1 for x (it was printed transposed)."""
    from rclverify.semantics.query import render_model
    f = z3.Function("f", z3.IntSort(), z3.IntSort(), z3.IntSort())
    x, y = z3.Ints("x y")
    s = z3.Solver()
    s.add(z3.ForAll([x, y], f(x, y) == x - 2 * y))
    assert s.check() == z3.sat
    text = render_model(s.model(), None)["f"]
    assert text.startswith("{(p1, p2) -> ") and "(-2 * p2)" in text and "(-2 * p1)" not in text, text


def test_a_function_constant_off_a_grid_of_points_is_an_exact_table() -> None:
    """An interpretation whose conditions only compare arguments with numerals
    is printed as the points where it differs from its value elsewhere, and
    that value (semantics/functable.py). Z3 answers this one with a disjunctive
    first branch of value 1 and an unreachable last ``else`` of 2, which a
    reading of the text would have called the value elsewhere."""
    from rclverify.semantics.query import render_model
    g = z3.Function("g", z3.RealSort(), z3.RealSort(), z3.IntSort())
    a, b = z3.Reals("a b")
    s = z3.Solver()
    s.add(g(5, 4) == 12, g(3, 2) == 7,
          z3.ForAll([a, b], z3.Implies(z3.And(z3.Or(a != 5, b != 4), z3.Or(a != 3, b != 2)), g(a, b) == 1)))
    assert s.check() == z3.sat
    m = s.model()
    text = render_model(m, None)["g"]
    assert text == "{(3, 2) -> 7, (5, 4) -> 12, else -> 1}", text
    from rclverify.diagnosis.table import function_table
    assert function_table(text) == {"rows": [["(3, 2)", "7"], ["(5, 4)", "12"]], "more": 0, "else": "1"}
    assert m.eval(g(z3.RealVal(3), z3.RealVal(4))).as_long() == 1  # a point on a numeral's line is elsewhere


def test_a_function_that_returns_its_argument_is_not_made_a_table() -> None:
    """f(x) = x except f(3) = 7 takes infinitely many values: it is printed as
    its term, never as a table with one value elsewhere."""
    from rclverify.semantics.query import render_model
    f = z3.Function("f", z3.IntSort(), z3.IntSort())
    x = z3.Int("x")
    s = z3.Solver()
    s.add(z3.ForAll([x], z3.Implies(x != 3, f(x) == x)), f(3) == 7)
    assert s.check() == z3.sat
    text = render_model(s.model(), None)["f"]
    assert "p1" in text and "else -> 4" not in text, text
