"""A requirement decided over the premises of its own nodes first.

:func:`.check.check_requirement` decides a state statement over its whole
upstream cone: the guarantees, environment assumptions and facts of every
node upstream of the nodes it mentions, encoded in a Z3 context of its own.
Summed over a system's requirements that is quadratic in its size (the
5000-node system of ``bench/system_scale.py``: 49 deadline requirements
over cones of 2,500 nodes on average, about two minutes of one core;
docs/scale.md).  The requirements stage asks :func:`decide` instead:

1. **The whole system's premises, once** (:func:`system_premises`): one
   satisfiability query over the premises of every node, in a fresh Z3
   context, memoised per loaded system.  Satisfiable means every cone's
   premises are (a cone's premises are some of them).
2. **The statement's own nodes** (:func:`own_nodes`): a statement that is
   not an implication and has no ``assuming:``, whose cone holds more than
   the nodes it mentions, is decided over those nodes' premises alone.
   Kept only when the answer is unsat with the negated statement in the
   core and the used premises are consistent, and only when step 1 said
   ``consistent``.
3. Otherwise, in a fresh Z3 context, :func:`.check.check_requirement` over
   the whole cone, as before: its record is the one it writes alone.

Why a kept record says what the whole cone's would (docs/decisions.md,
"Requirements from their own nodes first"): the whole cone's query asserts
every premise the own nodes' query asserts, and more, so an unsat core of
the smaller query is one of the larger (``proved``; adding premises never
makes an unsat query sat).  The cone's premises being consistent (step 1),
every unsat core of the cone's query holds the negated statement and every
set of its premises is consistent, so the cone's query would say
``proved``, ``consistent`` too.  The implication's vacuity query is asked
of the whole cone, and an ``assuming:`` formula is not among the system's
premises of step 1: those stay with the cone.  What can differ is which
premises the record lists as used (Z3's core is one of several; both are
proofs), its query's script and premise count (``premises_of`` names the
nodes it read).  A statement refuted or left undecided by its own nodes is
the cone's to decide: a counterexample must be the whole cone's.

Which path decides depends on step 1, which reads every node: its answer is
part of the requirement's fingerprint (:func:`fingerprint_inputs`), so an
incremental run re-checks exactly when a clean one would decide otherwise.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import z3

from rclverify.calculus.requirements.check import (MODEL_TIMEOUT_MS, _base, _points, _proved, check_requirement,
                                                   cone_of, formals_of)
from rclverify.calculus.requirements.premises import NEGATED, Query, ask
from rclverify.calculus.requirements.exercised import antecedent as _premise
from rclverify.lang.types import Checked
from rclverify.model.plan.formal import Formal
from rclverify.model.plan.model import Plan, Requirement
from rclverify.core.cache.memo import last_call
from rclverify.model.system.model import SystemModel
from rclverify.semantics.encode import Encoder
from rclverify.semantics import wallclock
from rclverify.semantics.query import DEFAULT_TIMEOUT_MS, solver_session
from rclverify.semantics.world import fresh as fresh_z3


@dataclass(frozen=True)
class Own:
    """A statement to decide over its own nodes first: the parsed ``formal``,
    ``nodes`` the nodes it mentions, ``cone`` their upstream cone (which
    holds more nodes), both in the model's order."""

    formal: Formal
    nodes: list[str]
    cone: list[str]


@last_call
def _own_answers(checked: Checked, model: SystemModel, plan: Plan) -> dict[int, tuple[Requirement, Own | None]]:
    """:func:`own_nodes`'s answers for one loaded system, by ``id`` of the requirement (kept with it)."""
    return {}


def own_nodes(req: Requirement, checked: Checked, model: SystemModel, plan: Plan) -> Own | None:
    """What step 2 reads (module docstring), or ``None`` when it does not
    apply: an informal or temporal statement, an implication (whether its
    premise can hold is asked of the whole cone: the vacuity query), an
    ``assuming:``, a cone of the statement's own nodes alone (then the two
    queries are one).  Kept per requirement and loaded system (parsing a
    statement reads every node's names: the stage asks twice, for the
    fingerprint and for the check).  Raises ``RclError`` like
    :func:`.check.formals_of`."""
    answers = _own_answers(checked, model, plan)
    kept = answers.get(id(req))
    if kept is not None and kept[0] is req:
        return kept[1]
    answer = _own_nodes(req, checked, model, plan)
    answers[id(req)] = (req, answer)
    return answer


