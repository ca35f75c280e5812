"""Lassos whose function-typed variables are finite tables.

An unbounded ``eventually P`` is refuted by a lasso: a run s0..sn missing
``P`` with sn == sj (:func:`rclverify.calculus.requirements.temporal.find_lasso`).
Over contracts with function-typed inputs over the reals (the case study's
``wayP : REAL x REAL --> NATURAL``, ``at``, ``position``) Z3 often cannot
decide even one state of that query: every state is an array constrained by
quantified guarantees.  This module asks the same query in a restricted
space: at every step each function-typed variable over REAL/INTEGER
arguments is a *finite table*, the ``ite`` chain over ``points`` points with
a default of :func:`rclverify.calculus.health.witness.table_term` (the shape the
health checks' consistency witnesses have).  A finite table is a function,
so a run found in the restricted space is a run of the unrestricted system:
a lasso found there is a genuine counterexample.  Finding none says nothing
(``None``); the caller's verdict stays ``inconclusive``.

Each query is solved in a Z3 context of its own, with a budget in resource
steps (:func:`rclverify.semantics.query.budgeted_solver`), so the answer does
not depend on the machine's load and the process's context is left as it
was.  The model is read back as concrete values (:mod:`rclverify.semantics.values`:
a table is a :class:`~rclverify.semantics.values.FiniteFunction`), which
:mod:`.lasso_confirm` checks independently before a refutation is reported.

Source of the rule: a lasso is a counterexample to a liveness property
(Biere, Cimatti, Clarke, Zhu, TACAS 1999, bounded model checking of LTL);
the table shape is the health checks' (docs/contract-health.md).
"""
from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from typing import Any, Callable, Mapping

import z3

from rclverify.calculus.health.witness import table_point, table_term
from rclverify.semantics.connectives import conj, disj
from rclverify.semantics.query import budgeted_solver, tactic_solver
from rclverify.semantics import wallclock
from rclverify.lang.types import DataT, EnumT, FuncT, Type
from rclverify.semantics.values import FiniteFunction, Term
from rclverify.calculus.requirements.temporal import Pred, State, TransitionSystem
from rclverify.calculus.requirements.tsys import FairLoops

#: Budget of one lasso query (ms worth of Z3 resource steps).
LASSO_BUDGET_MS = 5_000
#: The Z3 tactics a lasso query is first given to: ``qe-light`` eliminates
#: the quantified variables an equality fixes (the tables' point tests),
#: ``solve-eqs`` the state constants a transition fixes, then the SMT core.
#: The case study's REQ4 at length 2: sat in 0.3 s where Z3's default
#: strategy takes 2.5 s.  Tactics keep satisfiability both ways, so their
#: ``unsat`` moves on to the next length and their ``sat`` is a lasso (its
#: model read back through the tactics' model converters and confirmed on
#: its values by :mod:`.lasso_confirm`, as every lasso is).
TACTICS = ("qe-light", "simplify", "solve-eqs", "smt")
#: Budget of that first attempt (ms worth of Z3 resource steps); an
#: ``unknown`` there leaves the query to the default strategy with
#: :data:`LASSO_BUDGET_MS`, so nothing the default strategy decides is lost.
TACTICS_BUDGET_MS = 2_000


@dataclass
class TableLasso:
    """A lasso found with finite tables: ``values`` one ``{variable:
    value}`` per step (values of :mod:`rclverify.semantics.values`), the last state
    equal to state ``loop``; ``points`` the table size used."""

    values: list[dict[str, Any]]
    loop: int
    points: int


def _tabled(s: z3.SortRef) -> bool:
    if not isinstance(s, z3.ArraySortRef):
        return False
    n = z3.Z3_get_array_arity(s.ctx_ref(), s.ast)
    return all(s.domain_n(m) in (z3.RealSort(s.ctx), z3.IntSort(s.ctx)) for m in range(n))


def _arity(s: z3.ArraySortRef) -> int:
    return int(z3.Z3_get_array_arity(s.ctx_ref(), s.ast))


def table_state(ts: TransitionSystem, step: int, points: int) -> tuple[State, dict[str, list[z3.ExprRef]]]:
    """The state at ``step`` with every array variable over numbers a
    finite table (an array-valued ``lambda`` over the table's value
    constants).  Returns the state and, per variable, the constants that
    fix its value (a scalar: itself)."""
    state: State = {}
    keys: dict[str, list[z3.ExprRef]] = {}
    for name, s in ts.sorts.items():
        if _tabled(s):
            xs = [z3.Const(f"{name}@{step}!x{m}", s.domain_n(m)) for m in range(_arity(s))]
            body, values = table_term(xs, f"{name}@{step}", s.range(), points)
            lam = z3.Lambda(xs, body)
            state[name] = z3.ArrayRef(lam.as_ast(), lam.ctx)  # an array term: Select applies it
            keys[name] = values
        else:
            state[name] = z3.Const(f"{name}@{step}", s)
            keys[name] = [state[name]]
    return state, keys


