"""Repairs of a failed side condition ``G_p => c`` on the link
``P.out.v -> C.in.w``, ranked by what they cost the user (docs/diagnosis.md,
"Side condition: repairs ranked by what they cost").

1. ``strengthen-producer``: ``c`` (in ``P``'s output names) becomes a new
   guarantee of ``P``, the weakest strengthening of ``G_p`` that entails
   ``c``.  When a guarantee of ``P`` already bounds the output the same
   way at its top level (``out.max_speed <= 2.0`` against ``in.max_speed
   <= 1.5``), its bound is tightened in place instead (``2.0`` becomes
   ``1.5``): the same contract as the added guarantee, without leaving the
   old bound redundant (a health warning ``--strict`` fails on), its
   trigger and deadline kept.  Otherwise, when every guarantee of ``P`` on the linked output answers one
   input (``triggered by in.query``: a service's response), the new one
   answers it too, so it is owed to that input's events only, as theirs are
   (docs/monitors.md).  Offered only when ``P`` stays *implementable* (every input its
   assumption allows still has an answer, :func:`.realize.implementable`):
   adding ``out.d <= 30`` to ``out.d == 1000 * in.r`` is consistent but
   answers only ``in.r <= 0.03``; that is said (``not_offered``), not
   offered.
2. ``rescale-producer``: when the producer's range and the consumer's
   bound differ by a power of ten (``P`` reaches 30000 where ``C`` assumes
   at most 30: millimetres against metres), the coefficient of ``P``'s
   guarantee is rescaled (``1000 * in.r`` becomes ``in.r``), as a unit
   conversion, never as a bound.
3. ``weaken-consumer``: ``c`` widened to what ``P`` guarantees (the
   producer's extreme value, or one of its conjuncts), offered last and
   only with what it invalidates named: ``C``'s guarantees that read ``w``
   and ``C``'s evidence, established under ``c`` only; with a
   power-of-ten mismatch it is said to be probably unsafe (``C`` would
   read millimetres as metres).

The bound tightened in place is compared and written in its own unit
(``45 [N]`` becomes ``40 [N]``; a bare number is read in its variable's
declared unit), and when that edit is not shown the guarantee is added
instead, so a unit never suppresses the safe repair.  When the consumer's
assumption stems from a requirement (a formal statement reads the linked
value, or names the constant of its bound), weakening it is never the first
repair: alone, it is withdrawn into ``not_offered`` with the reason
.

Every repair is returned only when Z3 discharged the side condition on the
edited contracts and the edited node stays consistent; that is what its
``proves`` says, and ``not_shown`` what Z3 did not show.  The repairs made
on the producer (1 and 2) are :mod:`.producer_repairs`'.
"""
from __future__ import annotations

import difflib
import re
from fractions import Fraction
from typing import Any, Mapping, Sequence

from rclverify.calculus.compose import conjuncts
from rclverify.lang import ast
from rclverify.lang.printer import expr_to_rcl
from rclverify.lang.walk import subexpressions
from rclverify.diagnosis import realize, recheck
from rclverify.diagnosis.bounds import number_text, power_of_ten, value
from rclverify.diagnosis.edits import Edit
from rclverify.records.links import link_pairs
from rclverify.diagnosis.repairs import MAX_CANDIDATES, _and_text, _record, _rename
from rclverify.diagnosis.shapes import SideConditionRepairs
from rclverify.records.side_condition_rows import SideConditionRow
from rclverify.records.stage_records import Repair
from rclverify.model.plan.errors import PlanError
from rclverify.model.plan.load import all_requirements
from rclverify.diagnosis.producer_repairs import UPPER, implementable_check, inplace_edit, mirror, rescale, strengthen



def _bound_shape(target: ast.Expr, inputs: set[str]) -> tuple[str, bool, ast.NumLit] | None:
    """``(input, upper, literal)`` when the conjunct is ``in.w op N`` or
    ``N op in.w`` with an ordering ``op``: ``upper`` when it bounds ``w``
    from above."""
    if not (isinstance(target, ast.Compare) and len(target.ops) == 1 and target.ops[0] in UPPER):
        return None
    a, b = target.operands
    op: str = target.ops[0]
    if isinstance(b, ast.Var) and isinstance(a, ast.NumLit):
        a, b, op = b, a, mirror(op)
    if isinstance(a, ast.Var) and a.prefix in ("in", None) and a.name in inputs and isinstance(b, ast.NumLit):
        return a.name, UPPER[op], b
    return None


