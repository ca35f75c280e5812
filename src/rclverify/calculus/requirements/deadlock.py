"""Runs that stop: deadlocks of a transition system, decided with Z3.

A state of a :class:`~.tsys.TransitionSystem` is a *deadlock* when no state
follows it under the step relation; a deadlock reachable from an initial
state ends a finite run (docs/requirements.md, "Runs that stop").  Whether
a state ``s`` has a successor is the existential query ``exists t.
trans(s, t)``, so a reachable deadlock is an exists-forall query: a path
``s0 .. sk`` from ``init`` with ``forall t. not trans(sk, t)``.  It is
asked of Z3 as such:

* the successor's variables of finite sorts (BOOL, enumerations) are
  written out first, one case per combination of values, and so are the
  quantifiers over finite sorts inside the step relation
  (:func:`rclverify.semantics.retry.expand_finite`; both equivalences), so over
  finite domains the query is quantifier-free;
* the query is first given to Z3's default solver for a short look
  (:data:`FIRST_LOOK_MS`); its ``sat`` and ``unsat`` are answers;
* what it leaves open is first eliminated where Z3's ``qe`` tactic can
  (linear arithmetic: an equivalence), then left to Z3's quantifier
  instantiation, and when that answers ``unknown`` it is asked once more
  with model-based instantiation alone (``smt.ematching=false``);
* an ``unknown`` after that is ``inconclusive``: never deadlock-free.

Two checks:

:func:`find_deadlock`
    bounded: the shortest run ``s0 .. sk``, ``k < bound``, whose states all
    satisfy ``staying`` and whose last state has no successor;
:func:`check_deadlock_free`
    unbounded, by k-induction (Sheeran, Singh, Stalmarck, FMCAD 2000) of
    the path property "no run stays in ``staying`` until it stops": the
    base case is :func:`find_deadlock`'s query; the step case asks for any
    path of k steps through distinct states, every state in ``staying``
    (and in a proved invariant), whose last state has no successor.

:func:`runs_go_on` is the rule docs/requirements.md states for every
temporal requirement: a proof stands only over a system whose runs never
stop.
"""
from __future__ import annotations

import itertools
from typing import Sequence

import z3

from rclverify.semantics.connectives import disj
from rclverify.semantics.retry import MAX_INSTANCES, expand_finite, finite_values
from rclverify.semantics.subst import substitute
from rclverify.calculus.requirements.tsys import Pred, State, TemporalVerdict, TransitionSystem, distinct, trace_of, unroll
from rclverify.semantics import wallclock
from rclverify.semantics.query import tactic_solver

#: A deadlock query is first asked of Z3's default solver for this many milliseconds' worth of resource
#: steps: most are answered there in a few ms, where the quantifier elimination that leads
#: :func:`_attempts` takes about 100 ms whatever the query.  Its ``sat`` (a model Z3's
#: model-based instantiation checked) and ``unsat`` are answers; its ``unknown`` goes to the ladder.
FIRST_LOOK_MS = 250
#: The step-by-step search of :func:`find_deadlock` stops (``inconclusive``)
#: after this many times one query's budget in all.
SEARCH_BUDGET = 30
STOPS = ("no next state satisfies the contracts, the environment facts, the state declarations and the "
         "requirement's assumptions")


def successor_exists(ts: TransitionSystem, s: State) -> z3.BoolRef:
    """``exists t. trans(s, t)`` over a fresh successor state.  The
    successor's variables of finite sorts are written out (one disjunct per
    combination of their values, up to :data:`MAX_INSTANCES`; an
    equivalence), and quantifiers inside ``trans`` over finite sorts too
    (:func:`rclverify.semantics.retry.expand_finite`) where any sort is finite;
    the other variables stay bound by ``exists``."""
    t = {n: z3.Const(f"{n}@succ", srt) for n, srt in ts.sorts.items()}  # bound: no clash with a step's
    body = ts.trans(s, t)
    if any(finite_values(srt) is not None or isinstance(srt, z3.DatatypeSortRef) for srt in ts.sorts.values()):
        body = expand_finite(body)
    finite = {n: vs for n, vs in ((n, finite_values(srt)) for n, srt in ts.sorts.items()) if vs is not None}
    rest = [t[n] for n in ts.sorts if n not in finite]
    combos = list(itertools.islice(itertools.product(*finite.values()), MAX_INSTANCES + 1))
    if not t:
        return body
    if not finite or len(combos) > MAX_INSTANCES:
        return z3.Exists(list(t.values()), body)
    cases = [substitute(body, [(t[n], v) for n, v in zip(finite, combo)]) for combo in combos]
    return disj(*[z3.Exists(rest, c) if rest else c for c in cases])


def no_successor(ts: TransitionSystem, s: State) -> z3.BoolRef:
    """``forall t. not trans(s, t)``: ``s`` is a deadlock."""
    return z3.Not(successor_exists(ts, s))


