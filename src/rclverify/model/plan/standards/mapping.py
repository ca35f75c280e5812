"""A report's evidence rows mapped onto a standard profile's clauses (docs/standards.md).

:data:`SUPPORTS` is the one table from what an evidence row says (its record
``kind``, records/statuses.py ``EvidenceKind``, and its ``strength.kind``,
docs/confidence.md) to the profile evidence kinds it can support.  A clause
is ``covered`` when some supporting row is discharged, ``partial`` when
supporting rows exist but none is discharged, ``open`` when none exists.
The mapping is a traceability aid for an assessor, not a compliance claim.
"""
from __future__ import annotations

from typing import Mapping, Sequence, TypedDict

from rclverify.model.plan.standards.profiles import Profile
from rclverify.records.report_schema import EvidenceRow

#: (evidence row field, its value) -> the profile evidence kind it supports.  ``kind`` is the
#: record's kind (each backend's ``kind``: hoare and dafny "proof", ajpf "model checking",
#: property_tests "testing", monitors "monitoring", experiment, review); ``strength`` is the
#: strength the confidence pass gave the row ("statistical": a bound over recorded runs).
SUPPORTS: Mapping[tuple[str, str], str] = {
    ("kind", "proof"): "proof",
    ("kind", "model checking"): "model-checking",
    ("kind", "testing"): "property-tests",
    ("kind", "monitoring"): "runtime-monitoring",
    ("kind", "experiment"): "experiment",
    ("kind", "review"): "review",
    ("strength", "statistical"): "run-statistics",
}

#: A clause's status: all its supporting evidence discharged, some of it not, none.
CLAUSE_STATUSES: tuple[str, ...] = ("covered", "partial", "open")


class Support(TypedDict):
    """An evidence row that supports a clause, as the clause row shows it."""
    obligation: str
    backend: str
    kind: str
    status: str


class ClauseRow(TypedDict):
    """One clause of a profile at the chosen level, with its supporting evidence."""
    id: str
    title: str
    recommendation: str
    accepts: list[str]
    strength: str
    evidence: list[Support]
    status: str


def kinds_of(row: EvidenceRow) -> set[str]:
    """The profile evidence kinds the evidence ``row`` (a report ``evidence[]`` row) supports, by :data:`SUPPORTS`."""
    strength = row.get("strength")
    values = {"kind": row.get("kind"), "strength": strength.get("kind") if isinstance(strength, Mapping) else None}
    return {kind for (field, value), kind in SUPPORTS.items() if values[field] == value}


def clause_rows(profile: Profile, level: str | None, evidence: Sequence[EvidenceRow]) -> list[ClauseRow]:
    """The clause rows of ``profile`` at ``level`` (``None`` for a profile
    without levels) over the report's ``evidence`` rows (each with
    ``obligation``, ``backend``, ``kind``, ``status`` and optionally
    ``strength``), in the profile's order.  Pure: reads nothing else,
    raises nothing for well-formed rows."""
    kinds = [kinds_of(r) for r in evidence]
    out: list[ClauseRow] = []
    for item in profile.items:
        accepted = set(item.evidence)
        support: list[Support] = [
            {"obligation": str(r["obligation"]), "backend": str(r["backend"]), "kind": str(r["kind"]),
             "status": str(r["status"])} for r, k in zip(evidence, kinds) if k & accepted]
        status = ("covered" if support and all(s["status"] == "discharged" for s in support)
                  else "partial" if support else "open")
        out.append({"id": item.id, "title": item.title, "recommendation": item.at(level),
                    "accepts": list(item.evidence), "strength": item.strength, "evidence": support,
                    "status": status})
    return out


def not_covered(rows: Sequence[ClauseRow], code: str = "HR") -> list[str]:
    """The ids of the clause rows recommended ``code`` that are not ``covered`` (the ``--strict`` reading)."""
    return [r["id"] for r in rows if r["recommendation"] == code and r["status"] != "covered"]


__all__ = ["CLAUSE_STATUSES", "ClauseRow", "SUPPORTS", "Support", "clause_rows", "kinds_of", "not_covered"]
