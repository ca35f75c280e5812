"""Second attempts at a query Z3 answered ``unknown`` on.

Quantified formulas are where Z3 gives up.  Before a query is reported
``inconclusive`` (semantics/query.py), it is retried, in this order, each with
a deterministic resource limit (:data:`RETRY_RLIMIT`):

``finite instantiation``
    every quantifier's bound variables of finite sorts (enumerations, BOOL)
    are replaced by the conjunction (``forall``) or disjunction (``exists``)
    of its instances, and those of a non-recursive constructor set by one
    case per constructor with its arguments bound instead (written out in
    turn when finite; :func:`expand_finite`).  This is an equivalence, so
    the answer means the same.
``model-based quantifier instantiation``
    the same formulas with e-matching switched off (``smt.ematching=false``),
    so Z3 instantiates quantifiers only from candidate models (MBQI; de
    Moura and Bjorner, "Efficient E-matching for SMT solvers" and the Z3
    guide's section on quantifiers).  Often finds models for satisfiable
    quantified formulas that the default strategy times out on.

    When that runs out too, the same once more after Z3's ``simplify``
    tactic on the whole query (:func:`variants`; strategy name
    :data:`MBQI_SIMPLIFIED`): which of the two finds a model within the
    limit varies from query to query (on the case study the contract
    consistency check needs the first, the replacement check the second).

A retry never changes what an answer means: unsat is still unsat, sat still
comes with a model.  The strategy that answered is recorded on the result
(``QueryResult.strategy``) and shown in the report.
"""
from __future__ import annotations

import itertools
from typing import Callable, Sequence, cast

import z3

from rclverify.semantics.connectives import conj, disj
from rclverify.semantics.subst import substitute
from rclverify.semantics.wallclock import note_limit

#: Each retry is bounded by Z3's deterministic resource counter (``rlimit``),
#: not by wall-clock time, so its answer does not depend on the machine's load
#: (a serial and a parallel run agree).  About 2-5 s on one idle core; the
#: wall-clock timeout is only a safety net far above it.
RETRY_RLIMIT = 6_000_000
SAFETY_TIMEOUT_MS = 120_000

FINITE = "finite instantiation"
MBQI = "model-based quantifier instantiation"
MBQI_SIMPLIFIED = "model-based quantifier instantiation after simplification"
#: At most this many instances per quantifier are written out.
MAX_INSTANCES = 256


def finite_values(s: z3.SortRef) -> list[z3.ExprRef] | None:
    """Every value of a finite sort (BOOL, an enumeration), else ``None``."""
    if s.kind() == z3.Z3_BOOL_SORT:
        return [z3.BoolVal(False), z3.BoolVal(True)]
    if isinstance(s, z3.DatatypeSortRef):
        cons = [s.constructor(k) for k in range(s.num_constructors())]
        if cons and all(c.arity() == 0 for c in cons):
            return [c() for c in cons]
    return None


def _cases(v: z3.ExprRef, tag: str) -> list[tuple[z3.ExprRef, list[z3.ExprRef]]] | None:
    """The cases a bound variable ``v`` splits into: ``(value, new bound
    variables in it)``.  A finite sort gives its values; a constructor set
    that is not recursive gives one case per constructor, applied to new
    variables for its arguments (every value of a datatype is some
    constructor applied to arguments); other sorts give ``None``."""
    s = v.sort()
    values = finite_values(s)
    if values is not None:
        return [(x, []) for x in values]
    if isinstance(s, z3.DatatypeSortRef) and s.num_constructors() > 0:
        ctors = [s.constructor(k) for k in range(s.num_constructors())]
        if any(c.domain(j) == s for c in ctors for j in range(c.arity())):
            return None  # recursive: splitting would not end
        out: list[tuple[z3.ExprRef, list[z3.ExprRef]]] = []
        for c in ctors:
            args = [z3.Const(f"{tag}_{c.name()}_{j}", c.domain(j)) for j in range(c.arity())]
            out.append((c(*args), args))
        return out
    return None


