"""The report's summary: problem sentences, counts per status, the headline and the ``--strict`` gate.

``summary.problems`` lists one sentence per item that is not established
(a health problem, a requirement refuted or proved from an inconsistency, a
side condition not discharged, an altered record, an unanswered
acknowledgement, an unverified guarantee, failed/error/stale evidence, an
expected verdict that did not come); the problems grouped by root cause are
report/problems.py's.  Each function returns its part and changes nothing
it was given.
"""
from __future__ import annotations

from typing import Callable, Mapping, Sequence

from rclverify.records.findings import FindingRow
from rclverify.records.grounding_rows import GroundingRow
from rclverify.records.node_rows import UnverifiedRow
from rclverify.records.obligations import ObligationRow
from rclverify.records.records import SEVERITY
from rclverify.records.report_record import AssuranceReport
from rclverify.records.side_condition_rows import SideConditionRow
from rclverify.records.statuses import EvidenceStatus

#: Requirement verdicts that are a problem of their own.
_REQUIREMENT_PROBLEMS = ("refuted", "proved from an inconsistency", "proved vacuously", "error", "stale")


def brief(text: str, limit: int = 300) -> str:
    """``text`` cut to at most ``limit`` characters at a word boundary, with
    an ellipsis and a pointer to the full record when it was cut."""
    if len(text) <= limit:
        return text
    cut = text[:limit].rsplit(" ", 1)[0].rstrip(" ,;:")
    return cut + " ... (in full in the evidence record)"


def _health_problems(findings: Sequence[FindingRow]) -> list[str]:
    out = []
    for f in findings:
        if f.status == "problem":
            out.append(f"Contract health: {f.message}")
        elif f.status == "error":
            out.append(f"Contract health of {f.node} is error: {f.message}")
        elif f.status == "stale":
            out.append(f"Contract health of {f.node} is stale: made for another text of its contract or plan "
                       "(run `doit verify`)")
    return out


def problem_sentences(report: AssuranceReport, altered: Sequence[str]) -> list[str]:
    """The sentences of ``summary.problems`` (module docstring), in the
    report's order, from ``report``'s ``findings``, ``requirements``,
    ``side_conditions``, ``acknowledgements``, ``unverified``, ``evidence``
    and ``expected_verdicts`` rows; ``altered``: the sentences of records
    altered outside rclverify (report/evidence_rows.py)."""
    out = _health_problems(report.findings)
    out += [f"Requirement {rq.id} is {rq.verdict}: {brief(rq.note)}" for rq in report.requirements
            if rq.verdict in _REQUIREMENT_PROBLEMS]
    for sc in report.side_conditions:
        if sc.status != "discharged":
            where = " (checked in context too)" if sc.context and sc.status != "stale" else ""
            out.append(f"Side condition {sc.id} is {sc.status}{where}: {sc.conjunct}")
    out += altered
    out += [f"Acknowledgement {a.at} is {a.status}: {a.message}" for a in report.acknowledgements
            if a.status != "ok"]
    out += [u.message for u in report.unverified]
    out += [f"Evidence {e.obligation} is {e.status}: {brief(e.explanation)}" for e in report.evidence
            if e.status in ("failed", "error", "stale")]
    out += [f"Expected verdict mismatch: {x.obligation} is {x.actual}, the plan expects "
            f"{x.expected} ({x.source})" + (f": {x.reason}" if x.reason else "")
            for x in report.expected_verdicts if x.outcome == "MISMATCH"]
    return out


def grounding_problems(grounding: GroundingRow | None) -> list[str]:
    """The problems of the grounding in the robot's software (docs/ros.md): stale, or contract-vs-ROS errors."""
    out = []
    if grounding is not None and grounding.stale:
        out.append(f"Grounding is stale: {grounding.stale}")
    if grounding is not None and grounding.counts.error:
        out.append(f"Grounding: {grounding.counts.error} contract(s)-vs-ROS error(s) (rclverify ros check)")
    return out


def status_counts(obligations: Sequence[ObligationRow]) -> dict[EvidenceStatus, int]:
    """How many obligations have each status (``summary.counts``), in order of first appearance."""
    counts: dict[EvidenceStatus, int] = {}
    for row in obligations:
        counts[row.status] = counts.get(row.status, 0) + 1
    return counts


def strict_gate(report: AssuranceReport, guarantees_discharged: Callable[[], bool], deadlines_ok: bool) -> bool:
    """The ``--strict`` gate of ``report``'s rows before strength, the second solver's record and
    severities are weighed (report/build.py): every obligation discharged,
    every side condition proved, no health check that found a problem or
    could not decide, no guarantee left without evidence
    (``guarantees_discharged``), every formal requirement met
    (docs/requirements.md, "--strict"; an informal one is listed only),
    every end-to-end deadline proved (``deadlines_ok``) and no grounding
    error or stale grounding (docs/ros.md: findings never change a verdict)."""
    ok = (all(o.status == "discharged" for o in report.obligations)
          and all(sc.status == "discharged" for sc in report.side_conditions)
          and all(f.status in ("ok", "warning") for f in report.findings)
          and guarantees_discharged()
          and all(rq.verdict in ("met", "informal") for rq in report.requirements)
          and deadlines_ok)
    grounding = report.grounding
    if grounding is not None:
        ok = ok and not grounding.counts.error and not grounding.stale
    return ok


def headline(ob_rows: Sequence[ObligationRow], counts: Mapping[EvidenceStatus, int],
             side_conditions: Sequence[SideConditionRow], findings: Sequence[FindingRow],
             unverified: Sequence[UnverifiedRow] = ()) -> str:
    """The one-line summary, without empty fragments: a kind with nothing
    in it is said in words ("no obligations"), never as "0 obligations: ;".
    Guarantees no obligation covers (``unverified``) are counted after the
    obligations: "5 obligations: 5 discharged" alone would read as all done."""
    parts = []
    if ob_rows:
        parts.append(f"{len(ob_rows)} obligation{'s' if len(ob_rows) != 1 else ''}: "
                     + ", ".join(f"{counts[s]} {s}" for s in sorted(counts, key=lambda x: SEVERITY.get(x, 99))))
    else:
        parts.append("no obligations")
    if unverified:
        parts.append(f"{len(unverified)} guarantee{'s' if len(unverified) != 1 else ''} unverified "
                     "(no obligation covers " + ("it" if len(unverified) == 1 else "them") + ")")
    if side_conditions:
        discharged = [sc for sc in side_conditions if sc.status == "discharged"]
        in_context = sum(1 for sc in discharged if sc.verdict == "discharged in context")
        parts.append(f"{len(discharged)}/{len(side_conditions)} "
                     "side conditions discharged" + (f" ({in_context} in context)" if in_context else ""))
    else:
        parts.append("no side conditions")
    problems = sum(1 for f in findings if f.status == "problem")
    parts.append(f"{problems} contract health problem{'s' if problems != 1 else ''}" if problems
                 else "no contract health problem")
    altered = sum(1 for f in findings if f.status == "error")
    if altered:
        parts.append(f"{altered} contract health record{'s' if altered != 1 else ''} altered outside rclverify")
    return "; ".join(parts) + "."
