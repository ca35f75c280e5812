"""The abstract syntax of RCL's types: :data:`TypeExpr`, what a ``context``
clause declares a name to be and an input, output, constant or bound
variable is declared with (``REAL``, ``RadStat``, ``{red, green}``,
``REAL x REAL --> BOOL``, ``set(T)``, ``seq(T)``, ``(T1, T2)``).

Each is one small frozen dataclass carrying its :class:`~rclverify.lang.loc.Loc`
(left out of equality); the formulas and the declarations that use them are
:mod:`rclverify.lang.ast`'s.  Source of the syntax: the EBNF table of the
paper (shared/reference, lines 499-555), as :mod:`rclverify.lang.ast` says.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Literal, Union

from rclverify.lang.loc import Loc, loc_field


BaseName = Literal["REAL", "INTEGER", "NATURAL", "BOOL", "STRING"]


@dataclass(frozen=True)
class TBase:
    """A built-in scalar type: ``REAL``, ``INTEGER``, ``NATURAL``, ``BOOL``,
    or ``STRING`` (character strings, e.g. values read from ROS ``string``
    topics)."""

    name: BaseName
    loc: Loc = loc_field()


@dataclass(frozen=True)
class TName:
    """A reference to a type declared in a ``context`` clause (e.g. ``RadStat``)."""

    name: str
    loc: Loc = loc_field()


@dataclass(frozen=True)
class TEnum:
    """An enumeration ``{red, orange, green}``; ``values`` in source order."""

    values: tuple[str, ...]
    loc: Loc = loc_field()


@dataclass(frozen=True)
class Constructor:
    """One alternative ``move(REAL, REAL)`` of a constructor set."""

    name: str
    args: tuple["TypeExpr", ...]
    loc: Loc = loc_field()


@dataclass(frozen=True)
class TConstructors:
    """A constructor set ``{ move(REAL, REAL), inspect(NATURAL) }``.

    Alternatives without arguments (``stop``) have ``args == ()``; a set of
    only argument-less alternatives is written and parsed as a :class:`TEnum`.
    """

    ctors: tuple[Constructor, ...]
    loc: Loc = loc_field()


@dataclass(frozen=True)
class TFunc:
    """A function type ``REAL x REAL --> BOOL`` (``args`` are the domain factors)."""

    args: tuple["TypeExpr", ...]
    result: "TypeExpr"
    loc: Loc = loc_field()


@dataclass(frozen=True)
class TEmpty:
    """The empty type ``{}`` (used for hardware inputs, e.g. ``SensorsType``)."""

    loc: Loc = loc_field()


@dataclass(frozen=True)
class TSet:
    """``set(T)``: finite sets of ``T`` (also written ``P(T)``)."""

    elem: "TypeExpr"
    loc: Loc = loc_field()


@dataclass(frozen=True)
class TSeq:
    """``seq(T)``: finite sequences of ``T``."""

    elem: "TypeExpr"
    loc: Loc = loc_field()


@dataclass(frozen=True)
class TTuple:
    """``(T1, T2, ...)``: tuples (at least two components)."""

    elems: tuple["TypeExpr", ...]
    loc: Loc = loc_field()


TypeExpr = Union[TBase, TName, TEnum, TConstructors, TFunc, TEmpty, TSet, TSeq, TTuple]


__all__ = ["BaseName", "Constructor", "TBase", "TConstructors", "TEmpty", "TEnum", "TFunc", "TName", "TSeq", "TSet",
           "TTuple", "TypeExpr"]
