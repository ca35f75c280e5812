"""Why ``verify --strict`` fails: the clauses a failed gate names
(:func:`strict_reasons`, kept in the summary ``rclverify verify`` prints and
writes) and the one sentence it ends with (:func:`strict_sentence`); the
ROS grounding's errors as the terminal shows them (:func:`grounding_brief`).

The gate itself is :func:`rclverify.report.build.build_report`'s
(``meta.strict_ok``); each clause counts what fails it, one severity per
finding (:mod:`.severity`), and names the first few items.
"""
from __future__ import annotations

from typing import Any, Mapping

from rclverify.records.grounding_rows import GroundingRow
from rclverify.records.grounding_findings import GroundingFindingRow
from rclverify.records.records import SEVERITY
from rclverify.records.report_record import AssuranceReport
from rclverify.report.shapes import GroundingBrief, SummaryData


def _rank(status: str) -> int:
    return SEVERITY.get(status, SEVERITY["error"])


def _place(f: GroundingFindingRow) -> str:
    """``file:line:col: `` of a grounding finding (its RCL place, else its ROS one), ``""`` without a file."""
    at = f.rcl or f.ros
    return f"{at.text()}: " if at is not None and at.file else ""


def grounding_brief(g: GroundingRow | None) -> GroundingBrief | None:
    """The ROS grounding (docs/ros.md; the report's ``grounding`` decoded) as the terminal shows it:
    ``{"error": n, "warning": m, "errors": ["file:line:col: message (CODE)", ...]}``; ``None`` when
    the plan has no ``ros:`` section.  A finding is the ROS check's own JSON object
    (:class:`~rclverify.records.grounding_rows.GroundingRow` ``findings``), decoded
    (:class:`~rclverify.records.grounding_findings.GroundingFindingRow`)."""
    if g is None:
        return None
    found = [GroundingFindingRow.of(f) for f in g.findings]
    errors = [f"{_place(f)}{f.message or ''} ({f.code})" for f in found if f.severity == "error"]
    return {"error": g.counts.error, "warning": g.counts.warning, "errors": errors}


def _named(items: list[str], most: int) -> str:
    return ", ".join(items[:most]) + (", ..." if len(items) > most else "")


def _plural(n: int, many: str, one: str) -> str:
    return many if n != 1 else one


def strict_reasons(report: AssuranceReport | Mapping[str, Any]) -> list[str]:
    """Why ``verify --strict`` fails on ``report`` (the report, or its JSON object decoded here once
    into :class:`~rclverify.records.report_record.AssuranceReport`, which raises
    :class:`msgspec.ValidationError` for a report of another shape), as clauses
    (empty when ``meta.strict_ok``): obligations not discharged by status,
    guarantees no obligation covers, side conditions not proved, health
    checks with a problem or undecided, health and lint warnings (one
    severity per finding, :mod:`.severity`), formal requirements not met,
    ROS grounding errors, NoDL errors (the gate of
    :func:`rclverify.report.build.build_report`)."""
    report = AssuranceReport.of(report)
    if report.meta.strict_ok:
        return []
    out: list[str] = []
    counts = {k: v for k, v in report.summary.counts.items() if k != "discharged" and v}
    if counts:
        n = sum(counts.values())
        out.append(f"{n} obligation{_plural(n, 's are', ' is')} not discharged ("
                   + ", ".join(f"{v} {k}" for k, v in sorted(counts.items(), key=lambda kv: -_rank(kv[0]))) + ")")
    bare = [f"{n.name}.g{g.index}" for n in report.nodes for g in n.guarantees if not g.obligations]
    if bare:
        out.append(f"{len(bare)} guarantee{_plural(len(bare), 's are', ' is')} unverified (no obligation covers "
                   f"{_plural(len(bare), 'them', 'it')}): " + _named(bare, 4))
    sc = [x for x in report.side_conditions if x.status != "discharged"]
    if sc:
        out.append(f"{len(sc)} side condition{_plural(len(sc), 's are', ' is')} not proved")
    fs = [f for f in report.findings if f.status not in ("ok", "warning")]
    if fs:
        out.append(f"{len(fs)} contract health check{_plural(len(fs), 's', '')} found a problem or could not decide")
    warned = [f.id for f in report.findings if f.status == "warning" and not f.acknowledged]
    if warned:  # one severity per finding: a warning fails --strict as it is a warning everywhere (report/severity.py)
        out.append(f"{len(warned)} contract health warning{_plural(len(warned), 's', '')} (" + _named(warned, 4) + ")")
    # a lint warning answered in the plan passes (model/plan/acknowledged.py)
    lint = [x.location for x in report.lint if not x.acknowledged]
    if lint:
        out.append(f"{len(lint)} lint diagnostic{_plural(len(lint), 's', '')} (`rclverify check`: "
                   + _named(lint, 3) + ")")
    acks = [a.at for a in report.acknowledgements if a.status != "ok"]
    if acks:
        out.append(f"{len(acks)} acknowledgement{_plural(len(acks), 's', '')} in the plan "
                   f"{_plural(len(acks), 'are', 'is')} stale or refused (" + _named(acks, 3) + ")")
    rq = [r.id for r in report.requirements if r.verdict not in ("met", "informal")]
    if rq:
        out.append(f"{len(rq)} formal requirement{_plural(len(rq), 's are', ' is')} not met (" + _named(rq, 4) + ")")
    from rclverify.report.standards_rows import strict_clauses as standards_reason  # deferred: start-up (loads the standard profiles' modules only when --strict failed)
    from rclverify.report.deadlines import strict_reason  # deferred: start-up (loads rclverify.core, rclverify.core.atomic and more only when called)
    out += strict_reason(report.deadlines)  # end-to-end deadlines not proved
    out += standards_reason(report.standards)  # highly recommended items of the plan's standards not covered
    g = grounding_brief(report.grounding)
    if g and g["error"]:
        out.append(f"{g['error']} ROS grounding error{_plural(g['error'], 's', '')} (`rclverify ros check`)")
    from rclverify.report.nodl import strict_reason as nodl_reason  # deferred: start-up (loads rclverify.report.nodl only when --strict failed)
    out += nodl_reason(report.nodl)  # NoDL errors, a stale NoDL check
    from rclverify.report.near_misses import strict_reason as near_reason  # deferred: start-up (only when --strict failed)
    out += near_reason(report.near_misses)  # guarantees held by less than the plan's near_miss threshold
    return out


def strict_sentence(data: SummaryData) -> str:
    """The one sentence a failed ``verify --strict`` ends with, from the
    summary ``data`` (:func:`rclverify.report.summary.summary_data`): its ``strict`` reasons."""
    reasons = list(data.get("strict") or [])
    why = "; ".join(reasons) if reasons else ("some evidence is failed, inconclusive, pending, stale or error, or a "
                                               "side condition or contract health check is not proved")
    return f"--strict failed: {why} (reports/assurance.html)."


__all__ = ["grounding_brief", "strict_reasons", "strict_sentence"]
