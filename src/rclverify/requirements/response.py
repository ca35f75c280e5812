"""The bounded response pattern over the composed system (issue 48).

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

P and Q are read on published values (docs/semantics.md): the caller's
``trigger`` and ``goal`` are ``published and P`` and ``published and Q``.
A run that stops with an obligation pending is found by the caller's
check that no run stops (:func:`.deadlock.runs_go_on`), as for every
liveness statement.
"""
from __future__ import annotations

import z3

from .temporal import check_always
from .tsys import Pred, TemporalVerdict, TransitionSystem, with_flag


def with_counter(ts: TransitionSystem, name: str, init: "z3.ArithRef | object",
                 step: object) -> TransitionSystem:
    """``ts`` with one more integer history variable ``name``: ``init(s)``
    its first value, ``step(s, t)`` its next (it constrains nothing)."""
    sorts = {**ts.sorts, name: z3.IntSort()}
    return TransitionSystem(sorts, lambda s: z3.And(ts.init(s), s[name] == init(s)),  # type: ignore[operator]
                            lambda s, t: z3.And(ts.trans(s, t), t[name] == step(s, t)),  # type: ignore[operator]
                            ts.fairness)


def check_response(ts: TransitionSystem, trigger: Pred, goal: Pred, within: int | None, *, max_k: int = 10,
                   timeout_ms: int = 10_000) -> TemporalVerdict:
    """Decide ``always (trigger -> eventually[<= within] goal)``, or
    ``always (trigger -> next goal)`` when ``within`` is ``None`` (module
    docstring).  Returns the verdict of :func:`.temporal.check_always` on
    the monitor variable, its trace naming the monitor's value per step."""
    if within is None:
        ts2 = with_flag(ts, "<P before>", lambda s: z3.BoolVal(False), lambda s, t: trigger(s))
        return check_always(ts2, lambda s: z3.Implies(s["<P before>"], goal(s)), max_k=max_k, timeout_ms=timeout_ms)
    n = int(within)

    def start(s: dict[str, z3.ExprRef]) -> z3.ArithRef:
        return z3.If(z3.And(trigger(s), z3.Not(goal(s))), z3.IntVal(0), z3.IntVal(-1))

    def step(s: dict[str, z3.ExprRef], t: dict[str, z3.ExprRef]) -> z3.ArithRef:
        age = s["<pending>"]
        grown = z3.If(age + 1 > n, z3.IntVal(n), age + 1)
        return z3.If(goal(t), z3.IntVal(-1), z3.If(age >= 0, grown, start(t)))
    ts2 = with_counter(ts, "<pending>", start, step)
    inv = lambda s: z3.And(s["<pending>"] >= -1, s["<pending>"] < n)  # noqa: E731
    return check_always(ts2, inv, max_k=max(max_k, n + 2), timeout_ms=timeout_ms)
