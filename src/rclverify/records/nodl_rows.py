"""The NoDL part of the report, defined once: :class:`NodlRow` (with :class:`NodlFindingRow`,
:class:`NodlPlaceRow` and :class:`NodlSideConditionRow`).

``nodl`` is the NoDL stage's record (artifacts/nodl/index.json,
stages/nodl.py; docs/nodl.md) as the report shows it: the workspace's NoDL
documents checked against its contracts and each other, with ``stale``
when the record was made from other files (or not made yet) and
``altered`` when its seal does not hold; ``null`` when the workspace has no
NoDL document.

The rules (docs/decisions.md, "One definition per record"):

* These classes are the only statement of the part's fields.
  report/nodl.py decodes the stage's record into :class:`NodlRow` and
  writes :meth:`~rclverify.records.row.Row.to_json` (the fields in the
  order declared; ``stale`` and ``altered`` absent when there is nothing to
  say).
* The ``nodl`` part of docs/assurance.schema.json is generated from them
  (records/schema_gen.py); tests/records/test_record_shapes.py fails when
  the file and the classes differ.
"""
from __future__ import annotations

from typing import Annotated, Literal

import msgspec

from rclverify.records.shared_rows import WorkspacePlaceRow
from rclverify.records.row import DOC, Row

_DOC = DOC  # a field's description, as the generated JSON Schema shows it


class NodlPlaceRow(WorkspacePlaceRow, frozen=True, forbid_unknown_fields=True):
    """A place a NoDL finding involves."""


class NodlFindingRow(Row, frozen=True, forbid_unknown_fields=True):
    """One finding, at every place it involves."""

    code: Annotated[str, _DOC(description="The finding's code (docs/nodl.md, \"Findings\").")]
    severity: Annotated[Literal["error", "warning"], _DOC(description="An error fails --strict; a warning does "
                                                                      "not.")]
    message: Annotated[str, _DOC(description="What is wrong, in one sentence.")]
    places: Annotated[list[NodlPlaceRow], _DOC(description="Every place involved, most important first.")]


class NodlSideConditionRow(Row, frozen=True, forbid_unknown_fields=True):
    """A parameter's declared constraints against one conjunct its node assumes of the input it sets."""

    node: Annotated[str, _DOC(description="The node.")]
    parameter: Annotated[str, _DOC(description="The parameter.")]
    conjunct: Annotated[str, _DOC(description="The assumption's conjunct, as RCL text.")]
    status: Annotated[Literal["proved", "refuted", "inconclusive"], _DOC(description="Z3's decision.")]
    model: Annotated[dict[str, str], _DOC(description="Refuted: Z3's counterexample, RCL name to value.")]


class NodlRow(Row, frozen=True, forbid_unknown_fields=True, omit_defaults=True):
    """The NoDL stage's record (artifacts/nodl/index.json) as the report shows it."""

    documents: Annotated[dict[str, list[str]], _DOC(
        description="Per node with a document: the files read for it (the document, then what it includes).")]
    parts: Annotated[list[str], _DOC(description="Documents named after no node (parts for include).")]
    findings: Annotated[list[NodlFindingRow], _DOC(description="The findings, in file order.")]
    counts: Annotated[dict[str, int], _DOC(description="Findings per severity (error, warning).")]
    side_conditions: Annotated[list[NodlSideConditionRow], _DOC(
        description="The parameters' side conditions, each decided by Z3.")]
    inputs: Annotated[dict[str, str], _DOC(description="The sha256 of each file the record was made from.")]
    stale: Annotated[str | msgspec.UnsetType, _DOC(
        description="Why the record is not current (made from other files, or not made yet).")] = msgspec.UNSET
    altered: Annotated[str | msgspec.UnsetType, _DOC(
        description="Why the record is not believed (its seal does not hold).")] = msgspec.UNSET


__all__ = ["NodlFindingRow", "NodlPlaceRow", "NodlRow", "NodlSideConditionRow"]
