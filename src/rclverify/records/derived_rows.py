"""A node's derived property and an environment assumption of the system,
defined once: :class:`DerivedPropertyRow` and :class:`EnvironmentAssumptionRow`.

The report's ``derived_properties[]`` holds one row per node the calculus
derived a property for (report/contract_rows.py ``derived_rows``): the
rules and their instances, the environment assumptions of its upstream
cone, and two statuses side by side, its derivation (worst side condition
of the cone) and its evidence (worst guarantee of the cone's node
contracts, report/cones.py); the confidence pass adds ``confidence`` and
``limited_by`` (report/confidence_rows.py, docs/confidence.md).
``environment_assumptions[]`` holds the calculus records' assumptions no
node's guarantee discharges (rule R2's environment), node by node.

The rules (docs/decisions.md, "One definition per record"):

* These classes are the only statement of the rows' fields.  The report
  passes build them and write :meth:`~rclverify.records.row.Row.to_json`;
  a field at ``UNSET`` (the confidence pass's, until it runs) is not
  written, and that pass adds its keys to the JSON object only as fields
  declared here.  A reader decodes the JSON object with
  :meth:`~rclverify.records.row.Row.of`; a key no field declares, or a
  value of another type, raises :class:`msgspec.ValidationError`.
* The ``derived_properties[]`` and ``environment_assumptions[]`` items of
  docs/assurance.schema.json are generated from them (records/schema_gen.py);
  tests/records/test_record_shapes.py fails when the file and the classes differ.
* Every field of :class:`DerivedPropertyRow` is read by a node's section of
  the calculus (report/templates/parts/section.{html,md}.j2, filter
  ``derived_rows``) or named in :data:`INTERNAL` with the reason it is not
  shown; tests/records/test_record_shapes.py fails otherwise.
"""
from __future__ import annotations

from typing import Annotated, Any

import msgspec

from rclverify.records.node_rows import Confidence
from rclverify.records.row import DOC, Row
from rclverify.records.statuses import Derivation, EvidenceStatus
from rclverify.records.strength_rows import LimitedBy

_DOC = DOC

_NODE = "The node's name as the contracts declare it."


class DerivedPropertyRow(Row, frozen=True, forbid_unknown_fields=True):
    """A node's derived property and the two statuses beside it."""

    node: Annotated[str, _DOC(description=_NODE)]
    rules: Annotated[list[str], _DOC(description="The rules applied.")]
    instances: Annotated[list[dict[str, Any]], _DOC(description="The rule instances: rule, premises, conclusion, "
                                                                "shape.")]
    environment_assumptions: Annotated[list[str], _DOC(description="The environment assumptions of its cone.")]
    property: Annotated[str, _DOC(description="The derived property, RCL text.")]
    status: Annotated[EvidenceStatus, _DOC(description="Its derivation as a status: worst side condition of its "
                                                       "cone.")]
    derivation: Annotated[Derivation, _DOC(description="The derivation in words.")]
    evidence_status: Annotated[EvidenceStatus, _DOC(description="Worst status of the node contracts it rests on.")]
    evidence_note: Annotated[str, _DOC(description="Which node contracts it rests on that are not established.")]
    loop_assumption: Annotated[str | None, _DOC(
        description="The assumption a feedback loop's fixpoint used, null without a loop.")]
    confidence: Annotated[Confidence | msgspec.UnsetType, _DOC(
        description="Confidence over the argument, 0 to 1 (docs/confidence.md).")] = msgspec.UNSET
    limited_by: Annotated[LimitedBy | None | msgspec.UnsetType, _DOC(
        description="The weakest premise behind the confidence, null when nothing limits it.")] = msgspec.UNSET


class EnvironmentAssumptionRow(Row, frozen=True, forbid_unknown_fields=True):
    """An environment assumption: one no node's guarantee discharges."""

    node: Annotated[str, _DOC(description=_NODE)]
    text: Annotated[str, _DOC(description="The text as written (RCL for a contract clause, words for a "
                                          "requirement).")]
    source: Annotated[str, _DOC(description="file:line:col of the RCL or plan text (1-based line and column)")]


#: The fields of :class:`DerivedPropertyRow` no derived-property renderer shows, each with the reason.
INTERNAL: dict[str, str] = {}


__all__ = ["DerivedPropertyRow", "EnvironmentAssumptionRow", "INTERNAL"]
