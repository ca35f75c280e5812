"""Expressions of direct evaluation compiled once into nested closures
(per AST node, I/O node and number semantics) that do what
:meth:`rclverify.semantics.evaluator.Evaluator.interpret` does, node for node:
the tree walk and the name resolution that does not depend on bound
variables done once, membership, set and tuple literals and quantifiers
handed back to the evaluator.

Part of the direct evaluator (:mod:`rclverify.semantics.evaluate`, whose module
docstring states the semantics).
"""
from __future__ import annotations

from typing import Any, Callable, Mapping

from rclverify.lang import ast
from rclverify.lang.types import CheckedNode
from rclverify.lang.visit import Visitor
from rclverify.semantics.values import Term, Value
from rclverify.semantics.eval_values import _CMP, _LIT, Undecided
from rclverify.semantics.operators import OPERATORS, UNARY, Operator


#: Compiled expressions kept (per AST node and I/O node); cleared when full.
COMPILED_SIZE = 10_000
_Fn = Callable[[Any, Mapping[str, Value]], Any]  # (the evaluator, bound variables) -> value
_COMPILED: dict[tuple[int, int, int], tuple[Any, Any, Any, _Fn]] = {}


def _compile(e: Any, env: Any, node: CheckedNode, mode: str | None = None) -> _Fn:
    """``e`` as a closure ``fn(evaluator, bound) -> value`` doing exactly what
    :meth:`Evaluator.interpret` does for it (same order of evaluation, same
    values, same exceptions), with the tree walk and the name resolution
    that does not depend on the bound variables done once.  Membership,
    set/tuple literals and quantifiers are handed to the evaluator.  With a
    ``mode`` (an evaluator of other number semantics) literals, arithmetic
    and comparisons call the evaluator's :meth:`~Evaluator.literal`,
    :meth:`~Evaluator.arith` and :meth:`~Evaluator.compare`."""
    return _Compiler(env, node, mode).visit(e)


class _Compiler(Visitor[_Fn]):
    """:func:`_compile`, one method per node class (:mod:`rclverify.lang.visit`);
    a class without one is handed to the evaluator's tree walk."""

    def __init__(self, env: Any, node: CheckedNode, mode: str | None) -> None:
        self.env, self.node, self.mode = env, node, mode

    def generic_visit(self, e: Any) -> _Fn:
        return lambda ev, b: ev.interpret(e, b)

    def visit_Var(self, e: ast.Var) -> _Fn:
        return _compile_var(e, self.env, self.node, self.mode)

    def visit_NumLit(self, e: ast.NumLit) -> _Fn:
        if self.mode is not None:
            return lambda ev, b: ev.literal(e)
        lit = _LIT.get(e.text)
        if lit is None:
            v = e.value
            lit = _LIT[e.text] = int(v) if v.denominator == 1 else v
        value = lit
        return lambda ev, b: value

    def visit_BoolLit(self, e: ast.BoolLit) -> _Fn:
        truth = e.value
        return lambda ev, b: truth

    def visit_Apply(self, e: ast.Apply) -> _Fn:
        args = tuple(self.visit(a) for a in e.args)
        func = e.func
        fname, qualified = func.name, func.qualified
        ctor = func.prefix is None and fname in self.env.ctors
        fvar = _compile_var(func, self.env, self.node, self.mode)

        def apply(ev: Any, b: Mapping[str, Value]) -> Any:
            vals = tuple([a(ev, b) for a in args])
            if ctor and fname not in b:
                return Term(fname, vals)
            f = fvar(ev, b)
            if not callable(f):
                raise Undecided(f"{qualified} is not a function value")
            return f(*vals)
        return apply

    def visit_Unary(self, e: ast.Unary) -> _Fn:
        operand = self.visit(e.operand)
        meaning = UNARY[e.op].exact
        return lambda ev, b: meaning(operand(ev, b))

    def visit_Binary(self, e: ast.Binary) -> _Fn:
        return _compile_binary(e, self.env, self.node, self.mode)

    def visit_Compare(self, e: ast.Compare) -> _Fn:
        if self.mode is not None:
            parts = tuple(self.visit(o) for o in e.operands)
            ops = e.ops

            def compare_in_mode(ev: Any, b: Mapping[str, Value]) -> Any:
                vals = [o(ev, b) for o in parts]
                return all(ev.compare(e, b, op, x, y) for op, x, y in zip(ops, vals, vals[1:]))
            return compare_in_mode
        operands = tuple(self.visit(o) for o in e.operands)
        cmps = tuple(_CMP[op] for op in e.ops)
        if len(cmps) == 1:
            first, second = operands
            cmp = cmps[0]
            return lambda ev, b: bool(cmp(first(ev, b), second(ev, b)))  # all() of one comparison

        def compare(ev: Any, b: Mapping[str, Value]) -> Any:
            vals = [o(ev, b) for o in operands]
            return all(c(x, y) for c, x, y in zip(cmps, vals, vals[1:]))
        return compare