def side_condition_repairs(ws: Any, sc: SideConditionRow, before_sc: Mapping[str, str],
                           consumer_evidence: Sequence[str] = ()) -> SideConditionRepairs:
    """The repairs of the failed side condition ``sc`` (the report's record), in
    the order of the module docstring: ``{"repairs": [repair records],
    "not_offered": [sentences]}``.  ``before_sc`` maps every side condition
    id of the system to its status before the edit; ``consumer_evidence``
    names the consumer's evidence (``"Controller.g1.hoare.c1 (discharged)"``)
    that a weakened assumption invalidates."""
    out: SideConditionRepairs = {"repairs": [], "not_offered": []}
    pairs = link_pairs(sc)
    if not pairs:
        return out
    consumer = sc.node
    producers = sorted({p for p, _, _, _ in pairs})
    cons = ws.checked.nodes[consumer].node
    target = None
    for a in cons.assumes:
        for c in conjuncts(a.formula):
            if expr_to_rcl(c) == sc.conjunct and c.loc.end_line:
                target = c
    if target is None:
        return out
    to_producer = [(f"in.{iv}", f"out.{ov}") for _, ov, _, iv in pairs]
    to_consumer = [(f"out.{ov}", f"in.{iv}") for _, ov, _, iv in pairs]

    def cost_of(checked: Any, model: Any, nodes: Sequence[str], health_nodes: Sequence[str]) -> list[dict[str, str]] | None:
        after: dict[str, str] = {}
        for n in nodes:
            after.update(recheck.side_conditions(checked, model, n, ws))
        if after.get(sc.id) != "discharged":
            return None
        h_before: dict[str, str] = {}
        h_after: dict[str, str] = {}
        for n in health_nodes:  # both asked the same way, so a change is the edit's
            h_before.update(recheck.health(ws, ws.checked, n))
            h_after.update(recheck.health(ws, checked, n))
            if h_after.get(f"{n}.contract-consistent") != "ok":
                return None
        before = {k: v for k, v in before_sc.items() if k in after}
        return recheck.changes({**before, **h_before}, {**after, **h_after})

    # the consumer's bound against how far the producer's contract lets the value go
    shape = _bound_shape(target, {iv for _, _, _, iv in pairs})
    extreme: Fraction | None = None
    scale: int | None = None
    single = len(producers) == 1 and len({ov for _, ov, _, _ in pairs}) == 1
    if shape is not None and single:
        extreme = realize.extreme(ws, ws.checked, producers[0], pairs[0][1], shape[1])
        b = value(shape[2].text)
        scale = power_of_ten(extreme, b) if extreme is not None and b is not None else None
    discharged = {"check": sc.id, "status": "discharged (Z3: proved)"}

    if single:
        new_g = _rename(sc.conjunct, to_producer)
        inplace = inplace_edit(ws, producers[0], pairs[0][1], target)
        tightened = strengthen(ws, sc, producers[0], new_g, cost_of, discharged, [], inplace) if inplace else []
        # the bound tightened in place, else (no such bound, or its edit not shown) the guarantee added
        out["repairs"] += tightened or strengthen(ws, sc, producers[0], new_g, cost_of, discharged, out["not_offered"])
        if scale is not None and extreme is not None:
            out["repairs"] += rescale(ws, sc, producers[0], pairs[0][1], scale, extreme, cost_of, discharged)
    out["repairs"] += _weaken(ws, sc, target, shape, extreme, scale, producers, to_consumer, cost_of, discharged,
                              consumer_evidence)
    _requirement_guard(out, sc, _stems_from(ws, sc, pairs, target))
    return out


def _stems_from(ws: Any, sc: SideConditionRow, pairs: Sequence[tuple[str, str, str, str]],
                target: ast.Expr) -> list[str]:
    """The ids of the plan's requirements the consumer's assumption ``target``
    stems from: a formal statement that reads the linked value
    (``Gripper.in.force`` or ``Supervisor.out.force``) or names a constant
    the assumption's bound is written with."""
    try:
        reqs = all_requirements(ws.plan)
    except PlanError:  # a Doorstop tree that cannot be read: reported elsewhere; the plan's own requirements
        reqs = ws.plan.requirements
    names = {f"{c}.in.{w}" for _, _, c, w in pairs} | {f"{p}.out.{v}" for p, v, _, _ in pairs}
    consts = {v.name for v in subexpressions(target) if isinstance(v, ast.Var) and v.prefix is None
              and v.name in ws.checked.env.constants}
    out = []
    for r in reqs:
        text = r.formal.text if r.formal else ""
        if any(re.search(rf"(?<![\w.]){re.escape(n)}(?![\w'])", text) for n in names | consts):
            out.append(r.id)
    return out


def _requirement_guard(out: SideConditionRepairs, sc: SideConditionRow, reqs: Sequence[str]) -> None:
    """Weakening a consumer's assumption that stems from a requirement is
    never the first repair: when it would be the only one it is
    withdrawn into ``not_offered`` with the reason; after a safe repair it
    stays, saying which requirement its bound stems from."""
    if not reqs:
        return
    ids = ", ".join(reqs)
    weak = [r for r in out["repairs"] if r["kind"] == "weaken-consumer"]
    if not weak:
        return
    if out["repairs"][0]["kind"] == "weaken-consumer":
        out["repairs"] = [r for r in out["repairs"] if r["kind"] != "weaken-consumer"]
        out["not_offered"].append(
            f"Weakening {sc.node}'s assumption `{sc.conjunct}` is not offered: its bound stems from "
            f"requirement {ids}, and no safe repair (tightening the producer) was shown, so widening it would "
            f"trade the requirement for a green side condition. Repair the producer, or revise {ids} first.")
        return
    for r in weak:
        r["summary"] += (f" Its bound stems from requirement {ids}: widening it changes what {ids} demands, so "
                         "it is never the first repair.")


