"""The workspace's contracts (or a backend's program) with one edit made,
checked again by the pipeline's own Z3 checks.

Nothing here writes to the workspace: an edited contract file is parsed
from text under its own name, an edited program is written to a temporary
directory that stands in for the workspace root.  Every answer comes from
the real checks (:func:`rclverify.calculus.health.checks.check_node`,
:func:`rclverify.calculus.compose.compose_node`, the Hoare backend's
:func:`~rclverify.backends.hoare.solve.check_all`).
"""
from __future__ import annotations

import shutil
import tempfile
from dataclasses import replace
from pathlib import Path
from typing import Any, Mapping

import z3

from rclverify.calculus.health.witness import finite_witness as table_witness, points_for
from rclverify.semantics import world
from rclverify.semantics.subterms import subterms
from rclverify.lang.errors import RclError
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check
from rclverify.lang.types import Checked
from rclverify.model.system.model import SystemModel, build
from rclverify.diagnosis.edits import Edit
from rclverify.diagnosis.splice import FULL, spliced_system


def source_text(ws: Any, rel: str) -> str:
    """The text of the workspace file ``rel``."""
    return str(ws.path(rel).read_text(encoding="utf-8"))


def edited_system(ws: Any, edit: Edit) -> tuple[Checked, SystemModel] | None:
    """The type-checked system and its model with ``edit`` made to one
    contract file; ``None`` when the edited text does not parse or check.
    An edit inside one node's clauses re-reads that node only
    (:func:`.splice.spliced_system`: the cost of a candidate does not grow
    with the system); any other edit parses and checks every file again."""
    if edit.file in ws.plan.contracts:
        try:
            quick = spliced_system(ws, edit, source_text(ws, edit.file))
        except (KeyError, ValueError):
            quick = FULL  # the full path below says what is wrong
        if quick is not FULL:
            return quick  # type: ignore[return-value]
    specs = []
    try:
        for rel in ws.plan.contracts:
            text = source_text(ws, rel)
            if rel == edit.file:
                text = edit.apply(text)
            specs.append(parse_text(text, rel))
        checked = check(specs)
        return checked, build(checked, ws.plan.connections)
    except (RclError, KeyError, ValueError):
        return None


def health(ws: Any, checked: Checked, node: str, instances: Mapping[int, int] | None = None, *,
           known: Mapping[str, str] | None = None) -> dict[str, str]:
    """``{finding id: status}`` of the health checks of ``node`` in
    ``checked``, each asked as the health stage asks it but with a short
    budget and no instance scan (the full stage takes a minute on the case
    study's Agent): a check Z3 cannot decide in its budget is decided by a
    witness of the shape :func:`finite_witness` looks for (``ok``), else
    ``inconclusive``; an ``unsat`` answer is a ``problem``.  The
    non-vacuity of guarantee ``k`` is asked at ``instances[k]`` when given
    (where it was vacuous before).  The shape findings
    (:mod:`rclverify.calculus.health.shape`) are the stage's own.  The replacement
    check is not asked again.  ``known``: statuses of checks the caller has
    just asked Z3 on the same ``checked`` (``{"Agent.g1.non-vacuous":
    "ok"}``), taken as they are instead of being asked twice."""
    from rclverify.calculus.health.vacuity import INSTANCE_TIMEOUT_MS  # deferred: start-up (loads rclverify.calculus.compose, rclverify.calculus.context and more only when called)
    from rclverify.calculus.health.shape import shape_findings  # deferred: start-up (loads rclverify.calculus.compose, rclverify.calculus.context and more only when called)
    as_status = {"sat": "ok", "unsat": "problem"}
    known = known or {}
    h = _health(ws, checked, node)
    out: dict[str, str] = {}
    r = h.sat([], guarantees=False, comment=f"repair check {node}: assumption", timeout_ms=INSTANCE_TIMEOUT_MS)
    out[f"{node}.assumption-satisfiable"] = as_status.get(r.status, "inconclusive")
    # the guarantees with a premise, asked before the next queries start a fresh Z3 world
    premised = [k for k in range(1, len(checked.nodes[node].node.guarantees) + 1) if h.premise(k) is not None]
    cid = f"{node}.contract-consistent"
    out[cid] = known[cid] if cid in known else as_status.get(consistent(ws, checked, node), "inconclusive")
    for k in premised:
        gid = f"{node}.g{k}.non-vacuous"
        out[gid] = known[gid] if gid in known else as_status.get(
            premise_fires(ws, checked, node, k, (instances or {}).get(k)), "inconclusive")
    world.fresh()
    out.update({f.id: f.status for f in shape_findings(checked, node)})
    return out


