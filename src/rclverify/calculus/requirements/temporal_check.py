"""Decide a temporal requirement over the composed system (docs/requirements.md).

The statement (:mod:`rclverify.model.plan.temporal`) is decided over the
transition system of its cone (:mod:`.transition`) by the engine of
:mod:`.temporal`, picked by the statement's shape (:mod:`.temporal_decide`):

==========================  ===============================================
statement                   decided by
==========================  ===============================================
``always F``                BMC then k-induction (``proved`` with k)
``always next F``           the same from step 1 on
``eventually[<= N] F``      unrolling N steps (exact)
``eventually F``            the plan's ``ranking:`` (and ``invariant:``)
                            valid (proved, method ``ranking``); every run
                            reaches F within the bound (proved); a lasso
                            missing F (refuted); else inconclusive with the
                            bound checked: never met on a bound
``next F``                  one step (exact)
``F until G``               ``always (G seen or F)`` and ``eventually G``
``always (P -> eventually   ``always`` of a monitor variable: the age of the
[<= N] Q)``, ``always       oldest P not yet answered (BMC, k-induction;
(P -> next Q)``             :mod:`.response`)
``always (P -> eventually   a P pending: the plan's ranking function, or
Q)``                        the bounded form for a small N (proved); a
                            lasso with a P pending around its loop
                            (refuted); else inconclusive (:mod:`.response`)
==========================  ===============================================

Other nestings raise a located ``E-temporal`` error (the plan's
``resolve`` reports it through :func:`shape`).  The record has the fields of
a state requirement's (:func:`.check.check_requirement`) so that the
roll-up (:mod:`.rollup`) treats both alike, plus ``temporal``: ``{status,
method, k, bound, loop, detail, trace}`` with ``trace`` one entry per step,
``{"step": i, "nodes": [{"node", "values": {"in.x": v}}]}``.  A proof uses
every premise of the cone (there is no unsat core of an induction), so
``met`` needs the evidence of every guarantee of the cone discharged, with
one exception: a node's ``initially`` that the proof also holds without
(:mod:`.initial_needed`) is traced, not needed; a
system with no run at all (its premises contradict each other) proves
anything, and is reported ``consistency: inconsistent``; a proof from
consistent premises that no run exercises (a value it reads is never
published, its premise holds on no run: :mod:`.exercised`) is reported
``vacuity: vacuous`` with ``vacuity_reason``, as a state requirement's
premise that never holds is (docs/requirements.md, "A proof no run
exercises").
"""
from __future__ import annotations

import time
from typing import Any, Callable, Collection

import z3

from rclverify.model.plan.formal import Formal, parse_formal
from rclverify.model.plan.model import Plan, Requirement
from rclverify.model.plan.ranking import parse_hints
from rclverify.model.plan.state import state_types
from rclverify.model.plan.temporal import Temporal, operands, parse_temporal, shape
from rclverify.calculus.health.witness import points_for
from rclverify.lang.types import Checked, EmptyT
from rclverify.semantics.connectives import conj
from rclverify.semantics.values import render
from rclverify.model.system.model import SystemModel
from rclverify.calculus.requirements.safety import Hint
from rclverify.calculus.requirements.temporal import TemporalVerdict, TransitionSystem
from rclverify.calculus.requirements.temporal_decide import DEFAULT_BOUND, decide
from rclverify.calculus.requirements.lasso import find_table_lasso
from rclverify.calculus.requirements.lasso_confirm import confirm_lasso
from rclverify.calculus.requirements import math_runs
from rclverify.calculus.requirements.initial_needed import initially_not_needed
from rclverify.calculus.requirements.exercised import NON_VACUOUS, vacuity
from rclverify.calculus.requirements.composed import ComposedSystem, variable_types
from rclverify.calculus.requirements.transition import build_system
from rclverify.calculus.requirements.published import first_inputs
from rclverify.semantics.definedness import guarded
from rclverify.semantics.encode import Encoder
from rclverify.lang.types import FuncT
from rclverify.semantics import wallclock
from rclverify.calculus.shapes import Gaps, TraceStep, Vacuity
from rclverify.records.stage_records import RequirementBase

#: Each Z3 query's budget (ms): an unknown is inconclusive, never upgraded.
TIMEOUT_MS = 2_000


