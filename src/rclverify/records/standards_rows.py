"""A chosen standard's row of the report, defined once: :class:`StandardRow` and its clause rows.

The report's ``standards[]`` holds one row per ``standards:`` entry of the
plan (report/standards_rows.py): the profile, where it comes from
(:class:`ProfileOrigin`), each clause at the chosen level with its scope,
the evidence in it, who checked it, its status and why
(:class:`ClauseRow`, built by model/plan/standards/mapping.py, a row of the
compliance matrix), the clauses the profile leaves out and the counts
(docs/standards.md).  The mapping is a traceability aid, not a compliance
claim.

The rules (docs/decisions.md, "One definition per record"): these classes
are the only statement of the rows' fields; the standards pass builds the
row and checks it by decoding (:meth:`StandardRow.of`: a key no field
declares, or a value of another type, raises
:class:`msgspec.ValidationError`), then writes :meth:`StandardRow.to_json`
(every field, in the order declared); the ``standards`` items of
docs/assurance.schema.json are generated from it (records/schema_gen.py);
every field of a standard's row is read by the standards renderers
(report/templates/parts/standards.{html,md}.j2, which decode the rows with
the ``standard_rows`` filter) or named in :data:`INTERNAL`;
tests/records/test_record_shapes.py fails otherwise.
"""
from __future__ import annotations

from typing import Annotated, Any, Iterable, Literal, Mapping

import msgspec

from rclverify.records.row import DOC, Row
from rclverify.records.statuses import EvidenceKind, EvidenceStatus

_DOC = DOC  # a field's description, as the generated JSON Schema shows it

#: A recommendation code (model/plan/standards/profiles.py ``CODES``).
Recommendation = Literal["HR", "R", "---", "NR", "required"]
#: What a clause is about (profiles.py ``ABOUT``).
About = Literal["guarantees", "interfaces", "requirements", "system", "field-data", "trials"]
#: An independence level (profiles.py ``INDEPENDENCE``).
Independence = Literal["none", "person", "department", "organisation"]
#: The sort of an item in a clause's scope.
ScopeKind = Literal["guarantee", "side condition", "requirement", "target", "health check", "workspace"]
#: A clause's status, in the order the report counts them.
ClauseStatus = Literal["covered", "partial", "not covered", "open", "not recommended"]


