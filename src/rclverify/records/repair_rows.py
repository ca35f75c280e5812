"""A diagnosis's culprits, counterexample rows and repairs, defined once: :class:`DiagnosisCulprit`,
:class:`CexTableRow` (with :class:`FunctionTableRow`), :class:`RepairRow` (with :class:`EditRow`,
:class:`RepairCheck`, :class:`RepairCost`).

The diagnosis stage's producers build these parts as JSON objects of the
shapes records/stage_records.py types (``Culprit``, ``CexRow``, ``Repair``,
``EditJson``); a diagnosis read back (stages/diagnoses.py ``read_diagnoses``)
or a stored report is decoded into :class:`~rclverify.records.problem_rows.DiagnosisRow`,
whose ``culprits``, ``counterexample`` and ``repairs`` are these records, so
that the readers (``rclverify explain`` and ``repair``, the diagnoses'
templates, SARIF, the problems table) read attributes mypy checks.  Each
part refuses a key it does not declare; the report writes its keys sorted,
so the order of the fields is that of the producers for the reader only.
"""
from __future__ import annotations

from typing import Annotated

import msgspec

from rclverify.records.row import DOC, Row


class DiagnosisCulprit(Row, frozen=True, forbid_unknown_fields=True):
    """What a diagnosis names to repair (diagnosis/build.py and the other producers)."""

    what: Annotated[str, DOC(description="The culprit in words.")]
    source: Annotated[str, DOC(description="Where it is written: file:line:col (1-based), or '' when nowhere.")]
    text: Annotated[str, DOC(description="Its text as written ('' when it has none of its own).")] = ""


class FunctionTableRow(Row, frozen=True, forbid_unknown_fields=True):
    """A function value's finite table (diagnosis/table.py ``function_table``)."""

    rows: Annotated[list[list[str]], DOC(description="The points shown, each [arguments, value].")]
    more: Annotated[int, DOC(description="How many points are left out.")]
    elsewhere: Annotated[str, DOC(description="The value at every other point.")] = msgspec.field(name="else")


class CexTableRow(Row, frozen=True, forbid_unknown_fields=True):
    """One symbol of a counterexample as a diagnosis shows it (diagnosis/table.py ``counterexample_table``)."""

    node: Annotated[str, DOC(description="The node the symbol belongs to (the diagnosis's node for a name without a node part).")]
    variable: Annotated[str, DOC(description="The symbol.")]
    value: Annotated[str, DOC(description="Its value in the counterexample, shortened for a reader.")]
    table: Annotated[FunctionTableRow | None, DOC(description="A function's finite table, null for a value.")]


class EditRow(Row, frozen=True, forbid_unknown_fields=True):
    """A repair's edit of one file (diagnosis/edits.py ``Edit.to_json``)."""

    file: Annotated[str, DOC(description="The file, relative to the workspace.")]
    line: Annotated[int, DOC(description="1-based line where the edited region starts.")]
    col: Annotated[int, DOC(description="1-based column where it starts.")]
    end_line: Annotated[int, DOC(description="1-based line where it ends.")]
    end_col: Annotated[int, DOC(description="1-based column where it ends (exclusive).")]
    inserted: Annotated[str, DOC(description="The text put in.")]
    deleted: Annotated[str, DOC(description="The text taken out (the region's text the edit was computed on).")]


class RepairCheck(Row, frozen=True, forbid_unknown_fields=True):
    """A check a repair was checked against, with its answer."""

    check: Annotated[str, DOC(description="The check's id.")]
    status: Annotated[str, DOC(description="Its answer on the edited text.")]


class RepairCost(Row, frozen=True, forbid_unknown_fields=True):
    """A check whose status a repair changes."""

    check: Annotated[str, DOC(description="The check's id.")]
    before: Annotated[str, DOC(description="Its status before the edit ('absent': the report did not have it).")]
    after: Annotated[str, DOC(description="Its status after the edit.")]


class RepairRow(Row, frozen=True, forbid_unknown_fields=True):
    """One repair checked before it is offered (diagnosis/repairs.py ``_record``; docs/diagnosis.md, "Repairs")."""

    kind: Annotated[str, DOC(description="What kind of edit it is.")]
    summary: Annotated[str, DOC(description="What to change and why, in one sentence.")]
    file: Annotated[str, DOC(description="The file it edits, relative to the workspace.")]
    edit: Annotated[EditRow, DOC(description="The edit.")]
    diff: Annotated[str, DOC(description="The edit as a unified diff.")]
    checks: Annotated[list[RepairCheck], DOC(description="The checks the edited text passed.")]
    cost: Annotated[list[RepairCost], DOC(description="The checks whose status the edit changes.")]
    proves: Annotated[str, DOC(description="What the check showed follows from the edited text.")]
    not_shown: Annotated[str, DOC(description="What it did not show (that the change is right for the robot).")]
    checked_by: Annotated[str, DOC(description="What checked it (Z3's version, the property tests, the monitors).")]
    sha256: Annotated[str, DOC(description="The hex sha256 of the file's text the edit was computed on "
                                           "(`rclverify repair --apply` writes the edit only over that text; '' in "
                                           "a report written before repairs recorded it: not applied).")] = ""


__all__ = ["CexTableRow", "DiagnosisCulprit", "EditRow", "FunctionTableRow", "RepairCheck", "RepairCost", "RepairRow"]