def is_temporal(req: Requirement, checked: Checked, plan: Plan) -> bool:
    """Whether ``req``'s formal statement has a temporal operator."""
    if req.formal is None:
        return False
    return isinstance(parse_temporal(req.formal, checked, req.id, state_types(plan.states, checked)), Temporal)


def statement(req: Requirement, checked: Checked, plan: Plan) -> Temporal:
    """The parsed temporal statement of ``req`` (raises :class:`RclError`)."""
    assert req.formal is not None  # a temporal requirement has a formal statement (is_temporal)
    t = parse_temporal(req.formal, checked, f"{req.id} formal", state_types(plan.states, checked))
    assert isinstance(t, Temporal)
    return t


def _steps(trace: list[dict[str, str]], sys: ComposedSystem) -> list[TraceStep]:
    """A trace as steps x nodes: ``[{"step": i, "nodes": [{"node", "values"}]}]``."""
    out: list[TraceStep] = []
    for i, st in enumerate(trace):
        rows: dict[str, dict[str, str]] = {}
        for name, value in st.items():
            if name in sys.variables:
                n, p, v = sys.variables[name]
                rows.setdefault(n, {})[v if p == "run" else f"{p}.{v}"] = " ".join(value.split())
        out.append({"step": i, "nodes": [{"node": n, "values": rows[n]} for n in sys.cone if n in rows]})
    return out


def check_temporal(req: Requirement, checked: Checked, model: SystemModel, plan: Plan, base: RequirementBase,
                   *, bound: int = DEFAULT_BOUND, timeout_ms: int = TIMEOUT_MS) -> dict[str, Any]:
    """The record of temporal requirement ``req`` (module docstring);
    ``base`` the fields :func:`.check.check_requirement` fills for every
    requirement.  Raises :class:`RclError` for a statement that does not
    check; never raises on solver trouble."""
    t0 = time.perf_counter()
    t = statement(req, checked, plan)
    shape(t, req.formal.loc if req.formal else req.loc)
    assuming = [parse_formal(a, checked, f"{req.id} assuming") for a in req.assuming]
    rank, inv = parse_hints(req.ranking, req.invariant, t, checked, req.id, state_types(plan.states, checked))
    ops = operands(t)
    hints = [h for h in (rank, inv) if h is not None]
    want = {u for f in (*ops, *assuming, *hints) for n in f.nodes for u in (model.upstream(n) or [n])}
    cone = [n for n in model.nodes if n in want]  # as requirements/check.cone_of
    ctx = _Question(req, checked, model, plan, base, t, assuming, rank, inv, cone, bound, timeout_ms)
    sys, v, missing = ctx.solve()
    lasso = v.status == "refuted" and "lasso" in v.method.split(" + ")
    gaps = missing.get("missing_progress", []) if lasso else []
    stuck = missing.get("missing_initially", []) if lasso else []
    out: dict[str, Any] = {**base, "cone": cone, "premises": len(sys.premises), "used": [], "traced_not_needed": [],
                           "temporal": {**v.to_json(), "trace": _steps(v.trace, sys),
                                        "ranking": base.get("ranking"), "invariant": base.get("invariant"),
                                        "missing_progress": gaps, "missing_initially": stuck}}
    if v.status in ("proved", "met"):
        _proved(out, sys, ctx)
    elif v.status == "refuted":
        mentioned = {n for f in ops for n in f.nodes}
        # a run that stops, or a lasso resting on a node that never answers, is not let through by a guarantee
        out.update(verdict="refuted", failed_to_prevent=[] if "deadlock" in v.method.split(" + ") or gaps or stuck else [
            p for p in sys.premises if p["kind"] == "guarantee" and p["node"] in mentioned])
    else:
        out.update(verdict="inconclusive", reason=v.detail or "undecided")
    out["duration_s"] = round(time.perf_counter() - t0, 4)
    return out


