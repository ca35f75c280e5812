"""Validity and satisfiability queries with Z3, and their explanations.

Every query:

* runs with a per-query budget, given in milliseconds and enforced as Z3
  resource steps (:data:`STEPS_PER_MS`), so the answer does not depend on
  the machine's load; its wall-clock safety net (:mod:`.wallclock`), when
  it fires first, gives ``inconclusive`` with the reason "took longer than
  N s", and no retry is asked in its place (a retry's model would differ
  from the one the budget finds);
* maps Z3's answer to the tool's verdicts without ever upgrading an
  ``unknown``: validity -> ``proved`` (negation unsat) / ``refuted`` (sat,
  with a model) / ``inconclusive`` (unknown or timeout); a query applying
  ``sqrt``/``sin``/``cos`` gets their facts, and a model reading ``sin``/``cos``
  as unknown functions counts only when :func:`.mathfacts.unconfirmed`
  confirms it; unconfirmed, a validity query is asked of cvc5
  (:mod:`.cvc5_math`: its ``unsat`` is ``proved``, strategy :data:`CVC5`),
  else ``inconclusive`` with the reason; satisfiability ->
  ``sat`` (with a model) / ``unsat`` (with an unsat core of the labelled
  formulas) / ``inconclusive``;
* keeps its SMT-LIB2 text so a second solver can re-check it
  (shared/DESIGN.md, "Calculus").

Models are rendered in RCL terms by :func:`render_model`.  The solvers, their
budgets and the solver session are :mod:`rclverify.semantics.solvers`'s
(named here too).
"""
from __future__ import annotations

import time
from contextlib import ExitStack
from dataclasses import dataclass, field
from functools import cached_property
from typing import Callable, Sequence

import z3

from rclverify.semantics.encode import Encoder, term_to_rcl, value_to_rcl
from rclverify.semantics.functable import finite_table
from rclverify.semantics.retry import (DEFAULT, TABLES, attempts, bounded_solver, load_canonical, reasons_text, retry_order,
                    strategy_solver, variants)
from rclverify.semantics import cvc5_math, mathfacts, wallclock
from rclverify.semantics.wallclock import STEPS_PER_MS as STEPS_PER_MS, check, cut_reason, steps as steps
from rclverify.semantics.solvers import budgeted_solver as budgeted_solver, in_session, query_solver as query_solver
from rclverify.semantics.solvers import solver_session as solver_session, tactic_solver as tactic_solver

DEFAULT_TIMEOUT_MS = 10_000
#: the strategy of a validity cvc5 proved where Z3's model read sin/cos as unknown functions (:mod:`.cvc5_math`)
CVC5 = "cvc5 on the real sqrt/sin/cos"


@dataclass(frozen=True)
class QueryResult:
    """Outcome of one query.

    ``status``    ``proved``/``refuted``/``inconclusive`` for validity,
                  ``sat``/``unsat``/``inconclusive`` for satisfiability;
    ``model``     RCL name -> RCL value text (refuted or sat), else ``None``;
    ``core``      labels of the formulas in an unsat core (unsat), else ``None``;
    ``script``    makes the query's SMT-LIB2 script (read it as ``smt2``);
    ``reason``    Z3's reason for ``unknown`` ('' otherwise);
    ``duration_s`` wall time in seconds;
    ``strategy``  the retry of :mod:`.retry` that answered ('' when the
                  first attempt did, or when every attempt was unknown).
    """

    status: str
    script: Callable[[], str] = field(repr=False, compare=False)
    duration_s: float
    model: dict[str, str] | None = None
    core: list[str] | None = None
    reason: str = ""
    strategy: str = ""

    @cached_property
    def smt2(self) -> str:
        """The query as an SMT-LIB2 script, written when first asked for:
        most health queries find nothing and their text is never kept."""
        return self.script()


