"""One diagnosis per unit mismatch on a connection, joining what follows from it.

The driver publishes degrees where the localiser reads radians: the
connection's unit mismatch (:func:`rclverify.model.system.units.mismatches`,
declared at both ends or the driver's unit inferred from its guarantee,
:mod:`rclverify.lang.unitinfer`), the ``W-unit-missing`` warning on the
driver's output, the side condition of the localiser that reads it, the
calculus' probable scale mismatch on that side condition and the recorded
runs in which the localiser's assumption is violated, blamed on the driver,
are one defect.  :func:`unit_records` gives one record of kind ``unit`` for
it (the shape of :mod:`.build`), blaming the **producer**: its culprit is
the equation the unit was inferred from, or the producer's declaration;
``joins`` lists the ids of the other findings (lint rows by their
``file:line:col``, side conditions, findings, evidence), which
:func:`rclverify.report.problems.group_problems` puts in the same row.

The first repair is the conversion (:func:`conversion_repair`), offered only
when Z3 and the unit check show it on the edited text.
"""
from __future__ import annotations

import math
import re
from typing import Any, Callable, Mapping

from rclverify.lang.unitconv import factor_name, short_decimal
from rclverify.lang.units import Unit, ratio
from rclverify.model.system.units import Mismatch, mismatches
from rclverify.diagnosis import recheck
from rclverify.diagnosis.edits import Edit
from rclverify.records.links import link_pairs
from rclverify.diagnosis.repairs import _record
from rclverify.lang.printer import level, expr_to_rcl
from rclverify.lang import ast
from rclverify.lang.types import Type
from rclverify.lang.units import UnitError, parse_unit
from fractions import Fraction
from rclverify.diagnosis.bounds import number_text
from rclverify.diagnosis.shapes import ReportRows
from rclverify.diagnosis.record import diagnosis_record
from rclverify.records.problem_rows import DiagnosisRow
from rclverify.records.stage_records import Culprit, Repair


def _loc(loc: Any) -> str:
    return f"{loc.file}:{loc.line}:{loc.col}"


def _joins(report: ReportRows, m: Mismatch) -> list[str]:
    """The ids of the report's findings that the mismatch ``m`` explains
    (module docstring), in the report's order."""
    (p, _, v), (c, _, w) = m.writer, m.reader
    out = [_loc(m.at), _loc(m.writer_decl)]
    out += [x.location for x in report.lint if x.code.startswith("W-unit") and x.location == _loc(m.reader_decl)]
    scs = [sc for sc in report.side_conditions if sc.status != "discharged" and (p, v, c, w) in link_pairs(sc)]
    out += [sc.id for sc in scs]
    out += [f.id for f in report.findings if f.check == "probable-scale-mismatch"
            and any(f.id.startswith(f"{sc.id}.scale") for sc in scs)]
    obligations = {o.id: o for o in report.obligations}
    for e in report.evidence:
        # the monitors' payload (backends/monitors): its first violated assumption, blamed on a producer
        first = e.monitoring.get("first_assumption_violation")
        o = obligations.get(e.obligation)
        node = o.node if o is not None else None
        if first and node == c and re.search(rf"\b{re.escape(p)}\b", str(first.get("blame", ""))):
            out.append(e.obligation)
    return list(dict.fromkeys(out))


def _sentence(m: Mismatch, joined: list[str], report: ReportRows) -> str:
    writer, reader = ".".join(m.writer), ".".join(m.reader)
    p, c = m.writer[0], m.reader[0]
    whence = (f"its unit inferred from guarantee {m.inferred.guarantee} `{m.inferred.clause}` ({_loc(m.inferred.loc)})"
              if m.inferred is not None else f"as declared ({_loc(m.writer_decl)})")
    factor = (f", a factor of {factor_name(m.reader_unit, m.writer_unit)}" if m.code == "E-unit-scale"
              else f" ({m.reason})")
    found = [j for j in joined if not re.match(r".*:\d+:\d+$", j)]
    seen = f"; it explains {', '.join(found)}" if found else ""
    return (f"Unit mismatch: {p} publishes {writer} in {m.writer_unit}, {whence}, where {c} reads {reader} in "
            f"{m.reader_unit} ({_loc(m.reader_decl)}){factor}{seen}. Convert in {p}.")