def _proved(out: dict[str, Any], sys: ComposedSystem, ctx: _Question) -> None:
    """A proved (or met) statement's record: its premises used, whether
    they are consistent (a first step exists, the initial values can be
    met), and the ``initially`` declarations the proof does not need."""
    a, b = sys.ts.state(0), sys.ts.state(1)
    s = z3.Solver()
    wallclock.limit(s, ctx.timeout_ms)  # steps decide, the clock is a net
    s.add(sys.ts.init(a), sys.ts.trans(a, b))
    r = s.check()
    used = sys.premises
    out.update(verdict="proved", used=used)
    # an initial value no output meets forces its node to answer at step 0: it removes runs, as a contradiction
    bad, why = sys.initial_values_unsatisfiable(ctx.timeout_ms)
    if bad:  # the initial values no output meets: the precise core (they alone may leave no run)
        out.update(consistency="inconsistent", inconsistent_core=bad)
    elif r == z3.unsat:
        out.update(consistency="inconsistent", inconsistent_core=used)
    elif r == z3.sat and not why:
        out.update(consistency="consistent")
        vac = ctx.exercised(sys)  # a proof no run exercises is vacuous (.exercised)
        silent = vac.pop("never_publish", None)
        out.update(vac)
        if silent:
            out["temporal"]["never_publish"] = silent
        if vac.get("vacuity") in (None, NON_VACUOUS):
            spare = initially_not_needed(sys.premises, ctx.proved_without)
            out.update(used=[p for p in used if not (p["kind"] == "initial value" and p["node"] in spare)],
                       traced_not_needed=[p for p in used if p["kind"] == "initial value" and p["node"] in spare])
    else:
        out.update(consistency="undecided", consistency_reason=s.reason_unknown() if r != z3.sat else why)


class _Question:
    """One temporal statement asked of its cone: what every system built to
    decide it shares (:meth:`solve` builds one, with some nodes' ``initially``
    left out to ask whether the proof needs them)."""

    def __init__(self, req: Requirement, checked: Checked, model: SystemModel, plan: Plan, base: RequirementBase,
                 t: Any, assuming: list[Formal], rank: Any, inv: Formal | None, cone: list[str],
                 bound: int, timeout_ms: int) -> None:
        self.req, self.checked, self.model, self.plan, self.base = req, checked, model, plan, base
        self.t, self.assuming, self.rank, self.inv, self.cone = t, assuming, rank, inv, cone
        self.bound, self.timeout_ms = bound, timeout_ms

    def solve(self, without: Collection[str] = ()) -> tuple[ComposedSystem, TemporalVerdict, Gaps]:
        """The system of the cone (the nodes of ``without`` built with no ``initially``) and its verdict."""
        return _System(self, without).decide()

    def exercised(self, sys: ComposedSystem) -> Vacuity:
        """The vacuity fields of the statement proved over ``sys`` (:func:`.exercised.vacuity`)."""
        enc = Encoder(self.checked.env)

        def raw(f: Formal) -> Callable[[Any], Any]:
            return lambda s: enc.formula(f.expr, f.scope, sys.statement_symbols(s))
        hint = Hint(raw(self.inv), " ".join(self.req.invariant.text.split()) if self.req.invariant is not None
                    else "invariant:") if self.inv is not None else None
        return vacuity(self.t, sys.ts, sys.pub, raw, max_k=self.bound, timeout_ms=self.timeout_ms, hint=hint)

    def proved_without(self, nodes: Collection[str]) -> bool:
        """Whether the statement is still proved, and exercised by a run, on the system built without the
        ``initially`` of ``nodes`` (:func:`.initial_needed.initially_not_needed`): a loop only an initial value
        starts proves an ``always`` without it, vacuously, so the declaration stays needed."""
        sys, v, _ = self.solve(nodes)
        return v.status in ("proved", "met") and self.exercised(sys).get("vacuity") in (None, NON_VACUOUS)


