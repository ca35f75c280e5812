"""Static checking of a program of the hoare backend's language.

Types are RCL's (:mod:`rclverify.lang.types`): declarations name ``REAL``,
``INTEGER``, ``NATURAL``, ``BOOL`` or a type of the RCL context, resolved
through the checked :class:`~rclverify.lang.types.Env`, so the program's
``RadStat`` is the contract's ``RadStat`` (paper lines 1131-1140 declare it;
lines 1482-1491 use its values).

Rules
-----
* every variable and extern is declared once; their names do not clash with
  each other nor with the context's enumeration values and constructors;
* ``extern`` declarations have function types; variables do not;
* a name in an expression is a variable or an enumeration value; ``f(...)``
  calls an extern (or builds a constructor term of the context) with the
  declared number and types of arguments; ``old(x)`` names a variable;
* ``and``/``or``/``not``/``->`` take BOOL, ``< <= > >=`` and ``+ - * /`` take
  numbers, ``==``/``!=`` comparable types; conditions and invariants are BOOL;
* ``x := e`` needs ``e``'s type assignable to ``x``'s (numeric widening
  NATURAL <: INTEGER <: REAL), except that an INTEGER value may be assigned to
  a NATURAL variable: the weakest precondition then demands it is >= 0.

Numeric literal types: an integral literal is NATURAL, a decimal is REAL;
``a - b`` is at least INTEGER, ``a / b`` is REAL, ``-a`` is at least INTEGER.
"""
from __future__ import annotations

import difflib
from dataclasses import dataclass
from typing import Iterable, Mapping

from rclverify.lang import typeexpr
from rclverify.lang.ast import Loc, unhandled
from rclverify.lang.errors import Diagnostic, RclError, error
from rclverify.lang.types import (BOOL, INTEGER, NATURAL, REAL, DataT, EnumT, Env, FuncT, Scalar, Type, assignable,
                          comparable, is_numeric, numeric_join)
from rclverify.backends.hoare import lang


@dataclass(frozen=True)
class ProgramTypes:
    """The resolved declarations of a program.

    ``vars``     variable name -> RCL type (Scalar, EnumT or DataT);
    ``externs``  extern name -> :class:`FuncT`;
    ``env``      the RCL environment the names were resolved in.
    """

    vars: Mapping[str, Type]
    externs: Mapping[str, FuncT]
    env: Env

    def var_loc(self, program: lang.Program, name: str) -> Loc:
        """Location of ``name``'s declaration in ``program``."""
        for d in program.vars:
            if d.name == name:
                return d.loc
        return Loc(program.file, 1, 1)


class _Fail(Exception):
    """Internal: an expression could not be typed (a diagnostic was recorded)."""


def _candidates(name: str, pool: Iterable[str]) -> str:
    close = difflib.get_close_matches(name, sorted(set(pool)), n=4, cutoff=0.5)
    return f"; did you mean {', '.join(repr(c) for c in close)}?" if close else ""


_BASES = ("REAL", "INTEGER", "NATURAL", "BOOL")


