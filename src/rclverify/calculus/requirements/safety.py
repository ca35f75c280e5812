"""``always prop`` proved beyond plain k-induction: a user's invariant, then IC3/PDR.

:func:`.temporal.check_always` (BMC and k-induction) fails to prove a
property that holds when unreachable states lead to a violation: the step
case finds such a path, the base case no run.  :func:`prove_always` then

1. with the plan's ``invariant:`` (a :class:`Hint`), proves ``always (I and
   prop)`` by the same k-induction: I and the property strengthen each other
   (a candidate that is not invariant, or not strong enough, is named with
   the step that breaks it, :func:`hint_fails`);
2. generates an invariant from the system's constants (:mod:`.houdini`)
   and proves the property by k-induction in its states (method
   ``k-induction with generated invariant``);
3. asks Z3's Spacer for an inductive invariant (:mod:`.pdr`; within the
   proved hint, when there is one), re-checks the certificate with plain Z3
   queries and proves the property with it (method ``pdr``); a run Spacer
   says exists is searched by bounded model checking (method ``bmc``);
4. else says ``inconclusive``, with what each step found and the next step
   for the user: the counterexample to induction, one step from a state
   where the property holds to one where it fails, which an ``invariant:``
   must exclude.

A verdict is never guessed: each solver ``unknown`` or time limit leaves
``inconclusive`` with its reason (docs/requirements.md, "Proofs a user can
finish").  Source of the rules: k-induction with auxiliary invariants
(Sheeran, Singh, Stalmarck, FMCAD 2000; Kind 2's combination with IC3,
Champion et al., CAV 2016).
"""
from __future__ import annotations

from dataclasses import dataclass

import z3

from rclverify.calculus.requirements.houdini import generate, within as assuming
from rclverify.calculus.requirements.pdr import recheck, shortest_violation, shown, spacer_invariant
from rclverify.calculus.requirements.temporal import check_always
from rclverify.calculus.requirements.tsys import Pred, TemporalVerdict, TransitionSystem, trace_of
from rclverify.semantics import wallclock
from rclverify.semantics.connectives import conj

#: Spacer's time limit is this many times the per-query limit (it is one query that does the work of many).
PDR_FACTOR = 3
#: At most this many variables are named in a counterexample to induction.
NAMED = 12


@dataclass(frozen=True)
class Hint:
    """The plan's ``invariant:`` for a requirement: ``pred`` over one state,
    ``text`` as written (for the messages)."""

    pred: Pred
    text: str


def _values(state: dict[str, str], before: dict[str, str] | None = None) -> str:
    """``{x = 1, y = 2}``: the values of one state (with ``before``, only
    those that changed), at most :data:`NAMED`, ``<pending>`` read as the
    monitor's name."""
    items = [(k, " ".join(v.split())) for k, v in state.items()
             if before is None or before.get(k) != v]
    text = ", ".join(f"{k} = {v}" for k, v in items[:NAMED])
    more = f", ... ({len(items) - NAMED} more)" if len(items) > NAMED else ""
    return "{" + text + more + "}"


def induction_step(ts: TransitionSystem, inside: Pred, timeout_ms: int,
                   part: Pred | None = None) -> tuple[dict[str, str], dict[str, str], bool] | str | None:
    """A counterexample to 1-induction of ``inside``: a state where it holds
    and the next where it fails, ``(state, next, part fails next)`` with
    states as ``{variable: text}`` (``part``: a conjunct of ``inside``,
    default ``inside``); ``None`` when ``inside`` is inductive; a sentence
    when Z3 cannot say."""
    a, b = ts.state(0, "cti"), ts.state(1, "cti")
    s = z3.Solver()
    wallclock.limit(s, timeout_ms)  # steps decide, the clock is a net
    s.add(inside(a), ts.trans(a, b), z3.Not(inside(b)))
    r = s.check()
    if r == z3.unsat:
        return None
    if r == z3.unknown:
        return f"Z3 could not find a step that breaks it ({s.reason_unknown()})"
    m = s.model()
    first, second = trace_of(m, [a, b])
    return first, second, z3.is_false(m.eval((part or inside)(b), model_completion=True))