# STEPS_PER_MS and steps() (a budget in milliseconds' worth of Z3 resource
# steps) and SAFETY_FACTOR (the wall-clock safety net, a multiple of the
# budget) live in rclverify.semantics.wallclock, which also tells the net's
# firing apart; STEPS_PER_MS and steps are re-exported here.


def smt2_script(formulas: Sequence[z3.BoolRef], comment: str) -> Callable[[], str]:
    """A function making the SMT-LIB2 script of ``formulas`` (headed by
    ``comment`` as SMT-LIB comments) when called: most queries' text is
    never kept, and printing it costs more than many queries."""
    return lambda: _script(formulas, comment)


def _script(formulas: Sequence[z3.BoolRef], comment: str) -> str:
    header = "".join(f"; {line}\n" for line in comment.splitlines())
    return header + smtlib_benchmark(formulas)


def smtlib_benchmark(formulas: Sequence[z3.BoolRef], ctx: z3.Context | None = None) -> str:
    """``formulas`` as an SMT-LIB2 script, printed by the Z3 call
    ``z3.Solver.to_smt2()`` makes (``Z3_benchmark_to_smtlib_string``)
    without making a solver: a fresh solver costs about a millisecond, and
    the text of every health query is kept.  The same script as a solver's,
    up to which shared subterms the printer names with ``let`` (it decides
    by reference counts, which a solver holding the formulas raises).
    :func:`.retry.canonical_smt2`, whose text is parsed back and solved,
    keeps printing through a solver.  ``ctx`` is the formulas' context
    (default: the first formula's, else the main context)."""
    c = ctx if ctx is not None else formulas[0].ctx if formulas else z3.main_ctx()
    *init, last = list(formulas) or [z3.BoolVal(True, c)]
    v = (z3.Ast * len(init))(*[f.as_ast() for f in init])
    return str(z3.Z3_benchmark_to_smtlib_string(c.ref(), "benchmark generated from python API", "", "unknown", "",
                                                len(init), v, last.as_ast()))