def to_value(v: z3.ExprRef, t: Type) -> Any:
    """A Z3 model value of RCL type ``t`` as a value of :mod:`rclverify.semantics.values`.
    Raises ``ValueError`` for a value it cannot read (an irrational real)."""
    if z3.is_true(v) or z3.is_false(v):
        return z3.is_true(v)
    if z3.is_int_value(v):
        return v.as_long()
    if z3.is_rational_value(v):
        f = Fraction(v.numerator_as_long(), v.denominator_as_long())
        return f.numerator if f.denominator == 1 else f
    if isinstance(t, EnumT):
        return v.decl().name()
    if isinstance(t, DataT):
        name = v.decl().name()
        args = dict(t.ctors)[name]
        return Term(name, tuple(to_value(c, a) for c, a in zip(v.children(), args)))
    raise ValueError(f"cannot read the model value {v} of type {t}")


def _table_value(m: z3.ModelRef, values: list[z3.ExprRef], t: FuncT, sorts: list[z3.SortRef]) -> FiniteFunction:
    default = to_value(m.eval(values[-1], model_completion=True), t.result)
    table = {}
    for j, c in enumerate(values[:-1]):
        v = to_value(m.eval(c, model_completion=True), t.result)
        key = tuple(to_value(p, a) for p, a in zip(table_point(sorts, j), t.args))
        if v != default and key not in table:
            table[key] = v
    return FiniteFunction(table, default, len(t.args))


def _solve(formulas: list[z3.BoolRef], ctx: z3.Context, budget_ms: int) -> tuple[Any, bool, z3.Solver]:
    """Decide ``formulas`` (of ``ctx``): first with :data:`TACTICS`
    (at most :data:`TACTICS_BUDGET_MS`), then, where they answered
    ``unknown``, with Z3's default strategy and ``budget_ms``.  Returns the
    answer, whether the wall-clock net cut it, and the solver that gave it
    (its ``model()`` when ``sat``)."""
    tactic = tactic_solver(min(budget_ms, TACTICS_BUDGET_MS), TACTICS, ctx)
    tactic.add(*formulas)  # asserted, not assumed: the tactics preprocess assertions only
    r, cut = wallclock.check_cut(tactic)
    if r != z3.unknown:
        return r, cut, tactic
    solver = budgeted_solver(budget_ms, ctx)
    r, cut = wallclock.check_cut(solver, *formulas)
    return r, cut, solver


def find_table_lasso(ts: TransitionSystem, prop: Pred, types: Mapping[str, Type], *, bound: int, points: int,
                     budget_ms: int = LASSO_BUDGET_MS,
                     extra: Callable[[State], z3.BoolRef] | None = None) -> TableLasso | str:
    """Search lassos s0..sn (n = 1..``bound``) missing ``prop`` with every
    array variable over numbers a table of ``points`` points (module
    docstring), whose loop meets the fairness constraints of ``ts``.  ``types`` gives each variable's RCL type (to read the
    model back).  Returns the :class:`TableLasso` of the shortest one found,
    or a sentence saying what was tried (no lasso of that shape up to the
    bound, or the solver's unknown at length n)."""
    fair = FairLoops(ts)
    for n in range(1, bound + 1):
        steps = [table_state(ts, i, points) for i in range(n + 1)]
        states = [s for s, _ in steps]
        same = [conj(*[a == b for v in ts.sorts for a, b in zip(steps[n][1][v], steps[j][1][v])],
                       fair.loop(states, j, n)) for j in range(n)]
        formulas = [ts.init(states[0]), *[ts.trans(states[i], states[i + 1]) for i in range(n)],
                    *[z3.Not(prop(s)) for s in states], disj(*same)]
        ctx = z3.Context()
        r, cut, solver = _solve([f.translate(ctx) for f in formulas], ctx, budget_ms)
        if r == z3.unknown:  # the budget's reason, or the net's when the clock cut it (never another length)
            why = wallclock.why_unknown(solver, cut)
            return (f"no lasso of up to {n - 1} steps with {points}-point tables; at {n} steps the solver "
                    f"answered unknown ({why})")
        if r == z3.unsat:
            continue
        m = solver.model()
        loop = next(j for j in range(n) if z3.is_true(m.eval(same[j].translate(ctx), model_completion=True)))
        out = []
        for _, keys in steps:
            row: dict[str, Any] = {}
            for v, s in ts.sorts.items():
                cs = [c.translate(ctx) for c in keys[v]]
                t = types[v]
                if _tabled(s) and isinstance(t, FuncT):
                    row[v] = _table_value(m, cs, t, [s.domain_n(k) for k in range(_arity(s))])
                else:
                    row[v] = to_value(m.eval(cs[0], model_completion=True), t)
            out.append(row)
        return TableLasso(out, loop, points)
    return f"no lasso of up to {bound} steps with {points}-point tables"
