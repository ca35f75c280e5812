"""Immutable abstract syntax of RCL, the ROS Contract Language.

Every node carries a :class:`Loc`.  Locations are excluded from equality
(``compare=False``) so that a printed-and-reparsed file compares equal to the
original (the round-trip property of the printer).

Source of the syntax: the EBNF table and the listings of the paper
(shared/reference, lines 499-555, 1131-1171 and appendix A, 1890-1983).

The types are :mod:`rclverify.lang.typeexpr`'s and the location every node
carries :mod:`rclverify.lang.loc`'s (:class:`Loc` and :data:`NOLOC` are
named here too: a node's location is part of the tree a reader walks).

Shapes
------
* A :class:`Spec` is one RCL file: a tuple of :class:`Context` clauses and a
  tuple of :class:`Node` clauses, in source order.
* Types are :data:`~rclverify.lang.typeexpr.TypeExpr` values; formulas and terms are :data:`Expr`
  values (one syntactic category, told apart by the type checker).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from fractions import Fraction
from typing import Literal, NoReturn, Union

from rclverify.lang.loc import NOLOC as NOLOC, Loc as Loc, loc_field
from rclverify.lang.typeexpr import TypeExpr


# --------------------------------------------------------------------------
# Expressions (terms and formulas)
# --------------------------------------------------------------------------

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


# --------------------------------------------------------------------------
# Declarations
# --------------------------------------------------------------------------


@dataclass(frozen=True)
class TypeDecl:
    """``Name : type ;`` in a context clause."""

    name: str
    type: TypeExpr
    loc: Loc = loc_field()


@dataclass(frozen=True)
class ConstDecl:
    """``Name = value ;`` in a context clause (a named constant).

    ``type`` is optional: ``MaxLevel : REAL = 250 ;`` declares it, plain
    ``MaxLevel = 250 ;`` lets the checker infer it from ``value``.  ``unit``
    is the unit written after the type (``MaxRange : REAL [m] = 30 ;``).
    """

    name: str
    value: Expr
    type: TypeExpr | None = None
    loc: Loc = loc_field()
    unit: UnitAnn | None = None


@dataclass(frozen=True)
class Context:
    """``context { ... }``: type and constant declarations in source order."""

    decls: tuple[Union[TypeDecl, ConstDecl], ...]
    loc: Loc = loc_field()


@dataclass(frozen=True)
class IOVar:
    """``name : TypeName`` in ``inputs(...)``/``outputs(...)``; ``unit`` is
    the unit of measure written after the type (``d : REAL [m]``), ``None``
    when none is declared."""

    name: str
    type: TypeExpr
    loc: Loc = loc_field()
    unit: UnitAnn | None = None


@dataclass(frozen=True)
class Topic:
    """``ros_pkg/Type field matches(in.x)``.

    ``msg_type`` is the ROS message type (``gazebo_radiation_plugin/Snapshot``),
    ``field`` the topic's name as written (a ROS name: ``stop``, relative in a
    namespace ``safety/stop``, global ``/safety/stop``), ``match`` the contract
    variable it populates (``None`` when there is no ``matches`` clause);
    ``name_loc`` where the name is written.
    """

    msg_type: str
    field: str
    match: Var | None = None
    loc: Loc = loc_field()
    name_loc: Loc = loc_field()

    @property
    def key(self) -> str:
        """The name the system model and the monitors know the topic by: as
        written, a global name's leading ``/`` dropped (a contract's nodes
        sit in the root namespace, where ``safety/stop`` and
        ``/safety/stop`` are one topic; the grounding resolves the written
        name against the running node's namespace, ROS 2 design "Topic and
        Service Names")."""
        return self.field.lstrip("/")


@dataclass(frozen=True)
class Deadline:
    """``within 200 ms`` after a guarantee (docs/rcl-language.md, "Services,
    actions and deadlines").  ``amount`` is the number as written, ``unit``
    the unit name (``None`` when missing: a located type error), ``seconds``
    is left to the type checker."""

    amount: str
    unit: str | None
    loc: Loc = loc_field()


