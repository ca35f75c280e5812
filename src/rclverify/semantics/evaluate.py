"""Direct evaluation of an RCL formula on a node's concrete values (no solver).

Used by the offline trace checker (:mod:`rclverify.backends.monitors`) on
every event and by the property tests on every example
(:func:`rclverify.semantics.decide.decide`), so it must be fast.  Values follow
:mod:`rclverify.semantics.values`; the environment is keyed by qualified names
(``"in.r"``, ``"out.radiationStatus"``), a bare name resolving inputs first,
like :meth:`CheckedNode.io_type`.  REAL arithmetic is exact (a float is the
rational it denotes), as in the Z3 encoding (shared/DESIGN.md).

Quantifiers are decided by enumeration:

* over ``BOOL``, an enumeration, a set literal or a finite set value: every
  element;
* over ``INTEGER``/``NATURAL`` bounded by literal guards (``k <= 12 -> ...``
  under ``forall``, ``k >= -2 and k <= 2 and ...`` under ``exists``): every
  value in the range (at most :data:`MAX_RANGE`);
* a variable (or a pair ``x, y``) fixed by an equality guard ``v == t`` or
  ``move(x, y) == t`` (``t`` free of it): only the value of ``t``;
* a variable (or a tuple ``x, y``) guarded by ``f(x, y) == t`` (``f`` a
  function value given as a finite table, ``t`` free of them) when ``t``'s
  value is not ``f``'s default: only the table's keys with that result (every
  other point gives the default, which fails the guard), whatever else the
  body does with the variables;
* over ``REAL``/``INTEGER``/``NATURAL`` otherwise: exactly, when the bound
  variable occurs only as an argument of a function or of a constructor, or
  as an operand of ``==``/``!=`` (possibly shifted by a literal, ``i + 1``)
  whose other side is a literal, an I/O value, a function's result or a
  variable bound outside; a constructor term holding it must itself be
  compared with an I/O value, a function's result or a literal term.  Then
  only the values the environment and the formula mention (shifted back by
  those literals) can make an atom true; every other value behaves like one
  fresh value, which is enumerated once.  For ``exists_unique`` a fresh
  value satisfying the body stands for infinitely many, so uniqueness fails.
  Any other use (``x < 3``, ``x * y``, ``x == in.r + 1``) makes the
  quantifier undecidable here and :func:`evaluate` answers ``None`` (the
  callers then ask Z3).

tests/semantics/test_one_evaluator.py checks on random formulas and values that
wherever this module and Z3 (:mod:`.concrete`) both decide, they agree.

The evaluator is split by job: values and domains (:mod:`.eval_values`),
the static analysis of quantifier bodies (:mod:`.eval_shapes`), quantifier
search plans (:mod:`.eval_search`), quantifier enumeration
(:mod:`.eval_quant`), expressions compiled into closures
(:mod:`.eval_closures`) and the evaluation context (:mod:`.evaluator`);
this module is the entry point and keeps every name importable from here.
"""
from __future__ import annotations

from typing import Mapping

from rclverify.lang import ast
from rclverify.lang.types import Checked, CheckedNode
from rclverify.semantics.eval_closures import COMPILED_SIZE, _COMPILED, _compile, _compile_binary, _compile_var
from rclverify.semantics.eval_quant import QuantifierEvaluation
from rclverify.semantics.eval_search import (_Pin, _Preimage, _equalities, _function_args, _guards, _joint_groups, _pin, _plan,
                          _preimage_group, _stage)
from rclverify.semantics.eval_shapes import (MAX_RANGE, _STATIC, _bound_of, _children, _closed, _conjuncts, _ctor_uses, _free,
                          _integer_range, _literal_number, _literals, _mentions, _offsets, _only_as, _shift,
                          _static_literals, _static_shifts, _tuple_apps, _unused)
from rclverify.semantics.eval_values import (_CMP, _INFINITE, _LIT, Undecided, _fit, _fits, _Fresh, _integral, _NoDomain, _numbers,
                          arithmetic)
from rclverify.semantics.evaluator import Evaluator


def evaluate(formula: ast.Expr, checked: Checked, node: CheckedNode,
             values: Mapping[str, object]) -> bool | None:
    """Truth value of ``formula`` for ``node`` on ``values``.

    ``values`` maps qualified names (``"in.r"``) to values in the
    :mod:`rclverify.semantics.values` convention.  Returns ``True``/``False``, or
    ``None`` when the formula cannot be decided directly (a quantifier over
    an infinite domain that does not reduce to finitely many candidates, or
    a value the formula needs is missing).  Never raises for such cases.
    """
    return evaluate_why(formula, checked, node, values)[0]


def evaluate_why(formula: ast.Expr, checked: Checked, node: CheckedNode,
                 values: Mapping[str, object]) -> tuple[bool | None, str]:
    """:func:`evaluate`'s answer and, when it is ``None``, the reason
    (:func:`why_undecided`'s), from one evaluation: ``(truth, "")`` or
    ``(None, reason)``.  Never raises for a formula or value it cannot decide."""
    try:
        return bool(Evaluator(checked, node, values).eval(formula, {})), ""
    except Undecided as exc:
        return None, str(exc)
    except (TypeError, ZeroDivisionError) as exc:
        return None, f"a value has the wrong form for the formula: {exc}"


def why_undecided(formula: ast.Expr, checked: Checked, node: CheckedNode, values: Mapping[str, object]) -> str:
    """The reason :func:`evaluate` answers ``None`` ('' when it decides)."""
    return evaluate_why(formula, checked, node, values)[1]


__all__ = ["COMPILED_SIZE", "Evaluator", "MAX_RANGE", "QuantifierEvaluation", "Undecided", "arithmetic", "evaluate",
           "evaluate_why", "why_undecided"]
