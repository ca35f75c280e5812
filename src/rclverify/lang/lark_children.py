"""The children a lark callback of the RCL builder (:mod:`rclverify.lang.builder`)
receives: which are data and which are syntax kept only for their position,
and an intermediate value carrying the location of its text."""
from __future__ import annotations

from typing import Any

from lark import Token

from rclverify.lang import ast

# Terminals whose text is data; every other token (keywords, punctuation) is
# syntax, kept in the children only for its position.  "QUANT" is the
# quantifier-kind token the transformer itself makes.
_VALUE_TERMINALS = frozenset({"NAME", "IO_NAME", "NUMBER", "ROS_TYPE", "CMP_OP", "BASE_TYPE", "EXISTS_BANG",
                              "QUANT", "STRING_LIT", "QUALIFIED_BASE", "UNIT", "GLOBAL_NAME", "PRIVATE_NAME"})


class _Spanned:
    """An intermediate value with the location of the text it came from."""

    __slots__ = ("value", "loc")

    def __init__(self, value: Any, loc: ast.Loc) -> None:
        self.value, self.loc = value, loc


def _is_syntax(x: Any) -> bool:
    return isinstance(x, Token) and x.type not in _VALUE_TERMINALS


def _vals(c: list[Any]) -> list[Any]:
    """The data children of a rule (syntax tokens dropped, placeholders kept)."""
    return [x for x in c if not (isinstance(x, Token) and x.type not in _VALUE_TERMINALS)]  # _is_syntax, inlined


__all__ = ["_Spanned", "_is_syntax", "_vals"]
