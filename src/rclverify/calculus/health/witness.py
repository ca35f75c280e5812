"""Witnesses in which every function-typed input is a finite table.

A satisfiability query over a contract with uninterpreted functions over
the reals (the case study's Agent: ``wayP``, ``at``, ``inspected``) can keep
Z3's quantifier instantiation busy for its whole budget before it finds a
model.  Asking for a model of a fixed shape is far cheaper: each such
function takes a free value at ``points`` points ``(j, 0, ..., 0)``
(``j = 0 .. points - 1``) and one free value elsewhere.  A model of that
query is a model of the original one (the functions interpreted as those
tables), so ``sat`` is a witness; anything else says only that no witness
of this shape was found, never that there is none.

The query is built and solved in a Z3 context of its own (the formulas are
translated into it), so asking it leaves the process's context, and with it
the search of the queries asked after it, as it was.

A witness found can be extended (:func:`extend`): with every function and
every variable fixed to its value, a formula over new variables (a
premise's witnesses) is a small query.

Used by the health stage's consistency check (:mod:`.checks`, asked before
the general query; its witness extended for the non-vacuity checks), the
refinement check's counterexample (:mod:`rclverify.calculus.refinement`),
a requirement's consistency and vacuity queries
(:mod:`rclverify.calculus.requirements.check`) and the diagnosis's repair checks
(:mod:`rclverify.diagnosis.recheck`).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Iterator, Sequence

import z3

from rclverify.semantics.connectives import conj
from rclverify.semantics.encode import value_to_rcl
from rclverify.semantics.query import budgeted_solver, render_model, tactic_solver
from rclverify.semantics.wallclock import check
from rclverify.semantics.retry import load_canonical
from rclverify.semantics.subterms import subterms

#: Points of each function table (at least the plan's instances: see :func:`points_for`).
WITNESS_POINTS = 4
#: Budget of one witness query, in milliseconds' worth of Z3 resource steps
#: (:data:`rclverify.semantics.query.STEPS_PER_MS`), so the answer does not depend on load.
WITNESS_TIMEOUT_MS = 5_000
#: The Z3 tactics a witness query is first given to with ``simplified=True``
#: (:func:`finite_witness`): ``simplify``, then ``qe-light``, which eliminates
#: the quantified variables an equality fixes (the tables' ``x == j`` tests,
#: ``exists(x, y | wayP(x, y) == k)``), then the SMT core.  The diagnosis's
#: witnesses on the case study's Agent: 0.1 s each instead of 0.3-0.7 s.
SIMPLIFIED = ("simplify", "qe-light", "smt")
#: Budget of that first attempt (milliseconds' worth of Z3 resource steps);
#: undecided, the query goes to Z3's default strategy as without it.
SIMPLIFIED_MS = 1_000
#: Budget of one :func:`extend` query (every function and earlier symbol fixed: it
#: takes a few thousand steps on the case study).
EXTEND_TIMEOUT_MS = 250


@dataclass(frozen=True)
class Witness:
    """``status``: ``sat`` (``model`` maps each symbol's RCL name to its value
    in RCL syntax, a function to its table) or ``inconclusive``.  ``found``:
    the model itself, for :func:`extend` (``None`` when it cannot be
    extended)."""

    status: str
    model: dict[str, str] | None = None
    found: "_Found | None" = field(default=None, repr=False, compare=False)


@dataclass(frozen=True)
class _Found:
    """A witness's model as substitutions in its own Z3 context ``ctx``:
    each tabled function by its table with the model's values (``funcs``,
    for ``z3.substitute_funs``), each other symbol the encoder had then by
    its value (``consts``, for ``z3.substitute``)."""

    ctx: z3.Context
    funcs: list[tuple[z3.FuncDeclRef, z3.ExprRef]]
    consts: list[tuple[z3.ExprRef, z3.ExprRef]]


def points_for(instances: tuple[int, int] | None) -> int:
    """The table size for a node with the plan's ``instances: [lo, hi]``:
    at least :data:`WITNESS_POINTS`, and ``hi + 1`` so that every instance
    has a point of its own."""
    return max(WITNESS_POINTS, instances[1] + 1) if instances else WITNESS_POINTS


def _tabled(d: z3.FuncDeclRef) -> bool:
    return d.arity() > 0 and all(d.domain(m) in (z3.RealSort(d.ctx), z3.IntSort(d.ctx)) for m in range(d.arity()))


def has_tables(enc: Any) -> bool:
    """Does the encoder ``enc`` hold a function symbol over numbers (one
    :func:`finite_witness` would make a table of)?  Without one the witness
    query is the general query and asking it first only costs time."""
    return any(isinstance(s.decl, z3.FuncDeclRef) and _tabled(s.decl) for s in enc.symbols.values())


def _coordinate(d: z3.FuncDeclRef, m: int, v: int) -> z3.ExprRef:
    """``v`` as a value of argument ``m`` of ``d`` (REAL or INTEGER sort)."""
    return z3.RealVal(v, d.ctx) if d.domain(m) == z3.RealSort(d.ctx) else z3.IntVal(v, d.ctx)


def table_point(sorts: Sequence[z3.SortRef], j: int) -> list[z3.ExprRef]:
    """Point ``j`` of a table over arguments of ``sorts`` (each REAL or
    INTEGER): ``(j, 0, ..., 0)``."""
    return [(z3.RealVal if s == z3.RealSort(s.ctx) else z3.IntVal)(j if m == 0 else 0, s.ctx)
            for m, s in enumerate(sorts)]


def table_term(args: Sequence[z3.ExprRef], name: str, result: z3.SortRef,
               points: int) -> tuple[z3.ExprRef, list[z3.ExprRef]]:
    """The finite table of the module docstring applied to ``args`` (each
    of REAL or INTEGER sort): ``If(args == point 0, name!v0, If(...,
    name!else))``.  Returns the term and its free value constants
    ``[name!v0, ..., name!v<points-1>, name!else]`` (of sort ``result``):
    two tables with equal constants are the same function.  Also used for
    the runs of :mod:`rclverify.calculus.requirements.lasso`."""
    values = [z3.Const(f"{name}!v{j}", result) for j in range(points)] + [z3.Const(f"{name}!else", result)]
    body: z3.ExprRef = values[-1]
    for j in range(points):
        pt = table_point([a.sort() for a in args], j)
        body = z3.If(conj(*[a == p for a, p in zip(args, pt)]), values[j], body)
    return body, values


def finite_witness(enc: Any, formulas: Sequence[z3.BoolRef], points: int,
                   budget_ms: int = WITNESS_TIMEOUT_MS, *, deterministic: bool = False,
                   simplified: bool = False) -> Witness:
    """Look for a model of ``formulas`` (and ``enc``'s typing axioms) in
    which every function symbol of ``enc`` over REAL/INTEGER/NATURAL
    arguments is a table of ``points`` points and a default (module
    docstring).  ``budget_ms``: milliseconds' worth of Z3 resource steps.
    ``deterministic``: the query is loaded from its canonical SMT-LIB2 text
    (:func:`rclverify.semantics.retry.load_canonical`), so the search, hence the
    answer within the budget and the model, depends on the query alone, not
    on the Z3 terms the process made before (the refinement check's
    counterexample).  ``simplified``: first ask the query of the tactics
    :data:`SIMPLIFIED` with :data:`SIMPLIFIED_MS`; a model they give counts
    only once confirmed (:func:`_confirmed`: the query with every symbol
    fixed to its value is satisfiable), else the query is asked as without
    it, so nothing it decides is lost.  Returns a :class:`Witness`; never
    raises on solver trouble (an unknown answer is ``inconclusive``)."""
    ctx = z3.Context()  # the process's context is left as it was: its later queries search as before
    subs = []
    tables: dict[str, tuple[str, z3.FuncDeclRef]] = {}
    for name, sym in list(enc.symbols.items()):
        d = sym.decl
        if not isinstance(d, z3.FuncDeclRef) or not _tabled(d):
            continue
        # a FuncDeclRef of the fresh context (translate() hands back a plain AST handle)
        d = z3.FuncDeclRef(z3.Z3_to_func_decl(ctx.ref(), d.translate(ctx).as_ast()), ctx)
        # in z3.substitute_funs, Var(m) stands for argument m (not de Bruijn order)
        body, _ = table_term([z3.Var(j, d.domain(j)) for j in range(d.arity())], name, d.range(), points)
        subs.append((d, body))
        tables[name] = (sym.display, d)
    all_formulas = [f.translate(ctx) for f in list(formulas) + list(enc.axioms())]
    if subs:
        all_formulas = [z3.substitute_funs(f, *subs) for f in all_formulas]
    if simplified and len(tables) == sum(isinstance(x.decl, z3.FuncDeclRef) and x.decl.arity() > 0
                                         for x in enc.symbols.values()):
        s = tactic_solver(SIMPLIFIED_MS, SIMPLIFIED, z3.Context() if deterministic else ctx)
        if deterministic:
            load_canonical(s, all_formulas)
        else:
            s.add(*all_formulas)
        if check(s) == z3.sat and _confirmed(s.assertions(), s.model()):
            m = s.model()
            return Witness("sat", _render(m, enc, tables, points),
                           None if deterministic else _found(m, enc, ctx, tables, points))
    if deterministic:
        s = budgeted_solver(budget_ms, z3.Context())
        load_canonical(s, all_formulas)
        if check(s) != z3.sat:
            return Witness("inconclusive")
    else:
        s = budgeted_solver(budget_ms, ctx)
        if check(s, *all_formulas) != z3.sat:
            return Witness("inconclusive")
        return Witness("sat", _render(s.model(), enc, tables, points), _found(s.model(), enc, ctx, tables, points))
    return Witness("sat", _render(s.model(), enc, tables, points))


def _confirmed(formulas: Sequence[z3.BoolRef], model: z3.ModelRef) -> bool:
    """Is ``model`` (a tactic solver's) a model of ``formulas``, which hold
    no uninterpreted function?  Asked of Z3's default strategy with every
    constant of the formulas fixed to its value in ``model``: only the
    quantified formulas are left to check, on fixed values (a few thousand
    steps on the case study; the budget of :data:`EXTEND_TIMEOUT_MS`)."""
    consts: dict[int, z3.ExprRef] = {}
    for e in _uninterpreted(formulas):
        if e.decl().arity() > 0:
            return False
        consts[e.get_id()] = e
    subs = [(c, model.eval(c, model_completion=True)) for c in consts.values()]
    fixed = [z3.substitute(f, *subs) for f in formulas] if subs else list(formulas)
    s = budgeted_solver(EXTEND_TIMEOUT_MS, model.ctx)
    return bool(check(s, *fixed) == z3.sat)


def _found(model: z3.ModelRef, enc: Any, ctx: z3.Context, tables: dict[str, tuple[str, z3.FuncDeclRef]],
           points: int) -> _Found | None:
    """The substitutions of :class:`_Found` for ``model`` (of ``ctx``);
    ``None`` when ``enc`` has a function symbol that is not a table (its
    interpretation is not fixed here)."""
    funcs = []
    for name, (_, d) in tables.items():
        values = [model.eval(z3.Const(f"{name}!v{j}", d.range()), model_completion=True) for j in range(points)]
        body: z3.ExprRef = model.eval(z3.Const(f"{name}!else", d.range()), model_completion=True)
        args = [z3.Var(j, d.domain(j)) for j in range(d.arity())]
        for j in range(points):
            pt = table_point([a.sort() for a in args], j)
            body = z3.If(conj(*[a == p for a, p in zip(args, pt)]), values[j], body)
        funcs.append((d, body))
    consts = []
    for name, sym in enc.symbols.items():
        d = sym.decl
        if isinstance(d, z3.FuncDeclRef) and d.arity() > 0:
            if name not in tables:
                return None
            continue
        c = d.translate(ctx)
        consts.append((c, model.eval(c, model_completion=True)))
    return _Found(ctx, funcs, consts)


def _fixed_left(formulas: Sequence[z3.ExprRef], f: _Found) -> bool:
    """Is a symbol the witness fixes still free in ``formulas`` after the
    substitutions (a function not replaced by its table, a variable not by
    its value: a declaration the translation did not map onto the
    witness's)?  Then the query would search it too, and its answer would
    not be an extension of the witness."""
    fixed = {d.name() for d, _ in f.funcs} | {c.decl().name() for c, _ in f.consts}
    return any(e.decl().name() in fixed for e in _uninterpreted(formulas))


def _uninterpreted(formulas: Sequence[z3.ExprRef]) -> Iterator[z3.ExprRef]:
    """The applications of uninterpreted symbols (constants and functions)
    in ``formulas``, quantifier bodies included, each shared term once."""
    return (e for e in subterms(formulas) if z3.is_app(e) and e.decl().kind() == z3.Z3_OP_UNINTERPRETED)


def extend(w: Witness, enc: Any, formulas: Sequence[z3.BoolRef], budget_ms: int = EXTEND_TIMEOUT_MS) -> Witness:
    """Does the model of ``w`` (a :func:`finite_witness` answer ``sat`` for
    formulas ``F`` over ``enc``) extend to a model of ``F`` and
    ``formulas``, whose symbols are those of ``F`` and new ones the encoder
    made since (a premise's witness variables)?  Every function and every
    earlier symbol is fixed to its value in ``w``; only the new symbols are
    looked for, a small query (the non-vacuity of a guarantee that fires in
    the consistency check's witness: 0.01 s instead of a new witness's
    0.2-0.4 s on the case study's Agent).  ``sat``: the model of ``w`` with
    the new symbols' values, a model of ``F`` and ``formulas`` (``w``'s
    satisfies ``F``, which does not mention the new symbols);
    ``inconclusive`` otherwise (no such extension, or ``w`` cannot be
    extended), which says nothing about the query.  ``budget_ms``:
    milliseconds' worth of Z3 resource steps."""
    f = w.found
    if w.status != "sat" or f is None or w.model is None:
        return Witness("inconclusive")
    new = [x.translate(f.ctx) for x in list(formulas) + list(enc.axioms())]
    if f.funcs:
        new = [z3.substitute_funs(x, *f.funcs) for x in new]
    if f.consts:
        new = [z3.substitute(x, *f.consts) for x in new]
    if _fixed_left(new, f):
        return Witness("inconclusive")
    s = budgeted_solver(budget_ms, f.ctx)
    if check(s, *new) != z3.sat:
        return Witness("inconclusive")
    added = render_model(s.model(), enc)
    return Witness("sat", {**w.model, **{k: v for k, v in added.items() if k not in w.model}})


def _sort_in(sort: z3.SortRef, ctx: z3.Context) -> z3.SortRef:
    """``sort`` as a sort of ``ctx`` (a model's context, into which the
    query was parsed from text: the same names denote the same sorts)."""
    return z3.Const("__witness_sort", sort).translate(ctx).sort()


def _render(model: z3.ModelRef, enc: Any, tables: dict[str, tuple[str, z3.FuncDeclRef]],
            points: int) -> dict[str, str]:
    """The witness in RCL terms, as :func:`rclverify.semantics.query.render_model`
    shows a model, each tabled function as ``{(0, 0) -> v0, (1, 0) -> v1,
    ..., else -> v}``."""
    out = render_model(model, enc)
    for name, (display, d) in tables.items():
        result = d.range() if d.ctx == model.ctx else _sort_in(d.range(), model.ctx)
        rows = []
        for j in range(points):
            args = ", ".join(value_to_rcl(_coordinate(d, m, j if m == 0 else 0)) for m in range(d.arity()))
            value = model.eval(z3.Const(f"{name}!v{j}", result), model_completion=True)
            rows.append(f"({args}) -> {value_to_rcl(value)}")
        default = model.eval(z3.Const(f"{name}!else", result), model_completion=True)
        rows.append(f"else -> {value_to_rcl(default)}")
        out[display] = "{" + ", ".join(rows) + "}"
    return dict(sorted(out.items()))
