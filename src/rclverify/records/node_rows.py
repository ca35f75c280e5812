"""A node's row of the report and a guarantee no obligation covers, defined
once: :class:`NodeRow` (with :class:`InputRow`, :class:`OutputRow`,
:class:`AssumptionRow`, :class:`GuaranteeRow`, :class:`CulpritOf`) and
:class:`UnverifiedRow`.

The report's ``nodes[]`` holds one row per node of the contracts, in
contract order (report/contract_rows.py ``node_part``): its ports with
their links, its assumptions (``environment`` when no node's guarantee
discharges one), its guarantees with their statuses (worst of their
obligations, ``unverified`` without one, ``failed`` when health found the
guarantee vacuous), its LaTeX and its status (worst of its guarantees and
side conditions).  Later passes add keys to the row they built: the
confidence pass a guarantee's ``strength`` and the node's ``confidence``
and ``limited_by`` (report/confidence_rows.py, docs/confidence.md), the
culprit pass ``culprit_of`` on a node or guarantee a problem row blames
(report/culprits.py; such an item never reads discharged while its problem stands).
``unverified[]`` holds a row per guarantee of ``nodes[]`` no obligation
covers (report/unverified.py).

The rules (docs/decisions.md, "One definition per record"):

* These classes are the only statement of the rows' fields.  The report
  passes build them and write :meth:`~rclverify.records.row.Row.to_json`; a
  field at ``UNSET`` (a later pass's, until it runs, or a culprit's mark on
  an item no problem blames) is not written.  A later pass adds its key to
  the JSON object only as a field declared here.  A reader decodes the
  JSON object with :meth:`~rclverify.records.row.Row.of`; a key no field
  declares, or a value of another type, raises
  :class:`msgspec.ValidationError`.
* The ``nodes[]`` and ``unverified[]`` items of docs/assurance.schema.json
  are generated from them, and ``$defs/culprit_of`` from
  :class:`CulpritOf` (records/schema_gen.py); tests/records/test_record_shapes.py
  fails when the file and the classes differ.
* Every field of :class:`NodeRow` is read by a node's renderers (its
  section of the calculus, report/templates/parts/section.{html,md}.j2, and
  the LaTeX appendix, parts/latex.{html,md}.j2, filter ``node_rows``), every
  field of :class:`GuaranteeRow` by the section's guarantees table (filter
  ``guarantee_rows``), every field of :class:`UnverifiedRow` by the
  unverified table's renderers (report/templates/assurance.{html,md}.j2,
  filter ``unverified_rows``), or is named in :data:`INTERNAL`,
  :data:`GUARANTEE_INTERNAL` or :data:`UNVERIFIED_INTERNAL` with the reason
  it is not shown; tests/records/test_record_shapes.py fails otherwise.
"""
from __future__ import annotations

from typing import Annotated, Literal

import msgspec

from rclverify.records.row import DOC, Row
from rclverify.records.statuses import EvidenceStatus
from rclverify.records.strength_rows import LimitedBy, Strength

_DOC = DOC

_NAME = "The name as the contracts declare it."
_NODE = "The node's name as the contracts declare it."
_TEXT = "The text as written (RCL for a contract clause, words for a requirement)."
_SOURCE = "file:line:col of the RCL or plan text (1-based line and column)"
_CULPRIT = "The problem rows this item is the culprit of: such an item never reads discharged while its problem stands."
#: a claim's confidence, 0 to 1 (docs/confidence.md, rules C3-C5)
Confidence = Annotated[float, _DOC(ge=0, le=1)]


class CulpritOf(Row, frozen=True, forbid_unknown_fields=True):
    """A problem this item is the culprit of."""

    status: Annotated[EvidenceStatus, _DOC(description="The problem row's status.")]
    sentence: Annotated[str, _DOC(description="The problem row's sentence.")]


class InputRow(Row, frozen=True, forbid_unknown_fields=True):
    """An input variable."""

    name: Annotated[str, _DOC(description=_NAME)]
    type: Annotated[str, _DOC(description="Its RCL type.")]
    producer: Annotated[str | None, _DOC(description="The linked output 'Node.var', null for an environment input.")]


class OutputRow(Row, frozen=True, forbid_unknown_fields=True):
    """An output variable."""

    name: Annotated[str, _DOC(description=_NAME)]
    type: Annotated[str, _DOC(description="The RCL type.")]
    consumers: Annotated[list[str], _DOC(description="The linked inputs 'Node.var'.")]


class AssumptionRow(Row, frozen=True, forbid_unknown_fields=True):
    """An assumption."""

    text: Annotated[str, _DOC(description=_TEXT)]
    source: Annotated[str, _DOC(description=_SOURCE)]
    environment: Annotated[bool, _DOC(description="Whether no node's guarantee discharges it (an environment "
                                                  "assumption).")]


class GuaranteeRow(Row, frozen=True, forbid_unknown_fields=True):
    """A guarantee of a node with its evidence status."""

    index: Annotated[int, _DOC(ge=1, description="1-based index of the guarantee in its contract.")]
    text: Annotated[str, _DOC(description="The guarantee's RCL text.")]
    source: Annotated[str, _DOC(description=_SOURCE)]
    status: Annotated[EvidenceStatus, _DOC(description="Worst of its obligations, unverified when none; failed "
                                                       "when health found it vacuous.")]
    obligations: Annotated[list[str], _DOC(description="Ids of the obligations that bear on it.")]
    strength: Annotated[Strength | msgspec.UnsetType, _DOC(
        description="Its strongest evidence's kind and doubt.")] = msgspec.UNSET
    culprit_of: Annotated[list[CulpritOf] | msgspec.UnsetType, _DOC(description=_CULPRIT)] = msgspec.UNSET


