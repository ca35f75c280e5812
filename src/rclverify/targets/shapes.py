"""The records the translations hand to their templates, as types.

:class:`Carried` is what a generated Python package's ``contract.py``
carries (:func:`rclverify.targets.python.carry.carried`); :class:`TermFields`
the template context of a constructor set's C++ ``Term<Name>``
(:func:`rclverify.targets.cpp.values.term_fields`).
"""
# No ``from __future__ import annotations``: Python 3.11 reads ``NotRequired`` only from evaluated
# annotations (with string annotations every key would count as required).
from typing import TypedDict


class CarriedClause(TypedDict):
    """One assumption or guarantee: its expression tree (nested lists,
    ``["lit", True]``) and whether the double (``fs``) and the tolerance
    (``fs_tol``) readings can change its truth."""
    tree: list[object]
    fs: bool
    fs_tol: bool


class Carried(TypedDict):
    """``contract.py`` of one node: its clauses, ``ins`` (the inputs the
    contract reads, in declaration order), ``per`` (guarantee number as text
    -> [inputs, outputs] it reads) and ``enums`` (variable -> its values)."""
    assumes: list[CarriedClause]
    guarantees: list[CarriedClause]
    ins: list[str]
    per: dict[str, list[list[str]]]
    enums: dict[str, list[str]]


class TermArg(TypedDict):
    """An argument of a constructor: its struct field and C++ type (``None``: not held)."""
    field: str
    cpp: str | None


class TermCtor(TypedDict):
    """A constructor of a constructor set: its index, name, function name and arguments."""
    index: int
    name: str
    fn: str
    args: list[TermArg]


class TermFields(TypedDict):
    """``Term<Name>`` of a constructor set: the set's name, the struct's name
    (``None`` when an argument is not held) and the constructors."""
    name: str
    struct: str | None
    ctors: list[TermCtor]


__all__ = ["Carried", "CarriedClause", "TermArg", "TermCtor", "TermFields"]
