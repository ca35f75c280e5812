"""The program model of the hoare backend: a program's variables, ``old``
values and externs as Z3 constants and functions, its expressions as Z3
terms (:class:`ProgramModel`), and the walks over Z3 terms that find the
symbols a formula uses (:func:`iter_terms`, :func:`term_ids`).

Everything is a Z3 term: REAL -> Real, INTEGER/NATURAL -> Int, BOOL -> Bool,
context enumerations and constructor sets -> the *same* Z3 sorts the RCL
encoder uses (obtained through :class:`Sorts`, i.e.
:class:`rclverify.semantics.encode.Encoder`).  Variables are constants named
after them; ``old(x)`` is a constant named ``old(x)``; externs are
uninterpreted functions.
"""
from __future__ import annotations

from typing import Any, Iterator, Protocol

import z3
from z3.z3 import _to_expr_ref  # the typed wrapper of a raw term (ArithRef, BoolRef ...)

from rclverify.semantics.encode import apply_operator, widen
from rclverify.lang.ast import unhandled
from rclverify.lang.types import NATURAL, Type
from rclverify.backends.hoare import lang
from rclverify.backends.hoare.check import ProgramTypes


class Sorts(Protocol):
    """What the encoding needs from the RCL encoder (``Encoder`` satisfies it)."""

    def sort(self, t: Type) -> z3.SortRef: ...

    def enum_value(self, name: str) -> z3.ExprRef: ...

    def ctor(self, name: str) -> z3.FuncDeclRef: ...


class ProgramModel:
    """The Z3 vocabulary of one checked program.

    ``consts[x]``  the constant of variable ``x`` (its value in the state the
                   formula talks about); ``olds[x]`` the constant ``old(x)``
                   (its value in the initial state); ``funcs[f]`` the
                   uninterpreted function of extern ``f``.
    """

    def __init__(self, program: lang.Program, types: ProgramTypes, sorts: Sorts) -> None:
        self.program, self.types, self.sorts = program, types, sorts
        self.consts: dict[str, z3.ExprRef] = {}
        self.olds: dict[str, z3.ExprRef] = {}
        for name, t in types.vars.items():
            s = sorts.sort(t)
            self.consts[name] = z3.Const(name, s)
            self.olds[name] = z3.Const(f"old({name})", s)
        self.funcs: dict[str, z3.FuncDeclRef] = {
            name: z3.Function(name, *[sorts.sort(a) for a in ft.args], sorts.sort(ft.result))
            for name, ft in types.externs.items()}

    def sort_of_var(self, name: str) -> z3.SortRef:
        return self.consts[name].sort()

    def term(self, e: lang.Expr) -> z3.ExprRef:
        """Encode a (checked) expression over the current-state constants."""
        if isinstance(e, lang.Num):
            return z3.IntVal(int(e.text)) if e.is_integral else z3.RealVal(e.text)
        if isinstance(e, lang.BoolConst):
            return z3.BoolVal(e.value)
        if isinstance(e, lang.Name):
            if e.name in self.consts:
                return self.consts[e.name]
            return self.sorts.enum_value(e.name)
        if isinstance(e, lang.Old):
            return self.olds[e.name]
        if isinstance(e, lang.Call):
            f = self.funcs[e.func] if e.func in self.funcs else self.sorts.ctor(e.func)
            return f(*[widen(self.term(a), f.domain(k)) for k, a in enumerate(e.args)])
        if isinstance(e, lang.Unary):
            v = self.term(e.operand)
            if e.op == "not":
                return z3.Not(v)
            if e.op == "-":
                return -v
            unhandled(e.op)
        return apply_operator(e.op, self.term(e.left), self.term(e.right))

    def formula(self, e: lang.Expr) -> z3.BoolRef:
        """Encode a (checked) BOOL expression."""
        r = self.term(e)
        assert z3.is_bool(r)
        return r

    def value_for(self, name: str, value: z3.ExprRef) -> z3.ExprRef:
        """``value`` widened to variable ``name``'s sort (Int -> Real)."""
        return widen(value, self.sort_of_var(name))

    def typing_facts(self, formulas: list[z3.BoolRef]) -> list[z3.BoolRef]:
        """Range facts for the symbols of ``formulas``: ``x >= 0`` for every
        NATURAL variable (and ``old(x)``) occurring, and ``f(a) >= 0`` for every
        application of an extern with a NATURAL result occurring outside
        quantifiers.  Sorted by text for determinism."""
        nat_consts = {self.consts[n].get_id() for n, t in self.types.vars.items() if t == NATURAL}
        nat_consts.update(self.olds[n].get_id() for n, t in self.types.vars.items() if t == NATURAL)
        nat_funcs = {self.funcs[n].get_id() for n, ft in self.types.externs.items() if ft.result == NATURAL}
        facts: dict[str, z3.BoolRef] = {}
        for t in _matching_terms(formulas, nat_consts, nat_funcs):
            facts[t.sexpr()] = t >= 0
        return [facts[k] for k in sorted(facts)]

    def extern_applications(self, formulas: list[z3.BoolRef]) -> list[z3.ExprRef]:
        """Applications of externs in ``formulas`` (outside quantifiers), in first-seen order."""
        return list(_matching_terms(formulas, set(), {f.get_id() for f in self.funcs.values()}))

    def variables_in(self, formulas: list[z3.BoolRef]) -> list[str]:
        """Program variables whose current-state constant occurs in ``formulas`` (declaration order)."""
        ids = term_ids(formulas)
        return [n for n in self.types.vars if self.consts[n].get_id() in ids]

    def olds_in(self, formulas: list[z3.BoolRef]) -> list[str]:
        """Program variables whose ``old(x)`` constant occurs in ``formulas``."""
        ids = term_ids(formulas)
        return [n for n in self.types.vars if self.olds[n].get_id() in ids]


