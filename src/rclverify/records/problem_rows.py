"""The report's diagnoses and its problems grouped by root cause, defined once: :class:`DiagnosisRow`,
:class:`ProblemRow` (with :class:`ProblemMember` and :class:`RepairRef`).

``diagnoses[]`` holds the diagnosis stage's records of the report
(artifacts/diagnosis/index.json, stages/diagnoses.py; made by diagnosis/,
docs/diagnosis.md): one problem explained, its culprits by source location,
its counterexample as a table, the repairs Z3 checked.  ``problems[]``
groups the report's problems by root cause, one row per culprit
(report/problems.py; docs/reading-the-report.md).

The rules (docs/decisions.md, "One definition per record"):

* These classes are the only statement of the rows' fields.  The diagnosis
  stage's sealed records are decoded into :class:`DiagnosisRow` when read
  (stages/diagnoses.py ``read_diagnoses``: a record that does not decode is
  malformed); report/problems.py decodes each grouped row into
  :class:`ProblemRow` and writes :meth:`~rclverify.records.row.Row.to_json`
  (the fields in the order declared).  A field whose default is ``UNSET``
  is absent from the JSON when the record has nothing to say.
* The culprits, counterexample rows and repairs of a diagnosis are
  records/repair_rows.py's :class:`~rclverify.records.repair_rows.DiagnosisCulprit`,
  :class:`~rclverify.records.repair_rows.CexTableRow` and
  :class:`~rclverify.records.repair_rows.RepairRow`; a problem row's culprits
  (report/problems_places.py ``culprit``) are left open here.
* The ``diagnoses`` and ``problems`` items of docs/assurance.schema.json
  are generated from them (records/schema_gen.py);
  tests/records/test_record_shapes.py fails when the file and the classes
  differ.
* Every field of :class:`ProblemRow` is read by the problems table's
  renderers (report/templates/assurance.{html,md}.j2, filter
  ``problem_rows``) or named in :data:`INTERNAL` with the reason it is not
  shown, and read by each renderer written in Python (``rclverify
  explain``) or named in its table of :data:`INTERNAL_TO` (SARIF and JUnit
  show no group, and say so there); tests/records/test_record_shapes.py
  fails otherwise.
"""
from __future__ import annotations

from typing import Annotated, Any, Iterable, Mapping

import msgspec

from rclverify.records.repair_rows import CexTableRow, DiagnosisCulprit, RepairRow
from rclverify.records.row import DOC, Row, decode_rows
from rclverify.records.shared_rows import ItemRow
from rclverify.records.statuses import AnyStatus

_DOC = DOC  # a field's description, as the generated JSON Schema shows it


class DiagnosisRow(ItemRow, frozen=True, forbid_unknown_fields=True, omit_defaults=True):
    """One diagnosis per problem, with repairs checked by Z3 (docs/diagnosis.md)."""

    kind: Annotated[str, _DOC(description="What kind of item it is.")]
    node: Annotated[str, _DOC(description="The node's name as the contracts declare it.")]
    status: Annotated[AnyStatus, _DOC(description="Its status.")]
    sentence: Annotated[str, _DOC(description="One sentence for a reader.")]
    culprits: Annotated[list[DiagnosisCulprit], _DOC(description="The items to repair.")]
    counterexample: Annotated[list[CexTableRow], _DOC(description="The counterexample, as rows a reader follows.")]
    repairs: Annotated[list[RepairRow], _DOC(description="Repairs, each checked by Z3 before it is offered.")]
    guarantee: Annotated[int | None, _DOC(description="1-based guarantee index, null when it concerns the whole "
                                                      "contract.")]
    related: Annotated[list[str], _DOC(description="Other problems it relates to.")]
    not_offered: Annotated[list[str] | msgspec.UnsetType, _DOC(
        description="The repairs Z3 showed do not work (a side condition's), one sentence each.")] = msgspec.UNSET
    joins: Annotated[list[str] | msgspec.UnsetType, _DOC(
        description="A unit mismatch's: the ids of the findings it explains.")] = msgspec.UNSET
    lint: Annotated[str | msgspec.UnsetType, _DOC(
        description="A unit mismatch's: the location of its lint diagnostic (file:line:col).")] = msgspec.UNSET
    passes_through: Annotated[list[str] | msgspec.UnsetType, _DOC(
        description="A refuted requirement's: the failed side conditions its counterexample passes "
                    "through.")] = msgspec.UNSET
    consequence_of: Annotated[list[str] | msgspec.UnsetType, _DOC(
        description="A requirement refuted only because of failed side conditions: their ids.")] = msgspec.UNSET
    requirement: Annotated[str | msgspec.UnsetType, _DOC(
        description="A deadline's: the requirement whose deadline it is.")] = msgspec.UNSET


