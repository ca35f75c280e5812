"""A ROS grounding finding as the report's readers decode it: :class:`GroundingFindingRow`.

The report's ``grounding.findings[]`` are the grounding stage's records
(ros/ground/ground.py ``Finding.to_json``; their keys typed in
:class:`rclverify.records.stage_records.GroundingFinding`), kept in
:class:`rclverify.records.grounding_rows.GroundingRow` as JSON objects
because their shape belongs to that stage.  A reader that reads one by
attribute (SARIF, ``rclverify explain``) decodes it with
:meth:`GroundingFindingRow.of`: a key it does not declare is ignored, a
missing one is at its default (the default a reader printed before it read
the record so), a value of another type raises
:class:`msgspec.ValidationError`.
"""
from __future__ import annotations

from typing import Any, Mapping

import msgspec


class PlaceRow(msgspec.Struct, frozen=True):
    """A place in a file (:class:`rclverify.records.stage_records.SourceRef`): 1-based line and column."""

    file: str = ""
    line: int = 1
    col: int = 1

    def text(self) -> str:
        """``file:line:col``."""
        return f"{self.file}:{self.line}:{self.col}"


class GroundingFindingRow(msgspec.Struct, frozen=True):
    """One finding of grounding the contracts in the ROS graph: its code (a rule of ros/ground), severity,
    message, the contract node and topic it concerns (``""`` when none; ``None`` when written null), the
    RCL or plan place ``rcl`` and the software's place ``ros`` (``None`` when it has none)."""

    code: str = ""
    severity: str | None = None
    message: str | None = None
    node: str | None = ""
    topic: str | None = ""
    rcl: PlaceRow | None = None
    ros: PlaceRow | None = None

    @classmethod
    def of(cls, finding: Mapping[str, Any]) -> GroundingFindingRow:
        """``finding`` (a ``grounding.findings[]`` object) decoded (see the module docstring)."""
        return msgspec.convert(finding, cls)


__all__ = ["GroundingFindingRow", "PlaceRow"]