def hint_fails(ts: TransitionSystem, prop: Pred, hint: Hint, *, max_k: int,
               timeout_ms: int) -> tuple[str, bool] | TemporalVerdict:
    """``always (hint and prop)`` by k-induction: the verdict ``proved``
    (method ``k-induction with invariant``) or ``refuted`` when a run
    violates ``prop`` itself; else ``(why, hint proved)``: why the candidate
    failed, with the step that breaks it, ending in the next step to take,
    and whether the hint alone was proved invariant (by k-induction or
    IC3/PDR, :func:`by_pdr`: a hint false only deep in a run is found so)."""
    both = lambda s: conj(hint.pred(s), prop(s))  # noqa: E731
    v = check_always(ts, both, max_k=max_k, timeout_ms=timeout_ms)
    if v.status == "proved":
        return TemporalVerdict("proved", "k-induction with invariant", k=v.k, bound=v.bound,
                               detail=f"the invariant {hint.text!r} and the property together are {v.k}-inductive")
    if v.status == "refuted":  # the shortest run leaving both: does one as short violate the property?
        w = check_always(ts, prop, max_k=(v.bound or 0) + 1, timeout_ms=timeout_ms)
        if w.status == "refuted":
            return w
        return _false_on_a_run(hint, v), False
    if v.method == "bmc":  # the solver could not decide a base case
        return f"the invariant {hint.text!r} could not be checked ({v.detail})", False
    alone = check_always(ts, hint.pred, max_k=max_k, timeout_ms=timeout_ms)
    if alone.status == "inconclusive" and alone.method != "bmc":
        alone = by_pdr(ts, hint.pred, max_k=max_k, timeout_ms=timeout_ms)
    if alone.status == "refuted":
        return _false_on_a_run(hint, alone), False
    cti = induction_step(ts, both, timeout_ms, part=hint.pred)
    if cti is None or isinstance(cti, str):
        return (f"the invariant {hint.text!r} and the property are not {max_k}-inductive together"
                + (f"; {cti}" if cti else "")), alone.status == "proved"
    s0, s1, hint_broken = cti
    if alone.status == "proved":  # true on every run, not strong enough
        return (f"the invariant {hint.text!r} holds on every run ({alone.method}) but is not strong enough: it "
                f"allows the state {_values(s0)}, from which one step leads to {_values(s1, s0)}, where the property "
                "fails; next step: add to the invariant a conjunct that excludes the first state (it cannot be "
                "reached if the property holds)"), True
    broken = "the invariant" if hint_broken else "the property"
    return (f"the invariant {hint.text!r} is not inductive with the property: from the state {_values(s0)}, where "
            f"both hold, one step leads to {_values(s1, s0)}, where {broken} fails; next step: if the first state "
            f"cannot be reached, add to the invariant a conjunct that excludes it; if it can, {broken} is wrong "
            "there"), False


def _false_on_a_run(hint: Hint, v: TemporalVerdict) -> str:
    """The message for a hint that a run of the system violates (``v``'s trace)."""
    return (f"the invariant {hint.text!r} is false on a run of the system: at step {v.bound}, "
            f"{_values(v.trace[-1]) if v.trace else 'the last state'}; next step: weaken it so that it holds there")


def by_pdr(ts: TransitionSystem, prop: Pred, *, max_k: int, timeout_ms: int,
           within: Pred | None = None) -> TemporalVerdict:
    """``always prop`` by Spacer (:mod:`.pdr`), the certificate re-checked
    before it proves anything; ``within`` a proved invariant of ``ts`` that
    the clauses may assume.  ``proved`` (method ``pdr``, ``certificate`` the
    invariant's text; ``pdr with invariant`` with ``within``), ``refuted`` (method ``bmc``, the shortest run found
    from ``max_k`` steps on) or ``inconclusive`` with the reason."""
    sys = ts if within is None else TransitionSystem(
        ts.sorts, lambda s: conj(ts.init(s), within(s)), lambda s, t: conj(ts.trans(s, t), within(s), within(t)),
        ts.fairness)
    limit = timeout_ms * PDR_FACTOR
    ans = spacer_invariant(sys, prop, limit)
    if ans.status == "invariant":
        assert ans.invariant is not None
        bad = recheck(sys, prop, ans.invariant, timeout_ms)
        if bad is not None:
            return TemporalVerdict("inconclusive", "pdr", detail=f"IC3/PDR (Z3 Spacer) answered with an invariant, "
                                                                  f"but {bad}")
        text = shown(ans.invariant)
        return TemporalVerdict("proved", "pdr" if within is None else "pdr with invariant", certificate=text,
                               detail="IC3/PDR (Z3 Spacer) found an inductive invariant, re-checked by Z3: every "
                                      "initial state satisfies it, every step keeps it, it implies the property "
                                      "(the certificate)")
    if ans.status == "reachable":
        found = shortest_violation(sys, prop, max_k, limit)
        if isinstance(found, str):
            return TemporalVerdict("inconclusive", "pdr", detail=f"IC3/PDR (Z3 Spacer) says a run of the property's "
                                                                  f"cone of influence violates it, but {found}")
        n, trace = found
        return TemporalVerdict("refuted", "bmc", bound=n, trace=trace, detail=f"violated at step {n}")
    return TemporalVerdict("inconclusive", "pdr", detail=f"IC3/PDR (Z3 Spacer) found no inductive invariant within "
                                                          f"{limit} ms ({ans.reason or 'unknown'})")