def _compile_var(v: ast.Var, env: Any, node: CheckedNode, mode: str | None = None) -> _Fn:
    """:meth:`Evaluator.var` for ``v``: a bound variable first, then (fixed by
    the context) an enumeration value, a constant, a constructor, else the
    I/O value (:meth:`Evaluator.io`)."""
    if v.prefix is not None:
        key = v.qualified
    else:
        key = ("in." + v.name) if v.name in node.inputs else ("out." + v.name)

    def io(ev: Any, b: Mapping[str, Value]) -> Any:
        value = ev.values.get(key)
        if value is None:
            raise Undecided(f"no value for {key}")
        return value
    if v.prefix is not None:
        return io
    name = v.name
    if name in env.enum_values:
        return lambda ev, b: b.get(name, name)
    if name in env.constants:
        const = _compile(env.constants[name][1], env, node, mode)
        return lambda ev, b: b[name] if name in b else const(ev, {})
    if name in env.ctors:
        return lambda ev, b: b[name] if name in b else Term(name, ())
    return lambda ev, b: b[name] if name in b else io(ev, b)


def _compile_binary(e: ast.Binary, env: Any, node: CheckedNode, mode: str | None = None) -> _Fn:
    """:meth:`Evaluator.binary` for ``e``."""
    op = e.op
    left, right = _compile(e.left, env, node, mode), _compile(e.right, env, node, mode)
    entry = OPERATORS[op]
    if entry.kind == "connective":
        return _connective(entry, left, right)
    if mode is not None:
        return lambda ev, b: ev.arith(op, left(ev, b), right(ev, b))
    meaning = entry.exact
    return lambda ev, b: meaning(left(ev, b), right(ev, b))


def _connective(entry: Operator, left: _Fn, right: _Fn) -> _Fn:
    """A connective's closure from its entry in the semantics table: the left
    operand's truth first; when it is the entry's ``decisive`` truth, its
    ``decided`` value, else the truth table on both (which, for a connective
    that short-circuits, is the right operand's truth: then taken as is)."""
    truth, decisive, decided = entry.exact, entry.decisive, entry.decided
    if decisive is None:
        return lambda ev, b: truth(bool(left(ev, b)), bool(right(ev, b)))
    other = not decisive
    if not (truth(other, True) is True and truth(other, False) is False):
        return lambda ev, b: decided if bool(left(ev, b)) is decisive else truth(other, bool(right(ev, b)))
    # the right operand's truth when the left one does not decide: Python's own
    # short circuit for the three (decisive, decided) pairs, the same values
    if decisive is False and decided is False:  # and
        return lambda ev, b: bool(left(ev, b)) and bool(right(ev, b))
    if decisive is True and decided is True:  # or
        return lambda ev, b: bool(left(ev, b)) or bool(right(ev, b))
    if decisive is False and decided is True:  # ->
        return lambda ev, b: (not left(ev, b)) or bool(right(ev, b))
    return lambda ev, b: decided if bool(left(ev, b)) is decisive else bool(right(ev, b))
