"""An evidence record's row of the report, defined once: :class:`EvidenceRow`.

The report's ``evidence[]`` holds one row per obligation with an evidence
record (records/records.py :class:`~rclverify.records.records.Evidence`):
the record shown with its *current* status (report/evidence_rows.py:
``stale`` when an input changed, ``error`` for an altered record, a proof
the second solver does not confirm downgraded, the explanation then saying
why), the last 2000 characters of its log, what its backend asks the
report to show (figures, a plot, property-test examples, a monitored run,
the run counted) and its strength (report/assemble.py, docs/confidence.md).

The rules (docs/decisions.md, "One definition per record"):

* This class is the only statement of the row's fields.  The report pass
  builds it and writes :meth:`EvidenceRow.to_json`: every field, in the
  order declared, at its default when there is nothing to say (``[]``,
  ``""``, ``{}``, ``null``), so that a key is never present in one run and
  absent in the next.  A reader decodes the JSON object with
  :meth:`EvidenceRow.of`; a key the class does not declare, or a value of
  another type, raises :class:`msgspec.ValidationError`.
* The ``evidence[]`` items of docs/assurance.schema.json are generated from
  it (records/schema_gen.py), but for ``monitoring``: its inner shape
  belongs to the monitors backend (docs/monitors.md) and is described by
  hand in the file (records/schema_gen.py ``KEPT``).
  tests/records/test_record_shapes.py fails when the file and the class differ.
* Every field is read by a renderer of the evidence records
  (report/templates/parts/evidence.{html,md}.j2, which decode each row with
  the ``evidence_row`` filter) or named in :data:`INTERNAL` with the reason
  it is not shown; tests/records/test_record_shapes.py fails otherwise.
"""
from __future__ import annotations

from typing import Annotated, Any, Iterable, Mapping

from rclverify.records.row import DOC, Row, decode_rows
from rclverify.records.solvers_rows import Solvers
from rclverify.records.statuses import EvidenceKind, EvidenceStatus
from rclverify.records.strength_rows import Strength

_DOC = DOC


class EvidenceRow(Row, frozen=True, forbid_unknown_fields=True):
    """An evidence record as the report shows it."""

    obligation: Annotated[str, _DOC(description="The obligation's id.")]
    backend: Annotated[str, _DOC(description="The backend that discharges the obligation (hoare, dafny, ajpf, "
                                             "property_tests, monitors, experiment, review, ...).")]
    kind: Annotated[EvidenceKind, _DOC(description="What kind of item it is.")]
    status: Annotated[EvidenceStatus, _DOC(description="Its current status (never unverified).")]
    tool: Annotated[str, _DOC(description="The tool that produced the evidence.")]
    tool_version: Annotated[str, _DOC(description="Its version.")]
    started: Annotated[str, _DOC(description="When the tool started, ISO 8601.")]
    duration_s: Annotated[float, _DOC(ge=0, description="Seconds.")]
    explanation: Annotated[str, _DOC(description="What the tool found, in words.")]
    counterexample: Annotated[dict[str, Any] | None, _DOC(
        description="The counterexample in RCL terms, null when none.")]
    artifacts: Annotated[list[str], _DOC(description="Files it produced.")]
    log_excerpt: Annotated[str, _DOC(description="The last 2000 characters of its log.")]
    figures: Annotated[list[list[str]], _DOC(
        description="Rows the backend asks the report to show (experiment figures, review record): "
                    "[name, value] each, empty when none.")] = []
    plot_svg: Annotated[str, _DOC(description="An inline SVG plot, \"\" when none.")] = ""
    solvers: Annotated[Solvers | None, _DOC(
        description="The second solver's agreement (docs/second-solver.md), null when it was not asked.")] = None
    examples: Annotated[dict[str, Any], _DOC(
        description="Property tests: example counts, seed, replay command, facts, coverage; empty for "
                    "another backend.")] = {}
    monitoring: Annotated[dict[str, Any], _DOC(
        description="Monitors: the run's verdicts, violations and semantics (docs/monitors.md).")] = {}
    statistics: Annotated[dict[str, Any], _DOC(
        description="The run counted (docs/statistics.md), empty when not counted.")] = {}
    strength: Annotated[Strength | None, _DOC(
        description="How strong the evidence is (docs/confidence.md), null until the report rates it.")] = None


def rows_of(rows: Iterable[EvidenceRow | Mapping[str, Any]]) -> list[EvidenceRow]:
    """The report's ``evidence[]`` (JSON objects, or records already decoded: returned as they are) decoded, in order
    (:meth:`EvidenceRow.of` for what raises)."""
    return decode_rows(EvidenceRow, rows)


#: The fields of :class:`EvidenceRow` no evidence renderer shows, each with the reason.
INTERNAL: dict[str, str] = {
    "solvers": "the second solver's agreement, for tools reading the JSON; when it changes the row's status, "
               "the explanation the row shows says why",
}


__all__ = ["EvidenceRow", "INTERNAL", "rows_of"]
