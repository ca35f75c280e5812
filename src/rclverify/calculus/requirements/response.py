"""The bounded response pattern over the composed system.

``always (P -> eventually[<= N] Q)``, FRET's "whenever P, within N steps
Q" (Giannakopoulou et al., "Generation of formal requirements from
structured natural language", REFSQ 2020, the ``within`` timing), and its
next form ``always (P -> next Q)``, are safety properties: a violation is
a finite run.  Each is decided as ``always`` of a monitor variable added to
the transition system (a history variable: it constrains nothing), by the
BMC and k-induction of :func:`.temporal.check_always`:

* ``next``: a Boolean ``<P before>``, false initially, the value of P in the
  previous state; the property is ``<P before> -> Q``;
* ``eventually[<= N]``: an integer ``<pending>``, the age in steps of the
  oldest P not yet answered by Q (``-1``: none).  At each state: Q answers
  every pending P (``-1``); otherwise a pending age grows by one (kept at
  ``N``), and a P without Q starts one at 0.  The property is ``<pending> <
  N``: a P at step i needs Q at some step i..i+N (``eventually`` includes
  now, as ``eventually[<= N]`` does), so an age of N, reached at step i+N
  with no Q since i, is the violation.

What k-induction cannot prove (unreachable states that keep a P waiting)
is proved by IC3/PDR or with the plan's ``invariant:`` (:func:`.safety.prove_always`;
the monitor variable is part of the state Spacer's certificate speaks of).

P and Q are read on published values (docs/semantics.md): the caller's
``trigger`` and ``goal`` are ``published and P`` and ``published and Q``.
A run that stops with an obligation pending is found by the caller's
check that no run stops (:func:`.deadlock.runs_go_on`), as for every
liveness statement.

The **unbounded** form ``always (P -> eventually Q)`` (FRET's "whenever P,
eventually Q"; Dwyer, Avrunin and Corbett's response pattern, ICSE 1999)
is liveness: a violation is an infinite run on which some P is never
answered.  :func:`check_unbounded_response` adds a Boolean ``<pending>``
(a P not yet answered: ``P and not Q`` initially, then ``(pending or P)
and not Q``) and decides:

* ``proved`` (method ``ranking``) by the plan's ranking function: in every
  state of its invariant where a P is pending the rank is >= 0 and every
  step decreases it (the rule of :func:`.temporal.check_eventually`);
* ``proved`` (method ``bounded response``) when the bounded pattern holds
  for some N in :data:`BOUNDS` (at most the search bound): every P is then
  answered within N steps, so eventually;
* ``refuted`` (method ``lasso``) by a run whose last state equals an
  earlier one, the loop meeting the fairness constraints, with a P pending
  in every state of the loop: repeated forever, that P is never answered;
  or (method ``deadlock``) by a run that stops with a P pending (the
  caller's check that no run stops refutes a proof only);
* else ``inconclusive``, naming what was tried.
"""
from __future__ import annotations

import z3

from typing import Callable

from rclverify.calculus.requirements.deadlock import find_deadlock
from rclverify.calculus.requirements.safety import Hint, prove_always
from rclverify.calculus.requirements.temporal import _ranking_fails, check_always
from rclverify.calculus.requirements.tsys import Pred, TemporalVerdict, TransitionSystem, FairLoops, trace_of, unroll, with_flag
from rclverify.semantics import wallclock
from rclverify.semantics.connectives import conj, disj

#: The bounds N tried, in order, to prove the unbounded response from the bounded one.
BOUNDS = (0, 1, 2, 4, 8)


def with_counter(ts: TransitionSystem, name: str, init: "z3.ArithRef | object",
                 step: object) -> TransitionSystem:
    """``ts`` with one more integer history variable ``name``: ``init(s)``
    its first value, ``step(s, t)`` its next (it constrains nothing)."""
    sorts = {**ts.sorts, name: z3.IntSort()}
    return TransitionSystem(sorts, lambda s: conj(ts.init(s), s[name] == init(s)),  # type: ignore[operator]
                            lambda s, t: conj(ts.trans(s, t), t[name] == step(s, t)),  # type: ignore[operator]
                            ts.fairness)


def check_response(ts: TransitionSystem, trigger: Pred, goal: Pred, within: int | None, *, max_k: int = 10,
                   timeout_ms: int = 10_000, hint: Hint | None = None, deep: bool = True) -> TemporalVerdict:
    """Decide ``always (trigger -> eventually[<= within] goal)``, or
    ``always (trigger -> next goal)`` when ``within`` is ``None`` (module
    docstring).  Returns the verdict on the monitor variable, its trace
    naming the monitor's value per step: of :func:`.safety.prove_always`
    (k-induction, the plan's invariant ``hint``, IC3/PDR), or with
    ``deep=False`` of :func:`.temporal.check_always` alone (k-induction)."""
    def always(ts2: TransitionSystem, prop: Pred, monitor: str) -> TemporalVerdict:
        if not deep:
            return check_always(ts2, prop, max_k=max_k, timeout_ms=timeout_ms)
        return prove_always(ts2, prop, max_k=max_k, timeout_ms=timeout_ms, hint=hint, monitor=monitor)
    if within is None:
        ts2 = with_flag(ts, "<P before>", lambda s: z3.BoolVal(False), lambda s, t: trigger(s))
        return always(ts2, lambda s: z3.Implies(s["<P before>"], goal(s)), "<P before>: the trigger held one step before")
    n = int(within)

    def start(s: dict[str, z3.ExprRef]) -> z3.ArithRef:
        return z3.If(conj(trigger(s), z3.Not(goal(s))), z3.IntVal(0), z3.IntVal(-1))

    def step(s: dict[str, z3.ExprRef], t: dict[str, z3.ExprRef]) -> z3.ArithRef:
        age = s["<pending>"]
        grown = z3.If(age + 1 > n, z3.IntVal(n), age + 1)
        return z3.If(goal(t), z3.IntVal(-1), z3.If(age >= 0, grown, start(t)))
    ts2 = with_counter(ts, "<pending>", start, step)
    inv = lambda s: conj(s["<pending>"] >= -1, s["<pending>"] < n)  # noqa: E731
    max_k = max(max_k, n + 2)
    return always(ts2, inv, "<pending>: the age in steps of the oldest trigger not yet answered, -1 for none")