def prove(goal: z3.BoolRef, hypotheses: Sequence[z3.BoolRef], enc: Encoder | None = None, *,
          timeout_ms: int = DEFAULT_TIMEOUT_MS, comment: str = "", deterministic: bool = False,
          first_ms: float | None = None, likely_sat: Callable[[], bool] | None = None,
          counterexample: Callable[[], dict[str, str] | None] | None = None, models: bool = True) -> QueryResult:
    """Is ``hypotheses => goal`` valid?  Checks ``hypotheses and not goal``.

    ``enc`` (when given) renders a refuting model in RCL terms and adds its
    typing axioms to the hypotheses.  ``deterministic``: run the first
    attempt too in a fresh Z3 context bounded by a resource limit
    (:func:`.retry.bounded_solver`) instead of ``timeout_ms``, so the answer
    does not depend on load or history: the query is loaded from its
    canonical SMT-LIB2 text (:func:`.retry.load_canonical`), so not even
    the calling process's Z3 term ids reach the solver; the model is read
    back through ``enc``'s symbol names, which the text keeps.  Never raises
    on solver trouble: an unknown answer is ``inconclusive`` with Z3's reason.
    ``models=False``: a refuted query's model is not rendered (``model``
    is ``None``), for a caller that reads only the verdict.

    ``first_ms`` (decide first with what decides): the first
    attempt gets only this budget (milliseconds' worth of resource steps);
    a query it decides gets the answer the whole budget would give (a
    resource-bounded search with a smaller bound is a prefix of the same
    search).  Undecided, the strategies follow in the laddered order of
    :func:`.retry.retry_order` (finite instantiation first, then the
    default with its whole budget, then MBQI), each with its whole budget;
    ``likely_sat`` (called only then, e.g. "a finite-table witness of the
    refutation exists") puts the model-building MBQI first.  Not used
    inside a :func:`solver_session` unless ``deterministic`` (a session's
    first attempt is part of its history).

    ``counterexample`` (with ``first_ms``; called only when the first
    attempt did not decide): a more specific search for a refuting model,
    e.g. one in which every function-typed input is a finite table
    (:func:`rclverify.calculus.health.witness.finite_witness`).  Its model (RCL name
    -> value text) must satisfy the hypotheses and the negated goal, so the
    query is ``refuted`` with that model (strategy :data:`.retry.TABLES`)
    without the retries; ``None`` leaves the query to the ladder, in the
    order ``likely_sat`` gives (not asked again when it is the same search).
    """
    hyps = list(hypotheses) + (enc.axioms() if enc else [])
    stated = hyps + [z3.Not(goal)]
    formulas = stated + mathfacts.facts(stated)
    script = smt2_script(formulas, comment or "validity query: unsat means the goal follows from the hypotheses")
    ladder = first_ms is not None and (deterministic or not in_session())
    q = _Validity(formulas, script, enc, deterministic, timeout_ms)
    q.models = models
    q.confirm = stated if mathfacts.transcendental(stated) else None
    with ExitStack() as scope:
        if ladder or deterministic:
            s = q.default(first_ms if ladder else None)
        else:
            s = scope.enter_context(query_solver(timeout_ms))
            s.add(*formulas)
        seen = wallclock.cuts()
        got = q.answered(s, check(s))
        if got is not None:
            return got
        if wallclock.cuts() != seen:  # the clock, not the budget: no retry may answer in its place
            return QueryResult("inconclusive", script, q.elapsed(), reason=cut_reason())
        reasons = {DEFAULT: s.reason_unknown()}
        if ladder and counterexample is not None:
            model = counterexample()
            if model is not None:
                return QueryResult("refuted", script, q.elapsed(), model=model, strategy=TABLES)
        models_first = bool(ladder and likely_sat is not None and likely_sat())
        # the retries inline, not a method: the last solver lives as long as it always did (Z3 reuses the ids
        # of freed terms, and the `let` names of later scripts follow them)
        for name in retry_order(formulas, ladder=ladder, models_first=models_first):
            if name == DEFAULT:
                s2 = q.default(None)
            else:
                s2, rewrite = strategy_solver(name)
                load_canonical(s2, [rewrite(f) for f in formulas])
            got = q.answered(s2, check(s2), "" if name == DEFAULT else name)
            if got is not None:
                return got
            if wallclock.cuts() != seen:
                return QueryResult("inconclusive", script, q.elapsed(), reason=cut_reason())
            reasons[name] = s2.reason_unknown()
        return QueryResult("inconclusive", script, q.elapsed(), reason=reasons_text(reasons))


class _Validity:
    """The attempts of one :func:`prove` query: its ``formulas``
    (hypotheses and the negated goal), the maker of their SMT-LIB2
    ``script`` (:func:`smt2_script`), the
    encoder that renders a model, and the clock started when it was made."""

    def __init__(self, formulas: list[z3.BoolRef], script: Callable[[], str], enc: Encoder | None, deterministic: bool,
                 timeout_ms: int) -> None:
        self.formulas, self.script, self.enc = formulas, script, enc
        self.deterministic, self.timeout_ms = deterministic, timeout_ms
        self.models = True  # render a refuting model (prove's ``models``)
        #: the stated formulas a refuting model must be confirmed on (:func:`.mathfacts.unconfirmed`), or ``None``
        self.confirm: list[z3.BoolRef] | None = None
        self.t0 = time.perf_counter()

    def elapsed(self) -> float:
        """Seconds since the query was made, rounded to 0.1 ms."""
        return round(time.perf_counter() - self.t0, 4)

    def answered(self, s: z3.Solver, r: z3.CheckSatResult, strategy: str = "") -> QueryResult | None:
        """The result for answer ``r`` of solver ``s`` (``strategy`` the
        retry that gave it), or ``None`` when ``r`` is unknown."""
        if r == z3.unsat:
            return QueryResult("proved", self.script, self.elapsed(), strategy=strategy)
        if r == z3.sat and self.confirm is not None:
            why = mathfacts.unconfirmed(self.confirm, s.model())
            if why is not None and cvc5_math.refutes_negation(self.script()):  # cvc5 decides the real functions
                return QueryResult("proved", self.script, self.elapsed(), strategy=CVC5)
            if why is not None:
                return QueryResult("inconclusive", self.script, self.elapsed(), reason=why, strategy=strategy)
        if r == z3.sat:
            return QueryResult("refuted", self.script, self.elapsed(),
                               model=render_model(s.model(), self.enc) if self.models else None,
                               strategy=strategy)
        return None

    def default(self, budget_ms: float | None) -> z3.Solver:
        """The first attempt's solver with the query in it (``None``: its whole budget)."""
        if self.deterministic:
            s = bounded_solver() if budget_ms is None else bounded_solver(rlimit=steps(budget_ms))
            load_canonical(s, self.formulas)
        else:
            s = budgeted_solver(budget_ms if budget_ms is not None else self.timeout_ms)
            s.add(*self.formulas)
        return s