def unit_records(ws: Any, report: ReportRows, cached: Callable[[Any, Callable[[], Any]], Any]) -> list[DiagnosisRow]:
    """One record per unit mismatch of the workspace ``ws`` (module
    docstring), in link order: ``{"id": "<P>.out.<v>.unit", "kind": "unit",
    "node": P, "status": "failed", "sentence", "culprits", "counterexample":
    [], "repairs", "guarantee", "joins": [ids], "lint": the location of its
    lint row}``.  ``cached(key, make)`` keeps the repairs between runs (the
    diagnosis cache).  Never raises for a system that type-checked."""
    out: list[DiagnosisRow] = []
    for m in mismatches(ws.checked, ws.model.links):
        joined = _joins(report, m)
        p = m.writer[0]
        culprit: Culprit
        if m.inferred is not None:
            culprit = {"what": f"guarantee {m.inferred.guarantee} of {p}", "source": _loc(m.inferred.loc),
                       "text": m.inferred.clause}
        else:
            culprit = {"what": f"output {m.writer[2]} of {p}", "source": _loc(m.writer_decl), "text": str(m.writer_unit)}
        key = ["unit", m.name, str(m.writer_unit), str(m.reader_unit), _loc(m.at)]
        reps = cached(key, lambda: conversion_repair(ws, m)) or []
        out.append(diagnosis_record(f"{'.'.join(m.writer)}.unit", "unit", p, "failed", _sentence(m, joined, report),
                                    culprits=[culprit], counterexample=[], repairs=reps,
                                    guarantee=m.inferred.guarantee if m.inferred is not None else None,
                                    joins=joined, lint=_loc(m.at)))
    return out


def _number(u: Unit, t: Unit) -> tuple[str, str]:
    """``(operator, literal)`` that takes a number in ``u`` to ``t``:
    ``("*", "0.017453292519943295")`` for deg to rad, ``("/", "3.6")`` for
    km/h to m/s, the exact decimal when there is one."""
    f, pi = ratio(u, t)  # how many t make one u
    if pi == 0:
        if f.denominator == 1:
            return "*", str(f.numerator)
        for op, x in (("*", f), ("/", 1 / f)):
            if x.denominator == 1:
                return op, str(x.numerator)
            text = short_decimal(x)
            if text:
                return op, text
    return "*", repr(float(f) * math.pi ** pi)


def _wrap(text: str) -> str:
    return f"({text})" if any(ch in text for ch in "*/") else text


def conversion_repair(ws: Any, m: Mismatch) -> list[Repair]:
    """The conversion in the producer as a repair record
    (:func:`rclverify.diagnosis.repairs._record`, kind ``convert-unit``):
    the right side ``E`` of the equation the writer's unit was inferred
    from becomes ``E * k [t/u]`` (the factor with its unit, so RCL's unit
    algebra gives the reader's unit ``t`` exactly).  Returned only when the
    edited contracts type-check, the connection's units agree, and Z3 shows
    the producer consistent; the reader's side conditions are asked again
    and their changes are the repair's ``cost``.  ``[]`` otherwise (a
    declared mismatch: the fix changes two places of the producer; a unit
    inferred through a conversion with another reading; dimensions apart)."""
    got = m.inferred
    if got is None or got.alternative is not None or m.code != "E-unit-scale" or got.from_key is not None:
        return []
    p, c = m.writer[0], m.reader[0]
    cn = ws.checked.nodes[p]
    eq = None
    for g in cn.node.guarantees:
        stack = [g.formula]
        while stack:
            e = stack.pop()
            if getattr(e, "loc", None) == got.loc and hasattr(e, "operands"):
                eq = e
            stack += [x for x in (getattr(e, "left", None), getattr(e, "right", None)) if x is not None]
    if eq is None:
        return []
    lhs, rhs = eq.operands
    if not (getattr(lhs, "name", None) == m.writer[2]):
        rhs = lhs
    loc = rhs.loc
    if not loc.end_line:
        return []
    source = recheck.source_text(ws, loc.file)
    edit0 = Edit(loc.file, loc.line, loc.col, loc.end_line, loc.end_col, "")
    old = edit0.deleted(source)
    op, lit = _number(m.writer_unit, m.reader_unit)
    unit = f"{_wrap(m.reader_unit.text or str(m.reader_unit)[1:-1])}/{_wrap(m.writer_unit.text or str(m.writer_unit)[1:-1])}"
    body = old if level(rhs) >= 8 else f"({old})"
    edit = Edit(loc.file, loc.line, loc.col, loc.end_line, loc.end_col, f"{body} {op} {lit} [{unit}]")
    after = recheck.edited_system(ws, edit)
    if after is None:
        return []
    checked, model = after
    if any(x.writer == m.writer and x.reader == m.reader for x in mismatches(checked, model.links)):
        return []
    if recheck.consistent(ws, checked, p) != "sat":
        return []
    before = {k: v for k, v in recheck.side_conditions(ws.checked, ws.model, c, ws).items()}
    now = recheck.side_conditions(checked, model, c, ws)
    checks = [{"check": f"units of {m.name}", "status": f"agree: {m.reader_unit} at both ends"},
              {"check": f"{p} consistent", "status": "yes (Z3: sat)"}]
    checks += [{"check": k, "status": v} for k, v in sorted(now.items())]
    fixed = [k for k, v in now.items() if v == "discharged" and before.get(k) != "discharged"]
    still = [k for k, v in now.items() if v != "discharged"]
    words = factor_name(m.writer_unit, m.reader_unit)  # how many of the reader's units make one of the writer's
    side = expr_to_rcl(lhs if rhs is not lhs else eq.operands[1])
    summary = (f"Convert in {p}: write `{side} == {body} {op} {lit} [{unit}]` so that {p} publishes {m.reader_unit}, "
               f"the unit {c} reads ({m.writer_unit} to {m.reader_unit}: multiply by {words})")
    proves = (f"the units of {m.name} agree ({m.reader_unit} at both ends)"
              + (f" and {', '.join(fixed)} follow{'s' if len(fixed) == 1 else ''} from the edited contracts" if fixed else ""))
    not_shown = ("that the value's unit is really " + str(m.writer_unit) + " where it comes from"
                 + (f"; {', '.join(still)} still not discharged" if still else ""))
    return [_record("convert-unit", summary, edit, source, checks, recheck.changes(before, now), proves, not_shown)]


