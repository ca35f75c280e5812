"""One formula of one node judged on recorded values, compiled once: the
monitors' fast path to :func:`rclverify.semantics.floatsem.judge`.

:class:`FormulaJudge` answers exactly what ``judge(formula, checked, node,
values, tolerance)`` answers (the same truth, the same ``semantics``, the
same reason), faster where it can:

* the formula's exact truth comes from its straight-line function
  (:func:`rclverify.semantics.straightline.compile_exact`) instead of the
  evaluator.  True: it holds in exact arithmetic, ``judge``'s first answer.
  An I/O value missing where the evaluation needs it: undecided with
  ``no value for KEY``, ``judge``'s answer too (no semantics can decide);
* false, and the formula is one whose truth double arithmetic and the
  declared tolerance cannot change
  (:func:`rclverify.semantics.floatsens.float_sensitive`, computed once): false
  in exact arithmetic, ``judge``'s answer (it tries nothing else there);
* anything else (false where another semantics could say otherwise, a value
  of the wrong form, a formula the straight-line code does not handle, Z3
  needed on concrete values) is ``judge`` itself, so the answer is the
  same by construction.

The :attr:`FormulaJudge.fallback` text says when a formula is always left to
``judge`` (a debug field: which construct was not compiled).
"""
from __future__ import annotations

from typing import Mapping

from rclverify.lang import ast
from rclverify.lang.types import Checked, CheckedNode
from rclverify.semantics.floatsem import Judgement, Tolerance, judge
from rclverify.semantics.floatsens import float_sensitive
from rclverify.semantics.straightline import Missing, compile_exact

#: ``judge``'s answer for a formula that holds in exact arithmetic.
HOLDS_EXACT = Judgement(True, "exact")
#: ``judge``'s answer for a false formula only exact arithmetic applies to.
FALSE_EXACT = Judgement(False, "exact", "")


class FormulaJudge:
    """``formula`` of ``node`` judged on recorded values with ``tolerance``
    (``None``: none declared); call it with the values (qualified names ->
    values of :mod:`rclverify.semantics.values`) for a :class:`Judgement`.

    Attributes: ``compiled`` (the straight-line function is used),
    ``fallback`` (why not, ``""`` when it is), ``source`` (the generated
    code, for debugging)."""

    __slots__ = ("formula", "checked", "node", "tolerance", "_fn", "_false", "_missing", "fallback", "source")

    def __init__(self, formula: ast.Expr, checked: Checked, node: CheckedNode,
                 tolerance: Tolerance | None = None) -> None:
        self.formula, self.checked, self.node, self.tolerance = formula, checked, node, tolerance
        straight = compile_exact(formula, checked, node)
        self._fn = straight.fn
        self.fallback = straight.fallback
        self.source = straight.source
        changeable = float_sensitive(formula, checked, node) or (
            bool(tolerance) and float_sensitive(formula, checked, node, tolerant=True))
        self._false = None if changeable else FALSE_EXACT
        self._missing: dict[str, Judgement] = {}

    @property
    def compiled(self) -> bool:
        """Whether the formula's exact truth comes from straight-line code."""
        return self._fn is not None

    def quick(self, values: Mapping[str, object]) -> Judgement | None:
        """The judgement when the straight-line code decides it alone (true,
        a missing value, or false in a formula no other semantics can
        change); ``None`` when :func:`judge` must be asked."""
        fn = self._fn
        if fn is None:
            return None
        try:
            truth = fn(values)
        except Missing as exc:
            hit = self._missing.get(exc.key)
            if hit is None:
                hit = self._missing[exc.key] = Judgement(None, "", f"no value for {exc.key}")
            return hit
        except Exception:  # noqa: BLE001 - the evaluator's business: judge() meets the same and answers
            return None
        if truth:
            return HOLDS_EXACT
        return self._false

    def __call__(self, values: Mapping[str, object]) -> Judgement:
        """The judgement of the formula on ``values``: :func:`judge`'s."""
        hit = self.quick(values)
        if hit is not None:
            return hit
        return judge(self.formula, self.checked, self.node, values, self.tolerance)


__all__ = ["FALSE_EXACT", "FormulaJudge", "HOLDS_EXACT"]