# Walking terms: Z3's low-level API directly.  The typed Python wrappers
# (children(), is_app(), decl()) build and re-check an object per sub-term and
# were most of the time spent in these walks (docs/scale.md); the order of the
# walk and the terms found are the same.


def _walk(formulas: list[z3.BoolRef]) -> Iterator[tuple[int, Any, int]]:
    """``(ast id, ast, ast kind)`` of every sub-term of ``formulas`` outside
    quantifier bodies, each once, in :func:`iter_terms` order."""
    if not formulas:
        return
    ctx = formulas[0].ctx_ref()
    seen: set[int] = set()
    stack = [f.as_ast() for f in reversed(formulas)]
    while stack:
        a = stack.pop()
        i = z3.Z3_get_ast_id(ctx, a)
        if i in seen:
            continue
        seen.add(i)
        k = z3.Z3_get_ast_kind(ctx, a)
        if k != z3.Z3_APP_AST and k != z3.Z3_NUMERAL_AST:  # quantifiers and bound variables: not entered
            continue
        yield i, a, k
        if k == z3.Z3_APP_AST:
            n = z3.Z3_get_app_num_args(ctx, a)
            stack.extend(z3.Z3_get_app_arg(ctx, a, j) for j in range(n - 1, -1, -1))


def term_ids(formulas: list[z3.BoolRef]) -> set[int]:
    """Z3 ids of every sub-term of ``formulas`` outside quantifier bodies."""
    return {i for i, _, _ in _walk(formulas)}


def _matching_terms(formulas: list[z3.BoolRef], const_ids: set[int], func_ids: set[int]) -> Iterator[z3.ExprRef]:
    """Sub-terms of ``formulas`` (outside quantifiers, first-seen order) whose
    id is in ``const_ids`` or that apply, to one or more arguments, a function
    whose declaration's id is in ``func_ids``."""
    if not formulas:
        return
    ctx, c = formulas[0].ctx_ref(), formulas[0].ctx
    for i, a, k in _walk(formulas):
        hit = i in const_ids
        if not hit and func_ids and k == z3.Z3_APP_AST and z3.Z3_get_app_num_args(ctx, a) > 0:
            hit = z3.Z3_get_func_decl_id(ctx, z3.Z3_get_app_decl(ctx, a)) in func_ids
        if hit:
            yield _to_expr_ref(a, c)


def iter_terms(formulas: list[z3.BoolRef]) -> Iterator[z3.ExprRef]:
    """Every sub-term of ``formulas`` outside quantifier bodies, each once."""
    if not formulas:
        return
    c = formulas[0].ctx
    for _, a, _ in _walk(formulas):
        yield _to_expr_ref(a, c)
