"""The type expressions of RCL's grammar (``rcl.lark``, the paper's EBNF table:
base, named, empty, constructor, function, set, sequence and tuple types)
made into :mod:`rclverify.lang.typeexpr` values: the lark callbacks of
:class:`~rclverify.lang.builder.ToAst` for types, as a mixin."""
from __future__ import annotations

from typing import Any, Callable

from lark import Token

from rclverify.lang import ast, typeexpr
from rclverify.lang.lark_children import _vals


class TypeRules:
    """The type callbacks of the builder.  The builder gives ``_span`` (the
    location a rule's children cover) and ``wrapped`` (a parenthesised node's
    span with its parentheses, by id)."""

    wrapped: dict[int, tuple[Any, ast.Loc]]
    _span: Callable[[list[Any]], ast.Loc]

    # -- types ---------------------------------------------------------------
    def base_name(self, c: list[Token]) -> Token:
        return c[0]  # the BASE_TYPE token: its text and its position

    def base_type(self, c: list[Any]) -> typeexpr.TBase:
        return typeexpr.TBase(str(c[0]), self._span(c))  # type: ignore[arg-type]

    def named_type(self, c: list[Any]) -> typeexpr.TName:
        return typeexpr.TName(str(c[0]), self._span(c))

    def empty_type(self, c: list[Any]) -> typeexpr.TEmpty:
        return typeexpr.TEmpty(self._span(c))

    def alt(self, c: list[Any]) -> typeexpr.Constructor:
        v = _vals(c)
        return typeexpr.Constructor(str(v[0]), tuple(t for t in v[1:] if t is not None), self._span(c))

    def alt_type(self, c: list[Any]) -> typeexpr.TypeExpr:
        alts: list[typeexpr.Constructor] = _vals(c)
        if all(not a.args for a in alts):
            return typeexpr.TEnum(tuple(a.name for a in alts), self._span(c))
        return typeexpr.TConstructors(tuple(alts), self._span(c))

    def func_type(self, c: list[Any]) -> typeexpr.TFunc:
        arrow = next(k for k, x in enumerate(c) if isinstance(x, Token) and x.value == "-->")
        args, res = _vals(c[:arrow]), _vals(c[arrow + 1:])
        result = res[0] if len(res) == 1 else typeexpr.TTuple(tuple(res), self._span(c[arrow + 1:]))
        return typeexpr.TFunc(tuple(args), result, self._span(c))

    def set_type(self, c: list[Any]) -> typeexpr.TSet:
        return typeexpr.TSet(_vals(c)[0], self._span(c))

    def seq_type(self, c: list[Any]) -> typeexpr.TSeq:
        return typeexpr.TSeq(_vals(c)[0], self._span(c))

    def tuple_type(self, c: list[Any]) -> typeexpr.TTuple:
        return typeexpr.TTuple(tuple(_vals(c)), self._span(c))

    def type_atom(self, c: list[Any]) -> Any:
        t = c[1]  # "(" type ")": the type itself, spanning its parentheses for its parent
        self.wrapped[id(t)] = (t, self._span(c))
        return t


__all__ = ["TypeRules"]
