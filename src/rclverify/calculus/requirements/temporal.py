"""Temporal properties decided over a transition system with Z3.

The composed system is read as a transition system (docs/requirements.md,
"Temporal requirements"): a state assigns a value to every state variable
(nodes' inputs and outputs, the environment's facts, declared memory), and
one step relates the current state to the next.  A *run* is a maximal path
from an initial state: infinite, or finite and ending in a state with no
successor (a run that stops: :mod:`.deadlock`).  This module decides, over
such a system, with the finite-run semantics of docs/requirements.md:

* ``always P`` -- refuted by bounded model checking (a counterexample trace,
  one state per step), proved by k-induction (the k used is returned);
* ``eventually P within N`` -- a bounded response, decided exactly: met
  when no run of N steps misses P *and* no run stops before step N without
  reaching P; refuted with either run as the trace;
* ``eventually P`` without bound -- proved through a ranking function the
  user supplies, or because every run reaches P within the bound; refuted
  by a lasso or by a run that stops before reaching P; otherwise
  ``inconclusive`` with the bound checked.  Never ``met`` on a bound alone;
* ``next P`` (a next state exists and satisfies P) and ``P until Q``.

Whether the system's runs may stop at all (the rule every temporal
requirement is held to) is :func:`rclverify.calculus.requirements.deadlock.runs_go_on`.

Source of the rules: k-induction (Sheeran, Singh, Stalmarck, FMCAD 2000)
as used by Kind 2 and AGREE; lassos as counterexamples to liveness (Biere,
Cimatti, Clarke, Zhu, TACAS 1999); the paper's stream model
(compositional-verification-paper.tex, contracts consume one input and
persist outputs) fixes what a step is.
"""

from __future__ import annotations

from typing import Callable

import z3

from rclverify.calculus.requirements.deadlock import check_deadlock_free, find_deadlock
from rclverify.calculus.requirements.tsys import (FairLoops, Fairness, Pred, State, TemporalVerdict, Trans, TransitionSystem, distinct, trace_of, unroll,
                   with_flag)
from rclverify.semantics import wallclock
from rclverify.semantics.connectives import conj, disj

__all__ = ["Fairness", "Pred", "State", "TemporalVerdict", "Trans", "TransitionSystem", "check_always", "check_eventually",
           "check_eventually_within", "check_next", "check_until", "find_lasso", "with_flag"]


def check_always(ts: TransitionSystem, prop: Pred, *, max_k: int = 10,
                 timeout_ms: int = 10_000) -> TemporalVerdict:
    """Decide ``always prop`` by BMC and k-induction, k = 1..``max_k``.

    For each k: the base case asks for a run of k-1 steps from ``init``
    violating ``prop`` (found: ``refuted`` with that shortest trace); the
    step case asks whether k consecutive distinct states satisfying ``prop``
    can be followed by one violating it (unsat: ``proved`` with k).  No k up to
    ``max_k`` decides it: ``inconclusive`` with ``bound = max_k``.
    """
    for k in range(1, max_k + 1):
        states, steps = unroll(ts, k - 1)
        base = z3.Solver()
        wallclock.limit(base, timeout_ms)  # steps decide, the clock is a net
        base.add(ts.init(states[0]), *steps)
        base.add(z3.Not(prop(states[-1])))
        r = base.check()
        if r == z3.sat:
            return TemporalVerdict("refuted", "bmc", bound=k - 1,
                                   trace=trace_of(base.model(), states),
                                   detail=f"violated at step {k - 1}")
        if r == z3.unknown:
            return TemporalVerdict("inconclusive", "bmc", bound=k - 1,
                                   detail=f"solver: {base.reason_unknown()}")
        states, steps = unroll(ts, k)
        ind = z3.Solver()
        wallclock.limit(ind, timeout_ms)  # steps decide, the clock is a net
        ind.add(*steps, *[prop(s) for s in states[:-1]], *distinct(states))
        ind.add(z3.Not(prop(states[-1])))
        if ind.check() == z3.unsat:
            return TemporalVerdict("proved", "k-induction", k=k, bound=k - 1)
    return TemporalVerdict("inconclusive", "k-induction", bound=max_k - 1,
                           detail=f"no run of {max_k - 1} steps violates it; "
                                  f"not {max_k}-inductive")


