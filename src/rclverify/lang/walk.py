"""Traversals of RCL expressions shared by every stage (lint, calculus, backends).

``children(e)``       the direct subexpressions of ``e``;
``subexpressions(e)`` ``e`` and everything inside it, pre-order;
``free_names(e)``     the unprefixed names occurring free in ``e``.

Quantifier domains that are terms (``x in {1, 2}``) are subexpressions;
domains that are types are not (see :func:`rclverify.lang.printer.is_type`).
"""
from __future__ import annotations

import dataclasses
from typing import Any, Callable, Iterable, Iterator, Union

from rclverify.lang import ast

from rclverify.lang import typeexpr
from rclverify.lang.printer import is_type


def _quant_children(e: ast.Quant) -> Iterator[ast.Expr]:
    for b in e.bindings:
        if not is_type(b.domain):
            yield b.domain  # type: ignore[misc]
    yield e.body


def _tuple_quant_children(e: ast.TupleQuant) -> Iterator[ast.Expr]:
    if not is_type(e.domain):
        yield e.domain  # type: ignore[misc]
    yield e.body


_NONE: tuple[ast.Expr, ...] = ()
#: expression class -> its direct subexpressions (one look-up per node, no chain of tests)
_CHILDREN: dict[type, Callable[[Any], Iterable[ast.Expr]]] = {
    ast.Var: lambda e: _NONE, ast.BoolLit: lambda e: _NONE, ast.NumLit: lambda e: _NONE,
    ast.StrLit: lambda e: _NONE,
    ast.Apply: lambda e: (e.func, *e.args), ast.Unary: lambda e: (e.operand,),
    ast.Binary: lambda e: (e.left, e.right), ast.Compare: lambda e: e.operands,
    ast.Member: lambda e: (e.elem, e.collection), ast.SetLit: lambda e: e.items,
    ast.SeqLit: lambda e: e.items, ast.TupleLit: lambda e: e.items, ast.Quant: _quant_children,
    ast.SeqRange: lambda e: (e.lo, e.hi), ast.TupleQuant: _tuple_quant_children,
    ast.First: lambda e: (e.arg,),
}


def children(e: ast.Expr) -> Iterator[ast.Expr]:
    """The direct subexpressions of ``e`` (an applied function's name included);
    none for a value that is not an expression."""
    of = _CHILDREN.get(type(e))
    if of is not None:
        yield from of(e)


def subexpressions(e: ast.Expr) -> Iterator[ast.Expr]:
    """``e`` and every expression inside it, pre-order (including quantifier
    domains that are terms and applied function names)."""
    stack: list[ast.Expr] = [e]
    while stack:
        cur = stack.pop()
        yield cur
        stack.extend(reversed(list(children(cur))))


def free_names(e: Union[ast.Expr, typeexpr.TypeExpr], *, heads: bool = True, type_names: bool = True) -> set[str]:
    """Unprefixed names occurring free in ``e`` (bound variables of inner
    quantifiers excluded, shadowing respected; each binding's domain sees the
    bindings before it).

    ``heads``       count the name of an applied function or constructor
                    (``at`` in ``at(x, y)``, ``move`` in ``move(x, y)``);
    ``type_names``  count a quantifier domain written as a name (``x in s``
                    may name an earlier bound variable or a set).
    """
    if isinstance(e, typeexpr.TName):
        return {e.name} if type_names else set()
    if is_type(e):
        return set()
    if isinstance(e, ast.Var):
        return {e.name} if e.prefix is None else set()
    if isinstance(e, ast.Apply) and not heads:
        out: set[str] = set()
        for a in e.args:
            out |= free_names(a, heads=heads, type_names=type_names)
        return out
    if isinstance(e, ast.Quant):
        free: set[str] = set()
        bound: set[str] = set()
        for b in e.bindings:
            free |= free_names(b.domain, heads=heads, type_names=type_names) - bound
            bound |= set(b.names)
        return free | (free_names(e.body, heads=heads, type_names=type_names) - bound)
    if isinstance(e, ast.TupleQuant):
        dom = free_names(e.domain, heads=heads, type_names=type_names)
        return dom | (free_names(e.body, heads=heads, type_names=type_names) - set(e.names))
    found: set[str] = set()
    for c in children(e):  # type: ignore[arg-type]
        found |= free_names(c, heads=heads, type_names=type_names)
    return found


def reads(e: Any, out: set[str]) -> None:
    """Every name a formula mentions: each :class:`ast.Var`'s qualified and bare
    name, anywhere in the tree (quantifier domains included); a superset of
    the I/O variables it reads."""
    if isinstance(e, ast.Var):
        out.add(e.qualified)
        out.add(e.name)
        return
    if isinstance(e, tuple):
        for x in e:
            reads(x, out)
        return
    if dataclasses.is_dataclass(e) and not isinstance(e, (type, ast.Loc)):
        for f in dataclasses.fields(e):
            reads(getattr(e, f.name), out)


def names(e: Any, out: set[str]) -> None:
    """Add to ``out`` the qualified name of every :class:`ast.Var` reachable through an
    expression's operands (quantifier domains and bodies included; binding names not)."""
    if isinstance(e, ast.Var):
        out.add(e.qualified)
    for name in ("args", "operand", "left", "right", "operands", "elem", "collection", "items", "body", "func",
                 "bindings", "domain"):
        c = getattr(e, name, None)
        if c is None:
            continue
        for x in (c if isinstance(c, tuple) else (c,)):
            names(x, out)