def _own_nodes(req: Requirement, checked: Checked, model: SystemModel, plan: Plan) -> Own | None:
    if req.formal is None or req.assuming:
        return None
    from rclverify.calculus.requirements.temporal_check import is_temporal  # deferred: optional or conditional (inside a block)
    if is_temporal(req, checked, plan):
        return None
    formal, _ = formals_of(req, checked)
    if formal is None or _premise(formal.expr) is not None:
        return None
    cone = cone_of([formal], model)
    own = [n for n in cone if n in set(formal.nodes)]
    return Own(formal, own, cone) if len(own) < len(cone) else None


def _decide_system(checked: Checked, model: SystemModel, plan: Plan, timeout_ms: int) -> str:
    """Z3's answer for the premises of every node (no script kept: the answer only picks a path).  Asked
    of Z3's incremental SMT core, as a solver session's queries are (semantics/query.py): at 1000 nodes it
    finds the model in 15 ms where the default solver's preprocessing took 0.8 s and ran out of budget."""
    q = Query(Encoder(checked.env, model.alias()))
    q.cone_premises(list(model.nodes), checked, model, plan)
    s = wallclock.limit(z3.SimpleSolver(), timeout_ms)
    s.add(*q.enc.axioms(), *(f for _, f in q.labelled))
    r = wallclock.check(s)
    return "consistent" if r == z3.sat else "inconsistent" if r == z3.unsat else "undecided"


def system_premises(checked: Checked, model: SystemModel, plan: Plan, timeout_ms: int = DEFAULT_TIMEOUT_MS) -> str:
    """``consistent``, ``inconsistent`` or ``undecided``: Z3's answer whether
    the premises of every node of the system hold together (step 1 of the
    module docstring), decided once per ``(checked, model, plan)`` in a
    fresh Z3 context; a fresh context is started after it too, so the
    caller must hold no Z3 object across the call."""
    return _system_answer(checked, model, plan, timeout_ms)


@last_call  # once per loaded system (the model and plan compared by equality: the same objects are equal at once)
def _system_answer(checked: Checked, model: SystemModel, plan: Plan, timeout_ms: int) -> str:
    fresh_z3()
    answer = _decide_system(checked, model, plan, timeout_ms)
    fresh_z3()
    return answer


def fingerprint_inputs(req: Requirement, checked: Checked, model: SystemModel, plan: Plan) -> list[str]:
    """What :func:`decide`'s choice of path reads beyond the requirement's
    cone: ``["premises of every node: <answer>"]`` for a statement step 2
    applies to, else ``[]`` (part of :func:`.check.fingerprint`'s texts)."""
    if own_nodes(req, checked, model, plan) is None:
        return []
    return [f"premises of every node: {system_premises(checked, model, plan)}"]


def decide(req: Requirement, checked: Checked, model: SystemModel, plan: Plan, *,
           timeout_ms: int = DEFAULT_TIMEOUT_MS, model_ms: int = MODEL_TIMEOUT_MS) -> dict[str, Any]:
    """The record of ``req``: :func:`.check.check_requirement`'s (arguments
    and keys as there), from the statement's own nodes when they prove it
    (module docstring; then ``premises_of`` lists them and ``smt2`` is their
    query).  The caller starts a fresh Z3 context before the call (as the
    requirements stage does before each check) and holds no Z3 object
    across it.  Raises ``RclError`` for a statement that does not check."""
    own = own_nodes(req, checked, model, plan)
    if own is not None and system_premises(checked, model, plan, timeout_ms) == "consistent":
        rec = _decide_own(req, checked, model, plan, own, timeout_ms, model_ms)
        if rec is not None:
            return rec
        fresh_z3()  # the whole cone's query in the Z3 state it has without the attempt
    return check_requirement(req, checked, model, plan, timeout_ms=timeout_ms, model_ms=model_ms)


@solver_session()
def _decide_own(req: Requirement, checked: Checked, model: SystemModel, plan: Plan, own: Own, timeout_ms: int,
                model_ms: int) -> dict[str, Any] | None:
    """The record of ``req`` proved from the premises of its own nodes with
    the used premises consistent, or ``None`` (module docstring)."""
    base = _base(req)
    note = (f"\npremises: those of {', '.join(own.nodes)} alone, part of its cone (a proof from part of the "
            "premises is a proof from all of them)")
    q, _, goal, r = ask(base, own.nodes, own.formal, [], checked, model, plan, timeout_ms, note)  # goal held: ask
    if r.status != "unsat" or NEGATED not in (r.core or []):
        return None
    out: dict[str, Any] = {**base, "cone": own.cone, "premises_of": own.nodes, "premises": len(q.premises),
                           "smt2": r.smt2, "duration_s": r.duration_s}
    traced = [f"{t['node']} guarantee {t['guarantee']}" for t in base["traced"]]
    _proved(out, r, q, traced, req.id, model_ms, _points(plan, own.cone))
    return out if out.get("consistency") == "consistent" else None