class ProblemMember(ItemRow, frozen=True, forbid_unknown_fields=True, omit_defaults=True):
    """An item of a problem row."""

    kind: Annotated[str, _DOC(description="What it is: evidence, side-condition, requirement, deadline, lint, ...")]
    status: Annotated[AnyStatus, _DOC(description="The item's own status word.")]
    sentence: Annotated[str, _DOC(description="One sentence for a reader.")]
    anchor: Annotated[str, _DOC(description="Its anchor in the HTML report.")]
    diagnosis: Annotated[bool, _DOC(description="Whether a diagnosis explains it.")]
    consequence_of: Annotated[list[str] | msgspec.UnsetType, _DOC(
        description="Ids of the items whose failure this one follows from (it is listed under their row "
                    "too).")] = msgspec.UNSET


class RepairRef(Row, frozen=True, forbid_unknown_fields=True):
    """A repair by reference."""

    diagnosis: Annotated[str, _DOC(description="The diagnosis's id.")]
    index: Annotated[int, _DOC(description="0-based index into the diagnosis's repairs.")]


class ProblemRow(Row, frozen=True, forbid_unknown_fields=True):
    """Problems grouped by root cause: one row per culprit (docs/reading-the-report.md)."""

    key: Annotated[list[str], _DOC(description="The culprits' keys, e.g. guarantee:Node:1.")]
    status: Annotated[AnyStatus, _DOC(description="Worst status of its members (each keeps its item's own word).")]
    sentence: Annotated[str, _DOC(description="One sentence for a reader.")]
    culprits: Annotated[list[dict[str, Any]], _DOC(description="The contract items to repair.")]
    members: Annotated[list[ProblemMember], _DOC(description="The problems it explains.")]
    repairs: Annotated[list[RepairRef], _DOC(description="Repairs checked by Z3, pointing into diagnoses.")]
    where: Annotated[str, _DOC(description="file:line:col of the RCL or plan text (1-based line and column)")]


#: The fields of :class:`ProblemRow` no problems-table renderer shows, each with the reason.
INTERNAL: dict[str, str] = {
    "key": "the culprits' keys, by which the dashboard and the system diagram mark culprit nodes and a row is "
           "matched across runs; the row shows the culprits themselves",
}


#: For each renderer written in Python rather than a template (``sarif``: report/sarif.py, ``junit``:
#: report/junit.py, ``explain``: report/explain.py), the fields of :class:`ProblemRow` it does not show, each
#: with the reason (``"*"``: it shows no problem row at all, so none of its fields); every other field it reads
#: off the decoded row (tests/records/test_record_shapes.py).
INTERNAL_TO: dict[str, dict[str, str]] = {
    "sarif": {"*": "a SARIF result is one item (an obligation, a side condition, a check) at its own place, "
                   "not a group of them; each result carries the diagnosis that names its culprit"},
    "junit": {"*": "a JUnit test case is one item (an obligation, a side condition, a check), not a group of "
                   "them; the problems are the failing cases"},
    "explain": {"key": INTERNAL["key"]},
}


#: Keys a report written before they existed lacks, with the value such a row is read with: a stored
#: report of an earlier version still renders (its rows placed nowhere).
EARLIER: dict[str, Any] = {"where": ""}


def rows_of(rows: Iterable[ProblemRow | Mapping[str, Any]]) -> list[ProblemRow]:
    """The report's ``problems[]`` (JSON objects, or records already decoded: returned as they are) decoded, in order, a key of :data:`EARLIER` a row lacks
    read as its value there (:meth:`ProblemRow.of` for what raises)."""
    return decode_rows(ProblemRow, (r if isinstance(r, ProblemRow) else {**EARLIER, **r} for r in rows))


__all__ = ["DiagnosisRow", "EARLIER", "INTERNAL", "INTERNAL_TO", "ProblemMember", "ProblemRow", "RepairRef", "rows_of"]