def _conjunct_after(target: ast.Expr, edit: Edit, source: str) -> str:
    """The text of the conjunct ``target`` once ``edit`` (inside it, on one line) is made."""
    loc = target.loc
    if (edit.line, edit.col, edit.end_line, edit.end_col) == (loc.line, loc.col, loc.end_line, loc.end_col):
        return edit.text
    delta = len(edit.text) - (edit.end_col - edit.col) if edit.end_line == loc.end_line == edit.line else 0
    return Edit(edit.file, loc.line, loc.col, loc.end_line, loc.end_col + delta, "").deleted(edit.apply(source))


def _weaken(ws: Any, sc: SideConditionRow, target: ast.Expr, shape: tuple[str, bool, ast.NumLit] | None,
            extreme: Fraction | None, scale: int | None, producers: Sequence[str],
            to_consumer: Sequence[tuple[str, str]], cost_of: Any, discharged: dict[str, str],
            consumer_evidence: Sequence[str]) -> list[Repair]:
    """3. the consumer's conjunct widened to what the producers guarantee, last (module docstring)."""
    consumer = sc.node
    cons = ws.checked.nodes[consumer].node
    rel = target.loc.file
    source = recheck.source_text(ws, rel)
    cands: list[str] = []
    linked = {a for a, _ in to_consumer}
    for p in producers:
        for g in ws.checked.nodes[p].node.guarantees:
            for c in conjuncts(g.formula):
                t = expr_to_rcl(c)
                if any(re.search(rf"(?<![\w.']){re.escape(v)}(?![\w'])", t) for v in linked):
                    t2 = _rename(t, to_consumer)
                    if "out." not in t2 and t2 != sc.conjunct and t2 not in cands:
                        cands.append(t2)
    already = {expr_to_rcl(c) for a in cons.assumes for c in conjuncts(a.formula)}
    cands = [t for t in cands if t not in already]
    cands.sort(key=lambda t: -difflib.SequenceMatcher(None, t, sc.conjunct).ratio())
    loc = target.loc
    # the producers' own conjuncts first (their words), then the consumer's bound moved to the producer's extreme
    edits = [Edit(rel, loc.line, loc.col, loc.end_line, loc.end_col, t) for t in cands]
    if shape is not None and extreme is not None and shape[2].loc.end_line and number_text(extreme):
        lit = shape[2]
        edits.append(Edit(rel, lit.loc.line, lit.loc.col, lit.loc.end_line, lit.loc.end_col, str(number_text(extreme))))
    reads = [f"guarantee {k} `{expr_to_rcl(g.formula)}`" for k, g in enumerate(cons.guarantees, 1)
             if shape is None or re.search(rf"(?<![\w.])(in\.)?{re.escape(shape[0])}(?![\w'])", expr_to_rcl(g.formula))]
    for edit in edits[:MAX_CANDIDATES]:
        system = recheck.edited_system(ws, edit)
        if system is None:
            continue
        cost = cost_of(*system, [consumer], [consumer])
        if cost is None:
            continue
        impl, witness = realize.implementable(ws, system[0], consumer)
        if impl == "refuted":
            continue
        wider = _conjunct_after(target, edit, source)
        evidence = (f"{consumer}'s evidence was established under `{sc.conjunct}` and no longer covers the wider "
                    f"inputs: {', '.join(consumer_evidence)} must be established again"
                    if consumer_evidence else
                    f"{consumer} has no evidence yet; whatever it gets must cover the wider inputs")
        unsafe = (f" Probably unsafe: the ranges differ by a factor of "
                  f"{number_text(Fraction(10) ** abs(scale))}, the signature of a unit mismatch; widening the "
                  f"assumption makes {consumer} read {producers[0]}'s values in the wrong unit instead of converting "
                  "them." if scale is not None else "")
        return [_record(
            "weaken-consumer",
            f"Weaken {consumer}'s assumption (last resort): `{sc.conjunct}` becomes "
            f"`{wider}`, what {_and_text(list(producers))} "
            f"guarantee{'s' if len(producers) == 1 else ''}; {consumer} stays consistent. It invalidates what was "
            f"shown for the narrower inputs: {consumer}'s {_and_text(reads) if reads else 'guarantees'} must then hold "
            f"for the wider inputs, and {evidence}.{unsafe}",
            edit, source,
            [discharged, {"check": f"{consumer}.contract-consistent", "status": "ok (Z3: sat)"},
             implementable_check(impl, consumer)],
            cost, proves=f"{sc.id} follows from the edited contracts",
            not_shown=(f"that {consumer} behaves correctly on the wider inputs: its evidence must be established "
                       "again" + ("; the ranges suggest a unit mismatch, which widening does not convert"
                              if scale is not None else "")))]
    return []
