"""Decide a formal requirement from the composed contracts with Z3.

For a requirement ``R`` (its ``formal:`` statement, :mod:`rclverify.model.plan.formal`)
the premises are, over the **cone**: the nodes ``R`` (or its ``assuming:``)
mentions and every node upstream of them (``SystemModel.upstream``, the cone
of the calculus's derived properties, paper lines 556-768):

* every guarantee of every node of the cone (``Node guarantee k``);
* the connections: a consumer's input is the same Z3 symbol as the producer
  output feeding it (``SystemModel.alias``), so they are no formulas of
  their own;
* the environment conjuncts of the cone's assumptions (those over inputs
  nothing in the system produces: what the calculus leaves to the user,
  ``split_assumption``) and the plan's environment facts of the cone's nodes;
* the requirement's own ``assuming:`` formulas.

The internal conjuncts of the assumptions are not premises: the calculus
discharges them as side conditions from the producers' guarantees, and a
guarantee used by a proof only counts once its node's side conditions are
discharged (the roll-up, :mod:`.rollup`).

One labelled satisfiability query of ``premises and not R`` decides it
(``R`` with its well-definedness conditions, and those of the
``assuming:`` formulas, when they divide: docs/semantics.md,
"Definedness"; a refutation that divides by zero names the condition):

``proved``        unsat.  The unsat core, mapped back to the labelled premises
                  with their RCL source locations, is what the proof used; the
                  traced (``supported_by``) guarantees outside it are listed as
                  not needed.  A second query checks the used premises without
                  ``not R``: unsat means the proof rests on an inconsistency
                  (``consistency: inconsistent``, with that core), and the
                  requirement holds only vacuously.
``refuted``       sat.  The model is the counterexample, every I/O variable of
                  the cone in RCL names, node by node (a consumer's input shows
                  the value of the output it reads); the guarantees that failed
                  to prevent it are those of the cone that constrain a variable
                  ``R`` mentions, the traced ones first.
``inconclusive``  unknown (budget, quantifiers): never proved.

The requirements stage decides a statement over the premises of its own
nodes first (:mod:`.own_nodes`), and over the whole cone here when they do
not decide it.

A statement with a temporal operator (``always``, ``eventually``, ...) is
decided over the runs of the composed contracts instead: the check
dispatches to :mod:`.temporal_check`, whose record has the same fields plus
``temporal`` (docs/requirements.md, "Temporal requirements").
"""
from __future__ import annotations

import hashlib
import json
import time
from dataclasses import replace
from typing import Any, Sequence

import z3

from rclverify.calculus.requirements.exercised import antecedent as _premise  # the condition a requirement demands under
from rclverify.calculus.requirements.premises import NEGATED, Query, ask, first_undefined, where
from rclverify.calculus.shapes import TraceNode
from rclverify.records.stage_records import RequirementBase
from rclverify.semantics.encode import Encoder
from rclverify.calculus.health.witness import finite_witness, has_tables, points_for
from rclverify.semantics.query import DEFAULT_TIMEOUT_MS, QueryResult, satisfiable, solver_session
from rclverify.model.plan.formal import Formal, parse_formal
from rclverify.model.plan.model import Plan, Requirement
from rclverify.lang.types import Checked
from rclverify.model.system.model import SystemModel
from rclverify.model.plan.ranking import parse_hints
from rclverify.model.plan.state import state_types
from rclverify.model.plan.temporal import operands, parse_temporal

#: The first attempt's budget of the consistency and vacuity queries, which
#: look for a model (sat): Z3's default strategy rarely finds a model of a
#: quantified formula it did not find at once, while the retries of
#: :mod:`rclverify.semantics.retry` (finite instantiation, MBQI) often do; a short
#: first attempt hands over to them sooner (an unknown is never upgraded).
MODEL_TIMEOUT_MS = 1_000
#: The budget of the general query's first look at the consistency and
#: vacuity queries (decide first with what decides): an unsat
#: answer (a vacuous requirement, an inconsistent proof) comes at once;
#: what it does not decide goes to a finite-table witness (function-typed
#: inputs), then to the general query with :data:`MODEL_TIMEOUT_MS` and its
#: retries, as before.
FIRST_LOOK_MS = 50


def cone_of(formals: Sequence[Formal], model: SystemModel) -> list[str]:
    """The nodes the statements mention and every node upstream of them, in
    the model's (source) order."""
    want: set[str] = set()
    for f in formals:
        for n in f.nodes:
            want.update(model.upstream(n) or [n])
    return [n for n in model.nodes if n in want]


