"""The report's rows of the contract and plan texts' diagnostics and the plan's acknowledgements, defined
once: :class:`LintRow` and :class:`AcknowledgementRow`.

``lint[]`` holds the diagnostics of ``rclverify check``
(artifacts/check/diagnostics.json, report/finding_rows.py), a warning
marked with the text it flags and the plan's answer to it;
``acknowledgements[]`` holds one row per ``acknowledged:`` entry of the plan
with its status (model/plan/acknowledged.py; docs/plan.md, "Acknowledged
warnings").

The rules (docs/decisions.md, "One definition per record"):

* These classes are the only statement of the rows' fields.
  report/finding_rows.py decodes each marked row into its class and writes
  :meth:`~rclverify.records.row.Row.to_json` (the fields in the order
  declared); a lint row's ``flagged``, ``sha256`` and ``acknowledged`` are
  absent from a diagnostic that is no warning, or that no acknowledgement
  answers (``UNSET``, left out of the JSON).
* The ``lint`` and ``acknowledgements`` items of docs/assurance.schema.json
  are generated from them (records/schema_gen.py);
  tests/records/test_record_shapes.py fails when the file and the classes
  differ.
* Every field of :class:`LintRow` is read by the lint table's renderers
  (report/templates/assurance.{html,md}.j2, which decode each row with the
  ``lint_rows`` filter) or named in :data:`INTERNAL` with the reason it is
  not shown; tests/records/test_record_shapes.py fails otherwise.
"""
from __future__ import annotations

from typing import Annotated

import msgspec

from rclverify.records.findings import Acknowledged
from rclverify.records.row import DOC, Row
from rclverify.records.statuses import AcknowledgementStatus, LintSeverity

_DOC = DOC  # a field's description, as the generated JSON Schema shows it


class LintRow(Row, frozen=True, forbid_unknown_fields=True, omit_defaults=True):
    """A diagnostic of the contract or plan text."""

    severity: Annotated[LintSeverity, _DOC(description="error or warning.")]
    location: Annotated[str, _DOC(description="file:line:col of the RCL or plan text (1-based line and column)")]
    message: Annotated[str, _DOC(description="The problem or outcome in one sentence.")]
    code: Annotated[str, _DOC(description="The diagnostic's code (E-..., W-...).")]
    flagged: Annotated[str | msgspec.UnsetType, _DOC(
        description="The flagged text (what an acknowledgement binds).")] = msgspec.UNSET
    sha256: Annotated[str | msgspec.UnsetType, _DOC(description="The digest of the flagged text.")] = msgspec.UNSET
    acknowledged: Annotated[Acknowledged | msgspec.UnsetType, _DOC(
        description="The acknowledgement that answers it.")] = msgspec.UNSET


class AcknowledgementRow(Row, frozen=True, forbid_unknown_fields=True):
    """A plan acknowledgement of a warning (docs/plan.md)."""

    warning: Annotated[str, _DOC(description="The warning it names (a health finding id or a lint code).")]
    reason: Annotated[str, _DOC(description="Why, in one sentence.")]
    at: Annotated[str, _DOC(description="file:line:col of the RCL or plan text (1-based line and column)")]
    status: Annotated[AcknowledgementStatus, _DOC(description="Its status.")]
    message: Annotated[str, _DOC(description="The problem or outcome in one sentence.")]
    matched: Annotated[list[str], _DOC(description="The warnings it acknowledges.")]


#: The fields of :class:`LintRow` no lint-table renderer shows, each with the reason.
INTERNAL: dict[str, str] = {
    "flagged": "the text an acknowledgement binds; the row shows its sha256, to acknowledge it by, and the "
               "diagnostic's own message",
}


__all__ = ["AcknowledgementRow", "INTERNAL", "LintRow"]
