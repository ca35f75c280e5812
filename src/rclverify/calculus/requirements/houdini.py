"""Invariants generated for k-induction: Houdini over bounds from the system's own constants.

k-induction fails on a true property when unreachable states lead to a
violation; an invariant that excludes them, assumed in every state of the
step case, lets it finish (Sheeran, Singh, Stalmarck, FMCAD 2000, "k-induction
with strengthening").  :func:`generate` finds one without the user, by the
Houdini algorithm (Flanagan and Leino, "Houdini, an annotation assistant for
ESC/Java", FME 2001): start from a set of candidate facts and drop every
candidate some initial state violates, then, until no step breaks any, every
candidate a step from a state satisfying all of them breaks.  What survives
is the largest inductive subset of the candidates, an invariant by
construction (the last query is the proof of its induction step).

The candidates are bounds ``v >= c`` and ``v <= c`` for every integer or
real state variable ``v`` and every numeral ``c`` of its sort written in the
initial condition, the step relation or the property (and 0), and ``b`` and
``not b`` for every Boolean ``b``: the facts a counter, a saturation or a mode
flag needs, e.g. ``c <= 15`` for a counter that wraps at 15.  It complements
IC3/PDR (:mod:`.pdr`), which Z3 refuses on a step relation with a quantifier
(function-typed variables): Houdini's queries are ordinary ones.

A solver ``unknown`` in any query leaves no invariant (never a guess).
"""
from __future__ import annotations

from fractions import Fraction
from typing import Callable

import z3

from rclverify.calculus.requirements.tsys import Pred, State, TransitionSystem
from rclverify.semantics import wallclock
from rclverify.semantics.connectives import conj
from rclverify.semantics.subterms import subterms

#: At most this many numerals of each sort, and this many candidates in all.
MAX_NUMERALS = 12
MAX_CANDIDATES = 120

Candidate = tuple[str, Callable[[State], z3.BoolRef]]


def _numerals(exprs: list[z3.ExprRef]) -> dict[str, set[Fraction]]:
    """The integer and real numerals of ``exprs`` (``{"int": ..., "real": ...}``)."""
    out: dict[str, set[Fraction]] = {"int": {Fraction(0)}, "real": {Fraction(0)}}
    for e in subterms(exprs):
        if z3.is_int_value(e):
            out["int"].add(Fraction(e.as_long()))
        elif z3.is_rational_value(e):
            out["real"].add(Fraction(e.as_fraction()))
    return {k: set(sorted(v, key=lambda f: (abs(f), f))[:MAX_NUMERALS]) for k, v in out.items()}


def candidates(ts: TransitionSystem, prop: Pred) -> list[Candidate]:
    """The candidate facts of ``ts`` for property ``prop`` (module
    docstring), each ``(text, predicate over one state)``, at most
    :data:`MAX_CANDIDATES`."""
    a, b = ts.state(0, "hou"), ts.state(1, "hou")
    nums = _numerals([ts.init(a), ts.trans(a, b), prop(a)])
    out: list[Candidate] = []
    for name, sort in ts.sorts.items():
        if sort == z3.BoolSort():
            out += [_fact(name, "==", z3.BoolVal(True)), _fact(name, "==", z3.BoolVal(False))]
        elif sort in (z3.IntSort(), z3.RealSort()):
            kind = "int" if sort == z3.IntSort() else "real"
            for c in sorted(nums[kind]):
                val = z3.IntVal(int(c)) if kind == "int" else z3.RealVal(c)
                out += [_fact(name, ">=", val), _fact(name, "<=", val)]
    return out[:MAX_CANDIDATES]


def _fact(name: str, op: str, val: z3.ExprRef) -> Candidate:
    """The candidate ``name op val`` (``==``, ``>=``, ``<=``) as text and predicate."""
    def holds(s: State) -> z3.BoolRef:
        x = s[name]
        return x == val if op == "==" else (x >= val if op == ">=" else x <= val)
    shown = (name if z3.is_true(val) else f"not {name}") if op == "==" else f"{name} {op} {val}"
    return shown, holds


class _Cut(Exception):
    """A Houdini query the wall-clock safety net stopped (its text says so)."""


