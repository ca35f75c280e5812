"""The repairs of a failed side condition made on its producer
(:mod:`.sidecond`, repairs 1 and 2 of its module docstring): the consumer's
conjunct as a new guarantee of the producer, or a bound of the producer
tightened to it in place (:func:`strengthen`, :func:`inplace_edit`), and a
power-of-ten coefficient rescaled as a unit conversion (:func:`rescale`).
Each is offered only when Z3 discharged the side condition on the edited
contracts and the producer stays implementable.
"""
from __future__ import annotations

import re
from fractions import Fraction
from typing import Any, Mapping

from rclverify.calculus.compose import conjuncts
from rclverify.lang import ast
from rclverify.lang.types import Type
from rclverify.lang.printer import expr_to_rcl
from rclverify.lang.walk import subexpressions
from rclverify.diagnosis import realize, recheck
from rclverify.diagnosis.bounds import coefficient_literals, number_text, value
from rclverify.diagnosis.edits import Edit
from rclverify.records.links import link_pairs
from rclverify.diagnosis.repairs import _record
from rclverify.records.side_condition_rows import SideConditionRow
from rclverify.records.stage_records import Repair
from rclverify.diagnosis.units import declared_unit, literal_si, literal_in
from rclverify.semantics.operators import OPERATORS

#: a comparison operator -> whether it bounds its left side from above
UPPER = {"<=": True, "<": True, ">=": False, ">": False}


def mirror(op: str) -> str:
    """The comparison ``op`` reads as with its operands swapped, from the semantics table."""
    return str(OPERATORS[op].converse)


def implementable_check(status: str, node: str) -> dict[str, str]:
    """The ``proves`` item saying whether ``node`` stays implementable (``status``: Z3's answer,
    :func:`.realize.implementable`)."""
    return {"check": f"{node} implementable", "status": {
        "proved": "yes: every input its assumption allows has an answer (Z3: proved)",
        "inconclusive": "not decided (Z3 could not say in its budget)"}.get(status, status)}


def strengthen(ws: Any, sc: SideConditionRow, p: str, new_g: str, cost_of: Any, discharged: dict[str, str],
                not_offered: list[str], inplace: tuple[Edit, int, str] | None = None) -> list[Repair]:
    """1. the consumer's conjunct as a new guarantee of ``p``, or a bound of
    ``p`` tightened to it in place (``inplace``: :func:`inplace_edit`; module docstring)."""
    pn = ws.checked.nodes[p].node
    last = pn.guarantees[-1] if pn.guarantees else None
    if last is None or not last.loc.end_line:
        return []
    trigger = _trigger_of(pn, {ov for q, ov, _, _ in link_pairs(sc) if q == p})
    suffix = f" triggered by {trigger}" if trigger else ""
    answers = f" ({suffix.strip()}, as {p}'s guarantees on that output)" if trigger else ""
    rel = last.loc.file
    source = recheck.source_text(ws, rel)
    line = source.splitlines()[last.loc.line - 1]
    indent = line[:len(line) - len(line.lstrip())]
    edit = Edit(rel, last.loc.end_line, last.loc.end_col, last.loc.end_line, last.loc.end_col,
                f"\n{indent}guarantee( {new_g} ){suffix}")
    how = f"add the guarantee `{new_g}`{answers}"
    if inplace is not None:
        edit, k, old = inplace
        rel = edit.file
        how = (f"tighten the bound of its guarantee {k} in place, `{old}` becoming `{new_g}` (the same as adding "
               f"`{new_g}`, without leaving the old bound redundant)")
    system = recheck.edited_system(ws, edit)
    if system is None:
        return []
    consumers = sorted({l.to_node for l in system[1].links if l.from_node == p})
    cost = cost_of(*system, consumers, [p])
    if cost is None:
        return []
    impl, witness = realize.implementable(ws, system[0], p)
    if impl == "refuted":
        at = ", ".join(f"{k} = {v}" for k, v in witness.items()) or "an input"
        not_offered.append(f"Strengthening {p} by `{new_g}` discharges {sc.id} but leaves {p} unimplementable: "
                           f"for {at}, which its assumption allows, no output meets its guarantees.")
        return []
    undecided = " (Z3 could not decide whether it stays implementable)" if impl != "proved" else ""
    return [_record(
        "strengthen-producer",
        f"Strengthen {p}: {how}, the weakest strengthening of {p}'s guarantees that "
        f"entails {sc.node}'s assumption `{sc.conjunct}`; {p} stays consistent{' and implementable' if not undecided else ''}"
        f"{undecided}. {p}'s evidence must then establish the new guarantee.",
        edit, recheck.source_text(ws, rel),
        [discharged, {"check": f"{p}.contract-consistent", "status": "ok (Z3: sat)"}, implementable_check(impl, p)],
        cost, proves=f"{sc.id} follows from the edited contracts",
        not_shown=f"that {p} can be made to meet `{new_g}`: its evidence must establish it")]


