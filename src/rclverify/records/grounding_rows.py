"""The report's grounding in the robot's software, defined once: :class:`GroundingRow` (with
:class:`GroundingCounts`).

``grounding`` is the ROS grounding stage's record (artifacts/ros/grounding.json,
app/ros_stage.py; records/stage_records.py ``GroundingRecord``; docs/ros.md)
as the report shows it (report/finding_rows.py ``grounding_row``): the
contracts held against the computation graph recovered from the robot's
software, with ``stale`` when it was made from other files and ``altered``
(and one error, no ``inputs``) when its seal does not hold, and the
drawing's SVG text; ``null`` when the plan names no ROS software.

The rules (docs/decisions.md, "One definition per record"):

* This class is the only statement of the part's keys.  The report decodes
  the record into it and writes :meth:`~rclverify.records.row.Row.to_json`
  (the fields in the order declared; a field whose default is ``UNSET``
  absent when the record has nothing to say).
* The findings, graph, context and drawing inside are the grounding
  stage's records (ros/ground/ground.py ``Finding``, ros/graph/), whose
  inner shape belongs to that stage: they are left open here.
* The ``grounding`` part of docs/assurance.schema.json is generated from it
  (records/schema_gen.py); tests/records/test_record_shapes.py fails when
  the file and the class differ.
"""
from __future__ import annotations

from typing import Annotated, Any

import msgspec

from rclverify.records.row import DOC, Row

_DOC = DOC  # a field's description, as the generated JSON Schema shows it


class GroundingCounts(Row, frozen=True, forbid_unknown_fields=True):
    """Findings per severity."""

    error: Annotated[int, _DOC(description="How many grounding errors (they fail --strict).")]
    warning: Annotated[int, _DOC(description="How many grounding warnings.")]


class GroundingRow(Row, frozen=True, forbid_unknown_fields=True, omit_defaults=True, kw_only=True):
    """The contracts against the robot's software (docs/ros.md)."""

    findings: Annotated[list[dict[str, Any]], _DOC(
        description="The grounding findings: code, severity, message, node, topic and the contract's and the "
                    "software's places (ros/ground/ground.py).")]
    counts: Annotated[GroundingCounts, _DOC(description="Findings per severity.")]
    graph: Annotated[dict[str, Any], _DOC(
        description="The computation graph's nodes, each with the topics it publishes and subscribes to.")]
    context: Annotated[dict[str, Any], _DOC(
        description="What the graph was read from: the packages, the files by sha256, the launch files.")]
    drawing: Annotated[dict[str, Any], _DOC(
        description="The drawing of contracts and graph: its DOT file and its SVG file (null when none was "
                    "drawn), relative to the workspace.")]
    matched: Annotated[dict[str, str], _DOC(description="Each contract node's ROS node.")]
    inputs: Annotated[dict[str, str] | msgspec.UnsetType, _DOC(
        description="The sha256 of each file the record was made from (absent from an altered "
                    "record).")] = msgspec.UNSET
    stale: Annotated[str | msgspec.UnsetType, _DOC(
        description="Why the record is not current (made from other files).")] = msgspec.UNSET
    altered: Annotated[str | msgspec.UnsetType, _DOC(
        description="Why the record is not believed (its seal does not hold).")] = msgspec.UNSET
    svg_text: Annotated[str | None, _DOC(description="The drawing's SVG text, null when it cannot be read.")]


__all__ = ["GroundingCounts", "GroundingRow"]