def check_unbounded_response(ts: TransitionSystem, trigger: Pred, goal: Pred, *, max_k: int = 10,
                             timeout_ms: int = 10_000, ranking: Callable[[dict[str, z3.ExprRef]], z3.ArithRef] | None = None,
                             invariant: Pred | None = None) -> TemporalVerdict:
    """Decide ``always (trigger -> eventually goal)`` (module docstring):
    ``proved`` by ``ranking`` (inside ``invariant``, itself proved here by
    k-induction or IC3/PDR first, :func:`.safety.prove_always`: an invariant that is not proved leaves the ranking
    function unused) or by the bounded pattern for an N of :data:`BOUNDS` up to
    ``max_k``; ``refuted`` by a lasso of at most ``max_k`` steps with a
    trigger pending around its loop; else ``inconclusive``.  ``timeout_ms``
    bounds each solver call (milliseconds)."""
    ts2 = with_flag(ts, "<pending>", lambda s: conj(trigger(s), z3.Not(goal(s))),
                    lambda s, t: conj(disj(s["<pending>"], trigger(t)), z3.Not(goal(t))))
    why = "no ranking function"
    if ranking is not None:
        inv = invariant or (lambda st: z3.BoolVal(True))
        # the rule holds only inside the invariant: an invariant that is not proved proves nothing
        iv = prove_always(ts, inv, max_k=max_k, timeout_ms=timeout_ms) if invariant is not None else None
        if iv is not None and iv.status != "proved":
            why = (f"ranking function not used: its invariant is not proved ({iv.status} by {iv.method}"
                   + (f": {iv.detail}" if iv.detail else "") + ")")
        else:
            failed = _ranking_fails(ts2, lambda st: z3.Not(st["<pending>"]), inv, ranking, timeout_ms)
            if failed is None:
                return TemporalVerdict("proved", "ranking", k=iv.k if iv else None,
                                       detail="in every state of the invariant where a trigger is pending, the "
                                              "ranking function is >= 0 and every step decreases it")
            why = failed
    tried = []
    for n in (b for b in BOUNDS if b <= max_k):
        v = check_response(ts, trigger, goal, n, max_k=max_k, timeout_ms=timeout_ms, deep=False)
        if v.status == "proved":
            return TemporalVerdict("proved", "bounded response", k=v.k, bound=n,
                                   detail=f"every trigger is answered within {n} steps (k-induction, k = {v.k})")
        tried.append(f"within {n}: {v.status}")
    fair = FairLoops(ts2)
    for n in range(1, max_k + 1):
        states, steps = unroll(ts2, n)
        sv = z3.Solver()
        wallclock.limit(sv, timeout_ms)  # steps decide, the clock is a net
        loops = [conj(*[states[n][v] == states[j][v] for v in ts2.sorts], fair.loop(states, j, n),
                        *[st["<pending>"] for st in states[j:n + 1]]) for j in range(n)]
        sv.add(ts2.init(states[0]), *steps, disj(*loops))
        r = sv.check()
        if r == z3.sat:
            m = sv.model()
            loop = next(j for j in range(n) if z3.is_true(m.eval(loops[j], model_completion=True)))
            return TemporalVerdict("refuted", "lasso", bound=n, trace=trace_of(m, states), loop=loop,
                                   detail=f"a run whose step {n} returns to step {loop} with a trigger pending at "
                                          "every step of the loop: it is never answered")
        if r == z3.unknown:
            return TemporalVerdict("inconclusive", "lasso", bound=n - 1,
                                   detail=f"{why}; not answered within {', '.join(tried)}; Z3 could not decide "
                                          f"whether a run of {n} steps loops with a trigger pending "
                                          f"({sv.reason_unknown()})")
    # a run that stops with a trigger pending never answers it (docs/requirements.md, "Runs that stop")
    stop = find_deadlock(ts2, max_k, ending=lambda st: st["<pending>"], timeout_ms=timeout_ms,
                         what=" with a trigger pending")
    if stop is not None and stop.status == "refuted":
        return stop
    return TemporalVerdict("inconclusive", "lasso", bound=max_k, deadlock=stop.deadlock if stop is not None else "",
                           detail=f"{why}; the bounded pattern tried {', '.join(tried) or 'no bound'}; no run of up "
                                  f"to {max_k} steps loops with a trigger pending")
