"""A unit mismatch's row of the problem list: the findings it explains join it.

A diagnosis record of kind ``unit`` (:mod:`rclverify.diagnosis.units`)
names in ``joins`` the findings that follow from one unit mismatch on a
connection: its lint error and the ``W-unit-missing`` warning (by their
``file:line:col``), the reader's side condition, the probable scale
mismatch on it, the recorded runs whose assumption violations are blamed
on the producer.  :func:`rclverify.report.problems.group_problems` keys each
of them, and the record itself, by the record's root culprits (the
producer's equation or declaration), so they are one row blaming the
producer; a joined finding that is no problem of its own (a lint warning, a
health warning, a run whose evidence holds) is listed in that row too.
"""
from __future__ import annotations

from collections.abc import Callable, Sequence

from rclverify.records.monitored_run import AssumptionViolation, MonitoredRun
from rclverify.records.problem_rows import DiagnosisRow
from rclverify.records.report_record import AssuranceReport
from rclverify.report.problems_places import Member

#: The kind of a unit mismatch's diagnosis record.
KIND = "unit"


def joins(diagnoses: Sequence[DiagnosisRow]) -> dict[str, str]:
    """``{finding id: unit record id}`` of every unit record's ``joins``
    (the first record that names a finding keeps it)."""
    out: dict[str, str] = {}
    for d in diagnoses:
        if d.kind == KIND:
            for j in d.joins or ():
                out.setdefault(j, d.id)
    return out


def _violation(j: str, first: AssumptionViolation | None) -> str:
    """The sentence of evidence ``j`` whose run violated the node's assumption first at ``first`` (``?``
    for what the run did not say)."""
    where, time, blame = (first.where, first.time, first.blame) if first is not None else (None, None, None)
    return (f"{j}: the assumption `{first.assumption if first is not None else ''}` is violated at "
            f"{'?' if where is None else where} (t = {'?' if time is None else time} s), blamed on the "
            f"{'?' if blame is None else blame}.")


def extra_members(report: AssuranceReport, diagnoses: Sequence[DiagnosisRow], covered: set[str],
                  anchor: Callable[..., str]) -> list[tuple[Member, str]]:
    """The joined findings not yet among the row's members, each
    ``(member, unit record id)``: a lint row (by location), a health
    finding, an evidence record (members as ``group_problems`` makes them)."""
    lint = {x.location: (k, x) for k, x in enumerate(report.lint)}
    findings = {f.id: f for f in report.findings}
    evidence = {e.obligation: e for e in report.evidence}
    out: list[tuple[Member, str]] = []
    for d in diagnoses:
        if d.kind != KIND:
            continue
        for j in d.joins or ():
            if j in covered:
                continue
            covered.add(j)
            if j in lint:
                k, x = lint[j]
                m = Member(j, "lint", x.severity.lower(), f"{x.code}: {x.message}", anchor("lint", k + 1), False)
            elif j in findings:
                f = findings[j]
                m = Member(j, f"contract health: {f.check}", f.status, f.message, anchor("finding", j), False)
            elif j in evidence:
                e = evidence[j]
                m = Member(j, "evidence", e.status, _violation(j, MonitoredRun.of(e.monitoring).first_assumption_violation),
                           anchor("ev", j), False)
            else:
                continue
            out.append((m, d.id))
    return out
