"""The report's ``standards`` part: the evidence rows mapped onto the plan's standard profiles (docs/standards.md).

One row per ``standards:`` entry of the plan, each with its clause rows
(:func:`rclverify.model.plan.standards.mapping.clause_rows`) over the
report's evidence rows once the confidence pass has given them their
strength.  A clause recommended HR at the chosen level and not covered is
a sentence of the summary's problems; ``--strict`` fails on it for a
standard chosen with ``strict: true`` (:func:`strict_reason` names them).  The mapping is a
traceability aid, not a compliance claim.
"""
from __future__ import annotations

from typing import Any, Mapping, Sequence, TypedDict

from rclverify.records.report_schema import EvidenceRow, Report
from rclverify.model.plan.standards.choice import StandardChoice
from rclverify.model.plan.standards.mapping import CLAUSE_STATUSES, ClauseRow, clause_rows, not_covered


class StandardRow(TypedDict):
    """One chosen standard (``standards[]`` of the report)."""
    profile: str
    title: str
    edition: str
    level_name: str
    level: str | None
    source: str
    clauses: list[ClauseRow]
    open: list[str]
    counts: dict[str, int]
    required_not_covered: list[str]
    strict: bool


class StandardsPart(TypedDict):
    """What the pass gives the report: the rows, one problem sentence per
    standard with an HR clause not covered, and whether none has one."""
    rows: list[StandardRow]
    problems: list[str]
    ok: bool


def _label(row: Mapping[str, Any]) -> str:
    level = f" {str(row['level_name']).upper()} {row['level']}" if row.get("level") is not None else ""
    return f"{row['edition']}{level}"


def standards_part(choices: Sequence[StandardChoice], evidence: Sequence[EvidenceRow]) -> StandardsPart:
    """The ``standards`` part of the plan's ``choices`` over the report's
    ``evidence`` rows (``obligation``, ``backend``, ``kind``, ``status``,
    ``strength``).  Pure; raises nothing."""
    rows: list[StandardRow] = []
    problems: list[str] = []
    ok = True
    for c in choices:
        clauses = clause_rows(c.profile, c.level, evidence)
        missing = not_covered(clauses)
        row: StandardRow = {
            "profile": c.profile.id, "title": c.profile.title, "edition": c.profile.edition,
            "level_name": c.profile.level_name, "level": c.level,
            "source": f"{c.loc.file}:{c.loc.line}:{c.loc.col}", "clauses": clauses,
            "open": [x["id"] for x in clauses if x["status"] == "open"],
            "counts": {s: sum(1 for x in clauses if x["status"] == s) for s in CLAUSE_STATUSES},
            "required_not_covered": missing, "strict": c.strict}
        rows.append(row)
        ok = ok and not (missing and c.strict)
        if missing:
            problems.append(_missing_sentence(row, [x for x in clauses if x["id"] in missing]))
    return {"rows": rows, "problems": problems, "ok": ok}


def _missing_sentence(row: StandardRow, missing: Sequence[ClauseRow]) -> str:
    """The summary's sentence for a standard's HR items not covered: each with
    its title and why (no evidence of the kinds it accepts, or some of its
    records not discharged), and where to read them."""
    def why(c: ClauseRow) -> str:
        if not c["evidence"]:
            return f"no {' or '.join(c['accepts'])} evidence"
        bad = sum(1 for e in c["evidence"] if e["status"] != "discharged")
        return f"{bad} of its {len(c['evidence'])} records not discharged"
    items = "; ".join(f"{c['id']} {c['title'].lower()} ({why(c)})" for c in missing)
    return (f"Standard {_label(row)}: {len(missing)} highly recommended item{'s' if len(missing) != 1 else ''} "
            f"not covered by discharged evidence: {items}; the report's section Safety standards lists each "
            f"item's records")


def strict_reason(report: Report) -> list[str]:
    """Why the chosen standards fail ``--strict`` on ``report``: one clause
    per standard chosen with ``strict: true`` naming its HR items not
    covered (empty when none)."""
    out = []
    for row in report.get("standards") or ():
        missing = list(row.get("required_not_covered") or ())
        if missing and row.get("strict"):
            out.append(f"{_label(row)}: highly recommended item{'s' if len(missing) != 1 else ''} not covered ("
                       + ", ".join(missing) + ")")
    return out


__all__ = ["StandardRow", "StandardsPart", "standards_part", "strict_reason"]
