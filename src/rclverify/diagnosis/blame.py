"""Culprits Z3 has shown: a guarantee is named as the cause of a problem
only when strengthening that guarantee alone removes the counterexample.

A side condition ``G_p => c`` fails with a counterexample; a requirement is
refuted with one.  Naming every guarantee that mentions the variables
involved blames bystanders: a guarantee whose premise never fires (the
vacuous ``in.voltage > 30 -> out.battery == 0``) or a node that only passes
a value on (``out.altitude <= in.target_altitude``) while the gap is another
node's bound.  Here each candidate is strengthened on its own, the edited
contracts are checked again by the pipeline's own checks, and the candidate
is a culprit only when the problem is gone (docs/diagnosis.md, "Who is
named"):

* side condition: the candidate's *conclusion* gets the consumer's conjunct
  (in the producer's output names): ``P -> Q`` becomes ``P -> (Q) and (c)``,
  an unconditional ``Q`` becomes ``(Q) and (c)``; a culprit when Z3 then
  discharges the side condition (:func:`side_condition_culprits`);
* refuted requirement: a numeric bound of a guarantee of the cone (a
  literal compared with something, :func:`.bounds.bound_literals`: never a
  coefficient, a scale factor or a unit, such as ``1000`` in ``out.d ==
  1000 * in.r``) is replaced by a constant of the requirement's statement
  (the bound that lets the counterexample through); a culprit when Z3 then
  proves the requirement from consistent premises, non-vacuously, and the
  edited node stays implementable (:func:`.realize.implementable`: not
  refuted).  When no bound does it, a guarantee of a node the statement
  mentions gets the statement (in that node's names) added to its
  conclusion, as above, with the same checks
  (:func:`requirement_culprits`).

Every check is made on an edited copy of the contract text
(:func:`rclverify.diagnosis.recheck.edited_system`); nothing is written.
"""
from __future__ import annotations

import re
from collections.abc import Sequence
from typing import Any

from rclverify.semantics import world
from rclverify.lang import ast
from rclverify.lang.printer import expr_to_rcl
from rclverify.diagnosis import realize, recheck
from rclverify.diagnosis.bounds import FLIP, bound_literals, thresholds, value
from rclverify.diagnosis.edits import Edit
from rclverify.records.links import link_pairs
from rclverify.diagnosis.shapes import ReportRows, Strengthening
from rclverify.records.side_condition_rows import SideConditionRow
from rclverify.diagnosis.repairs import _numbers, _peel, _rename
from rclverify.model.plan.load import all_requirements
from rclverify.calculus.requirements.check import check_requirement, formals_of
from rclverify.lang.walk import subexpressions

#: Most edited systems checked per problem (each costs a parse, a type check and a Z3 query).
MAX_TRIALS = 24
#: Most edited systems checked per refuted temporal requirement (each costs a temporal check:
#: bounded model checking and an induction, several Z3 queries).
TEMPORAL_TRIALS = 12


def _span(e: Any) -> tuple[int, int, int, int] | None:
    loc = getattr(e, "loc", None)
    if loc is None or not loc.line:
        return None
    if loc.end_line:
        return loc.line, loc.col, loc.end_line, loc.end_col
    if isinstance(e, ast.NumLit):
        return loc.line, loc.col, loc.line, loc.col + len(e.text)
    return None


def conclusion_edit(ws: Any, node: str, k: int, extra: str) -> Edit | None:
    """The edit adding ``extra`` (RCL text in ``node``'s names) to the
    conclusion of guarantee ``k`` of ``node`` (the right side of its
    top-level ``->`` under its ``forall``s, else the whole body); ``None``
    when the clause has no exact location."""
    g = ws.checked.nodes[node].node.guarantees[k - 1]
    _, body = _peel(g.formula)
    target = body.right if isinstance(body, ast.Binary) and body.op == "->" else body
    span = _span(target)
    if span is None:
        return None
    probe = Edit(g.loc.file, *span, "")
    old = probe.deleted(recheck.source_text(ws, g.loc.file))
    return Edit(g.loc.file, *span, f"({old}) and ({extra})")


