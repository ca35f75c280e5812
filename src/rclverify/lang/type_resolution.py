"""The state a type check of RCL carries (declared types, constants,
enumeration values, constructors) and type expressions resolved to
:data:`~rclverify.lang.types.Type` against it: enumerations and constructor
sets named by their declaration, a type defined in terms of itself and an
unknown type name each a located diagnostic (shared/DESIGN.md "RCL"; paper
lines 499-555).  :mod:`rclverify.lang.typecheck_expr` types the expressions
on top of it.
"""
from __future__ import annotations

from typing import Iterable

from rclverify.lang import ast
from rclverify.lang import typeexpr
from rclverify.lang.errors import Diagnostic, error
from rclverify.lang.types import (BASE_NAMES, DataT, EmptyT, EnumT, Env, FuncT, Scalar, SeqT, SetT, TupleT, Type)
from rclverify.lang.unitcheck import UnitChecker


class CheckFailed(Exception):
    """An expression or type could not be typed (its diagnostic is already recorded)."""


def candidates(name: str, pool: Iterable[str]) -> str:
    """``"; did you mean 'STRING'?"``: close names from ``pool``, a name that
    differs only in case first (``String`` -> ``STRING``); ``""`` if none."""
    names = sorted(set(pool))
    same = [c for c in names if c.lower() == name.lower() and c != name]
    lower = {c.lower(): c for c in names}
    import difflib  # deferred: start-up (a close spelling is only looked for in an error)
    close = same + [lower[c] for c in difflib.get_close_matches(name.lower(), sorted(lower), n=4, cutoff=0.5)
                    if lower[c] not in same]
    return f"; did you mean {', '.join(repr(c) for c in close[:4])}?" if close else ""

class TypeResolver:
    """The state of a type check of one system (declared types, constants,
    enumeration values, constructors, the diagnostics so far) and the
    resolution of type expressions against it.

    Diagnostics accumulate in ``diags`` (:meth:`err`); a failure to type
    raises :class:`CheckFailed` after recording its diagnostic.
    :class:`rclverify.lang.typecheck_expr.ExprChecker` adds the typing of
    expressions."""

    def __init__(self) -> None:
        self.diags: list[Diagnostic] = []
        self.types: dict[str, Type] = {}
        self.type_decls: dict[str, ast.TypeDecl] = {}
        self.constants: dict[str, tuple[Type, ast.Expr]] = {}
        self.enum_values: dict[str, EnumT] = {}
        self.ctors: dict[str, DataT] = {}
        self._resolving: set[str] = set()
        #: nodes allowed without assumption and guarantee (:func:`check`'s ``interface_only``)
        self.interface_only: frozenset[str] = frozenset()
        # Names whose declaration already failed (an unknown type was
        # reported there): later uses fail silently instead of adding
        # knock-on messages.  ``unknown_types``: reported once per name.
        self.unknown_types: set[str] = set()
        self.failed_io: set[tuple[str, str]] = set()
        self.failed_consts: set[str] = set()
        # units of measure (docs/rcl-language.md, "Units of measure"): declarations and formulas,
        # checked only when some file of the system writes a unit (check() sets it)
        self.units = UnitChecker(self.err)
        self.with_units = True

    # -- diagnostics -------------------------------------------------------------
    def err(self, loc: ast.Loc, msg: str, code: str = "E-type") -> None:
        self.diags.append(error(loc, msg, code))

    @property
    def env(self) -> Env:
        return Env(self.types, self.constants, self.enum_values, self.ctors, self.units.constants)

    # -- types ----------------------------------------------------------------------
    def resolve(self, t: typeexpr.TypeExpr, name: str) -> Type:
        """Resolve a type expression; ``name`` names enums/constructor sets."""
        if isinstance(t, typeexpr.TBase):
            return Scalar(t.name)
        if isinstance(t, typeexpr.TName):
            if t.name in self.types:
                return self.types[t.name]
            if t.name in self.type_decls:
                if t.name in self._resolving:
                    self.err(t.loc, f"type {t.name!r} is defined in terms of itself", "E-type-cycle")
                    raise CheckFailed
                return self.declare_type(self.type_decls[t.name])
            if t.name not in self.unknown_types:
                self.unknown_types.add(t.name)
                self.err(t.loc, f"unknown type {t.name!r}" + candidates(t.name, list(self.type_decls) + list(BASE_NAMES)), "E-name")
            raise CheckFailed
        if isinstance(t, typeexpr.TEnum):
            enum = EnumT(name, t.values)
            seen: set[str] = set()
            for v in t.values:
                if v in seen:
                    self.err(t.loc, f"enumeration value {v!r} appears twice in {name}", "E-duplicate")
                    continue
                seen.add(v)
                self._claim_value(v, t.loc)
                self.enum_values[v] = enum
            return enum
        if isinstance(t, typeexpr.TConstructors):
            ctors = []
            for c in t.ctors:
                args = tuple(self.resolve(a, f"{name}_{c.name}") for a in c.args)
                ctors.append((c.name, args))
            data = DataT(name, tuple(ctors))
            for c in t.ctors:
                self._claim_value(c.name, c.loc)
                self.ctors[c.name] = data
            return data
        if isinstance(t, typeexpr.TFunc):
            return FuncT(tuple(self.resolve(a, name + "_arg") for a in t.args), self.resolve(t.result, name + "_res"))
        if isinstance(t, typeexpr.TEmpty):
            return EmptyT(name)
        if isinstance(t, typeexpr.TSet):
            return SetT(self.resolve(t.elem, name + "_elem"))
        if isinstance(t, typeexpr.TSeq):
            return SeqT(self.resolve(t.elem, name + "_elem"))
        if isinstance(t, typeexpr.TTuple):
            return TupleT(tuple(self.resolve(e, f"{name}_{k}") for k, e in enumerate(t.elems)))
        raise AssertionError(t)  # pragma: no cover

    def _claim_value(self, v: str, loc: ast.Loc) -> None:
        if v in self.enum_values or v in self.ctors:
            self.err(loc, f"{v!r} is already a value of {(self.enum_values.get(v) or self.ctors[v]).name}", "E-duplicate")

    def declare_type(self, d: ast.TypeDecl) -> Type:
        if d.name in self.types:
            return self.types[d.name]
        self._resolving.add(d.name)
        try:
            t = self.resolve(d.type, d.name)
        finally:
            self._resolving.discard(d.name)
        self.types[d.name] = t
        return t