def satisfiable(labelled: Sequence[tuple[str, z3.BoolRef]], enc: Encoder | None = None, *,
                timeout_ms: int = DEFAULT_TIMEOUT_MS, comment: str = "", retry: bool = True) -> QueryResult:
    """Can all the labelled formulas hold together?

    ``retry``: on ``unknown``, try the strategies of :mod:`.retry` (off for
    the many small per-instance queries whose caller has its own fallback).

    On ``unsat`` the result's ``core`` lists the labels of an unsat core
    (the encoder's typing axioms are unlabelled background).
    """
    background = enc.axioms() if enc else []
    stated = background + [f for _, f in labelled]
    confirm = stated if mathfacts.transcendental(stated) else None
    background = background + mathfacts.facts(stated)
    with query_solver(timeout_ms, cores=True) as s:
        s.add(*background)
        trackers = {}
        for k, (label, f) in enumerate(labelled):
            b = z3.Bool(f"__label_{k}")
            trackers[f"__label_{k}"] = label
            s.assert_and_track(f, b)
        t0 = time.perf_counter()
        seen = wallclock.cuts()
        r = check(s)
        dt = round(time.perf_counter() - t0, 4)
        script = smt2_script(background + [f for _, f in labelled], comment or "satisfiability query")
        if wallclock.cuts() != seen:  # the clock, not the budget: no retry may answer in its place
            return QueryResult("inconclusive", script, dt, reason=cut_reason())
        if r == z3.sat and confirm is not None and (why := mathfacts.unconfirmed(confirm, s.model())) is not None:
            return QueryResult("inconclusive", script, dt, reason=why)
        if r == z3.sat:
            return QueryResult("sat", script, dt, model=render_model(s.model(), enc))
        if r == z3.unsat:
            # a tracker's name read from the core, not printed (Z3's Python printer: 0.1 ms a tracker)
            core = sorted({trackers[n] for c in s.unsat_core() if (n := c.decl().name()) in trackers},
                          key=[lbl for lbl, _ in labelled].index)
            return QueryResult("unsat", script, dt, core=core)
        reasons = [f"default: {s.reason_unknown()}"]
        labels = [lbl for lbl, _ in labelled]
        for name0, s0, rewrite in attempts(background + [f for _, f in labelled], timeout_ms) if retry else []:
            for name, s2 in variants(name0, s0):
                # loaded untracked from canonical text (tracking changes Z3's search)
                load_canonical(s2, [rewrite(g) for g in background + [f for _, f in labelled]])
                r = check(s2)
                dt = round(time.perf_counter() - t0, 4)
                if wallclock.cuts() != seen:
                    return QueryResult("inconclusive", script, dt, reason=cut_reason())
                if r == z3.sat and confirm is not None and (why := mathfacts.unconfirmed(confirm, s2.model())):
                    return QueryResult("inconclusive", script, dt, reason=why, strategy=name)
                if r == z3.sat:
                    return QueryResult("sat", script, dt, model=render_model(s2.model(), enc), strategy=name)
                if r == z3.unsat:
                    tracked = _retry_core(background, labelled, rewrite)
                    core = tracked if tracked is not None else labels
                    return QueryResult("unsat", script, round(time.perf_counter() - t0, 4), core=core, strategy=name)
                reasons.append(f"{name}: {s2.reason_unknown()}")
        return QueryResult("inconclusive", script, dt, reason="; ".join(reasons) if len(reasons) > 1 else s.reason_unknown())


