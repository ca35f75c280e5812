"""A requirement's row of the report, defined once: :class:`RequirementRow`.

The report's ``requirements[]`` holds one row per requirement of the plan
(and of its ``requirements_from`` documents), in plan order: the guarantees
it is traced to with their statuses (:class:`SupportRow`), what the Z3 check
of its formal statement decided rolled up with that evidence (``verdict``,
``status``: only ``met`` is ``discharged``; records/statuses.py, "Verdict and
status"), its check record, and what later passes of the report give it: its
end-to-end deadline (rule D3, report/deadlines.py), its statistical target's
rows (report/statistics.py), its confidence and the strength it asks of its
evidence (report/confidence_rows.py, docs/confidence.md).

The rules (docs/decisions.md, "One definition per record"):

* This class is the only statement of the row's fields.  report/requirement_rows.py
  builds it and writes :meth:`RequirementRow.to_json`: every field, in the
  order declared, at its default when there is nothing to say (``null``,
  ``[]``), so that a key is never present in one run and absent in the next;
  a later pass gives a field its value by replacing that key.  A reader
  decodes the JSON object with :meth:`RequirementRow.of`; a key the class
  does not declare, or a value of another type, raises
  :class:`msgspec.ValidationError`.
* The ``requirements[]`` items of docs/assurance.schema.json are generated
  from it (records/schema_gen.py), but for ``check``: the requirements
  stage's record (calculus/requirements/check.py) whose inner shape belongs
  to that stage, described by hand in the file (records/schema_gen.py ``KEPT``).
  tests/records/test_record_shapes.py fails when the file and the class differ.
* Every field is read by a renderer of the requirements (the requirement
  tables and the list of requirements checked with Z3 in
  report/templates/assurance.{html,md}.j2, which decode the rows with the
  ``requirement_rows`` filter) or named in :data:`INTERNAL` with the reason
  it is not shown; tests/records/test_record_shapes.py fails otherwise.
"""
from __future__ import annotations

from typing import Annotated, Any, Iterable, Literal, Mapping

import msgspec

from rclverify.records.deadline_rows import DeadlineRow
from rclverify.records.strength_rows import LimitedBy
from rclverify.records.statistics_rows import RequirementRuns
from rclverify.records.row import DOC
from rclverify.records.shared_rows import ItemRow
from rclverify.records.statuses import EvidenceStatus, RequirementVerdict

_DOC = DOC  # a field's description, as the generated JSON Schema shows it

#: The strengths of evidence, strongest first (docs/confidence.md; the plan's ``strength:`` words).
StrengthKind = Literal["proof", "bounded", "statistical", "tested", "observed", "reviewed", "assumed"]


