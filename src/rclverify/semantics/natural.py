"""Every NATURAL part of a value typed ``>= 0`` (docs/decisions.md, "Z3
encoding": NATURAL is Z3's ``Int`` with ``>= 0``).

A NATURAL value, a constructor's NATURAL field and a tuple's NATURAL
component are all Z3 integers; the type's meaning is the constraint.  It
was written for a NATURAL constant and a constructor's direct fields only,
so a query over a ``(NATURAL, NATURAL)`` ranged over ``(-1, 0)`` as well: a
contract whose guarantee only a negative component satisfies read
consistent, and one no output answers read realizable
(:mod:`rclverify.calculus.health.realizable`).  A sequence's or a set's elements
need a quantified constraint: given as an axiom on a free symbol
(``quantified``; the encoder's), where a consistency query whose guarantee
only a negative element of a ``seq(NATURAL)`` meets read consistent;
left out under realizability's quantifier over the outputs, where Z3 did
not decide it in 20 s: they are then reported as not typed (``exact``
false), and a caller must not believe an ``unsat`` over such a value.
"""
from __future__ import annotations

from typing import Any

import z3

from rclverify.lang.types import NATURAL, DataT, SeqT, SetT, TupleT, Type
from rclverify.semantics.connectives import conj
from rclverify.semantics.sorts import sort_of


def natural_typing(term: z3.ExprRef, t: Type, depth: int = 0, quantified: bool = False
                   ) -> tuple[list[z3.BoolRef], bool]:
    """``(constraints, exact)``: that every NATURAL part of value ``term`` of
    RCL type ``t`` is ``>= 0`` (the type's meaning, docs/decisions.md "Z3
    encoding"): ``t`` itself, a constructor's fields (under its recogniser),
    a tuple's components, at any depth (a constructor set nested in itself
    followed 3 levels); ``exact`` is false when a NATURAL part is left
    unconstrained: a sequence's or a set's elements (a quantified typing
    left Z3 undecided for 20 s where the query without it takes 0.1 s), or
    a nesting deeper than followed.  With ``quantified`` (an axiom on a free
    symbol, where Z3 copes with it), a sequence's or a set's elements are
    typed too, by a quantifier over the positions or the members."""
    if t == NATURAL:
        return [term >= 0], True
    if isinstance(t, (SeqT, SetT)):
        if not quantified or depth > 3 or not has_natural(t.elem, 0):
            return [], not has_natural(t.elem, 0)
        if isinstance(t, SeqT):
            x: Any = z3.Const(f"_nat{depth}", z3.IntSort())
            cs, ok = natural_typing(term[x], t.elem, depth + 1, quantified)
            guard = z3.And(x >= 0, x < z3.Length(term))
        else:
            x = z3.Const(f"_nat{depth}", sort_of(t.elem))
            cs, ok = natural_typing(x, t.elem, depth + 1, quantified)
            guard = z3.IsMember(x, term)
        return ([z3.ForAll([x], z3.Implies(guard, cs[0] if len(cs) == 1 else conj(*cs)))] if cs else []), ok
    if not isinstance(t, (DataT, TupleT)):
        return [], True
    if depth > 3:
        return [], not has_natural(t, 0)
    out: list[z3.BoolRef] = []
    exact = True
    s: Any = sort_of(t)
    ctors = t.ctors if isinstance(t, DataT) else (("", t.elems),)
    for k, (_, args) in enumerate(ctors):
        parts: list[z3.BoolRef] = []
        for i, a in enumerate(args):
            cs, ok = natural_typing(s.accessor(k, i)(term), a, depth + 1, quantified)
            parts += cs
            exact = exact and ok
        if parts:
            both = parts[0] if len(parts) == 1 else conj(*parts)
            out.append(z3.Implies(s.recognizer(k)(term), both) if isinstance(t, DataT) else both)
    return out, exact


def has_natural(t: Type, depth: int) -> bool:
    """Whether type ``t`` has a NATURAL part (followed 6 levels; deeper: assumed so)."""
    if t == NATURAL or depth > 6:
        return t == NATURAL or isinstance(t, (DataT, TupleT, SeqT, SetT))
    if isinstance(t, (SeqT, SetT)):
        return has_natural(t.elem, depth + 1)
    if isinstance(t, TupleT):
        return any(has_natural(e, depth + 1) for e in t.elems)
    if isinstance(t, DataT):
        return any(has_natural(a, depth + 1) for _, args in t.ctors for a in args)
    return False
