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
  values (one syntactic category, told apart by the type checker), the nodes of
  :mod:`rclverify.lang.exprs`, named here too (``ast.Var``, ``ast.Quant``).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Union

from rclverify.lang.loc import NOLOC as NOLOC, Loc as Loc, loc_field
from rclverify.lang.exprs import (  # the expression nodes: one tree, one namespace
    Prefix as Prefix,
    Var as Var,
    BoolLit as BoolLit,
    UnitAnn as UnitAnn,
    NumLit as NumLit,
    Apply as Apply,
    UnaryOp as UnaryOp,
    MATH_FUNCTIONS as MATH_FUNCTIONS,
    unhandled as unhandled,
    Unary as Unary,
    First as First,
    BinaryOp as BinaryOp,
    Binary as Binary,
    CompareOp as CompareOp,
    Compare as Compare,
    Member as Member,
    SetLit as SetLit,
    TupleLit as TupleLit,
    SeqLit as SeqLit,
    Binding as Binding,
    QuantKind as QuantKind,
    Quant as Quant,
    StrLit as StrLit,
    SeqRange as SeqRange,
    TupleQuant as TupleQuant,
    Expr as Expr,
)
from rclverify.lang.typeexpr import TypeExpr


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

