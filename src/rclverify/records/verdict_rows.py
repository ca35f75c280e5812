"""The report's rows of obligations not yet decided and of the verdicts the plan expects, defined once:
:class:`PendingRow` and :class:`ExpectedVerdictRow`.

``pending[]`` holds one row per obligation without a decided evidence
record (report/evidence_rows.py); ``expected_verdicts[]`` one row per
``expected:`` entry of the plan against the obligation it names
(report/expected.py, model/plan/expected.py).

The rules (docs/decisions.md, "One definition per record"): these classes
are the only statement of the rows' fields; the report's passes build them
and write :meth:`~rclverify.records.row.Row.to_json` (every field, in the
order declared); the ``pending`` and ``expected_verdicts`` items of
docs/assurance.schema.json are generated from them (records/schema_gen.py);
tests/records/test_record_shapes.py fails when the file and the classes
differ.  Every field of :class:`PendingRow` is read by the pending table's
renderers (report/templates/assurance.{html,md}.j2, which decode each row
with the ``pending_rows`` filter) or named in :data:`INTERNAL` with the
reason it is not shown; tests/records/test_record_shapes.py fails otherwise.
"""
from __future__ import annotations

from typing import Annotated

from rclverify.records.row import DOC, Row
from rclverify.records.statuses import EvidenceStatus

_DOC = DOC  # a field's description, as the generated JSON Schema shows it

_BACKEND = ("The backend that discharges the obligation (hoare, dafny, ajpf, property_tests, monitors, experiment, "
            "review, ...).")


class PendingRow(Row, frozen=True, forbid_unknown_fields=True):
    """An obligation without a decided record."""

    obligation: Annotated[str, _DOC(description="The obligation's id.")]
    backend: Annotated[str, _DOC(description=_BACKEND)]
    reason: Annotated[str, _DOC(description="Why, in one sentence.")]


class ExpectedVerdictRow(Row, frozen=True, forbid_unknown_fields=True):
    """A verdict the plan expects of an obligation, against the actual one."""

    node: Annotated[str, _DOC(description="The node's name as the contracts declare it.")]
    backend: Annotated[str, _DOC(description=_BACKEND)]
    source: Annotated[str, _DOC(description="file:line:col of the RCL or plan text (1-based line and column)")]
    obligation: Annotated[str | None, _DOC(description="The obligation's id.")]
    actual: Annotated[EvidenceStatus | None, _DOC(description="The obligation's status, null when none matches.")]
    guarantee: Annotated[int | None, _DOC(description="1-based guarantee index, null when it concerns the whole "
                                                      "contract.")]
    instance: Annotated[str | None, _DOC(description="The part of the guarantee the obligation covers (a "
                                                     "conjunct, a waypoint instance), empty for all of it.")]
    expected: Annotated[str | None, _DOC(description="The expected verdict (discharged or failed), null when "
                                                     "malformed.")]
    reason: Annotated[str, _DOC(description="Why, in one sentence.")]
    outcome: Annotated[str, _DOC(description="as expected, MISMATCH, not yet decided, no obligation matches, or "
                                             "why the expectation is invalid.")]


#: The fields of :class:`PendingRow` no pending-table renderer shows, each with the reason.
INTERNAL: dict[str, str] = {}


__all__ = ["ExpectedVerdictRow", "INTERNAL", "PendingRow"]
