"""What a node's assumption says about the range of each input, read as bounds
(docs/property-tests.md, "Strategies" and "Sequences").

Every top-level conjunct of the assumption of the form ``c <= in.x``,
``in.x < c``, ``a <= in.x < b``, ``abs(in.x) <= c`` (numeric literals or
named constants of the context) bounds a numeric input; ``in.e in {v1,
v2}`` restricts an enumeration input; ``forall(q in in.s | body)`` bounds
every item of the sequence input ``s`` by ``body``'s conjuncts of those
forms over ``q``, and ``exists(q in in.s | ...)`` gives ``s`` at least one
item.  :mod:`.strategies` draws within them by construction; the
comparisons' converses come from the semantics table.
"""
from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from typing import Callable, Mapping

from rclverify.lang import ast
from rclverify.lang.types import CheckedNode, EnumT, Scalar, SeqT, Type
from rclverify.semantics.operators import OPERATORS


@dataclass
class Bound:
    """Closed/open numeric bounds of one input (``None``: unbounded); of a sequence input, the bounds of
    each of its items."""

    lo: Fraction | None = None
    hi: Fraction | None = None
    lo_strict: bool = False
    hi_strict: bool = False
    enum: frozenset[str] | None = None
    #: the least number of items of a sequence input (1 under a top-level ``exists(q in in.s | ...)``)
    min_len: int = 0

    def lower(self, v: Fraction, strict: bool) -> None:
        if self.lo is None or v > self.lo or (v == self.lo and strict):
            self.lo, self.lo_strict = v, strict

    def upper(self, v: Fraction, strict: bool) -> None:
        if self.hi is None or v < self.hi or (v == self.hi and strict):
            self.hi, self.hi_strict = v, strict


def _num(e: ast.Expr, named: Mapping[str, Fraction] | None = None) -> Fraction | None:
    """A numeric literal's value, or a named constant's (``named``: name -> value), negated under ``-``."""
    if isinstance(e, ast.NumLit):
        return e.value
    if isinstance(e, ast.Var) and e.prefix is None and named and e.name in named:
        return named[e.name]
    if isinstance(e, ast.Unary) and e.op == "-":
        v = _num(e.operand, named)
        return None if v is None else -v
    return None


def _input(e: ast.Expr, node: CheckedNode) -> str | None:
    if isinstance(e, ast.Var) and e.prefix in (None, "in") and e.name in node.inputs:
        return e.name
    return None


def _abs_bound(out: dict[str, Bound], op: str, name: str | None, v: Fraction | None) -> None:
    """``abs(in.x) op v`` with ``op`` ``<`` or ``<=``: the bounds ``-v`` and ``v`` of ``x``."""
    if name is None or v is None or op not in ("<", "<="):
        return
    bd = out.setdefault(name, Bound())
    bd.lower(-v, op == "<")
    bd.upper(v, op == "<")


def conjuncts(e: ast.Expr) -> list[ast.Expr]:
    """Top-level ``and`` conjuncts of a formula."""
    if isinstance(e, ast.Binary) and e.op == "and":
        return conjuncts(e.left) + conjuncts(e.right)
    return [e]


def _converse(op: str) -> str:
    """The comparison ``op`` reads as with its operands swapped, from the semantics table."""
    return str(OPERATORS[op].converse)


def _compare_bounds(out: dict[str, Bound], c: ast.Compare, who: Callable[[ast.Expr], str | None],
                    named: Mapping[str, Fraction] | None) -> None:
    """The bounds ``c`` (a chain ``a op b op ...``) puts on the variables ``who`` names (``who``: an
    operand -> the input it bounds, else ``None``), against numeric literals and the constants of ``named``."""
    for cop, a, b in zip(c.ops, c.operands, c.operands[1:]):
        op: str = cop
        name, v = who(a), _num(b, named)
        if name is None:
            name, v, op = who(b), _num(a, named), _converse(cop)
        if name is None:  # abs(x) <= c: -c <= x <= c
            _abs_bound(out, cop, _abs_of(a, who), _num(b, named))
            _abs_bound(out, _converse(cop), _abs_of(b, who), _num(a, named))
        if name is None or v is None:
            continue
        bd = out.setdefault(name, Bound())
        if op in (">", ">=", "=="):
            bd.lower(v, op == ">")
        if op in ("<", "<=", "=="):
            bd.upper(v, op == "<")