class _System:
    """One system of a question's cone and the predicates over its states."""

    def __init__(self, q: _Question, without: Collection[str]) -> None:
        self.q = q
        firsts = first_inputs([f.expr for f in [*operands(q.t), *q.assuming]])  # each first(C.in.x): a flag
        self.sys = build_system(q.cone, q.checked, q.model, q.plan, without_initially=without, firsts=firsts)
        self.enc = Encoder(q.checked.env)
        if q.assuming:  # the requirement's own assumptions hold in every state
            self.assume()
        if math_runs.mentions_math([q.checked.nodes[n] for n in q.cone if n in q.checked.nodes], q.checked.env,
                                   q.t, q.assuming, q.inv):  # else no term is built: the query stays as it was
            self.sys.ts = math_runs.with_facts(self.sys.ts, [self.raw(f) for f in operands(q.t)])
        self.types = variable_types(self.sys, q.checked, q.plan)
        self.points = max([points_for(q.plan.instances.get(n)) for n in q.cone] or [points_for(None)])
        self.confirmed: list[dict[str, str]] | None = None  # the trace of a lasso confirmed on its values

    def raw(self, f: Formal) -> Callable[[Any], Any]:
        """``f`` in a state; a statement's formula counts only where it is defined (its definedness
        conditions with it, docs/semantics.md, "Definedness"), an ``assuming`` formula as written."""
        enc, sys = self.enc, self.sys
        expr = f.expr if any(f is a for a in self.q.assuming) else guarded(f.expr)
        return lambda s: enc.formula(expr, f.scope, sys.statement_symbols(s))

    def pred(self, f: Formal) -> Callable[[Any], Any]:  # must hold: only where its values are published
        raw = self.raw(f)
        return lambda s: z3.Implies(self.sys.pub.defined(f.mentions, s), raw(s))

    def reach(self, f: Formal) -> Callable[[Any], Any]:  # must be reached: on published values
        raw = self.raw(f)
        return lambda s: conj(self.sys.pub.defined(f.mentions, s), raw(s))

    def assume(self) -> None:
        """The requirement's ``assuming`` formulas hold in every state of the system."""
        sys, q = self.sys, self.q
        holds = [self.pred(a) for a in q.assuming]
        ts = sys.ts
        sys.ts = TransitionSystem(ts.sorts, lambda s: conj(ts.init(s), *[h(s) for h in holds]),
                                  lambda s, u: conj(ts.trans(s, u), *[h(s) for h in holds], *[h(u) for h in holds]),
                                  ts.fairness)
        for k, a in enumerate(q.assuming, 1):
            sys.premises.append({"label": f"assuming {k}", "kind": "assuming", "node": None, "index": k,
                                 "text": q.base["assuming"][k - 1], "source": q.base["source"]})

    def tables(self, goal: Formal, v: TemporalVerdict, ts: TransitionSystem) -> TemporalVerdict:
        """The finite-table lasso search over ``ts``, confirmed on the trace (:mod:`.lasso`)."""
        q, types, points = self.q, self.types, self.points
        if any(isinstance(ty, EmptyT) for ty in types.values()):
            return v
        try:
            found = find_table_lasso(ts, self.reach(goal), types, bound=q.bound, points=points)
        except (ValueError, z3.Z3Exception) as exc:
            found = f"the finite-table search failed ({exc})"
        if isinstance(found, str):
            return TemporalVerdict(v.status, v.method, k=v.k, bound=v.bound, trace=v.trace, loop=v.loop,
                                   detail=f"{v.detail}; {found}")
        why = confirm_lasso(found.values, found.loop, q.cone, self.sys.variables, types, q.checked, q.model, q.plan,
                            goal, q.assuming, [f.label for f in ts.fairness], self.sys.pub)
        if why is not None:
            return TemporalVerdict(v.status, v.method, k=v.k, bound=v.bound, trace=v.trace, loop=v.loop,
                                   detail=f"{v.detail}; a lasso with {points}-point tables was found but not "
                                          f"confirmed on its values ({why})")
        n = len(found.values) - 1
        self.confirmed = [{k: render(x) for k, x in st.items()} for st in found.values]
        return TemporalVerdict("refuted", "lasso", bound=n, loop=found.loop,
                               trace=[{k: render(x) for k, x in st.items()} for st in found.values],
                               detail=f"a run whose step {n} returns to step {found.loop} and never reaches it "
                                      f"(found with every function a {points}-point table, confirmed on the "
                                      f"trace's values)")

    def decide(self) -> tuple[ComposedSystem, TemporalVerdict, Gaps]:
        q, sys, enc, rank = self.q, self.sys, self.enc, self.q.rank
        ranking = (lambda s: enc.term(rank.expr, rank.scope, sys.statement_symbols(s))) if rank is not None else None
        inv_pred = self.raw(q.inv) if q.inv is not None else None
        missing: Gaps = {}
        v = decide(q.t, sys, self.pred, bound=q.bound, timeout_ms=q.timeout_ms, tables=self.tables, ranking=ranking,
                   invariant=inv_pred, checked=q.checked, gaps=missing,
                   tables_first=any(isinstance(ty, FuncT) for ty in self.types.values()), reach=self.reach,
                   hint_text=" ".join(q.req.invariant.text.split()) if q.req.invariant is not None else "")
        return sys, math_runs.unconfirmed(v, sys.ts, [self.raw(f) for f in operands(q.t)], self.confirmed), missing
