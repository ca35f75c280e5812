"""Temporal properties decided over a transition system with Z3.

The composed system is read as a transition system (docs/requirements.md,
"Temporal requirements"): a state assigns a value to every state variable
(nodes' inputs and outputs, the environment's facts, declared memory), and
one step relates the current state to the next.  This module decides, over
such a system:

* ``always P`` -- refuted by bounded model checking (a counterexample trace,
  one state per step), proved by k-induction (the k used is returned);
* ``eventually P within N`` -- a bounded response, decided exactly by
  unrolling N steps (met: every run reaches P within N steps; refuted: a
  run of N steps that never reaches P, returned as its trace);
* ``eventually P`` without bound -- proved only through a ranking function
  the user supplies; otherwise ``inconclusive`` with the bound checked.
  Never ``met`` on a bound alone.

Source of the rules: k-induction (Sheeran, Singh, Stalmarck, FMCAD 2000)
as used by Kind 2 and AGREE; the paper's stream model
(compositional-verification-paper.tex, contracts consume one input and
persist outputs) fixes what a step is.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import z3

State = dict[str, z3.ExprRef]
Pred = Callable[[State], z3.BoolRef]
Trans = Callable[[State, State], z3.BoolRef]


@dataclass(frozen=True)
class TransitionSystem:
    """A symbolic transition system.

    ``sorts`` maps each state variable's name to a Z3 sort; ``init`` is a
    predicate over the first state; ``trans`` relates a state to the next.
    """

    sorts: dict[str, z3.SortRef]
    init: Pred
    trans: Trans

    def state(self, step: int) -> State:
        """Fresh Z3 constants for the state at ``step`` (0-based)."""
        return {n: z3.Const(f"{n}@{step}", s) for n, s in self.sorts.items()}


@dataclass
class TemporalVerdict:
    """The verdict on one temporal property.

    ``status`` is ``proved`` | ``met`` | ``refuted`` | ``inconclusive``;
    ``method`` names how (``k-induction``, ``bounded``, ``ranking``, ``bmc``);
    ``k`` the induction depth used; ``bound`` the number of steps checked;
    ``trace`` the counterexample, one ``{variable: value}`` per step.
    """

    status: str
    method: str
    k: int | None = None
    bound: int | None = None
    trace: list[dict[str, str]] = field(default_factory=list)
    detail: str = ""
    #: a lasso's loop: the last state of ``trace`` equals state ``loop``
    loop: int | None = None

    def to_json(self) -> dict:
        """The record fields (a JSON-ready dict)."""
        return {"status": self.status, "method": self.method, "k": self.k,
                "bound": self.bound, "trace": self.trace, "detail": self.detail, "loop": self.loop}


def _unroll(ts: TransitionSystem, n: int) -> tuple[list[State], list[z3.BoolRef]]:
    states = [ts.state(i) for i in range(n + 1)]
    steps = [ts.trans(states[i], states[i + 1]) for i in range(n)]
    return states, steps


def _trace(model: z3.ModelRef, states: list[State]) -> list[dict[str, str]]:
    return [{n: str(model.eval(v, model_completion=True)) for n, v in s.items()}
            for s in states]


def check_always(ts: TransitionSystem, prop: Pred, *, max_k: int = 10,
                 timeout_ms: int = 10_000) -> TemporalVerdict:
    """Decide ``always prop`` by BMC and k-induction, k = 1..``max_k``.

    For each k: the base case asks for a run of k-1 steps from ``init``
    violating ``prop`` (found: ``refuted`` with that shortest trace); the
    step case asks whether k consecutive states satisfying ``prop`` can be
    followed by one violating it (unsat: ``proved`` with k).  No k up to
    ``max_k`` decides it: ``inconclusive`` with ``bound = max_k``.
    """
    for k in range(1, max_k + 1):
        states, steps = _unroll(ts, k - 1)
        base = z3.Solver()
        base.set("timeout", timeout_ms)
        base.add(ts.init(states[0]), *steps)
        base.add(z3.Not(prop(states[-1])))
        r = base.check()
        if r == z3.sat:
            return TemporalVerdict("refuted", "bmc", bound=k - 1,
                                   trace=_trace(base.model(), states),
                                   detail=f"violated at step {k - 1}")
        if r == z3.unknown:
            return TemporalVerdict("inconclusive", "bmc", bound=k - 1,
                                   detail=f"solver: {base.reason_unknown()}")
        states, steps = _unroll(ts, k)
        ind = z3.Solver()
        ind.set("timeout", timeout_ms)
        ind.add(*steps, *[prop(s) for s in states[:-1]])
        ind.add(z3.Not(prop(states[-1])))
        if ind.check() == z3.unsat:
            return TemporalVerdict("proved", "k-induction", k=k, bound=k - 1)
    return TemporalVerdict("inconclusive", "k-induction", bound=max_k - 1,
                           detail=f"no run of {max_k - 1} steps violates it; "
                                  f"not {max_k}-inductive")


def check_eventually_within(ts: TransitionSystem, prop: Pred, bound: int, *,
                            timeout_ms: int = 10_000) -> TemporalVerdict:
    """Decide ``eventually[<= bound] prop``: every run reaches ``prop`` at
    some step 0..``bound``.  Exact: ``met`` if no run of ``bound`` steps
    avoids it, else ``refuted`` with such a run as the trace.
    """
    states, steps = _unroll(ts, bound)
    s = z3.Solver()
    s.set("timeout", timeout_ms)
    s.add(ts.init(states[0]), *steps, *[z3.Not(prop(st)) for st in states])
    r = s.check()
    if r == z3.unsat:
        return TemporalVerdict("met", "bounded", bound=bound)
    if r == z3.sat:
        return TemporalVerdict("refuted", "bounded", bound=bound,
                               trace=_trace(s.model(), states),
                               detail=f"not reached within {bound} steps")
    return TemporalVerdict("inconclusive", "bounded", bound=bound,
                           detail=f"solver: {s.reason_unknown()}")


def check_eventually(ts: TransitionSystem, prop: Pred, *,
                     ranking: Callable[[State], z3.ArithRef] | None = None,
                     invariant: Pred | None = None, bound: int = 10,
                     timeout_ms: int = 10_000) -> TemporalVerdict:
    """Decide unbounded ``eventually prop``.

    Proved only through a user-supplied integer ``ranking`` function and
    an ``invariant`` (default true) that is itself proved by k-induction:
    in every invariant state where ``prop`` is false, the rank is >= 0
    and every step decreases it strictly.  Without a ranking function, or
    if its conditions fail: a run of ``bound`` steps missing ``prop`` is
    reported as ``inconclusive`` with its trace (it is not a lasso, so not
    a counterexample to liveness).  If every run of ``bound`` steps reaches
    ``prop``, that is a proof (``proved``, method ``bounded``).
    """
    inv = invariant or (lambda st: z3.BoolVal(True))
    why: str | None = "no ranking function"
    if ranking is not None:
        iv = check_always(ts, inv, max_k=bound, timeout_ms=timeout_ms) if invariant else None
        if iv is not None and iv.status != "proved":
            why = (f"ranking function not used: its invariant is not proved ({iv.status} by {iv.method}"
                   + (f": {iv.detail}" if iv.detail else "") + ")")
        else:
            why = _ranking_fails(ts, prop, inv, ranking, timeout_ms)
            if why is None:
                return TemporalVerdict("proved", "ranking", k=iv.k if iv else None,
                                       detail="in every state of the invariant where it does not hold, the "
                                              "ranking function is >= 0 and every step decreases it")
    bounded = check_eventually_within(ts, prop, bound, timeout_ms=timeout_ms)
    if bounded.status == "inconclusive":  # the solver could not say: nothing was checked, and no lasso is sought
        return TemporalVerdict("inconclusive", "bounded", bound=None,
                               detail=f"Z3 could not decide whether a run of {bound} steps misses it "
                                      f"({bounded.detail}); no step was checked")
    if bounded.status == "met":
        # every run reaches prop within `bound` steps: a proof, not a guess
        return TemporalVerdict("proved", "bounded", bound=bound,
                               detail=f"reached within {bound} steps on every run")
    lasso = find_lasso(ts, prop, bound, timeout_ms=timeout_ms)
    if lasso is not None:
        return lasso
    return TemporalVerdict("inconclusive", "bounded", bound=bound, trace=bounded.trace,
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
        s.set("timeout", timeout_ms)
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
    one, s_n == s_j.  Repeating s_j..s_n forever is an infinite run of the
    system (a step depends on its two states only) on which ``prop`` never
    holds: ``refuted`` (method ``lasso``, ``loop = j``).  ``None`` when no
    such run of up to ``bound`` steps exists or the solver cannot say.
    """
    for n in range(1, bound + 1):
        states, steps = _unroll(ts, n)
        s = z3.Solver()
        s.set("timeout", timeout_ms)
        same = [z3.And(*[states[n][v] == states[j][v] for v in ts.sorts]) for j in range(n)]
        s.add(ts.init(states[0]), *steps, *[z3.Not(prop(st)) for st in states], z3.Or(*same))
        if s.check() == z3.sat:
            m = s.model()
            loop = next(j for j in range(n) if z3.is_true(m.eval(same[j], model_completion=True)))
            return TemporalVerdict("refuted", "lasso", bound=n, trace=_trace(m, states), loop=loop,
                                   detail=f"a run whose step {n} returns to step {loop} and never reaches it")
    return None
