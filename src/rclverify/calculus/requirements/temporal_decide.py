"""A temporal statement decided over a composed system by its shape (the
table of :mod:`.temporal_check`): which engine decides which shape
(:func:`decide`), the finite-table lasso search asked where the general
query is inconclusive, a lasso in which a node never answers explained
(:mod:`.progress_gap`), and ``proved`` standing only where no run stops
(:mod:`.deadlock`).
"""
from __future__ import annotations

from typing import Any, Callable, cast

import z3

from rclverify.model.plan.formal import Formal
from rclverify.model.plan.temporal import Temporal, shape
from rclverify.lang.types import Checked
from rclverify.semantics.connectives import disj
from rclverify.calculus.requirements.composed import ComposedSystem
from rclverify.calculus.requirements.deadlock import runs_go_on
from rclverify.calculus.requirements.safety import Hint, prove_always
from rclverify.calculus.requirements.temporal import (TemporalVerdict, TransitionSystem, check_eventually,
                                                      check_eventually_within, check_next, check_until, find_lasso,
                                                      with_flag)
from rclverify.calculus.requirements.progress_gap import EVEN_SO, explain_idle, stuck_in_loop, stuck_words
from rclverify.calculus.shapes import Gaps


#: The bound of BMC for an unbounded ``eventually`` and of k-induction's k.
DEFAULT_BOUND = 10



#: A table search over a system: ``tables(F, v, ts)`` (:func:`check_temporal`).
Tables = Callable[[Formal, TemporalVerdict, TransitionSystem], TemporalVerdict]



def decide(t: Temporal, sys: ComposedSystem, pred: Callable[[Formal], Callable[[Any], Any]], *,
           bound: int = DEFAULT_BOUND, timeout_ms: int = 10_000, tables: Tables | None = None,
           ranking: Callable[[Any], Any] | None = None, invariant: Callable[[Any], Any] | None = None,
           checked: Checked | None = None, gaps: Gaps | None = None,
           tables_first: bool = False, reach: Callable[[Formal], Callable[[Any], Any]] | None = None,
           hint_text: str = "") -> TemporalVerdict:
    """Decide statement ``t`` over ``sys`` (module table); ``pred(F)`` is
    F as a predicate over one state where F must hold (under ``always``,
    the left of ``until``), ``reach(F)`` (default ``pred``) where F must be
    reached (under ``eventually`` and ``next``, the right of ``until``): on
    published values, :mod:`.published`.  ``tables(F, v, ts)`` is asked when the
    verdict ``v`` on an unbounded ``eventually F`` over ``ts`` is
    inconclusive (the finite-table lasso search of :func:`check_temporal`);
    with ``tables_first`` (the system has function-typed variables, over
    which Z3's general bounded query seldom decides: "decide first
    with what decides") it is asked first, on the system in which every node
    answers what it accepts, and a confirmed lasso there is the verdict
    without the general query;
    ``ranking`` and ``invariant`` (over one state) are the plan's, for that
    ``eventually``.  A lasso in which a node never answers what it accepts
    is explained (:func:`.progress_gap.explain_idle`, with ``checked``): what
    is missing is put in ``gaps`` (``missing_progress``, ``missing_initially``).  A verdict ``proved`` stands
    only if no run of the system stops (:func:`.deadlock.runs_go_on`).  ``invariant`` (written ``hint_text``)
    also strengthens the proof of a safety shape (``always``, ``always next``, the bounded and next
    response, ``until``'s safety part: :func:`.safety.prove_always`, which tries IC3/PDR too)."""
    hint = Hint(invariant, hint_text or "invariant:") if invariant is not None else None
    return runs_go_on(sys.ts, _decide(t, sys, pred, bound, timeout_ms, tables, ranking, invariant, checked,
                                      gaps if gaps is not None else {}, tables_first, reach or pred, hint),
                      max_k=bound, timeout_ms=timeout_ms)



