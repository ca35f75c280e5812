"""The contract's decimal constants compared the way a field carries them.

RCL speaks of reals; a ROS field carries an IEEE 754 value of its IDL type's
width (rosidl's type mapping: ``float32`` is binary32, ``float64`` binary64).
A threshold written ``0.2`` cannot be carried by a ``float32`` field: the
field's nearest value is 0.20000000298023223876953125.  A node that compares
at the field's width (``percentage <= 0.2f`` in C++, or a Python node that
decides on the value it publishes before the wire narrows it) answers "at or
below" for the carried 0.2, which is above the decimal 0.2: judged against
the decimal, the correct ``<=`` reads as a violation and the ``<`` slip as
correct (an inverted verdict).

The rule (docs/semantics.md, "Widths"): a comparison is read at the width
of what it compares, as C++ computes ``float`` arithmetic with ``f``
literals and numpy computes on ``float32`` arrays: each side's width is that
of the widest input or output of known width it reads, through unary
``-``, ``abs`` and ``+ - * /`` (C++'s usual arithmetic conversions: a
``float32`` with a ``float64`` is at ``float64``), and every constant part
of either side (a numeric literal, a named constant of the context, an
expression of them such as ``0.1 + 0.1``) is replaced by its value at that
width: each literal rounded to the width's nearest value (IEEE 754
round-to-nearest, ties to even; binary32 has a 24-bit significand,
exponents from -126, subnormals down to 2**-149), each operation on them
rounded as an IEEE 754 operation of the width is.  So ``x <= 0.2``, ``x <=
LowCharge`` (``LowCharge = 0.2``), ``x - 0.2 <= 0``, ``-x >= -0.2`` and
``x <= 0.1 + 0.1`` compare ``x`` with the same carried 0.2, and ``abs(x) <=
0.2`` with it too.  Everything else keeps its meaning: the recorded value
is never moved, arithmetic on recorded values is not rounded, and the
exact, double and tolerance readings of :mod:`.floatsem` then all compare
against the carried constant, so a ``<``/``<=`` slip at the threshold is
found in each of them and in each of these forms.  A constant beyond the
width's largest finite value is left as written (the field cannot carry
it; the comparison is then decided as before).

Every other primitive keeps its width and kind (rosidl's type mapping; the
ranges of OMG IDL 4.2, table 7-13: :data:`INT_RANGES`): a constant compared
with an integer field keeps its exact value (every value of the field is an
integer, compared exactly); what a field carries (:class:`Carried`: the
primitive, a ``string<=N`` bound, a ``T[<=N]`` or ``T[N]`` sequence) bounds
what the property tests draw (:func:`int_edges`) and decides whether a
value can travel at all (:func:`carried_fault`: ``uint8 cannot carry 300``).
The numbers at a width are :mod:`rclverify.semantics.width_numbers`'s.
"""
from __future__ import annotations

import dataclasses
from fractions import Fraction
from typing import Any, Mapping

from rclverify.lang import ast
from rclverify.lang.types import Type
from rclverify.lang.visit import Transformer
from rclverify.semantics.operators import OPERATORS, UNARY, Undecided
from rclverify.semantics.width_numbers import (  # named here too: the rule and its numbers
    FLOAT_WIDTHS as FLOAT_WIDTHS,
    IDL_ALIASES as IDL_ALIASES,
    INT_RANGES as INT_RANGES,
    Carried as Carried,
    Width as Width,
    carried_fault as carried_fault,
    edges_at_width as edges_at_width,
    exact_decimal as exact_decimal,
    idl_name as idl_name,
    int_edges as int_edges,
    narrow as narrow,
    nearest_at_width as nearest_at_width,
    width_fault as width_fault,
)

def _literal(v: Fraction, like: ast.Expr) -> ast.Expr:
    """``v`` (a dyadic rational: finitely many decimal digits) as a literal where ``like`` stood,
    its digits exact (:func:`exact_decimal`)."""
    text = exact_decimal(v)
    loc: ast.Loc = like.loc
    if v < 0:
        return ast.Unary("-", ast.NumLit(text.lstrip("-"), loc), loc)
    return ast.NumLit(text, loc)


#: the floating widths from narrowest to widest: an operation on two widths is at the wider (C++'s usual
#: arithmetic conversions, numpy's type promotion)
_WIDER = {"float32": 0, "float64": 1}


def at_widths(e: ast.Expr, widths: Mapping[str, str],
              constants: Mapping[str, tuple[Type, ast.Expr]] | None = None) -> ast.Expr:
    """``e`` with every constant read at the width of what it is combined
    with (module docstring, and docs/semantics.md, "Widths"): in a
    comparison, each side's width is that of the widest input or output of
    known width it reads (``widths``: ``"in.x"``/``"out.y"`` -> ``float32``
    or ``float64``; for a sequence, its items' width, which a variable bound
    by ``r in in.xs`` carries) through ``-``, ``abs``, ``+ - * /``; a pair
    of sides with a width has every constant part on either side (a
    literal, a named constant of ``constants``, the context's definitions
    ``name -> (type, defining expression)``, or an expression of them,
    ``0.1 + 0.1``) replaced by its value at that width: each literal rounded
    to the width (IEEE 754 round to nearest, ties to even), each operation
    on them rounded as an IEEE 754 operation of that width is.  So ``x <=
    0.2``, ``x <= LowCharge``, ``x - 0.2 <= 0``, ``-x >= -0.2``, ``x <= 0.1
    + 0.1`` and, for ``x >= 0``, ``abs(x) <= 0.2`` compare ``x`` with the
    same carried value.  ``e`` itself when nothing changes."""
    if not widths:
        return e
    out: ast.Expr = _AtWidths(constants or {}).visit(e, _Scope(widths, frozenset()))
    return out