def check_eventually_within(ts: TransitionSystem, prop: Pred, bound: int, *,
                            timeout_ms: int = 10_000) -> TemporalVerdict:
    """Decide ``eventually[<= bound] prop``: every run reaches ``prop`` at
    some step 0..``bound``.  A run misses it in two ways: it goes on for
    ``bound`` steps outside ``prop``, or it stops (no successor) at a step
    before ``bound`` without having reached it (:func:`.deadlock.find_deadlock`).
    Exact: ``met`` when neither run exists; ``refuted`` with the run as the
    trace (method ``bounded``, or ``deadlock`` for a run that stops);
    ``inconclusive`` when Z3 cannot decide a query.
    """
    states, steps = unroll(ts, bound)
    s = z3.Solver()
    wallclock.limit(s, timeout_ms)  # steps decide, the clock is a net
    s.add(ts.init(states[0]), *steps, *[z3.Not(prop(st)) for st in states])
    r = s.check()
    if r == z3.sat:
        return TemporalVerdict("refuted", "bounded", bound=bound,
                               trace=trace_of(s.model(), states),
                               detail=f"not reached within {bound} steps")
    if r == z3.unknown:
        return TemporalVerdict("inconclusive", "bounded", bound=bound,
                               detail=f"solver: {s.reason_unknown()}")
    # no run goes on for `bound` steps outside prop: does one stop before reaching it?  First by
    # induction (a few queries whatever the bound), then step by step up to the bound
    outside = lambda st: z3.Not(prop(st))  # noqa: E731
    quick = check_deadlock_free(ts, staying=outside, max_k=min(bound, 2), timeout_ms=timeout_ms,
                                what=" before reaching it") if bound > 0 else None
    if quick is not None and quick.status == "refuted":  # it stops at a step < 2 <= bound
        return quick
    stop = None if quick is not None and quick.status == "proved" else find_deadlock(
        ts, bound, staying=outside, timeout_ms=timeout_ms, what=" before reaching it")
    if stop is None:
        return TemporalVerdict("met", "bounded", bound=bound,
                               deadlock=f"no run stops before reaching it within {bound} steps")
    if stop.status == "refuted":
        return stop
    return TemporalVerdict("inconclusive", "bounded", bound=bound,
                           detail=f"no run of {bound} steps misses it, but {stop.detail[0].lower()}"
                                  f"{stop.detail[1:]}", deadlock=stop.deadlock)


def check_next(ts: TransitionSystem, prop: Pred, *, timeout_ms: int = 10_000) -> TemporalVerdict:
    """Decide ``next prop``: every run has a step 1, and ``prop`` holds
    there.  ``refuted`` by a step whose next state misses it (method
    ``bmc``) or by a run that stops at step 0 (method ``deadlock``);
    ``proved`` (method ``bounded``) otherwise; ``inconclusive`` on an
    unknown."""
    a, b = ts.state(0), ts.state(1)
    s = z3.Solver()
    wallclock.limit(s, timeout_ms)  # steps decide, the clock is a net
    s.add(ts.init(a), ts.trans(a, b), z3.Not(prop(b)))
    r = s.check()
    if r == z3.sat:
        return TemporalVerdict("refuted", "bmc", bound=1, detail="fails at step 1", trace=trace_of(s.model(), [a, b]))
    if r == z3.unknown:
        return TemporalVerdict("inconclusive", "bmc", bound=1, detail=f"solver: {s.reason_unknown()}")
    stop = find_deadlock(ts, 1, timeout_ms=timeout_ms, what=" (there is no step 1)")
    if stop is None:
        return TemporalVerdict("proved", "bounded", bound=1, detail="holds at step 1 of every run",
                               deadlock="no run stops at step 0")
    return stop if stop.status == "refuted" else TemporalVerdict(
        "inconclusive", "bmc", bound=1, detail=f"holds at every step 1, but {stop.detail}", deadlock=stop.deadlock)