def _abs_of(e: ast.Expr, who: Callable[[ast.Expr], str | None]) -> str | None:
    """The input ``who`` names in a term ``abs(x)``, else ``None``."""
    return who(e.operand) if isinstance(e, ast.Unary) and e.op == "abs" else None


def _member_bound(out: dict[str, Bound], c: ast.Member, name: str | None, t: Type | None) -> None:
    """``x in {v1, v2}`` of an enumeration ``x`` (of type ``t``): ``x``'s values narrowed to those named."""
    if name is not None and isinstance(t, EnumT) and not c.negated and isinstance(c.collection, ast.SetLit):
        vals = frozenset(i.name for i in c.collection.items if isinstance(i, ast.Var))
        bd = out.setdefault(name, Bound())
        bd.enum = vals if bd.enum is None else bd.enum & vals


def _seq_input(q: ast.Expr, node: CheckedNode) -> tuple[str, str, Type] | None:
    """``(input, bound name, item type)`` of a quantifier ``forall(x in in.s | ...)`` over one input
    sequence ``s`` of scalars or enumeration values, else ``None``."""
    if not isinstance(q, ast.Quant) or len(q.bindings) != 1 or len(q.bindings[0].names) != 1:
        return None
    dom = q.bindings[0].domain
    name = _input(dom, node) if isinstance(dom, ast.Var) else None
    t = node.inputs.get(name) if name is not None else None
    if name is None or not isinstance(t, SeqT) or not isinstance(t.elem, (Scalar, EnumT)):
        return None
    return name, q.bindings[0].names[0], t.elem


def _item_bounds(out: dict[str, Bound], q: ast.Quant, node: CheckedNode,
                 named: Mapping[str, Fraction] | None) -> None:
    """A top-level ``forall(x in in.s | body)``: the top-level conjuncts of ``body`` comparing ``x``
    with constants bound every item of ``s``; ``exists(x in in.s | ...)``: ``s`` has an item."""
    found = _seq_input(q, node)
    if found is None:
        return
    name, var, elem = found
    if q.kind != "forall":
        bd = out.setdefault(name, Bound())
        bd.min_len = max(bd.min_len, 1)
        return

    def who(e: ast.Expr) -> str | None:
        return name if isinstance(e, ast.Var) and e.prefix is None and e.name == var else None

    for c in conjuncts(q.body):
        if isinstance(c, ast.Compare):
            _compare_bounds(out, c, who, named)
        elif isinstance(c, ast.Member):
            _member_bound(out, c, who(c.elem), elem)


def assumption_bounds(node: CheckedNode, named: Mapping[str, Fraction] | None = None) -> dict[str, Bound]:
    """Bounds per input name found in the assumption's top-level conjuncts
    (against numeric literals, and against the context constants of
    ``named``, name -> value: ``in.x <= MaxRange``).  The bound of a
    sequence input is the bound of each of its items, from a top-level
    ``forall(q in in.s | lo <= q and q <= hi)``; a top-level
    ``exists(q in in.s | ...)`` gives it at least one item (:attr:`Bound.min_len`)."""
    out: dict[str, Bound] = {}

    def who(e: ast.Expr) -> str | None:
        return _input(e, node)

    for clause in node.node.assumes:
        for c in conjuncts(clause.formula):
            if isinstance(c, ast.Compare):
                _compare_bounds(out, c, who, named)
            elif isinstance(c, ast.Member):
                name = _input(c.elem, node)
                _member_bound(out, c, name, node.inputs[name] if name is not None else None)
            elif isinstance(c, ast.Quant):
                _item_bounds(out, c, node, named)
    return out


__all__ = ["Bound", "assumption_bounds", "conjuncts"]