def expand_finite(e: z3.ExprRef, depth: int = 0) -> z3.ExprRef:
    """``e`` (a closed formula) with every quantifier over finite sorts
    written out, and every bound variable of a (non-recursive) constructor
    set split into one case per constructor, whose arguments are bound
    instead (and written out in turn when their sorts are finite); other
    bound variables stay quantified.  Equivalent to ``e``.

    Each quantifier is opened top-down: its bound variables become constants
    named ``<name>!q<depth>_<k>`` (``!`` never occurs in an encoder's name, and
    the depth keeps nested binders apart), so a body never holds a loose de
    Bruijn index, and the names depend on the formula only (``FreshConst``'s
    counter would carry the process's history into the query).  ``depth`` is
    the number of enclosing binders (internal).  At most
    :data:`MAX_INSTANCES` instances are written per quantifier; beyond that
    it is kept.  Each distinct subterm is expanded once per depth (a
    transition relation shares its states' validity many times over; walked
    as a tree, that was most of a deadlock check's time).
    """
    return _expand(e, depth, {})


#: The memo of one :func:`expand_finite` call: (term id, depth) -> (the term, its expansion).  It holds
#: each term it is keyed by, so no id is reused for another term while the call runs (the bodies opened
#: on the way are not subterms of the root).
_Memo = dict[tuple[int, int], tuple[z3.ExprRef, z3.ExprRef]]


def _expand(e: z3.ExprRef, depth: int, memo: _Memo) -> z3.ExprRef:
    """:func:`expand_finite` of ``e`` at ``depth``, with ``memo``."""
    key = (e.get_id(), depth)
    hit = memo.get(key)
    if hit is None:
        hit = memo[key] = (e, _expand_once(e, depth, memo))
    return hit[1]


def _expand_once(e: z3.ExprRef, depth: int, memo: _Memo) -> z3.ExprRef:
    if z3.is_quantifier(e):
        q = e
        if q.is_lambda():
            return e
        names = [z3.Const(f"{q.var_name(k)}!q{depth}_{k}", q.var_sort(k)) for k in range(q.num_vars())]
        # de Bruijn: variable 0 is the last bound one
        opened = z3.substitute_vars(q.body(), *reversed(names))
        body = _expand(opened, depth + 1, memo)
        cases = [_cases(v, f"{v}") for v in names]
        split = [k for k, c in enumerate(cases) if c is not None]
        if split:
            combos = list(itertools.islice(itertools.product(*[cases[k] or [] for k in split]), MAX_INSTANCES + 1))
            if len(combos) <= MAX_INSTANCES:
                kept = [v for k, v in enumerate(names) if cases[k] is None]
                insts = []
                for combo in combos:
                    inst = substitute(body, [(names[k], val) for k, (val, _) in zip(split, combo)])
                    bound = kept + [a for _, args in combo for a in args]
                    if not bound:
                        insts.append(inst)
                        continue
                    inner = z3.ForAll(bound, inst) if q.is_forall() else z3.Exists(bound, inst)
                    insts.append(_expand(inner, depth + 1, memo) if any(args for _, args in combo) else inner)
                return conj(*insts) if q.is_forall() else disj(*insts)
        if body.eq(opened):
            return e
        return z3.ForAll(names, body) if q.is_forall() else z3.Exists(names, body)
    if z3.is_app(e) and e.num_args() > 0:
        kids = [_expand(c, depth, memo) for c in e.children()]
        return e.decl()(*kids)
    return e


