"""Temporal requirements over contracts that apply ``sqrt``, ``sin`` or ``cos``.

The queries of the temporal engine (:mod:`.temporal`, :mod:`.safety`,
:mod:`.lasso`) read the three functions as the uninterpreted functions of
:mod:`rclverify.semantics.mathfacts` (docs/semantics.md, "Mathematical
functions").  Two rules keep their verdicts sound:

* :func:`with_facts`: every state of the transition system satisfies the
  facts of the applications its initial predicate, its step and the
  statement's formulas make at that state (:func:`~rclverify.semantics.mathfacts.facts`).
  Each fact holds of the real functions at every argument, so no run of the
  real system is removed: a proof stays a proof, and a ``sqrt`` outside a
  quantifier is pinned to its one value;
* :func:`unconfirmed`: a refutation from a run that applies ``sin``/``cos``
  (or any of the three inside a quantifier), which the facts do not pin, is
  ``inconclusive`` with the reason unless the run was confirmed on its values
  by the evaluator (:mod:`.lasso_confirm`, Python's ``math``).
"""
from __future__ import annotations

import dataclasses
from fractions import Fraction
from typing import Any, Callable, Mapping, Sequence

from rclverify.calculus.requirements.tsys import TemporalVerdict, TransitionSystem
from rclverify.lang import ast
from rclverify.semantics import mathfacts
from rclverify.semantics.connectives import conj

#: a statement's formula as a predicate over one state
Prop = Callable[[Any], Any]


def _terms(ts: TransitionSystem, props: Sequence[Prop]) -> list[Any]:
    s0, s1 = ts.state(0, "math"), ts.state(1, "math")
    return [ts.init(s0), ts.trans(s0, s1), *[p(s0) for p in props]]


def mentions_math(*roots: object) -> bool:
    """Whether a ``sqrt``, ``sin`` or ``cos`` (:data:`rclverify.lang.ast.MATH_FUNCTIONS`) is written
    anywhere in ``roots`` (ASTs, checked nodes, formal statements, the environment, and the
    dataclasses, mappings and sequences holding them).  Read from the syntax, so asking builds no
    Z3 term: a query of a system without them is the query it was, term for term."""
    seen: set[int] = set()
    stack: list[object] = list(roots)
    while stack:
        o = stack.pop()
        if o is None or isinstance(o, (str, bytes, int, float, Fraction)) or id(o) in seen:
            continue
        seen.add(id(o))
        if isinstance(o, ast.Unary) and o.op in ast.MATH_FUNCTIONS:
            return True
        if dataclasses.is_dataclass(o) and not isinstance(o, type):
            stack.extend(getattr(o, f.name) for f in dataclasses.fields(o))
        elif isinstance(o, Mapping):
            stack.extend(o.values())
        elif isinstance(o, (list, tuple, set, frozenset)):
            stack.extend(o)
        elif hasattr(o, "__dict__") and type(o).__module__.startswith("rclverify."):
            stack.extend(vars(o).values())
    return False


def with_facts(ts: TransitionSystem, props: Sequence[Prop]) -> TransitionSystem:
    """``ts`` with the facts of its math applications (and those of ``props``) in every state; ``ts``
    itself when nothing applies a mathematical function."""
    if not mathfacts.applies_math(_terms(ts, props)):
        return ts

    def init(s: Any) -> Any:
        here = ts.init(s)
        return conj(here, *mathfacts.facts([here, *[p(s) for p in props]]))

    def trans(s: Any, u: Any) -> Any:
        step = ts.trans(s, u)
        return conj(step, *mathfacts.facts([step, *[p(u) for p in props]]))
    return TransitionSystem(ts.sorts, init, trans, ts.fairness)


def unconfirmed(v: TemporalVerdict, ts: TransitionSystem, props: Sequence[Prop],
                confirmed: list[dict[str, str]] | None) -> TemporalVerdict:
    """``v``, or ``inconclusive`` when it refutes from a run that reads ``sin``/``cos`` as unknown
    functions and is not the run ``confirmed`` on its values (module docstring)."""
    if v.status != "refuted" or (confirmed is not None and v.trace == confirmed):
        return v
    if not mathfacts.transcendental(_terms(ts, props)):
        return v
    return TemporalVerdict("inconclusive", v.method, k=v.k, bound=v.bound, trace=v.trace, loop=v.loop,
                           detail=f"{v.detail}; not a verdict: the run was found with sin/cos read as unknown "
                                  f"functions and is not confirmed on its values")


__all__ = ["mentions_math", "unconfirmed", "with_facts"]