def _health(ws: Any, checked: Checked, node: str) -> Any:
    from rclverify.calculus.health.node_health import NodeHealth  # deferred: start-up (loads rclverify.calculus.compose, rclverify.calculus.context and more only when called)
    from rclverify.calculus.health.vacuity import INSTANCE_TIMEOUT_MS  # deferred: start-up (loads rclverify.calculus.compose, rclverify.calculus.context and more only when called)
    world.fresh()
    facts = [(f.expr, f.loc) for f in ws.plan.facts.get(node, ())]
    return NodeHealth(checked, checked.nodes[node], facts, None, INSTANCE_TIMEOUT_MS)


def finite_witness(h: Any, extra: list[tuple[str, z3.BoolRef]], points: int) -> str:
    """``"sat"`` when Z3 finds a witness of ``h``'s assumption, guarantees,
    facts and ``extra`` in which every function-typed input is a finite
    table of ``points`` points (:func:`rclverify.calculus.health.witness.finite_witness`),
    or, failing that, of :func:`numeral_points` points when that is more;
    else ``"inconclusive"`` (no witness of those shapes, which is not a proof
    that there is none).  Asked of Z3's ``simplify`` and ``qe-light``
    tactics first (``simplified``: the case study's Agent, 0.1 s a witness
    instead of 0.3-0.7 s), then as the health stage asks it."""
    formulas = [f for _, f in h.labelled(extra)]
    if table_witness(h.enc, formulas, points, simplified=True).status == "sat":
        return "sat"
    wide = numeral_points(formulas)
    return table_witness(h.enc, formulas, wide, simplified=True).status if wide > points else "inconclusive"


#: The most points :func:`numeral_points` gives a table.
MAX_NUMERAL_POINTS = 32


def numeral_points(formulas: list[z3.BoolRef]) -> int:
    """One more than the largest whole number written in ``formulas`` (at most
    :data:`MAX_NUMERAL_POINTS`): a table of that many points can take each value
    from 0 up to it at a point of its own.  Without the plan's ``instances`` a
    table has :data:`~rclverify.calculus.health.witness.WITNESS_POINTS`; a contract
    that asks for a function to reach every number up to 12 (the cut-down rover's
    guard ``i + 1 <= 12`` with "each waypoint has a next one") has a witness only
    with 13, which the general query does not find within its budget."""
    top = 0
    for e in subterms(formulas):
        if z3.is_int_value(e):
            top = max(top, abs(e.as_long()))
        elif z3.is_rational_value(e) and e.denominator_as_long() == 1:
            top = max(top, abs(e.numerator_as_long()))
    return min(top + 1, MAX_NUMERAL_POINTS)


def _points(ws: Any, node: str) -> int:
    return points_for(ws.plan.instances.get(node))


def premise_fires(ws: Any, checked: Checked, node: str, k: int, at: int | None = None) -> str:
    """Can the premise of guarantee ``k`` of ``node`` (at ``at`` for its
    first NATURAL variable, when given) hold together with the assumption,
    every guarantee and the facts?  ``sat`` when Z3 found a witness: of the
    shape :func:`finite_witness` looks for (asked first), or for the query
    of the health check ``non-vacuous``; else that query's ``unsat`` or
    ``inconclusive``."""
    from rclverify.calculus.health.vacuity import INSTANCE_TIMEOUT_MS  # deferred: start-up (loads rclverify.calculus.compose, rclverify.calculus.context and more only when called)
    h = _health(ws, checked, node)
    var = h.natural_vars(k)
    prem = h.premise(k, {var[0]: at} if at is not None and var else None)
    if prem is None:
        return "inconclusive"
    # the finite-table witness first: its sat is a witness of the general query too, and it is
    # found in a fraction of the time in which the general query runs out of budget (the Agent)
    if finite_witness(h, prem[0], _points(ws, node)) == "sat":
        return "sat"
    r = h.sat(prem[0], comment=f"repair check {node}: can the premise of guarantee {k} hold?",
              timeout_ms=INSTANCE_TIMEOUT_MS)
    return str(r.status)


