"""One evaluation for a formula's truth and, when undecided, the reason
(:func:`rclverify.semantics.evaluate.evaluate_why`): the same answers as
:func:`evaluate` and :func:`why_undecided` evaluated apart, on decided and
undecided formulas, and the reason :func:`floatsem.judge` gives a guarantee
whose output is missing (docs/monitors.md, "Against its peers")."""
from __future__ import annotations

import pytest

from rclverify.lang import ast
from rclverify.lang.parser import parse_formula, parse_text
from rclverify.lang.typecheck import check
from rclverify.semantics.evaluate import evaluate, evaluate_why, why_undecided
from rclverify.semantics.floatsem import judge
from rclverify.semantics.values import FiniteFunction

SIGNATURE = """
node n {
  inputs( x : NATURAL --> REAL )
  outputs( y : NATURAL --> REAL )
  guarantee( TRUE )
}
"""
CHECKED = check([parse_text(SIGNATURE)])
NODE = CHECKED.nodes["n"]
UNTIL = "exists(j in <0 upto 3> | out.y(j) > 4 and forall(i in <0 upto 3> | i < j -> in.x(i) > 1))"


def _seq(*v: float) -> FiniteFunction:
    """A window as the monitors map it: index -> value."""
    return FiniteFunction({(i,): x for i, x in enumerate(v)}, 0.0, 1)


X = _seq(2.0, 0.5, 3.0, 1.5)


def _formula(text: str) -> ast.Expr:
    return parse_formula(text)


@pytest.mark.parametrize("text, values, truth", [
    (UNTIL, {"in.x": X, "out.y": _seq(1.0, 5.0, 0.0, 0.0)}, True),  # j = 1: y(1) > 4, x(0) > 1
    (UNTIL, {"in.x": X, "out.y": _seq(1.0, 1.0, 5.0, 0.0)}, False),  # j = 2 needs x(1) > 1
    (UNTIL, {"in.x": X}, None),  # the question on its inputs alone: the output is missing
    ("forall(i in <0 upto 3> | in.x(i) > 0)", {"in.x": X}, True),  # inputs alone decide it (the control)
])
def test_one_evaluation_answers_as_two(text: str, values: dict[str, object], truth: bool | None) -> None:
    f = _formula(text)
    got = evaluate_why(f, CHECKED, NODE, values)
    assert got == (evaluate(f, CHECKED, NODE, values), why_undecided(f, CHECKED, NODE, values))
    assert got[0] is truth
    assert (got[1] == "") == (truth is not None)


def test_judge_names_the_missing_output() -> None:
    f = _formula(UNTIL)
    undecided = judge(f, CHECKED, NODE, {"in.x": X})
    assert undecided.truth is None and "no value for out.y" in undecided.reason
    decided = judge(f, CHECKED, NODE, {"in.x": X, "out.y": _seq(1.0, 5.0, 0.0, 0.0)})  # control: with the output
    assert decided.truth is True and decided.reason == ""