@dataclasses.dataclass(frozen=True)
class _Scope:
    """What :class:`_AtWidths` reads at a point of the formula: the widths of
    the names visible there and the bound names (which hide a constant's)."""

    widths: Mapping[str, str]
    bound: frozenset[str]


class _AtWidths(Transformer):
    """:func:`at_widths` as a :class:`~rclverify.lang.visit.Transformer`: comparisons and binders
    are its own; every other node is rebuilt only where something below it changed."""

    def __init__(self, constants: Mapping[str, tuple[Type, ast.Expr]]) -> None:
        self.constants = constants

    def visit_Quant(self, e: ast.Quant, sc: _Scope) -> ast.Expr:
        inner = dict(sc.widths)  # `r in in.ranges`: r carries the sequence's item width; another binder shadows
        for b in e.bindings:
            d = b.domain
            w = sc.widths.get(d.qualified) if isinstance(d, ast.Var) and d.prefix else None
            for n in b.names:
                if w is not None:
                    inner[n] = w
                else:
                    inner.pop(n, None)
        body = self.visit(e.body, _Scope(inner, sc.bound | frozenset(e.variables)))
        return dataclasses.replace(e, body=body) if body is not e.body else e

    def visit_TupleQuant(self, e: ast.TupleQuant, sc: _Scope) -> ast.Expr:
        inner = {k: v for k, v in sc.widths.items() if k not in e.names}
        body = self.visit(e.body, _Scope(inner, sc.bound | frozenset(e.names)))
        return dataclasses.replace(e, body=body) if body is not e.body else e

    def width(self, e: ast.Expr, sc: _Scope) -> str | None:
        """The floating width ``e`` is computed at: its widest input or output of known width."""
        if isinstance(e, ast.Var):
            w = sc.widths.get(e.qualified)
            return w if w in FLOAT_WIDTHS else None
        if isinstance(e, ast.Unary) and e.op != "not":
            return self.width(e.operand, sc)
        if isinstance(e, ast.Binary) and OPERATORS[e.op].kind == "arithmetic":
            found = [w for w in (self.width(e.left, sc), self.width(e.right, sc)) if w is not None]
            return max(found, key=_WIDER.__getitem__) if found else None
        return None

    def value(self, e: ast.Expr, width: str | None, bound: frozenset[str], seen: tuple[str, ...] = ()
              ) -> Fraction | None:
        """The value of ``e`` if it is a constant expression: exact (``width``
        ``None``) or at ``width`` (every literal and every operation rounded to
        it); ``None`` when ``e`` reads a variable, a value is beyond the
        width's range or a division is by zero."""
        v: Any
        if isinstance(e, ast.NumLit):
            v = e.value
        elif isinstance(e, ast.Var) and e.prefix is None and e.name in self.constants and e.name not in bound \
                and e.name not in seen:
            return self.value(self.constants[e.name][1], width, frozenset(), (*seen, e.name))
        elif isinstance(e, ast.Unary) and e.op != "not":
            x = self.value(e.operand, width, bound, seen)
            if x is None or e.op == "-" or e.op == "abs":
                return None if x is None else Fraction(UNARY[e.op].exact(x))  # exact at every width
            try:  # sqrt, sin, cos: rounded to the width below
                v = Fraction(UNARY[e.op].exact(x))
            except Undecided:
                return None
        elif isinstance(e, ast.Binary) and OPERATORS[e.op].kind == "arithmetic":
            x, y = self.value(e.left, width, bound, seen), self.value(e.right, width, bound, seen)
            if x is None or y is None:
                return None
            try:
                v = Fraction(OPERATORS[e.op].exact(x, y))
            except Undecided:
                return None
        else:
            return None
        return Fraction(v) if width is None else nearest_at_width(Fraction(v), width)

    def at(self, e: ast.Expr, width: str, sc: _Scope) -> ast.Expr:
        """``e`` (a side of a comparison at ``width``) with its constant parts at ``width``."""
        v = self.value(e, width, sc.bound)
        if v is not None:
            return e if v == self.value(e, None, sc.bound) else _literal(v, e)
        if isinstance(e, ast.Binary) and OPERATORS[e.op].kind == "arithmetic":
            left, right = self.at(e.left, width, sc), self.at(e.right, width, sc)
            return e if (left is e.left and right is e.right) else dataclasses.replace(e, left=left, right=right)
        if isinstance(e, ast.Unary) and e.op != "not":
            operand = self.at(e.operand, width, sc)
            return e if operand is e.operand else dataclasses.replace(e, operand=operand)
        return e

    def visit_Compare(self, e: ast.Compare, sc: _Scope) -> ast.Expr:
        ops = [self.visit(o, sc) for o in e.operands]
        for i in range(len(ops) - 1):
            found = [w for w in (self.width(e.operands[i], sc), self.width(e.operands[i + 1], sc)) if w is not None]
            if found:
                w = max(found, key=_WIDER.__getitem__)
                ops[i], ops[i + 1] = self.at(ops[i], w, sc), self.at(ops[i + 1], w, sc)
        return dataclasses.replace(e, operands=tuple(ops)) if any(a is not b for a, b in zip(ops, e.operands)) else e


__all__ = ["FLOAT_WIDTHS", "IDL_ALIASES", "INT_RANGES", "Carried", "Width", "at_widths", "carried_fault",
           "edges_at_width", "exact_decimal", "idl_name", "int_edges", "narrow", "nearest_at_width", "width_fault"]
