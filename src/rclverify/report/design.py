"""The design stage's result in SARIF and JUnit (docs/nodl.md, "The design stage"): the report's ``design``
(:class:`~rclverify.records.design_rows.DesignRow`, stages/design.py) as results and test cases.

SARIF (:func:`sarif_results`): one result of rule ``RCL-DESIGN`` per monitoring field decided, at the field's
line in the design file: a refuted ``timeout`` or ``error_rate`` an ``error``, a refuted ``warn_rate`` or an
undecided field a ``warning`` (the severities of the stage's findings, ``design-timeout`` ...), a proved
field a ``note`` (met: the chain's longest gap and the limit in the text); the contract clauses the gap adds
up are the related locations.  Each finding that is no field's (``design-missing``, ``design-unwired``,
``design-record``) is a result of the same rule at its places.

JUnit (:func:`junit_suite`): a ``design`` ``<testsuite>``, one ``<testcase>`` per field (classname
``design``, name ``<node> <trigger> <field>``, at the field's line): proved passes, a refuted ``timeout`` or
``error_rate`` fails, undecided is skipped, a refuted ``warn_rate`` passes with the warning in its
``<system-out>`` (a warning does not fail ``--strict``); each error that is no field's fails a case of its
code (``design-record``, the record not believed, an ``<error>``), a stale record fails a ``design-stale``
case; warnings that are no field's go to the suite's ``<system-out>``.  ``None`` without a design.
"""
from __future__ import annotations

import xml.etree.ElementTree as ET
from typing import Callable

from rclverify.records.design_rows import DesignFieldRow, DesignFindingRow, DesignPlaceRow
from rclverify.records.report_record import AssuranceReport
from rclverify.records.sarif import SarifLocation, SarifResult
from rclverify.report.junit_suite import FindingSuite

#: The SARIF rule of a design result (id, name, level, text).
SARIF_RULES = (
    ("RCL-DESIGN", "DesignMonitoringField", "error",
     "A monitoring field (timeout, error_rate, warn_rate) of the Autoware System Designer design the plan names, "
     "decided against the contracts along its chain, or a design node or port without contract "
     "(docs/nodl.md, \"The design stage\"; the result's code names which)."),
)
#: The finding code of each field when it is refuted.
_REFUTED = {"timeout": ("design-timeout", "error"), "error_rate": ("design-error-rate", "error"),
            "warn_rate": ("design-warn-rate", "warning")}


def _at(p: DesignPlaceRow) -> str:
    return f"{p.file}:{p.line}:{p.col}"


def _field_of(f: DesignFindingRow, fields: list[DesignFieldRow]) -> bool:
    """Whether finding ``f`` is a field's (refuted or undecided: its first place is a decided field's)."""
    return bool(f.places) and f.code in ("design-timeout", "design-error-rate", "design-warn-rate",
                                         "design-undecided") and any(
        d.at is not None and _at(d.at) == _at(f.places[0]) for d in fields)


def _verdict(d: DesignFieldRow) -> tuple[str, str, str]:
    """``(code, severity, text)`` of field ``d``; severity ``note`` when it is met."""
    what = f"{d.node} {d.trigger}: {d.field} ({d.limit})"
    if d.status == "proved":
        return "design-met", "note", f"{what} holds: the contracts let it wait at most {d.bound} <= {d.limit}."
    if d.status == "undecided":
        return "design-undecided", "warning", f"{what} is not decided: {d.why}."
    code, severity = _REFUTED[d.field]
    return code, severity, f"{what} cannot be met: the contracts let it wait {d.bound} > {d.limit}."


def _related(places: list[str], location: Callable[[str], list[SarifLocation]], text: str) -> list[SarifLocation]:
    out = [loc for p in places for loc in location(p)]
    for i, loc in enumerate(out):
        loc["id"] = i
        loc["message"] = {"text": text}
    return out


def sarif_results(report: AssuranceReport, result: Callable[..., SarifResult],
                  location: Callable[[str], list[SarifLocation]]) -> list[SarifResult]:
    """The design's SARIF results (module docstring); ``result(rule, level, text, where, key, props)`` and
    ``location(where)`` are report/sarif.py's.  Empty without a design."""
    row = report.design
    if row is None:
        return []
    out = []
    for k, d in enumerate(row.decided):
        code, level, text = _verdict(d)
        where = _at(d.at) if d.at is not None else ""
        res = result("RCL-DESIGN", level, f"{text} [{code}]", where, f"design:{d.node}:{d.trigger}:{d.field}:{k}",
                     {"code": code, "node": d.node, "trigger": d.trigger, "field": d.field, "status": d.status,
                      "limit_s": d.limit_s, "bound_s": d.bound_s})
        related = _related([_at(s.at) for s in d.steps], location, "a contract clause the chain's gap adds up")
        if related:
            res["relatedLocations"] = related
        out.append(res)
    for k, f in enumerate(row.findings):
        if _field_of(f, row.decided):
            continue
        places = [_at(p) for p in f.places]
        res = result("RCL-DESIGN", f.severity, f"{f.message} [{f.code}]", places[0] if places else "",
                     f"design:{f.code}:{':'.join(places)}:{k}", {"code": f.code})
        related = _related(places[1:], location, "the other place of this finding")
        if related:
            res["relatedLocations"] = related
        out.append(res)
    return out


def junit_suite(report: AssuranceReport, case: Callable[..., ET.Element],
                outcome: Callable[..., str]) -> tuple[ET.Element, dict[str, int], float] | None:
    """The ``design`` ``<testsuite>`` (module docstring); ``case`` and ``outcome`` are report/junit.py's.
    ``None`` without a design."""
    row = report.design
    if row is None:
        return None
    found = FindingSuite("design", outcome, "design")
    suite, add = found.suite, found.add
    for d in row.decided:
        code, severity, text = _verdict(d)
        where = _at(d.at) if d.at is not None else ""
        c = case(suite, "design", f"{d.node} {d.trigger} {d.field}", where, 0.0)
        chain = "\n".join(f"{_at(s.at)}: {s.text}" for s in d.steps)
        if severity == "error":
            add(c, "refuted", f"{text} [{code}]", chain)
        elif d.status == "undecided":
            add(c, "unknown", f"{text} [{code}]", "")
        else:
            add(c, "ok", "", "")
            if severity == "warning":
                ET.SubElement(c, "system-out").text = f"{where + ': ' if where else ''}warning: {text} [{code}]"
    warned = []
    for f in row.findings:
        if _field_of(f, row.decided):
            continue
        places = [_at(p) for p in f.places]
        if f.severity != "error":
            warned.append(f"{places[0] + ': ' if places else ''}warning: {f.message} [{f.code}]")
            continue
        add(case(suite, "design", f"{f.code} {places[0] if places else ''}".strip(), places[0] if places else "", 0.0),
            "error" if f.code == "design-record" else "failed", f"{f.message} [{f.code}]",
            "\n".join(f"{p}: error: {f.message}" for p in places))
    if row.stale:
        add(case(suite, "design", "design-stale", "", 0.0), "stale", f"the design check is stale: {row.stale}",
            "`doit verify` checks the current design and contracts")
    if warned:
        ET.SubElement(suite, "system-out").text = "\n".join(warned)
    return found.closed()


__all__ = ["SARIF_RULES", "junit_suite", "sarif_results"]