def formals_of(req: Requirement, checked: Checked) -> tuple[Formal | None, list[Formal]]:
    """The parsed formal statement (``None`` when informal) and ``assuming:`` formulas."""
    f = parse_formal(req.formal, checked, f"{req.id} formal") if req.formal else None
    return f, [parse_formal(a, checked, f"{req.id} assuming") for a in req.assuming]


def statement_formals(req: Requirement, checked: Checked, plan: Plan) -> list[Any]:
    """The state formulas a requirement's cone is computed from: its formal
    statement (every operand of a temporal one), its ``assuming:``, then
    its ``ranking:`` term and ``invariant:`` (:mod:`rclverify.model.plan.ranking`),
    each with ``nodes``; ``[]`` for an informal requirement."""
    if req.formal is None:
        return []
    stypes = state_types(plan.states, checked)
    t = parse_temporal(req.formal, checked, f"{req.id} formal", stypes)
    hints = [h for h in parse_hints(req.ranking, req.invariant, t, checked, req.id, stypes) if h is not None]
    return [*operands(t), *assuming_of(req, checked), *hints]


def assuming_of(req: Requirement, checked: Checked) -> list[Formal]:
    """The parsed ``assuming:`` formulas of ``req``."""
    return [parse_formal(a, checked, f"{req.id} assuming") for a in req.assuming]


def state_text(plan: Plan, cone: Sequence[str]) -> str:
    """The plan's state declarations of the nodes of ``cone`` as text (part
    of a temporal requirement's fingerprint)."""
    return json.dumps([[s.node, s.name, s.type_name, s.init.text, s.next.text, str(s.loc)]
                       for s in plan.states if s.node in cone])


def fingerprint(req: Requirement, cone_snapshots: Sequence[str], model_json: str, code: str = "") -> str:
    """A sha256 of everything a requirement's record is computed from: its
    statements (and where they are written) and traced guarantees, the contract snapshots of its cone
    (artifacts/contracts/<Node>.json, which include the node's plan facts) and
    the system model, and ``code`` (the rclverify code and Z3 version that
    decide it).  An unchanged fingerprint means the recorded verdict still
    holds (the ``requirements`` task re-checks only changed ones)."""
    h = hashlib.sha256(code.encode())
    h.update(json.dumps([req.id, req.text, [req.formal.text, req.formal.line, req.formal.col] if req.formal else None,
                         [[a.text, a.line, a.col] for a in req.assuming], str(req.loc),
                         [[x.text, x.line, x.col] if x else None for x in (req.ranking, req.invariant)],
                         [[s.node, list(s.guarantees)] for s in req.support], req.origin]).encode())
    for s in cone_snapshots:
        h.update(b"\0" + s.encode())
    h.update(b"\0" + model_json.encode())
    return h.hexdigest()


def _base(req: Requirement) -> RequirementBase:
    """The keys of a requirement's record that come from the plan alone."""
    return {
        "id": req.id, "text": req.text, "origin": req.origin,
        "source": where(req.formal.loc if req.formal else req.loc),
        "formal": " ".join(req.formal.text.split()) if req.formal else None,
        "assuming": [" ".join(a.text.split()) for a in req.assuming],
        "ranking": " ".join(req.ranking.text.split()) if req.ranking else None,
        "invariant": " ".join(req.invariant.text.split()) if req.invariant else None,
        "traced": [{"node": s.node, "guarantee": k} for s in req.support for k in s.guarantees],
    }