def _normal(c: ast.Expr, prefix: str | None, name: str,
            constants: Mapping[str, tuple[Type, ast.Expr]] | None = None) -> tuple[str, ast.Expr] | None:
    """``(op, bound)`` when ``c`` is ``<prefix>.<name> op N`` (or ``N op
    <prefix>.<name>``, mirrored) with an ordering ``op``; ``N`` a numeral,
    or, with ``constants`` (the context's, name -> (type, defining
    expression)), a named constant whose value is a numeral (one
    first repair also when the bound is a named constant)."""
    if not (isinstance(c, ast.Compare) and len(c.ops) == 1 and c.ops[0] in UPPER):
        return None
    a, b = c.operands
    op: str = c.ops[0]

    def bound(e: ast.Expr) -> bool:
        return isinstance(e, ast.NumLit) or (constants is not None and isinstance(e, ast.Var) and e.prefix is None
                                             and e.name in constants and _const_value(e, constants) is not None)
    if bound(a) and isinstance(b, ast.Var) and not bound(b):
        a, b, op = b, a, mirror(op)
    if isinstance(a, ast.Var) and a.prefix == prefix and a.name == name and bound(b):
        return op, b
    return None


def _const_value(e: ast.Expr, constants: Mapping[str, tuple[Type, ast.Expr]] | None) -> Fraction | None:
    """The value of a numeral, or of a named constant defined by one."""
    if isinstance(e, ast.NumLit):
        return value(e.text)
    if isinstance(e, ast.Var) and constants is not None and e.name in constants:
        defining = constants[e.name][1]
        return value(defining.text) if isinstance(defining, ast.NumLit) else None
    return None


def inplace_edit(ws: Any, p: str, ov: str, target: ast.Expr) -> tuple[Edit, int, str] | None:
    """``(edit, guarantee index, old conjunct text)``: the top-level conjunct
    ``out.ov op N`` of a guarantee of ``p`` with the operator of the
    consumer's conjunct ``target`` (``in.w op B``) and a weaker ``N``, its
    literal (with its unit, ``45 [N]``) replaced by ``B``; ``None`` when
    there is none.  ``N`` and ``B`` are compared in one unit, each read in
    the unit written after it or else in its variable's declared unit
    (:func:`.units.literal_si`); ``B`` is written in ``N``'s unit, or as the
    consumer's named constant (a unit on the bound no longer
    suppresses the safe repair)."""
    consts = ws.checked.env.constants
    mine = next(((v, _normal(target, pre, v.name, consts)) for pre in ("in", None) for v in subexpressions(target)
                 if isinstance(v, ast.Var) and v.prefix == pre and v.name not in consts
                 and _normal(target, pre, v.name, consts)), None)
    if mine is None or mine[1] is None:
        return None
    var, (op, lit) = mine[0], mine[1]
    cons = next((n for n in ws.checked.nodes.values() if var.name in n.inputs
                 and any(c is target for a in n.node.assumes for c in conjuncts(a.formula))), None)
    want = literal_si(lit, consts, declared_unit(cons.node.inputs if cons else (), var.name))
    pn = ws.checked.nodes[p].node
    unit_p = declared_unit(pn.outputs, ov)
    for k, g in enumerate(pn.guarantees, 1):
        for c in conjuncts(g.formula):
            got = _normal(c, "out", ov)
            if got is None or got[0] != op or not got[1].loc.line or not isinstance(got[1], ast.NumLit):
                continue
            n = got[1]
            old = literal_si(n, consts, unit_p)
            if old is None or want is None or None not in (old[1], want[1]) and old[1] != want[1]:
                continue  # two dimensions (the unit check reports it), or a value not read
            if not (old[0] > want[0] if UPPER[op] else old[0] < want[0]):
                continue
            text = expr_to_rcl(lit) if isinstance(lit, ast.Var) else literal_in(want[0], n, unit_p)
            if text is None:
                continue
            end = n.loc.end_col if n.loc.end_line == n.loc.line else n.loc.col + len(n.text)
            return Edit(n.loc.file, n.loc.line, n.loc.col, n.loc.line, end, text), k, expr_to_rcl(c)
    return None


