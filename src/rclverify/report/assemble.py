"""The one place the report's parts become the report: each pass of report/build.py returns its part, and
the functions here put a part in, giving a new :class:`~rclverify.records.report_record.AssuranceReport`.

A pass reads the report as the parts before it made it and returns what
it adds (report/statistics.py, report/confidence_rows.py, report/standards_rows.py, the diagnosis
stage's record, report/problems.py, report/culprits.py); nothing a pass returned is
changed afterwards: the records are frozen, a row that gains a field is a new record
(:func:`msgspec.structs.replace`), the rows it does not touch are shared.
"""
from __future__ import annotations

from typing import Any, Mapping, Sequence

from msgspec.structs import replace

from rclverify.records.node_rows import NodeRow
from rclverify.records.problem_rows import DiagnosisRow
from rclverify.records.report_record import AssuranceReport
from rclverify.records.standards_rows import StandardRow
from rclverify.records.row import decode_rows
from rclverify.records.summary_rows import DiagnosisBrief
from rclverify.report.confidence_rows import ConfidencePart
from rclverify.report.standards_rows import StandardsPart
from rclverify.report.statistics import StatisticsPart


def with_statistics(report: AssuranceReport, part: StatisticsPart) -> AssuranceReport:
    """``report`` with the statistics pass's ``part``: the ``statistics``
    table, each per-run evidence row's ``statistics.group`` and each
    requirement's ``statistics`` rows."""
    groups, by_req = part.groups, part.requirements
    evidence = [replace(e, statistics={**e.statistics, "group": groups[i]}) if i in groups else e
                for i, e in enumerate(report.evidence)]
    requirements = [replace(rq, statistics=by_req[rq.id]) if rq.id in by_req else rq for rq in report.requirements]
    return replace(report, evidence=evidence, requirements=requirements, statistics=part.table)


def with_solvers(report: AssuranceReport, counts: Mapping[str, int], problem: str) -> AssuranceReport:
    """``report`` with ``summary.solvers`` (how many items two solvers, one
    solver, ... decided) and the second solver's record's
    ``problem`` ('' when none) among the problems."""
    s = report.summary
    problems = [*s.problems, *([f"Second-solver record: {problem}"] if problem else [])]
    return replace(report, summary=replace(s, problems=problems, solvers=dict(counts)))


def _nodes_with_confidence(nodes: Sequence[NodeRow], part: ConfidencePart) -> list[NodeRow]:
    out = []
    for n in nodes:
        strengths = part.guarantees.get(n.name, [])
        guarantees = [replace(g, strength=s) for g, s in zip(n.guarantees, strengths)]
        conf = part.nodes.get(n.name)
        row = replace(n, guarantees=guarantees + list(n.guarantees[len(strengths):]))
        out.append(row if conf is None else replace(row, confidence=conf.confidence, limited_by=conf.limited_by))
    return out


def with_confidence(report: AssuranceReport, part: ConfidencePart) -> AssuranceReport:
    """``report`` with the confidence pass's ``part`` (report/confidence_rows.py):
    strengths on evidence rows, side conditions and guarantees, confidence
    on nodes, derived properties and requirements, ``summary.confidence``
    and the requirements short of their required strength among the problems."""
    s = report.summary
    summary = replace(s, problems=[*s.problems, *part.problems])
    if part.confidence is not None:
        summary = replace(summary, confidence=part.confidence)
    derived, reqs = part.derived, part.requirements
    return replace(
        report, summary=summary,
        evidence=[replace(e, strength=st) for e, st in zip(report.evidence, part.evidence)],
        side_conditions=[replace(sc, strength=st) for sc, st in zip(report.side_conditions, part.side_conditions)],
        nodes=_nodes_with_confidence(report.nodes, part),
        derived_properties=[replace(d, confidence=derived[d.node].confidence, limited_by=derived[d.node].limited_by)
                            if d.node in derived else d for d in report.derived_properties],
        requirements=[replace(rq, **reqs[rq.id]._asdict()) if rq.id in reqs else rq for rq in report.requirements],
    )


def with_standards(report: AssuranceReport, part: StandardsPart) -> AssuranceReport:
    """``report`` with the ``standards`` rows (report/standards_rows.py) and
    their problem sentences (a highly recommended item not covered)."""
    summary = replace(report.summary, problems=[*report.summary.problems, *part["problems"]])
    return replace(report, summary=summary, standards=decode_rows(StandardRow, part["rows"]))


def with_strict(report: AssuranceReport, strict_ok: bool) -> AssuranceReport:
    """``report`` with ``meta.strict_ok`` (the ``--strict`` gate, report/build.py)."""
    return replace(report, meta=replace(report.meta, strict_ok=strict_ok))


def with_diagnoses(report: AssuranceReport, diagnoses: Sequence[DiagnosisRow | Mapping[str, Any]]) -> AssuranceReport:
    """``report`` with one diagnosis record per problem (docs/diagnosis.md;
    :class:`~rclverify.records.problem_rows.DiagnosisRow`, or its JSON object) and their brief
    in ``summary.diagnoses`` (how many repairs Z3 checked).  Raises
    :class:`msgspec.ValidationError` for a record of another shape (a bug of the build)."""
    rows = decode_rows(DiagnosisRow, diagnoses)
    brief = [DiagnosisBrief(d.id, d.kind, d.sentence, len(d.repairs)) for d in rows]
    return replace(report, diagnoses=rows, summary=replace(report.summary, diagnoses=brief))
