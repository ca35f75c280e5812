"""Second attempts at a query Z3 answered ``unknown`` on.

Quantified formulas are where Z3 gives up.  Before a query is reported
``inconclusive`` (logic/query.py), it is retried, in this order, each with
a deterministic resource limit (:data:`RETRY_RLIMIT`):

``finite instantiation``
    every quantifier whose bound variables all range over finite sorts
    (enumerations, BOOL) is replaced by the conjunction (``forall``) or
    disjunction (``exists``) of its instances.  This is an equivalence, so
    the answer means the same.
``model-based quantifier instantiation``
    the same formulas with e-matching switched off (``smt.ematching=false``),
    so Z3 instantiates quantifiers only from candidate models (MBQI; de
    Moura and Bjorner, "Efficient E-matching for SMT solvers" and the Z3
    guide's section on quantifiers).  Often finds models for satisfiable
    quantified formulas that the default strategy times out on.

A retry never changes what an answer means: unsat is still unsat, sat still
comes with a model.  The strategy that answered is recorded on the result
(``QueryResult.strategy``) and shown in the report.
"""
from __future__ import annotations

import itertools
from typing import Callable, Sequence

import z3

#: Each retry is bounded by Z3's deterministic resource counter (``rlimit``),
#: not by wall-clock time, so its answer does not depend on the machine's load
#: (a serial and a parallel run agree).  About 2-5 s on one idle core; the
#: wall-clock timeout is only a safety net far above it.
RETRY_RLIMIT = 6_000_000
SAFETY_TIMEOUT_MS = 120_000

FINITE = "finite instantiation"
MBQI = "model-based quantifier instantiation"
#: At most this many instances per quantifier are written out.
MAX_INSTANCES = 256


def _finite_values(s: z3.SortRef) -> list[z3.ExprRef] | None:
    if s.kind() == z3.Z3_BOOL_SORT:
        return [z3.BoolVal(False), z3.BoolVal(True)]
    if isinstance(s, z3.DatatypeSortRef):
        cons = [s.constructor(k) for k in range(s.num_constructors())]
        if cons and all(c.arity() == 0 for c in cons):
            return [c() for c in cons]
    return None


def expand_finite(e: z3.ExprRef) -> z3.ExprRef:
    """``e`` with every quantifier over finite sorts only written out
    (innermost first); other quantifiers are kept, with their bodies
    expanded.  Equivalent to ``e``."""
    if z3.is_quantifier(e):
        q = e
        body = expand_finite(q.body())
        if q.is_lambda():
            return e
        domains = [_finite_values(q.var_sort(k)) for k in range(q.num_vars())]
        if all(d is not None for d in domains):
            combos = list(itertools.islice(itertools.product(*[d for d in domains if d is not None]),
                                           MAX_INSTANCES + 1))
            if len(combos) <= MAX_INSTANCES:
                # de Bruijn: variable 0 is the last bound one
                insts = [z3.substitute_vars(body, *reversed(c)) for c in combos]
                return z3.And(*insts) if q.is_forall() else z3.Or(*insts)
        if body.eq(q.body()):
            return e
        names = [z3.FreshConst(q.var_sort(k), q.var_name(k)) for k in range(q.num_vars())]
        inner = z3.substitute_vars(body, *reversed(names))
        return z3.ForAll(names, inner) if q.is_forall() else z3.Exists(names, inner)
    if z3.is_app(e) and e.num_args() > 0:
        kids = [expand_finite(c) for c in e.children()]
        return e.decl()(*kids)
    return e


def _has_quantifier(e: z3.ExprRef) -> bool:
    todo, seen = [e], set()
    while todo:
        x = todo.pop()
        if x.get_id() in seen:
            continue
        seen.add(x.get_id())
        if z3.is_quantifier(x):
            return True
        if z3.is_app(x):
            todo.extend(x.children())
    return False


def bounded_solver() -> z3.Solver:
    """A solver in a fresh Z3 context (so the answer does not depend on what
    the process encoded before) bounded by :data:`RETRY_RLIMIT`."""
    s = z3.Solver(ctx=z3.Context())
    s.set("rlimit", RETRY_RLIMIT)
    s.set("timeout", SAFETY_TIMEOUT_MS)
    return s


def attempts(formulas: Sequence[z3.BoolRef], timeout_ms: int
             ) -> list[tuple[str, z3.Solver, Callable[[z3.BoolRef], z3.BoolRef]]]:
    """The retries that apply to ``formulas`` (none without a quantifier):
    ``(strategy name, configured solver, rewrite of each formula)``.
    ``timeout_ms`` (the first attempt's) is not used: retries are bounded by
    :data:`RETRY_RLIMIT` so that their answers are reproducible."""
    if not any(_has_quantifier(f) for f in formulas):
        return []
    out: list[tuple[str, z3.Solver, Callable[[z3.BoolRef], z3.BoolRef]]] = []
    changed = [expand_finite(f) for f in formulas]
    if any(not a.eq(b) for a, b in zip(changed, formulas)):
        s = bounded_solver()
        out.append((FINITE, s, _translating(s.ctx, expand_finite)))
    s = bounded_solver()
    s.set("smt.ematching", False)
    out.append((MBQI, s, _translating(s.ctx, lambda f: f)))
    return out


def _translating(ctx: z3.Context, rewrite: Callable[[z3.BoolRef], z3.BoolRef]
                 ) -> Callable[[z3.BoolRef], z3.BoolRef]:
    """``rewrite`` followed by translation into the solver's context ``ctx``."""
    def apply(f: z3.BoolRef) -> z3.BoolRef:
        return rewrite(f).translate(ctx)
    return apply
