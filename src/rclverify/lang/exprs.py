"""The expression nodes of RCL's abstract syntax: terms and formulas.

One syntactic category, :data:`Expr`, told apart by the type checker:
names (:class:`Var`), literals, applications, unary, binary and chained
comparison operators, membership, set/tuple/sequence literals, ranges and
quantifiers.  Every node carries a :class:`~rclverify.lang.loc.Loc`, excluded
from equality (``compare=False``) so that a printed-and-reparsed formula
compares equal to the original.  The declarations that hold these
expressions (contexts, nodes, clauses) are :mod:`rclverify.lang.ast`'s, which
names every node here too: readers walk one tree, ``ast.Var`` beside
``ast.Node``.

Source of the syntax: the EBNF table and the listings of the paper
(shared/reference, lines 499-555, 1131-1171 and appendix A, 1890-1983).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from fractions import Fraction
from typing import Literal, NoReturn, Union

from rclverify.lang.loc import Loc, loc_field
from rclverify.lang.typeexpr import TypeExpr


Prefix = Literal["in", "out"]


@dataclass(frozen=True)
class Var:
    """A name: an input/output (``in.at``/``out.command``, or bare ``r``),
    a bound variable (``x'``), a context constant, or an enumeration value
    (``green``).  ``prefix`` is ``"in"``, ``"out"`` or ``None``; primes are
    part of ``name`` (``"x''"``)."""

    name: str
    prefix: Prefix | None = None
    loc: Loc = loc_field()

    @property
    def qualified(self) -> str:
        """``in.at`` / ``out.command`` / ``r``: the name as written."""
        return f"{self.prefix}.{self.name}" if self.prefix else self.name


@dataclass(frozen=True)
class BoolLit:
    """``TRUE`` / ``FALSE``."""

    value: bool
    loc: Loc = loc_field()


@dataclass(frozen=True)
class UnitAnn:
    """A unit of measure as written between brackets, ``[m/s^2]``
    (docs/rcl-language.md, "Units of measure").  ``text`` is the text
    between the brackets with its blanks removed (``m/s^2``); ``loc`` is the
    opening bracket.  The unit it denotes is read by
    :func:`rclverify.lang.units.parse_unit` in the type checker."""

    text: str
    loc: Loc = loc_field()


@dataclass(frozen=True)
class NumLit:
    """A numeric literal; ``text`` is kept for printing, ``value`` is exact.
    ``unit`` is the unit written after it (``1000 [mm/m]``), ``None`` for a
    bare number (which takes the unit of what it is added to or compared
    with).  The unit does not change the value: every term's number is read
    in its own unit."""

    text: str
    loc: Loc = loc_field()
    unit: UnitAnn | None = None

    @property
    def value(self) -> Fraction:
        return Fraction(self.text)

    @property
    def is_integral(self) -> bool:
        return "." not in self.text and "e" not in self.text.lower()


@dataclass(frozen=True)
class Apply:
    """``f(a, b)``: a function-typed input applied to arguments, or a
    constructor term ``move(x, y)``; the checker tells which."""

    func: Var
    args: tuple["Expr", ...]
    loc: Loc = loc_field()


UnaryOp = Literal["not", "-", "abs", "sqrt", "sin", "cos"]

#: the mathematical functions of one real argument (``sqrt(t)``, ``sin(t)``, ``cos(t)``; radians), read as
#: :class:`Unary` operators beside ``abs`` (docs/semantics.md, "Mathematical functions")
MATH_FUNCTIONS: tuple[UnaryOp, ...] = ("sqrt", "sin", "cos")


def unhandled(op: NoReturn) -> NoReturn:
    """The end of an operator dispatch that handled every operator: mypy strict rejects a call it
    can reach with an operator value left, so an operator added to :data:`UnaryOp` (or another set) is
    listed at every translation that must give it a meaning; at run time (an unchecked caller) raises
    ``AssertionError`` naming it, never a silent reading as another operator."""
    raise AssertionError(f"operator {op!r} is not handled here")


@dataclass(frozen=True)
class Unary:
    """``not f``, ``- t``, ``abs(t)`` (the absolute value) or a mathematical
    function of :data:`MATH_FUNCTIONS` (``sqrt(t)``, ``sin(t)``, ``cos(t)``)."""

    op: UnaryOp
    operand: "Expr"
    loc: Loc = loc_field()


@dataclass(frozen=True)
class First:
    """``first(in.x)``: TRUE exactly when the message of input ``in.x`` the
    node reads is the first one published on that input in the run (in a
    requirement, ``first(Node.in.x)``: TRUE at the step whose value of the
    input is the first published on it).  ``arg`` is the input as written
    (a requirement's ``Node.in.x`` is a bare name of the system's pseudo
    node, :mod:`rclverify.model.plan.formal`).  A formula (BOOL); its
    meaning in every reading: docs/semantics.md, "The first published
    value"."""

    arg: Var
    loc: Loc = loc_field()


BinaryOp = Literal["<=>", "->", "or", "and", "+", "-", "*", "/"]


@dataclass(frozen=True)
class Binary:
    """A binary connective or arithmetic operator.

    Precedence, loosest first: ``<=>``, ``->`` (right-assoc), ``or``,
    ``and``, ``not``, comparison, ``+ -``, ``* /``.
    ``parenthesised`` records whether the source wrapped this node in
    parentheses (used only by lint; excluded from equality).
    """

    op: BinaryOp
    left: "Expr"
    right: "Expr"
    loc: Loc = loc_field()
    parenthesised: bool = field(default=False, compare=False)


CompareOp = Literal["==", "!=", "<", "<=", ">", ">="]


@dataclass(frozen=True)
class Compare:
    """A (possibly chained) comparison ``a < b <= c``: ``operands`` has one
    more element than ``ops``; it means ``a < b and b <= c``."""

    ops: tuple[CompareOp, ...]
    operands: tuple["Expr", ...]
    loc: Loc = loc_field()


@dataclass(frozen=True)
class Member:
    """``e in S`` (``negated`` for ``e !in S``); ``S`` is a set literal,
    a type name, or a set-typed term."""

    elem: "Expr"
    collection: "Expr"
    negated: bool = False
    loc: Loc = loc_field()


@dataclass(frozen=True)
class SetLit:
    """``{a, b, c}``."""

    items: tuple["Expr", ...]
    loc: Loc = loc_field()


@dataclass(frozen=True)
class TupleLit:
    """``(a, b)`` with at least two items."""

    items: tuple["Expr", ...]
    loc: Loc = loc_field()


@dataclass(frozen=True)
class SeqLit:
    """``[a, b, c]``."""

    items: tuple["Expr", ...]
    loc: Loc = loc_field()


@dataclass(frozen=True)
class Binding:
    """``x', y' in REAL``: the names bound and their domain.

    ``domain`` is a :data:`TypeExpr` (``REAL``, ``RadStat``) or, for a
    bounded quantifier over a finite set, an :data:`Expr` (``{1, 2, 3}``).
    """

    names: tuple[str, ...]
    domain: Union[TypeExpr, "Expr"]
    loc: Loc = loc_field()
    name_locs: tuple[Loc, ...] = field(default=(), compare=False, repr=False)


QuantKind = Literal["forall", "exists", "exists_unique"]


@dataclass(frozen=True)
class Quant:
    """``forall (x in REAL, i in NATURAL | body)``; ``exists_unique`` is ``∃!``."""

    kind: QuantKind
    bindings: tuple[Binding, ...]
    body: "Expr"
    loc: Loc = loc_field()

    @property
    def variables(self) -> tuple[str, ...]:
        return tuple(n for b in self.bindings for n in b.names)


@dataclass(frozen=True)
class StrLit:
    """A string literal ``"hello"``; ``value`` is the text between the quotes
    with the escapes ``\\"`` and ``\\\\`` resolved.  Type ``STRING``."""

    value: str
    loc: Loc = loc_field()


@dataclass(frozen=True)
class SeqRange:
    """``<lo upto hi>``: the sequence of the integers ``lo, lo+1, ..., hi``
    (empty when ``hi < lo``).  Type ``seq(INTEGER)`` (``seq(NATURAL)`` when
    both bounds are natural numbers)."""

    lo: "Expr"
    hi: "Expr"
    loc: Loc = loc_field()


@dataclass(frozen=True)
class TupleQuant:
    """A quantifier over the tuples of a collection, destructured:
    ``forall((u, v) in S | body)`` binds ``u`` and ``v`` to the components
    of each element of ``S`` (a set or sequence of tuples, or a tuple type).
    ``exists`` and ``exists_unique`` likewise (unique: exactly one element).
    A separate node class so that consumers which only know :class:`Quant`
    reject it rather than misread it."""

    kind: QuantKind
    names: tuple[str, ...]
    domain: Union[TypeExpr, "Expr"]
    body: "Expr"
    loc: Loc = loc_field()
    name_locs: tuple[Loc, ...] = field(default=(), compare=False, repr=False)

    @property
    def variables(self) -> tuple[str, ...]:
        return self.names


Expr = Union[Var, BoolLit, NumLit, Apply, Unary, Binary, Compare, Member, SetLit, TupleLit, SeqLit, Quant,
             StrLit, SeqRange, TupleQuant, First]