def _attempts(timeout_ms: int) -> list[tuple[str, z3.Solver]]:
    """The solvers a deadlock query is asked of, in order (module docstring)."""
    qe = tactic_solver(timeout_ms, ("qe", "smt"))  # eliminates the successor's quantifier over linear arithmetic
    plain = _solver(timeout_ms)
    mbqi = _solver(timeout_ms)
    mbqi.set("smt.ematching", False)
    return [("quantifier elimination", qe), ("default", plain), ("model-based instantiation", mbqi)]


def _check(solver: z3.Solver, extra: Sequence[z3.BoolRef], timeout_ms: int) -> tuple[z3.CheckSatResult, z3.ModelRef | None, str]:
    """``solver``'s assertions and ``extra``: (answer, model when sat, why
    when unknown).  Without ``extra`` ``solver`` answers (incrementally);
    with ``extra`` (the quantified deadlock condition) a first look of
    :data:`FIRST_LOOK_MS` is taken, then each of :func:`_attempts` is asked
    in turn, in a solver of its own, until one answers sat or unsat."""
    if not extra:
        r, cut = wallclock.check_cut(solver)
        why = wallclock.why_unknown(solver, cut) if r == z3.unknown else ""
        return r, solver.model() if r == z3.sat else None, why
    first = _solver(min(FIRST_LOOK_MS, timeout_ms))
    first.add(*solver.assertions(), *extra)
    try:
        r = first.check()  # not the clock's tally: an unknown here only hands the query on
    except z3.Z3Exception:
        r = z3.unknown
    if r == z3.sat:
        return r, first.model(), ""
    if r == z3.unsat:
        return r, None, ""
    whys = []
    for name, s in _attempts(timeout_ms):
        s.add(*solver.assertions(), *extra)
        try:
            r, cut = wallclock.check_cut(s)
        except z3.Z3Exception as exc:  # a tactic that refuses the query: that attempt is undecided
            whys.append(f"{name}: {exc}")
            continue
        if cut:  # the clock, not the budget: the next attempt may not answer in its place
            return z3.unknown, None, f"{name}: {wallclock.cut_reason()}"
        if r == z3.sat:
            return r, s.model(), ""
        if r == z3.unsat:
            return r, None, ""
        whys.append(f"{name}: {s.reason_unknown()}")
    return z3.unknown, None, "; ".join(whys)


def _solver(timeout_ms: int) -> z3.Solver:
    s = z3.Solver()
    wallclock.limit(s, timeout_ms)  # steps decide, the clock is a net
    return s


def _stopped(states: list[State], m: z3.ModelRef, k: int, what: str) -> TemporalVerdict:
    return TemporalVerdict("refuted", "deadlock", bound=k, trace=trace_of(m, states),
                           detail=f"the run stops at step {k}{what}: {STOPS} (a deadlock)",
                           deadlock=f"reachable at step {k}")


def find_deadlock(ts: TransitionSystem, bound: int, *, staying: Pred | None = None,
                  timeout_ms: int = 10_000, what: str = "", ending: Pred | None = None) -> TemporalVerdict | None:
    """The shortest run ``s0 .. sk`` (``0 <= k < bound``) from an initial
    state whose states all satisfy ``staying`` (default: any) and whose last
    state has no successor (and satisfies ``ending``, default: any; the
    unbounded response's "a trigger is pending when it stops").

    Returns ``refuted`` (method ``deadlock``, ``bound = k``, the run as the
    trace; ``what`` is appended to "the run stops at step k" in the
    detail), ``inconclusive`` when Z3 cannot decide a step, or ``None`` when
    no such run of fewer than ``bound`` steps exists (the search also ends
    early, exactly, once no run stays in ``staying`` that long).  The whole
    search has :data:`SEARCH_BUDGET` times ``timeout_ms``; past that it is
    ``inconclusive``."""
    s = _solver(timeout_ms)
    states = [ts.state(0)]
    s.add(ts.init(states[0]))
    # the whole search's budget in Z3 resource steps (the context's counter, read through any of its
    # solvers), so that where it stops does not depend on the machine's load
    start, total = wallclock.steps_taken(s), wallclock.steps(SEARCH_BUDGET * timeout_ms)
    for k in range(bound):
        if wallclock.steps_taken(s) - start > total:
            return TemporalVerdict("inconclusive", "deadlock", bound=k,
                                   detail=f"no run stops{what} before step {k}; the search stopped there, after "
                                          f"{SEARCH_BUDGET} query budgets of Z3 resource steps",
                                   deadlock=f"undecided from step {k} on (search budget spent)")
        if staying is not None:
            s.add(staying(states[k]))
        r, _, why = _check(s, [], timeout_ms)
        if r == z3.unsat:
            return None  # no run stays that long: none stops later either
        if r == z3.unknown:
            return TemporalVerdict("inconclusive", "deadlock", bound=k,
                                   detail=f"Z3 could not decide whether a run reaches step {k} ({why})",
                                   deadlock=f"undecided at step {k}")
        r, m, why = _check(s, [no_successor(ts, states[k]), *([ending(states[k])] if ending is not None else [])],
                           timeout_ms)
        if r == z3.sat:
            assert m is not None
            return _stopped(states, m, k, what)
        if r == z3.unknown:
            return TemporalVerdict("inconclusive", "deadlock", bound=k,
                                   detail=f"Z3 could not decide whether a run stops at step {k} ({why})",
                                   deadlock=f"undecided at step {k} ({why})")
        nxt = ts.state(k + 1)
        s.add(ts.trans(states[k], nxt))
        states.append(nxt)
    return None