def _drop(cands: list[Candidate], query: Callable[[list[Candidate]], tuple[z3.CheckSatResult, z3.ModelRef | None]],
          at: Callable[[z3.ModelRef, Candidate], bool], spent: Callable[[], bool]) -> list[Candidate] | str:
    """Drop candidates until ``query(cands)`` is unsat: each sat model drops
    the candidates ``at`` says it violates.  A string: the solver's reason
    for an unknown, the step budget of all the queries spent (``spent()``),
    or the wall-clock net that cut a query (docs/decisions.md, "Results
    never depend on the wall clock")."""
    while cands:
        if spent():
            return "the step budget of invariant generation was spent"
        try:
            r, m = query(cands)
        except _Cut as exc:
            return f"a Houdini query {exc}"
        if r == z3.unsat:
            return cands
        if r != z3.sat or m is None:
            return ("the step budget of invariant generation was spent" if spent()
                    else f"Z3 could not decide a Houdini query ({r})")
        keep = [c for c in cands if not at(m, c)]
        if len(keep) == len(cands):  # a model that breaks none: cannot happen for a sound solver
            return "a Houdini query's model breaks no candidate"
        cands = keep
    return cands


def generate(ts: TransitionSystem, prop: Pred, timeout_ms: int, budget_ms: int) -> list[Candidate] | str:
    """The largest inductive subset of :func:`candidates` (module
    docstring): every initial state satisfies it and every step from a state
    that satisfies it keeps it.  ``[]``: no candidate survives; a string:
    why no invariant was generated (a solver ``unknown``, the budget spent,
    the wall-clock net).  ``timeout_ms`` bounds each query, ``budget_ms``
    all of them, both as Z3 resource steps (:func:`.wallclock.steps`: the
    same queries decide on a loaded machine)."""
    left = [wallclock.steps(budget_ms)]
    a, b = ts.state(0, "hou"), ts.state(1, "hou")

    def ask(*formulas: z3.BoolRef) -> tuple[z3.CheckSatResult, z3.ModelRef | None]:
        s = z3.Solver()
        wallclock.limit(s, timeout_ms, rlimit=max(1, min(wallclock.steps(timeout_ms), left[0])))
        s.add(*formulas)
        before = wallclock.steps_taken(s)  # the context's counter, before this query
        r, cut = wallclock.check_cut(s)
        left[0] -= wallclock.steps_taken(s) - before
        if cut:
            raise _Cut(wallclock.cut_reason())
        return r, s.model() if r == z3.sat else None

    def initial(cs: list[Candidate]) -> tuple[z3.CheckSatResult, z3.ModelRef | None]:
        return ask(ts.init(a), z3.Not(conj(*[p(a) for _, p in cs])))

    def step(cs: list[Candidate]) -> tuple[z3.CheckSatResult, z3.ModelRef | None]:
        return ask(*[p(a) for _, p in cs], ts.trans(a, b), z3.Not(conj(*[p(b) for _, p in cs])))

    def spent() -> bool:
        return left[0] <= 0
    first = _drop(candidates(ts, prop), initial, lambda m, c: z3.is_false(m.eval(c[1](a), model_completion=True)),
                  spent)
    if isinstance(first, str):
        return first
    last = _drop(first, step, lambda m, c: z3.is_false(m.eval(c[1](b), model_completion=True)), spent)
    return last if isinstance(last, str) else tightest(last)


def tightest(inv: list[Candidate]) -> list[Candidate]:
    """``inv`` without the bounds another of its bounds implies (``c >= -1``
    beside ``c >= 0``): the same invariant, shorter to read."""
    best: dict[tuple[str, str], tuple[Fraction, Candidate]] = {}
    out: list[Candidate] = []
    for cand in inv:
        parts = cand[0].split(" ")
        if len(parts) != 3 or parts[1] not in (">=", "<="):
            out.append(cand)
            continue
        name, op, v = parts[0], parts[1], Fraction(parts[2])
        old = best.get((name, op))
        if old is None or (v > old[0] if op == ">=" else v < old[0]):
            best[(name, op)] = (v, cand)
    return out + [c for _, c in best.values()]


def within(ts: TransitionSystem, inv: list[Candidate]) -> TransitionSystem:
    """``ts`` with the invariant ``inv`` assumed in every state (the same
    reachable states: ``inv`` holds in all of them)."""
    def holds(s: State) -> z3.BoolRef:
        return conj(*[p(s) for _, p in inv])
    return TransitionSystem(ts.sorts, lambda s: conj(ts.init(s), holds(s)),
                            lambda s, t: conj(ts.trans(s, t), holds(s), holds(t)), ts.fairness)