def _retry_core(background: Sequence[z3.BoolRef], labelled: Sequence[tuple[str, z3.BoolRef]],
                rewrite: Callable[[z3.BoolRef], z3.BoolRef]) -> list[str] | None:
    """Labels of an unsat core of a query a retry found unsat: the formulas
    tracked as ``label -> formula`` and checked under the labels, in a fresh
    bounded context; ``None`` when that check is not ``unsat`` (the caller
    then names every label, which is a core too)."""
    s = bounded_solver()
    s.set("smt.ematching", False)
    s.set("unsat_core", True)
    load_canonical(s, [rewrite(f) for f in background]
                   + [z3.Implies(z3.Bool(f"__label_{k}", f.ctx), rewrite(f)) for k, (_, f) in enumerate(labelled)])
    if check(s, *[z3.Bool(f"__label_{k}", s.ctx) for k in range(len(labelled))]) != z3.unsat:
        return None
    found = {str(c) for c in s.unsat_core()}
    return [lbl for k, (lbl, _) in enumerate(labelled) if f"__label_{k}" in found]


def render_model(model: z3.ModelRef, enc: Encoder | None) -> dict[str, str]:
    """The free symbols of ``enc`` (or every declaration of ``model``) in RCL terms.

    Constants map to their value (``green``, ``move(0.5, 1)``); functions to a
    finite table ``{(0, 0) -> 3, else -> 0}``.  Names are the RCL names of the
    symbols (``Agent.in.wayP``).
    """
    out: dict[str, str] = {}
    decls = {d.name(): d for d in model.decls()}
    names = ({n: s.display for n, s in enc.symbols.items()} if enc else {n: n for n in decls})
    for z3name, display in sorted(names.items(), key=lambda kv: kv[1]):
        d = decls.get(z3name)
        if d is None:
            continue
        if d.arity() == 0:
            out[display] = value_to_rcl(model.eval(d(), model_completion=True))
            continue
        interp = model[d]
        if not isinstance(interp, z3.FuncInterp):
            out[display] = str(interp)
            continue
        rows = []
        for k in range(interp.num_entries()):
            e = interp.entry(k)
            args = ", ".join(value_to_rcl(e.arg_value(j)) for j in range(e.num_args()))
            rows.append(f"({args}) -> {value_to_rcl(e.value())}")
        else_v = interp.else_value()
        params = [z3.Const(f"p{j + 1}", d.domain(j)) for j in range(d.arity())]
        if else_v is None:
            rows.append("else -> ?")
        elif z3.is_app(else_v) and else_v.num_args() == 0 or z3.is_rational_value(else_v) or z3.is_int_value(else_v):
            rows.append(f"else -> {value_to_rcl(else_v)}")
        else:
            table = finite_table(model, d, else_v, value_to_rcl)
            if table is not None:  # an exact table: the points that differ, then the value elsewhere
                rows = [f"({args}) -> {v}" for args, v in table[0]] + [f"else -> {table[1]}"]
            else:
                # Var(j) of a function interpretation stands for argument j (first to last)
                body = z3.substitute_vars(else_v, *params) if params else else_v
                rows.append(f"({', '.join(map(str, params))}) -> {term_to_rcl(body)}")
        out[display] = "{" + ", ".join(rows) + "}"
    return out