# ---------------------------------------------------------------------------
# Bounds in one unit: the in-place tightening of a bound written with a unit
# (``45 [N]`` tightened to ``40 [N]``) compares and writes numbers
# in a common unit
# ---------------------------------------------------------------------------

def declared_unit(decls: Any, name: str) -> Any:
    """The ``UnitAnn`` declared for the input or output ``name`` among
    ``decls`` (``IOVar``s, or a mapping of name to one), ``None`` when none is."""
    items = decls.values() if isinstance(decls, Mapping) else decls
    for v in items:
        if isinstance(v, ast.IOVar) and v.name == name:
            return v.unit
    return None


def _unit_of(ann: Any) -> Unit | None:
    if ann is None:
        return None
    try:
        u = parse_unit(str(ann.text))
    except UnitError:
        return None
    return u if u.offset is None and u.pi == 0 else None  # affine (degC) and pi-scaled units: not compared


def literal_si(lit: Any, constants: Mapping[str, tuple[Type, ast.Expr]], declared: Any) -> tuple[Any, Any] | None:
    """``(value in the coherent SI unit, dimensions)`` of a bound: a numeral
    read in the unit written after it (``45 [N]``), else in ``declared`` (the
    compared variable's ``UnitAnn``: a bare number takes the unit of what it
    is compared with, docs/rcl-language.md "Units of measure"); a named
    constant defined by a numeral likewise.  Dimensions are ``None`` for a
    number with no unit at all.  ``None`` when the value or unit cannot be
    read (an affine or pi-scaled unit, a constant not defined by a numeral)."""
    if isinstance(lit, ast.Var) and lit.name in constants:
        lit = constants[lit.name][1]
    if not isinstance(lit, ast.NumLit):
        return None
    v = Fraction(lit.text)
    ann = lit.unit if lit.unit is not None else declared
    if ann is None:
        return v, None
    u = _unit_of(ann)
    return None if u is None else (v * u.factor, u.dims)


def literal_in(si: Any, like: Any, declared: Any) -> str | None:
    """The value ``si`` (coherent SI) as a numeral in the unit of the
    literal ``like``: with ``like``'s unit written after it when it has one
    (``40 [N]``), else bare in ``declared``'s unit; ``None`` when that is no
    finite decimal."""
    ann = like.unit if like.unit is not None else declared
    u = _unit_of(ann)
    if ann is not None and u is None:
        return None
    text = number_text(si / u.factor if u is not None else si)
    if text is None:
        return None
    return f"{text} [{like.unit.text}]" if like.unit is not None else text
