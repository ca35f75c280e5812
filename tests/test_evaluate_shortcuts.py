"""The evaluator's shortcuts for the monitors' speed (docs/monitors.md,
"Direct evaluation"): a quantified variable pinned by an equality guard is not
enumerated, one the body never mentions is bound once (forall/exists only),
and the answers are those of full enumeration and of Z3."""
from __future__ import annotations

import pytest

from rclverify.logic.concrete import check_concrete
from rclverify.logic.evaluate import evaluate, why_undecided
from rclverify.rcl.parser import parse_formula, parse_text
from rclverify.rcl.typecheck import check
from rclverify.values import FiniteFunction, Term

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
])
def test_shortcut_answers_agree_with_z3(text: str, expected: bool) -> None:
    f = parse_formula(text)
    assert evaluate(f, CHECKED, NODE, VALUES) is expected, why_undecided(f, CHECKED, NODE, VALUES)
    z3_answer, reason = check_concrete(f, CHECKED, NODE, VALUES)
    assert z3_answer in (None, expected), reason