@solver_session()
def check_requirement(req: Requirement, checked: Checked, model: SystemModel, plan: Plan, *,
                      timeout_ms: int = DEFAULT_TIMEOUT_MS, model_ms: int = MODEL_TIMEOUT_MS) -> dict[str, Any]:
    """Decide ``req`` (module docstring).  Returns its JSON record:

    ``id``, ``text``, ``origin``, ``source`` (``file:line:col`` of the formal
    statement or of the requirement), ``formal``, ``assuming`` (RCL text),
    ``cone`` (node names), ``verdict`` (``proved``/``refuted``/
    ``inconclusive``/``informal``), ``used`` (premises in the unsat core:
    ``{label, kind, node, index, text, source}``), ``traced_not_needed``,
    ``consistency`` (``consistent``/``inconsistent``/``undecided``, proved
    only) with ``inconsistent_core``, ``vacuity`` (``non-vacuous``/
    ``vacuous``/``undecided``, proved implications only) with
    ``vacuity_core``, ``counterexample`` (``[{node, values:
    {var: value}}]``, refuted only), ``failed_to_prevent`` (premises), ``reason``
    (Z3's, inconclusive only), ``smt2`` (the query's text), ``duration_s``;
    ``consistency_smt2`` and ``vacuity_smt2``: the text of the consistency
    and vacuity queries when Z3 decided them (sat or unsat).

    ``timeout_ms`` is the validity query's budget, ``model_ms`` the first
    attempt's of the consistency and vacuity queries (:data:`MODEL_TIMEOUT_MS`).
    Raises :class:`~rclverify.lang.errors.RclError` for a statement that does
    not check (the plan's ``resolve`` reports those first); never raises on
    solver trouble.
    """
    base = _base(req)
    if req.formal is not None and plan is not None:
        from rclverify.calculus.requirements.temporal_check import check_temporal, is_temporal  # deferred: optional or conditional (inside a block)
        if is_temporal(req, checked, plan):  # over the composed system's runs (calculus/requirements/temporal_check.py)
            return check_temporal(req, checked, model, plan, base)
    formal, assuming = formals_of(req, checked)
    if formal is None:
        return {**base, "verdict": "informal", "cone": [], "used": [], "traced_not_needed": [],
                "explanation": "No formal statement: the requirement is traced to guarantees, never checked, never met."}
    cone = cone_of([formal, *assuming], model)
    q, symbols, goal, r = ask(base, cone, formal, assuming, checked, model, plan, timeout_ms)  # goal held: ask
    enc = q.enc
    out: dict[str, Any] = {**base, "cone": cone, "premises": len(q.premises), "smt2": r.smt2,
                           "duration_s": r.duration_s}
    traced = [f"{t['node']} guarantee {t['guarantee']}" for t in base["traced"]]
    if r.status == "unsat":
        _proved(out, r, q, traced, req.id, model_ms, _points(plan, cone))
        premise = _premise(formal.expr)
        if out["consistency"] == "consistent" and premise is not None:
            _vacuity(out, q, enc.formula(premise, formal.scope, symbols), req.id, model_ms, _points(plan, cone))
        return out
    out.update(used=[], traced_not_needed=[])
    if r.status == "sat":
        undefined = first_undefined(q, formal, assuming, symbols, req.id, timeout_ms)
        refuting = q.labelled
        if undefined is not None:  # not defined where the premises allow: that condition and its model
            cond, refuting, r = undefined
            out["explanation"] = (f"The statement is not defined where the premises allow it: {cond.describe()}, "
                                  "which the premises do not ensure (the counterexample divides by zero); a "
                                  "statement is proved only where it is defined (docs/semantics.md, "
                                  "\"Definedness\").")
        mentioned = {enc.symbol_name(n, p, v) for f in (formal,) for n, p, v in f.mentions}
        hit = [lbl for lbl, syms in q.g_symbols.items() if syms & mentioned]
        first = [l for l in hit if l in traced] or hit
        from rclverify.calculus.requirements.readable import readable_counterexample  # within the assumptions, short values; deferred: optional or conditional (inside a block); deferred: optional or conditional (inside a block)
        shown, note = readable_counterexample(refuting, r.model or {}, cone, checked, model, enc)
        out.update(verdict="refuted", counterexample=_counterexample(shown, cone, checked, enc),
                   failed_to_prevent=[q.by_label[l] for l in first], **note)
        return out
    out.update(verdict="inconclusive", reason=r.reason or "unknown")
    return out


def _proved(out: dict[str, Any], r: QueryResult, q: Query, traced: list[str], rid: str, model_ms: int,
            points: int) -> None:
    """A proved requirement's record: the premises its proof used (the unsat
    core), the traced guarantees it did not need, and whether the used
    premises are consistent (Z3 looks for a model of them)."""
    by_label = q.by_label
    core = [c for c in (r.core or []) if c != NEGATED]
    used = [by_label[c] for c in core]
    out.update(verdict="proved", used=used,
               traced_not_needed=[by_label.get(t, {"label": t, "kind": "guarantee"}) for t in traced if t not in core])
    if NEGATED not in (r.core or []):
        out.update(consistency="inconsistent", inconsistent_core=used, consistency_duration_s=0.0)
        return
    r2 = _model_query([(lbl, f) for lbl, f in q.labelled if lbl in core], q.enc, model_ms, points,
                      f"rclverify requirement {rid}: are the premises its proof used consistent?")
    out["consistency_duration_s"] = r2.duration_s
    if r2.status in ("sat", "unsat"):  # decided: a second solver re-decides it (docs/second-solver.md)
        out["consistency_smt2"] = r2.smt2
    if r2.status == "unsat":
        out.update(consistency="inconsistent", inconsistent_core=[by_label[c] for c in (r2.core or [])])
    elif r2.status == "sat":
        out.update(consistency="consistent")
    else:
        out.update(consistency="undecided", consistency_reason=r2.reason)


