"""The direct evaluator's context (:class:`Evaluator`): one node, its
values, name resolution, expressions (compiled closures, or the tree walk
they follow) and the semantics of numbers (exact here; the float-faithful
semantics of recorded runs, :mod:`rclverify.semantics.floatsem`, override
:meth:`Evaluator.literal`, :meth:`Evaluator.arith` and
:meth:`Evaluator.compare`).  Quantifiers are
:class:`rclverify.semantics.eval_quant.QuantifierEvaluation`'s.

Part of the direct evaluator (:mod:`rclverify.semantics.evaluate`, whose module
docstring states the semantics).
"""
from __future__ import annotations

from typing import Any, Mapping

from rclverify.lang import ast
from rclverify.lang import types as T
from rclverify.lang.types import Checked, CheckedNode
from rclverify.lang.visit import Visitor
from rclverify.semantics.values import Term, Value, conforms
from rclverify.semantics.eval_closures import COMPILED_SIZE, _COMPILED, _compile
from rclverify.semantics.eval_quant import QuantifierEvaluation
from rclverify.semantics.eval_values import _CMP, _LIT, Undecided, _numbers, arithmetic
from rclverify.semantics.operators import OPERATORS, UNARY


class Evaluator(QuantifierEvaluation, Visitor[Any]):
    """One evaluation context: the node, its values and the candidate numbers.

    ``compiled`` (class attribute, True): evaluate through the compiled
    closures; False walks the tree (:meth:`interpret`) everywhere, the
    reference the tests compare the closures with."""

    compiled = True
    #: ``None``: exact arithmetic (the compiled closures of this class); a
    #: subclass with other number semantics names them here (its expressions
    #: are compiled apart, calling :meth:`literal`, :meth:`arith` and
    #: :meth:`compare`)
    mode: str | None = None

    def __init__(self, checked: Checked, node: CheckedNode, values: Mapping[str, object]) -> None:
        self.env = checked.env
        self.node = node
        self.values = values
        self._numbers: set[Any] | None = None
        self._slots: dict[int, tuple[list[tuple[str, ...]], list[list[tuple[Any, ...]]]]] = {}
        self.uncacheable = False  # set when a quantifier's candidates depend on outer bound values
        self.io_names = frozenset(node.inputs) | frozenset(node.outputs)

    def numbers(self) -> set[Any]:
        if self._numbers is None:
            found: set[Any] = set()
            for v in self.values.values():
                _numbers(v, found)
            self._numbers = found
        return self._numbers

    # -- names ---------------------------------------------------------------
    def io(self, v: ast.Var) -> Any:
        if v.prefix is not None:
            key = v.qualified
        elif v.name in self.node.inputs:
            key = "in." + v.name
        else:
            key = "out." + v.name
        value = self.values.get(key)
        if value is None:  # absent, or not observed yet: nothing to evaluate on
            raise Undecided(f"no value for {key}")
        return value

    def var(self, v: ast.Var, bound: Mapping[str, Value]) -> Any:
        if v.prefix is None and v.name in bound:
            return bound[v.name]
        if v.prefix is None and v.name in self.env.enum_values:
            return v.name
        if v.prefix is None and v.name in self.env.constants:
            return self.eval(self.env.constants[v.name][1], {})
        if v.prefix is None and v.name in self.env.ctors:
            return Term(v.name, ())
        return self.io(v)

    # -- expressions -----------------------------------------------------------
    def eval(self, e: ast.Expr, b: Mapping[str, Value]) -> Any:
        """The value of ``e`` under bound variables ``b``: the expression is
        compiled once (per AST node and I/O node) into nested closures that
        do what :meth:`interpret` does, node for node (:func:`_compile`)."""
        if not self.compiled:
            return self.interpret(e, b)
        mode = self.mode
        key: tuple[Any, ...] = (id(e), id(self.node), id(self.env)) if mode is None else \
            (id(e), id(self.node), id(self.env), mode)
        hit = _COMPILED.get(key)
        if hit is None or hit[0] is not e or hit[1] is not self.node or hit[2] is not self.env:
            if len(_COMPILED) >= COMPILED_SIZE:
                _COMPILED.clear()
            hit = _COMPILED[key] = (e, self.node, self.env, _compile(e, self.env, self.node, mode))
        return hit[3](self, b)

    def interpret(self, e: ast.Expr, b: Mapping[str, Value]) -> Any:
        """The value of ``e`` under ``b`` by walking the tree (the reference the
        compiled closures follow; what they delegate membership, set and
        tuple literals and quantifiers to): the method ``visit_<Class>`` of
        ``e``'s class (:class:`rclverify.lang.visit.Visitor`; its table read
        here directly, one call less per node)."""
        method = self._dispatch.get(type(e))
        if method is None:
            return self.visit(e, b)  # not a node: the visitor's error
        return method(self, e, b)

    def generic_visit(self, e: Any, b: Mapping[str, Value]) -> Any:
        raise Undecided(f"cannot evaluate {type(e).__name__}")

    def visit_BoolLit(self, e: ast.BoolLit, b: Mapping[str, Value]) -> Any:
        return e.value

    def visit_NumLit(self, e: ast.NumLit, b: Mapping[str, Value]) -> Any:
        return self.literal(e)

    def visit_Var(self, e: ast.Var, b: Mapping[str, Value]) -> Any:
        return self.var(e, b)

    def visit_Apply(self, e: ast.Apply, b: Mapping[str, Value]) -> Any:
        args = tuple(self.eval(a, b) for a in e.args)
        if e.func.prefix is None and e.func.name in self.env.ctors and e.func.name not in b:
            return Term(e.func.name, args)
        f = self.var(e.func, b)
        if not callable(f):
            raise Undecided(f"{e.func.qualified} is not a function value")
        return f(*args)

    def visit_First(self, e: ast.First, b: Mapping[str, Value]) -> Any:
        """``first(in.x)``: the Boolean given as ``first(in.x)`` (the monitors: whether this message is the
        first the run published on that input; docs/semantics.md, "The first published value"); without
        one, :class:`Undecided`."""
        key = f"first(in.{e.arg.name})"
        value = self.values.get(key)
        if isinstance(value, str):  # why it is not known (backends/monitors/first_messages.py)
            raise Undecided(value)
        if not isinstance(value, bool):
            raise Undecided(f"no record of whether this message is the first published on "
                            f"{e.arg.name if '.in.' in e.arg.name else 'in.' + e.arg.name}")
        return value

    def visit_Unary(self, e: ast.Unary, b: Mapping[str, Value]) -> Any:
        return UNARY[e.op].exact(self.eval(e.operand, b))

    def visit_Binary(self, e: ast.Binary, b: Mapping[str, Value]) -> Any:
        return self.binary(e, b)

    def visit_Compare(self, e: ast.Compare, b: Mapping[str, Value]) -> Any:
        vals = [self.eval(o, b) for o in e.operands]
        return all(self.compare(e, b, op, x, y) for op, x, y in zip(e.ops, vals, vals[1:]))

    def visit_Member(self, e: ast.Member, b: Mapping[str, Value]) -> Any:
        x = self.eval(e.elem, b)
        carrier = self.carrier(e.collection, b)
        if carrier is not None:  # `x in NATURAL`, `(x, y) in REAL.REAL`
            inside = conforms(x, carrier) is None
            return (not inside) if e.negated else inside
        coll = self.collection(e.collection, b)
        return (x not in coll) if e.negated else (x in coll)

    def visit_SetLit(self, e: ast.SetLit, b: Mapping[str, Value]) -> Any:
        return frozenset(self.eval(i, b) for i in e.items)

    def visit_TupleLit(self, e: ast.TupleLit, b: Mapping[str, Value]) -> Any:
        return tuple(self.eval(i, b) for i in e.items)

    visit_SeqLit = visit_TupleLit

    def visit_SeqRange(self, e: ast.SeqRange, b: Mapping[str, Value]) -> Any:
        """``<lo upto hi>``: the integers from ``lo`` to ``hi`` in order (empty when ``hi < lo``)."""
        lo, hi = self.eval(e.lo, b), self.eval(e.hi, b)
        if type(lo) is not int or type(hi) is not int:
            raise Undecided(f"<{lo} upto {hi}>: bounds that are not integers")
        return tuple(range(lo, hi + 1))

    def visit_Quant(self, e: ast.Quant, b: Mapping[str, Value]) -> Any:
        return self.quant(e, b)

    def carrier(self, e: Any, b: Mapping[str, Value]) -> T.Type | None:
        """The type a built-in term on the right of ``in`` stands for
        (``NATURAL``, or the product ``REAL.REAL``), else ``None``."""
        if not isinstance(e, ast.Var) or e.prefix is not None or e.name in b:
            return None
        if e.name in T.BASE_NAMES:
            return T.Scalar(e.name)
        return T.qualified_base(e.name)

    def collection(self, e: Any, b: Mapping[str, Value]) -> Any:
        if isinstance(e, ast.SetLit):
            return {self.eval(i, b) for i in e.items}
        v = self.eval(e, b)
        if isinstance(v, (frozenset, tuple, set)):
            return v
        raise Undecided("membership in a value that is not a set")

    def binary(self, e: ast.Binary, b: Mapping[str, Value]) -> Any:
        """A connective (short-circuit left to right) or arithmetic (:meth:`arith`),
        as the operator's entry in the semantics table states it."""
        entry = OPERATORS[e.op]
        if entry.kind == "connective":
            left = bool(self.eval(e.left, b))
            if left is entry.decisive:
                return entry.decided
            return entry.exact(left, bool(self.eval(e.right, b)))
        return self.arith(e.op, self.eval(e.left, b), self.eval(e.right, b))

    # -- the semantics of numbers: exact here (REAL as rationals); the
    # float-faithful semantics of recorded runs (semantics/floatsem.py) override
    # these three and set ``mode``, under which expressions are compiled apart
    def literal(self, e: ast.NumLit) -> Any:
        """The value of a numeric literal: its exact rational (an ``int`` when whole)."""
        lit = _LIT.get(e.text)
        if lit is None:
            v = e.value
            lit = _LIT[e.text] = int(v) if v.denominator == 1 else v
        return lit

    def arith(self, op: str, x: Any, y: Any) -> Any:
        """``x op y`` (:func:`arithmetic`: exact)."""
        return arithmetic(op, x, y)

    def compare(self, e: ast.Compare, b: Mapping[str, Value], op: str, x: Any, y: Any) -> bool:
        """One comparison ``x op y`` of ``e`` under bound variables ``b`` (exact)."""
        return _CMP[op](x, y)
