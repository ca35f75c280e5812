"""The abstract syntax of the hoare backend's imperative language
(:mod:`.lang` parses and prints it and re-exports these names).  The
classes are this language's own, parsed from program files, not copies of
RCL's: docs/semantics.md, "One formula core".
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal, Union

from rclverify.lang import typeexpr
from rclverify.lang.ast import Loc
from rclverify.semantics.operators import COMPARISONS as OPERATORS_COMPARISONS
from rclverify.semantics.operators import CONNECTIVES as OPERATORS_CONNECTIVES

NOLOC = Loc()


def _loc() -> Loc:
    return field(default=NOLOC, compare=False, repr=False)


# --------------------------------------------------------------------------
# Expressions
# --------------------------------------------------------------------------


@dataclass(frozen=True)
class Num:
    """A numeric literal; ``text`` as written (``120``, ``2.5``)."""

    text: str
    loc: Loc = _loc()

    @property
    def is_integral(self) -> bool:
        return "." not in self.text


@dataclass(frozen=True)
class BoolConst:
    """``TRUE`` / ``FALSE``."""

    value: bool
    loc: Loc = _loc()


@dataclass(frozen=True)
class Name:
    """A variable or an enumeration value of the RCL context (``green``)."""

    name: str
    loc: Loc = _loc()


@dataclass(frozen=True)
class Old:
    """``old(x)``: the value of variable ``x`` in the initial state."""

    name: str
    loc: Loc = _loc()


@dataclass(frozen=True)
class Call:
    """``f(a, ...)``: an uninterpreted (``extern``) function or an RCL constructor."""

    func: str
    args: tuple["Expr", ...]
    loc: Loc = _loc()


UnOp = Literal["not", "-"]
BinOp = Literal["->", "or", "and", "==", "!=", "<", "<=", ">", ">=", "+", "-", "*", "/"]
#: the comparisons and connectives of the language: RCL's (the semantics table), without ``<=>``
COMPARISONS: frozenset[str] = OPERATORS_COMPARISONS
CONNECTIVES: frozenset[str] = OPERATORS_CONNECTIVES - {"<=>"}


@dataclass(frozen=True)
class Unary:
    """``not e`` or ``- e``."""

    op: UnOp
    operand: "Expr"
    loc: Loc = _loc()


@dataclass(frozen=True)
class Binary:
    """A binary connective, comparison or arithmetic operator (``op`` in :data:`BinOp`)."""

    op: BinOp
    left: "Expr"
    right: "Expr"
    loc: Loc = _loc()


Expr = Union[Num, BoolConst, Name, Old, Call, Unary, Binary]


# --------------------------------------------------------------------------
# Statements and programs
# --------------------------------------------------------------------------


@dataclass(frozen=True)
class Assign:
    """``target := value``."""

    target: str
    value: Expr
    loc: Loc = _loc()


@dataclass(frozen=True)
class If:
    """``if cond then then_ else else_ end``; a missing ``else`` is ``else_ == ()``.

    ``elif`` chains and the paper's ``IF/THEN/ELSE`` spelling parse to nested
    :class:`If` values.
    """

    cond: Expr
    then_: tuple["Stmt", ...]
    else_: tuple["Stmt", ...] = ()
    loc: Loc = _loc()


@dataclass(frozen=True)
class While:
    """``while cond invariant invariant do body end`` (several ``invariant``
    clauses are conjoined)."""

    cond: Expr
    invariant: Expr
    body: tuple["Stmt", ...]
    loc: Loc = _loc()


@dataclass(frozen=True)
class Skip:
    """``skip``."""

    loc: Loc = _loc()


Stmt = Union[Assign, If, While, Skip]


@dataclass(frozen=True)
class VarDecl:
    """``var name : type;`` (``type`` is an RCL type expression)."""

    name: str
    type: typeexpr.TypeExpr
    loc: Loc = _loc()


@dataclass(frozen=True)
class ExternDecl:
    """``extern name : T1 x ... --> T;``: an uninterpreted function."""

    name: str
    type: typeexpr.TypeExpr
    loc: Loc = _loc()


@dataclass(frozen=True)
class Program:
    """A whole program: declarations in source order and the statement sequence."""

    vars: tuple[VarDecl, ...]
    externs: tuple[ExternDecl, ...]
    body: tuple[Stmt, ...]
    file: str = field(default="<string>", compare=False)