class NodeRow(Row, frozen=True, forbid_unknown_fields=True):
    """A node's contract and its status."""

    name: Annotated[str, _DOC(description=_NAME)]
    source: Annotated[str, _DOC(description=_SOURCE)]
    status: Annotated[EvidenceStatus, _DOC(description="Worst of its guarantees and side conditions.")]
    inputs: Annotated[list[InputRow], _DOC(description="Its inputs.")]
    outputs: Annotated[list[OutputRow], _DOC(description="Its outputs.")]
    assumptions: Annotated[list[AssumptionRow], _DOC(description="Its assumptions.")]
    guarantees: Annotated[list[GuaranteeRow], _DOC(description="Its guarantees, in contract order.")]
    latex: Annotated[str, _DOC(description="The contract typeset in LaTeX.")]
    confidence: Annotated[Confidence | msgspec.UnsetType, _DOC(
        description="Confidence over the argument, 0 to 1 (docs/confidence.md).")] = msgspec.UNSET
    limited_by: Annotated[LimitedBy | None | msgspec.UnsetType, _DOC(
        description="The weakest premise behind the confidence, null when nothing limits it.")] = msgspec.UNSET
    culprit_of: Annotated[list[CulpritOf] | msgspec.UnsetType, _DOC(description=_CULPRIT)] = msgspec.UNSET


class UnverifiedRow(Row, frozen=True, forbid_unknown_fields=True):
    """A guarantee no obligation covers."""

    id: Annotated[str, _DOC(description="Node.g<k>.")]
    node: Annotated[str, _DOC(description=_NODE)]
    guarantee: Annotated[int, _DOC(ge=1, description="1-based.")]
    text: Annotated[str, _DOC(description=_TEXT)]
    source: Annotated[str, _DOC(description=_SOURCE)]
    status: Annotated[Literal["unverified"], _DOC(description="Its status.")]
    reason: Annotated[str, _DOC(description="Why, in one sentence.")]
    message: Annotated[str, _DOC(description="The problem or outcome in one sentence.")]


#: The fields of :class:`NodeRow` no node renderer shows, each with the reason.
INTERNAL: dict[str, str] = {}

#: The fields of :class:`NodeRow` the LaTeX appendix (parts/latex.{html,md}.j2) does not show, each with the
#: reason: it typesets each node's contract (``latex``) under the node's name, and the node's section shows
#: the rest (tests/records/test_record_shapes.py holds the appendix to this table).
LATEX_INTERNAL: dict[str, str] = {k: f"the appendix typesets the contract alone; the node's section shows its {what}"
                                  for k, what in (("source", "source"), ("status", "status"), ("inputs", "inputs"),
                                                  ("outputs", "outputs"), ("assumptions", "assumptions"),
                                                  ("guarantees", "guarantees"), ("confidence", "confidence"),
                                                  ("limited_by", "weakest premise"),
                                                  ("culprit_of", "problems it is the culprit of"))}

_WHY_ROLLED_UP = "the worst of the node's guarantees and side conditions, each of which is an item of its own here"
_WHY_DECLARED = "the contract's declarations; an item is located at its own text in the contract (file:line:col), and " \
            "explain and the HTML and Markdown reports list them"
_WHY_TYPESET = "the contract typeset for the LaTeX appendix"
_WHY_CONFIDENCE = "a confidence over the argument, shown by the node's section of the HTML and Markdown reports"
_WHY_CULPRIT = "the problems it is the culprit of are the diagnoses, each with the item it explains; explain prints them"

#: Per renderer written in Python (SARIF: report/sarif.py, JUnit: report/junit.py, ``rclverify explain``:
#: report/explain.py and explain_items.py), the fields of :class:`NodeRow` it does not show, each with the
#: reason (tests/records/test_record_shapes.py holds each renderer to its table).
INTERNAL_TO: dict[str, dict[str, str]] = {
    "sarif": {"status": _WHY_ROLLED_UP, "inputs": _WHY_DECLARED, "outputs": _WHY_DECLARED,
              "assumptions": _WHY_DECLARED, "latex": _WHY_TYPESET, "confidence": _WHY_CONFIDENCE,
              "limited_by": _WHY_CONFIDENCE, "culprit_of": _WHY_CULPRIT},
    "junit": {"status": _WHY_ROLLED_UP, "inputs": _WHY_DECLARED, "outputs": _WHY_DECLARED,
              "assumptions": _WHY_DECLARED, "latex": _WHY_TYPESET, "confidence": _WHY_CONFIDENCE,
              "limited_by": _WHY_CONFIDENCE, "culprit_of": _WHY_CULPRIT},
    "explain": {"latex": _WHY_TYPESET, "confidence": _WHY_CONFIDENCE, "limited_by": _WHY_CONFIDENCE},
}

#: The fields of :class:`GuaranteeRow` no guarantees-table renderer shows, each with the reason.
GUARANTEE_INTERNAL: dict[str, str] = {}

#: The fields of :class:`UnverifiedRow` no unverified-table renderer shows, each with the reason.
UNVERIFIED_INTERNAL: dict[str, str] = {
    "message": "the row's id, source and reason in one sentence, for the one-line outputs (terminal, SARIF); the "
               "table shows each of them",
}


__all__ = ["AssumptionRow", "Confidence", "CulpritOf", "GUARANTEE_INTERNAL", "GuaranteeRow", "INTERNAL", "INTERNAL_TO",
           "InputRow", "LATEX_INTERNAL", "NodeRow", "OutputRow", "UNVERIFIED_INTERNAL", "UnverifiedRow"]
