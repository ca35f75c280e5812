"""RCL text of a type: ``REAL``, ``RadStat``, ``{red, orange, green}``,
``{move(REAL, REAL), inspect(NATURAL)}``, ``REAL x REAL --> BOOL``, ``{}``,
``set(T)``, ``seq(T)``, ``(T1, T2)`` (:mod:`rclverify.lang.typeexpr`'s
values), and whether a value is a type at all (a quantifier domain is a type
or a term).  The printer of formulas and files, :mod:`rclverify.lang.printer`,
names both too.
"""
from __future__ import annotations

from rclverify.lang import typeexpr


def _type_atom(t: typeexpr.TypeExpr) -> str:
    """A type in a position that admits only a type atom (function factors)."""
    s = type_to_rcl(t)
    return f"({s})" if isinstance(t, typeexpr.TFunc) else s


def type_to_rcl(t: typeexpr.TypeExpr) -> str:
    """RCL text of a type: ``REAL``, ``RadStat``, ``{red, orange, green}``,
    ``{move(REAL, REAL), inspect(NATURAL)}``, ``REAL x REAL --> BOOL``, ``{}``,
    ``set(T)``, ``seq(T)``, ``(T1, T2)``.  Raises ``TypeError`` for a value
    that is not a type."""
    if isinstance(t, (typeexpr.TBase, typeexpr.TName)):
        return t.name
    if isinstance(t, typeexpr.TEnum):
        return "{" + ", ".join(t.values) + "}"
    if isinstance(t, typeexpr.TConstructors):
        return "{" + ", ".join(_ctor(c) for c in t.ctors) + "}"
    if isinstance(t, typeexpr.TFunc):
        return " x ".join(_type_atom(a) for a in t.args) + " --> " + _type_atom(t.result)
    if isinstance(t, typeexpr.TEmpty):
        return "{}"
    if isinstance(t, typeexpr.TSet):
        return f"set({type_to_rcl(t.elem)})"
    if isinstance(t, typeexpr.TSeq):
        return f"seq({type_to_rcl(t.elem)})"
    if isinstance(t, typeexpr.TTuple):
        return "(" + ", ".join(type_to_rcl(e) for e in t.elems) + ")"
    raise TypeError(f"not an RCL type: {t!r}")


def _ctor(c: typeexpr.Constructor) -> str:
    if not c.args:
        return c.name
    return f"{c.name}(" + ", ".join(type_to_rcl(a) for a in c.args) + ")"


_TYPE_CLASSES = (typeexpr.TBase, typeexpr.TName, typeexpr.TEnum, typeexpr.TConstructors, typeexpr.TFunc, typeexpr.TEmpty,
                 typeexpr.TSet, typeexpr.TSeq, typeexpr.TTuple)


def is_type(d: object) -> bool:
    """Whether ``d`` is a type (a quantifier domain is a type or a term)."""
    return isinstance(d, _TYPE_CLASSES)