def consistent(ws: Any, checked: Checked, node: str) -> str:
    """Can the assumption, every guarantee and the facts of ``node`` hold
    together?  ``sat`` (a witness: the general query or :func:`finite_witness`),
    ``unsat`` or ``inconclusive``."""
    from rclverify.calculus.health.vacuity import INSTANCE_TIMEOUT_MS  # deferred: start-up (loads rclverify.calculus.compose, rclverify.calculus.context and more only when called)
    h = _health(ws, checked, node)
    if finite_witness(h, [], _points(ws, node)) == "sat":  # first, as in premise_fires
        return "sat"
    r = h.sat([], comment=f"repair check {node}: is the contract consistent?", timeout_ms=INSTANCE_TIMEOUT_MS)
    return str(r.status)


def side_conditions(checked: Checked, model: SystemModel, node: str, ws: Any = None) -> dict[str, str]:
    """``{side condition id: status}`` of ``node`` in the edited system (a fresh Z3 world), with the
    plan's environment facts of ``ws`` (the workspace) as the stage has them: a side condition that
    fails locally is checked in context with them (docs/calculus.md)."""
    from rclverify.calculus.compose import compose_node  # deferred: start-up (loads rclverify.calculus.compose, rclverify.calculus.context and more only when called)
    world.fresh()
    facts = {n: [f.expr for f in fs] for n, fs in ws.plan.facts.items()} if ws is not None else None
    return {sc.id: sc.status for sc in compose_node(checked, model, node, facts=facts).side_conditions}


def hoare_statuses(ws: Any, node: str, index: int, program: str, new_text: str) -> dict[str, str]:
    """``{obligation id: status}`` of every Hoare triple of the plan entry
    ``index`` of ``node`` with its program replaced by ``new_text`` (written to
    a temporary copy of the program's path; the workspace is not touched).
    A pending triple is ``pending``; a triple Z3 cannot decide ``inconclusive``."""
    from rclverify.backends.hoare.backend import prepare  # deferred: start-up (loads jinja2, z3 and more only when called)
    from rclverify.backends.hoare.solve import check_all  # deferred: start-up (loads jinja2, z3 and more only when called)
    world.fresh()
    tmp = Path(tempfile.mkdtemp(prefix="rclverify-repair-"))
    try:
        dest = tmp / program
        dest.parent.mkdir(parents=True, exist_ok=True)
        dest.write_text(new_text, encoding="utf-8")
        target = replace(ws.target(node, index), root=tmp, artifacts=tmp / "artifacts")
        out: dict[str, str] = {}
        for p in prepare(target):
            if p.pending or p.triple is None:
                out[p.id] = "pending"
                continue
            res = check_all(p.vcs, p.triple.background, p.model, p.config.timeout_ms, p.triple.observe,
                            p.triple.observe_final, p.triple.names, triple=(p.triple.pre, p.triple.post))
            out[p.id] = res.status if res.status in ("discharged", "failed") else "inconclusive"
        return out
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def triple_checks(after: Mapping[str, str]) -> tuple[list[dict[str, str]], str]:
    """A Hoare program's triples judged again (:func:`hoare_statuses`): each as a repair's check (a
    discharged one marked "Z3: proved"), and the words saying how many there are and how many stay
    pending (``"3 in all, 1 still pending for what the program does not model"``)."""
    checks = [{"check": k, "status": v + (" (Z3: proved)" if v == "discharged" else "")} for k, v in sorted(after.items())]
    pending = sum(1 for s in after.values() if s == "pending")
    return checks, f"{len(after)} in all, {pending} still pending for what the program does not model"


def changes(before: Mapping[str, str], after: Mapping[str, str]) -> list[dict[str, str]]:
    """What changes status: ``[{"check", "before", "after"}]`` for every key
    of either mapping whose status differs (a check that disappears is
    ``absent``)."""
    out = []
    for k in sorted(set(before) | set(after)):
        a, b = before.get(k, "absent"), after.get(k, "absent")
        if a != b:
            out.append({"check": k, "before": a, "after": b})
    return out