def side_condition_culprits(ws: Any, sc: SideConditionRow) -> tuple[list[tuple[str, int]], int]:
    """``([(producer, guarantee index)], undecided)`` of the failed side
    condition ``sc`` (the report's record, its ``id``, ``node``, ``conjunct`` and
    ``links``): the producer guarantees on the linked outputs whose
    conclusion, strengthened by the conjunct, makes Z3 discharge ``sc``
    (module docstring), and how many candidates could not be decided (Z3
    answered unknown, or the strengthened text does not type-check)."""
    pairs = link_pairs(sc)
    to_producer = [(f"in.{iv}", f"out.{ov}") for _, ov, _, iv in pairs]
    extra = _rename(sc.conjunct, to_producer)
    out: list[tuple[str, int]] = []
    trials = undecided = 0
    for p in sorted({p for p, _, _, _ in pairs}):
        outs = [ov for q, ov, _, _ in pairs if q == p]
        for k, g in enumerate(ws.checked.nodes[p].node.guarantees, 1):
            text = expr_to_rcl(g.formula)
            if not any(re.search(rf"(?<![\w.])out\.{re.escape(ov)}(?!\w)", text) for ov in outs):
                continue
            if trials >= MAX_TRIALS:
                return out, undecided + 1
            trials += 1
            edit = conclusion_edit(ws, p, k, extra)
            system = recheck.edited_system(ws, edit) if edit is not None else None
            if system is None:  # the conjunct does not read in the producer's names: nothing shown either way
                undecided += 1
                continue
            status = recheck.side_conditions(*system, sc.node, ws).get(sc.id)
            if status == "discharged":
                out.append((p, k))
            elif status != "failed":
                undecided += 1
    return out, undecided


def fixed_side_condition(ws: Any, sc: SideConditionRow, producer: str, k: int) -> Edit | None:
    """The edit that discharges the failed side condition ``sc`` through
    guarantee ``k`` of ``producer`` (one of :func:`side_condition_culprits`):
    its conclusion strengthened by the consumer's conjunct in the producer's
    names; ``None`` without an exact location."""
    to_producer = [(f"in.{iv}", f"out.{ov}") for _, ov, _, iv in link_pairs(sc)]
    return conclusion_edit(ws, producer, k, _rename(sc.conjunct, to_producer))


def proved_with(ws: Any, req_id: str, edit: Edit) -> bool:
    """Does Z3 prove the requirement ``req_id`` from consistent premises,
    non-vacuously, once ``edit`` is made (the pipeline's own requirement
    check on an edited copy; nothing is written)?  ``False`` when the edited
    text does not check or the requirement is not in the plan."""
    req = next((r for r in all_requirements(ws.plan) if r.id == req_id), None)
    system = recheck.edited_system(ws, edit)
    return req is not None and system is not None and _proved(req, system, ws.plan)


def _proved(req: Any, system: Any, plan: Any) -> bool:
    world.fresh()
    rec = check_requirement(req, system[0], system[1], plan, timeout_ms=5000, model_ms=2000)
    return rec.get("verdict") == "proved" and rec.get("consistency") == "consistent" \
        and rec.get("vacuity") != "vacuous"


def _implementable(ws: Any, system: Any, node: str) -> str:
    """``proved`` / ``inconclusive`` when the edited ``node`` is not shown
    unimplementable, ``""`` when it is (a strengthening that answers only
    some of the inputs its assumption allows is no repair)."""
    status = realize.implementable(ws, system[0], node)[0]
    return "" if status == "refuted" else status