def has_quantifier(e: z3.ExprRef) -> bool:
    """Does ``e`` hold a quantifier anywhere (shared subterms visited once)?
    Walked with Z3's low-level API on the raw terms, as
    :func:`rclverify.semantics.modeltext.term_to_rcl` does: no Python wrapper
    object per subterm."""
    c = e.ctx.ref()
    ast_id, kind, n_args, arg = z3.Z3_get_ast_id, z3.Z3_get_ast_kind, z3.Z3_get_app_num_args, z3.Z3_get_app_arg
    todo, seen = [e.as_ast()], set()
    while todo:
        a = todo.pop()
        i = ast_id(c, a)
        if i in seen:
            continue
        seen.add(i)
        k = kind(c, a)
        if k == z3.Z3_QUANTIFIER_AST:
            return True
        if k == z3.Z3_APP_AST:
            todo.extend(arg(c, a, j) for j in range(n_args(c, a)))
    return False


def bounded_solver(*tactics: str, rlimit: int = RETRY_RLIMIT) -> z3.Solver:
    """A solver in a fresh Z3 context (so the answer does not depend on what
    the process encoded before) bounded by ``rlimit`` resource steps
    (default :data:`RETRY_RLIMIT`); with ``tactics`` (Z3 tactic names, e.g.
    ``"simplify", "smt"``), the solver runs them in sequence (models are
    mapped back to the query's symbols).  Its wall-clock safety net,
    :data:`SAFETY_TIMEOUT_MS`, is registered with
    :func:`.wallclock.note_limit`: a check it cuts counts as cut, never
    as the budget's ``unknown``."""
    ctx = z3.Context()
    s = z3.Then(*tactics, ctx=ctx).solver() if len(tactics) > 1 else z3.Solver(ctx=ctx)
    s.set("rlimit", rlimit)
    note_limit(s, SAFETY_TIMEOUT_MS)
    return s


def canonical_smt2(formulas: Sequence[z3.BoolRef]) -> str:
    """``formulas`` as SMT-LIB2 text that depends only on their structure.

    Z3's printer names and orders shared subterms by term id, and ids are
    history of the process (what it encoded before); so, measurably, is the
    search of a solver whose context was filled by ``translate`` from the
    process's context.  The formulas are first copied into a fresh context,
    where ids follow the formulas' structure alone, and printed there.
    """
    ctx = z3.Context()
    s = z3.Solver(ctx=ctx)
    s.add(*[f.translate(ctx) for f in formulas])
    return str(s.to_smt2())


def load_canonical(s: z3.Solver, formulas: Sequence[z3.BoolRef]) -> None:
    """Assert ``formulas`` in ``s`` (a solver of its own fresh context) by
    parsing :func:`canonical_smt2`, so the solver's state, and hence its
    answer under a resource limit, is a function of the query alone."""
    s.from_string(canonical_smt2(formulas))


def attempts(formulas: Sequence[z3.BoolRef], timeout_ms: int
             ) -> list[tuple[str, z3.Solver, Callable[[z3.BoolRef], z3.BoolRef]]]:
    """The retries that apply to ``formulas`` (none without a quantifier):
    ``(strategy name, configured solver, rewrite of each formula)``.  The
    rewrite stays in the formulas' context; load its results into the
    solver with :func:`load_canonical`.
    ``timeout_ms`` (the first attempt's) is not used: retries are bounded by
    :data:`RETRY_RLIMIT` so that their answers are reproducible."""
    if not any(has_quantifier(f) for f in formulas):
        return []
    out: list[tuple[str, z3.Solver, Callable[[z3.BoolRef], z3.BoolRef]]] = []
    changed = [expand_finite(f) for f in formulas]
    if any(not a.eq(b) for a, b in zip(changed, formulas)):
        s = bounded_solver()
        out.append((FINITE, s, lambda f: cast(z3.BoolRef, expand_finite(f))))
    s = bounded_solver()
    s.set("smt.ematching", False)
    out.append((MBQI, s, lambda f: f))
    return out


