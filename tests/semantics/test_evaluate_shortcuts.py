"""The evaluator's shortcuts for the monitors' speed (docs/monitors.md,
"Direct evaluation"): a quantified variable pinned by an equality guard is not
enumerated, one the body never mentions is bound once (forall/exists only),
and the answers are those of full enumeration and of Z3."""
from __future__ import annotations

from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rclverify.semantics.concrete import check_concrete
from rclverify.semantics.evaluate import evaluate, why_undecided
from rclverify.lang.parser import parse_formula, parse_text
from rclverify.lang.typecheck import check
from rclverify.semantics.values import FiniteFunction, Term

SIGNATURE = """
context {
  Cmd : { move(REAL, REAL), inspect(NATURAL) } ;
  Seen : NATURAL --> BOOL ;
  Way : REAL x REAL --> NATURAL ;
}
node n {
  inputs( r : REAL, f : Seen, g : Way )
  outputs( ocmd : Cmd )
  guarantee( TRUE )
}
"""
CHECKED = check([parse_text(SIGNATURE)])
NODE = CHECKED.nodes["n"]
VALUES = {"in.r": 2.0, "in.f": FiniteFunction({(1,): True, (2,): False}, False, 1),
          "in.g": FiniteFunction({(0.0, 0.0): 0, (2.0, 1.0): 1, (4.0, 1.5): 2}, 0, 2),
          "out.ocmd": Term("move", (2.0, 1.0))}


@pytest.mark.parametrize("text, expected", [
    # i pinned by in.g(x, y) == i: only g's results are tried
    ("forall(x, y in REAL, i in NATURAL | in.g(x, y) == i and in.f(i) == FALSE -> i != 1)", True),
    ("forall(x, y in REAL, i in NATURAL | in.g(x, y) == i and in.f(i) == FALSE -> i == 1)", False),
    ("exists(x, y in REAL, i in NATURAL | in.g(x, y) == i and in.f(i) == TRUE)", True),
    # x' and y' never used: one value stands for all (REAL is never empty)
    ("forall(x', y' in REAL, i in NATURAL | in.f(i) == TRUE -> i == 1)", True),
    ("exists(x' in REAL | in.r == 2.0)", True),
    ("exists(x' in REAL | in.r == 3.0)", False),
    ("forall(x' in INTEGER | in.r == 3.0)", False),
    # ... but exists_unique: a true body has infinitely many witnesses
    ("exists_unique(x' in REAL | in.r == 2.0)", False),
    ("exists_unique(x' in NATURAL | in.r == 2.0)", False),
    # a variable used only inside a nested quantifier counts as used
    ("exists(k in NATURAL | exists(x, y in REAL | in.g(x, y) == k and in.f(k) == TRUE))", True),
    ("forall(k in NATURAL | exists(x, y in REAL | in.g(x, y) == k and in.f(k) == FALSE))", False),
    ("exists(x, y in REAL | out.ocmd == move(x, y) and in.g(x, y) == 1)", True),
    # a slot guarded by f(slot) == t, t's value not f's default: only the table keys with that
    # result are tried, so a body that uses the variable any way (n * n) is decided
    ("exists(n in NATURAL | in.f(n) == TRUE and n * n == 1)", True),
    ("exists(n in NATURAL | in.f(n) == TRUE and n * n == 4)", False),
    ("forall(x, y in REAL | in.g(x, y) == 2 -> x * y == 6.0)", True),
    ("forall(x, y in REAL | in.g(x, y) == 1 -> x < y)", False),
    ("forall(k in NATURAL | k <= 2 -> exists(x, y in REAL | in.g(x, y) == k))", True),
    ("forall(k in NATURAL | k <= 3 -> exists(x, y in REAL | in.g(x, y) == k))", False),
])
def test_shortcut_answers_agree_with_z3(text: str, expected: bool) -> None:
    f = parse_formula(text)
    assert evaluate(f, CHECKED, NODE, VALUES) is expected, why_undecided(f, CHECKED, NODE, VALUES)
    z3_answer, reason = check_concrete(f, CHECKED, NODE, VALUES)
    assert z3_answer in (None, expected), reason


def test_a_guard_that_the_default_meets_leaves_the_slot_to_its_domain() -> None:
    """``in.f(n) == FALSE`` holds at every point outside f's table (its
    default is FALSE), so the guard cannot narrow ``n`` to table keys; with
    ``n * n`` in the body the quantifier is left to Z3."""
    f = parse_formula("exists(n in NATURAL | in.f(n) == FALSE and n * n == 9)")
    assert evaluate(f, CHECKED, NODE, VALUES) is None
    assert "n" in why_undecided(f, CHECKED, NODE, VALUES)
    assert check_concrete(f, CHECKED, NODE, VALUES)[0] is True


# -- the compiled closures against the tree walk ----------------------------------------------

REAL_TERMS = ["in.r", "0.5", "2", "x", "(in.r + x)", "(x - 1)", "(in.r * 2)", "(x / in.r)", "(x / 0)"]
NAT_TERMS = ["in.g(x, x)", "in.g(in.r, 1.0)", "i", "(i + 1)", "3"]
ATOMS = ["{a} == {b}", "{a} != {b}", "{a} < {b}", "{a} <= {b} <= {c}", "in.f({n}) == TRUE", "in.f({n})",
         "out.ocmd == move({a}, {b})", "out.ocmd == inspect({n})", "{n} in {{1, 2}}", "{a} in NATURAL",
         "out.missing == 1"]


def _formula(draw: Any, depth: int) -> str:
    kind = draw(st.integers(0, 5 if depth > 0 else 0))
    if kind == 0:
        atom = draw(st.sampled_from(ATOMS))
        return "(" + atom.format(a=draw(st.sampled_from(REAL_TERMS)), b=draw(st.sampled_from(REAL_TERMS)),
                                 c=draw(st.sampled_from(REAL_TERMS)), n=draw(st.sampled_from(NAT_TERMS))) + ")"
    if kind == 1:
        return f"(not {_formula(draw, depth - 1)})"
    if kind <= 3:
        op = draw(st.sampled_from(["and", "or", "->", "<=>"]))
        return f"({_formula(draw, depth - 1)} {op} {_formula(draw, depth - 1)})"
    q = draw(st.sampled_from(["forall", "exists", "exists_unique"]))
    return f"{q}(x in REAL, i in NATURAL | {_formula(draw, depth - 1)})"


@st.composite
def formulas(draw: Any) -> str:
    return _formula(draw, 3)


def _outcome(f: Any, values: dict[str, Any], compiled: bool) -> Any:
    from rclverify.semantics.evaluate import Evaluator
    ev = Evaluator(CHECKED, NODE, values)
    ev.compiled = compiled
    try:
        return ("value", ev.eval(f, {"x": 1.5, "i": 2}))
    except Exception as exc:  # noqa: BLE001 - the exception itself is part of the behaviour compared
        return ("raised", type(exc).__name__, str(exc))


def test_compiled_closures_do_what_the_tree_walk_does() -> None:
    """Random formulas (arithmetic, comparisons, chains, function and
    constructor terms, membership, missing values, division by zero, nested
    quantifiers) on two states: the same value or the same exception."""
    states = [VALUES, {**VALUES, "in.r": 0, "out.ocmd": Term("inspect", (2,))}]

    @settings(max_examples=300, deadline=None, suppress_health_check=list(HealthCheck))
    @given(formulas())
    def check(text: str) -> None:
        f = parse_formula(text)
        for values in states:
            assert _outcome(f, values, True) == _outcome(f, values, False)
    check()
