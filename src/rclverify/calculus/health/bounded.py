"""Contract health, realizability over an output sequence its interface
bounds (docs/semantics.md, "Realizability over bounded output sequences").

The realizability query (:mod:`.realizable`) quantifies over the outputs:
``forall out. body(in, out)``.  Over an output of a sequence sort neither
Z3 nor cvc5 decides that quantifier in general (cvc5 answers ``unknown
(INCOMPLETE)`` as soon as a guarantee quantifies over the sequence's
items), so the contract's realizability, and with it ``--strict``, would
stay open.  When the interface bounds the sequence (the message field that
carries it is a bounded sequence ``T[<=N]`` or a fixed array ``T[N]``:
:class:`Bound`), the quantifier ranges over finitely many lengths, and for
each length ``k`` the sequence is written out as its items::

    forall out. body(out)   ==   and_{k in lengths} forall e1 .. ek. body(<e1, ..., ek>)

with ``lengths`` ``0..N`` (``T[<=N]``) or ``N`` alone (``T[N]``).  Each
conjunct quantifies over scalars only; Z3's simplifier rewrites a
guarantee's ``x in out.ys`` over the written-out sequence into ``x == e1 or
... or x == ek``, so a contract over linear arithmetic stays in linear
arithmetic, which Z3's quantifier elimination and cvc5 decide.  Each item
of a ``seq(NATURAL)`` is typed ``>= 0`` (:func:`natural_typing`), which the
quantifier over the sequence could not do.  The expansion is a rewriting
of the same statement (the sequences of at most ``N`` items are exactly
those of the lengths listed), so its answer is the contract's
realizability over the outputs the interface can carry.

Expansion is refused (``None``: the query over the sequence stands) when
the lengths of all bounded outputs together exceed :data:`MAX_LENGTHS`
combinations or :data:`MAX_ITEMS` items in one combination.
"""
from __future__ import annotations

import itertools
from dataclasses import dataclass
from typing import Mapping, Sequence

import z3

from rclverify.lang.types import SeqT, Type
from rclverify.semantics.natural import natural_typing

#: Combinations of lengths (one length per bounded output) written out at most.
MAX_LENGTHS = 64
#: Items of all bounded outputs together in one combination at most.
MAX_ITEMS = 32


@dataclass(frozen=True)
class Bound:
    """How the interface carries one output sequence: at most ``max_len``
    items (a ROS bounded sequence ``T[<=N]``), or exactly ``max_len`` when
    ``fixed`` (a ROS array ``T[N]``), as rosidl defines the field kinds."""

    max_len: int
    fixed: bool = False

    def lengths(self) -> list[int]:
        """The lengths the field can carry."""
        return [self.max_len] if self.fixed else list(range(self.max_len + 1))

    def text(self) -> str:
        """``at most 4 items`` / ``exactly 4 items``."""
        return f"{'exactly' if self.fixed else 'at most'} {self.max_len} item{'s' if self.max_len != 1 else ''}"


@dataclass(frozen=True)
class Expansion:
    """A quantifier over outputs with the bounded sequences written out:
    ``formula`` the conjunction over the lengths; ``exact`` whether every
    NATURAL part of the written-out outputs is typed (the items are)."""

    formula: z3.BoolRef
    exact: bool


def _written(s: z3.ExprRef, items: Sequence[z3.ExprRef]) -> z3.ExprRef:
    """The sequence of ``items`` in the sort of ``s``."""
    if not items:
        return z3.Empty(s.sort())
    units = [z3.Unit(e) for e in items]
    return units[0] if len(units) == 1 else z3.Concat(*units)


def expand(outs: Sequence[z3.ExprRef], types: Sequence[Type], bounds: Mapping[int, Bound],
           body: z3.BoolRef) -> Expansion | None:
    """``forall outs. body`` with each output ``outs[i]`` of a sequence
    type ``types[i]`` that ``bounds`` bounds (by index) written out item by
    item over its lengths (module docstring); the other outputs stay
    quantified as they are.  ``None`` when nothing is bounded or the
    expansion is beyond :data:`MAX_LENGTHS` / :data:`MAX_ITEMS`."""
    which = [i for i in sorted(bounds) if isinstance(types[i], SeqT)]
    if not which:
        return None
    choices = [bounds[i].lengths() for i in which]
    combos = list(itertools.product(*choices))
    if len(combos) > MAX_LENGTHS or any(sum(c) > MAX_ITEMS for c in combos):
        return None
    kept = [o for i, o in enumerate(outs) if i not in which]
    parts: list[z3.BoolRef] = []
    exact = True
    for combo in combos:
        items: list[z3.ExprRef] = []
        sub: list[tuple[z3.ExprRef, z3.ExprRef]] = []
        typing: list[z3.BoolRef] = []
        for i, k in zip(which, combo):
            elem = types[i]
            assert isinstance(elem, SeqT)
            es = [z3.Const(f"{outs[i].decl().name()}.{j}", outs[i].sort().basis()) for j in range(k)]
            for e in es:
                cs, ok = natural_typing(e, elem.elem)
                typing += cs
                exact = exact and ok
            items += es
            sub.append((outs[i], _written(outs[i], es)))
        b = z3.simplify(z3.substitute(body, *sub))
        if typing:
            b = z3.Implies(z3.And(*typing) if len(typing) > 1 else typing[0], b)
        bound = [*kept, *items]
        parts.append(z3.ForAll(bound, b) if bound else b)
    return Expansion(z3.And(*parts) if len(parts) > 1 else parts[0], exact)


__all__ = ["Bound", "Expansion", "MAX_ITEMS", "MAX_LENGTHS", "expand"]
