"""Which formulas the float semantics of recorded runs can change.

:func:`rclverify.semantics.floatsem.judge` evaluates a formula again in the
node's double arithmetic (or within a tolerance) only when that could give
another truth value than exact arithmetic: :func:`float_sensitive`, a
static analysis of the formula (and of the named constants it reads) over
the declared types of its I/O variables and bound variables.  Integer
arithmetic is exact in both; a literal that is a double (``0.5``, ``3``)
reads the same in both; anything whose type is not known to be integral
counts as possibly fractional (a conservative answer: at worst the formula
is evaluated again for nothing).
"""
from __future__ import annotations

from fractions import Fraction
from typing import Any, Mapping

from rclverify.lang import ast

from rclverify.lang import typeexpr
from rclverify.lang import types as T
from rclverify.lang.types import Checked, CheckedNode
from rclverify.lang.visit import Visitor, children
from rclverify.semantics.operators import OPERATORS

_SENSITIVE: dict[tuple[int, int, bool], tuple[Any, bool]] = {}


def float_sensitive(formula: ast.Expr, checked: Checked, node: CheckedNode, tolerant: bool = False) -> bool:
    """Could ``formula`` have another truth value in double arithmetic than
    in exact arithmetic (``tolerant``: or within a tolerance)?  True when it
    has an arithmetic operation that may round (``/``, or ``+ - *`` with an
    operand that may be a non-integer), a literal that is no double
    (``0.1``), or, ``tolerant``, a comparison of possibly non-integer numbers;
    the constants it names count too.  Memoised per formula object."""
    key = (id(formula), id(node), tolerant)
    hit = _SENSITIVE.get(key)
    if hit is not None and hit[0] is formula:
        return hit[1]
    out = _Sensitive(checked.env, node, tolerant).visit(formula, {})
    if len(_SENSITIVE) >= 10_000:
        _SENSITIVE.clear()
    _SENSITIVE[key] = (formula, out)
    return out


class _Sensitive(Visitor[bool]):
    """:func:`float_sensitive` node by node: a literal that is no double, an
    arithmetic operation that may round, a tolerant comparison of possibly
    non-integer numbers, a named constant's expression (once); any other
    node is sensitive when one of its children is."""

    def __init__(self, env: Any, node: CheckedNode, tolerant: bool) -> None:
        self.env, self.node, self.tolerant = env, node, tolerant
        self.seen: set[str] = set()

    def generic_visit(self, e: Any, scope: Mapping[str, typeexpr.TypeExpr | ast.Expr]) -> bool:
        return any(self.visit(c, scope) for c in children(e))

    def visit_NumLit(self, e: ast.NumLit, scope: Mapping[str, typeexpr.TypeExpr | ast.Expr]) -> bool:
        v = e.value
        return v.denominator != 1 and Fraction(float(v)) != v

    def visit_Var(self, e: ast.Var, scope: Mapping[str, typeexpr.TypeExpr | ast.Expr]) -> bool:
        env = self.env
        if e.prefix is None and e.name not in scope and e.name in env.constants and e.name not in self.seen:
            self.seen.add(e.name)
            return self.visit(env.constants[e.name][1], {})
        return False

    def visit_Binary(self, e: ast.Binary, scope: Mapping[str, typeexpr.TypeExpr | ast.Expr]) -> bool:
        if OPERATORS[e.op].kind == "arithmetic" and (
                e.op == "/" or _fractional(e.left, self.env, self.node, scope)
                or _fractional(e.right, self.env, self.node, scope)):
            return True
        return self.generic_visit(e, scope)

    def visit_Compare(self, e: ast.Compare, scope: Mapping[str, typeexpr.TypeExpr | ast.Expr]) -> bool:
        if self.tolerant and any(_fractional(o, self.env, self.node, scope) for o in e.operands):
            return True
        return self.generic_visit(e, scope)

    def visit_Quant(self, e: ast.Quant, scope: Mapping[str, typeexpr.TypeExpr | ast.Expr]) -> bool:
        inner = dict(scope)
        for bd in e.bindings:
            if not isinstance(bd.domain, (typeexpr.TBase, typeexpr.TName, typeexpr.TEnum)) and self.visit(bd.domain, scope):
                return True
            for n in bd.names:
                inner[n] = bd.domain
        return self.visit(e.body, inner)


def _integral_type(t: Any) -> bool:
    return isinstance(t, T.Scalar) and t.name in ("INTEGER", "NATURAL")


def _fractional(e: Any, env: Any, node: CheckedNode, scope: Mapping[str, typeexpr.TypeExpr | ast.Expr]) -> bool:
    """May ``e``'s value be a non-integer number?  (False only when its type
    is INTEGER/NATURAL or it is an integer literal; unknown is True.)"""
    if isinstance(e, ast.NumLit):
        return e.value.denominator != 1
    if isinstance(e, ast.Unary) and e.op == "-":
        return _fractional(e.operand, env, node, scope)
    if isinstance(e, ast.Binary) and e.op in ("+", "-", "*"):
        return _fractional(e.left, env, node, scope) or _fractional(e.right, env, node, scope)
    if isinstance(e, ast.Var):
        if e.prefix is None and e.name in scope:
            dom = scope[e.name]
            if isinstance(dom, typeexpr.TBase):
                return dom.name not in ("INTEGER", "NATURAL")
            if isinstance(dom, typeexpr.TName):
                return not _integral_type(env.types.get(dom.name))
            return True
        if e.prefix is None and e.name in env.constants:
            return not _integral_type(env.constants[e.name][0])
        return not _integral_type(node.io_type(e))
    if isinstance(e, ast.Apply):
        f = node.io_type(e.func) if (e.func.prefix is not None or e.func.name not in scope) else None
        return not (isinstance(f, T.FuncT) and _integral_type(f.result))
    return True


__all__ = ["float_sensitive"]