def check_until(ts: TransitionSystem, prop: Pred, goal: Pred, *,
                eventually: Callable[[], TemporalVerdict] | None = None, max_k: int = 10,
                timeout_ms: int = 10_000,
                always: Callable[[TransitionSystem, Pred], TemporalVerdict] | None = None) -> TemporalVerdict:
    """Decide ``prop until goal``: every run reaches ``goal``, and ``prop``
    holds at every step before.  Decided as its safety part, ``always (goal
    seen or prop)`` over ``ts`` with a history flag (:func:`check_always`),
    and its liveness part ``eventually goal`` (``eventually()``; default
    :func:`check_eventually` with ``bound = max_k``; ``always(ts, prop)``
    decides the safety part, default :func:`check_always`).  ``refuted`` when
    either part is; ``proved`` when both are; else ``inconclusive`` with
    both parts' statuses."""
    ts2 = with_flag(ts, "<G seen>", goal, lambda s, u: disj(s["<G seen>"], goal(u)))
    safe_prop = lambda s: disj(s["<G seen>"], prop(s))  # noqa: E731
    safe = always(ts2, safe_prop) if always is not None else check_always(ts2, safe_prop, max_k=max_k,
                                                                           timeout_ms=timeout_ms)
    if safe.status == "refuted":
        return safe
    live = eventually() if eventually is not None else check_eventually(ts, goal, bound=max_k, timeout_ms=timeout_ms)
    if live.status == "refuted" or (safe.status == "proved" and live.status == "proved"):
        return TemporalVerdict(live.status, f"{safe.method} + {live.method}", k=safe.k, bound=live.bound,
                               trace=live.trace, loop=live.loop, detail=live.detail, deadlock=live.deadlock)
    return TemporalVerdict("inconclusive", f"{safe.method} + {live.method}", k=safe.k, bound=live.bound,
                           trace=live.trace, detail=f"safety part {safe.status}; liveness part {live.status}: "
                                                    f"{live.detail or safe.detail}", deadlock=live.deadlock)


def check_eventually(ts: TransitionSystem, prop: Pred, *,
                     ranking: Callable[[State], z3.ArithRef] | None = None,
                     invariant: Pred | None = None, bound: int = 10,
                     timeout_ms: int = 10_000,
                     prove: Callable[[TransitionSystem, Pred], TemporalVerdict] | None = None) -> TemporalVerdict:
    """Decide unbounded ``eventually prop``: every run, infinite or one
    that stops, reaches ``prop``.

    ``proved`` (method ``ranking``) through a user-supplied integer
    ``ranking`` function and an ``invariant`` (default true) that is itself
    proved by k-induction: in every invariant state where ``prop`` is
    false, the rank is >= 0 and every step decreases it strictly, so no
    infinite run misses ``prop``; and no run stops before reaching it
    (:func:`.deadlock.check_deadlock_free` outside ``prop``, by k-induction
    strengthened by the invariant).  ``proved`` (method ``bounded``) when
    every run reaches ``prop`` within ``bound`` steps
    (:func:`check_eventually_within`).  ``refuted`` by a run that stops
    before reaching it (method ``deadlock``) or by a lasso missing it
    (:func:`find_lasso`).  Otherwise ``inconclusive``: a run of ``bound``
    steps missing ``prop`` is not a counterexample to liveness (it is
    reported as the trace).  ``prove(ts, invariant)`` proves the invariant
    (default :func:`check_always`; the requirement check passes
    :func:`.safety.prove_always`, which also tries IC3/PDR and names the step
    that breaks a candidate).
    """
    inv = invariant or (lambda st: z3.BoolVal(True))
    outside = lambda st: z3.Not(prop(st))  # noqa: E731
    why: str | None = "no ranking function"
    if ranking is not None:
        iv = (prove(ts, inv) if prove is not None else check_always(ts, inv, max_k=bound, timeout_ms=timeout_ms)) \
            if invariant else None
        if iv is not None and iv.status != "proved":
            why = (f"ranking function not used: its invariant is not proved ({iv.status} by {iv.method}"
                   + (f": {iv.detail}" if iv.detail else "") + ")")
        else:
            why = _ranking_fails(ts, prop, inv, ranking, timeout_ms)
            if why is None:
                stops = check_deadlock_free(ts, staying=outside, invariant=invariant, max_k=bound,
                                            timeout_ms=timeout_ms, what=" before reaching it")
                if stops.status == "refuted":
                    return stops
                if stops.status == "proved":
                    return TemporalVerdict("proved", "ranking", k=iv.k if iv else None, deadlock=stops.deadlock,
                                           detail="in every state of the invariant where it does not hold, the "
                                                  "ranking function is >= 0 and every step decreases it; no run "
                                                  "stops before reaching it")
                why = (f"the ranking function holds, but whether a run stops before reaching it is undecided "
                       f"({stops.detail})")
    bounded = check_eventually_within(ts, prop, bound, timeout_ms=timeout_ms)
    if bounded.status == "inconclusive":  # the solver could not say: nothing was decided, and no lasso is sought
        return TemporalVerdict("inconclusive", "bounded", bound=None, deadlock=bounded.deadlock,
                               detail=f"Z3 could not decide whether a run of {bound} steps misses it "
                                      f"({bounded.detail}); no step was checked")
    if bounded.status == "met":
        # every run reaches prop within `bound` steps, and none stops before: a proof, not a guess
        return TemporalVerdict("proved", "bounded", bound=bound, deadlock=bounded.deadlock,
                               detail=f"reached within {bound} steps on every run")
    if bounded.method == "deadlock":  # a run that stops before reaching it: a counterexample
        return bounded
    lasso = find_lasso(ts, prop, bound, timeout_ms=timeout_ms)
    if lasso is not None:
        return lasso
    stop = find_deadlock(ts, bound, staying=outside, timeout_ms=timeout_ms, what=" before reaching it")
    if stop is not None and stop.status == "refuted":
        return stop
    return TemporalVerdict("inconclusive", "bounded", bound=bound, trace=bounded.trace,
                           deadlock=stop.deadlock if stop is not None else "",
                           detail=f"{why}; a run of {bound} steps does not reach it")


