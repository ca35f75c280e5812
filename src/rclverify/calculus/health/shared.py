"""One encoding of a node's formulas for all its health checks.

The consistency and vacuity checks (:mod:`.checks`) and the shape checks
(:mod:`.shape`) each keep an encoder of their own: its symbol table
decides their typing axioms and the symbols a model shows.  Each encoded
the node's assumption and guarantees again (with
realizability's, a fifth of a small node's health stage; realizability
keeps encoding on its own, see :func:`.checks.check_node`'s comment).
:class:`SharedEncoder` keeps that
separation and shares the work: a formula encoded once (the same RCL
expression of the same node, with no substituted symbols and no bound
variables) is handed to the next encoder as the same Z3 term, and the
symbols its encoding registered are registered in that encoder too, in the
order the encoding would have registered them, so its symbol table, hence
its axioms and models, is what encoding the formula again would make.
"""
from __future__ import annotations

from typing import Any, Mapping

import z3

from rclverify.lang import ast
from rclverify.lang.types import CheckedNode, Env
from rclverify.semantics.encode import Encoder
from rclverify.semantics.symbols import Symbol

#: ``(id of the RCL expression, node) -> (the expression, its Z3 formula, the symbols its encoding touched,
#: in order)``; the expression is kept so that its id names it while the table lives.
Table = dict[tuple[int, str], tuple[ast.Expr, z3.BoolRef, list[tuple[str, Symbol]]]]


class SharedEncoder(Encoder):
    """An :class:`~rclverify.semantics.encode.Encoder` whose plain formulas
    (:meth:`formula` without ``symbols`` or ``bound``) come from ``table``,
    shared by the encoders of one node's health checks (module docstring)."""

    def __init__(self, env: Env, table: Table) -> None:
        super().__init__(env)
        self.table = table
        self._touched: list[str] | None = None

    def io_symbol(self, node: CheckedNode, prefix: str, var: str) -> Any:
        """:meth:`Encoder.io_symbol`, the name noted while a formula is encoded."""
        if self._touched is not None:
            self._touched.append(self.symbol_name(node.name, prefix, var))
        return super().io_symbol(node, prefix, var)

    def formula(self, e: ast.Expr, node: CheckedNode, symbols: Mapping[str, z3.AstRef] | None = None,
                bound: Mapping[str, z3.ExprRef] | None = None) -> z3.BoolRef:
        """:meth:`Encoder.formula`, from the table when ``e`` was encoded
        before for ``node`` (its symbols registered here as encoding it would)."""
        if symbols or bound:
            return super().formula(e, node, symbols, bound)
        hit = self.table.get((id(e), node.name))
        if hit is None:
            outer, self._touched = self._touched, []
            try:
                f = super().formula(e, node)
                touched = self._touched
            finally:
                self._touched = outer
            hit = self.table[(id(e), node.name)] = (e, f, [(n, self.symbols[n]) for n in touched])
        else:
            for name, sym in hit[2]:
                self.symbols.setdefault(name, sym)
        if self._touched is not None:
            self._touched += [n for n, _ in hit[2]]
        return hit[1]


__all__ = ["SharedEncoder", "Table"]