class _Checker:
    def __init__(self, env: Env) -> None:
        self.env = env
        self.diags: list[Diagnostic] = []
        self.vars: dict[str, Type] = {}
        self.externs: dict[str, FuncT] = {}

    def err(self, loc: Loc, msg: str, code: str = "E-type") -> None:
        self.diags.append(error(loc, msg, code))

    # -- declarations ---------------------------------------------------------------
    def resolve(self, t: typeexpr.TypeExpr) -> Type:
        if isinstance(t, typeexpr.TBase):
            return Scalar(t.name)
        if isinstance(t, typeexpr.TName):
            if t.name in self.env.types:
                return self.env.types[t.name]
            self.err(t.loc, f"unknown type {t.name!r}" + _candidates(t.name, list(self.env.types) + list(_BASES)),
                     "E-name")
            raise _Fail
        if isinstance(t, typeexpr.TFunc):
            return FuncT(tuple(self.resolve(a) for a in t.args), self.resolve(t.result))
        self.err(t.loc, "this type cannot be written in a program")
        raise _Fail

    def declare(self, program: lang.Program) -> None:
        seen: dict[str, Loc] = {}
        decls: list[lang.VarDecl | lang.ExternDecl] = [*program.vars, *program.externs]
        for d in sorted(decls, key=lambda d: (d.loc.line, d.loc.col)):
            if d.name in seen:
                self.err(d.loc, f"{d.name!r} is already declared at {seen[d.name]}", "E-duplicate")
                continue
            seen[d.name] = d.loc
            if d.name in self.env.enum_values or d.name in self.env.ctors:
                owner = (self.env.enum_values.get(d.name) or self.env.ctors[d.name]).name
                self.err(d.loc, f"{d.name!r} is a value of the context type {owner}; choose another name",
                         "E-duplicate")
                continue
            try:
                t = self.resolve(d.type)
            except _Fail:
                continue
            if isinstance(d, lang.ExternDecl):
                if not isinstance(t, FuncT):
                    self.err(d.loc, f"extern {d.name!r} must have a function type (T1 x ... --> T), found {t}")
                    continue
                bad = [a for a in (*t.args, t.result) if not self._first_order(a)]
                if bad:
                    self.err(d.loc, f"extern {d.name!r}: type {bad[0]} cannot be an argument or result")
                    continue
                self.externs[d.name] = t
            else:
                if not self._first_order(t):
                    hint = "; declare functions with 'extern'" if isinstance(t, FuncT) else ""
                    self.err(d.loc, f"variable {d.name!r} cannot have type {t}{hint}")
                    continue
                self.vars[d.name] = t

    @staticmethod
    def _first_order(t: Type) -> bool:
        return isinstance(t, (Scalar, EnumT, DataT))

    # -- expressions ------------------------------------------------------------------
    def infer(self, e: lang.Expr) -> Type:
        if isinstance(e, lang.Num):
            return NATURAL if e.is_integral else REAL
        if isinstance(e, lang.BoolConst):
            return BOOL
        if isinstance(e, lang.Name):
            if e.name in self.vars:
                return self.vars[e.name]
            if e.name in self.env.enum_values:
                return self.env.enum_values[e.name]
            if e.name in self.env.ctors and self.env.ctors[e.name].ctor(e.name) == ():
                return self.env.ctors[e.name]
            if e.name in self.externs:
                self.err(e.loc, f"{e.name!r} is a function; call it with arguments")
                raise _Fail
            pool = [*self.vars, *self.env.enum_values]
            self.err(e.loc, f"undeclared name {e.name!r}" + _candidates(e.name, pool), "E-name")
            raise _Fail
        if isinstance(e, lang.Old):
            if e.name not in self.vars:
                self.err(e.loc, f"old({e.name}): {e.name!r} is not a variable" + _candidates(e.name, self.vars),
                         "E-name")
                raise _Fail
            return self.vars[e.name]
        if isinstance(e, lang.Call):
            return self.call(e)
        if isinstance(e, lang.Unary):
            t = self.infer(e.operand)
            if e.op == "not":
                self.expect_bool(e.operand, t, "not")
                return BOOL
            if e.op == "-":
                if not is_numeric(t):
                    self.err(e.operand.loc, f"unary '-' needs a number, found {t}")
                    raise _Fail
                return REAL if t == REAL else INTEGER
            unhandled(e.op)
        lt, rt = self.infer(e.left), self.infer(e.right)
        if e.op in lang.CONNECTIVES:
            self.expect_bool(e.left, lt, e.op)
            self.expect_bool(e.right, rt, e.op)
            return BOOL
        if e.op in ("==", "!="):
            if not comparable(lt, rt):
                self.err(e.loc, f"cannot compare {lt} with {rt}")
                raise _Fail
            return BOOL
        for side, t in ((e.left, lt), (e.right, rt)):
            if not is_numeric(t):
                self.err(side.loc, f"'{e.op}' needs numbers, found {t}")
                raise _Fail
        if e.op in lang.COMPARISONS:
            return BOOL
        if e.op == "/":
            return REAL
        joined = numeric_join(lt, rt)
        assert joined is not None
        if e.op == "-" and joined == NATURAL:
            return INTEGER
        return joined

    def call(self, e: lang.Call) -> Type:
        if e.func in self.externs:
            ft = self.externs[e.func]
            params, result = ft.args, ft.result
        elif e.func in self.env.ctors:
            data = self.env.ctors[e.func]
            params, result = data.ctor(e.func) or (), data
        else:
            self.err(e.loc, f"unknown function {e.func!r}; declare it with 'extern'"
                     + _candidates(e.func, [*self.externs, *self.env.ctors]), "E-name")
            raise _Fail
        if len(e.args) != len(params):
            self.err(e.loc, f"{e.func} takes {len(params)} argument(s), {len(e.args)} given")
            raise _Fail
        for a, p in zip(e.args, params):
            at = self.infer(a)
            if not assignable(at, p):
                self.err(a.loc, f"argument of {e.func} must be {p}, found {at}")
                raise _Fail
        return result

    def expect_bool(self, e: lang.Expr, t: Type, what: str) -> None:
        if t != BOOL:
            self.err(e.loc, f"'{what}' needs a BOOL operand, found {t}")
            raise _Fail

    def formula(self, e: lang.Expr, what: str) -> None:
        try:
            t = self.infer(e)
        except _Fail:
            return
        if t != BOOL:
            self.err(e.loc, f"{what} must be BOOL, found {t}")

    # -- statements -----------------------------------------------------------------
    def stmts(self, body: tuple[lang.Stmt, ...]) -> None:
        for s in body:
            if isinstance(s, lang.Assign):
                if s.target not in self.vars:
                    self.err(s.loc, f"assignment to undeclared variable {s.target!r}"
                             + _candidates(s.target, self.vars), "E-name")
                    continue
                try:
                    vt = self.infer(s.value)
                except _Fail:
                    continue
                dst = self.vars[s.target]
                if not (assignable(vt, dst) or (vt == INTEGER and dst == NATURAL)):
                    self.err(s.value.loc, f"cannot assign a {vt} value to {s.target!r} of type {dst}")
            elif isinstance(s, lang.If):
                self.formula(s.cond, "the condition")
                self.stmts(s.then_)
                self.stmts(s.else_)
            elif isinstance(s, lang.While):
                self.formula(s.cond, "the loop condition")
                self.formula(s.invariant, "the loop invariant")
                self.stmts(s.body)


def check_program(program: lang.Program, env: Env) -> ProgramTypes:
    """Check ``program``'s declarations and statements against the RCL ``env``.

    Returns the resolved :class:`ProgramTypes`; raises :class:`RclError`
    listing every error, located in the program file.
    """
    c = _Checker(env)
    c.declare(program)
    c.stmts(program.body)
    if c.diags:
        raise RclError(sorted(c.diags, key=lambda d: (d.loc.line, d.loc.col)))
    return ProgramTypes(dict(c.vars), dict(c.externs), env)


def expr_type(e: lang.Expr, types: ProgramTypes) -> Type:
    """Type of expression ``e`` over ``types``' declarations.

    Raises :class:`RclError` (located at ``e``) when it is ill-typed.
    """
    c = _Checker(types.env)
    c.vars, c.externs = dict(types.vars), dict(types.externs)
    try:
        return c.infer(e)
    except _Fail:
        raise RclError(c.diags) from None