def threshold_edit(ws: Any, cmp: ast.Compare) -> tuple[Edit, str, str] | None:
    """``(edit, old, new)``: the edit giving the comparison ``cmp`` (of
    :func:`.bounds.thresholds`) the other strictness (``<`` -> ``<=``),
    and the comparison's text before and after; ``None`` without exact
    locations.  Only the operator is replaced, whatever spacing surrounds it."""
    a, b, whole = _span(cmp.operands[0]), _span(cmp.operands[1]), _span(cmp)
    if a is None or b is None or whole is None:
        return None
    source = recheck.source_text(ws, cmp.loc.file)
    between = Edit(cmp.loc.file, a[2], a[3], b[0], b[1], "").deleted(source)
    op = cmp.ops[0]
    at = between.find(op)
    if at < 0 or between[:at].strip() or between[at + len(op):].strip():
        return None
    line, col = a[2], a[3]  # the operator's position (columns count characters)
    for ch in between[:at]:
        line, col = (line + 1, 1) if ch == "\n" else (line, col + 1)
    edit = Edit(cmp.loc.file, line, col, line, col + len(op), FLIP[op])
    f = cmp.loc.file
    left, rest = Edit(f, whole[0], whole[1], a[2], a[3], "").deleted(source), Edit(f, b[0], b[1], whole[2], whole[3], "")
    new = left + between[:at] + FLIP[op] + between[at + len(op):] + rest.deleted(source)
    return edit, Edit(f, *whole, "").deleted(source), new


def requirement_culprits(ws: Any, req_id: str, cone: Sequence[str]) -> list[Strengthening]:
    """The guarantees of ``cone`` (node names) to blame for the refuted
    requirement ``req_id`` (module docstring), each a
    :class:`~rclverify.diagnosis.shapes.Strengthening` (``how`` ``bound`` |
    ``threshold`` | ``conclusion``) with the strengthening Z3 checked and
    whether the node stays ``implementable`` (``proved`` or
    ``inconclusive``).  ``[]`` when no single strengthening proves it."""
    req = next((r for r in all_requirements(ws.plan) if r.id == req_id), None)
    if req is None:
        return []
    formal, _ = formals_of(req, ws.checked)
    if formal is None:
        return []
    consts = list(dict.fromkeys(n.text for n in _numbers(formal.expr)))
    found: list[Strengthening] = []
    trials = 0
    values = {value(c) for c in consts} - {None}
    for n in cone:
        for k, g in enumerate(ws.checked.nodes[n].node.guarantees, 1):
            hit = False
            for cmp, lit in thresholds(g.formula):  # the statement's own number with the other strictness
                flip = threshold_edit(ws, cmp) if value(lit.text) in values and trials < MAX_TRIALS else None
                if flip is None:
                    continue
                trials += 1
                system = recheck.edited_system(ws, flip[0])
                impl = _implementable(ws, system, n) if system is not None and _proved(req, system, ws.plan) else ""
                if impl:
                    found.append(Strengthening(node=n, guarantee=k, edit=flip[0], how="threshold",
                                               old=flip[1], new=flip[2], implementable=impl, threshold=lit.text,
                                               inclusive=flip[0].text in ("<=", ">=")))
                    hit = True
                    break
            if hit:
                continue
            for lit in bound_literals(g.formula):  # bounds only: a coefficient is no bound to tighten
                span = _span(lit)
                for c in consts:
                    if span is None or c == lit.text or trials >= MAX_TRIALS:
                        continue
                    trials += 1
                    edit = Edit(g.loc.file, *span, c)
                    system = recheck.edited_system(ws, edit)
                    impl = _implementable(ws, system, n) if system is not None and _proved(req, system, ws.plan) else ""
                    if impl:
                        found.append(Strengthening(node=n, guarantee=k, edit=edit, how="bound",
                                                   old=lit.text, new=c, implementable=impl))
                        break
    if found:
        return found
    # no bound: the statement itself, in the names of a node it mentions, added to that node's guarantees
    mentioned = sorted({m[0] for m in formal.mentions})
    if len(mentioned) != 1:
        return []
    n = mentioned[0]
    assert req.formal is not None  # formals_of parsed a formal statement
    extra = re.sub(rf"(?<![\w.]){re.escape(n)}\.(in|out)\.", r"\1.", " ".join(req.formal.text.split()))
    for k, _g in enumerate(ws.checked.nodes[n].node.guarantees, 1):
        if trials >= MAX_TRIALS:
            break
        trials += 1
        added = conclusion_edit(ws, n, k, extra)
        system = recheck.edited_system(ws, added) if added is not None else None
        impl = _implementable(ws, system, n) if system is not None and _proved(req, system, ws.plan) else ""
        if impl and added is not None:
            found.append(Strengthening(node=n, guarantee=k, edit=added, how="conclusion", old="", new=extra,
                                       implementable=impl))
    return found


