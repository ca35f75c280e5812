"""Why ``verify --strict`` fails: the clauses a failed gate names
(:func:`strict_reasons`, kept in the summary ``rclverify verify`` prints and
writes) and the one sentence it ends with (:func:`strict_sentence`); the
ROS grounding's errors as the terminal shows them (:func:`grounding_brief`).

The gate itself is :func:`rclverify.report.build.build_report`'s
(``meta.strict_ok``); each clause counts what fails it, one severity per
finding (:mod:`.severity`), and names the first few items.
"""
from __future__ import annotations

from typing import Mapping

from rclverify.records.findings import rows_of
from rclverify.records.records import SEVERITY
from rclverify.records.report_schema import Report
from rclverify.report.shapes import GroundingBrief, SummaryData


def _rank(status: str) -> int:
    return SEVERITY.get(status, SEVERITY["error"])


def grounding_brief(g: object) -> GroundingBrief | None:
    """The ROS grounding (docs/ros.md) as the terminal shows it: ``{"error":
    n, "warning": m, "errors": ["file:line:col: message (CODE)", ...]}``;
    ``None`` when the plan has no ``ros:`` section."""
    if not isinstance(g, Mapping):
        return None
    errors: list[str] = []
    for f in g.get("findings", []):
        if f.get("severity") == "error":
            at = f.get("rcl") or f.get("ros") or {}
            where = f"{at['file']}:{at.get('line', 1)}:{at.get('col', 1)}: " if at.get("file") else ""
            errors.append(f"{where}{f.get('message', '')} ({f.get('code', '')})")
    counts = g.get("counts", {})
    return {"error": int(counts.get("error", len(errors))), "warning": int(counts.get("warning", 0)), "errors": errors}


def strict_reasons(report: Report) -> list[str]:
    """Why ``verify --strict`` fails on ``report``, as clauses (empty when
    ``report["meta"]["strict_ok"]``): obligations not discharged by status,
    guarantees no obligation covers, side conditions not proved, health
    checks with a problem or undecided, health and lint warnings (one
    severity per finding, :mod:`.severity`), formal requirements not met,
    ROS grounding errors, NoDL errors (the gate of
    :func:`rclverify.report.build.build_report`)."""
    if report["meta"]["strict_ok"]:
        return []
    out: list[str] = []
    counts = {k: v for k, v in report["summary"].get("counts", {}).items() if k != "discharged" and v}
    if counts:
        n = sum(counts.values())
        out.append(f"{n} obligation{'s are' if n != 1 else ' is'} not discharged ("
                   + ", ".join(f"{v} {k}" for k, v in sorted(counts.items(), key=lambda kv: -_rank(kv[0]))) + ")")
    bare = [f"{n['name']}.g{g['index']}" for n in report["nodes"] for g in n.get("guarantees", [])
            if not g.get("obligations")]
    if bare:
        out.append(f"{len(bare)} guarantee{'s are' if len(bare) != 1 else ' is'} unverified (no obligation covers "
                   f"{'them' if len(bare) != 1 else 'it'}): " + ", ".join(bare[:4]) + (", ..." if len(bare) > 4 else ""))
    sc = [x for x in report["side_conditions"] if x["status"] != "discharged"]
    if sc:
        out.append(f"{len(sc)} side condition{'s are' if len(sc) != 1 else ' is'} not proved")
    findings = rows_of(report["findings"])
    fs = [f for f in findings if f.status not in ("ok", "warning")]
    if fs:
        out.append(f"{len(fs)} contract health check{'s' if len(fs) != 1 else ''} found a problem or could not decide")
    warned = [f.id for f in findings if f.status == "warning" and not f.acknowledged]
    if warned:  # one severity per finding: a warning fails --strict as it is a warning everywhere (report/severity.py)
        out.append(f"{len(warned)} contract health warning{'s' if len(warned) != 1 else ''} ("
                   + ", ".join(warned[:4]) + (", ..." if len(warned) > 4 else "") + ")")
    lint = [x for x in report.get("lint") or () if str(x.get("severity", "")).lower() in ("warning", "error")
            and not x.get("acknowledged")]  # a warning answered in the plan passes (model/plan/acknowledged.py)
    if lint:
        out.append(f"{len(lint)} lint diagnostic{'s' if len(lint) != 1 else ''} (`rclverify check`: "
                   + ", ".join(str(x["location"]) for x in lint[:3]) + (", ..." if len(lint) > 3 else "") + ")")
    acks = [a for a in report.get("acknowledgements") or () if a.get("status") != "ok"]
    if acks:
        out.append(f"{len(acks)} acknowledgement{'s' if len(acks) != 1 else ''} in the plan "
                   f"{'are' if len(acks) != 1 else 'is'} stale or refused ("
                   + ", ".join(str(a["at"]) for a in acks[:3]) + (", ..." if len(acks) > 3 else "") + ")")
    rq = [r["id"] for r in report.get("requirements", []) if r.get("verdict", "informal") not in ("met", "informal")]
    if rq:
        out.append(f"{len(rq)} formal requirement{'s are' if len(rq) != 1 else ' is'} not met ("
                   + ", ".join(rq[:4]) + (", ..." if len(rq) > 4 else "") + ")")
    from rclverify.report.standards_rows import strict_reason as standards_reason  # deferred: start-up (loads the standard profiles' modules only when --strict failed)
    from rclverify.report.deadlines import strict_reason  # deferred: start-up (loads rclverify.core, rclverify.core.atomic and more only when called)
    out += strict_reason(report)  # end-to-end deadlines not proved
    out += standards_reason(report)  # highly recommended items of the plan's standards not covered
    g = grounding_brief(report.get("grounding"))
    if g and g["error"]:
        out.append(f"{g['error']} ROS grounding error{'s' if g['error'] != 1 else ''} (`rclverify ros check`)")
    from rclverify.report.nodl import strict_reason as nodl_reason  # deferred: start-up (loads rclverify.report.nodl only when --strict failed)
    out += nodl_reason(report)  # NoDL errors, a stale NoDL check
    from rclverify.report.near_misses import strict_reason as near_reason  # deferred: start-up (only when --strict failed)
    out += near_reason(report)  # guarantees held by less than the plan's near_miss threshold
    return out


def strict_sentence(data: SummaryData) -> str:
    """The one sentence a failed ``verify --strict`` ends with, from the
    summary ``data`` (:func:`rclverify.report.summary.summary_data`): its ``strict`` reasons."""
    reasons = list(data.get("strict") or [])
    why = "; ".join(reasons) if reasons else ("some evidence is failed, inconclusive, pending, stale or error, or a "
                                               "side condition or contract health check is not proved")
    return f"--strict failed: {why} (reports/assurance.html)."


__all__ = ["grounding_brief", "strict_reasons", "strict_sentence"]
