"""The encoding's names and its error: :class:`EncodingError` (a
well-typed formula the Z3 encoding does not support, located),
:func:`smt_symbol` (an RCL name as an SMT-LIB2 symbol) and :class:`Symbol`
(a free symbol the encoder made).  Part of the Z3 encoding
(:mod:`rclverify.semantics.encode`).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from rclverify.lang import ast
from rclverify.lang.types import Type


class EncodingError(Exception):
    """A well-typed formula that the Z3 encoding does not support (located)."""

    def __init__(self, loc: ast.Loc, message: str) -> None:
        self.loc = loc
        super().__init__(f"{loc}: error: {message}")


def smt_symbol(name: str) -> str:
    """A Z3/SMT-LIB2 symbol for an RCL name: primes (``x'``), which SMT-LIB
    simple symbols do not allow, become ``_prime`` (``x_prime``), so that the
    written queries can be re-checked by a second solver."""
    return name.replace("'", "_prime")


@dataclass(frozen=True)
class Symbol:
    """A free symbol created by the encoder: its Z3 name, RCL display name and type."""

    z3name: str
    display: str
    type: Type
    decl: Any  # z3.ExprRef for constants, z3.FuncDeclRef for functions