class ClauseEvidence(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """An evidence row of an accepted kind in a clause's scope."""

    obligation: Annotated[str, _DOC(description="The obligation the evidence row is of.")]
    backend: Annotated[str, _DOC(description="The backend that produced it.")]
    kind: Annotated[EvidenceKind, _DOC(description="The evidence row's kind.")]
    status: Annotated[EvidenceStatus, _DOC(description="The evidence row's current status.")]
    counts: Annotated[bool, _DOC(description="Whether the row may cover the clause (false: shown, never "
                                             "counted).")]
    note: Annotated[str, _DOC(description="Why the row does not count (a harness run, a review without the "
                                          "independence asked), or empty.")]


class ScopeItem(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """One item of a clause's scope, with its state."""

    item: Annotated[str, _DOC(description="What the item is: a guarantee (Node gK), a side condition, a "
                                          "requirement, a target, a health check, the workspace.")]
    kind: Annotated[ScopeKind, _DOC(description="The item's sort.")]
    covered: Annotated[bool, _DOC(description="Whether evidence of an accepted kind covers it.")]
    state: Annotated[str, _DOC(description="covered, or in a word what keeps it from being covered (a status, "
                                           "no evidence, not counted).")]
    detail: Annotated[str, _DOC(description="The state as a sentence.")]
    evidence: Annotated[list[str], _DOC(description="What covers it: obligations, side conditions or "
                                                    "requirement checks.")]


class PlanNote(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """What the plan says of a clause (``standards[].clauses``)."""

    nodes: Annotated[list[str] | None, _DOC(description="The nodes the plan narrows the clause's scope to; "
                                                        "null: not narrowed.")]
    reason: Annotated[str, _DOC(description="Why the plan narrows the scope (empty when it does not).")]
    justification: Annotated[str, _DOC(description="The plan's justification for the clause, or why it does not "
                                                   "apply (empty: none).")]
    at: Annotated[str, _DOC(description="Where the plan says it, file:line:col.")]


class ClauseRow(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """One clause or technique of a standard profile at the chosen level: a row of the compliance matrix."""

    id: Annotated[str, _DOC(description="The clause or table-and-item id in the profile (docs/standards.md).")]
    title: Annotated[str, _DOC(description="What the clause asks, in the profile's own words (never the "
                                           "standard's text).")]
    recommendation: Annotated[Recommendation, _DOC(
        description="The recommendation at the chosen level: highly recommended, recommended, none, not "
                    "recommended; required for a standard that does not grade HR/R.")]
    accepts: Annotated[list[str], _DOC(description="The evidence kinds that can support the clause.")]
    strength: Annotated[str, _DOC(description="The least evidence strength the clause asks (docs/confidence.md's "
                                              "words).")]
    about: Annotated[About, _DOC(description="What the clause concerns: its scope in the workspace "
                                             "(docs/standards.md, Scope).")]
    independence: Annotated[Independence, _DOC(description="The independence from the author a review needs to "
                                                           "count for the clause.")]
    evidence: Annotated[list[ClauseEvidence], _DOC(
        description="The evidence rows of an accepted kind in the clause's scope, each saying whether it counts.")]
    scope: Annotated[list[ScopeItem], _DOC(description="The items the clause concerns in this workspace, each "
                                                       "with its state.")]
    covered_by: Annotated[list[str], _DOC(description="What covers the clause's covered items.")]
    checked_by: Annotated[list[str], _DOC(
        description="Who checked what covers the clause: each backend with its tool and version, each review's "
                    "reviewer and author, Z3.")]
    status: Annotated[ClauseStatus, _DOC(
        description="covered: every item in scope covered (never a clause the tool does not cover alone); "
                    "partial: some, or all of a clause that asks more than rclverify's evidence (its why says "
                    "what the safety case must add); not covered: none; open: no evidence of an accepted kind in "
                    "scope; not recommended: NR at this level.")]
    why: Annotated[str, _DOC(description="Why the clause has its status, with the items in scope counted by "
                                         "state.")]
    plan: Annotated[PlanNote | None, _DOC(
        description="What the plan says of the clause (standards[].clauses): a narrowed scope with its reason, "
                    "a justification; null when it says nothing.")]


class ProfileOrigin(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """Where the profile comes from: one of rclverify's built-in profiles, or a file of the workspace
    (docs/standards.md)."""

    kind: Annotated[Literal["built-in", "workspace"], _DOC(
        description="built-in: one of rclverify's profiles; workspace: the plan's own file.")]
    file: Annotated[str, _DOC(description="The profile's file: package-relative for a built-in one, "
                                          "workspace-relative otherwise.")]
    sha256: Annotated[str, _DOC(description="The hex sha256 of the profile file's bytes.")]
    edition: Annotated[str, _DOC(description="The standard and edition the profile names.")]


class LeftOut(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """A clause of the standard the profile does not list, and why."""

    id: Annotated[str, _DOC(description="The clause, item or table left out.")]
    why: Annotated[str, _DOC(description="Why the profile leaves it out.")]


class StandardRow(Row, frozen=True, forbid_unknown_fields=True):
    """A standard the plan names (standards:), its clauses and the evidence mapped onto them: a traceability
    aid, not a compliance claim."""

    profile: Annotated[str, _DOC(description="The profile's id (a built-in one, or the plan's own file: origin "
                                             "says which).")]
    title: Annotated[str, _DOC(description="The profile's title.")]
    edition: Annotated[str, _DOC(description="The standard and edition the profile's ids come from.")]
    level_name: Annotated[str, _DOC(description="What the level is called (sil, dal, pl, level).")]
    level: Annotated[str | None, _DOC(description="The chosen level; null for a profile without levels.")]
    source: Annotated[str, _DOC(description="Where the plan chose the standard, file:line:col.")]
    origin: Annotated[ProfileOrigin, _DOC(description="Where the profile comes from.")]
    clauses: Annotated[list[ClauseRow], _DOC(description="Every clause of the profile, in its order.")]
    left_out: Annotated[list[LeftOut], _DOC(description="The standard's clauses the profile does not list, and "
                                                        "why.")]
    open: Annotated[list[str], _DOC(description="The ids of the clauses with no evidence of an accepted kind in "
                                                "scope.")]
    counts: Annotated[dict[str, int], _DOC(description="How many clauses have each status (covered, partial, not "
                                                       "covered, open, not recommended).")]
    required_not_covered: Annotated[list[str], _DOC(
        description="The clauses asked at the chosen level (HR, or required for a standard that does not grade "
                    "HR/R) that are not covered; --strict fails while any is left when the standard is chosen "
                    "with strict: true.")]
    strict: Annotated[bool, _DOC(description="Chosen with strict: true: --strict requires every clause asked at "
                                             "the level covered.")]


def rows_of(rows: Iterable[StandardRow | Mapping[str, Any]]) -> list[StandardRow]:
    """The report's ``standards[]`` (JSON objects) decoded, in order
    (:meth:`StandardRow.of` for what raises)."""
    return [StandardRow.of(r) for r in rows]


#: The fields of :class:`StandardRow` no standards renderer shows, each with the reason.
INTERNAL: dict[str, str] = {
    "open": "the clauses it lists are shown in the clause table, each with its status open",
}


#: The fields of :class:`StandardRow` the standards exports (report/standards_sheets.py, the CSV and XLSX
#: compliance matrix with its header; report/standards_export.py, the gaps) do not show, each with the reason.
EXPORTS_INTERNAL: dict[str, str] = {
    "title": "a standard is named by its edition and profile in each row; its title heads the report's section",
    "source": "where the plan names the standard; the export's header names the plan file with its sha256",
    "left_out": "a clause the profile does not list is no row of the matrix; the report lists each with why",
    "open": "each open clause is a row of the matrix with its status open",
    "strict": "whether --strict gates on the standard: the gate's, not a column an assessor decides on",
}
#: The fields of :class:`ClauseRow` the compliance matrix does not show, each with the reason.
CLAUSE_EXPORTS_INTERNAL: dict[str, str] = {
    "strength": "the least strength the clause asks is shown in the report's clause table; the matrix gives the "
                "state of each item in scope and the clause's status and why",
    "evidence": "each covering record is shown once, in 'evidence that covers it' (with its sha256 and start), "
                "and each item's state in 'items in scope and their state'",
}


__all__ = ["About", "CLAUSE_EXPORTS_INTERNAL", "ClauseEvidence", "ClauseRow", "ClauseStatus", "EXPORTS_INTERNAL",
           "INTERNAL", "Independence", "LeftOut",
           "PlanNote", "ProfileOrigin", "Recommendation", "ScopeItem", "ScopeKind", "StandardRow", "rows_of"]
