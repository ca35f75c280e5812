"""The report's ``standards`` part: the evidence rows mapped onto the plan's standard profiles (docs/standards.md).

One row per ``standards:`` entry of the plan, each with its clause rows
(:func:`rclverify.model.plan.standards.mapping.clause_rows`: each clause's
scope, the evidence in it, who checked it, its status and why) over the
report once the confidence pass has given its evidence rows their
strength, where the profile comes from (``origin``: ``built-in`` with its
edition, or ``workspace`` with the file and its sha256) and the clauses
the profile leaves out.  A clause the standard asks at the chosen level
(``HR``, or ``required`` for a standard that does not grade) and not
covered is a sentence of the summary's problems; ``--strict`` fails on it
for a standard chosen with ``strict: true`` (:func:`strict_reason` names
them).  The mapping is a traceability aid, not a compliance claim.
"""
from __future__ import annotations

from typing import Any, Collection, Mapping, Sequence, TypedDict

import msgspec

from rclverify.records.report_record import AssuranceReport
from rclverify.model.plan.standards.choice import StandardChoice
from rclverify.model.plan.standards.mapping import CLAUSE_STATUSES, ClauseRow, clause_rows, not_covered
from rclverify.model.plan.standards.profiles import Profile
from rclverify.records.row import decode_rows
from rclverify.records.standards_rows import ProfileOrigin, StandardRow


#: A chosen standard's row (``standards[]``) as the report's JSON object: the encoding of
#: :class:`rclverify.records.standards_rows.StandardRow`, the one definition of its fields.
StandardJson = dict[str, Any]


class StandardsPart(TypedDict):
    """What the pass gives the report: the rows, one problem sentence per
    standard with an HR clause not covered, and whether none has one."""
    rows: list[StandardJson]
    problems: list[str]
    ok: bool


def profile_origin(p: Profile) -> ProfileOrigin:
    """Where the profile ``p`` comes from: ``built-in`` with its edition, or ``workspace`` with its file and sha256."""
    return ProfileOrigin(kind="built-in" if p.builtin else "workspace", file=p.file, sha256=p.sha256,
                         edition=p.edition)


def origin_text(origin: ProfileOrigin) -> str:
    """``origin`` as one phrase: ``built-in profile`` or ``workspace profile std/mine.yaml, sha256 <hex>``."""
    if origin.kind == "built-in":
        return "built-in profile"
    return f"workspace profile {origin.file}, sha256 {origin.sha256}"


def _label(row: StandardRow) -> str:
    level = f" {row.level_name.upper()} {row.level}" if row.level is not None else ""
    return f"{row.edition}{level}"


def standards_part(choices: Sequence[StandardChoice],
                   report: AssuranceReport | Mapping[str, Any] | Sequence[Mapping[str, Any]],
                   unstated: Collection[tuple[str, str]] = ()) -> StandardsPart:
    """The ``standards`` part of the plan's ``choices`` over ``report`` (the
    report so far, or its JSON object: its evidence rows with their strength, obligations,
    nodes, side conditions, requirements, findings, unverified guarantees,
    system and summary; a bare list of evidence rows reads as a report of
    those rows alone); ``unstated``: the (node, environment) of the run
    sets whose plan entry states no origin, never field data
    (:func:`~rclverify.model.plan.standards.field_data.unstated_origins`).  Each row is checked by decoding it into
    :class:`~rclverify.records.standards_rows.StandardRow` and written as
    its JSON object (every field).  Pure; raises
    :class:`msgspec.ValidationError` only for a row its definition does not
    admit (a bug of the mapping)."""
    rows: list[StandardJson] = []
    problems: list[str] = []
    ok = True
    # the mapping (model/plan/standards/) reads the report's JSON object
    rep: Mapping[str, Any] | Sequence[Mapping[str, Any]] = (
        msgspec.to_builtins(report) if isinstance(report, AssuranceReport) and choices
        else {} if isinstance(report, AssuranceReport) else report)
    for c in choices:
        clauses = clause_rows(c.profile, c.level, rep, c.clauses, unstated, c.people)
        missing = not_covered(clauses)
        record = StandardRow.of({
            "profile": c.profile.id, "title": c.profile.title, "edition": c.profile.edition,
            "level_name": c.profile.level_name, "level": c.level,
            "source": f"{c.loc.file}:{c.loc.line}:{c.loc.col}", "origin": profile_origin(c.profile),
            "clauses": clauses, "left_out": [{"id": i, "why": w} for i, w in c.profile.left_out],
            "open": [x["id"] for x in clauses if x["status"] == "open"],
            "counts": {s: sum(1 for x in clauses if x["status"] == s) for s in CLAUSE_STATUSES},
            "required_not_covered": missing, "strict": c.strict})
        rows.append(record.to_json())
        ok = ok and not (missing and c.strict)
        if missing:
            problems.append(_missing_sentence(record, [x for x in clauses if x["id"] in missing]))
    return {"rows": rows, "problems": problems, "ok": ok}


def _missing_sentence(row: StandardRow, missing: Sequence[ClauseRow]) -> str:
    """The summary's sentence for a standard's asked items not covered: each with
    its title and why (its clause row's ``why``), where the profile comes
    from, and where to read them."""
    items = "; ".join(f"{c['id']} {c['title'][:1].lower()}{c['title'][1:]} ({c['why']})" for c in missing)
    return (f"Standard {_label(row)} ({origin_text(row.origin)}): {len(missing)} {_asked(row)} "
            f"item{'s' if len(missing) != 1 else ''} not covered: {items}; the report's section Safety "
            f"standards lists each item's scope and records")


def _asked(row: StandardRow) -> str:
    """How the standard's asked items are called: highly recommended (a graded standard) or required."""
    codes = {c.recommendation for c in row.clauses if c.id in row.required_not_covered}
    return "highly recommended" if codes == {"HR"} else "required" if codes == {"required"} else "asked"


def strict_clauses(rows: Sequence[StandardRow]) -> list[str]:
    """Why the chosen standards fail ``--strict``: one clause per standard
    of ``rows`` (the report's ``standards``, decoded) chosen with ``strict:
    true`` naming its asked items (``HR`` or ``required``) not covered
    (empty when none)."""
    return [f"{_label(row)}: {_asked(row)} item{'s' if len(row.required_not_covered) != 1 else ''} not covered ("
            + ", ".join(row.required_not_covered) + ")" for row in rows if row.required_not_covered and row.strict]


def strict_reason(report: Mapping[str, Any]) -> list[str]:
    """:func:`strict_clauses` of ``report``'s ``standards`` (the report's JSON object, or a part of it
    holding ``standards``), decoded into :class:`~rclverify.records.standards_rows.StandardRow`."""
    return strict_clauses(decode_rows(StandardRow, report.get("standards") or ()))


__all__ = ["StandardJson", "StandardsPart", "origin_text", "profile_origin",
           "standards_part", "strict_clauses", "strict_reason"]