def _ranking_fails(ts: TransitionSystem, prop: Pred, inv: Pred, ranking: Callable[[State], z3.ArithRef],
                   timeout_ms: int) -> str | None:
    """Which condition of the ranking rule fails (``None``: both hold):
    (1) in a state of ``inv`` where ``prop`` is false, rank >= 0; (2) every
    step from such a state decreases the rank strictly.  A condition the
    solver cannot decide fails (never a proof on an unknown)."""
    a, b = ts.state(0), ts.state(1)
    for cond, text in ((ranking(a) >= 0, "is not >= 0"),
                       (ranking(b) < ranking(a), "does not decrease on every step")):
        s = z3.Solver()
        wallclock.limit(s, timeout_ms)  # steps decide, the clock is a net
        s.add(inv(a), z3.Not(prop(a)), ts.trans(a, b), z3.Not(cond))
        r = s.check()
        if r != z3.unsat:
            where = "in a state of the invariant where the goal does not hold"
            if r == z3.unknown:
                return f"ranking function not accepted: Z3 could not decide whether it {text} {where} " \
                       f"({s.reason_unknown()})"
            m = s.model()
            vals = f"{m.eval(ranking(a), model_completion=True)}"
            if "decrease" in text:
                vals += f" then {m.eval(ranking(b), model_completion=True)}"
            return f"ranking function not accepted: it {text} {where} (rank {vals})"
    return None


def find_lasso(ts: TransitionSystem, prop: Pred, bound: int, *,
               timeout_ms: int = 10_000) -> TemporalVerdict | None:
    """A counterexample to unbounded ``eventually prop``: a run s0..sn
    (n <= ``bound``) missing ``prop`` whose last state equals an earlier
    one, s_n == s_j, and whose loop s_j..s_{n-1} meets the fairness
    constraints of ``ts`` (:func:`.tsys.fair_loop`).  Repeating s_j..s_n
    forever is an infinite run of the system (a step depends on its two
    states only) on which ``prop`` never holds: ``refuted`` (method
    ``lasso``, ``loop = j``).  ``None`` when no such run of up to ``bound``
    steps exists or the solver cannot say.
    """
    # the unrolling and each state's "prop fails" grow by one step per length instead of being built
    # again for each, and each state's fairness terms are built once (the same terms: unroll, fair_loop)
    states, steps = unroll(ts, 0)
    init = ts.init(states[0])
    misses = [z3.Not(prop(states[0]))]
    fair = FairLoops(ts)
    for n in range(1, bound + 1):
        states.append(ts.state(n))
        steps.append(ts.trans(states[n - 1], states[n]))
        misses.append(z3.Not(prop(states[n])))
        s = z3.Solver()
        wallclock.limit(s, timeout_ms)  # steps decide, the clock is a net
        same = [conj(*[states[n][v] == states[j][v] for v in ts.sorts], fair.loop(states, j, n))
                for j in range(n)]
        s.add(init, *steps, *misses, disj(*same))
        if s.check() == z3.sat:
            m = s.model()
            loop = next(j for j in range(n) if z3.is_true(m.eval(same[j], model_completion=True)))
            return TemporalVerdict("refuted", "lasso", bound=n, trace=trace_of(m, states), loop=loop,
                                   detail=f"a run whose step {n} returns to step {loop} and never reaches it")
    return None
