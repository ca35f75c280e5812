"""One entry point for the truth of an RCL formula on concrete values.

Direct evaluation (:func:`rclverify.semantics.evaluate.evaluate`, the monitors'
engine) decides the formula wherever it can; Z3
(:func:`rclverify.semantics.concrete.check_concrete`) is asked only when it
cannot.  Which formulas fall to Z3 is listed in docs/property-tests.md
("Checking each example"): a quantifier over REAL/INTEGER/NATURAL whose
variable is used outside equalities and function/constructor arguments and
is not bounded by a literal guard (``k <= 12 -> ...``), a quantifier over a
function or product type, division by zero, a function-typed value that is
not a :class:`~rclverify.semantics.values.FiniteFunction`.  Where both engines decide,
they agree (tests/semantics/test_one_evaluator.py checks it on random formulas and
values).
"""
from __future__ import annotations

from typing import Mapping

from rclverify.lang import ast
from rclverify.lang.types import Checked, CheckedNode
from rclverify.semantics.concrete import CHECK_RLIMIT, check_concrete
from rclverify.semantics.evaluate import evaluate
from rclverify.semantics.retry import SAFETY_TIMEOUT_MS


def decide(formula: ast.Expr, checked: Checked, node: CheckedNode, values: Mapping[str, object], *,
           timeout_ms: int = SAFETY_TIMEOUT_MS, rlimit: int = CHECK_RLIMIT) -> tuple[bool | None, str]:
    """Does ``formula`` (an RCL formula of ``node``) hold on these concrete values?

    ``values`` maps qualified names (``"in.r"``) to values of
    :mod:`rclverify.semantics.values`.  Returns ``(True, "")`` or ``(False, "")``
    when direct evaluation or Z3 decides it, ``(None, reason)`` when Z3 is
    needed and answers unknown within ``rlimit`` (Z3 steps; ``timeout_ms``
    milliseconds are a safety net).  When Z3 is needed it raises what
    :func:`check_concrete` raises (``KeyError`` for a missing or unknown
    name, :class:`~rclverify.semantics.concrete.ConcreteValueError`,
    :class:`~rclverify.semantics.encode.EncodingError`).

    Semantics: shared/DESIGN.md ("Semantics the tool commits to"), per
    input/output pair as in the paper, lines 462-495.
    """
    v = evaluate(formula, checked, node, values)
    if v is not None:
        return v, ""
    return check_concrete(formula, checked, node, values, timeout_ms=timeout_ms, rlimit=rlimit)


__all__ = ["decide"]