def check_deadlock_free(ts: TransitionSystem, *, staying: Pred | None = None, invariant: Pred | None = None,
                        max_k: int = 10, timeout_ms: int = 10_000, what: str = "") -> TemporalVerdict:
    """Decide "no run from an initial state stays in ``staying`` (default:
    any state) until it stops" by k-induction, k = 1..``max_k`` (module
    docstring).  ``invariant`` must be proved an invariant by the caller: it
    strengthens the step case only.

    Returns ``proved`` (method ``k-induction`` with its k; ``deadlock``
    says deadlock-free), ``refuted`` (method ``deadlock``, the shortest run
    that stops, as :func:`find_deadlock`), or ``inconclusive`` (Z3 could
    not decide a query, or the property is not k-inductive up to ``max_k``).
    """
    base = _solver(timeout_ms)
    states = [ts.state(0)]
    base.add(ts.init(states[0]))
    for k in range(1, max_k + 1):
        # base case: a run of k-1 steps, staying, that stops at step k-1
        last = states[-1]
        if staying is not None:
            base.add(staying(last))
            r, _, why = _check(base, [], timeout_ms)
            if r == z3.unsat:  # no run stays in `staying` for k-1 steps: none stops there later
                return TemporalVerdict("proved", "bounded", bound=k - 1,
                                       deadlock=f"no run stops{what}: none gets to step {k - 1}")
            if r == z3.unknown:
                return TemporalVerdict("inconclusive", "deadlock", bound=k - 1,
                                       detail=f"Z3 could not decide whether a run reaches step {k - 1} ({why})",
                                       deadlock=f"undecided at step {k - 1} ({why})")
        r, m, why = _check(base, [no_successor(ts, last)], timeout_ms)
        if r == z3.sat:
            assert m is not None
            return _stopped(states, m, k - 1, what)
        if r == z3.unknown:
            return TemporalVerdict("inconclusive", "deadlock", bound=k - 1,
                                   detail=f"Z3 could not decide whether a run stops{what} at step {k - 1} ({why})",
                                   deadlock=f"undecided at step {k - 1} ({why})")
        # step case: any k steps, staying (and in the invariant), then no successor
        path, steps = unroll(ts, k, tag="ind")
        step = _solver(timeout_ms)
        step.add(*steps, *[staying(x) for x in path if staying is not None],
                 *[invariant(x) for x in path if invariant is not None], *distinct(path))
        r, _, why = _check(step, [no_successor(ts, path[-1])], timeout_ms)
        if r == z3.unsat:
            return TemporalVerdict("proved", "k-induction", k=k, bound=k - 1,
                                   deadlock=f"no run stops{what} ({k}-induction)")
        nxt = ts.state(k)
        base.add(ts.trans(last, nxt))
        states.append(nxt)
    return TemporalVerdict("inconclusive", "deadlock", bound=max_k - 1,
                           detail=f"no run of up to {max_k - 1} steps stops{what}, but that no run ever stops is "
                                  f"not {max_k}-inductive",
                           deadlock=f"undecided: none up to step {max_k - 1}, not {max_k}-inductive")


def runs_go_on(ts: TransitionSystem, v: TemporalVerdict, *, max_k: int = 10,
               timeout_ms: int = 10_000) -> TemporalVerdict:
    """The verdict ``v`` on a temporal requirement over ``ts`` under the rule
    that a proof stands only over a system whose runs never stop
    (docs/requirements.md, "Runs that stop").  ``v`` proved or met: the
    system's deadlock freedom is decided (:func:`check_deadlock_free`);
    deadlock-free keeps ``v`` (its ``deadlock`` says how), a reachable
    deadlock makes it ``refuted`` (method ``deadlock``, the run that stops
    as the trace), undecided makes it ``inconclusive``.  Any other ``v`` is
    returned unchanged (a counterexample or an undecided verdict needs no
    more)."""
    if v.status not in ("proved", "met"):
        return v
    dl = check_deadlock_free(ts, max_k=max_k, timeout_ms=timeout_ms)
    if dl.status == "proved":
        return TemporalVerdict(v.status, v.method, k=v.k, bound=v.bound, trace=v.trace, detail=v.detail,
                               loop=v.loop, deadlock=dl.deadlock, certificate=v.certificate)
    if dl.status == "refuted":
        return TemporalVerdict("refuted", "deadlock", bound=dl.bound, trace=dl.trace,
                               detail=f"{dl.detail}; the statement itself was {v.status} by {v.method}, but only "
                                      f"over runs that stop, and the runs of the system must not stop",
                               deadlock=dl.deadlock)
    return TemporalVerdict("inconclusive", v.method, k=v.k, bound=v.bound,
                           detail=f"{v.status} by {v.method}, but whether a run of the system stops (a deadlock) "
                                  f"is undecided: {dl.detail}",
                           deadlock=dl.deadlock)