def _trigger_of(node: ast.Node, outs: set[str]) -> str:
    """``in.x`` when every guarantee of ``node`` that mentions one of the
    outputs ``outs`` is ``triggered by in.x`` (the same input), else ``""``."""
    found = set()
    for g in node.guarantees:
        text = expr_to_rcl(g.formula)
        if any(re.search(rf"(?<![\w.])out\.{re.escape(ov)}(?!\w)", text) for ov in outs):
            found.add(g.trigger.name if g.trigger is not None else None)
    if len(found) == 1 and None not in found:
        return f"in.{found.pop()}"
    return ""


def rescale(ws: Any, sc: SideConditionRow, p: str, ov: str, k: int, extreme: Fraction, cost_of: Any,
             discharged: dict[str, str]) -> list[Repair]:
    """2. a coefficient of ``p``'s guarantees on ``out.ov`` divided by ``10**k`` (module docstring)."""
    factor = Fraction(10) ** k
    for g in ws.checked.nodes[p].node.guarantees:
        if not re.search(rf"(?<![\w.])out\.{re.escape(ov)}(?!\w)", expr_to_rcl(g.formula)):
            continue
        for lit, parent in coefficient_literals(g.formula):
            v = value(lit.text)
            if v is None or not (lit.loc.end_line and parent.loc.end_line):
                continue
            new = v / factor if parent.op == "*" else v * factor
            text = number_text(new)
            if text is None:
                continue
            rel = g.loc.file
            source = recheck.source_text(ws, rel)
            if new == 1:  # `1000 * in.r` becomes `in.r`, `in.r / 0.001` becomes `in.r`
                other = parent.left if parent.op == "/" or parent.right is lit else parent.right
                probe = Edit(rel, other.loc.line, other.loc.col, other.loc.end_line, other.loc.end_col, "")
                if not other.loc.end_line:
                    continue
                edit = Edit(rel, parent.loc.line, parent.loc.col, parent.loc.end_line, parent.loc.end_col,
                            probe.deleted(source))
            else:
                edit = Edit(rel, lit.loc.line, lit.loc.col, lit.loc.end_line, lit.loc.end_col, text)
            system = recheck.edited_system(ws, edit)
            if system is None:
                continue
            consumers = sorted({l.to_node for l in system[1].links if l.from_node == p})
            cost = cost_of(*system, consumers, [p])
            if cost is None:
                continue
            impl, _ = realize.implementable(ws, system[0], p)
            if impl == "refuted":
                continue
            old, new_text = edit.deleted(source), edit.text
            bigger = "larger" if k > 0 else "smaller"
            return [_record(
                "rescale-producer",
                f"{p}'s contract lets `out.{ov}` reach {number_text(extreme) or extreme} where {sc.node} assumes "
                f"`{sc.conjunct}`: a factor of {number_text(abs(factor) if k > 0 else 1 / factor)}, so {p} "
                f"probably publishes `{ov}` in a unit {number_text(factor if k > 0 else 1 / factor)} times {bigger} "
                f"than {sc.node} reads (millimetres against metres). Convert it in {p}: `{old}` becomes "
                f"`{new_text}`. This is a unit conversion, not a bound: {p}'s implementation must publish in "
                f"{sc.node}'s unit.",
                edit, source,
                [discharged, {"check": f"{p}.contract-consistent", "status": "ok (Z3: sat)"},
                 implementable_check(impl, p)],
                cost, proves=f"{sc.id} follows from the edited contracts",
                not_shown=(f"which unit is right: {p}'s code must publish `{ov}` in the unit {sc.node} reads, "
                           f"and {p}'s evidence be established again for the rescaled guarantee"))]
    return []
