"""The one place the report's parts become the report: each pass of report/build.py returns its part, and
the functions here put a part in, giving a new report.

A pass reads the report as the parts before it made it and returns what
it adds (report/statistics.py, report/confidence_rows.py, the diagnosis stage's record,
report/problems.py, report/culprits.py); nothing a pass returned is
changed afterwards: a row that gains keys is a new row, the rows it does
not touch are shared.  The last step, :func:`finished`, checks the whole
against the schema's types (records/report_schema.py).
"""
from __future__ import annotations

from typing import Any, Mapping, Sequence

from rclverify.records.problem_rows import DiagnosisRow
from rclverify.records.report_schema import Report, as_report
from rclverify.records.summary_rows import DiagnosisBrief, Summary
from rclverify.report.confidence_rows import ConfidencePart
from rclverify.report.standards_rows import StandardsPart
from rclverify.report.statistics import StatisticsPart


def with_statistics(report: Mapping[str, Any], part: StatisticsPart) -> dict[str, Any]:
    """``report`` with the statistics pass's ``part``: the ``statistics``
    table, each per-run evidence row's ``statistics.group`` and each
    requirement's ``statistics`` rows."""
    evidence = [{**e, "statistics": {**e["statistics"], "group": part["groups"][i]}} if i in part["groups"] else e
                for i, e in enumerate(report["evidence"])]
    requirements = [{**rq, "statistics": part["requirements"][str(rq["id"])]}
                    if str(rq["id"]) in part["requirements"] else rq for rq in report["requirements"]]
    return {**report, "evidence": evidence, "requirements": requirements, "statistics": part["table"]}


def with_solvers(report: Mapping[str, Any], counts: Mapping[str, int], problem: str) -> dict[str, Any]:
    """``report`` with ``summary.solvers`` (how many items two solvers, one
    solver, ... decided) and the second solver's record's
    ``problem`` ('' when none) among the problems."""
    problems = list(report["summary"]["problems"]) + ([f"Second-solver record: {problem}"] if problem else [])
    return {**report, "summary": {**report["summary"], "problems": problems, "solvers": dict(counts)}}


def _nodes_with_confidence(nodes: Sequence[Mapping[str, Any]], part: ConfidencePart) -> list[dict[str, Any]]:
    out = []
    for n in nodes:
        strengths = part["guarantees"].get(n["name"], [])
        guarantees = [{**g, "strength": s.to_json()} for g, s in zip(n["guarantees"], strengths)]
        out.append({**n, "guarantees": guarantees + list(n["guarantees"][len(strengths):]),
                    **part["nodes"].get(n["name"], {})})
    return out


def with_confidence(report: Mapping[str, Any], part: ConfidencePart) -> dict[str, Any]:
    """``report`` with the confidence pass's ``part`` (report/confidence_rows.py):
    strengths on evidence rows, side conditions and guarantees, confidence
    on nodes, derived properties and requirements, ``summary.confidence``
    and the requirements short of their required strength among the problems."""
    summary = {**report["summary"], "problems": list(report["summary"]["problems"]) + part["problems"]}
    if part["confidence"] is not None:
        summary["confidence"] = part["confidence"]
    return {
        **report, "summary": summary,
        "evidence": [{**e, "strength": s.to_json()} for e, s in zip(report["evidence"], part["evidence"])],
        "side_conditions": [{**sc, "strength": s.to_json()}
                            for sc, s in zip(report["side_conditions"], part["side_conditions"])],
        "nodes": _nodes_with_confidence(report["nodes"], part),
        "derived_properties": [{**d, **part["derived"].get(d["node"], {})} for d in report["derived_properties"]],
        "requirements": [{**rq, **part["requirements"].get(str(rq["id"]), {})} for rq in report["requirements"]],
    }


def with_standards(report: Mapping[str, Any], part: StandardsPart) -> dict[str, Any]:
    """``report`` with the ``standards`` rows (report/standards_rows.py) and
    their problem sentences (a highly recommended item not covered)."""
    summary = {**report["summary"], "problems": list(report["summary"]["problems"]) + part["problems"]}
    return {**report, "summary": summary, "standards": part["rows"]}


def with_strict(report: Mapping[str, Any], strict_ok: bool) -> dict[str, Any]:
    """``report`` with ``meta.strict_ok`` (the ``--strict`` gate, report/build.py)."""
    return {**report, "meta": {**report["meta"], "strict_ok": strict_ok}}


def with_diagnoses(report: Mapping[str, Any], diagnoses: list[dict[str, Any]]) -> dict[str, Any]:
    """``report`` with one diagnosis record per problem (docs/diagnosis.md;
    :class:`~rclverify.records.problem_rows.DiagnosisRow`) and their brief
    in ``summary.diagnoses`` (how many repairs Z3 checked): the last part
    of the summary, which is then decoded into
    :class:`~rclverify.records.summary_rows.Summary`.  Raises
    :class:`msgspec.ValidationError` for a record or summary of another
    shape (a bug of the build)."""
    rows = [DiagnosisRow.of(d) for d in diagnoses]
    brief = [DiagnosisBrief(d.id, d.kind, d.sentence, len(d.repairs)) for d in rows]
    summary = Summary.of({**report["summary"], "diagnoses": [b.to_json() for b in brief]})
    return {**report, "diagnoses": [d.to_json() for d in rows], "summary": summary.to_json()}


def finished(report: Mapping[str, Any], problems: list[dict[str, Any]], nodes: list[dict[str, Any]]) -> Report:
    """``report`` with the ``problems`` grouped by root cause and the
    ``nodes`` their culprits marked (report/culprits.py), checked as a
    :class:`~rclverify.records.report_schema.Report` (``ValueError`` when a
    part is missing: a bug of the build, never shown)."""
    return as_report({**report, "problems": problems, "nodes": nodes})