def variants(name: str, s: z3.Solver) -> list[tuple[str, z3.Solver]]:
    """The solvers to try, in order, for the retry ``name`` whose configured
    solver is ``s``: ``s`` itself, and for MBQI also MBQI after Z3's
    ``simplify`` tactic (:data:`MBQI_SIMPLIFIED`), each in its own fresh,
    resource-bounded context."""
    out = [(name, s)]
    if name == MBQI:
        s2 = bounded_solver("simplify", "smt")
        s2.set("smt.ematching", False)
        out.append((MBQI_SIMPLIFIED, s2))
    return out


#: A refuting model in which every function-typed input is a finite table
#: (calculus/health/witness.py), found before any retry (``prove``'s ``counterexample``).
TABLES = "a counterexample in which every function-typed input is a finite table"
#: The name of Z3's default strategy (the first attempt) in a retry order.
DEFAULT = "default"
#: Every strategy, in the order their reasons for giving up are reported.
REPORTED = (DEFAULT, FINITE, MBQI, MBQI_SIMPLIFIED)


def retry_order(formulas: Sequence[z3.BoolRef], *, ladder: bool, models_first: bool = False) -> list[str]:
    """The strategies to try, in order, after a first attempt at
    ``formulas`` answered ``unknown``.

    Without ``ladder`` (the first attempt had the query's whole budget):
    the retries of the module docstring, finite instantiation (when a
    quantifier has a finite sort to write out) then the two MBQI variants
    (when there is a quantifier).

    With ``ladder`` (the first attempt had only a small first budget:
    decide first with what decides): finite instantiation first,
    an equivalent query over the finite domains written out; then the two
    MBQI variants; the default strategy with its whole budget
    (:data:`DEFAULT`) last: it is more of the search that just gave up,
    which rarely decides what its first look did not (the diagnosis's "does
    guard g imply guard h": the default spent its whole 2 s budget where
    MBQI proved it in 0.1 s).
    ``models_first`` (the caller knows the query is satisfiable, e.g. a
    finite-table witness exists): the two MBQI variants, which build
    models, come before both, the one after simplification first; e-matching, the default's first resort,
    finds instances that refute, never a model of a universally quantified
    formula over an infinite sort.  Every strategy of the unladdered order
    is in the laddered one, each with its whole budget, so a query one of
    them decides is still decided; only which one answers first (and so a
    model) can differ."""
    quantified = any(has_quantifier(f) for f in formulas)
    finite = quantified and any(not expand_finite(f).eq(f) for f in formulas)
    fin = [FINITE] if finite else []
    models = [MBQI, MBQI_SIMPLIFIED] if quantified else []
    if not ladder:
        return fin + models
    # models first: after simplification first, the smaller query (the case study's replacement check:
    # plain MBQI runs out of its budget, after simplification it answers in 60 % of it)
    return models[::-1] + fin + [DEFAULT] if models_first else fin + models + [DEFAULT]


def strategy_solver(name: str) -> tuple[z3.Solver, Callable[[z3.BoolRef], z3.BoolRef]]:
    """The solver (a fresh, resource-bounded context: :func:`bounded_solver`)
    and the rewrite of each formula for the retry ``name`` (not
    :data:`DEFAULT`, whose solver is the caller's first attempt with its
    whole budget).  Load the rewritten formulas with :func:`load_canonical`."""
    if name == FINITE:
        return bounded_solver(), lambda f: cast(z3.BoolRef, expand_finite(f))
    if name == MBQI:
        s = bounded_solver()
    elif name == MBQI_SIMPLIFIED:
        s = bounded_solver("simplify", "smt")
    else:
        raise ValueError(f"no retry strategy {name!r}")
    s.set("smt.ematching", False)
    return s, lambda f: f


def reasons_text(reasons: dict[str, str]) -> str:
    """Why every strategy tried gave up, ``"default: canceled; finite
    instantiation: canceled; ..."`` in the order of :data:`REPORTED`
    whatever order they ran in; the default's reason alone when nothing
    else ran."""
    if set(reasons) <= {DEFAULT}:
        return reasons.get(DEFAULT, "")
    return "; ".join(f"{n}: {reasons[n]}" for n in REPORTED if n in reasons)
