"""The visitor and transformer over the RCL syntax (rclverify.lang.visit): every
node class has a method name, an unknown value or an unhandled class is a
clear error, the generic traversal agrees with lang/walk.py, and a transformer
rebuilds exactly what changed."""
from __future__ import annotations

import dataclasses
from typing import Any

import pytest

from rclverify.lang import ast, exprs

from rclverify.lang import typeexpr
from rclverify.lang.parser import parse_text as parse
from rclverify.lang.printer import expr_to_rcl
from rclverify.lang.visit import (EXPR_CLASSES, METHOD_NAMES, NODE_CLASSES, MissingVisit, Transformer, UnknownNode,
                                  Visitor, children)
from rclverify.lang.walk import subexpressions

SPEC = """
context { Level : {low, high} ; Max = 250 ; F : REAL --> REAL ; }
node n {
  inputs(x : REAL, s : set(INTEGER), f : F)
  outputs(y : REAL, l : Level)
  topics()
  assume(in.x >= 0 and in.x in {1, 2, 3} and not (in.x < -1))
  guarantee(out.y == in.f(in.x) * 2 - 1 / 3 -> (out.l == high <=> out.y > Max))
  guarantee(forall (k in in.s, j in {1, 2} | k + j != 0) and exists ((a, b) in {(1, 2)} | a < b))
  guarantee(0 <= out.y <= 10 or [1, 2] == [1, 2] or <1 upto 3> == [1, 2, 3] or "a" == "a")
}
"""


@pytest.fixture(scope="module")
def formulas() -> list[ast.Expr]:
    spec = parse(SPEC, "visit.rcl")
    node = spec.nodes[0]
    return [c.formula for c in (*node.assumes, *node.guarantees)]


def test_every_node_class_has_a_method_name() -> None:
    defined = {c for m in (typeexpr, exprs, ast) for c in vars(m).values() if isinstance(c, type)
               and dataclasses.is_dataclass(c) and c.__module__ == m.__name__}
    assert ast.Loc not in defined and typeexpr.TBase in defined and ast.Spec in defined
    assert set(NODE_CLASSES) == defined
    assert set(METHOD_NAMES) == defined
    assert METHOD_NAMES[ast.Binary] == "visit_Binary"
    assert set(ast.Expr.__args__) == EXPR_CLASSES  # type: ignore[attr-defined]


def test_unknown_value_is_a_clear_error() -> None:
    class Names(Visitor[int]):
        def visit_Var(self, v: ast.Var) -> int:
            return 1

    with pytest.raises(UnknownNode, match="Names cannot visit a int"):
        Names().visit(3)
    with pytest.raises(UnknownNode):
        Visitor().visit("x")


def test_unhandled_class_is_an_error_not_a_default(formulas: list[ast.Expr]) -> None:
    class OnlyVars(Visitor[int]):
        def visit_Var(self, v: ast.Var) -> int:
            return 1

    with pytest.raises(MissingVisit, match=r"OnlyVars has no visit_Apply for Apply at visit.rcl:8:\d+"):
        OnlyVars().visit(formulas[1])


def test_generic_visit_follows_walk(formulas: list[ast.Expr]) -> None:
    class Count(Visitor[int]):
        def combine(self, node: Any, results: list[int]) -> int:
            return 1 + sum(results)

    class Order(Visitor[None]):
        def __init__(self) -> None:
            self.seen: list[Any] = []

        def visit(self, node: Any, *args: Any) -> None:
            self.seen.append(node)
            return super().visit(node, *args)

        def combine(self, node: Any, results: list[None]) -> None:
            return None

    for f in formulas:
        assert Count().visit(f) == sum(1 for _ in subexpressions(f))
        order = Order()
        order.visit(f)
        assert [id(n) for n in order.seen] == [id(n) for n in subexpressions(f)]


def test_children_of_non_expressions() -> None:
    spec = parse(SPEC, "visit.rcl")
    node = spec.nodes[0]
    kinds = {type(c) for c in children(node)}
    assert ast.IOVar in kinds and ast.Clause in kinds
    assert list(children(node.assumes[0])) == [node.assumes[0].formula]
    q = next(e for e in subexpressions(node.guarantees[1].formula) if isinstance(e, ast.Quant))
    assert [type(c) for c in children(q.bindings[1])] == [ast.SetLit]


def test_extra_arguments_pass_through(formulas: list[ast.Expr]) -> None:
    class Depth(Visitor[int]):
        def visit_Var(self, v: ast.Var, depth: int) -> int:
            return depth

        def combine(self, node: Any, results: list[int]) -> int:
            return max(results, default=0)

        def generic_visit(self, node: Any, depth: int) -> int:
            return self.combine(node, [self.visit(c, depth + 1) for c in children(node)])

    assert Depth().visit(formulas[0], 0) >= 3


def test_transformer_rebuilds_only_what_changed(formulas: list[ast.Expr]) -> None:
    class Identity(Transformer):
        pass

    class Rename(Transformer):
        def visit_Var(self, v: ast.Var) -> ast.Var:
            return dataclasses.replace(v, name="z") if v.name == "x" else v

    for f in formulas:
        assert Identity().visit(f) is f
    new = Rename().visit(formulas[0])
    assert new != formulas[0]
    assert expr_to_rcl(new) == expr_to_rcl(formulas[0]).replace("in.x", "in.z")
    untouched = Rename().visit(formulas[2])  # reads no in.x
    assert untouched is formulas[2]
    assert new.loc == formulas[0].loc


def test_transformer_reaches_bindings_and_types() -> None:
    class Widen(Transformer):
        def visit_TBase(self, t: typeexpr.TBase) -> typeexpr.TBase:
            return typeexpr.TBase("REAL", t.loc) if t.name == "INTEGER" else t

    spec = parse("node m { inputs(a : INTEGER) outputs(b : BOOL) topics() "
                 "guarantee(forall (k in INTEGER | k == k)) }", "m.rcl")
    out = Widen().visit(spec)
    assert out.nodes[0].inputs[0].type == typeexpr.TBase("REAL")
    q = out.nodes[0].guarantees[0].formula
    assert q.bindings[0].domain == typeexpr.TBase("REAL")
    assert spec.nodes[0].inputs[0].type == typeexpr.TBase("INTEGER")  # the input is unchanged
