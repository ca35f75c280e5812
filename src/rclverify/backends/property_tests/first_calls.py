"""``first(in.x)`` in the property tests (docs/semantics.md, "The first
published value"; docs/property-tests.md).

A stateful implementation (a class, one instance per example, its ``step``
called once per drawn input) is judged with ``first(in.x)`` TRUE on its
first step and FALSE on every later one: each step hands it a message on
every input.  A function is called with one message and cannot know
whether it is the first, so a guarantee over ``first`` must hold for every
value: each conjunct is judged for every combination of the ``first(...)``
it reads (two per input), and the first combination that fails it is the
counterexample's, shown beside its inputs.
"""
from __future__ import annotations

from itertools import product
from typing import Callable, Mapping

from rclverify.lang import ast, walk
from rclverify.lang.types import Checked, CheckedNode
from rclverify.semantics.floatsem import Judgement, judge


def first_keys(formula: ast.Expr) -> list[str]:
    """The ``first(in.x)`` keys ``formula`` reads, in order."""
    return list(dict.fromkeys(f"first(in.{x.arg.name})" for x in walk.subexpressions(formula)
                              if isinstance(x, ast.First)))


def judge_first(formula: ast.Expr, checked: Checked, node: CheckedNode, values: Mapping[str, object],
                step: int | None, judge_fn: Callable[..., Judgement] = judge) -> tuple[Judgement, dict[str, object]]:
    """The judgement of ``formula`` on ``values`` (module docstring) and the
    ``first(...)`` values it was decided with (``{}`` when it reads none):
    ``step`` is the stateful step (1 the first), ``None`` for a function;
    ``judge_fn`` judges one reading (:func:`~rclverify.semantics.floatsem.judge`).
    False on the first combination that fails; else undecided on the first
    that is undecided; else true."""
    keys = first_keys(formula)
    if not keys:
        return judge_fn(formula, checked, node, values), {}
    combos = [dict.fromkeys(keys, step == 1)] if step is not None else \
        [dict(zip(keys, bits)) for bits in product((True, False), repeat=len(keys))]
    undecided: tuple[Judgement, dict[str, object]] | None = None
    last: tuple[Judgement, dict[str, object]] | None = None
    for combo in combos:
        j = judge_fn(formula, checked, node, {**values, **combo})
        if j.truth is False:
            return j, dict(combo)
        if j.truth is None and undecided is None:
            undecided = (j, dict(combo))
        last = (j, dict(combo))
    assert last is not None
    return undecided or last


__all__ = ["first_keys", "judge_first"]