def _decide(t: Temporal, sys: ComposedSystem, pred: Callable[[Formal], Callable[[Any], Any]], bound: int,
            timeout_ms: int, tables: Tables | None,
            ranking: Callable[[Any], Any] | None, invariant: Callable[[Any], Any] | None,
            checked: Checked | None, gaps: Gaps, tables_first: bool = False,
            reach: Callable[[Formal], Callable[[Any], Any]] | None = None, hint: Hint | None = None) -> TemporalVerdict:
    kind = shape(t, None)
    got = reach or pred
    ts = sys.ts

    def even_so(w: TemporalVerdict) -> TemporalVerdict:
        """A lasso of the synchronous system: the goal is missed even with progress, unless the loop
        never starts for want of a published value (then the initial values to declare are named)."""
        stuck = stuck_in_loop(w.trace, w.loop, sys, checked) if checked is not None else []
        gaps["missing_initially"] = stuck
        said = stuck_words(stuck) if stuck else EVEN_SO
        return TemporalVerdict(w.status, w.method, k=w.k, bound=w.bound, trace=w.trace, loop=w.loop,
                               deadlock=w.deadlock, detail=f"{w.detail}; {said}")

    def eventually(g: Formal) -> TemporalVerdict:
        tried_sync = False
        if tables_first and tables is not None and checked is not None and not sys.eager:
            w = tables(g, TemporalVerdict("inconclusive", "bounded"), sys.synchronous(ts))
            if w.status == "refuted":  # a confirmed lasso of the declared system: the general query cannot undo it
                return even_so(w)
            tried_sync = True
        v = check_eventually(ts, got(g), ranking=ranking, invariant=invariant, bound=bound, timeout_ms=timeout_ms,
                             prove=lambda ts2, p: prove_always(ts2, p, max_k=bound, timeout_ms=timeout_ms))
        by_tables = tables is not None and v.status == "inconclusive"
        if by_tables and checked is not None and not sys.eager and not tried_sync:
            # every node answering what it accepts at once: the query Z3 decides best, and a lasso there is one
            # of the declared system that rests on no missing progress (.progress_gap)
            w = tables(g, v, sys.synchronous(ts))  # type: ignore[misc]
            if w.status == "refuted":
                return even_so(w)
            tried_sync = True
        if by_tables:
            v = tables(g, v, ts)  # type: ignore[misc]
        if checked is None:
            return v

        def search(ts2: TransitionSystem) -> TemporalVerdict | None:
            if by_tables:
                w = tables(g, TemporalVerdict("inconclusive", "lasso"), ts2)  # type: ignore[misc]
                return w if w.status == "refuted" else None
            return find_lasso(ts2, got(g), bound, timeout_ms=timeout_ms)
        v, found = explain_idle(v, sys, ts, checked, search, tried_sync=tried_sync)
        gaps.update(found)
        return v
    if kind == "always":
        return prove_always(ts, pred(cast(Formal, t.args[0])), max_k=bound, timeout_ms=timeout_ms, hint=hint)
    if kind == "response":  # always (P -> eventually[<= N] Q) / always (P -> next Q): calculus/requirements/response.py
        from rclverify.calculus.requirements.response import check_response, check_unbounded_response  # deferred: optional or conditional (inside a block)
        left, right = cast(Temporal, t.args[0]).args  # the shape: P -> eventually[<= N] Q or P -> next Q
        p, r = cast(Formal, left), cast(Temporal, right)
        if r.op == "eventually" and r.bound is None:
            return check_unbounded_response(ts, got(p), got(cast(Formal, r.args[0])), max_k=bound,
                                            timeout_ms=timeout_ms, ranking=ranking, invariant=invariant)
        within = r.bound if r.op == "eventually" else None
        return check_response(ts, got(p), got(cast(Formal, r.args[0])), within, max_k=bound,
                              timeout_ms=timeout_ms, hint=hint)
    if kind == "always next":
        f = pred(cast(Formal, cast(Temporal, t.args[0]).args[0]))
        ts2 = with_flag(ts, "<started>", lambda s: z3.BoolVal(False), lambda s, u: z3.BoolVal(True))
        return prove_always(ts2, lambda s: disj(z3.Not(s["<started>"]), f(s)), max_k=bound, timeout_ms=timeout_ms,
                            hint=hint)
    if kind == "next":
        return _exact(check_next(ts, got(cast(Formal, t.args[0])), timeout_ms=timeout_ms), hint)
    if kind == "eventually":
        f = got(cast(Formal, t.args[0]))
        if t.bound is not None:
            v = check_eventually_within(ts, f, t.bound, timeout_ms=timeout_ms)
            return _exact(TemporalVerdict("proved", v.method, bound=v.bound, detail=v.detail,
                                          deadlock=v.deadlock) if v.status == "met" else v, hint)
        return eventually(cast(Formal, t.args[0]))
    held, goal = cast(Formal, t.args[0]), cast(Formal, t.args[1])  # until: two formulas (the shape)
    return check_until(ts, pred(held), got(goal), eventually=lambda: eventually(goal),
                       max_k=bound, timeout_ms=timeout_ms,
                       always=lambda ts2, p: prove_always(ts2, p, max_k=bound, timeout_ms=timeout_ms, hint=hint))



def _exact(v: TemporalVerdict, hint: Hint | None) -> TemporalVerdict:
    """``v``, decided exactly by unrolling (``next F``, ``eventually[<= N] F``), with a note that the plan's
    invariant was not needed."""
    if hint is not None:
        v.detail = "; ".join(x for x in (v.detail, f"the invariant {hint.text!r} is not needed: this statement is "
                                                     "decided exactly by unrolling the steps it speaks of") if x)
    return v