class SupportRow(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """A guarantee a requirement is traced to."""

    node: Annotated[str, _DOC(description="The node's name as the contracts declare it.")]
    guarantee: Annotated[int, _DOC(ge=1, description="1-based guarantee index.")]
    text: Annotated[str, _DOC(description="The text as written (RCL for a contract clause, words for a "
                                          "requirement).")]
    source: Annotated[str, _DOC(description="file:line:col of the RCL or plan text (1-based line and column)")]
    status: Annotated[EvidenceStatus, _DOC(description="The guarantee's status.")]
    obligations: Annotated[list[str], _DOC(description="Its obligations' ids.")]


class WithoutDeadline(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """A requirement's verdict before its end-to-end deadline was folded in."""

    verdict: Annotated[RequirementVerdict, _DOC(description="The verdict.")]
    status: Annotated[EvidenceStatus, _DOC(description="Its status.")]
    note: Annotated[str, _DOC(description="Why this verdict, in a sentence.")]


class RequirementRow(ItemRow, frozen=True, forbid_unknown_fields=True):
    """A requirement with its verdict, the guarantees it is traced to and its Z3 check."""

    text: Annotated[str, _DOC(description="The requirement in words.")]
    verdict: Annotated[RequirementVerdict, _DOC(description="What its check found, rolled up with its evidence.")]
    status: Annotated[EvidenceStatus, _DOC(description="Its evidence status: only met is discharged.")]
    note: Annotated[str, _DOC(description="Why this verdict, in a sentence.")]
    support: Annotated[list[SupportRow], _DOC(description="The guarantees it is traced to.")]
    check: Annotated[dict[str, Any], _DOC(
        description="Its Z3 check record (requirements/check.py): the formal statement, cone, premises used, "
                    "consistency, vacuity, counterexample, temporal verdict, declarations.")]
    deadline: Annotated[DeadlineRow | None, _DOC(
        description="Its end-to-end deadline (rule D3) when the plan gives one, else null; the requirement's "
                    "verdict includes it.")] = None
    without_deadline: Annotated[WithoutDeadline | None, _DOC(
        description="Its verdict before the deadline was folded in; null without a deadline.")] = None
    statistics: Annotated[list[RequirementRuns], _DOC(
        description="Its recorded runs by environment tag, decided against its statistical target when it "
                    "states one (docs/statistics.md); empty without recorded runs.")] = []
    confidence: Annotated[Annotated[float, _DOC(ge=0, le=1)] | None, _DOC(
        description="Confidence over the argument, 0 to 1 (docs/confidence.md); null for an informal "
                    "requirement.")] = None
    limited_by: Annotated[LimitedBy | None, _DOC(
        description="The weakest premise behind the confidence; null when there is none.")] = None
    required_strength: Annotated[StrengthKind | None, _DOC(
        description="The least strength the plan asks of the guarantees its proof uses (its `strength:`; "
                    "docs/confidence.md); null when the plan states none.")] = None
    strength_shortfall: Annotated[list[str], _DOC(
        description="The guarantees its proof uses whose evidence is weaker than required_strength, each with "
                    "its strength ('nothing discharged' when none); empty when none falls short. A shortfall "
                    "fails --strict.")] = []


def rows_of(rows: Iterable[RequirementRow | Mapping[str, Any]]) -> list[RequirementRow]:
    """The report's ``requirements[]`` (JSON objects) decoded, in order
    (:meth:`RequirementRow.of` for what raises)."""
    return [RequirementRow.of(r) for r in rows]


#: The fields of :class:`RequirementRow` no requirements renderer shows, each with the reason.
INTERNAL: dict[str, str] = {
    "support": "shown through the traceability rows the view builds from it (report/view.py): each "
               "guarantee with its obligations and their evidence",
    "deadline": "the deadline is shown in the report's end-to-end deadlines section (deadlines[]); its "
                "effect on the verdict is the note shown",
    "without_deadline": "for the argument (report/argument/deadlines.py) and the diagnoses; the note "
                        "shown says the verdict without the deadline",
    "statistics": "the statistical target's rows are shown in the report's statistics section "
                  "(statistics[])",
}


_DEADLINE = "a deadline is its own item: a SARIF result and a JUnit test case of its own (report/deadlines.py), the " \
            "report's end-to-end deadlines section; its effect on the verdict is the note shown"
_WITHOUT = "for the argument (report/argument/deadlines.py) and the diagnoses; the note shown says the verdict without " \
           "the deadline"
_RUNS = "the statistical target's rows are shown in the report's statistics section (statistics[])"
_STRENGTH = "what the plan asks of the evidence's strength and what falls short of it are shown in the HTML and " \
            "Markdown requirements list; a shortfall is also one of the summary's problems (report/confidence_rows.py)"
_CONFIDENCE = "a confidence over the argument, shown by the HTML and Markdown reports and JUnit's properties; this " \
              "output states the verdict and its check"

#: Per renderer written in Python (SARIF: report/sarif.py, JUnit: report/junit.py, ``rclverify explain``:
#: report/explain.py and explain_items.py), the fields of :class:`RequirementRow` it does not show, each with
#: the reason (tests/records/test_record_shapes.py holds each renderer to its table).
INTERNAL_TO: dict[str, dict[str, str]] = {
    "sarif": {
        "text": "a result is located at the requirement's formal statement (check.source), where its words are; "
                "the message says the verdict and the formal statement",
        "support": "a result is the requirement's; a guarantee it is traced to has results of its own when it fails",
        "deadline": _DEADLINE, "without_deadline": _WITHOUT, "statistics": _RUNS,
        "confidence": _CONFIDENCE, "limited_by": _CONFIDENCE,
        "required_strength": _STRENGTH, "strength_shortfall": _STRENGTH,
    },
    "junit": {
        "support": "each guarantee it is traced to is a test case of its node's suite",
        "deadline": _DEADLINE, "without_deadline": _WITHOUT, "statistics": _RUNS,
        "required_strength": _STRENGTH, "strength_shortfall": _STRENGTH,
    },
    "explain": {
        "deadline": _DEADLINE, "without_deadline": _WITHOUT, "statistics": _RUNS,
        "confidence": _CONFIDENCE, "limited_by": _CONFIDENCE,
        "required_strength": _STRENGTH, "strength_shortfall": _STRENGTH,
    },
}


__all__ = ["INTERNAL", "INTERNAL_TO", "RequirementRow", "StrengthKind", "SupportRow", "WithoutDeadline", "rows_of"]
