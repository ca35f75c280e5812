"""An obligation's row of the report, defined once: :class:`ObligationRow`.

The report's ``obligations[]`` holds one row per obligation of the plan's
evidence entries: the exported obligation (records/records.py
:class:`~rclverify.records.records.Obligation`, its ``source`` as
``file:line:col``) with the *current* status of its evidence
(report/evidence_rows.py: ``stale`` when an input changed, ``pending``
without a record, ``error`` for an altered record, a proof the second
solver does not confirm downgraded).

The rules (docs/decisions.md, "One definition per record"):

* This class is the only statement of the row's fields.  The report pass
  builds it and writes :meth:`ObligationRow.to_json` (every field, in the
  order declared); a reader decodes the JSON object with
  :meth:`ObligationRow.of` (a key the class does not declare, or a value of
  another type, raises :class:`msgspec.ValidationError`).
* The ``obligations[]`` items of docs/assurance.schema.json are generated
  from it (records/schema_gen.py); tests/records/test_record_shapes.py fails when
  the file and the class differ.
* Every field is read by a renderer of the obligations table
  (report/templates/parts/obligations.{html,md}.j2, which decode each row
  with the ``obligation_row`` filter) or named in :data:`INTERNAL` with the
  reason it is not shown, and read by each renderer written in Python
  (SARIF, JUnit, ``rclverify explain``) or named in its table of
  :data:`INTERNAL_TO`; tests/records/test_record_shapes.py fails otherwise.
"""
from __future__ import annotations

from typing import Annotated, Any, Iterable, Mapping

from rclverify.records.row import DOC, Row, decode_rows
from rclverify.records.statuses import EvidenceKind, EvidenceStatus

_DOC = DOC


class ObligationRow(Row, frozen=True, forbid_unknown_fields=True):
    """An obligation: what one backend must establish about one guarantee."""

    id: Annotated[str, _DOC(description="Stable id <node>.g<k>.<backend>[.<instance>].")]
    node: Annotated[str, _DOC(description="The node's name as the contracts declare it.")]
    guarantee: Annotated[int, _DOC(ge=0, description="1-based guarantee index; 0: the whole contract.")]
    backend: Annotated[str, _DOC(description="The backend that discharges the obligation (hoare, dafny, ajpf, "
                                             "property_tests, monitors, experiment, review, ...).")]
    kind: Annotated[EvidenceKind, _DOC(description="The kind of evidence it asks for.")]
    instance: Annotated[str, _DOC(description="The part of the guarantee the obligation covers (a conjunct, a "
                                              "waypoint instance), empty for all of it.")]
    statement: Annotated[str, _DOC(description="What must be established, RCL text.")]
    source: Annotated[str, _DOC(description="file:line:col of the RCL or plan text (1-based line and column)")]
    artifact: Annotated[str, _DOC(description="The file it was rendered to.")]
    status: Annotated[EvidenceStatus, _DOC(description="Its evidence's current status (stale when an input "
                                                       "changed; pending without a record).")]


def rows_of(rows: Iterable[ObligationRow | Mapping[str, Any]]) -> list[ObligationRow]:
    """The report's ``obligations[]`` (JSON objects, or records already decoded: returned as they are) decoded, in order
    (:meth:`ObligationRow.of` for what raises)."""
    return decode_rows(ObligationRow, rows)


#: The fields of :class:`ObligationRow` no obligations-table renderer shows, each with the reason.
INTERNAL: dict[str, str] = {}


#: For each renderer written in Python rather than a template (``sarif``: report/sarif.py, ``junit``:
#: report/junit.py, ``explain``: report/explain.py), the fields of :class:`ObligationRow` it does not show,
#: each with the reason; every other field it reads off the decoded row (tests/records/test_record_shapes.py).
INTERNAL_TO: dict[str, dict[str, str]] = {
    "sarif": {},
    "junit": {
        "node": "the test suite is the node's, named after it",
        "instance": "the last part of the obligation's id, which is the test case's name",
    },
    "explain": {},
}


__all__ = ["INTERNAL", "INTERNAL_TO", "ObligationRow", "rows_of"]