@dataclass(frozen=True)
class Scope:
    """``while active`` (``while inactive or active``) after a guarantee of a
    lifecycle node (docs/rcl-language.md, "Lifecycle nodes"): the states, as
    written, in which the guarantee is asked."""

    states: tuple[str, ...]
    loc: Loc = loc_field()


@dataclass(frozen=True)
class Clause:
    """One ``assume(...)`` or ``guarantee(...)`` clause.

    A guarantee may carry ``triggered by in.x`` (``trigger``: the output is
    produced in response to input ``x``), ``within N unit`` (``deadline``)
    and ``while S`` (``scope``: lifecycle states); all are ``None`` for every
    contract written before them, so those keep their meaning."""

    formula: Expr
    loc: Loc = loc_field()
    trigger: Var | None = None
    deadline: Deadline | None = None
    scope: Scope | None = None


@dataclass(frozen=True)
class TransitionDeadline:
    """``ready within 200 ms of activate`` in a lifecycle node
    (docs/rcl-language.md, "Lifecycle nodes"): the node reaches the state
    ``transition`` leads to within ``deadline`` of entering its transition
    state."""

    transition: str
    deadline: Deadline
    loc: Loc = loc_field()


@dataclass(frozen=True)
class Link:
    """``pkg/Type name serves(in.req, out.resp)`` in ``services(...)`` or
    ``pkg/Action name calls(out.goal, in.feedback, in.result)`` in
    ``actions(...)``.

    ``kind`` is ``"service"`` or ``"action"``; ``role`` ``"serves"`` or
    ``"calls"``; ``parts`` the contract variables of the request and response
    (service) or goal, feedback and result (action), in that order."""

    kind: str
    ros_type: str
    name: str
    role: str
    parts: tuple[Var, ...]
    loc: Loc = loc_field()
    name_loc: Loc = loc_field()


@dataclass(frozen=True)
class Progress:
    """``progress( eventually )`` or ``progress( within K steps )`` in a node
    (docs/rcl-language.md, "Progress, initial values and periodic outputs"):
    the node answers every input its assumption accepts, eventually or
    within K steps of the composed system.  ``bound`` is K as written
    (``None`` for ``eventually``), ``unit`` the word after it (``steps``;
    another word, or none, is a located type error)."""

    bound: str | None
    unit: str | None
    loc: Loc = loc_field()


@dataclass(frozen=True)
class Periodic:
    """``periodic( out.y, 100 ms )`` or ``periodic( out.y, 3 steps )``: the
    node refreshes output ``y`` at least once per period.  ``amount`` is the
    number as written, ``unit`` the word after it (a unit of time or
    ``steps``; checked by :mod:`rclverify.lang.progress`)."""

    output: Var
    amount: str
    unit: str | None
    loc: Loc = loc_field()


@dataclass(frozen=True)
class Node:
    """``node name { inputs(...) outputs(...) topics(...) assume(...)* guarantee(...)+ }``.

    ``initially`` (formulas over the outputs before the node's first answer),
    ``progress`` and ``periodic`` are the temporal declarations of
    docs/rcl-language.md, ``transitions`` a lifecycle node's transition
    deadlines; all four are empty for every contract written before them,
    which keep their meaning."""

    name: str
    inputs: tuple[IOVar, ...]
    outputs: tuple[IOVar, ...]
    topics: tuple[Topic, ...]
    assumes: tuple[Clause, ...]
    guarantees: tuple[Clause, ...]
    loc: Loc = loc_field()
    links: tuple[Link, ...] = ()
    initially: tuple[Clause, ...] = ()
    progress: tuple[Progress, ...] = ()
    periodic: tuple[Periodic, ...] = ()
    transitions: tuple[TransitionDeadline, ...] = ()


@dataclass(frozen=True)
class Spec:
    """One RCL file."""

    contexts: tuple[Context, ...]
    nodes: tuple[Node, ...]
    file: str = field(default="<string>", compare=False)
    #: whether the file may write a unit of measure anywhere (the parser sets
    #: ``False`` when it read none, so the type checker skips the unit pass of
    #: a system without units; a tree made by a program keeps ``True``)
    has_units: bool = field(default=True, compare=False)