def _summands(e: Any) -> list[ast.NumLit]:
    """The integer literals under ``e`` that are a direct operand of ``+``
    or ``-`` (an index offset: ``1`` in ``out.joint == in.index + 1``)."""
    out: list[ast.NumLit] = []
    for x in subexpressions(e):
        if isinstance(x, ast.Binary) and x.op in ("+", "-"):
            out += [o for o in (x.left, x.right) if isinstance(o, ast.NumLit) and o.text.isdigit()]
    return out


def temporal_culprits(ws: Any, req_id: str, cone: Sequence[str]) -> list[Strengthening]:
    """The guarantees of ``cone`` to blame for the refuted temporal
    requirement ``req_id`` whose run meets every contract (an
    off-by-one names the node with the slip): a guarantee is named when one
    edit of it by one value -- a threshold's strictness where the statement
    names the threshold (as :func:`requirement_culprits`), or an index
    offset (a summand ``+ 1``) moved by one either way -- lets Z3's temporal
    check prove the requirement (the pipeline's own check, on an edited copy)
    and the edited node stays implementable.  Each a
    :class:`~rclverify.diagnosis.shapes.Strengthening` (``how`` ``threshold`` | ``offset``);
    ``[]`` when no such edit does it within :data:`TEMPORAL_TRIALS`."""
    req = next((r for r in all_requirements(ws.plan) if r.id == req_id), None)
    if req is None or req.formal is None:
        return []
    values = {value(t) for t in re.findall(r"(?<![\w.])\d+(?:\.\d+)?(?![\w.])", req.formal.text)} - {None}
    found: list[Strengthening] = []
    trials = 0

    def holds(edit: Edit, n: str) -> str:
        system = recheck.edited_system(ws, edit)
        return _implementable(ws, system, n) if system is not None and _proved(req, system, ws.plan) else ""
    for n in cone:
        for k, g in enumerate(ws.checked.nodes[n].node.guarantees, 1):
            tries: list[tuple[str, Edit, str, str]] = []
            for cmp, lit in thresholds(g.formula):
                flip = threshold_edit(ws, cmp) if value(lit.text) in values else None
                if flip is not None:
                    tries.append(("threshold", flip[0], flip[1], flip[2]))
            for lit in _summands(g.formula):
                span = _span(lit)
                if span is not None:
                    tries += [("offset", Edit(g.loc.file, *span, str(v)), lit.text, str(v))
                              for v in (int(lit.text) - 1, int(lit.text) + 1) if v >= 0]
            for how, edit, old, new in tries:
                if trials >= TEMPORAL_TRIALS:
                    return found
                trials += 1
                impl = holds(edit, n)
                if impl:
                    found.append(Strengthening(node=n, guarantee=k, edit=edit, how=how, old=old, new=new,
                                               implementable=impl))
                    break
    return found


def cost(ws: Any, report: ReportRows, node: str, edit: Edit) -> list[dict[str, str]]:
    """What else changes status when ``edit`` strengthens a guarantee of
    ``node``: the side conditions of the nodes it feeds and ``node``'s own
    health checks, asked before and after the edit the same way
    (:func:`rclverify.diagnosis.recheck.changes`)."""
    system = recheck.edited_system(ws, edit)
    if system is None:
        return []
    consumers = sorted({l.to_node for l in system[1].links if l.from_node == node})
    after: dict[str, str] = {}
    for n in consumers:
        after.update(recheck.side_conditions(*system, n, ws))
    before = {sc.id: str(sc.status) for sc in report.side_conditions if sc.id in after}
    h_before = recheck.health(ws, ws.checked, node)
    h_after = recheck.health(ws, system[0], node)
    return recheck.changes({**before, **h_before}, {**after, **h_after})