def _vacuity(out: dict[str, Any], q: Query, premise: z3.BoolRef, rid: str, model_ms: int, points: int) -> None:
    """A proved implication's vacuity: can its premise hold with every premise of the cone?"""
    r3 = _model_query([(lbl, f) for lbl, f in q.labelled if lbl != NEGATED] + [("requirement premise", premise)],
                      q.enc, model_ms, points,
                      f"rclverify requirement {rid}: can its premise hold with every premise of the cone?")
    out["vacuity_duration_s"] = r3.duration_s
    if r3.status in ("sat", "unsat"):
        out["vacuity_smt2"] = r3.smt2
    if r3.status == "unsat":
        out.update(vacuity="vacuous", vacuity_core=[q.by_label[c] for c in (r3.core or []) if c in q.by_label])
    else:
        out["vacuity"] = {"sat": "non-vacuous", "inconclusive": "undecided"}.get(r3.status, "undecided")


def _points(plan: Plan, cone: Sequence[str]) -> int:
    """The size of the witness tables for a query over ``cone``: every
    instance of every node of the cone gets a point of its own
    (:func:`rclverify.calculus.health.witness.points_for`; the plan's instance ranges
    are part of the cone's snapshots, hence of the record's fingerprint)."""
    return max([points_for(plan.instances.get(n)) for n in cone] or [points_for(None)])


def _model_query(labelled: list[tuple[str, z3.BoolRef]], enc: Encoder, model_ms: int, points: int,
                 comment: str) -> QueryResult:
    """Can ``labelled`` hold together?  The consistency and vacuity queries,
    which look for a model: first the general query with
    :data:`FIRST_LOOK_MS` (what it decides, its whole budget decides the
    same way: a resource-bounded search with a smaller bound is a prefix of
    the same search), then, with function-typed inputs, a witness in which
    each is a finite table of ``points`` points
    (:func:`rclverify.calculus.health.witness.finite_witness`: its model is a model
    of the query; the case study's REQ2 and REQ3: 0.1-0.3 s where the
    general query ran out of its budget before a retry found a model), then
    the general query with ``model_ms`` and the retries of
    :mod:`rclverify.semantics.retry`.  Returns the :class:`QueryResult` of
    whichever decided (``sat`` with a model, ``unsat`` with a core), else
    the last one's ``inconclusive``."""
    t0 = time.perf_counter()
    r = satisfiable(labelled, enc, timeout_ms=min(model_ms, FIRST_LOOK_MS), comment=comment, retry=False)
    if r.status != "inconclusive":
        return r
    if has_tables(enc):
        w = finite_witness(enc, [f for _, f in labelled], points)
        if w.status == "sat":
            return QueryResult("sat", r.script, round(time.perf_counter() - t0, 4), model=w.model)
    r = satisfiable(labelled, enc, timeout_ms=model_ms, comment=comment)
    return replace(r, duration_s=round(time.perf_counter() - t0, 4))


def _counterexample(model: dict[str, str], cone: Sequence[str], checked: Checked, enc: Encoder) -> list[TraceNode]:
    """The model's values of every I/O variable of the cone, node by node in
    the cone's order: ``[{"node": N, "values": {"in.x": value, "out.y": value}}]``
    (a consumer's input shows the value of the producer's output it reads)."""
    shown = {s.z3name: s.display for s in enc.symbols.values()}
    out: list[TraceNode] = []
    for n in cone:
        cn = checked.nodes[n]
        row: dict[str, str] = {}
        for p, table in (("in", cn.inputs), ("out", cn.outputs)):
            for v in table:
                z = enc.symbol_name(n, p, v)
                if z in shown and shown[z] in model:
                    row[f"{p}.{v}"] = model[shown[z]]
        if row:
            out.append({"node": n, "values": row})
    return out