def _generated(ts: TransitionSystem, prop: Pred, *, max_k: int, timeout_ms: int) -> TemporalVerdict | str:
    """k-induction of ``prop`` assuming the invariant :func:`.houdini.generate`
    finds: the verdict when it decides, else what was found (a sentence)."""
    g = generate(ts, prop, timeout_ms, timeout_ms * PDR_FACTOR)
    if isinstance(g, str):
        return f"no invariant was generated ({g})"
    if not g:
        return "no bound of the system's constants is invariant"
    text = " and ".join(t for t, _ in g)
    shown_ = text if len(text) <= 300 else text[:297] + "..."
    w = check_always(assuming(ts, g), prop, max_k=max_k, timeout_ms=timeout_ms)
    if w.status == "proved":
        return TemporalVerdict("proved", "k-induction with generated invariant", k=w.k, bound=w.bound,
                               detail=f"{w.k}-inductive in the states of the invariant generated from the system's "
                                      f"constants (Houdini; every initial state satisfies it and every step keeps "
                                      f"it): {shown_}")
    if w.status == "refuted":  # the same runs as the system's: a genuine counterexample
        return w
    return f"k-induction assuming the generated invariant ({shown_}) is not {max_k}-inductive either"


def prove_always(ts: TransitionSystem, prop: Pred, *, max_k: int = 10, timeout_ms: int = 10_000,
                 hint: Hint | None = None, monitor: str = "") -> TemporalVerdict:
    """Decide ``always prop`` (module docstring): k-induction, then the
    ``hint`` with the property, then k-induction with a generated invariant,
    then IC3/PDR.  ``monitor`` names, for the
    messages, a history variable the property reads (the bounded response's
    pending age).  Returns a :class:`TemporalVerdict`; ``inconclusive``
    names what each step found and, when no hint was given, the step that
    breaks 1-induction as the place an ``invariant:`` must exclude."""
    v = check_always(ts, prop, max_k=max_k, timeout_ms=timeout_ms)
    if v.status != "inconclusive" or v.method == "bmc":
        return v
    said = [v.detail]
    proved_hint, hint_said = None, ""
    if hint is not None:
        h = hint_fails(ts, prop, hint, max_k=max_k, timeout_ms=timeout_ms)
        if isinstance(h, TemporalVerdict):
            return h
        hint_said = h[0]
        said.append(hint_said)
        proved_hint = hint.pred if h[1] else None
    g = _generated(ts, prop, max_k=max_k, timeout_ms=timeout_ms)
    if isinstance(g, TemporalVerdict):
        if hint is not None and g.status == "proved":
            g.detail += f" (the plan's invariant did not help: {hint_said})"
        return g
    said.append(g)
    p = by_pdr(ts, prop, max_k=max_k, timeout_ms=timeout_ms, within=proved_hint)
    if p.status != "inconclusive":
        if hint is not None and p.status == "proved":
            p.detail += (" (inside the plan's invariant, proved on its own)" if proved_hint else
                         f" (the plan's invariant did not help: {hint_said})")
        return p
    said.append(p.detail)
    if hint is None:
        cti = induction_step(ts, prop, timeout_ms)
        if isinstance(cti, tuple):
            said.append(f"the step that breaks induction goes from {_values(cti[0])} to {_values(cti[1], cti[0])}"
                        + (f" ({monitor})" if monitor else "")
                        + "; next step: if the first state cannot be reached, give the requirement an invariant: that "
                          "excludes it (docs/requirements.md, Proofs a user can finish)")
    return TemporalVerdict("inconclusive", v.method, k=v.k, bound=v.bound, detail="; ".join(said))
